//! Tangential contact force: none, LIGGGHTS' total displacement, or YADE's increments.
//!
//! Every formulation gets the relative velocity of the contact points `vt` (tangential
//! part, m/s, of grain i relative to grain j), the tangential stiffness `kt` (N/m), the
//! damping coefficient `gt` (kg/s), the Coulomb cap `mu |Fn|` (N) and the time step, and
//! returns the elastic and the damping part of the tangential force on grain i.

use nalgebra::Vector2;

use crate::physics::dim::cross;
use crate::physics::lanes::{Real, k, pick, pick2};

/// What a tangential formulation needs of one contact (or one per lane) at one step.
#[derive(Clone, Copy, Debug)]
pub struct TangentialInput<R: Real = f64> {
    /// Unit normal, from j to i.
    pub n: Vector2<R>,
    /// Tangential relative velocity of the contact points (i relative to j), m/s.
    pub vt: Vector2<R>,
    /// Tangential stiffness, N/m.
    pub kt: R,
    /// Tangential damping coefficient, kg/s.
    pub gt: R,
    /// Coulomb cap mu |Fn|, N.
    pub cap: R,
    /// Time step, s.
    pub dt: R,
}

/// The tangential force on grain i, split for the energy balance.
#[derive(Clone, Copy, Debug, Default)]
pub struct TangentialForce<R: Real = f64> {
    /// Elastic (spring) part, N.
    pub elastic: Vector2<R>,
    /// Viscous part, N.
    pub damping: Vector2<R>,
    /// Elastic energy removed from the spring by sliding at this step, J.
    pub slip_energy: R,
}

/// A tangential formulation, written once for one contact (`R = f64`) and for four
/// contacts in lanes (`R = Lanes`), without branches on the data: sliding or sticking
/// is a select.
pub trait Tangential: Copy + Default + Send + Sync + 'static {
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
    fn force<R: Real>(h: &mut Self::History<R>, inp: &TangentialInput<R>) -> TangentialForce<R>;
    /// Four contacts' states in lanes.
    fn gather(h: [&Self::History<f64>; crate::physics::lanes::LANES]) -> Self::History<crate::physics::lanes::Lanes>;
    /// Lane `l` of a state in lanes.
    fn lane(h: &Self::History<crate::physics::lanes::Lanes>, l: usize) -> Self::History<f64>;
}

/// No tangential force at all.
#[derive(Clone, Copy, Debug, Default)]
pub struct Frictionless;

impl Tangential for Frictionless {
    const NAME: &'static str = "Frictionless";
    const FRICTION: bool = false;
    type History<R: Real> = ();
    type Saved = ();
    fn save(_: ()) {}
    fn load(_: ()) {}
    #[inline(always)]
    fn force<R: Real>(_: &mut (), _: &TangentialInput<R>) -> TangentialForce<R> {
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
        type History<R: Real> = Vector2<R>;
        type Saved = Vector2<f64>;
        fn save(xi: Vector2<f64>) -> Vector2<f64> {
            xi
        }
        fn load(xi: Vector2<f64>) -> Vector2<f64> {
            xi
        }
        #[inline(always)]
        fn gather(h: [&Vector2<f64>; crate::physics::lanes::LANES]) -> Vector2<crate::physics::lanes::Lanes> {
            crate::physics::lanes::gather2(|l| *h[l])
        }
        #[inline(always)]
        fn lane(h: &Vector2<crate::physics::lanes::Lanes>, l: usize) -> Vector2<f64> {
            crate::physics::lanes::lane2(h, l)
        }
    };
}

/// One step of a total displacement as LIGGGHTS keeps it: `xi += vt dt`, then projected
/// onto the current tangent line (the part along the normal `n` removed).
#[inline(always)]
fn advance_on_tangent<R: Real>(xi: &mut Vector2<R>, inp: &TangentialInput<R>) {
    *xi += inp.vt * inp.dt;
    let along_n = xi.dot(&inp.n);
    *xi -= inp.n * along_n;
}

