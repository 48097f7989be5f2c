//! Tangential contact force: none, LIGGGHTS' total displacement, or YADE's increments.
//!
//! Every formulation gets the relative velocity of the contact points `vt` (tangential
//! part, m/s, of grain i relative to grain j), the tangential stiffness `kt` (N/m), the
//! damping coefficient `gt` (kg/s), the Coulomb cap `mu |Fn|` (N) and the time step, and
//! returns the elastic and the damping part of the tangential force on grain i.
//!
//! The laws are written once for the plane and for space ([`Dim`]): the total
//! displacement, the two total-force caps and YADE's increments in both (in space the
//! history lives in the tangent plane, and YADE's force turns with the contact frame about
//! the normal too); micro-slip, whose bed of springs lies along one tangent, in the plane
//! only.

use nalgebra::Vector2;

use crate::physics::dim::{Dim, Plane};
use crate::physics::lanes::{Real, k, pick};

/// What a tangential formulation needs of one contact (or one per lane) at one step.
#[derive(Clone, Copy, Debug)]
pub struct TangentialInput<R: Real = f64, D: Dim = Plane> {
    /// Unit normal, from j to i.
    pub n: D::Vector<R>,
    /// Tangential relative velocity of the contact points (i relative to j), m/s.
    pub vt: D::Vector<R>,
    /// Tangential stiffness, N/m.
    pub kt: R,
    /// Tangential damping coefficient, kg/s.
    pub gt: R,
    /// Coulomb cap mu |Fn|, N.
    pub cap: R,
    /// Time step, s.
    pub dt: R,
    /// What turns the contact about its normal: the pair's spin sum `w_i + w_j` in space
    /// (rad/s); nothing in the plane, where every spin is perpendicular to the normal.
    pub twist: D::Twist<R>,
}

/// The tangential force on grain i, split for the energy balance.
#[derive(Clone, Copy, Debug, Default)]
pub struct TangentialForce<R: Real = f64, D: Dim = Plane> {
    /// Elastic (spring) part, N.
    pub elastic: D::Vector<R>,
    /// Viscous part, N.
    pub damping: D::Vector<R>,
    /// Elastic energy removed from the spring by sliding at this step, J.
    pub slip_energy: R,
}

/// A tangential formulation, written once for one contact (`R = f64`) and for four
/// contacts in lanes (`R = Lanes`), without branches on the data: sliding or sticking
/// is a select; and for the plane (`D = Plane`, the default) or for space.
pub trait Tangential<D: Dim = Plane>: Copy + Default + Send + Sync + 'static {
    const NAME: &'static str;
    /// False for frictionless contacts: no tangential force, no torque, no spin.
    const FRICTION: bool;
    /// The state a contact carries from step to step (one per lane with `R = Lanes`).
    type History<R: Real>: Copy + Default + Send + Sync + std::fmt::Debug;
    /// A contact's state as a checkpoint stores it, the same numbers as its
    /// `History<f64>` ([`crate::engine::snapshot`]).
    type Saved: serde::Serialize + serde::de::DeserializeOwned;
    fn save(h: Self::History<f64>) -> Self::Saved;
    fn load(s: Self::Saved) -> Self::History<f64>;
    fn force<R: Real>(h: &mut Self::History<R>, inp: &TangentialInput<R, D>) -> TangentialForce<R, D>;
    /// Four contacts' states in lanes.
    fn gather(h: [&Self::History<f64>; crate::physics::lanes::LANES]) -> Self::History<crate::physics::lanes::Lanes>;
    /// Lane `l` of a state in lanes.
    fn lane(h: &Self::History<crate::physics::lanes::Lanes>, l: usize) -> Self::History<f64>;
}

/// No tangential force at all.
#[derive(Clone, Copy, Debug, Default)]
pub struct Frictionless;

impl<D: Dim> Tangential<D> for Frictionless {
    const NAME: &'static str = "Frictionless";
    const FRICTION: bool = false;
    type History<R: Real> = ();
    type Saved = ();
    fn save(_: ()) {}
    fn load(_: ()) {}
    #[inline(always)]
    fn force<R: Real>(_: &mut (), _: &TangentialInput<R, D>) -> TangentialForce<R, D> {
        TangentialForce::default()
    }
    #[inline(always)]
    fn gather(_: [&(); crate::physics::lanes::LANES]) {}
    #[inline(always)]
    fn lane(_: &(), _: usize) {}
}

/// The state of a total-displacement history, `xi` (m), a checkpoint storing the same
/// vector: the associated types and the four state functions of [`Tangential`] for
/// [`TotalDisplacement`] and [`TotalForceCap`].
macro_rules! displacement_history {
    () => {
        /// The tangential displacement xi, m.
        type History<R: Real> = D::Vector<R>;
        type Saved = D::Saved;
        fn save(xi: D::Vector<f64>) -> D::Saved {
            D::save(xi)
        }
        fn load(xi: D::Saved) -> D::Vector<f64> {
            D::load(xi)
        }
        #[inline(always)]
        fn gather(h: [&D::Vector<f64>; crate::physics::lanes::LANES]) -> D::Vector<crate::physics::lanes::Lanes> {
            D::gather(|l| *h[l])
        }
        #[inline(always)]
        fn lane(h: &D::Vector<crate::physics::lanes::Lanes>, l: usize) -> D::Vector<f64> {
            D::lane(h, l)
        }
    };
}

