//! From a scene to a running engine: grains, walls, time step, contact model, pipeline.

use std::time::Duration;

use crate::boundary::Boundary;
use crate::contact::damping::Damping;
use crate::contact::model::*;
use crate::contact::tangential::Tangential;
use crate::contact::{ContactHistory, ContactLaw, ContactModel, ModelOptions};
use crate::dim::Vec2;
use crate::error::Error;
use crate::integrate::{FinalIntegrate, InitialIntegrate};
use crate::material::{PairMaterial, PairTable, reduced};
use crate::neighbor::{Neighbours, PairList};
use crate::observe::energy::{EnergyLedger, EnergyRow};
use crate::pack::relaxed_packing;
use crate::particles::Particles;
use crate::pipeline::*;
use crate::scene::{ControlSpec, Grains, Scene, SurfaceSpec, TangentialSpec, TimeStepRule};
use crate::sim::{Simulation, World};
use crate::timestep::{RefContact, TimeStepInfo, choose};
use crate::walls::{Control, Surface, Wall};

/// A running simulation behind one dynamic call per step, whatever its contact model.
pub trait Engine: Send {
    fn step(&mut self) -> Result<(), Error>;
    /// One step, after which nothing looks at the grains' velocities or spins (`look`
    /// false) before the next: see [`Simulation::advance`].
    fn advance(&mut self, look: bool) -> Result<(), Error>;
    fn particles(&self) -> &Particles;
    fn walls(&self) -> &[Wall];
    fn boundary(&self) -> Boundary;
    fn energy_row(&self) -> EnergyRow;
    fn steps(&self) -> u64;
    fn time(&self) -> f64;
    fn dt(&self) -> f64;
    /// Number of pairs touching now.
    fn touching(&self) -> usize;
    /// Number of neighbour-list builds so far.
    fn neighbour_builds(&self) -> u64;
    /// The stages in order.
    fn stage_names(&self) -> Vec<String>;
    fn timings(&self) -> Vec<(String, Duration)>;
    /// The contact model in one line.
    fn model(&self) -> String;
    /// The full state check ([`World::health`]).
    fn health(&self) -> Result<(), Error>;
}

impl<L: ContactLaw> Engine for Simulation<L> {
    fn step(&mut self) -> Result<(), Error> {
        Simulation::step(self)
    }
    fn advance(&mut self, look: bool) -> Result<(), Error> {
        Simulation::advance(self, look)
    }
    fn particles(&self) -> &Particles {
        &self.world.p
    }
    fn walls(&self) -> &[Wall] {
        &self.world.walls
    }
    fn boundary(&self) -> Boundary {
        self.world.boundary
    }
    fn energy_row(&self) -> EnergyRow {
        self.world.energy_row()
    }
    fn steps(&self) -> u64 {
        self.world.step
    }
    fn time(&self) -> f64 {
        self.world.time()
    }
    fn dt(&self) -> f64 {
        self.world.dt
    }
    fn touching(&self) -> usize {
        self.world.pairs.touching() + self.world.wall_active.iter().flatten().filter(|&&a| a).count()
    }
    fn neighbour_builds(&self) -> u64 {
        self.world.neighbours.builds
    }
    fn stage_names(&self) -> Vec<String> {
        Simulation::stage_names(self)
    }
    fn timings(&self) -> Vec<(String, Duration)> {
        Simulation::timings(self)
    }
    fn model(&self) -> String {
        self.world.law.describe()
    }
    fn health(&self) -> Result<(), Error> {
        self.world.health()
    }
}

/// What was built, besides the engine.
pub struct Built {
    pub engine: Box<dyn Engine>,
    pub time_step: TimeStepInfo,
    /// Depth that turns wall forces into stresses, m.
    pub depth: f64,
    /// Length of the periodic cell (or of the packing), m.
    pub length: f64,
}

impl Built {
    /// The pipeline in one line, with dt and steps per contact.
    pub fn explain(&self) -> String {
        let ts = &self.time_step;
        let mut parts = self.engine.stage_names();
        if let Some(c) = parts.iter_mut().find(|s| s.as_str() == "PairContacts") {
            *c = self.engine.model();
        }
        parts.retain(|s| s != "ClearForces" && s != "FinalKick");
        let accuracy = match ts.accuracy {
            Some(a) => format!(
                "; chosen for {} <= {:e}: measured {:.2e} against a converged head-on impact",
                a.quantity.name(),
                a.tolerance,
                a.measured_error
            ),
            None => String::new(),
        };
        format!(
            "{} (dt = {:.3e} s = t_c/{:.1}, t_c = {:.3e} s at {} m/s; stability limit {:.3e} s{accuracy})",
            parts.join(" -> "),
            ts.dt_s,
            ts.steps_per_contact,
            ts.contact_time_s,
            ts.characteristic_speed_m_s,
            ts.stability_limit_s
        )
    }
}

