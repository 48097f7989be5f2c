//! The contact kernel driver: each touching pair's input gathered from the grains'
//! slices, the contact law run one pair or four in SIMD lanes with the same bits, each
//! pair's force and torque handed to a sink in list order, each pair's energy terms
//! added to its own sums (no order between pairs to keep). It reads a view of the grains
//! ([`PairView`]) and the list's slices ([`PairSlices`]): no World, no Engine. Uses
//! physics and the pair list.

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
use crate::physics::contact::{ContactInput, ContactModel, ContactRecord, EnergyMemory, LeverArm, Partner};
use crate::physics::dim::{Dim, Plane};
use crate::physics::lanes::{LANES, Lanes, Real, gather};
use crate::physics::material::PairMaterial;
use crate::physics::particles::Particles;

/// What one grain-grain pair did this step, for the grains to collect.
#[derive(Clone, Copy, Debug, Default)]
pub struct PairOut<D: Dim = Plane> {
    /// Force on the first grain (the second gets the opposite), N.
    pub force: D::Vector<f64>,
    /// Torques to subtract from the first and the second grain, N m.
    pub torque: [D::Spin<f64>; 2],
    /// Overlap over the smaller radius (0 when not touching).
    pub ratio: f64,
}

/// The contact input of touching pairs (one, or one per lane) from their separation
/// `d` (minimum image, i minus j), radii, spins (unread without `SPIN`: the grains do not
/// rotate), relative velocity and constants.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn pair_input<R: Real, D: Dim, T: Tangential<D>, Rr: Rolling<D>, const SPIN: bool>(lever: LeverArm, d: D::Vector<R>, ri: R, rj: R, wi: D::Spin<R>, wj: D::Spin<R>, v_rel: D::Vector<R>, r_star: R, sqrt_m_star: R, dt: R) -> ContactInput<R, D> {
    let radsum = ri + rj;
    let r = D::norm_squared(d).simd_sqrt();
    let n = d * r.simd_recip();
    let dn = radsum - r;
    let spin = if T::FRICTION && SPIN { wi * lever.arm(ri, dn) + wj * lever.arm(rj, dn) } else { D::spin_zero() };
    let tangential_scale = if T::FRICTION { lever.translation_scale(radsum, dn) } else { R::one() };
    let roll = if Rr::ON && SPIN { wi - wj } else { D::spin_zero() };
    let twist = if T::FRICTION && SPIN { D::twist(wi + wj) } else { D::twist(D::spin_zero()) };
    ContactInput { n, dn, r_star, sqrt_m_star, v_rel, spin, dt, tangential_scale, roll, roll_scale: R::one(), twist }
}

/// The torques to subtract from grains i and j: `-a n x Ft` and, with rolling
/// resistance, the rolling torque `rolling` on i (its opposite on j).
#[inline(always)]
fn pair_torque<R: Real, D: Dim, Rr: Rolling<D>>(lever: LeverArm, c: &ContactInput<R, D>, ft: D::Vector<R>, rolling: D::Spin<R>, ri: R, rj: R) -> [D::Spin<R>; 2] {
    let t = D::cross(c.n, ft);
    let (ti, tj) = (t * lever.torque_arm(ri, c.dn), t * lever.torque_arm(rj, c.dn));
    if Rr::ON { [ti - rolling, tj + rolling] } else { [ti, tj] }
}