/// One step of a total displacement as LIGGGHTS keeps it: `xi += vt dt`, then projected
/// onto the current tangent line or plane (the part along the normal `n` removed).
#[inline(always)]
fn advance_on_tangent<R: Real, D: Dim>(xi: &mut D::Vector<R>, inp: &TangentialInput<R, D>) {
    *xi += inp.vt * inp.dt;
    let along_n = D::dot(*xi, inp.n);
    *xi -= inp.n * along_n;
}

/// A slip of a total displacement: `xi` scaled by `scale` where `slide` holds (the
/// displacement whose spring gives the capped force), and the elastic energy the slip
/// took from the spring, `kt (|xi|^2 - |xi'|^2) / 2` (0 elsewhere), J.
#[inline(always)]
fn slip_to<R: Real, D: Dim>(xi: &mut D::Vector<R>, kt: R, scale: R, slide: R::SimdBool) -> R {
    let before = k::<R>(0.5) * kt * D::norm_squared(*xi);
    let xi_slid = *xi * scale;
    let after = k::<R>(0.5) * kt * D::norm_squared(xi_slid);
    *xi = D::pick(slide, xi_slid, *xi);
    pick(slide, before - after, R::zero())
}

/// The dashpot's part of a tangential force whose *total* is capped (the spring-kept cap
/// and micro-slip): `damping` while the total `trial` (spring before any slip plus
/// dashpot, N) is within `cap` (N); above it the total is `trial` scaled to the cap and
/// the dashpot takes what the spring after its slip, `kept` (N), does not hold (along the
/// trial, against the slip).
#[inline(always)]
fn dashpot_takes_rest<R: Real, D: Dim>(trial: D::Vector<R>, kept: D::Vector<R>, damping: D::Vector<R>, cap: R) -> D::Vector<R> {
    let f = D::norm(trial);
    // cap >= 0, so a sliding contact has f > 0.
    let slide = f.simd_gt(cap);
    D::pick(slide, trial * (cap / f) - kept, damping)
}

/// LIGGGHTS `tangential history`: a total tangential displacement `xi`, advanced by
/// `vt dt` and projected onto the current tangent line each step; `Ft = -kt xi - gt vt`
/// while sticking. When `|kt xi| > mu |Fn|` the contact slides: the force is the
/// elastic force scaled down to the cap, `xi = -Ft/kt`, and there is no damping.
#[derive(Clone, Copy, Debug, Default)]
pub struct TotalDisplacement;

impl<D: Dim> Tangential<D> for TotalDisplacement {
    const NAME: &'static str = "TotalDisplacementHistory";
    const FRICTION: bool = true;
    displacement_history!();
    #[inline(always)]
    fn force<R: Real>(xi: &mut D::Vector<R>, inp: &TangentialInput<R, D>) -> TangentialForce<R, D> {
        advance_on_tangent(xi, inp);
        let elastic = *xi * -inp.kt;
        let f_el = D::norm(elastic);
        // cap >= 0, so a sliding contact has f_el > 0.
        let slide = f_el.simd_gt(inp.cap);
        let scale = pick(slide, inp.cap / f_el, R::one());
        let scaled = elastic * scale;
        // The displacement that gives the capped force: -scaled/kt = xi scale.
        let slip_energy = slip_to::<R, D>(xi, inp.kt, scale, slide);
        let damping = inp.vt * -inp.gt;
        TangentialForce { elastic: scaled, damping: D::pick(slide, D::zero(), damping), slip_energy }
    }
}

/// State of a YADE-style incremental contact.
#[derive(Clone, Copy, Debug, Default)]
pub struct IncrementalState<R: Real = f64, D: Dim = Plane> {
    /// Elastic tangential force on grain i, N.
    pub force: D::Vector<R>,
    /// The normal at the previous step (zero before the first step of a contact).
    pub n_prev: D::Vector<R>,
}

/// An incremental contact's state as a checkpoint stores it: the same two vectors, in
/// the same order.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
#[serde(bound = "")]
pub struct IncrementalSaved<D: Dim = Plane> {
    /// Elastic tangential force on grain i, N.
    pub force: D::Saved,
    /// The normal at the previous step.
    pub n_prev: D::Saved,
}

