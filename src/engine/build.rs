//! From a scene to a running engine: grains, walls, time step, contact model, pipeline.

use crate::engine::consistency::{self, GrainNames, MAX_PACKING_OVERLAP, MAX_START_OVERLAP, MAX_STEP_MOVE};
use crate::engine::domain::{Context, Domain};
use crate::engine::effects::Effects;
use crate::engine::integrate::{FinalIntegrate, InitialIntegrate};
use crate::engine::neighbor::Neighbours;
use crate::engine::simulation::{Engine, Simulation};
use crate::engine::stages::*;
use crate::engine::timestep::{RefContact, TimeStepInfo, choose};
use crate::engine::world::World;
use crate::error::{Error, Shown};
use crate::kernels::pairs::PairList;
use crate::physics::boundary::Boundary;
use crate::physics::contact::cohesion::Cohesion;
use crate::physics::contact::rolling::Rolling;
use crate::physics::contact::damping::Damping;
use crate::physics::contact::normal::{Hertz, Normal};
use crate::physics::contact::model::*;
use crate::physics::contact::tangential::Tangential;
use crate::physics::contact::{ContactHistory, ContactModel, ModelOptions};
use crate::physics::dim::{Dim, Plane, Space, Vec2};
use nalgebra::Vector3;
use crate::physics::energy::EnergyLedger;
use crate::physics::material::{PairMaterial, PairTable};
use crate::physics::particles::Particles;
use crate::physics::walls::{Control, Surface, Wall};
use crate::scene::grains::read_grain_file;
use crate::scene::limits::{Limits, MemoryEstimate};
use crate::scene::pack::relaxed_packing;
use crate::physics::contact::rolling::Sds;
use crate::scene::{Analysis, ControlSpec, Dimension, DampingSpec, Grains, RollingSpec, Scene, SurfaceSpec, TangentialSpec, TimeStepRule};

/// What was built, besides the engine.
pub struct Built<D: Dim = Plane> {
    pub engine: Box<dyn Engine<D>>,
    pub time_step: TimeStepInfo,
    /// Depth that turns wall forces into stresses, m (in space the cell's z length).
    pub depth: f64,
    /// Length of the periodic cell (or of the packing), m.
    pub length: f64,
    /// Each effect on or off and why ([`Effects`]).
    pub effects: Effects,
    /// A protocol's stages in one line ([`Scene::describe_stages`]).
    pub stages: Option<String>,
}

impl<D: Dim> Built<D> {
    /// Every effect, on or off, why, and its measured cost ([`Effects::table`]).
    pub fn explain_effects(&self) -> String {
        self.effects.table(&crate::engine::effects::cost_runs(), &crate::engine::effects::this_cpu())
    }

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
        let stages = self.stages.as_ref().map(|s| format!("; {s}")).unwrap_or_default();
        let space = if D::D == 3 { "in space (3D): " } else { "" };
        format!(
            "{space}{} (dt = {:.3e} s = t_c/{:.1}, t_c = {:.3e} s at {} m/s; stability limit {:.3e} s{accuracy}){stages}",
            parts.join(" -> "),
            ts.dt_s,
            ts.steps_per_contact,
            ts.contact_time_s,
            ts.characteristic_speed_m_s,
            ts.stability_limit_s
        )
    }
}

/// Build the engine a scene describes.
pub fn build(scene: &Scene) -> Result<Built, Error> {
    build_with(scene, 1)
}

/// Build with the contact forces on `threads` threads (feature `parallel`; results are
/// bit-identical to one thread), within the machine's default [`Limits`].
pub fn build_with(scene: &Scene, threads: usize) -> Result<Built, Error> {
    build_limited(scene, threads, &Limits::machine())
}

/// Whether a packing's region `[a, b]` is the periodic cell along its axis (`periodic`,
/// from `min`, of length `period`).
fn periodic_along([a, b]: [f64; 2], periodic: bool, min: f64, period: f64) -> bool {
    periodic && a == min && b == min + period
}

/// A packing's region along `axis` at least a grain wide (two, periodic).
fn region_wide([a, b]: [f64; 2], axis: &str, periodic: bool, r_max: f64) -> Result<(), Error> {
    let widest = if periodic { 4.0 * r_max } else { 2.0 * r_max };
    crate::error::check(b - a >= widest, "grains.pack", axis, format!("[{}, {}]", a.shown(), b.shown()), &format!("a region at least {} m wide ({} the largest radius drawn, {} m)", widest.shown(), if periodic { "four times" } else { "twice" }, r_max.shown()))
}

/// The number of grains a rough wall of glued grains of `radius` holds over `length`.
fn glued_count(length: f64, radius: f64) -> f64 {
    (length / (2.0 * radius)).floor().max(1.0)
}

/// Build within `limits`: every size is estimated from the scene and checked against the
/// memory budget before it is allocated, and the grains, walls and time step are checked
/// for consistency ([`crate::engine::consistency`]) before the engine is. A plane
/// scene's engine ([`build_in`] builds either).
pub fn build_limited(scene: &Scene, threads: usize, limits: &Limits) -> Result<Built, Error> {
    build_in::<Plane>(scene, threads, limits)
}

