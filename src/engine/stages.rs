//! The step's stages: the [`Stage`] trait and every stage a scene may ask for, in the
//! order a step runs them (walls, neighbours, forces, the contact stages, walls'
//! forces, the watchdog); the drift and the kicks are [`crate::engine::integrate`]. A
//! scene without walls has no wall stages, without gravity no gravity stage, without
//! friction no spin update; `explain` prints the list. The contact stages hand the
//! World's slices to the kernels ([`crate::kernels::driver`]).

use crate::engine::world::{DimOf, World};
use crate::error::Error;
use crate::kernels::driver::{PairOut, PairSlices, PairView, compute_pairs, record_pair};
use crate::kernels::sweep::sort_pairs;
use crate::physics::contact::cohesion::Cohesion;
use crate::physics::contact::rolling::Rolling;
use crate::physics::contact::damping::Damping;
use crate::physics::contact::normal::Normal;
use crate::physics::contact::tangential::Tangential;
use crate::physics::contact::{ContactInput, ContactLaw, ContactModel, ContactRecord, Partner};
use crate::physics::dim::{Dim, Plane, Vec2};
use crate::physics::walls::{Control, Surface};

pub use crate::engine::world::Stage;

/// Move the walls: prescribed x velocity, and for a loaded wall the first half kick and
/// drift in y. Their glued grains follow in the drift that comes next
/// ([`crate::physics::walls::Glued`], in [`crate::engine::integrate::InitialIntegrate`]), on the thread that owns them.
pub struct MoveWalls;

impl<L: ContactLaw> Stage<L> for MoveWalls {
    fn name(&self) -> String {
        "MoveWalls".into()
    }
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error> {
        let dt = w.dt;
        for wall in &mut w.walls {
            if let Control::Load { .. } = wall.control {
                wall.v[1] += 0.5 * dt * (wall.force[1] + wall.load_y()) / wall.mass;
            }
            let d = wall.v * dt;
            wall.y += d[1];
            wall.x_shift += d[0];
        }
        Ok(())
    }
}

/// Rebuild the Verlet list when a grain has moved more than half the skin (the pairs'
/// energy sums go into the ledger first, in list order: the new list starts them at 0).
pub struct UpdateNeighbours;

impl<L: ContactLaw> Stage<L> for UpdateNeighbours {
    fn name(&self) -> String {
        "Neighbours".into()
    }
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error> {
        if w.neighbours.needs_rebuild(w.p.len()) {
            // Every grain inside the domain, none that jumped: checked here, where the
            // rebuild passes over all grains anyway.
            w.check_domain()?;
            let pairs = w.neighbours.build(&w.p.x, &w.p.r, w.p.n_free, &w.boundary, &w.threads);
            if w.pairs.keep_energy {
                w.ledger.add(&w.pairs.energy_sums());
                w.ledger.rolling += w.pairs.rolling_taken();
            }
            w.pairs.replace(pairs, &w.p.r, &w.p.m, &w.threads);
        }
        Ok(())
    }
}

/// Zero forces and torques (and start the step's stored-energy sums): those the drift
/// has not set to zero already ([`World::zeroed`]; in a step, the rough walls' grains).
pub struct ClearForces;

impl<L: ContactLaw> Stage<L> for ClearForces {
    fn name(&self) -> String {
        "ClearForces".into()
    }
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error> {
        let n = w.p.len();
        let z = std::mem::take(&mut w.zeroed);
        w.threads.split(n - z.forces, &mut w.p.f[z.forces..], |f| f.fill(DimOf::<L>::zero()));
        if L::Tang::FRICTION {
            w.threads.split(n - z.torques, &mut w.p.torque[z.torques..], |t| t.fill(DimOf::<L>::spin_zero()));
        }
        w.ledger.begin_step();
        w.max_overlap = (0.0, 0, 0);
        Ok(())
    }
}

/// Gravity on the free grains.
pub struct Gravity<const ENERGY: bool>;

