//! The step pipeline: the stages a scene asks for, in order, and nothing else.
//!
//! A scene without walls has no wall stages, without gravity no gravity stage, without
//! friction no spin update, without periodicity no wrap; `explain` prints the list.

use crate::contact::{ContactInput, ContactLaw, ContactModel};
use crate::contact::damping::Damping;
use crate::contact::tangential::Tangential;
use crate::dim::{Vec2, cross};
use crate::error::Error;
use crate::sim::World;
use crate::walls::{Control, Surface};

/// One stage of a time step.
pub trait Stage<L: ContactLaw>: Send {
    fn name(&self) -> String;
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error>;
}

/// Move the walls: prescribed x velocity, and for a loaded wall the first half kick and
/// drift in y; glued grains follow their wall.
pub struct MoveWalls;

impl<L: ContactLaw> Stage<L> for MoveWalls {
    fn name(&self) -> String {
        "MoveWalls".into()
    }
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error> {
        let dt = w.dt;
        for wall in &mut w.walls {
            if let Control::Load { .. } = wall.control {
                wall.v.y += 0.5 * dt * (wall.force.y + wall.load_y()) / wall.mass;
            }
            let d = wall.v * dt;
            wall.y += d.y;
            wall.x_shift += d.x;
            if let Surface::Rough { grains } = &wall.surface {
                for k in grains.clone() {
                    w.p.x[k] += d;
                    w.p.v[k] = wall.v;
                }
            }
        }
        Ok(())
    }
}

/// Bring grains that left the periodic cell back in.
pub struct PeriodicWrap;

impl<L: ContactLaw> Stage<L> for PeriodicWrap {
    fn name(&self) -> String {
        "PeriodicX".into()
    }
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error> {
        let b = w.boundary;
        for x in &mut w.p.x {
            b.wrap(x);
        }
        Ok(())
    }
}

/// Rebuild the Verlet list when a grain has moved more than half the skin.
pub struct UpdateNeighbours;

impl<L: ContactLaw> Stage<L> for UpdateNeighbours {
    fn name(&self) -> String {
        "Neighbours".into()
    }
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error> {
        if w.neighbours.needs_rebuild(&w.p.x, &w.boundary) {
            let pairs = w.neighbours.build(&w.p.x, &w.p.r, w.p.n_free, &w.boundary);
            w.pairs.replace(pairs, &w.p.r, &w.p.m);
        }
        Ok(())
    }
}

/// Zero forces and torques (and start the step's stored-energy sums).
pub struct ClearForces;

impl<L: ContactLaw> Stage<L> for ClearForces {
    fn name(&self) -> String {
        "ClearForces".into()
    }
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error> {
        w.p.f.iter_mut().for_each(|f| *f = Vec2::zeros());
        if L::Tang::FRICTION {
            w.p.torque.iter_mut().for_each(|t| *t = 0.0);
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
            w.p.f[i] += w.p.m[i] * g;
            if ENERGY {
                // Constant force: the work over the step is exact with the step's displacement.
                w.ledger.gravity += w.p.m[i] * g.dot(&w.p.v[i]) * w.dt;
            }
        }
        Ok(())
    }
}

/// The seed's general damping: `F = -c m v`, `M = -c I w` on every free grain, with the
/// half-step velocities the contact forces see. Its work is integrated by the trapezoid
/// rule like every other term of the balance.
pub struct GeneralDamping<const ENERGY: bool> {
    /// Rate c, 1/s.
    pub rate: f64,
    prev_f: Vec<Vec2>,
    prev_m: Vec<f64>,
}

impl<const ENERGY: bool> GeneralDamping<ENERGY> {
    pub fn new(rate: f64) -> Self {
        GeneralDamping { rate, prev_f: Vec::new(), prev_m: Vec::new() }
    }
}

impl<L: ContactLaw, const ENERGY: bool> Stage<L> for GeneralDamping<ENERGY> {
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
            self.prev_f = vec![Vec2::zeros(); n];
            self.prev_m = vec![0.0; n];
        }
        for i in 0..n {
            let f = -c * w.p.m[i] * w.p.v[i];
            let m = -c * w.p.inertia[i] * w.p.omega[i];
            if first {
                self.prev_f[i] = f;
                self.prev_m[i] = m;
            }
            w.p.f[i] += f;
            w.p.torque[i] += m;
            if ENERGY {
                w.ledger.general_damping -= 0.5 * ((self.prev_f[i] + f).dot(&w.p.v[i]) + (self.prev_m[i] + m) * w.p.omega[i]) * w.dt;
                self.prev_f[i] = f;
                self.prev_m[i] = m;
            }
        }
        Ok(())
    }
}