/// LIGGGHTS `tangential history`: a total tangential displacement `xi`, advanced by
/// `vt dt` and projected onto the current tangent line each step; `Ft = -kt xi - gt vt`
/// while sticking. When `|kt xi| > mu |Fn|` the contact slides: the force is the
/// elastic force scaled down to the cap, `xi = -Ft/kt`, and there is no damping.
#[derive(Clone, Copy, Debug, Default)]
pub struct TotalDisplacement;

impl Tangential for TotalDisplacement {
    const NAME: &'static str = "TotalDisplacementHistory";
    const FRICTION: bool = true;
    displacement_history!();
    #[inline(always)]
    fn force<R: Real>(xi: &mut Vector2<R>, inp: &TangentialInput<R>) -> TangentialForce<R> {
        advance_on_tangent(xi, inp);
        let elastic = *xi * -inp.kt;
        let f_el = elastic.norm();
        // cap >= 0, so a sliding contact has f_el > 0.
        let slide = f_el.simd_gt(inp.cap);
        let scale = pick(slide, inp.cap / f_el, R::one());
        let scaled = elastic * scale;
        let before = k::<R>(0.5) * inp.kt * xi.norm_squared();
        // The displacement that gives the capped force: -scaled/kt = xi scale.
        let xi_slid = *xi * scale;
        let after = k::<R>(0.5) * inp.kt * xi_slid.norm_squared();
        *xi = pick2(slide, xi_slid, *xi);
        let damping = inp.vt * -inp.gt;
        TangentialForce { elastic: scaled, damping: pick2(slide, Vector2::zeros(), damping), slip_energy: pick(slide, before - after, R::zero()) }
    }
}

/// State of a YADE-style incremental contact.
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct IncrementalState<R: Real = f64> {
    /// Elastic tangential force on grain i, N.
    pub force: Vector2<R>,
    /// The normal at the previous step (zero before the first step of a contact).
    pub n_prev: Vector2<R>,
}

/// YADE `Law2_ScGeom_MindlinPhys_Mindlin`: the elastic tangential force is rotated with
/// the contact frame (to first order, as YADE's `ScGeom::rotate`) and incremented by
/// `-kt vt dt` with `kt` at the current overlap; Coulomb caps the elastic part; the
/// viscous part `-gt vt` is added on top while sticking.
#[derive(Clone, Copy, Debug, Default)]
pub struct IncrementalForce;