impl<L: ContactLaw, const ENERGY: bool> Stage<L> for Gravity<ENERGY> {
    fn name(&self) -> String {
        "Gravity".into()
    }
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error> {
        let g = w.gravity;
        for i in 0..w.p.n_free {
            w.p.f[i] += g * w.p.m[i];
            if ENERGY {
                // Constant force: the work over the step is exact with the step's displacement.
                w.ledger.gravity += w.p.m[i] * DimOf::<L>::dot(g, w.p.v[i]) * w.dt;
            }
        }
        Ok(())
    }
}

/// The seed's general damping: `F = -c m v`, `M = -c I w` on every free grain, with the
/// half-step velocities the contact forces see. Its work is integrated by the trapezoid
/// rule like every other term of the balance.
pub struct GeneralDamping<const ENERGY: bool, D: Dim = Plane> {
    /// Rate c, 1/s.
    pub rate: f64,
    prev_f: Vec<D::Vector<f64>>,
    prev_m: Vec<D::Spin<f64>>,
}

impl<const ENERGY: bool, D: Dim> GeneralDamping<ENERGY, D> {
    pub fn new(rate: f64) -> Self {
        GeneralDamping { rate, prev_f: Vec::new(), prev_m: Vec::new() }
    }
}

impl<L: ContactLaw<D = D>, D: Dim, const ENERGY: bool> Stage<L> for GeneralDamping<ENERGY, D> {
    fn name(&self) -> String {
        format!("GeneralDamping(c = {} 1/s)", self.rate)
    }
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error> {
        let c = self.rate;
        let n = w.p.n_free;
        // The first call has no previous force: take this one (the set-up stages, run
        // with dt = 0 before the first step, are a separate instance).
        let first = ENERGY && self.prev_f.len() != n;
        if first {
            self.prev_f = vec![D::zero(); n];
            self.prev_m = vec![D::spin_zero(); n];
        }
        for i in 0..n {
            let f = w.p.v[i] * (-c * w.p.m[i]);
            let m = w.p.omega[i] * (-c * w.p.inertia[i]);
            if first {
                self.prev_f[i] = f;
                self.prev_m[i] = m;
            }
            w.p.f[i] += f;
            w.p.torque[i] = w.p.torque[i] + m;
            if ENERGY {
                w.ledger.general_damping -= 0.5 * (D::dot(self.prev_f[i] + f, w.p.v[i]) + D::spin_dot(self.prev_m[i] + m, w.p.omega[i])) * w.dt;
                self.prev_f[i] = f;
                self.prev_m[i] = m;
            }
        }
        Ok(())
    }
    /// The previous step's damping forces and torques (for the trapezoid rule): the
    /// force's components, then the torque's, of each grain (x, y and the torque in the
    /// plane).
    fn carried(&self) -> Vec<f64> {
        let (f, m) = (D::flat(&self.prev_f), D::spin_flat(&self.prev_m));
        f.chunks_exact(D::D).zip(m.chunks_exact(D::SPIN)).flat_map(|(f, m)| f.iter().chain(m).copied()).collect()
    }
    fn restore(&mut self, carried: &[f64]) -> Result<(), String> {
        let per = D::D + D::SPIN;
        if !carried.len().is_multiple_of(per) {
            return Err(format!("{}: {} numbers, not {per} per grain", <Self as Stage<L>>::name(self), carried.len()));
        }
        let n = carried.len() / per;
        self.prev_f = vec![D::zero(); n];
        self.prev_m = vec![D::spin_zero(); n];
        let (f, m) = (D::flat_mut(&mut self.prev_f), D::spin_flat_mut(&mut self.prev_m));
        for ((c, f), m) in carried.chunks_exact(per).zip(f.chunks_exact_mut(D::D)).zip(m.chunks_exact_mut(D::SPIN)) {
            f.copy_from_slice(&c[..D::D]);
            m.copy_from_slice(&c[D::D..]);
        }
        Ok(())
    }
}

/// Grain-grain contacts over the Verlet list, in two passes: a branch-free sweep sorts
/// out the pairs that are touching (and those just released), then the kernel runs on
/// those only, four at a time in SIMD lanes. Most listed pairs are not touching (the
/// skin): the sweep spares them the kernel. `SPIN`: the grains rotate (the pairs' torques
/// are computed and collected).
#[derive(Default)]
pub struct PairForces<const ENERGY: bool, const SPIN: bool, D: Dim = Plane> {
    touching: Vec<u32>,
    sep: Vec<D::Vector<f64>>,
    released: Vec<u32>,
}

