//! The step pipeline: the stages a scene asks for, in order, and nothing else.
//!
//! A scene without walls has no wall stages, without gravity no gravity stage, without
//! friction no spin update; `explain` prints the list. (The periodic wrap rides along
//! the drift, [`crate::integrate::InitialIntegrate`], and costs a branch without
//! periodicity.)

use nalgebra::Vector2;
use simba::simd::{SimdBool, SimdPartialOrd, SimdValue};

use crate::boundary::Boundary;
use crate::contact::damping::Damping;
use crate::contact::tangential::Tangential;
use crate::contact::{ContactInput, ContactLaw, ContactModel, EnergyMemory, EnergyTerms, LeverArm};
use crate::dim::{Vec2, cross};
use crate::lanes::{LANES, Lanes, Real, gather, gather2, lane2};
use crate::material::PairMaterial;
use crate::neighbor::{CheckedPairs, PairConst};
use crate::observe::energy::EnergyLedger;
use crate::particles::Particles;
use crate::error::Error;
use crate::sim::World;
use crate::walls::{Control, Surface};

/// One stage of a time step.
pub trait Stage<L: ContactLaw>: Send {
    fn name(&self) -> String;
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error>;
}

/// Move the walls: prescribed x velocity, and for a loaded wall the first half kick and
/// drift in y. Their glued grains follow in the drift that comes next
/// ([`crate::walls::Glued`], in [`crate::integrate::InitialIntegrate`]), on the thread that owns them.
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
        if w.neighbours.needs_rebuild(w.p.len()) {
            // Every grain inside the domain, none that jumped: checked here, where the
            // rebuild passes over all grains anyway.
            w.check_domain()?;
            let pairs = w.neighbours.build(&w.p.x, &w.p.r, w.p.n_free, &w.boundary, &w.threads);
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
        w.threads.split(n - z.forces, &mut w.p.f[z.forces..], |f| f.fill(Vec2::zeros()));
        if L::Tang::FRICTION {
            w.threads.split(n - z.torques, &mut w.p.torque[z.torques..], |t| t.fill(0.0));
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

/// The contact input of touching pairs (one, or one per lane) from their separation
/// `d` (minimum image, i minus j), radii, spins (unread without `SPIN`: the grains do not
/// rotate), relative velocity and constants.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn pair_input<R: Real, T: Tangential, const SPIN: bool>(lever: LeverArm, d: Vector2<R>, ri: R, rj: R, wi: R, wj: R, v_rel: Vector2<R>, r_star: R, sqrt_m_star: R, dt: R) -> ContactInput<R> {
    let radsum = ri + rj;
    let r = d.norm_squared().simd_sqrt();
    let n = d * r.simd_recip();
    let dn = radsum - r;
    let spin = if T::FRICTION && SPIN { lever.arm(ri, dn) * wi + lever.arm(rj, dn) * wj } else { R::zero() };
    let tangential_scale = if T::FRICTION { lever.translation_scale(radsum, dn) } else { R::one() };
    ContactInput { n, dn, r_star, sqrt_m_star, v_rel, spin, dt, tangential_scale }
}

/// The torques `-a n x Ft` to subtract from grains i and j.
#[inline(always)]
fn pair_torque<R: Real>(lever: LeverArm, c: &ContactInput<R>, ft: Vector2<R>, ri: R, rj: R) -> [R; 2] {
    let t = cross(c.n, ft);
    [lever.torque_arm(ri, c.dn) * t, lever.torque_arm(rj, c.dn) * t]
}

/// One pair of the Verlet list: the contact force (touching), the end of a contact
/// (released), or nothing; tangential state `h`, energy memory `e` (with `ENERGY`) and
/// energy terms updated.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn pair_contact<Dm: Damping, T: Tangential, const ENERGY: bool>(
    w: &PairView<'_, ContactModel<Dm, T>>,
    pair: [u32; 2],
    pc: &PairConst,
    h: &mut T::History<f64>,
    e: &mut EnergyMemory,
    active: &mut bool,
    ledger: &mut EnergyLedger,
) -> PairOut {
    let model = w.law;
    let p = w.p;
    let (i, j) = (pair[0] as usize, pair[1] as usize);
    let d = w.boundary.image(p.x[i] - p.x[j]);
    let rsq = d.norm_squared();
    let (ri, rj) = (p.r[i], p.r[j]);
    let radsum = ri + rj;
    if rsq >= radsum * radsum {
        if *active {
            let n = d / rsq.sqrt();
            let spin = if T::FRICTION { ri * p.omega[i] + rj * p.omega[j] } else { 0.0 };
            let vc = p.v[i] - p.v[j] + spin * Vec2::new(n.y, -n.x);
            model.release::<ENERGY>(vc, n, w.dt, h, e, ledger);
            *active = false;
        }
        return PairOut::default();
    }
    let (o, pend) = one_pair::<Dm, T, true>(w, (i, j), d, pc, h, active);
    if ENERGY {
        model.account(pend.n, pend.dn, w.dt, &pend.state, e, ledger);
    }
    o
}

