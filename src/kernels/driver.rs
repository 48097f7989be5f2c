//! The contact kernel driver: each touching pair's input gathered from the grains'
//! slices, the contact law run one pair or four in SIMD lanes with the same bits, each
//! pair's force and torque handed to a sink in list order, each pair's energy terms
//! added to its own sums (no order between pairs to keep). It reads a view of the grains
//! ([`PairView`]) and the list's slices ([`PairSlices`]): no World, no Engine. Uses
//! physics and the pair list.

use nalgebra::Vector2;
use simba::simd::{SimdBool, SimdPartialOrd, SimdValue};
use crate::kernels::pairs::{CheckedPairs, PairConst};
use crate::physics::boundary::Boundary;
use crate::physics::contact::cohesion::Cohesion;
use crate::physics::contact::rolling::Rolling;
use crate::physics::contact::damping::Damping;
use crate::physics::contact::normal::Normal;
use crate::physics::contact::tangential::Tangential;
use crate::physics::contact::model::ContactState;
use crate::physics::contact::model::Held;
use crate::physics::contact::{ContactInput, ContactLaw, ContactModel, ContactRecord, EnergyMemory, LeverArm, Partner};
use crate::physics::dim::{Vec2, cross};
use crate::physics::lanes::{LANES, Lanes, Real, gather, gather2, lane2};
use crate::physics::material::PairMaterial;
use crate::physics::particles::Particles;

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
fn pair_input<R: Real, T: Tangential, Rr: Rolling, const SPIN: bool>(lever: LeverArm, d: Vector2<R>, ri: R, rj: R, wi: R, wj: R, v_rel: Vector2<R>, r_star: R, sqrt_m_star: R, dt: R) -> ContactInput<R> {
    let radsum = ri + rj;
    let r = d.norm_squared().simd_sqrt();
    let n = d * r.simd_recip();
    let dn = radsum - r;
    let spin = if T::FRICTION && SPIN { lever.arm(ri, dn) * wi + lever.arm(rj, dn) * wj } else { R::zero() };
    let tangential_scale = if T::FRICTION { lever.translation_scale(radsum, dn) } else { R::one() };
    let roll = if Rr::ON && SPIN { wi - wj } else { R::zero() };
    ContactInput { n, dn, r_star, sqrt_m_star, v_rel, spin, dt, tangential_scale, roll, roll_scale: R::one(), twist: () }
}

/// The torques to subtract from grains i and j: `-a n x Ft` and, with rolling
/// resistance, the rolling torque `rolling` on i (its opposite on j).
#[inline(always)]
fn pair_torque<R: Real, Rr: Rolling>(lever: LeverArm, c: &ContactInput<R>, ft: Vector2<R>, rolling: R, ri: R, rj: R) -> [R; 2] {
    let t = cross(c.n, ft);
    let (ti, tj) = (lever.torque_arm(ri, c.dn) * t, lever.torque_arm(rj, c.dn) * t);
    if Rr::ON { [ti - rolling, tj + rolling] } else { [ti, tj] }
}

/// One pair of the Verlet list: the contact force (touching), the end of a contact
/// (released), or nothing; tangential state `h` and (with `ENERGY`) energy memory `e`
/// updated.
#[inline(always)]
pub fn pair_contact<N: Normal, Dm: Damping, T: Tangential, C: Cohesion, Rr: Rolling, const ENERGY: bool>(
    w: &PairView<'_, ContactModel<N, Dm, T, C, Rr>>,
    pair: [u32; 2],
    pc: &PairConst,
    h: &mut Held<T, Rr>,
    e: &mut EnergyMemory<f64, Rr::Energy>,
    active: &mut bool,
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
            let roll = if Rr::ON { p.omega[i] - p.omega[j] } else { 0.0 };
            model.release::<ENERGY>(vc, n, roll, w.dt, h, e);
            *active = false;
        }
        return PairOut::default();
    }
    let (o, n, state) = one_pair::<N, Dm, T, C, Rr, true>(w, (i, j), d, pc, h, active);
    if ENERGY {
        model.energy_step(n, w.dt, &state, e);
    }
    o
}