/// What one grain-grain pair did this step, for the grains to collect.
#[derive(Clone, Copy, Debug, Default)]
pub struct PairOut {
    /// Force on the first grain (the second gets the opposite), N.
    pub force: Vec2,
    /// Torques to subtract from the first and the second grain, N m.
    pub torque: [f64; 2],
    /// Overlap over the smaller radius (0 when not touching).
    pub ratio: f64,
}

/// One pair of the Verlet list: the contact force (touching), the end of a contact
/// (released), or nothing; history and energy terms updated. Shared by the serial and
/// the parallel stage, so that both compute the same bits.
#[inline(always)]
pub fn pair_contact<Dm: Damping, T: Tangential, const ENERGY: bool>(
    w: &PairView<'_, ContactModel<Dm, T>>,
    pair: [u32; 2],
    pc: &crate::neighbor::PairConst,
    h: &mut crate::sim::Hist<ContactModel<Dm, T>>,
    ledger: &mut crate::observe::energy::EnergyLedger,
) -> PairOut {
    let model = w.law;
    let lever = model.options.lever_arm;
    let p = w.p;
    let (i, j) = (pair[0] as usize, pair[1] as usize);
    let d = w.boundary.image(p.x[i] - p.x[j]);
    let rsq = d.norm_squared();
    let (ri, rj) = (p.r[i], p.r[j]);
    let radsum = ri + rj;
    if rsq >= radsum * radsum {
        if h.active {
            let n = d / rsq.sqrt();
            let spin = if T::FRICTION { ri * p.omega[i] + rj * p.omega[j] } else { 0.0 };
            let vc = p.v[i] - p.v[j] + spin * Vec2::new(n.y, -n.x);
            model.release::<ENERGY>(vc, n, w.dt, h, ledger);
        }
        return PairOut::default();
    }
    let r = rsq.sqrt();
    let n = d / r;
    let dn = radsum - r;
    let (ai, aj) = if T::FRICTION { (lever.arm(ri, dn), lever.arm(rj, dn)) } else { (0.0, 0.0) };
    let spin = if T::FRICTION { ai * p.omega[i] + aj * p.omega[j] } else { 0.0 };
    let tangential_scale = if T::FRICTION { lever.translation_scale(radsum, dn) } else { 1.0 };
    let input = ContactInput { n, dn, r_star: pc.r_star, m_star: pc.m_star, v_rel: p.v[i] - p.v[j], spin, dt: w.dt, tangential_scale };
    let pm = w.pair_table.get(p.material[i] as usize, p.material[j] as usize);
    let c = model.touch::<ENERGY>(&input, pm, h, ledger);
    let torque = if T::FRICTION {
        let t = cross(n, c.tangential);
        [lever.torque_arm(ri, dn) * t, lever.torque_arm(rj, dn) * t]
    } else {
        [0.0, 0.0]
    };
    PairOut { force: c.force, torque, ratio: dn * pc.inv_r_min }
}

/// What the pair kernel reads: everything but the forces it produces.
pub struct PairView<'a, L: ContactLaw> {
    pub p: &'a crate::particles::Particles,
    pub boundary: crate::boundary::Boundary,
    pub law: L,
    pub pair_table: &'a crate::material::PairTable,
    pub dt: f64,
}

/// Grain-grain contacts over the Verlet list, in two passes: a branch-free sweep picks
/// the pairs that need the kernel (touching now, or touching at the previous step), then
/// the kernel runs over those only, in list order. Most listed pairs are not touching
/// (the skin): the sweep spares them the kernel's mispredicted branch.
#[derive(Default)]
pub struct PairForces<const ENERGY: bool> {
    /// Indices into the pair list of the pairs this step works on.
    work: Vec<u32>,
}

/// The pairs of `pairs[range]` that are touching or were touching at the previous step,
/// as indices into `pairs`, appended to `work` in list order. No branch per pair.
#[inline(never)]
pub fn pairs_in_contact<H>(p: &crate::particles::Particles, boundary: &crate::boundary::Boundary, pairs: &[[u32; 2]], hist: &[crate::contact::ContactHistory<H>], range: std::ops::Range<usize>, work: &mut Vec<u32>) {
    let start = work.len();
    work.resize(start + range.len(), 0);
    let mut count = start;
    for k in range {
        let pair = pairs[k];
        let (i, j) = (pair[0] as usize, pair[1] as usize);
        let d = boundary.image(p.x[i] - p.x[j]);
        let radsum = p.r[i] + p.r[j];
        let keep = (d.norm_squared() < radsum * radsum) | hist[k].active;
        work[count] = k as u32;
        count += keep as usize;
    }
    work.truncate(count);
}