/// YADE `Law2_ScGeom_MindlinPhys_Mindlin`: the elastic tangential force is rotated with
/// the contact frame (to first order, as YADE's `ScGeom::rotate`, [`Dim::turn`]: in
/// space about the normal too, by the pair's mean spin along it) and incremented by
/// `-kt vt dt` with `kt` at the current overlap; Coulomb caps the elastic part; the
/// viscous part `-gt vt` is added on top while sticking.
#[derive(Clone, Copy, Debug, Default)]
pub struct IncrementalForce;

impl<D: Dim> Tangential<D> for IncrementalForce {
    const NAME: &'static str = "IncrementalForce";
    const FRICTION: bool = true;
    type History<R: Real> = IncrementalState<R, D>;
    type Saved = IncrementalSaved<D>;
    fn save(h: IncrementalState<f64, D>) -> IncrementalSaved<D> {
        IncrementalSaved { force: D::save(h.force), n_prev: D::save(h.n_prev) }
    }
    fn load(s: IncrementalSaved<D>) -> IncrementalState<f64, D> {
        IncrementalState { force: D::load(s.force), n_prev: D::load(s.n_prev) }
    }
    #[inline(always)]
    fn force<R: Real>(h: &mut IncrementalState<R, D>, inp: &TangentialInput<R, D>) -> TangentialForce<R, D> {
        let n = inp.n;
        let rotated = D::turn(h.force, h.n_prev, n, inp.twist, inp.dt);
        h.n_prev = n;
        let trial = rotated - inp.vt * inp.kt * inp.dt;
        let f_el = D::norm(trial);
        // cap >= 0, so a sliding contact has f_el > 0 (and kt > 0: the trial force grew).
        let slide = f_el.simd_gt(inp.cap);
        let scaled = trial * (inp.cap / f_el);
        let slip_energy = k::<R>(0.5) * (D::norm_squared(trial) - D::norm_squared(scaled)) / inp.kt;
        let elastic = D::pick(slide, scaled, trial);
        h.force = elastic;
        let damping = inp.vt * -inp.gt;
        TangentialForce { elastic, damping: D::pick(slide, D::zero(), damping), slip_energy: pick(slide, slip_energy, R::zero()) }
    }
    #[inline(always)]
    fn gather(h: [&IncrementalState<f64, D>; crate::physics::lanes::LANES]) -> IncrementalState<crate::physics::lanes::Lanes, D> {
        IncrementalState { force: D::gather(|l| h[l].force), n_prev: D::gather(|l| h[l].n_prev) }
    }
    #[inline(always)]
    fn lane(h: &IncrementalState<crate::physics::lanes::Lanes, D>, l: usize) -> IncrementalState<f64, D> {
        IncrementalState { force: D::lane(&h.force, l), n_prev: D::lane(&h.n_prev, l) }
    }
}

/// LAMMPS `pair granular ... tangential mindlin` (Hertz) and `tangential linear_history`
/// (the linear spring), as its 20220106 release computes them: a total tangential
/// displacement `xi` whose Coulomb cap is on the *total* tangential force, damping
/// included. Each step, when the history's part along the normal would give a force above
/// 1e-10 of the cap (the contact frame has turned), `xi` is projected onto the tangent
/// line and rescaled to its old length; then `xi += vt dt` and `Ft = -kt xi - gt vt`.
/// When `|Ft| > mu |Fn|` the force is scaled to the cap and `xi = -(Ft + gt vt)/kt`, the
/// displacement whose spring gives the capped force together with the damping (a contact
/// whose history is exactly 0 then has no tangential force, as in LAMMPS). The friction
/// impulse never exceeds mu times the normal one (with Fn >= 0); it equals it in gross
/// sliding under the linear spring, and falls short under damped Hertz, where the spring's
/// stored dashpot force meets a kt that grows while loading (tests/chung_ooi.rs, tests 6
/// and 8: 9-15% at e = 0.5).
///
/// The split for the energy ledger: elastic `-kt xi`, viscous `-gt vt` (which still acts
/// while sliding); friction takes what a slip removes from the spring, `kt (|xi_trial|^2
/// - |xi|^2) / 2` when positive. A slip that stores the dashpot's force in the spring
/// loads it instead: that energy is the law's own work (`W_t`, [`crate::physics::energy`]),
/// as the work of a kt that changes under a loaded spring is.
#[derive(Clone, Copy, Debug, Default)]
pub struct TotalForceCap;