impl Tangential for IncrementalForce {
    const NAME: &'static str = "IncrementalForce";
    const FRICTION: bool = true;
    type History<R: Real> = IncrementalState<R>;
    type Saved = IncrementalState<f64>;
    fn save(h: IncrementalState<f64>) -> IncrementalState<f64> {
        h
    }
    fn load(h: IncrementalState<f64>) -> IncrementalState<f64> {
        h
    }
    #[inline(always)]
    fn force<R: Real>(h: &mut IncrementalState<R>, inp: &TangentialInput<R>) -> TangentialForce<R> {
        let n = inp.n;
        // Rotate with the normal: in the plane the axis n_prev x n is along z and the
        // first-order rotation adds (axis x F).
        let s = cross(h.n_prev, n);
        let f = h.force;
        let rotated = f + Vector2::new(-f.y, f.x) * s;
        h.n_prev = n;
        let trial = rotated - inp.vt * inp.kt * inp.dt;
        let f_el = trial.norm();
        // cap >= 0, so a sliding contact has f_el > 0 (and kt > 0: the trial force grew).
        let slide = f_el.simd_gt(inp.cap);
        let scaled = trial * (inp.cap / f_el);
        let slip_energy = k::<R>(0.5) * (trial.norm_squared() - scaled.norm_squared()) / inp.kt;
        let elastic = pick2(slide, scaled, trial);
        h.force = elastic;
        let damping = inp.vt * -inp.gt;
        TangentialForce { elastic, damping: pick2(slide, Vector2::zeros(), damping), slip_energy: pick(slide, slip_energy, R::zero()) }
    }
    #[inline(always)]
    fn gather(h: [&IncrementalState<f64>; crate::physics::lanes::LANES]) -> IncrementalState<crate::physics::lanes::Lanes> {
        IncrementalState { force: crate::physics::lanes::gather2(|l| h[l].force), n_prev: crate::physics::lanes::gather2(|l| h[l].n_prev) }
    }
    #[inline(always)]
    fn lane(h: &IncrementalState<crate::physics::lanes::Lanes>, l: usize) -> IncrementalState<f64> {
        IncrementalState { force: crate::physics::lanes::lane2(&h.force, l), n_prev: crate::physics::lanes::lane2(&h.n_prev, l) }
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

impl Tangential for TotalForceCap {
    const NAME: &'static str = "TotalForceCapHistory";
    const FRICTION: bool = true;
    displacement_history!();
    #[inline(always)]
    fn force<R: Real>(xi: &mut Vector2<R>, inp: &TangentialInput<R>) -> TangentialForce<R> {
        let n = inp.n;
        // The frame turn: onto the tangent line, at the old length (0 if nothing is left).
        let along = xi.dot(&n);
        let turned = (along.simd_abs() * inp.kt).simd_gt(k::<R>(1e-10) * inp.cap);
        let length = xi.norm();
        let projected = *xi - n * along;
        let left = projected.norm();
        let rescale = pick(left.simd_gt(R::zero()), length / left, R::zero());
        *xi = pick2(turned, projected * rescale, *xi);
        *xi += inp.vt * inp.dt;
        let damping = inp.vt * -inp.gt;
        let trial = *xi * -inp.kt + damping;
        let f = trial.norm();
        // cap >= 0, so a sliding contact has f > 0.
        let slide = f.simd_gt(inp.cap);
        let before = xi.norm_squared();
        let held = before.simd_gt(R::zero());
        let capped = trial * (inp.cap / f);
        let xi_slid = (capped - damping) * (-R::one() / inp.kt);
        // Sliding with a history: the capped force; sliding without one: no force at all.
        *xi = pick2(slide & held, xi_slid, *xi);
        // What the slip takes out of the spring; a slip that loads it (the dashpot's force
        // put in) is the law's own work, which the ledger counts in W_t.
        let slip_energy = pick(slide & held, (k::<R>(0.5) * inp.kt * (before - xi.norm_squared())).simd_max(R::zero()), R::zero());
        let elastic = *xi * -inp.kt;
        let none = slide & !held;
        TangentialForce { elastic: pick2(none, Vector2::zeros(), elastic), damping: pick2(none, Vector2::zeros(), damping), slip_energy }
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

impl Tangential for TotalForceCapSpringKept {
    const NAME: &'static str = "TotalForceCapSpringKept";
    const FRICTION: bool = true;
    displacement_history!();
    #[inline(always)]
    fn force<R: Real>(xi: &mut Vector2<R>, inp: &TangentialInput<R>) -> TangentialForce<R> {
        advance_on_tangent(xi, inp);
        let elastic = *xi * -inp.kt;
        let damping = inp.vt * -inp.gt;
        let trial = elastic + damping;
        let f = trial.norm();
        // cap >= 0, so a sliding contact has f > 0 (and a spring over the cap f_el > 0).
        let slide = f.simd_gt(inp.cap);
        let f_el = elastic.norm();
        let over = slide & f_el.simd_gt(inp.cap);
        let scale = pick(over, inp.cap / f_el, R::one());
        let before = k::<R>(0.5) * inp.kt * xi.norm_squared();
        *xi = *xi * scale;
        let after = k::<R>(0.5) * inp.kt * xi.norm_squared();
        let kept = *xi * -inp.kt;
        // Sliding: the trial force at the cap, of which the dashpot takes what the spring
        // does not hold (along the trial, against the slip).
        let total = trial * (inp.cap / f);
        TangentialForce { elastic: kept, damping: pick2(slide, total - kept, damping), slip_energy: pick(over, before - after, R::zero()) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One step of the spring-kept cap from history `xi` (m) along x, the normal along y,
    /// at tangential velocity `vt` (m/s), kt = 1e4 N/m, gt = 2 kg/s, dt = 1e-4 s, cap in N.
    fn step(xi: f64, vt: f64, cap: f64) -> (Vector2<f64>, TangentialForce<f64>) {
        let mut h = Vector2::new(xi, 0.0);
        let inp = TangentialInput { n: Vector2::new(0.0, 1.0), vt: Vector2::new(vt, 0.0), kt: 1e4, gt: 2.0, cap, dt: 1e-4 };
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