/// Four touching pairs at once, one per SIMD lane (`ks`: their indices in the list, `ds`
/// their separations): the same bits as [`one_pair`] gives each of them, handed to
/// `sink` (index in the part, grains, output) in lane order; with `ENERGY`, their energy
/// terms (also in lanes, their energy memories moved on) go to `pending`. Without `SPIN`
/// (grains that do not rotate) the spins are not read and the torques not computed.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn four_pairs<Dm: Damping, T: Tangential, const ENERGY: bool, const SPIN: bool>(
    w: &PairView<'_, ContactModel<Dm, T>>,
    list: PairSlices<'_, T>,
    single: Option<&PairMaterial<Lanes>>,
    ks: &[u32],
    ds: &[Vec2],
    sink: &mut impl FnMut(usize, (usize, usize), PairOut),
    pending: &mut [EnergyTerms],
    best: &mut (f64, usize),
) {
    let (model, p) = (w.law, w.p);
    let lever = model.options.lever_arm;
    // The per-pair slices cut to one length, so that one bounds check per index serves
    // them all; the per-grain arrays are read through the checked list, with none.
    let np = list.pairs.len();
    let (pairs, consts, hist, active) = (list.pairs.pairs(), &list.consts[..np], &mut list.hist[..np], &mut list.active[..np]);
    let (v, r, omega) = (list.pairs.of(&p.v), list.pairs.of(&p.r), list.pairs.of(&p.omega));
    let ks: [usize; LANES] = std::array::from_fn(|l| ks[l] as usize);
    let ij: [(usize, usize); LANES] = std::array::from_fn(|l| {
        let q = pairs[ks[l]];
        (q[0] as usize, q[1] as usize)
    });
    let pc: [&PairConst; LANES] = std::array::from_fn(|l| &consts[ks[l]]);
    let d = gather2(|l| ds[l]);
    let rs: [(f64, f64); LANES] = std::array::from_fn(|l| r.at(ks[l]));
    let (ri, rj) = (gather(|l| rs[l].0), gather(|l| rs[l].1));
    let (wi, wj) = if T::FRICTION && SPIN {
        let ws: [(f64, f64); LANES] = std::array::from_fn(|l| omega.at(ks[l]));
        (gather(|l| ws[l].0), gather(|l| ws[l].1))
    } else {
        (Lanes::splat(0.0), Lanes::splat(0.0))
    };
    let v_rel = gather2(|l| {
        let (vi, vj) = v.at(ks[l]);
        vi - vj
    });
    let input = pair_input::<Lanes, T, SPIN>(lever, d, ri, rj, wi, wj, v_rel, gather(|l| pc[l].r_star), gather(|l| pc[l].sqrt_m_star), Lanes::splat(w.dt));
    let pm = match single {
        Some(pm) => *pm,
        None => {
            let mat = list.pairs.of(&p.material);
            PairMaterial::gather(std::array::from_fn(|l| {
                let (mi, mj) = mat.at(ks[l]);
                w.pair_table.get(mi as usize, mj as usize)
            }))
        }
    };
    let mut h = T::gather(std::array::from_fn(|l| &hist[ks[l]]));
    let c = model.force(&input, &pm, &mut h);
    let torque = if T::FRICTION && SPIN { pair_torque(lever, &input, c.tangential.elastic + c.tangential.damping, ri, rj) } else { [Lanes::splat(0.0); 2] };
    let ratio = input.dn * gather(|l| pc[l].inv_r_min);
    // The largest overlap so far: a lane beats it rarely, so one test per four pairs.
    let beats = ratio.simd_gt(Lanes::splat(best.0)).bitmask();
    if beats != 0 {
        for (l, &k) in ks.iter().enumerate() {
            if ratio.extract(l) > best.0 {
                *best = (ratio.extract(l), k);
            }
        }
    }
    // With the ledger, the energy terms too, in lanes; the ledger adds them later in
    // list order.
    let terms = if ENERGY {
        let mut e = EnergyMemory::gather(std::array::from_fn(|l| &list.energy[ks[l]]));
        let t = model.energy_terms(input.n, input.dn, input.dt, &c, &mut e);
        for (l, &k) in ks.iter().enumerate() {
            list.energy[k] = e.lane(l);
        }
        t
    } else {
        EnergyTerms::default()
    };
    for l in 0..LANES {
        hist[ks[l]] = T::lane(&h, l);
        active[ks[l]] = true;
        sink(ks[l], ij[l], PairOut { force: lane2(&c.force, l), torque: [torque[0].extract(l), torque[1].extract(l)], ratio: ratio.extract(l) });
        if ENERGY {
            pending[l] = terms.lane(l);
        }
    }
}