impl<D: Dim> Tangential<D> for TotalForceCap {
    const NAME: &'static str = "TotalForceCapHistory";
    const FRICTION: bool = true;
    displacement_history!();
    #[inline(always)]
    fn force<R: Real>(xi: &mut D::Vector<R>, inp: &TangentialInput<R, D>) -> TangentialForce<R, D> {
        let n = inp.n;
        // The frame turn: onto the tangent line or plane, at the old length (0 if nothing
        // is left).
        let along = D::dot(*xi, n);
        let turned = (along.simd_abs() * inp.kt).simd_gt(k::<R>(1e-10) * inp.cap);
        let length = D::norm(*xi);
        let projected = *xi - n * along;
        let left = D::norm(projected);
        let rescale = pick(left.simd_gt(R::zero()), length / left, R::zero());
        *xi = D::pick(turned, projected * rescale, *xi);
        *xi += inp.vt * inp.dt;
        let damping = inp.vt * -inp.gt;
        let trial = *xi * -inp.kt + damping;
        let f = D::norm(trial);
        // cap >= 0, so a sliding contact has f > 0.
        let slide = f.simd_gt(inp.cap);
        let before = D::norm_squared(*xi);
        let held = before.simd_gt(R::zero());
        let capped = trial * (inp.cap / f);
        let xi_slid = (capped - damping) * (-R::one() / inp.kt);
        // Sliding with a history: the capped force; sliding without one: no force at all.
        *xi = D::pick(slide & held, xi_slid, *xi);
        // What the slip takes out of the spring; a slip that loads it (the dashpot's force
        // put in) is the law's own work, which the ledger counts in W_t.
        let slip_energy = pick(slide & held, (k::<R>(0.5) * inp.kt * (before - D::norm_squared(*xi))).simd_max(R::zero()), R::zero());
        let elastic = *xi * -inp.kt;
        let none = slide & !held;
        TangentialForce { elastic: D::pick(none, D::zero(), elastic), damping: D::pick(none, D::zero(), damping), slip_energy }
    }
}

/// The cap on the total tangential force with the spring kept (`model.tangential =
/// "total_force_cap_spring_kept"`), the rule of Kratos DEMApplication's
/// `DEM_D_Hertz_viscous_Coulomb` (Chung & Ooi's benchmarks as Kratos runs them) on
/// LIGGGHTS' total displacement: `xi += vt dt`, projected onto the tangent line, and
/// `Ft = -kt xi - gt vt` while `|Ft| <= mu |Fn|`. Above it the contact slides and the
/// total force is the trial one scaled to the cap, `mu |Fn|` exactly; the spring keeps its
/// own displacement unless it alone exceeds the cap (then it is scaled to it, as
/// LIGGGHTS'), and the dashpot takes the rest, so it never stores the dashpot's force
/// (as LAMMPS' law does) nor adds it above the cap (as LIGGGHTS' and YADE's do while
/// sticking). In gross sliding the friction impulse is mu times the normal impulse to
/// rounding, under damped Hertz too (tests/chung_ooi.rs, tests 4, 6 and 8).
///
/// Kratos increments its elastic force instead, and keeps a spring over the cap where a
/// larger dashpot opposes it; here the spring never holds more than the cap.
///
/// The split for the energy ledger: elastic `-kt xi`, viscous the rest of the force
/// (against the slip: it dissipates); friction takes what a slip removes from the spring.
#[derive(Clone, Copy, Debug, Default)]
pub struct TotalForceCapSpringKept;

impl<D: Dim> Tangential<D> for TotalForceCapSpringKept {
    const NAME: &'static str = "TotalForceCapSpringKept";
    const FRICTION: bool = true;
    displacement_history!();
    #[inline(always)]
    fn force<R: Real>(xi: &mut D::Vector<R>, inp: &TangentialInput<R, D>) -> TangentialForce<R, D> {
        advance_on_tangent(xi, inp);
        let elastic = *xi * -inp.kt;
        let damping = inp.vt * -inp.gt;
        let trial = elastic + damping;
        let f = D::norm(trial);
        // cap >= 0, so a sliding contact has f > 0 (and a spring over the cap f_el > 0).
        let slide = f.simd_gt(inp.cap);
        let f_el = D::norm(elastic);
        let over = slide & f_el.simd_gt(inp.cap);
        let scale = pick(over, inp.cap / f_el, R::one());
        let slip_energy = slip_to::<R, D>(xi, inp.kt, scale, over);
        let kept = *xi * -inp.kt;
        TangentialForce { elastic: kept, damping: dashpot_takes_rest::<R, D>(trial, kept, damping, inp.cap), slip_energy }
    }
}

/// Springs per contact of the micro-slip law ([`MicroSlip`]): the contact radius is
/// resolved by between half and all of them. Chung & Ooi's test 5 (the rebound spin at
/// tan / mu = 0.06, 0.32, 1.19, 3.3) moves by at most 0.05% with 128 or 256 springs
/// (docs/model.md).
pub const MICROSLIP_SPRINGS: usize = 64;

/// State of a micro-slip contact: the tangential displacement of each spring of the
/// contact's bed ([`MicroSlip`]).
#[derive(Clone, Copy, Debug)]
pub struct MicroSlipState<R: Real = f64> {
    /// Spring i's tangential displacement along the tangent `t = (-n_y, n_x)`, m (i
    /// relative to j; 0 while the spring is out of contact).
    pub u: [R; MICROSLIP_SPRINGS],
    /// The width of one spring's cell, as a stiffness, N/m: spring i covers radii whose
    /// `8 G* r` lies in `[i cell, (i + 1) cell)` (0 before the contact's first step).
    pub cell: R,
    /// The tangential stiffness at the previous step, N/m (its contact radius, in the
    /// same units).
    pub kt: R,
}