fn read_particle_file(path: &str) -> Result<Vec<(Vec2, f64)>, Error> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(format!("grains.file.path = {path}"), e))?;
    let mut out = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let v: Result<Vec<f64>, _> = line.split_whitespace().map(str::parse).collect();
        let bad = || Error::Scene(format!("{path}:{}: expected `x y r` or `x y z r` in m, got `{line}`", k + 1));
        let v = v.map_err(|_| bad())?;
        let (x, y, r) = match v.as_slice() {
            [x, y, r] => (*x, *y, *r),
            [x, y, _z, r] => (*x, *y, *r),
            _ => return Err(bad()),
        };
        if !(r > 0.0 && x.is_finite() && y.is_finite()) {
            return Err(bad());
        }
        out.push((Vec2::new(x, y), r));
    }
    Ok(out)
}

/// Build the engine a scene describes.
pub fn build(scene: &Scene) -> Result<Built, Error> {
    build_with(scene, 1)
}

/// Build with the contact forces on `threads` threads (feature `parallel`; results are
/// bit-identical to one thread).
pub fn build_with(scene: &Scene, threads: usize) -> Result<Built, Error> {
    crate::threads::Threads::check_count(threads, 1)?;
    scene.validate()?;
    let shape = scene.grain_shape;
    let mats = &scene.materials;
    let mut p = Particles::default();
    let push = |p: &mut Particles, x: Vec2, v: Vec2, w: f64, r: f64, mat: usize| {
        let m = shape.mass(r, mats[mat].density);
        p.push(x, v, w, r, m, shape.inertia(r, m), mat as u16);
    };
    let boundary = match scene.domain.periodic_x {
        Some([a, b]) => Boundary::periodic_x(a, b - a),
        None => Boundary::open(),
    };
    let bottom_surface_y = scene.walls.as_ref().map(|w| {
        let y = w.bottom.y.unwrap_or(0.0);
        match w.bottom.surface {
            SurfaceSpec::Flat => y,
            SurfaceSpec::Rough { radius } => y + radius,
        }
    });
    let mut length = boundary.period;
    match &scene.grains {
        Grains::List(list) => {
            for g in list {
                push(&mut p, Vec2::from(g.x), Vec2::from(g.v), g.omega, g.r, g.material);
            }
        }
        Grains::File { path, material } => {
            for (x, r) in read_particle_file(path)? {
                push(&mut p, x, Vec2::zeros(), 0.0, r, *material);
            }
        }
        Grains::Pack(spec) => {
            let radii = spec.radius.sample(spec.count, spec.seed);
            let y0 = spec.y_min.or(bottom_surface_y).expect("validated");
            let area: f64 = radii.iter().map(|r| std::f64::consts::PI * r * r).sum();
            let lx = spec.x[1] - spec.x[0];
            let h = area / (spec.packing_fraction * lx);
            let r_max = radii.iter().cloned().fold(0.0, f64::max);
            // Too few grains to fill the x range one grain high at this packing fraction.
            if h < 2.0 * r_max {
                let need = (2.0 * r_max * spec.packing_fraction * lx / (area / spec.count as f64)).ceil();
                let allowed = format!(">= about {need} (to fill x = [{}, {}] m at packing_fraction {} at least one grain diameter high)", spec.x[0], spec.x[1], spec.packing_fraction);
                return Err(Error::Invalid { field: "grains.pack.count".into(), value: spec.count.to_string(), allowed });
            }
            let centres = relaxed_packing(&radii, spec.x[0], spec.x[1], y0, y0 + h, boundary.is_periodic(), spec.seed);
            // A packing's order is arbitrary: store it along a space-filling curve.
            for k in crate::pack::morton_order(&centres, spec.x[0], y0, 2.0 * r_max) {
                push(&mut p, centres[k], Vec2::zeros(), 0.0, radii[k], spec.material);
            }
            if length == 0.0 {
                length = lx;
            }
        }
    }
    p.n_free = p.len();
    if length == 0.0 {
        let (lo, hi) = p.x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x.x), b.max(x.x)));
        length = (hi - lo).max(2.0 * p.r[0]);
    }
    let n_free = p.n_free;
    let mean_r = p.r.iter().sum::<f64>() / n_free as f64;
    let depth = match &scene.walls {
        Some(w) => w.thickness.unwrap_or(shape.depth(2.0 * mean_r)),
        None => shape.depth(2.0 * mean_r),
    };

    // Walls.
    let mut walls = Vec::new();
    if let Some(ws) = &scene.walls {
        let top_of_grains = (0..n_free).map(|i| p.x[i].y + p.r[i]).fold(f64::NEG_INFINITY, f64::max);
        let x0 = boundary.is_periodic().then_some(boundary.x_min).unwrap_or_else(|| p.x.iter().map(|x| x.x).fold(f64::INFINITY, f64::min));
        for (name, spec, side) in [("bottom", &ws.bottom, 1.0), ("top", &ws.top, -1.0)] {
            let rough_r = match spec.surface {
                SurfaceSpec::Rough { radius } => radius,
                SurfaceSpec::Flat => 0.0,
            };
            let y = spec.y.unwrap_or(top_of_grains + rough_r);
            let surface = match spec.surface {
                SurfaceSpec::Flat => Surface::Flat,
                SurfaceSpec::Rough { radius } => {
                    let count = ((length / (2.0 * radius)).floor() as usize).max(1);
                    let start = p.len();
                    for k in 0..count {
                        let x = x0 + (k as f64 + 0.5) * length / count as f64;
                        push(&mut p, Vec2::new(x, y), Vec2::new(spec.velocity_x, 0.0), 0.0, radius, spec.material);
                    }
                    Surface::Rough { grains: start..p.len() }
                }
            };
            let mass = spec.mass.unwrap_or_else(|| match &surface {
                Surface::Rough { grains } => grains.clone().map(|k| p.m[k]).sum(),
                Surface::Flat => (length / (2.0 * mean_r)) * shape.mass(mean_r, mats[spec.material].density),
            });
            let control = match spec.control {
                ControlSpec::Fixed => Control::Fixed,
                ControlSpec::Pressure(pa) => Control::Load { force: pa * length * depth },
            };
            walls.push(Wall {
                name,
                surface,
                control,
                side,
                y,
                x_shift: 0.0,
                v: Vec2::new(spec.velocity_x, 0.0),
                mass,
                material: spec.material,
                force: Vec2::zeros(),
                force_prev: Vec2::zeros(),
            });
        }
    }

    // Time step from the smallest grain.
    let friction = scene.model.tangential != TangentialSpec::Frictionless;
    let imin = (0..n_free).min_by(|&a, &b| p.r[a].total_cmp(&p.r[b])).expect("at least one grain");
    let (r, m, i) = (p.r[imin], p.m[imin], p.inertia[imin]);
    let mat = &mats[p.material[imin] as usize];
    let mut refs = vec![RefContact { r_star: r / 2.0, m_star: m / 2.0, pair: PairMaterial::mix(mat, mat), inv_tangential_mass: 2.0 / m + 2.0 * r * r / i }];
    // Against each flat wall, with the wall's own material.
    for w in walls.iter().filter(|w: &&Wall| w.is_flat()) {
        refs.push(RefContact { r_star: r, m_star: m, pair: PairMaterial::mix(mat, &mats[w.material]), inv_tangential_mass: 1.0 / m + r * r / i });
    }
    let _ = reduced;
    let ts = &scene.time_step;
    let time_step = match ts.rule {
        TimeStepRule::Accuracy { quantity, tolerance, impact_speed } => {
            let cal = crate::accuracy::calibrate(mat, r, impact_speed, scene.model.limit_force, quantity, tolerance)?;
            let rule = TimeStepRule::StepsPerContact { steps: cal.steps_per_contact, impact_speed };
            let mut info = choose(&rule, ts.characteristic_speed, ts.allow_unstable, &refs, (r, m, mat), friction)?;
            info.accuracy = Some(crate::accuracy::AccuracyNote { quantity, tolerance, measured_error: cal.measured_error });
            info
        }
        _ => choose(&ts.rule, ts.characteristic_speed, ts.allow_unstable, &refs, (r, m, mat), friction)?,
    };

    let skin = scene.neighbor.skin * 2.0 * p.r[..n_free].iter().cloned().fold(f64::INFINITY, f64::min);
    let options = ModelOptions { limit_force: scene.model.limit_force, lever_arm: scene.model.lever_arm };
    let all_elastic = mats.iter().all(|m| m.restitution == 1.0);
    let threads = crate::threads::Threads::new(threads)?;
    let parts = Parts { p, boundary, walls, dt: time_step.dt_s, skin, scene, threads };
    let engine: Box<dyn Engine> = match (scene.model.tangential, all_elastic) {
        (TangentialSpec::Frictionless, false) => parts.assemble(HertzFrictionless::new(options))?,
        (TangentialSpec::Frictionless, true) => parts.assemble(HertzFrictionlessElastic::new(options))?,
        (TangentialSpec::TotalDisplacement, false) => parts.assemble(LiggghtsHertzHistory::new(options))?,
        (TangentialSpec::TotalDisplacement, true) => parts.assemble(LiggghtsHertzHistoryElastic::new(options))?,
        (TangentialSpec::IncrementalForce, false) => parts.assemble(YadeMindlin::new(options))?,
        (TangentialSpec::IncrementalForce, true) => parts.assemble(YadeMindlinElastic::new(options))?,
    };
    Ok(Built { engine, time_step, depth, length })
}