/// What the build does differently in the plane and in space: the scene's periodic
/// cell, a packing's region and its relaxation, the rough walls' glued grains (a row in
/// the plane, an x-z lattice in space), the depth that turns a wall's force into a
/// stress, and the contact laws only the plane has (rolling resistance, micro-slip).
/// Everything else is [`build_in`], written once.
pub trait Building: Pipeline {
    /// The `dimension` a scene declares for it.
    const DIMENSION: Dimension;
    /// The scene's periodic cell.
    fn boundary(domain: &crate::scene::Domain) -> Boundary<Self>;
    /// The z extent a rough wall spans and a flat wall's area has, m (0 in the plane):
    /// the periodic cell's, the packing region's, or the listed grains'.
    fn z_length(scene: &Scene) -> f64;
    /// Where a rough wall's lattice starts along z, m (in space): the periodic cell's
    /// start, the packing region's, or, for listed grains, centred on their z range (a
    /// plane scene's grains at z = 0 get their glued grains at z = 0).
    fn z_start(scene: &Scene, boundary: &Boundary<Self>, p: &Particles<Self>, z_length: f64) -> f64;
    /// A rough wall's glued grains at height `y`: their centres, spread over `length` in
    /// x from `x0` (and over `z_length` in z from `z0`).
    fn lattice(length: f64, x0: f64, z_length: f64, z0: f64, y: f64, radius: f64) -> Vec<Self::Vector<f64>>;
    /// How many glued grains a rough wall of this radius has (an estimate, before any is made).
    fn glued(length: f64, z_length: f64, radius: f64) -> f64;
    /// The grains a flat wall's default mass counts: a row (times a row along z in space)
    /// of mean grains.
    fn rows(length: f64, z_length: f64, diameter: f64) -> f64;
    /// A packing's region is periodic along x (and z) where it is the periodic cell along
    /// it (the packing then wraps); a narrower region is packed between its ends. Each
    /// side at least a grain wide (two, periodic: a grain must not meet its own image).
    fn check_region(spec: &crate::scene::PackSpec, boundary: &Boundary<Self>, r_max: f64) -> Result<(), Error>;
    /// A packing's relaxed centres for radii `radii` in its region from `y0`, of height
    /// `h`, and the order to store them in: along a space-filling curve (a packing's
    /// order is arbitrary: near in space, near in memory).
    fn pack(spec: &crate::scene::PackSpec, radii: &[f64], boundary: &Boundary<Self>, y0: f64, h: f64, r_max: f64) -> (Vec<Self::Vector<f64>>, Vec<usize>);
    /// The region's cross-section a packing fills upwards (m in the plane, m^2 in space)
    /// and the measure of a grain of radius r in it (area, volume).
    fn cross_section(spec: &crate::scene::PackSpec) -> f64;
    fn measure(r: f64) -> f64;
    /// The laws only the plane has: rolling resistance and micro-slip (`None`: not
    /// asked for). Space refuses them by name (validation refused them first).
    fn plane_only(parts: Parts<'_, Self>, rolling: RollingSpec, tangential: TangentialSpec, elastic: bool, options: ModelOptions) -> Result<Result<Box<dyn Engine<Self>>, Parts<'_, Self>>, Error>;
}

impl Building for Plane {
    const DIMENSION: Dimension = Dimension::Two;
    fn boundary(domain: &crate::scene::Domain) -> Boundary {
        match domain.periodic_x {
            Some([a, b]) => Boundary::periodic_x(a, b - a),
            None => Boundary::open(),
        }
    }
    fn z_length(_: &Scene) -> f64 {
        0.0
    }
    fn z_start(_: &Scene, _: &Boundary, _: &Particles, _: f64) -> f64 {
        0.0
    }
    fn lattice(length: f64, x0: f64, _: f64, _: f64, y: f64, radius: f64) -> Vec<Vec2> {
        let count = glued_count(length, radius) as usize;
        (0..count).map(|k| Vec2::new(x0 + (k as f64 + 0.5) * length / count as f64, y)).collect()
    }
    fn glued(length: f64, _: f64, radius: f64) -> f64 {
        glued_count(length, radius)
    }
    fn rows(length: f64, _: f64, diameter: f64) -> f64 {
        length / diameter
    }
    fn cross_section(spec: &crate::scene::PackSpec) -> f64 {
        spec.x[1] - spec.x[0]
    }
    fn measure(r: f64) -> f64 {
        std::f64::consts::PI * r * r
    }
    fn check_region(spec: &crate::scene::PackSpec, boundary: &Boundary, r_max: f64) -> Result<(), Error> {
        region_wide(spec.x, "x", periodic_along(spec.x, boundary.is_periodic(), boundary.x_min, boundary.period), r_max)
    }
    fn pack(spec: &crate::scene::PackSpec, radii: &[f64], boundary: &Boundary, y0: f64, h: f64, r_max: f64) -> (Vec<Vec2>, Vec<usize>) {
        let periodic = periodic_along(spec.x, boundary.is_periodic(), boundary.x_min, boundary.period);
        let centres = relaxed_packing(radii, spec.x[0], spec.x[1], y0, y0 + h, periodic, spec.seed);
        let order = crate::scene::pack::morton_order(&centres, spec.x[0], y0, 2.0 * r_max);
        (centres, order)
    }
    fn plane_only(parts: Parts<'_>, rolling: RollingSpec, tangential: TangentialSpec, elastic: bool, options: ModelOptions) -> Result<Result<Box<dyn Engine>, Parts<'_>>, Error> {
        let hooke = parts.scene.model.normal.hooke();
        Ok(Ok(match (hooke, tangential, elastic) {
            // Rolling resistance, with the restitution damping (0 when every e = 1) and the
            // total displacement; validation refused the other combinations.
            (None, _, _) if rolling == RollingSpec::Cdt => parts.assemble(HertzHistoryCdt::new(options, Hertz))?,
            (None, _, _) if rolling == RollingSpec::Epsd2 => parts.assemble(HertzHistoryEpsd2::new(options, Hertz))?,
            (Some(h), _, _) if rolling == RollingSpec::Cdt => parts.assemble(HookeHistoryCdt::new(options, h))?,
            (Some(h), _, _) if rolling == RollingSpec::Epsd2 => parts.assemble(HookeHistoryEpsd2::new(options, h))?,
            (None, _, _) if let RollingSpec::Sds { stiffness, damping } = rolling => parts.assemble(HertzHistorySds::with_rolling(options, Hertz, Sds { k: stiffness, g: damping }))?,
            (Some(h), _, _) if let RollingSpec::Sds { stiffness, damping } = rolling => parts.assemble(HookeHistorySds::with_rolling(options, h, Sds { k: stiffness, g: damping }))?,
            // Micro-slip (Hertz only: validation refused it with the spring).
            (None, TangentialSpec::MindlinDeresiewicz, false) => parts.assemble(HertzMicroSlip::new(options, Hertz))?,
            (None, TangentialSpec::MindlinDeresiewicz, true) => parts.assemble(HertzMicroSlipElastic::new(options, Hertz))?,
            _ => return Ok(Err(parts)),
        }))
    }
}

impl Building for Space {
    const DIMENSION: Dimension = Dimension::Three;
    fn boundary(domain: &crate::scene::Domain) -> Boundary<Space> {
        Boundary::<Space>::periodic(domain.periodic_x.map(|[a, b]| (a, b - a)), domain.periodic_z.map(|[a, b]| (a, b - a)))
    }
    fn z_length(scene: &Scene) -> f64 {
        if let Some([a, b]) = scene.domain.periodic_z {
            return b - a;
        }
        match &scene.grains {
            Grains::Pack(spec) => spec.z.map_or(0.0, |[a, b]| b - a),
            Grains::List(list) => extent(list.iter().map(|g| (g.x.z(), g.r))),
            Grains::File { .. } => 0.0,
        }
    }
    fn z_start(scene: &Scene, boundary: &Boundary<Space>, p: &Particles<Space>, z_length: f64) -> f64 {
        match &scene.grains {
            _ if boundary.is_periodic_z() => boundary.z_min,
            Grains::Pack(spec) => spec.z.map_or(0.0, |z| z[0]),
            _ => {
                let free = &p.x[..p.n_free];
                let (lo, hi) = free.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x.z), b.max(x.z)));
                0.5 * (lo + hi) - 0.5 * z_length
            }
        }
    }
    fn lattice(length: f64, x0: f64, z_length: f64, z0: f64, y: f64, radius: f64) -> Vec<Vector3<f64>> {
        let (nx, nz) = (glued_count(length, radius) as usize, glued_count(z_length, radius) as usize);
        let mut at = Vec::with_capacity(nx * nz);
        for m in 0..nz {
            for k in 0..nx {
                at.push(Vector3::new(x0 + (k as f64 + 0.5) * length / nx as f64, y, z0 + (m as f64 + 0.5) * z_length / nz as f64));
            }
        }
        at
    }
    fn glued(length: f64, z_length: f64, radius: f64) -> f64 {
        glued_count(length, radius) * glued_count(z_length, radius)
    }
    fn rows(length: f64, z_length: f64, diameter: f64) -> f64 {
        (length / diameter) * (z_length / diameter).max(1.0)
    }
    fn cross_section(spec: &crate::scene::PackSpec) -> f64 {
        let [z0, z1] = spec.z.expect("validated: a 3D packing has a z range");
        (spec.x[1] - spec.x[0]) * (z1 - z0)
    }
    fn measure(r: f64) -> f64 {
        4.0 / 3.0 * std::f64::consts::PI * r * r * r
    }
    fn check_region(spec: &crate::scene::PackSpec, boundary: &Boundary<Space>, r_max: f64) -> Result<(), Error> {
        let z = spec.z.expect("validated: a 3D packing has a z range");
        region_wide(spec.x, "x", periodic_along(spec.x, boundary.is_periodic(), boundary.x_min, boundary.period), r_max)?;
        region_wide(z, "z", periodic_along(z, boundary.is_periodic_z(), boundary.z_min, boundary.z_period), r_max)
    }
    fn pack(spec: &crate::scene::PackSpec, radii: &[f64], boundary: &Boundary<Space>, y0: f64, h: f64, r_max: f64) -> (Vec<Vector3<f64>>, Vec<usize>) {
        let z = spec.z.expect("validated: a 3D packing has a z range");
        let periodic_x = periodic_along(spec.x, boundary.is_periodic(), boundary.x_min, boundary.period);
        let periodic_z = periodic_along(z, boundary.is_periodic_z(), boundary.z_min, boundary.z_period);
        let centres = crate::scene::pack::relaxed_packing_space(radii, spec.x, [y0, y0 + h], z, periodic_x, periodic_z, spec.seed);
        let order = crate::scene::pack::morton_order_space(&centres, [spec.x[0], y0, z[0]], 2.0 * r_max);
        (centres, order)
    }
    fn plane_only(parts: Parts<'_, Space>, rolling: RollingSpec, tangential: TangentialSpec, _: bool, _: ModelOptions) -> Result<Result<Box<dyn Engine<Space>>, Parts<'_, Space>>, Error> {
        if !rolling.is_none() {
            return Err(Error::Invalid { field: "model.rolling".into(), value: serde_json::to_string(&rolling).unwrap_or_default(), allowed: "\"none\" in a 3D scene (rolling resistance is the plane's)".into() });
        }
        if tangential == TangentialSpec::MindlinDeresiewicz {
            return Err(Error::Invalid { field: "model.tangential".into(), value: "\"mindlin_deresiewicz\"".into(), allowed: "another formulation in a 3D scene (micro-slip is the plane's)".into() });
        }
        Ok(Err(parts))
    }
}