/// One touching pair of grains `(i, j)` at separation `d` (minimum image, i minus j):
/// its force, advancing its tangential state `h`, and what its energy accounting needs.
#[inline(always)]
fn one_pair<Dm: Damping, T: Tangential, const SPIN: bool>(
    w: &PairView<'_, ContactModel<Dm, T>>,
    (i, j): (usize, usize),
    d: Vec2,
    pc: &PairConst,
    h: &mut T::History<f64>,
    active: &mut bool,
) -> (PairOut, Touch) {
    let (model, p) = (w.law, w.p);
    let lever = model.options.lever_arm;
    let input = pair_input::<f64, T, SPIN>(lever, d, p.r[i], p.r[j], p.omega[i], p.omega[j], p.v[i] - p.v[j], pc.r_star, pc.sqrt_m_star, w.dt);
    let pm = w.pair_table.get(p.material[i] as usize, p.material[j] as usize);
    let c = model.force(&input, pm, h);
    *active = true;
    let torque = if T::FRICTION && SPIN { pair_torque(lever, &input, c.tangential.elastic + c.tangential.damping, p.r[i], p.r[j]) } else { [0.0, 0.0] };
    (PairOut { force: c.force, torque, ratio: input.dn * pc.inv_r_min }, Touch { n: input.n, dn: input.dn, state: c })
}

/// What a touching pair's energy accounting needs: the normal, the overlap (m), and the
/// step's contact state.
#[derive(Clone, Copy, Debug, Default)]
struct Touch {
    n: Vec2,
    dn: f64,
    state: crate::contact::model::ContactState,
}

/// A part of the pair list: the pairs, their constants, tangential states, energy
/// memories (empty without the energy ledger) and touching flags.
pub struct PairSlices<'a, T: Tangential> {
    pub pairs: CheckedPairs<'a>,
    pub consts: &'a [PairConst],
    pub hist: &'a mut [T::History<f64>],
    pub energy: &'a mut [EnergyMemory],
    pub active: &'a mut [bool],
}

/// Where the energy terms of the pairs go: the world's ledger (serial order), or one
/// ledger per pair of the list part (merged in list order later).
pub enum Ledgers<'a> {
    One(&'a mut EnergyLedger),
    PerPair(&'a mut [EnergyLedger]),
}

impl Ledgers<'_> {
    /// The same ledgers, for a shorter while.
    pub fn reborrow(&mut self) -> Ledgers<'_> {
        match self {
            Ledgers::One(l) => Ledgers::One(l),
            Ledgers::PerPair(v) => Ledgers::PerPair(v),
        }
    }
    #[inline(always)]
    fn get(&mut self, k: usize) -> &mut EnergyLedger {
        match self {
            Ledgers::One(l) => l,
            Ledgers::PerPair(v) => &mut v[k],
        }
    }
}

/// The pairs of a list part that are touching, and those that were at the previous step
/// and are not any more, as indices into the part, in list order: the first `nt` of
/// `touching` and the first `nr` of `released`, `(nt, nr)` returned; `sep[m]` is the
/// separation (minimum image, i minus j) of pair `touching[m]`. `reach` holds each
/// pair's `(r_i + r_j)^2` ([`crate::neighbor::PairList::reach`]). `skip` (indices into
/// the part, ascending) leaves out pairs computed elsewhere: the portable sweep sweeps
/// the stretches between them one after the other, so that no pair pays for a test; the
/// CPU-specific sweeps (AVX-512, AVX2) mask their lanes. No branch per pair, and the
/// lists keep their length from step to step (no clearing).
#[allow(clippy::too_many_arguments)]
pub fn sort_pairs(x: &[Vec2], boundary: &Boundary, pairs: CheckedPairs<'_>, reach: &[f64], active: &[bool], skip: &[u32], touching: &mut Vec<u32>, sep: &mut Vec<Vec2>, released: &mut Vec<u32>) -> (usize, usize) {
    sort_pairs_with(true, x, boundary, pairs, reach, active, skip, touching, sep, released)
}