impl<N: Normal, Dm: Damping, T: Tangential<D>, C: Cohesion, Rr: Rolling<D>, D: Dim, const ENERGY: bool, const SPIN: bool> Stage<ContactModel<N, Dm, T, C, Rr, D>> for PairForces<ENERGY, SPIN, D> {
    fn name(&self) -> String {
        "PairContacts".into()
    }
    fn run(&mut self, w: &mut World<ContactModel<N, Dm, T, C, Rr, D>>) -> Result<(), Error> {
        let mut worst = w.max_overlap;
        let mut f = std::mem::take(&mut w.p.f);
        let mut torque = std::mem::take(&mut w.p.torque);
        let (pairs, consts) = (w.pairs.pairs.checked(), &w.pairs.consts);
        let (nt, nr) = sort_pairs(&w.p.x, &w.boundary, pairs, &w.pairs.reach, &w.pairs.active, &[], &mut self.touching, &mut self.sep, &mut self.released);
        let (touching, sep, released) = (&self.touching[..nt], &self.sep[..nt], &self.released[..nr]);
        let view = PairView { p: &w.p, boundary: w.boundary, law: w.law, pair_table: &w.pair_table, dt: w.dt };
        let list = PairSlices::<T, Rr, D> { pairs, consts, hist: &mut w.pairs.hist, energy: &mut w.pairs.energy, active: &mut w.pairs.active };
        // Each pair's force goes to its grains as it comes, in list order.
        let n = f.len();
        let (fs, ts) = (&mut f[..n], &mut torque[..n]);
        let sink = |_, (i, j): (usize, usize), o: PairOut<D>| {
            fs[i] += o.force;
            fs[j] -= o.force;
            if T::FRICTION && SPIN {
                ts[i] = ts[i] - o.torque[0];
                ts[j] = ts[j] - o.torque[1];
            }
        };
        let (ratio, k) = compute_pairs::<N, Dm, T, C, Rr, D, ENERGY, SPIN>(&view, list, touching, sep, released, sink);
        if ratio > worst.0 {
            let [i, j] = pairs.pairs()[k];
            worst = (ratio, i as usize, j as usize);
        }
        w.p.f = f;
        w.p.torque = torque;
        w.max_overlap = worst;
        Ok(())
    }
}

/// The contact input of free grain `i` touching flat `wall` (normal `n` into the grain,
/// overlap `dn`): R* = r, m* = m. Shared by the wall contact stage and the record of it.
/// In space the contact turns about its normal with the grain's spin (YADE's twist).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn wall_input<D: Dim, T: Tangential<D>, Rr: Rolling<D>>(lever: crate::physics::contact::LeverArm, p: &crate::physics::particles::Particles<D>, i: usize, wall: &crate::physics::walls::Wall<D>, n: D::Vector<f64>, dn: f64, dt: f64) -> ContactInput<f64, D> {
    let ri = p.r[i];
    let spin = if T::FRICTION { p.omega[i] * lever.wall_arm(ri, dn) } else { D::spin_zero() };
    let (roll, roll_scale) = if Rr::ON { (p.omega[i], lever.wall_rolling(ri, dn)) } else { (D::spin_zero(), 1.0) };
    let twist = D::twist(if T::FRICTION { p.omega[i] } else { D::spin_zero() });
    ContactInput { n, dn, r_star: ri, sqrt_m_star: p.m[i].sqrt(), v_rel: p.v[i] - wall.v, spin, dt, tangential_scale: 1.0, roll, roll_scale, twist }
}

/// The unit normal of a wall on side `side` (+1 bottom, -1 top) into the grains: along y.
#[inline(always)]
fn wall_normal<D: Dim>(side: f64) -> D::Vector<f64> {
    let mut n = D::zero();
    n[1] = side;
    n
}