/// Build a plane scene's engine (`D = Plane`) or a 3D scene's (`D = Space`), within
/// `limits`: written once for both ([`Building`] holds what differs).
pub fn build_in<D: Building>(scene: &Scene, threads: usize, limits: &Limits) -> Result<Built<D>, Error>
where
    D::Vector<f64>: serde::Serialize + serde::de::DeserializeOwned,
    D::Spin<f64>: serde::Serialize + serde::de::DeserializeOwned,
{
    crate::kernels::threads::Threads::check_count(threads, 1)?;
    scene.validate()?;
    if scene.dimension != D::DIMENSION {
        let (want, other) = (D::DIMENSION.count(), scene.dimension.count());
        return Err(Error::Invalid { field: "dimension".into(), value: other.to_string(), allowed: format!("{want} for this build (a {other}D scene is built by build_in::<{}>)", if other == 3 { "Space" } else { "Plane" }) });
    }
    // The contact forces in space run on one thread so far (`Pipeline for Space`).
    if D::D == 3 && threads > 1 {
        return Err(Error::BadOption { option: "--threads".into(), value: threads.to_string(), allowed: "1 for a 3D scene (its contact forces run on one thread so far)".into() });
    }
    let shape = scene.grain_shape;
    let mats = &scene.materials;
    let boundary = D::boundary(&scene.domain);
    let z_length = D::z_length(scene);
    // How many grains, before any is made: a file is read (within the budget's file
    // size) to count them.
    let file = match &scene.grains {
        Grains::File { path, columns, .. } => Some(read_grain_file(path, *columns, limits)?),
        _ => None,
    };
    let (count, count_field, count_value) = match &scene.grains {
        Grains::List(list) => (list.len() as u64, "grains.list".to_string(), format!("{} grains", list.len())),
        Grains::File { path, .. } => (file.as_ref().map_or(0, |f| f.0.len()) as u64, "grains.file.path".to_string(), format!("{path} ({} grains)", file.as_ref().map_or(0, |f| f.0.len()))),
        Grains::Pack(spec) => (spec.count as u64, "grains.pack.count".to_string(), spec.count.to_string()),
    };
    match (&scene.grains, &file) {
        (Grains::List(list), _) => consistency::given_coordinates(list.iter().map(|g| (g.x.as_slice(), g.r)), |k| format!("grains.list[{k}]"))?,
        (Grains::File { path, .. }, Some((grains, lines))) => consistency::given_coordinates(grains.iter().map(|(x, r)| (&x[..D::D], *r)), |k| format!("the grain on line {} of {path}", lines[k]))?,
        _ => {}
    }
    // The x length the rough walls span: the periodic cell, the packing's region, or the
    // listed grains' extent.
    let mut length = boundary.period;
    if length == 0.0 {
        length = match (&scene.grains, &file) {
            (Grains::Pack(spec), _) => spec.x[1] - spec.x[0],
            (Grains::List(list), _) => extent(list.iter().map(|g| (g.x[0], g.r))),
            (_, Some((grains, _))) => extent(grains.iter().map(|(x, r)| (x[0], *r))),
            _ => 0.0,
        };
    }
    // Named by the wall with the most.
    let mut wall_grains = (0u64, String::new(), String::new());
    let mut most = 0.0;
    if let Some(ws) = &scene.walls {
        for (name, spec) in [("bottom", &ws.bottom), ("top", &ws.top)] {
            if let SurfaceSpec::Rough { radius } = spec.surface {
                let n = D::glued(length, z_length, radius);
                wall_grains.0 = wall_grains.0.saturating_add(if n < 1e18 { n as u64 } else { u64::MAX });
                if n > most {
                    most = n;
                    wall_grains.1 = format!("walls.{name}.surface.rough.radius");
                    wall_grains.2 = format!("{} m ({n:.0} grains over {} m)", radius.shown(), length.shown());
                }
            }
        }
    }
    let microslip = scene.model.tangential == TangentialSpec::MindlinDeresiewicz;
    let mut estimate = MemoryEstimate { grains: (count, count_field, count_value), wall_grains, materials: mats.len() as u64, microslip, ..Default::default() };
    limits.check(&estimate)?;

    let mut p = Particles::<D>::default();
    let push = |p: &mut Particles<D>, x: D::Vector<f64>, v: D::Vector<f64>, w: D::Spin<f64>, r: f64, mat: usize| {
        let m = shape.mass(r, mats[mat].density);
        p.push(x, v, w, r, m, shape.inertia(r, m), mat as u16);
    };
    let mut names = GrainNames::of(scene);
    let mut packed = false;
    match &scene.grains {
        Grains::List(list) => {
            for g in list {
                push(&mut p, g.x.lift::<D>(), g.v.lift::<D>(), g.omega.lift::<D>(), g.r, g.material);
            }
        }
        Grains::File { material, .. } => {
            let (grains, lines) = file.expect("read above");
            for (x, r) in grains {
                push(&mut p, crate::scene::Coords::from(x).lift::<D>(), D::zero(), D::spin_zero(), r, *material);
            }
            if let GrainNames::File(_, l) = &mut names {
                *l = lines;
            }
        }
        Grains::Pack(spec) => {
            let (lo, hi) = spec.radius.bounds();
            let bound = crate::scene::limits::MAX_COORDINATE_RADII * hi;
            let coordinate_ok = |v: f64| v.abs() <= bound;
            let y0 = scene.grains_floor().expect("validated: y_min or walls");
            for (field, v) in [("x", spec.x[0]), ("x", spec.x[1]), ("y_min", y0)] {
                crate::error::check(coordinate_ok(v), "grains.pack", field, v, &format!("within {bound:e} m of the origin ({:e} largest radii)", crate::scene::limits::MAX_COORDINATE_RADII))?;
            }
            let mass_ok = |r: f64| {
                let m = shape.mass(r, mats[spec.material].density);
                m.is_finite() && m > 0.0
            };
            crate::error::check(mass_ok(lo) && mass_ok(hi), "grains.pack", "radius", format!("[{lo}, {hi}] m"), "radii whose masses are finite and > 0 at this density")?;
            let radii = spec.radius.sample(spec.count, spec.seed);
            let area: f64 = radii.iter().map(|&r| D::measure(r)).sum();
            let lx = D::cross_section(spec);
            let h = area / (spec.packing_fraction * lx);
            let r_max = radii.iter().cloned().fold(0.0, f64::max);
            // Too few grains to fill the x range one grain high at this packing fraction.
            if !(h >= 2.0 * r_max) {
                let need = (2.0 * r_max * spec.packing_fraction * lx / (area / spec.count as f64)).ceil();
                let zs = spec.z.map(|[a, b]| format!(", z = [{}, {}] m", a.shown(), b.shown())).unwrap_or_default();
                let allowed = format!(">= about {} (to fill x = [{}, {}] m{zs} at packing_fraction {} at least one grain diameter high)", need.shown(), spec.x[0].shown(), spec.x[1].shown(), spec.packing_fraction);
                return Err(Error::Invalid { field: "grains.pack.count".into(), value: spec.count.to_string(), allowed });
            }
            D::check_region(spec, &boundary, r_max)?;
            crate::error::check(coordinate_ok(y0 + h), "grains.pack", "count", spec.count, &format!("a packing whose top (y = {} m, from the count, radii and packing_fraction) lies within {bound:e} m of the origin", (y0 + h).shown()))?;
            // The region must fit under a top wall placed by the scene.
            if let Some(ws) = &scene.walls
                && let Some(t) = ws.top.y
            {
                let top_surface = t - ws.top.surface.radius();
                crate::error::check(
                    y0 + h <= top_surface,
                    "walls.top",
                    "y",
                    t,
                    &format!(">= {} m: the packing fills y = [{y0}, {}] m (its count at its packing_fraction), below the top wall's surface", y0 + h + ws.top.surface.radius(), y0 + h),
                )?;
            }
            let (centres, order) = D::pack(spec, &radii, &boundary, y0, h, r_max);
            for k in order {
                push(&mut p, centres[k], D::zero(), D::spin_zero(), radii[k], spec.material);
            }
            packed = true;
        }
    }
    p.n_free = p.len();
    if length == 0.0 {
        length = 2.0 * p.r[0];
    }
    let n_free = p.n_free;
    let mean_r = p.r.iter().sum::<f64>() / n_free as f64;
    let depth = match &scene.walls {
        _ if D::D == 3 => z_length,
        Some(w) => w.thickness.unwrap_or(shape.depth(2.0 * mean_r)),
        None => shape.depth(2.0 * mean_r),
    };

    // Walls.
    let mut walls = Vec::new();
    if let Some(ws) = &scene.walls {
        let top_of_grains = (0..n_free).map(|i| p.x[i][1] + p.r[i]).fold(f64::NEG_INFINITY, f64::max);
        let x0 = if boundary.is_periodic() { boundary.x_min } else { p.x.iter().map(|x| x[0]).fold(f64::INFINITY, f64::min) };
        let z0 = D::z_start(scene, &boundary, &p, z_length);
        for (name, spec, side) in [("bottom", &ws.bottom, 1.0), ("top", &ws.top, -1.0)] {
            let rough_r = spec.surface.radius();
            let y = spec.y.unwrap_or(top_of_grains + rough_r);
            let surface = match spec.surface {
                SurfaceSpec::Flat => Surface::Flat,
                SurfaceSpec::Rough { radius } => {
                    let start = p.len();
                    let mut v = D::zero::<f64>();
                    (v[0], v[1]) = (spec.velocity_x, spec.velocity_y);
                    for x in D::lattice(length, x0, z_length, z0, y, radius) {
                        push(&mut p, x, v, D::spin_zero(), radius, spec.material);
                    }
                    Surface::Rough { grains: start..p.len() }
                }
            };
            let mass = spec.mass.unwrap_or_else(|| match &surface {
                Surface::Rough { grains } => grains.clone().map(|k| p.m[k]).sum(),
                Surface::Flat => D::rows(length, z_length, 2.0 * mean_r) * shape.mass(mean_r, mats[spec.material].density),
            });
            let control = control(&spec.control, length, depth);
            let mut v = D::zero::<f64>();
            (v[0], v[1]) = (spec.velocity_x, spec.velocity_y);
            walls.push(Wall { name, surface, control, side, y, x_shift: 0.0, v, mass, glued_radius: rough_r, material: spec.material, force: D::zero(), force_prev: D::zero() });
        }
    }

    // Where the grains sit: coordinates, masses, the periodic cell, the walls, overlaps.
    consistency::coordinates(scene, &p, &names, &walls)?;
    consistency::masses(&p, &names, &walls, mats)?;
    consistency::periodic_cell(&boundary, &p)?;
    let worst = consistency::start_overlaps(&p, &walls, &boundary, &names, if packed { MAX_PACKING_OVERLAP } else { MAX_START_OVERLAP }, scene)?;
    // The largest overlap at the start, and the speed its stored energy would throw two
    // grains apart at: sqrt(E*/rho) (dn/r)^(5/4) (Hertz: the speed of an impact that
    // presses a contact in that far).
    let start_overlap = worst.map(|(i, j, ratio)| {
        let (a, b) = (&mats[p.material[i] as usize], &mats[p.material[j] as usize]);
        let release = (PairMaterial::mix(a, b).e_star / a.density.min(b.density)).sqrt() * ratio.powf(1.25);
        (ratio, format!("{} and {}", names.name(i, &p, &walls), names.name(j, &p, &walls)), release)
    });

    // What the scene calls for, declared or derived from its values: an effect that is off
    // has no stage and no kernel branch, and the time step does not allow for it.
    let effects = Effects::of(scene, &p, &walls);
    // Time step from the smallest grain.
    let friction = effects.friction;
    let imin = (0..n_free).min_by(|&a, &b| p.r[a].total_cmp(&p.r[b])).expect("at least one grain");
    let (r, m, i) = (p.r[imin], p.m[imin], p.inertia[imin]);
    let mat = &mats[p.material[imin] as usize];
    let rule = scene.model.beta_rule();
    let mut refs = vec![RefContact::twin(r, m, i, PairMaterial::mix_with(mat, mat, rule))];
    // Against each flat wall, with the wall's own material.
    for w in walls.iter().filter(|w: &&Wall<D>| w.is_flat()) {
        refs.push(RefContact::wall(r, m, i, PairMaterial::mix_with(mat, &mats[w.material], rule)));
    }
    let ts = &scene.time_step;
    // An accuracy rule is resolved into steps per contact before the engine is built
    // (`crate::study::build`: the calibration runs engines of its own).
    if let TimeStepRule::Accuracy { .. } = ts.rule {
        return Err(Error::Scene("an accuracy time step rule must be resolved first: build the scene with grainlab::build (the study's build), which calibrates it".into()));
    }
    let time_step = choose(&scene.model, &ts.rule, ts.characteristic_speed, ts.allow_unstable, &refs, (r, m, mat), friction)?;
    let dt = time_step.dt_s;
    let steps = crate::engine::timestep::step_count(scene.duration, dt, "duration")?;
    // Every stage of a protocol takes at least a step.
    let counts = crate::engine::timestep::stage_steps(scene.stages.iter().map(|s| s.duration), dt);
    if let Some(k) = counts.iter().position(|&n| n == 0) {
        return Err(crate::engine::timestep::stage_too_short(k, scene.stages[k].duration, dt));
    }
    // The rows the summary keeps: a wall row per sample, an impact curve point per step
    // in contact (at most every step, and at most MAX_CURVE_POINTS).
    let samples = if scene.stages.is_empty() { scene.output.samples as f64 } else { scene.stages.iter().map(|st| st.samples.unwrap_or(scene.output.samples) as f64).sum() };
    let samples = samples.min(steps as f64);
    let (rows, field, value) = if scene.analysis == Analysis::Impact {
        let curve = (steps as f64).min(crate::scene::limits::MAX_CURVE_POINTS as f64);
        (curve + samples, "duration".to_string(), format!("{} s ({steps} steps of {dt:.3e} s)", scene.duration))
    } else {
        (samples, "output.samples".to_string(), scene.output.samples.to_string())
    };
    estimate.rows = (rows as u64, field, value);
    if scene.output.contacts {
        estimate.inside = (p.len() as u64, samples as u64);
    }
    limits.check(&estimate)?;
    consistency::motion(&p, &walls, scene.gravity.lift::<D>(), &names, dt)?;
    consistency::load(scene, &p, &walls, length, depth, dt)?;
    consistency::stages(scene, &p, &walls, length, depth, dt)?;
    consistency::stable_for_every_pair(scene, &p, &walls, &time_step, friction)?;
    consistency::cohesion(scene, &p, &walls)?;
    consistency::drag(scene, dt)?;
    consistency::impact(scene, &p, &walls, &boundary, scene.duration)?;

    let r_min = p.r[..n_free].iter().cloned().fold(f64::INFINITY, f64::min);
    let skin = scene.neighbor.skin * 2.0 * r_min;
    let domain = Domain::new(&p, &walls, &boundary, travel(scene, &p, &walls), MAX_STEP_MOVE * r_min);
    let start_speed = (0..n_free).map(|k| D::norm(p.v[k])).chain(walls.iter().map(|w| D::norm(w.v))).fold(0.0, f64::max);
    let context = Context {
        start_overlap,
        characteristic_speed: time_step.characteristic_speed_m_s,
        contact_time: time_step.contact_time_s,
        stability_limit: time_step.stability_limit_s,
        allow_unstable: ts.allow_unstable,
        pressure: scene.walls.as_ref().and_then(|w| if let ControlSpec::Pressure(pa) = w.top.control { Some(pa) } else { None }),
        start_speed,
    };
    let options = ModelOptions { limit_force: scene.model.limit_force, lever_arm: scene.model.lever_arm };
    let all_elastic = !effects.damping;
    // Without friction (declared, or no pair that can touch has any) the frictionless law.
    let tangential = if effects.friction { scene.model.tangential } else { TangentialSpec::Frictionless };
    let threads = crate::kernels::threads::Threads::new(threads)?;
    let parts = Parts { p, boundary, walls, dt, skin, scene, threads, domain, context };
    let tsuji = scene.model.damping == DampingSpec::Tsuji;
    let tsuji_sqrt2 = scene.model.damping == DampingSpec::TsujiSqrt2;
    let rolling = if effects.rolling { scene.model.rolling } else { RollingSpec::None };
    // Rolling resistance and micro-slip: the plane's laws.
    let parts = match D::plane_only(parts, rolling, tangential, all_elastic, options)? {
        Ok(engine) => return Ok(Built { engine, time_step, depth, length, effects, stages: scene.describe_stages() }),
        Err(parts) => parts,
    };
    let engine: Box<dyn Engine<D>> = match (scene.model.normal.hooke(), tangential, all_elastic) {
        // DMT cohesion, with the restitution damping (0 when every e = 1); validation
        // refused it with the incremental force, Tsuji's damping and the clamp.
        (None, TangentialSpec::Frictionless, _) if effects.cohesion => parts.assemble(HertzDmtFrictionless::new(options, Hertz))?,
        (None, _, _) if effects.cohesion => parts.assemble(HertzDmtHistory::new(options, Hertz))?,
        (Some(h), TangentialSpec::Frictionless, _) if effects.cohesion => parts.assemble(HookeDmtFrictionless::new(options, h))?,
        (Some(h), _, _) if effects.cohesion => parts.assemble(HookeDmtHistory::new(options, h))?,
        // LAMMPS' Tsuji damping (validation refused it with the incremental force).
        (None, TangentialSpec::Frictionless, _) if tsuji => parts.assemble(HertzTsujiFrictionless::new(options, Hertz))?,
        (None, TangentialSpec::TotalForceCap, _) if tsuji => parts.assemble(HertzTsujiForceCap::new(options, Hertz))?,
        (None, _, _) if tsuji => parts.assemble(HertzTsujiHistory::new(options, Hertz))?,
        (Some(h), TangentialSpec::Frictionless, _) if tsuji => parts.assemble(HookeTsujiFrictionless::new(options, h))?,
        (Some(h), TangentialSpec::TotalForceCap, _) if tsuji => parts.assemble(HookeTsujiForceCap::new(options, h))?,
        (Some(h), _, _) if tsuji => parts.assemble(HookeTsujiHistory::new(options, h))?,
        // LAMMPS' current Tsuji damping (the fit times sqrt(2)), the same combinations.
        (None, TangentialSpec::Frictionless, _) if tsuji_sqrt2 => parts.assemble(HertzTsujiSqrt2Frictionless::new(options, Hertz))?,
        (None, TangentialSpec::TotalForceCap, _) if tsuji_sqrt2 => parts.assemble(HertzTsujiSqrt2ForceCap::new(options, Hertz))?,
        (None, _, _) if tsuji_sqrt2 => parts.assemble(HertzTsujiSqrt2History::new(options, Hertz))?,
        (Some(h), TangentialSpec::Frictionless, _) if tsuji_sqrt2 => parts.assemble(HookeTsujiSqrt2Frictionless::new(options, h))?,
        (Some(h), TangentialSpec::TotalForceCap, _) if tsuji_sqrt2 => parts.assemble(HookeTsujiSqrt2ForceCap::new(options, h))?,
        (Some(h), _, _) if tsuji_sqrt2 => parts.assemble(HookeTsujiSqrt2History::new(options, h))?,
        (None, TangentialSpec::Frictionless, false) => parts.assemble(HertzFrictionless::new(options, Hertz))?,
        (None, TangentialSpec::Frictionless, true) => parts.assemble(HertzFrictionlessElastic::new(options, Hertz))?,
        (None, TangentialSpec::TotalDisplacement, false) => parts.assemble(LiggghtsHertzHistory::new(options, Hertz))?,
        (None, TangentialSpec::TotalDisplacement, true) => parts.assemble(LiggghtsHertzHistoryElastic::new(options, Hertz))?,
        (None, TangentialSpec::TotalForceCap, false) => parts.assemble(HertzForceCap::new(options, Hertz))?,
        (None, TangentialSpec::TotalForceCap, true) => parts.assemble(HertzForceCapElastic::new(options, Hertz))?,
        (None, TangentialSpec::TotalForceCapSpringKept, false) => parts.assemble(HertzSpringKept::new(options, Hertz))?,
        (None, TangentialSpec::TotalForceCapSpringKept, true) => parts.assemble(HertzSpringKeptElastic::new(options, Hertz))?,
        (None, TangentialSpec::IncrementalForce, false) => parts.assemble(YadeMindlin::new(options, Hertz))?,
        (None, TangentialSpec::IncrementalForce, true) => parts.assemble(YadeMindlinElastic::new(options, Hertz))?,
        (Some(h), TangentialSpec::Frictionless, false) => parts.assemble(HookeFrictionless::new(options, h))?,
        (Some(h), TangentialSpec::Frictionless, true) => parts.assemble(HookeFrictionlessElastic::new(options, h))?,
        (Some(h), TangentialSpec::TotalDisplacement, false) => parts.assemble(LiggghtsHookeHistory::new(options, h))?,
        (Some(h), TangentialSpec::TotalDisplacement, true) => parts.assemble(LiggghtsHookeHistoryElastic::new(options, h))?,
        (Some(h), TangentialSpec::TotalForceCap, false) => parts.assemble(HookeForceCap::new(options, h))?,
        (Some(h), TangentialSpec::TotalForceCap, true) => parts.assemble(HookeForceCapElastic::new(options, h))?,
        (Some(h), TangentialSpec::TotalForceCapSpringKept, false) => parts.assemble(HookeSpringKept::new(options, h))?,
        (Some(h), TangentialSpec::TotalForceCapSpringKept, true) => parts.assemble(HookeSpringKeptElastic::new(options, h))?,
        // Taken above in the plane; refused in space, and with the linear spring.
        (_, TangentialSpec::MindlinDeresiewicz, _) => return Err(Error::Invalid { field: "model.tangential".into(), value: "\"mindlin_deresiewicz\"".into(), allowed: "another formulation with a linear spring, or in 3D (micro-slip is the plane's)".into() }),
        (Some(h), TangentialSpec::IncrementalForce, false) => parts.assemble(HookeIncremental::new(options, h))?,
        (Some(h), TangentialSpec::IncrementalForce, true) => parts.assemble(HookeIncrementalElastic::new(options, h))?,
    };
    Ok(Built { engine, time_step, depth, length, effects, stages: scene.describe_stages() })
}