/// The loop of a CPU-specific sweep of [`sort_pairs`] over `range` (a multiple of its
/// width), as [`sweep_wide`] describes it, on raw pointers: the list, the grains' (x, y)
/// values, the boundary, `reach`, the touching flags, the pairs to skip (ascending, within
/// the range), the three outputs and their counts. The caller makes sure that the
/// pointers are good for the pairs of the range and their grains, and that every write
/// (at most a width of entries from a count, which is at most the index of the first
/// pair of the width) falls within the range.
type WideLoop = unsafe fn(*const [u32; 2], *const f64, &Boundary, *const f64, *const bool, &[u32], std::ops::Range<usize>, *mut u32, *mut Vec2, *mut u32, &mut usize, &mut usize);

/// Four touching flags (bytes 0 or 1) as the low four bits (bit l: flag l): one load and
/// one multiply, the shifted copies of the bytes landing on bits 24..27 without carries.
#[inline(always)]
pub(crate) fn four_flags(flags: [u8; 4]) -> u32 {
    u32::from_le_bytes(flags).wrapping_mul(0x0102_0408) >> 24 & 0xf
}

/// The pairs a CPU-specific sweep leaves out (the `skip` of [`sort_pairs`], ascending),
/// as lane masks of its blocks of pairs, block after block. (Builds without one do not
/// use it.)
#[allow(dead_code)]
pub(crate) struct LeftOut<'a> {
    rest: std::slice::Iter<'a, u32>,
    /// The next pair to leave out (`usize::MAX` when none is left).
    next: usize,
}

#[allow(dead_code)]
impl<'a> LeftOut<'a> {
    pub(crate) fn new(skip: &'a [u32]) -> Self {
        let mut rest = skip.iter();
        let next = rest.next().map_or(usize::MAX, |&k| k as usize);
        LeftOut { rest, next }
    }
    /// The lanes of the block of `width` pairs from `k` to leave out (bit l: pair k + l):
    /// usually none, at the cost of one compare. Blocks are asked for in ascending order.
    #[inline(always)]
    pub(crate) fn lanes(&mut self, k: usize, width: usize) -> u32 {
        let mut left_out = 0;
        while self.next < k + width {
            left_out |= 1 << (self.next - k);
            self.next = self.rest.next().map_or(usize::MAX, |&k| k as usize);
        }
        left_out
    }
}

/// The CPU-specific sweep the build has, as its width (pairs per step) and loop: eight
/// pairs a step with AVX-512 ([`crate::avx512`]), four with AVX2 alone
/// ([`crate::avx2`]), none otherwise.
#[cfg(all(target_arch = "x86_64", target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"))]
const WIDE_SWEEP: Option<(usize, WideLoop)> = Some((crate::avx512::WIDTH, crate::avx512::eights));
#[cfg(all(target_arch = "x86_64", target_feature = "avx2", not(all(target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"))))]
const WIDE_SWEEP: Option<(usize, WideLoop)> = Some((crate::avx2::WIDTH, crate::avx2::fours));
#[cfg(not(any(all(target_arch = "x86_64", target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"), all(target_arch = "x86_64", target_feature = "avx2", not(all(target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"))))))]
const WIDE_SWEEP: Option<(usize, WideLoop)> = None;

/// Sort out the pairs `range.start..range.start + width m` (the largest multiple of
/// `width` that fits in `range`) with a CPU-specific loop `body`, as the portable sweep
/// does, leaving out those in `skip` (ascending, within the range): touching pairs
/// appended to `touching` (with their separations to `sep`) from `nt` on, released ones to
/// `released` from `nr` on; `nt` and `nr` move on. Every pair before the range is sorted
/// out or skipped already, so `nt` and `nr` are at most `range.start`. Returns the end of
/// what it swept, for the portable sweep to take the rest. Skipped pairs (the parallel
/// stage's cross pairs) are masked lanes, not breaks in the sweep.
#[allow(clippy::too_many_arguments, dead_code)]
fn sweep_wide(
    (width, body): (usize, WideLoop),
    x: &[Vec2],
    boundary: &Boundary,
    pairs: CheckedPairs<'_>,
    reach: &[f64],
    active: &[bool],
    skip: &[u32],
    range: std::ops::Range<usize>,
    touching: &mut [u32],
    sep: &mut [Vec2],
    released: &mut [u32],
    nt: &mut usize,
    nr: &mut usize,
) -> usize {
    let end = range.start + range.len() / width * width;
    // Every read of the loop is of pairs before `end`, and of the grains of those pairs
    // (`CheckedPairs::of` checks that `x` covers them). Every write is of at most `width`
    // entries from `nt` or `nr`, which are at most the index of the first pair of the
    // width: so within `end`.
    let xs = pairs.of(x);
    assert!(end <= pairs.len() && end <= reach.len() && end <= active.len());
    // The AVX-512 loop's gathers take a grain index doubled as an i32 offset.
    assert!(x.len() <= 1 << 30, "{} grains: the CPU-specific sweeps take at most 2^30", x.len());
    assert!(*nt <= range.start && *nr <= range.start && end <= touching.len().min(sep.len()).min(released.len()));
    assert!(skip.first().is_none_or(|&k| k as usize >= range.start) && skip.is_sorted());
    // SAFETY: the build targets the loop's CPU features (it is compiled only then), and
    // the pointers are good for the pairs before `end`, their grains and the writes
    // (asserted above).
    unsafe { body(pairs.pairs().as_ptr(), xs.as_ptr() as *const f64, boundary, reach.as_ptr(), active.as_ptr(), skip, range.start..end, touching.as_mut_ptr(), sep.as_mut_ptr(), released.as_mut_ptr(), nt, nr) };
    end
}