/// Record every touching contact of this step, grain-grain and grain-flat wall, as the
/// contact stages that follow will compute it, when the run wants it (`w.probe.wanted`):
/// the same contact law on the same inputs, on copies of the tangential states. Placed
/// right before the grain-grain contact stage; in the pipeline only when the scene's
/// `output.contacts` asks, and at the other steps a flag test.
pub struct RecordContacts<const SPIN: bool>;

impl<N: Normal, Dm: Damping, T: Tangential, C: Cohesion, Rr: Rolling, const SPIN: bool> Stage<ContactModel<N, Dm, T, C, Rr, Plane>> for RecordContacts<SPIN> {
    fn name(&self) -> String {
        "RecordContacts".into()
    }
    fn run(&mut self, w: &mut World<ContactModel<N, Dm, T, C, Rr>>) -> Result<(), Error> {
        if !w.probe.wanted {
            return Ok(());
        }
        let mut out = std::mem::take(&mut w.probe.contacts);
        out.clear();
        let pr = &mut w.probe;
        pr.x.clone_from(&w.p.x);
        pr.v.clone_from(&w.p.v);
        pr.omega.clone_from(&w.p.omega);
        pr.walls = w.walls.iter().map(|wall| (wall.contact_surface(), wall.v)).collect();
        let view = PairView { p: &w.p, boundary: w.boundary, law: w.law, pair_table: &w.pair_table, dt: w.dt };
        for (k, &[i, j]) in w.pairs.pairs.checked().pairs().iter().enumerate() {
            if let Some(c) = record_pair::<N, Dm, T, C, Rr, SPIN>(&view, (i as usize, j as usize), &w.pairs.consts[k], &w.pairs.hist[k]) {
                out.push(c);
            }
        }
        let (model, p) = (w.law, &w.p);
        let lever = model.options.lever_arm;
        for (k, wall) in w.walls.iter().enumerate() {
            if !wall.is_flat() {
                continue;
            }
            let n = Vec2::new(0.0, wall.side);
            for i in 0..p.n_free {
                let gap = wall.side * (p.x[i].y - wall.y);
                let ri = p.r[i];
                if gap >= ri {
                    continue;
                }
                // As FlatWallForces computes it, on a copy of the history.
                let dn = ri - gap;
                let input = wall_input::<Plane, T, Rr>(lever, p, i, wall, n, dn, w.dt);
                let pm = w.pair_table.get(p.material[i] as usize, wall.material);
                let mut h = w.wall_hist[k][i].state;
                let c = model.force(&input, pm, &mut h);
                out.push(ContactRecord {
                    i: i as u32,
                    partner: Partner::Wall(k as u32),
                    normal: n,
                    overlap: dn,
                    branch: n * gap,
                    point: p.x[i] - n * gap,
                    normal_force: c.normal,
                    tangential_force: c.tangential.elastic + c.tangential.damping,
                    tangential_elastic: c.tangential.elastic,
                    sliding: c.tangential.slip_energy > 0.0,
                });
            }
        }
        (w.probe.wanted, w.probe.contacts, w.probe.step) = (false, out, w.step);
        Ok(())
    }
}

/// Contacts of free grains with flat walls (R* = r, m* = m).
pub struct FlatWallForces<const ENERGY: bool>;