/// Four touching pairs at once, one per SIMD lane (`ks`: their indices in the list, `ds`
/// their separations): the same bits as [`one_pair`] gives each of them, handed to
/// `sink` (index in the part, grains, output) in lane order; with `ENERGY`, their energy
/// memories move on (in lanes too). Without `SPIN`
/// (grains that do not rotate) the spins are not read and the torques not computed.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn four_pairs<N: Normal, Dm: Damping, T: Tangential, C: Cohesion, Rr: Rolling, const ENERGY: bool, const SPIN: bool>(
    w: &PairView<'_, ContactModel<N, Dm, T, C, Rr>>,
    list: PairSlices<'_, T, Rr>,
    single: Option<&PairMaterial<Lanes>>,
    ks: &[u32],
    ds: &[Vec2],
    sink: &mut impl FnMut(usize, (usize, usize), PairOut),
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
    let input = pair_input::<Lanes, T, Rr, SPIN>(lever, d, ri, rj, wi, wj, v_rel, gather(|l| pc[l].r_star), gather(|l| pc[l].sqrt_m_star), Lanes::splat(w.dt));
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
    let mut h = ContactModel::<N, Dm, T, C, Rr>::gather(std::array::from_fn(|l| &hist[ks[l]]));
    let c = model.force(&input, &pm, &mut h);
    let torque = if T::FRICTION && SPIN { pair_torque::<_, Rr>(lever, &input, c.tangential.elastic + c.tangential.damping, c.rolling, ri, rj) } else { [Lanes::splat(0.0); 2] };
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
    // With the ledger, the energy memories too, in lanes.
    if ENERGY {
        let mut e = ContactModel::<N, Dm, T, C, Rr>::gather_energy(std::array::from_fn(|l| &list.energy[ks[l]]), T::FRICTION);
        model.energy_step(input.n, input.dt, &c, &mut e);
        for (l, &k) in ks.iter().enumerate() {
            ContactModel::<N, Dm, T, C, Rr>::store_energy_lane(&e, l, &mut list.energy[k], T::FRICTION);
        }
    }
    for l in 0..LANES {
        hist[ks[l]] = ContactModel::<N, Dm, T, C, Rr>::lane(&h, l);
        active[ks[l]] = true;
        sink(ks[l], ij[l], PairOut { force: lane2(&c.force, l), torque: [torque[0].extract(l), torque[1].extract(l)], ratio: ratio.extract(l) });
    }
}

/// One touching pair of grains `(i, j)` at separation `d` (minimum image, i minus j):
/// its output, advancing its tangential state `h`, and what its energy accounting needs
/// (the normal and the step's contact state).
#[inline(always)]
fn one_pair<N: Normal, Dm: Damping, T: Tangential, C: Cohesion, Rr: Rolling, const SPIN: bool>(
    w: &PairView<'_, ContactModel<N, Dm, T, C, Rr>>,
    (i, j): (usize, usize),
    d: Vec2,
    pc: &PairConst,
    h: &mut Held<T, Rr>,
    active: &mut bool,
) -> (PairOut, Vec2, ContactState) {
    let (model, p) = (w.law, w.p);
    let lever = model.options.lever_arm;
    let input = pair_input::<f64, T, Rr, SPIN>(lever, d, p.r[i], p.r[j], p.omega[i], p.omega[j], p.v[i] - p.v[j], pc.r_star, pc.sqrt_m_star, w.dt);
    let pm = w.pair_table.get(p.material[i] as usize, p.material[j] as usize);
    let c = model.force(&input, pm, h);
    *active = true;
    let torque = if T::FRICTION && SPIN { pair_torque::<_, Rr>(lever, &input, c.tangential.elastic + c.tangential.damping, c.rolling, p.r[i], p.r[j]) } else { [0.0, 0.0] };
    (PairOut { force: c.force, torque, ratio: input.dn * pc.inv_r_min }, input.n, c)
}