/// A wall's control in the engine's terms: a pressure (Pa) becomes the force on the
/// wall's area, `length` x `depth` (m).
pub fn control(spec: &ControlSpec, length: f64, depth: f64) -> Control {
    match *spec {
        ControlSpec::Fixed => Control::Fixed,
        ControlSpec::Pressure(pa) => Control::Load { force: pa * length * depth },
    }
}

/// The x extent of grains given as (x, r), m.
fn extent(grains: impl Iterator<Item = (f64, f64)>) -> f64 {
    let (lo, hi, r0) = grains.fold((f64::INFINITY, f64::NEG_INFINITY, 0.0f64), |(a, b, r0), (x, r)| (a.min(x), b.max(x), if r0 == 0.0 { r } else { r0 }));
    (hi - lo).max(2.0 * r0)
}

/// How far a grain may travel from its first place over the run where no wall or
/// periodic cell bounds it, m: four times what the fastest it could go carries it. The
/// fastest: the whole kinetic energy the scene starts with in its lightest grain, plus
/// twice the fastest wall's speed (a grain dragged along and flung), plus gravity's
/// pull over the run.
fn travel<D: Dim>(scene: &Scene, p: &Particles<D>, walls: &[Wall<D>]) -> f64 {
    let n = p.n_free;
    let energy: f64 = (0..n).map(|i| 0.5 * p.m[i] * D::norm_squared(p.v[i]) + 0.5 * p.inertia[i] * D::spin_dot(p.omega[i], p.omega[i])).sum();
    let m_min = p.m[..n].iter().cloned().fold(f64::INFINITY, f64::min);
    let v_walls = walls.iter().map(|w| D::norm(w.v)).fold(scene.fastest_wall(), f64::max);
    let t = scene.duration;
    let g = scene.strongest_gravity();
    let speed = (2.0 * energy / m_min).sqrt() + 2.0 * v_walls + g * t;
    4.0 * speed * t
}