struct Parts<'a> {
    p: Particles,
    boundary: Boundary,
    walls: Vec<Wall>,
    dt: f64,
    skin: f64,
    scene: &'a Scene,
    threads: crate::threads::Threads,
}

impl Parts<'_> {
    fn assemble<Dm: Damping, T: Tangential>(self, law: ContactModel<Dm, T>) -> Result<Box<dyn Engine>, Error> {
        if self.scene.output.energy { self.assemble_with::<Dm, T, true>(law) } else { self.assemble_with::<Dm, T, false>(law) }
    }

    fn assemble_with<Dm: Damping, T: Tangential, const E: bool>(self, law: ContactModel<Dm, T>) -> Result<Box<dyn Engine>, Error> {
        type L<Dm, T> = ContactModel<Dm, T>;
        let scene = self.scene;
        let rotation = T::FRICTION && scene.model.rotation;
        let has_walls = !self.walls.is_empty();
        let has_flat = self.walls.iter().any(Wall::is_flat);
        let gravity = Vec2::from(scene.gravity);
        let n_free = self.p.n_free;
        let wall_hist = self.walls.iter().map(|w| if w.is_flat() { vec![ContactHistory::default(); n_free] } else { Vec::new() }).collect();
        let wall_active = self.walls.iter().map(|w| vec![false; if w.is_flat() { n_free } else { 0 }]).collect();
        let world = World {
            p: self.p,
            boundary: self.boundary,
            law,
            pair_table: PairTable::new(&scene.materials),
            pairs: PairList { keep_energy: E, ..Default::default() },
            walls: self.walls,
            wall_hist,
            wall_active,
            neighbours: Neighbours::new(self.skin),
            ledger: EnergyLedger::default(),
            gravity,
            dt: self.dt,
            step: 0,
            max_overlap: (0.0, 0, 0),
            initial_energy: 0.0,
            energy: E,
            threads: self.threads.clone(),
            kick: Default::default(),
            zeroed: Default::default(),
        };
        // The force stages, shared by the step and by the set-up at t = 0.
        let threads = self.threads.clone();
        let forces = || -> Result<Vec<Box<dyn Stage<L<Dm, T>>>>, Error> {
            let mut s: Vec<Box<dyn Stage<L<Dm, T>>>> = vec![Box::new(UpdateNeighbours), Box::new(ClearForces)];
            if gravity != Vec2::zeros() {
                s.push(Box::new(Gravity::<E>));
            }
            if let Some(c) = scene.model.general_damping {
                s.push(Box::new(GeneralDamping::<E>::new(c)));
            }
            s.push(if rotation { pair_stage::<Dm, T, E, true>(&threads) } else { pair_stage::<Dm, T, E, false>(&threads) });
            if has_flat {
                s.push(Box::new(FlatWallForces::<E>));
            }
            Ok(s)
        };
        let mut stages: Vec<Box<dyn Stage<L<Dm, T>>>> = Vec::new();
        // The walls first: their grains follow them in the drift.
        if has_walls {
            stages.push(Box::new(MoveWalls));
        }
        if rotation {
            stages.push(Box::new(InitialIntegrate::<true>::default()));
        } else {
            stages.push(Box::new(InitialIntegrate::<false>::default()));
        }
        stages.extend(forces()?);
        if has_walls {
            stages.push(Box::new(FinishWalls::<E>));
        }
        if rotation {
            stages.push(Box::new(FinalIntegrate::<true>));
        } else {
            stages.push(Box::new(FinalIntegrate::<false>));
        }
        stages.push(Box::new(Watchdog { max_overlap: 0.1, every: 100 }));
        let mut setup = forces()?;
        if has_walls {
            setup.push(Box::new(FinishWalls::<E>));
        }
        Ok(Box::new(Simulation::new(world, stages, setup)?))
    }
}

/// The grain-grain contact stage: serial, or on the run's pool of threads; with `SPIN` when
/// the grains rotate (without, the kernel neither reads spins nor computes torques).
fn pair_stage<Dm: Damping, T: Tangential, const E: bool, const SPIN: bool>(threads: &crate::threads::Threads) -> Box<dyn Stage<ContactModel<Dm, T>>> {
    #[cfg(feature = "parallel")]
    if threads.count() > 1 {
        return Box::new(crate::parallel::ParallelPairForces::<E, SPIN>::new(threads.clone()));
    }
    let _ = threads;
    Box::new(PairForces::<E, SPIN>::default())
}