/// [`sort_pairs`], with the CPU-specific sweep (`wide`, where the build has one:
/// [`WIDE_SWEEP`]) or the portable one alone (for the tests that compare them).
#[allow(clippy::too_many_arguments)]
fn sort_pairs_with(wide: bool, x: &[Vec2], boundary: &Boundary, pairs: CheckedPairs<'_>, reach: &[f64], active: &[bool], skip: &[u32], touching: &mut Vec<u32>, sep: &mut Vec<Vec2>, released: &mut Vec<u32>) -> (usize, usize) {
    let np = pairs.len();
    if touching.len() < np {
        touching.resize(np, 0);
        sep.resize(np, Vec2::zeros());
        released.resize(np, 0);
    }
    let (reach, active, touching, sep, released) = (&reach[..np], &active[..np], &mut touching[..np], &mut sep[..np], &mut released[..np]);
    let (mut nt, mut nr, mut from) = (0, 0, 0);
    // Where the build has a CPU-specific sweep, it takes all but a short tail.
    let skip = match WIDE_SWEEP {
        Some(w) if wide => {
            from = sweep_wide(w, x, boundary, pairs, reach, active, skip, 0..np, touching, sep, released, &mut nt, &mut nr);
            &skip[skip.partition_point(|&k| (k as usize) < from)..]
        }
        _ => skip,
    };
    for to in skip.iter().map(|&k| k as usize).chain(std::iter::once(np)) {
        if to > from {
            sweep(x, boundary, pairs, reach, active, from..to, touching, sep, released, &mut nt, &mut nr);
        }
        from = to + 1;
    }
    (nt, nr)
}

/// The sweep of [`sort_pairs`] over the pairs `range` of the part: four pairs'
/// distances at a time in lanes, then their indices appended where they belong (from
/// `nt` and `nr` on, which it moves on). Every pair before the range is already sorted
/// out or skipped, so `nt` and `nr` are at most its first index and every write is in
/// bounds.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn sweep(x: &[Vec2], boundary: &Boundary, pairs: CheckedPairs<'_>, reach: &[f64], active: &[bool], range: std::ops::Range<usize>, touching: &mut [u32], sep: &mut [Vec2], released: &mut [u32], nt: &mut usize, nr: &mut usize) {
    let xs = pairs.of(x);
    let (mut t, mut r) = (*nt, *nr);
    // Every index written below is at most the index of the pair being sorted out
    // (`t` and `r` count a part of the pairs before it), so these checks cover them all.
    assert!(t <= range.start && r <= range.start && range.end <= touching.len().min(sep.len()).min(released.len()));
    let quads = range.len() / LANES * LANES;
    let k0 = range.start;
    let (reach, active) = (&reach[range.clone()], &active[range.clone()]);
    for (q, (rq, aq)) in reach[..quads].chunks_exact(LANES).zip(active[..quads].chunks_exact(LANES)).enumerate() {
        let k = k0 + q * LANES;
        let g = xs.four(k);
        let d: Vector2<Lanes> = boundary.image(gather2(|l| g[l].0 - g[l].1));
        let touch = d.norm_squared().simd_lt(gather(|l| rq[l])).bitmask();
        let was = four_flags([aq[0] as u8, aq[1] as u8, aq[2] as u8, aq[3] as u8]) as u64;
        // Touching: every index written, the count moved on where it touches.
        for l in 0..LANES {
            debug_assert!(t <= k + l);
            // SAFETY: t <= k + l < range.end <= touching.len(), sep.len() (asserted above).
            unsafe {
                *touching.get_unchecked_mut(t) = (k + l) as u32;
                *sep.get_unchecked_mut(t) = lane2(&d, l);
            }
            t += touch as usize >> l & 1;
        }
        // Released: a few per step, so a branch that is almost never taken.
        let gone = !touch & was;
        if gone != 0 {
            for l in 0..LANES {
                released[r] = (k + l) as u32;
                r += gone as usize >> l & 1;
            }
        }
    }
    for m in quads..range.len() {
        let k = k0 + m;
        let (xi, xj) = xs.at(k);
        let d = boundary.image(xi - xj);
        let touch = d.norm_squared() < reach[m];
        touching[t] = k as u32;
        sep[t] = d;
        released[r] = k as u32;
        t += touch as usize;
        r += (!touch & active[m]) as usize;
    }
    (*nt, *nr) = (t, r);
}