/// A built scene's grains, walls and settings, before its contact law is chosen.
pub struct Parts<'a, D: Dim = Plane> {
    p: Particles<D>,
    domain: Domain<D>,
    context: Context,
    boundary: Boundary<D>,
    walls: Vec<Wall<D>>,
    dt: f64,
    skin: f64,
    scene: &'a Scene,
    threads: crate::kernels::threads::Threads,
}

impl<D: Pipeline> Parts<'_, D>
where
    D::Vector<f64>: serde::Serialize + serde::de::DeserializeOwned,
    D::Spin<f64>: serde::Serialize + serde::de::DeserializeOwned,
{
    fn assemble<N: Normal, Dm: Damping, T: Tangential<D>, C: Cohesion, Rr: Rolling<D>>(self, law: ContactModel<N, Dm, T, C, Rr, D>) -> Result<Box<dyn Engine<D>>, Error> {
        if self.scene.output.energy { self.assemble_with::<N, Dm, T, C, Rr, true>(law) } else { self.assemble_with::<N, Dm, T, C, Rr, false>(law) }
    }

    fn assemble_with<N: Normal, Dm: Damping, T: Tangential<D>, C: Cohesion, Rr: Rolling<D>, const E: bool>(self, law: ContactModel<N, Dm, T, C, Rr, D>) -> Result<Box<dyn Engine<D>>, Error> {
        let scene = self.scene;
        let rotation = T::FRICTION && scene.model.rotation;
        let has_walls = !self.walls.is_empty();
        let has_flat = self.walls.iter().any(Wall::is_flat);
        let gravity = scene.gravity.lift::<D>();
        // A stage that turns gravity on needs its stage from the start.
        let pulled = scene.strongest_gravity() > 0.0;
        let n_free = self.p.n_free;
        let wall_hist = self.walls.iter().map(|w| if w.is_flat() { vec![ContactHistory::default(); n_free] } else { Vec::new() }).collect();
        let wall_active = self.walls.iter().map(|w| vec![false; if w.is_flat() { n_free } else { 0 }]).collect();
        let world = World {
            p: self.p,
            boundary: self.boundary,
            law,
            pair_table: PairTable::new(&scene.materials, scene.model.beta_rule()),
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
            probe: Default::default(),
            domain: self.domain,
            context: self.context,
        };
        let plan = Plan {
            rotation,
            walls: has_walls,
            flat_walls: has_flat,
            gravity: pulled,
            general_damping: scene.model.general_damping,
            contacts: scene.output.contacts,
            threads: self.threads.clone(),
        };
        let (stages, setup) = pipeline::<N, Dm, T, C, Rr, D, E>(&plan);
        Ok(Box::new(Simulation::new(world, stages, setup)?))
    }
}