impl<N: Normal, Dm: Damping, T: Tangential<D>, C: Cohesion, Rr: Rolling<D>, D: Dim, const ENERGY: bool> Stage<ContactModel<N, Dm, T, C, Rr, D>> for FlatWallForces<ENERGY> {
    fn name(&self) -> String {
        "FlatWallContacts".into()
    }
    fn run(&mut self, w: &mut World<ContactModel<N, Dm, T, C, Rr, D>>) -> Result<(), Error> {
        let model = w.law;
        let lever = model.options.lever_arm;
        let dt = w.dt;
        let p = &mut w.p;
        let mut worst = w.max_overlap;
        for (k, wall) in w.walls.iter_mut().enumerate() {
            if !wall.is_flat() {
                continue;
            }
            let (hist, active) = (&mut w.wall_hist[k], &mut w.wall_active[k]);
            let n = wall_normal::<D>(wall.side);
            let mut on_wall = D::zero();
            for i in 0..p.n_free {
                let h = &mut hist[i];
                let gap = wall.side * (p.x[i][1] - wall.y);
                let ri = p.r[i];
                if gap >= ri {
                    if active[i] {
                        let spin = if T::FRICTION { p.omega[i] * ri } else { D::spin_zero() };
                        let vc = p.v[i] - wall.v + D::cross_spin(n, spin);
                        model.release::<ENERGY>(vc, n, p.omega[i], dt, &mut h.state, &mut h.energy);
                        if ENERGY {
                            w.ledger.add(&std::mem::take(&mut h.energy.sums));
                        }
                        active[i] = false;
                    }
                    continue;
                }
                let dn = ri - gap;
                let input = wall_input::<D, T, Rr>(lever, p, i, wall, n, dn, dt);
                let pm = w.pair_table.get(p.material[i] as usize, wall.material);
                let c = model.touch::<ENERGY>(&input, pm, h, &mut w.ledger);
                active[i] = true;
                p.f[i] += c.force;
                on_wall -= c.force;
                if T::FRICTION {
                    p.torque[i] = p.torque[i] - D::cross(n, c.tangential) * lever.wall_torque_arm(ri, dn);
                }
                if Rr::ON {
                    p.torque[i] = p.torque[i] + c.rolling;
                }
                if dn / ri > worst.0 {
                    worst = (dn / ri, i, usize::MAX - k);
                }
            }
            wall.force = on_wall;
        }
        w.max_overlap = worst;
        Ok(())
    }
}

/// Sum the force on rough walls, account for the walls' work, and give a loaded wall
/// its second half kick.
pub struct FinishWalls<const ENERGY: bool>;

impl<L: ContactLaw, const ENERGY: bool> Stage<L> for FinishWalls<ENERGY> {
    fn name(&self) -> String {
        "WallForces".into()
    }
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error> {
        let dt = w.dt;
        for wall in &mut w.walls {
            if let Surface::Rough { grains } = &wall.surface {
                wall.force = grains.clone().fold(DimOf::<L>::zero(), |sum, k| sum + w.p.f[k]);
            }
            if ENERGY {
                // Work of the wall's prescribed motion on the grains over this step
                // (trapezoid); a loaded wall's y motion is its own dynamics, and the load
                // does the work there.
                let d = wall.v * dt;
                let f = (wall.force_prev + wall.force) * 0.5;
                match wall.control {
                    Control::Fixed => w.ledger.walls -= DimOf::<L>::dot(f, d),
                    Control::Load { .. } => {
                        // The prescribed motion: along x (and in space z).
                        let mut drive = f[0] * d[0];
                        if DimOf::<L>::D == 3 {
                            drive += f[2] * d[2];
                        }
                        w.ledger.walls -= drive;
                        w.ledger.load += wall.load_y() * d[1];
                    }
                }
            }
            wall.force_prev = wall.force;
            if let Control::Load { .. } = wall.control {
                wall.v[1] += 0.5 * dt * (wall.force[1] + wall.load_y()) / wall.mass;
            }
        }
        Ok(())
    }
}

/// Stop a run that has gone wrong, with a diagnosis.
pub struct Watchdog {
    /// Largest overlap allowed, as a fraction of the smaller radius.
    pub max_overlap: f64,
    /// Check for non-finite state every this many steps.
    pub every: u64,
}

impl<L: ContactLaw> Stage<L> for Watchdog {
    fn name(&self) -> String {
        format!("Watchdog(overlap < {} r)", self.max_overlap)
    }
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error> {
        let (ratio, i, j) = w.max_overlap;
        if ratio > self.max_overlap {
            let what = if j > w.p.len() {
                format!("grain {i} overlaps the {} wall by {:.3} of its radius (bound {})", w.walls[usize::MAX - j].name, ratio, self.max_overlap)
            } else {
                format!("grains {i} and {j} overlap by {:.3} of the smaller radius (bound {})", ratio, self.max_overlap)
            };
            return Err(w.unstable_at(what, Some(i)));
        }
        if w.step.is_multiple_of(self.every) {
            // The velocities as they are at the end of the step.
            crate::engine::integrate::settle(w);
            w.check_finite()?;
        }
        Ok(())
    }
}