/// Compute the pairs `touching` and `released` of a list part (indices from
/// [`sort_pairs`]): the output of each touching pair goes to `sink` (its index in the
/// part, its grains and its output), in list order. The touching pairs run four at a
/// time in SIMD lanes, their energy terms too (with the energy ledger); the ledger then
/// adds those and the released pairs' in list order, so that it sums in the serial
/// order; `pending` holds the terms meanwhile. Returns the largest overlap over the
/// smaller radius of the touching pairs and the index (in the part) of the first pair
/// that has it, `(0, usize::MAX)` if none touches.
#[allow(clippy::too_many_arguments)]
pub fn compute_pairs<Dm: Damping, T: Tangential, const ENERGY: bool, const SPIN: bool>(
    w: &PairView<'_, ContactModel<Dm, T>>,
    list: PairSlices<'_, T>,
    touching: &[u32],
    sep: &[Vec2],
    released: &[u32],
    mut ledgers: Ledgers<'_>,
    mut sink: impl FnMut(usize, (usize, usize), PairOut),
    pending: &mut Vec<EnergyTerms>,
) -> (f64, usize) {
    let mut best = (0.0, usize::MAX);
    if ENERGY && pending.len() < touching.len() {
        pending.resize(touching.len(), EnergyTerms::default());
    }
    let quads = touching.len() / LANES * LANES;
    // One material: its lanes once, not a table lookup per lane.
    let single = w.pair_table.single().map(|m| PairMaterial::gather([m; LANES]));
    let PairSlices { pairs, consts, hist, energy, active } = list;
    let mut pend = pending.chunks_exact_mut(LANES);
    for (ks, ds) in touching[..quads].chunks_exact(LANES).zip(sep.chunks_exact(LANES)) {
        let slices = PairSlices::<T> { pairs, consts, hist: &mut *hist, energy: &mut *energy, active: &mut *active };
        four_pairs::<Dm, T, ENERGY, SPIN>(w, slices, single.as_ref(), ks, ds, &mut sink, if ENERGY { pend.next().expect("a slot per pair") } else { &mut [] }, &mut best);
    }
    for (m, &k) in touching.iter().enumerate().skip(quads) {
        let k = k as usize;
        let [i, j] = pairs.pairs()[k].map(|g| g as usize);
        let (o, p) = one_pair::<Dm, T, SPIN>(w, (i, j), sep[m], &consts[k], &mut hist[k], &mut active[k]);
        if o.ratio > best.0 {
            best = (o.ratio, k);
        }
        sink(k, (i, j), o);
        if ENERGY {
            pending[m] = w.law.energy_terms(p.n, p.dn, w.dt, &p.state, &mut energy[k]);
        }
    }
    let mut none = EnergyLedger::default();
    if !ENERGY {
        for &k in released {
            let k = k as usize;
            pair_contact::<Dm, T, false>(w, pairs.pairs()[k], &consts[k], &mut hist[k], &mut EnergyMemory::default(), &mut active[k], &mut none);
        }
        return best;
    }
    // Both kinds merged in list order: the ledger is a sum.
    let (mut a, mut b) = (0, 0);
    while a < touching.len() || b < released.len() {
        if b == released.len() || (a < touching.len() && touching[a] < released[b]) {
            let k = touching[a] as usize;
            w.law.add_terms(&pending[a], ledgers.get(k));
            a += 1;
        } else {
            let k = released[b] as usize;
            pair_contact::<Dm, T, true>(w, pairs.pairs()[k], &consts[k], &mut hist[k], &mut energy[k], &mut active[k], ledgers.get(k));
            b += 1;
        }
    }
    best
}

/// What the pair kernel reads: everything but the forces it produces.
pub struct PairView<'a, L: ContactLaw> {
    pub p: &'a Particles,
    pub boundary: Boundary,
    pub law: L,
    pub pair_table: &'a crate::material::PairTable,
    pub dt: f64,
}

/// Grain-grain contacts over the Verlet list, in two passes: a branch-free sweep sorts
/// out the pairs that are touching (and those just released), then the kernel runs on
/// those only, four at a time in SIMD lanes. Most listed pairs are not touching (the
/// skin): the sweep spares them the kernel. `SPIN`: the grains rotate (the pairs' torques
/// are computed and collected).
#[derive(Default)]
pub struct PairForces<const ENERGY: bool, const SPIN: bool> {
    touching: Vec<u32>,
    sep: Vec<Vec2>,
    released: Vec<u32>,
    pending: Vec<EnergyTerms>,
}