/// One pair of the Verlet list: the contact force (touching), the end of a contact
/// (released), or nothing; tangential state `h` and (with `ENERGY`) energy memory `e`
/// updated.
#[inline(always)]
pub fn pair_contact<N: Normal, Dm: Damping, T: Tangential<D>, C: Cohesion, Rr: Rolling<D>, D: Dim, const ENERGY: bool>(
    w: &PairView<'_, ContactModel<N, Dm, T, C, Rr, D>, D>,
    pair: [u32; 2],
    pc: &PairConst,
    h: &mut Held<T, Rr, f64, D>,
    e: &mut EnergyMemory<f64, Rr::Energy, D>,
    active: &mut bool,
) -> PairOut<D> {
    let model = w.law;
    let p = w.p;
    let (i, j) = (pair[0] as usize, pair[1] as usize);
    let d = w.boundary.image(p.x[i] - p.x[j]);
    let rsq = D::norm_squared(d);
    let (ri, rj) = (p.r[i], p.r[j]);
    let radsum = ri + rj;
    if rsq >= radsum * radsum {
        if *active {
            let n = d / rsq.sqrt();
            let spin = if T::FRICTION { p.omega[i] * ri + p.omega[j] * rj } else { D::spin_zero() };
            let vc = p.v[i] - p.v[j] + D::cross_spin(n, spin);
            let roll = if Rr::ON { p.omega[i] - p.omega[j] } else { D::spin_zero() };
            model.release::<ENERGY>(vc, n, roll, w.dt, h, e);
            *active = false;
        }
        return PairOut::default();
    }
    let (o, n, state) = one_pair::<N, Dm, T, C, Rr, D, true>(w, (i, j), d, pc, h, active);
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
fn four_pairs<N: Normal, Dm: Damping, T: Tangential<D>, C: Cohesion, Rr: Rolling<D>, D: Dim, const ENERGY: bool, const SPIN: bool>(
    w: &PairView<'_, ContactModel<N, Dm, T, C, Rr, D>, D>,
    list: PairSlices<'_, T, Rr, D>,
    single: Option<&PairMaterial<Lanes>>,
    ks: &[u32],
    ds: &[D::Vector<f64>],
    sink: &mut impl FnMut(usize, (usize, usize), PairOut<D>),
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
    let d = D::gather(|l| ds[l]);
    let rs: [(f64, f64); LANES] = std::array::from_fn(|l| r.at(ks[l]));
    let (ri, rj) = (gather(|l| rs[l].0), gather(|l| rs[l].1));
    let (wi, wj) = if T::FRICTION && SPIN {
        let ws: [(D::Spin<f64>, D::Spin<f64>); LANES] = std::array::from_fn(|l| omega.at(ks[l]));
        (D::gather_spin(|l| ws[l].0), D::gather_spin(|l| ws[l].1))
    } else {
        (D::spin_zero(), D::spin_zero())
    };
    let v_rel = D::gather(|l| {
        let (vi, vj) = v.at(ks[l]);
        vi - vj
    });
    let input = pair_input::<Lanes, D, T, Rr, SPIN>(lever, d, ri, rj, wi, wj, v_rel, gather(|l| pc[l].r_star), gather(|l| pc[l].sqrt_m_star), Lanes::splat(w.dt));
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
    let mut h = ContactModel::<N, Dm, T, C, Rr, D>::gather(std::array::from_fn(|l| &hist[ks[l]]));
    let c = model.force(&input, &pm, &mut h);
    let torque = if T::FRICTION && SPIN { pair_torque::<_, D, Rr>(lever, &input, c.tangential.elastic + c.tangential.damping, c.rolling, ri, rj) } else { [D::spin_zero(); 2] };
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
        let mut e = ContactModel::<N, Dm, T, C, Rr, D>::gather_energy(std::array::from_fn(|l| &list.energy[ks[l]]), T::FRICTION);
        model.energy_step(input.n, input.dt, &c, &mut e);
        for (l, &k) in ks.iter().enumerate() {
            ContactModel::<N, Dm, T, C, Rr, D>::store_energy_lane(&e, l, &mut list.energy[k], T::FRICTION);
        }
    }
    for l in 0..LANES {
        hist[ks[l]] = ContactModel::<N, Dm, T, C, Rr, D>::lane(&h, l);
        active[ks[l]] = true;
        sink(ks[l], ij[l], PairOut { force: D::lane(&c.force, l), torque: [D::spin_lane(&torque[0], l), D::spin_lane(&torque[1], l)], ratio: ratio.extract(l) });
    }
}