/// Grain-grain pair `(i, j)` as the contact stage is about to compute it at this step
/// (positions, velocities and tangential state `h` as they are now): its record, or
/// `None` when it does not touch. The same function of the same inputs as the stage's
/// (`one_pair`, whose lanes give the same bits), on a copy of the state: nothing moves.
pub fn record_pair<N: Normal, Dm: Damping, T: Tangential, C: Cohesion, Rr: Rolling, const SPIN: bool>(w: &PairView<'_, ContactModel<N, Dm, T, C, Rr>>, (i, j): (usize, usize), pc: &PairConst, h: &Held<T, Rr>) -> Option<ContactRecord> {
    let p = w.p;
    let d = w.boundary.image(p.x[i] - p.x[j]);
    let (ri, rj) = (p.r[i], p.r[j]);
    if d.norm_squared() >= (ri + rj) * (ri + rj) {
        return None;
    }
    let (mut h, mut active) = (*h, true);
    let (_, n, c) = one_pair::<N, Dm, T, C, Rr, SPIN>(w, (i, j), d, pc, &mut h, &mut active);
    let dn = ri + rj - d.norm();
    Some(ContactRecord {
        i: i as u32,
        partner: Partner::Grain(j as u32),
        normal: n,
        overlap: dn,
        branch: d,
        point: p.x[i] - n * (ri - 0.5 * dn),
        normal_force: c.normal,
        tangential_force: c.tangential.elastic + c.tangential.damping,
        tangential_elastic: c.tangential.elastic,
        sliding: c.tangential.slip_energy > 0.0,
    })
}

/// A part of the pair list: the pairs, their constants, tangential states, energy
/// memories (empty without the energy ledger) and touching flags.
pub struct PairSlices<'a, T: Tangential, Rr: Rolling> {
    pub pairs: CheckedPairs<'a>,
    pub consts: &'a [PairConst],
    pub hist: &'a mut [Held<T, Rr>],
    pub energy: &'a mut [EnergyMemory<f64, Rr::Energy>],
    pub active: &'a mut [bool],
}

/// Compute the pairs `touching` and `released` of a list part (indices from
/// [`crate::kernels::sweep::sort_pairs`]): the output of each touching pair goes to `sink`
/// (its index in the part, its grains and its output), in list order. The touching pairs
/// run four at a time in SIMD lanes, their energy memories too (with the energy ledger);
/// each pair adds its energy terms to its own sums, so the pairs need no order among
/// them for the ledger. Returns the largest overlap over the smaller radius of the
/// touching pairs and the index (in the part) of the first pair that has it,
/// `(0, usize::MAX)` if none touches.
pub fn compute_pairs<N: Normal, Dm: Damping, T: Tangential, C: Cohesion, Rr: Rolling, const ENERGY: bool, const SPIN: bool>(
    w: &PairView<'_, ContactModel<N, Dm, T, C, Rr>>,
    list: PairSlices<'_, T, Rr>,
    touching: &[u32],
    sep: &[Vec2],
    released: &[u32],
    mut sink: impl FnMut(usize, (usize, usize), PairOut),
) -> (f64, usize) {
    let mut best = (0.0, usize::MAX);
    let quads = touching.len() / LANES * LANES;
    // One material: its lanes once, not a table lookup per lane.
    let single = w.pair_table.single().map(|m| PairMaterial::gather([m; LANES]));
    let PairSlices { pairs, consts, hist, energy, active } = list;
    for (ks, ds) in touching[..quads].chunks_exact(LANES).zip(sep.chunks_exact(LANES)) {
        let slices = PairSlices::<T, Rr> { pairs, consts, hist: &mut *hist, energy: &mut *energy, active: &mut *active };
        four_pairs::<N, Dm, T, C, Rr, ENERGY, SPIN>(w, slices, single.as_ref(), ks, ds, &mut sink, &mut best);
    }
    for (m, &k) in touching.iter().enumerate().skip(quads) {
        let k = k as usize;
        let [i, j] = pairs.pairs()[k].map(|g| g as usize);
        let (o, n, state) = one_pair::<N, Dm, T, C, Rr, SPIN>(w, (i, j), sep[m], &consts[k], &mut hist[k], &mut active[k]);
        if o.ratio > best.0 {
            best = (o.ratio, k);
        }
        sink(k, (i, j), o);
        if ENERGY {
            w.law.energy_step(n, w.dt, &state, &mut energy[k]);
        }
    }
    let mut none = EnergyMemory::<f64, Rr::Energy>::default();
    for &k in released {
        let k = k as usize;
        let e = if ENERGY { &mut energy[k] } else { &mut none };
        pair_contact::<N, Dm, T, C, Rr, ENERGY>(w, pairs.pairs()[k], &consts[k], &mut hist[k], e, &mut active[k]);
    }
    best
}

/// What the pair kernel reads: everything but the forces it produces.
pub struct PairView<'a, L: ContactLaw> {
    pub p: &'a Particles,
    pub boundary: Boundary,
    pub law: L,
    pub pair_table: &'a crate::physics::material::PairTable,
    pub dt: f64,
}