impl<Dm: Damping, T: Tangential, const ENERGY: bool, const SPIN: bool> Stage<ContactModel<Dm, T>> for PairForces<ENERGY, SPIN> {
    fn name(&self) -> String {
        "PairContacts".into()
    }
    fn run(&mut self, w: &mut World<ContactModel<Dm, T>>) -> Result<(), Error> {
        let mut worst = w.max_overlap;
        let mut f = std::mem::take(&mut w.p.f);
        let mut torque = std::mem::take(&mut w.p.torque);
        let (pairs, consts) = (w.pairs.pairs.checked(), &w.pairs.consts);
        let (nt, nr) = sort_pairs(&w.p.x, &w.boundary, pairs, &w.pairs.reach, &w.pairs.active, &[], &mut self.touching, &mut self.sep, &mut self.released);
        let (touching, sep, released) = (&self.touching[..nt], &self.sep[..nt], &self.released[..nr]);
        let view = PairView { p: &w.p, boundary: w.boundary, law: w.law, pair_table: &w.pair_table, dt: w.dt };
        let list = PairSlices::<T> { pairs, consts, hist: &mut w.pairs.hist, energy: &mut w.pairs.energy, active: &mut w.pairs.active };
        // Each pair's force goes to its grains as it comes, in list order.
        let n = f.len();
        let (fs, ts) = (&mut f[..n], &mut torque[..n]);
        let sink = |_, (i, j): (usize, usize), o: PairOut| {
            fs[i] += o.force;
            fs[j] -= o.force;
            if T::FRICTION && SPIN {
                ts[i] -= o.torque[0];
                ts[j] -= o.torque[1];
            }
        };
        let (ratio, k) = compute_pairs::<Dm, T, ENERGY, SPIN>(&view, list, touching, sep, released, Ledgers::One(&mut w.ledger), sink, &mut self.pending);
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
            let (hist, active) = (&mut w.wall_hist[k], &mut w.wall_active[k]);
            let n = Vec2::new(0.0, wall.side);
            let mut on_wall = Vec2::zeros();
            for i in 0..p.n_free {
                let h = &mut hist[i];
                let gap = wall.side * (p.x[i].y - wall.y);
                let ri = p.r[i];
                if gap >= ri {
                    if active[i] {
                        let spin = if T::FRICTION { ri * p.omega[i] } else { 0.0 };
                        let vc = p.v[i] - wall.v + spin * Vec2::new(n.y, -n.x);
                        model.release::<ENERGY>(vc, n, dt, &mut h.tangential, &mut h.energy, &mut w.ledger);
                        active[i] = false;
                    }
                    continue;
                }
                let dn = ri - gap;
                let ai = if T::FRICTION { lever.arm(ri, dn) } else { 0.0 };
                let spin = if T::FRICTION { ai * p.omega[i] } else { 0.0 };
                let input = ContactInput { n, dn, r_star: ri, sqrt_m_star: p.m[i].sqrt(), v_rel: p.v[i] - wall.v, spin, dt, tangential_scale: 1.0 };
                let pm = w.pair_table.get(p.material[i] as usize, wall.material);
                let c = model.touch::<ENERGY>(&input, pm, h, &mut w.ledger);
                active[i] = true;
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
                format!("grain {i} overlaps the {} wall by {:.3} of its radius (bound {})", w.walls[usize::MAX - j].name, ratio, self.max_overlap)
            } else {
                format!("grains {i} and {j} overlap by {:.3} of the smaller radius (bound {})", ratio, self.max_overlap)
            };
            return Err(w.unstable_at(what, Some(i)));
        }
        if w.step.is_multiple_of(self.every) {
            // The velocities as they are at the end of the step.
            crate::integrate::settle(w);
            w.check_finite()?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::neighbor::{PairList, brute_force_pairs};
    use rand::{Rng, SeedableRng};

    /// The CPU-specific sweep (AVX-512 or AVX2) gives the portable sweep's lists and
    /// separations, bit for bit: across the periodic seam and without periodicity, with
    /// pairs released, and with skipped pairs at every lane position (masked in the wide
    /// blocks, between stretches in the portable sweep that takes the tail).
    #[cfg(any(all(target_arch = "x86_64", target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"), all(target_arch = "x86_64", target_feature = "avx2", not(all(target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw")))))]
    #[test]
    fn wide_sweep_gives_the_portable_bits() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let n = 400;
        for boundary in [Boundary::periodic_x(-0.5, 1.0), Boundary::open()] {
            let x: Vec<Vec2> = (0..n).map(|_| Vec2::new(rng.random::<f64>() - 0.5, 0.3 * rng.random::<f64>())).collect();
            let r: Vec<f64> = (0..n).map(|_| 0.01 + 0.01 * rng.random::<f64>()).collect();
            let mut list: PairList<f64> = PairList::default();
            list.replace(brute_force_pairs(&x, &r, n, &boundary, 0.01), &r, &vec![1.0; n], &crate::threads::Threads::serial());
            let np = list.pairs.len();
            let seam = list.pairs.iter().filter(|p| (x[p[0] as usize].x - x[p[1] as usize].x).abs() > 0.5).count();
            assert!(np > 200 && (seam > 5) == boundary.is_periodic(), "{np} pairs, {seam} across the seam");
            let active: Vec<bool> = (0..np).map(|_| rng.random::<bool>()).collect();
            for skip_rate in [0.0, 0.05, 0.3] {
                let skip: Vec<u32> = (0..np as u32).filter(|_| rng.random::<f64>() < skip_rate).collect();
                let sweep = |wide: bool| {
                    let (mut t, mut s, mut rel) = (Vec::new(), Vec::new(), Vec::new());
                    let (nt, nr) = sort_pairs_with(wide, &x, &boundary, list.pairs.checked(), &list.reach, &active, &skip, &mut t, &mut s, &mut rel);
                    (t[..nt].to_vec(), s[..nt].iter().map(|d| [d.x.to_bits(), d.y.to_bits()]).collect::<Vec<_>>(), rel[..nr].to_vec())
                };
                let (wide, portable) = (sweep(true), sweep(false));
                assert!(portable.0.len() > 20 && portable.2.len() > 20, "{} touching, {} released", portable.0.len(), portable.2.len());
                assert_eq!(wide, portable, "skip rate {skip_rate}, periodic {}", boundary.is_periodic());
            }
        }
    }