/// What a scene asks of the step's pipeline (the same in the plane and in space).
#[derive(Clone)]
pub struct Plan {
    /// The grains rotate (friction, and the scene's `model.rotation`).
    pub rotation: bool,
    /// The scene has walls.
    pub walls: bool,
    /// ... and one of them is flat.
    pub flat_walls: bool,
    /// Gravity is on at some time of the run.
    pub gravity: bool,
    /// The seed's general damping rate, 1/s.
    pub general_damping: Option<f64>,
    /// Record the contacts (`output.contacts`).
    pub contacts: bool,
    /// The threads the stages may use.
    pub threads: crate::kernels::threads::Threads,
}

/// The stages of a step and of the set-up at t = 0 (the force stages, then the walls'
/// forces) for contact model `ContactModel<N, Dm, T, C, Rr, D>` and the energy ledger
/// (`E`), in the order a step runs them: written once for the plane and space; what
/// differs between them is [`Pipeline`]'s.
#[allow(clippy::type_complexity)]
pub fn pipeline<N: Normal, Dm: Damping, T: Tangential<D>, C: Cohesion, Rr: Rolling<D>, D: Pipeline, const E: bool>(plan: &Plan) -> (Vec<Box<dyn Stage<ContactModel<N, Dm, T, C, Rr, D>>>>, Vec<Box<dyn Stage<ContactModel<N, Dm, T, C, Rr, D>>>>) {
    type Stages<N, Dm, T, C, Rr, D> = Vec<Box<dyn Stage<ContactModel<N, Dm, T, C, Rr, D>>>>;
    let rotation = plan.rotation;
    // The force stages, shared by the step and by the set-up at t = 0.
    let forces = || -> Stages<N, Dm, T, C, Rr, D> {
        let mut s: Stages<N, Dm, T, C, Rr, D> = vec![Box::new(UpdateNeighbours), Box::new(ClearForces)];
        if plan.gravity {
            s.push(Box::new(Gravity::<E>));
        }
        if let Some(c) = plan.general_damping {
            s.push(Box::new(GeneralDamping::<E, D>::new(c)));
        }
        if plan.contacts {
            s.extend(if rotation { D::record_stage::<N, Dm, T, C, Rr, true>() } else { D::record_stage::<N, Dm, T, C, Rr, false>() });
        }
        s.push(if rotation { D::pair_stage::<N, Dm, T, C, Rr, E, true>(&plan.threads) } else { D::pair_stage::<N, Dm, T, C, Rr, E, false>(&plan.threads) });
        if plan.flat_walls {
            s.push(Box::new(FlatWallForces::<E>));
        }
        s
    };
    let mut stages: Stages<N, Dm, T, C, Rr, D> = Vec::new();
    // The walls first: their grains follow them in the drift.
    if plan.walls {
        stages.push(Box::new(MoveWalls));
    }
    if rotation {
        stages.push(Box::new(InitialIntegrate::<true, D>::default()));
    } else {
        stages.push(Box::new(InitialIntegrate::<false, D>::default()));
    }
    stages.extend(forces());
    if plan.walls {
        stages.push(Box::new(FinishWalls::<E>));
    }
    if rotation {
        stages.push(Box::new(FinalIntegrate::<true>));
    } else {
        stages.push(Box::new(FinalIntegrate::<false>));
    }
    stages.push(Box::new(Watchdog { max_overlap: MAX_START_OVERLAP, every: 100 }));
    let mut setup = forces();
    if plan.walls {
        setup.push(Box::new(FinishWalls::<E>));
    }
    (stages, setup)
}