impl<R: Real> Default for MicroSlipState<R> {
    fn default() -> Self {
        MicroSlipState { u: [R::zero(); MICROSLIP_SPRINGS], cell: R::zero(), kt: R::zero() }
    }
}

/// A micro-slip contact's state as a checkpoint stores it: the same numbers.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct MicroSlipSaved {
    /// Each spring's tangential displacement, m ([`MicroSlipState::u`]; a checkpoint
    /// with fewer is read with the rest 0, one with more with the extra dropped).
    pub u: Vec<f64>,
    /// The width of one spring's cell as a stiffness, N/m.
    pub cell: f64,
    /// The tangential stiffness at the previous step, N/m.
    pub kt: f64,
}

/// The share of spring i's cell `[i cell, (i + 1) cell)` of a contact of radius `kt`
/// (both as stiffnesses, N/m) that is in contact: 0 to 1.
#[inline(always)]
fn cell_weight<R: Real>(kt: R, i: usize, cell: R) -> R {
    ((kt - cell * k::<R>(i as f64)) / cell).simd_clamp(R::zero(), R::one())
}

/// Keep the contact radius `kt` over half to all of the springs: when it outgrows the
/// bed, neighbouring springs merge (their forces at the old radius summed); when it falls
/// under half of it, each spring splits in two (the same displacement, so the same
/// forces). A contact whose radius outgrows 2^64 cells at once starts a new bed.
#[inline(always)]
fn regrid<R: Real>(h: &mut MicroSlipState<R>, kt: R) {
    use simba::simd::SimdBool;
    const N: usize = MICROSLIP_SPRINGS;
    let beds = k::<R>(N as f64);
    for _ in 0..64 {
        let grow = kt.simd_gt(h.cell * beds);
        if !grow.any() {
            break;
        }
        for j in 0..N / 2 {
            let (wa, wb) = (cell_weight(h.kt, 2 * j, h.cell), cell_weight(h.kt, 2 * j + 1, h.cell));
            let both = wa + wb;
            let merged = pick(both.simd_gt(R::zero()), (wa * h.u[2 * j] + wb * h.u[2 * j + 1]) / both, R::zero());
            h.u[j] = pick(grow, merged, h.u[j]);
        }
        for j in N / 2..N {
            h.u[j] = pick(grow, R::zero(), h.u[j]);
        }
        h.cell = pick(grow, h.cell * k::<R>(2.0), h.cell);
    }
    let lost = kt.simd_gt(h.cell * beds);
    h.cell = pick(lost, kt * k::<R>(2.0 / N as f64), h.cell);
    for u in h.u.iter_mut() {
        *u = pick(lost, R::zero(), *u);
    }
    for _ in 0..64 {
        let shrink = kt.simd_gt(R::zero()) & (kt * k::<R>(2.0)).simd_lt(h.cell * beds);
        if !shrink.any() {
            break;
        }
        for j in (0..N / 2).rev() {
            let v = h.u[j];
            h.u[2 * j + 1] = pick(shrink, v, h.u[2 * j + 1]);
            h.u[2 * j] = pick(shrink, v, h.u[2 * j]);
        }
        h.cell = pick(shrink, h.cell * k::<R>(0.5), h.cell);
    }
}

/// Mindlin-Deresiewicz micro-slip (`model.tangential = "mindlin_deresiewicz"`, Hertz
/// only): the Cattaneo-Mindlin contact of two elastic spheres under any history of normal
/// and tangential load, slip spreading in from the edge of the contact area, by Popov and
/// Heß's method of dimensionality reduction, exact for these contacts (V. L. Popov,
/// M. Heß, "Method of Dimensionality Reduction in Contact Mechanics and Friction",
/// Springer 2015; "... A users handbook. I. Axially-symmetric contacts", Facta
/// Universitatis, Mech. Eng. 12(1):1-14, 2014): the contact is a bed of independent springs across its radius a, of total
/// tangential stiffness `kt = 8 G* a`, each loaded with its share of the Hertz pressure,
/// `mu |Fn| (3/2)(1 - r^2/a^2) dr/a`. Each step every spring in contact moves by the
/// contact's tangential displacement `vt dt` and slips where its force would exceed its
/// share; a spring that leaves the contact (a shrinks) lets go of its displacement, one
/// that enters it starts from none. At constant normal load this is Mindlin's loading
/// curve `mu P (1 - (1 - d/ds)^(3/2))`, Masing's unloading and the energy per cycle of
/// Mindlin and Deresiewicz (unit tests), and a tangential load that grows with the normal
/// one at a ratio under mu gives no slip; at small impact angles the contact point's
/// tangential velocity reverses as in Chung & Ooi's finite-element reference (test 5,
/// tests/chung_ooi.rs), which no-slip springs miss.
///
/// The bed is [`MICROSLIP_SPRINGS`] springs in cells of the radius (measured as the
/// stiffness `8 G* r`, so the law needs nothing but `kt` and the cap), the edge cell
/// counted for the part in contact; the bed regrids as the radius grows and shrinks
/// ([`regrid`]). The dashpot `-gt vt` acts on top as in the spring-kept cap: the total
/// force is capped at `mu |Fn|`, the springs keep theirs, the dashpot takes the rest.
///
/// For the energy ledger: elastic the springs' sum, friction what the springs' slips
/// take; the ledger's stored tangential energy is `|Ft|^2 / (2 kt)`, a lower bound of
/// the bed's (a bed with slipped springs holds more), the rest is in `W_t`.
#[derive(Clone, Copy, Debug, Default)]
pub struct MicroSlip;