    /// The sweep with pairs to skip gives what it gives without, less those pairs: the
    /// stretches between skipped pairs (any length, so with and without a scalar tail)
    /// are swept as the whole list is.
    #[test]
    fn skipped_pairs_leave_the_rest_of_the_sweep_unchanged() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let n = 300;
        let boundary = Boundary::periodic_x(0.0, 1.0);
        let x: Vec<Vec2> = (0..n).map(|_| Vec2::new(rng.random::<f64>(), 0.3 * rng.random::<f64>())).collect();
        let r: Vec<f64> = (0..n).map(|_| 0.01 + 0.01 * rng.random::<f64>()).collect();
        let mut list: PairList<f64> = PairList::default();
        list.replace(brute_force_pairs(&x, &r, n, &boundary, 0.01), &r, &vec![1.0; n], &crate::threads::Threads::serial());
        let np = list.pairs.len();
        assert!(np > 100, "{np} pairs");
        let active: Vec<bool> = (0..np).map(|_| rng.random::<bool>()).collect();
        let skip: Vec<u32> = (0..np as u32).filter(|_| rng.random::<f64>() < 0.1).chain([0, np as u32 - 1]).collect::<std::collections::BTreeSet<_>>().into_iter().collect();
        let sweep = |skip: &[u32]| {
            let (mut t, mut s, mut rel) = (Vec::new(), Vec::new(), Vec::new());
            let (nt, nr) = sort_pairs(&x, &boundary, list.pairs.checked(), &list.reach, &active, skip, &mut t, &mut s, &mut rel);
            (t[..nt].to_vec(), s[..nt].to_vec(), rel[..nr].to_vec())
        };
        let (all_t, all_s, all_r) = sweep(&[]);
        let (t, s, rel) = sweep(&skip);
        assert!(!all_t.is_empty() && !all_r.is_empty());
        let kept = |k: &u32| skip.binary_search(k).is_err();
        let want: Vec<(u32, Vec2)> = all_t.iter().zip(&all_s).filter(|(k, _)| kept(k)).map(|(&k, &d)| (k, d)).collect();
        assert_eq!(t.iter().copied().zip(s).collect::<Vec<_>>(), want);
        assert_eq!(rel, all_r.iter().copied().filter(|k| kept(k)).collect::<Vec<_>>());
        // Against the definition: touching when closer than r_i + r_j, released when
        // not touching but active.
        for (k, (p, &was)) in list.pairs.iter().zip(&active).enumerate() {
            let [i, j] = p.map(|g| g as usize);
            let touch = boundary.image(x[i] - x[j]).norm() < r[i] + r[j];
            assert_eq!(all_t.contains(&(k as u32)), touch, "pair {k}");
            assert_eq!(all_r.contains(&(k as u32)), !touch && was, "pair {k}");
        }
    }
}