impl<Dm: Damping, T: Tangential, const ENERGY: bool> Stage<ContactModel<Dm, T>> for PairForces<ENERGY> {
    fn name(&self) -> String {
        "PairContacts".into()
    }
    fn run(&mut self, w: &mut World<ContactModel<Dm, T>>) -> Result<(), Error> {
        let mut worst = w.max_overlap;
        let mut f = std::mem::take(&mut w.p.f);
        let mut torque = std::mem::take(&mut w.p.torque);
        let pairs = &w.pairs.pairs;
        self.work.clear();
        pairs_in_contact(&w.p, &w.boundary, pairs, &w.pairs.hist, 0..pairs.len(), &mut self.work);
        {
            let view = PairView { p: &w.p, boundary: w.boundary, law: w.law, pair_table: &w.pair_table, dt: w.dt };
            let (consts, hist) = (&w.pairs.consts, &mut w.pairs.hist);
            for &k in &self.work {
                let (pair, k) = (pairs[k as usize], k as usize);
                let o = pair_contact::<Dm, T, ENERGY>(&view, pair, &consts[k], &mut hist[k], &mut w.ledger);
                if o.ratio > 0.0 {
                    let (i, j) = (pair[0] as usize, pair[1] as usize);
                    f[i] += o.force;
                    f[j] -= o.force;
                    if T::FRICTION {
                        torque[i] -= o.torque[0];
                        torque[j] -= o.torque[1];
                    }
                    if o.ratio > worst.0 {
                        worst = (o.ratio, i, j);
                    }
                }
            }
        }
        w.p.f = f;
        w.p.torque = torque;
        w.max_overlap = worst;
        Ok(())
    }
}

/// Contacts of free grains with flat walls (R* = r, m* = m).
pub struct FlatWallForces<const ENERGY: bool>;

impl<Dm: Damping, T: Tangential, const ENERGY: bool> Stage<ContactModel<Dm, T>> for FlatWallForces<ENERGY> {
    fn name(&self) -> String {
        "FlatWallContacts".into()
    }
    fn run(&mut self, w: &mut World<ContactModel<Dm, T>>) -> Result<(), Error> {
        let model = w.law;
        let lever = model.options.lever_arm;
        let dt = w.dt;
        let p = &mut w.p;
        let mut worst = w.max_overlap;
        for (k, wall) in w.walls.iter_mut().enumerate() {
            if !wall.is_flat() {
                continue;
            }
            let hist = &mut w.wall_hist[k];
            let n = Vec2::new(0.0, wall.side);
            let mut on_wall = Vec2::zeros();
            for i in 0..p.n_free {
                let h = &mut hist[i];
                let gap = wall.side * (p.x[i].y - wall.y);
                let ri = p.r[i];
                if gap >= ri {
                    if h.active {
                        let spin = if T::FRICTION { ri * p.omega[i] } else { 0.0 };
                        let vc = p.v[i] - wall.v + spin * Vec2::new(n.y, -n.x);
                        model.release::<ENERGY>(vc, n, dt, h, &mut w.ledger);
                    }
                    continue;
                }
                let dn = ri - gap;
                let ai = if T::FRICTION { lever.arm(ri, dn) } else { 0.0 };
                let spin = if T::FRICTION { ai * p.omega[i] } else { 0.0 };
                let input = ContactInput { n, dn, r_star: ri, m_star: p.m[i], v_rel: p.v[i] - wall.v, spin, dt, tangential_scale: 1.0 };
                let pm = w.pair_table.get(p.material[i] as usize, w.wall_material);
                let c = model.touch::<ENERGY>(&input, pm, h, &mut w.ledger);
                p.f[i] += c.force;
                on_wall -= c.force;
                if T::FRICTION {
                    p.torque[i] -= lever.wall_torque_arm(ri, dn) * cross(n, c.tangential);
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
                wall.force = grains.clone().map(|k| w.p.f[k]).sum();
            }
            if ENERGY {
                // Work of the wall's prescribed motion on the grains over this step
                // (trapezoid); a loaded wall's y motion is its own dynamics, and the load
                // does the work there.
                let d = wall.v * dt;
                let f = 0.5 * (wall.force_prev + wall.force);
                match wall.control {
                    Control::Fixed => w.ledger.walls -= f.dot(&d),
                    Control::Load { .. } => {
                        w.ledger.walls -= f.x * d.x;
                        w.ledger.load += wall.load_y() * d.y;
                    }
                }
            }
            wall.force_prev = wall.force;
            if let Control::Load { .. } = wall.control {
                wall.v.y += 0.5 * dt * (wall.force.y + wall.load_y()) / wall.mass;
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
                format!("grain {i} overlaps wall {} by {:.3} of its radius (bound {})", w.walls[usize::MAX - j].name, ratio, self.max_overlap)
            } else {
                format!("grains {i} and {j} overlap by {:.3} of the smaller radius (bound {})", ratio, self.max_overlap)
            };
            return Err(w.unstable(what));
        }
        if w.step % self.every == 0 {
            w.check_finite()?;
        }
        Ok(())
    }
}