/// What the pipeline's stages differ by in the plane and in space: the grain-grain
/// contact stage (in the plane serial or on the run's threads, in space serial so far)
/// and the contact record (the plane's only so far: space refuses `output.contacts`).
pub trait Pipeline: Dim {
    fn pair_stage<N: Normal, Dm: Damping, T: Tangential<Self>, C: Cohesion, Rr: Rolling<Self>, const E: bool, const SPIN: bool>(threads: &crate::kernels::threads::Threads) -> Box<dyn Stage<ContactModel<N, Dm, T, C, Rr, Self>>>;
    fn record_stage<N: Normal, Dm: Damping, T: Tangential<Self>, C: Cohesion, Rr: Rolling<Self>, const SPIN: bool>() -> Option<Box<dyn Stage<ContactModel<N, Dm, T, C, Rr, Self>>>>;
}

impl Pipeline for Plane {
    fn pair_stage<N: Normal, Dm: Damping, T: Tangential, C: Cohesion, Rr: Rolling, const E: bool, const SPIN: bool>(threads: &crate::kernels::threads::Threads) -> Box<dyn Stage<ContactModel<N, Dm, T, C, Rr>>> {
        pair_stage::<N, Dm, T, C, Rr, E, SPIN>(threads)
    }
    fn record_stage<N: Normal, Dm: Damping, T: Tangential, C: Cohesion, Rr: Rolling, const SPIN: bool>() -> Option<Box<dyn Stage<ContactModel<N, Dm, T, C, Rr>>>> {
        Some(Box::new(RecordContacts::<SPIN>))
    }
}