impl Tangential for MicroSlip {
    const NAME: &'static str = "MindlinDeresiewiczMicroSlip";
    const FRICTION: bool = true;
    type History<R: Real> = MicroSlipState<R>;
    type Saved = MicroSlipSaved;
    fn save(h: MicroSlipState<f64>) -> MicroSlipSaved {
        MicroSlipSaved { u: h.u.to_vec(), cell: h.cell, kt: h.kt }
    }
    fn load(s: MicroSlipSaved) -> MicroSlipState<f64> {
        let mut h = MicroSlipState { cell: s.cell, kt: s.kt, ..Default::default() };
        for (to, from) in h.u.iter_mut().zip(s.u) {
            *to = from;
        }
        h
    }
    #[inline(always)]
    fn force<R: Real>(h: &mut MicroSlipState<R>, inp: &TangentialInput<R>) -> TangentialForce<R> {
        let kt = inp.kt;
        // A new contact's bed: twice its radius now.
        h.cell = pick(h.cell.simd_gt(R::zero()), h.cell, kt * k::<R>(1.0 / MICROSLIP_SPRINGS as f64));
        regrid(h, kt);
        let t = Vector2::new(-inp.n.y, inp.n.x);
        let step = inp.vt.dot(&t) * inp.dt;
        let inv_kt = R::one() / kt;
        let (mut sum, mut slip) = (R::zero(), R::zero());
        for (i, u) in h.u.iter_mut().enumerate() {
            let w = cell_weight(kt, i, h.cell);
            let on = w.simd_gt(R::zero());
            // The part of the cell that has come into contact during the step moved by
            // half the step (it joined, on average, halfway): the cell's displacement is
            // the mean over its part in contact.
            let was = cell_weight(h.kt, i, h.cell).simd_min(w);
            let old = pick(on, was / w, R::zero());
            // The cell's share of the Hertz pressure: (3/2) the integral of 1 - x^2 over
            // its part of x = r / a in [0, 1].
            let x0 = h.cell * k::<R>(i as f64) * inv_kt;
            let x1 = ((h.cell * k::<R>(i as f64 + 1.0)).simd_min(kt)) * inv_kt;
            let share = k::<R>(1.5) * (x1 - x0) * (R::one() - (x1 * x1 + x1 * x0 + x0 * x0) * k::<R>(1.0 / 3.0));
            let limit = inp.cap * share;
            let ki = w * h.cell;
            let trial = pick(on, *u * old + step * (R::one() + old) * k::<R>(0.5), R::zero());
            let over = on & (ki * trial).simd_abs().simd_gt(limit);
            let slid = (limit / ki).simd_copysign(trial);
            *u = pick(over, slid, trial);
            slip += pick(over, k::<R>(0.5) * ki * (trial * trial - slid * slid), R::zero());
            sum += pick(on, ki * *u, R::zero());
        }
        h.kt = kt;
        let elastic = t * -sum;
        let damping = inp.vt * -inp.gt;
        TangentialForce { elastic, damping: dashpot_takes_rest::<R, Plane>(elastic + damping, elastic, damping, inp.cap), slip_energy: slip }
    }
    #[inline(always)]
    fn gather(h: [&MicroSlipState<f64>; crate::physics::lanes::LANES]) -> MicroSlipState<crate::physics::lanes::Lanes> {
        use crate::physics::lanes::gather;
        MicroSlipState { u: std::array::from_fn(|i| gather(|l| h[l].u[i])), cell: gather(|l| h[l].cell), kt: gather(|l| h[l].kt) }
    }
    #[inline(always)]
    fn lane(h: &MicroSlipState<crate::physics::lanes::Lanes>, l: usize) -> MicroSlipState<f64> {
        use simba::simd::SimdValue;
        MicroSlipState { u: std::array::from_fn(|i| h.u[i].extract(l)), cell: h.cell.extract(l), kt: h.kt.extract(l) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One step of the spring-kept cap from history `xi` (m) along x, the normal along y,
    /// at tangential velocity `vt` (m/s), kt = 1e4 N/m, gt = 2 kg/s, dt = 1e-4 s, cap in N.
    fn step(xi: f64, vt: f64, cap: f64) -> (Vector2<f64>, TangentialForce<f64>) {
        let mut h = Vector2::new(xi, 0.0);
        let inp = TangentialInput { n: Vector2::new(0.0, 1.0), vt: Vector2::new(vt, 0.0), kt: 1e4, gt: 2.0, cap, dt: 1e-4, twist: () };
        let f = TotalForceCapSpringKept::force(&mut h, &inp);
        (h, f)
    }

    #[test]
    fn spring_kept_cap_sticks_below_the_cap_and_slides_at_it() {
        // Sticking: spring -kt (xi + vt dt) = -1e4 (1e-4 + 1e-4) = -2 N, dashpot -2 N:
        // 4 N total, under a 5 N cap: both as computed, no slip.
        let (h, f) = step(1e-4, 1.0, 5.0);
        assert_eq!((f.elastic.x, f.damping.x, f.slip_energy, h.x), (-2.0, -2.0, 0.0, 2e-4));
        // The spring below the cap, the total above (3 N cap): the total is the cap, the
        // spring keeps its displacement and the dashpot takes 1 N, against the slip.
        let (h, f) = step(1e-4, 1.0, 3.0);
        assert_eq!((f.elastic.x, h.x, f.slip_energy), (-2.0, 2e-4, 0.0));
        assert!((f.elastic.x + f.damping.x + 3.0).abs() < 1e-15 && (f.damping.x + 1.0).abs() < 1e-15, "{f:?}");
        // The spring alone above the cap (1.5 N): scaled to it, no dashpot, and the slip
        // takes kt (|xi|^2 - |xi'|^2) / 2 = 1e4 (4e-8 - 2.25e-8) / 2 = 8.75e-5 J.
        let (h, f) = step(1e-4, 1.0, 1.5);
        assert!((f.elastic.x + 1.5).abs() < 1e-15 && f.damping.x.abs() < 1e-15 && (h.x - 1.5e-4).abs() < 1e-19, "{f:?} {h:?}");
        assert!((f.slip_energy - 8.75e-5).abs() < 1e-18, "{}", f.slip_energy);
        // The dashpot opposite a spring that is released (vt against xi): spring -1e4 (5e-4
        // - 1e-4) = -4 N, dashpot +2 N, total -2 N under a 3 N cap: sticks.
        let (_, f) = step(5e-4, -1.0, 3.0);
        assert_eq!((f.elastic.x, f.damping.x), (-4.0, 2.0));
        // Fast the other way (vt = -10): spring -1e4 (5e-4 - 1e-3) = 5 N, dashpot 20 N,
        // 25 N against a 3 N cap: the spring scaled to 3 N, the total 3 N, no dashpot left.
        let (h, f) = step(5e-4, -10.0, 3.0);
        assert!((f.elastic.x - 3.0).abs() < 1e-15 && f.damping.x.abs() < 1e-15 && (h.x + 3e-4).abs() < 1e-19, "{f:?} {h:?}");
    }
}

#[cfg(test)]
mod microslip_tests {
    use super::*;

    /// A micro-slip contact driven along its tangent: normal along y, so t = (-1, 0).
    struct Driven {
        h: MicroSlipState<f64>,
        /// Tangential displacement so far, m.
        d: f64,
        /// Energy the springs' slips took, J.
        slipped: f64,
    }

    impl Driven {
        fn new() -> Self {
            Driven { h: MicroSlipState::default(), d: 0.0, slipped: 0.0 }
        }
        /// One step by `dd` (m) at stiffness `kt` (N/m) and cap `cap` (N): the load the
        /// springs carry, N (the force on grain i is minus it along t).
        fn step(&mut self, dd: f64, kt: f64, cap: f64) -> f64 {
            let t = Vector2::new(-1.0, 0.0);
            let inp = TangentialInput { n: Vector2::new(0.0, 1.0), vt: t * dd, kt, gt: 0.0, cap, dt: 1.0, twist: () };
            let f = MicroSlip::force(&mut self.h, &inp);
            self.d += dd;
            self.slipped += f.slip_energy;
            -f.elastic.dot(&t)
        }
    }

    // Mindlin (1949) at constant normal load P: a tangential displacement d gives
    // T = mu P (1 - (1 - d/ds)^(3/2)), ds = 3 mu P / (16 G* a) = 3 mu P / (2 kt)
    // (kt = 8 G* a). With kt = 1e6 N/m and mu P = 1 N, ds = 1.5e-6 m.
    const KT: f64 = 1e6;
    const CAP: f64 = 1.0;
    const DS: f64 = 1.5 * CAP / KT;

    fn mindlin(d: f64) -> f64 {
        CAP * (1.0 - (1.0 - (d / DS).min(1.0)).powf(1.5))
    }

    #[test]
    fn at_constant_load_micro_slip_follows_mindlin_loading_and_masing_unloading() {
        // Bound 1e-3 of mu P: the bed resolves the radius by 64 springs here, and each
        // slips as a whole (measured 4.5e-4).
        let mut c = Driven::new();
        let steps = 1000;
        let mut worst: f64 = 0.0;
        let d_star = 0.6 * DS;
        for _ in 0..steps {
            let t = c.step(d_star / steps as f64, KT, CAP);
            worst = worst.max((t - mindlin(c.d)).abs());
        }
        let t_star = mindlin(d_star);
        // Masing: unloading from (d*, T*) is the loading curve doubled in both axes.
        for _ in 0..2 * steps {
            let t = c.step(-d_star / steps as f64, KT, CAP);
            let masing = t_star - 2.0 * mindlin((d_star - c.d) / 2.0);
            worst = worst.max((t - masing).abs());
        }
        assert!(worst < 2e-3 * CAP, "largest gap {worst:e} N of mu P = {CAP} N");
        // Loaded on past ds: gross slip, the load is mu P.
        let mut c = Driven::new();
        for _ in 0..steps {
            c.step(1.2 * DS / steps as f64, KT, CAP);
        }
        let t = c.step(0.0, KT, CAP);
        assert!((t - CAP).abs() < 1e-12, "{t}");
    }

    #[test]
    fn the_energy_of_a_load_cycle_is_mindlin_and_deresiewiczs() {
        // Cycling between +-T0 at constant P dissipates, per cycle (Mindlin & Deresiewicz
        // 1953; Johnson, Contact Mechanics, 7.4), with x = T0 / (mu P):
        // W = 9 (mu P)^2 / (10 G* a) [1 - (1 - x)^(5/3) - 5x/6 (1 + (1 - x)^(2/3))],
        // G* a = kt / 8. The amplitude d0 reaches T0 on the loading curve: d0 = ds (1 - (1 - x)^(2/3)).
        for x in [0.2f64, 0.6, 0.9] {
            let d0 = DS * (1.0 - (1.0 - x).powf(2.0 / 3.0));
            let closed = 9.0 * CAP * CAP / (10.0 * KT / 8.0) * (1.0 - (1.0 - x).powf(5.0 / 3.0) - 5.0 * x / 6.0 * (1.0 + (1.0 - x).powf(2.0 / 3.0)));
            let mut c = Driven::new();
            let steps = 2000;
            for _ in 0..steps {
                c.step(d0 / steps as f64, KT, CAP);
            }
            let before = c.slipped;
            // Down to -d0 and back: one cycle.
            for dir in [-1.0, 1.0] {
                for _ in 0..2 * steps {
                    c.step(dir * d0 / steps as f64, KT, CAP);
                }
            }
            let w = c.slipped - before;
            // Bound 0.5%: the bed's 64 cells, each slipping whole (measured 0.18%, 0.23%,
            // 0.10% at x = 0.2, 0.6, 0.9).
            assert!((w / closed - 1.0).abs() < 5e-3, "x = {x}: {w:e} J against {closed:e} J");
        }
    }

    #[test]
    fn a_tangential_load_growing_with_the_normal_one_below_mu_does_not_slip() {
        // Mindlin & Deresiewicz: T and P growing together with dT/dP < mu, nothing slips
        // and T = integral of kt dd. Discretely, the first steps attach the whole contact
        // area at once, and its edge cells slip a little: bounded by 1e-6 of the stored
        // energy (measured 3.1e-19 J of 4e-10 J, all within the first 30 of 2000 steps),
        // T to 1e-3 (measured 3.7e-4: the cells' attachment, halfway through a step, is
        // first order in the step). Hertz: P = 4/3 E* sqrt(R) d^(3/2), kt = 8 G* a,
        // a = sqrt(R d); driven so that T = c P with c = 0.5 mu (mu = 0.3).
        let (e_star, g_star, r, mu): (f64, f64, f64, f64) = (1e9, 4e8, 1e-3, 0.3);
        let c_ratio = 0.5 * mu;
        let mut drv = Driven::new();
        let (mut t_law, mut p_prev) = (0.0, 0.0);
        for i in 1..=2000 {
            let dn = 1e-6 * i as f64 / 2000.0;
            let p = 4.0 / 3.0 * e_star * r.sqrt() * dn.powf(1.5);
            let kt = 8.0 * g_star * (r * dn).sqrt();
            let dd = c_ratio * (p - p_prev) / kt;
            p_prev = p;
            t_law = drv.step(dd, kt, mu * p);
        }
        let stored = t_law * t_law / (2.0 * 8.0 * g_star * (r * 1e-6f64).sqrt());
        assert!(drv.slipped < 1e-6 * stored, "slipped {:e} J of {stored:e} J", drv.slipped);
        assert!((t_law / (c_ratio * p_prev) - 1.0).abs() < 1e-3, "{t_law} vs {}", c_ratio * p_prev);
    }
}