/// One touching pair of grains `(i, j)` at separation `d` (minimum image, i minus j):
/// its output, advancing its tangential state `h`, and what its energy accounting needs
/// (the normal and the step's contact state).
#[inline(always)]
fn one_pair<N: Normal, Dm: Damping, T: Tangential<D>, C: Cohesion, Rr: Rolling<D>, D: Dim, const SPIN: bool>(
    w: &PairView<'_, ContactModel<N, Dm, T, C, Rr, D>, D>,
    (i, j): (usize, usize),
    d: D::Vector<f64>,
    pc: &PairConst,
    h: &mut Held<T, Rr, f64, D>,
    active: &mut bool,
) -> (PairOut<D>, D::Vector<f64>, ContactState<f64, D>) {
    let (model, p) = (w.law, w.p);
    let lever = model.options.lever_arm;
    let input = pair_input::<f64, D, T, Rr, SPIN>(lever, d, p.r[i], p.r[j], p.omega[i], p.omega[j], p.v[i] - p.v[j], pc.r_star, pc.sqrt_m_star, w.dt);
    let pm = w.pair_table.get(p.material[i] as usize, p.material[j] as usize);
    let c = model.force(&input, pm, h);
    *active = true;
    let torque = if T::FRICTION && SPIN { pair_torque::<_, D, Rr>(lever, &input, c.tangential.elastic + c.tangential.damping, c.rolling, p.r[i], p.r[j]) } else { [D::spin_zero(); 2] };
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
    let (_, n, c) = one_pair::<N, Dm, T, C, Rr, Plane, SPIN>(w, (i, j), d, pc, &mut h, &mut active);
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
pub struct PairSlices<'a, T: Tangential<D>, Rr: Rolling<D>, D: Dim = Plane> {
    pub pairs: CheckedPairs<'a>,
    pub consts: &'a [PairConst],
    pub hist: &'a mut [Held<T, Rr, f64, D>],
    pub energy: &'a mut [EnergyMemory<f64, Rr::Energy, D>],
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
pub fn compute_pairs<N: Normal, Dm: Damping, T: Tangential<D>, C: Cohesion, Rr: Rolling<D>, D: Dim, const ENERGY: bool, const SPIN: bool>(
    w: &PairView<'_, ContactModel<N, Dm, T, C, Rr, D>, D>,
    list: PairSlices<'_, T, Rr, D>,
    touching: &[u32],
    sep: &[D::Vector<f64>],
    released: &[u32],
    mut sink: impl FnMut(usize, (usize, usize), PairOut<D>),
) -> (f64, usize) {
    let mut best = (0.0, usize::MAX);
    let quads = touching.len() / LANES * LANES;
    // One material: its lanes once, not a table lookup per lane.
    let single = w.pair_table.single().map(|m| PairMaterial::gather([m; LANES]));
    let PairSlices { pairs, consts, hist, energy, active } = list;
    for (ks, ds) in touching[..quads].chunks_exact(LANES).zip(sep.chunks_exact(LANES)) {
        let slices = PairSlices::<T, Rr, D> { pairs, consts, hist: &mut *hist, energy: &mut *energy, active: &mut *active };
        four_pairs::<N, Dm, T, C, Rr, D, ENERGY, SPIN>(w, slices, single.as_ref(), ks, ds, &mut sink, &mut best);
    }
    for (m, &k) in touching.iter().enumerate().skip(quads) {
        let k = k as usize;
        let [i, j] = pairs.pairs()[k].map(|g| g as usize);
        let (o, n, state) = one_pair::<N, Dm, T, C, Rr, D, SPIN>(w, (i, j), sep[m], &consts[k], &mut hist[k], &mut active[k]);
        if o.ratio > best.0 {
            best = (o.ratio, k);
        }
        sink(k, (i, j), o);
        if ENERGY {
            w.law.energy_step(n, w.dt, &state, &mut energy[k]);
        }
    }
    let mut none = EnergyMemory::<f64, Rr::Energy, D>::default();
    for &k in released {
        let k = k as usize;
        let e = if ENERGY { &mut energy[k] } else { &mut none };
        pair_contact::<N, Dm, T, C, Rr, D, ENERGY>(w, pairs.pairs()[k], &consts[k], &mut hist[k], e, &mut active[k]);
    }
    best
}

/// What the pair kernel reads: everything but the forces it produces.
pub struct PairView<'a, L, D: Dim = Plane> {
    pub p: &'a Particles<D>,
    pub boundary: Boundary<D>,
    pub law: L,
    pub pair_table: &'a crate::physics::material::PairTable,
    pub dt: f64,
}