impl Pipeline for Space {
    fn pair_stage<N: Normal, Dm: Damping, T: Tangential<Space>, C: Cohesion, Rr: Rolling<Space>, const E: bool, const SPIN: bool>(_: &crate::kernels::threads::Threads) -> Box<dyn Stage<ContactModel<N, Dm, T, C, Rr, Space>>> {
        Box::new(PairForces::<E, SPIN, Space>::default())
    }
    fn record_stage<N: Normal, Dm: Damping, T: Tangential<Space>, C: Cohesion, Rr: Rolling<Space>, const SPIN: bool>() -> Option<Box<dyn Stage<ContactModel<N, Dm, T, C, Rr, Space>>>> {
        None
    }
}

/// The grain-grain contact stage: serial, or on the run's pool of threads; with `SPIN` when
/// the grains rotate (without, the kernel neither reads spins nor computes torques).
fn pair_stage<N: Normal, Dm: Damping, T: Tangential, C: Cohesion, Rr: Rolling, const E: bool, const SPIN: bool>(threads: &crate::kernels::threads::Threads) -> Box<dyn Stage<ContactModel<N, Dm, T, C, Rr>>> {
    #[cfg(feature = "parallel")]
    if threads.count() > 1 {
        return Box::new(crate::engine::parallel::ParallelPairForces::<E, SPIN>::new(threads.clone()));
    }
    let _ = threads;
    Box::new(PairForces::<E, SPIN>::default())
}

