//! Rolling resistance of a contact: none, a constant torque (CDT), an elastic-plastic
//! torque spring (EPSD2), or a spring-dashpot-slider on a rolling displacement (SDS).
//!
//! Every law acts on the relative spin of the two bodies, `w = w_i - w_j` (rad/s; a
//! flat wall does not spin), and returns the torque `M` on grain i (N m, about z); grain
//! j gets `-M`. The cap is `mu_r R* |Fn|` with `mu_r` the pair's rolling friction
//! coefficient ([`crate::physics::material::Material::rolling_friction`], dimensionless:
//! the torque arm of the cap in units of R*), `R*` the reduced radius (the grain's radius
//! on a flat wall) and `Fn` the normal force.
//!
//! - [`Cdt`] (LIGGGHTS `rolling_friction cdt`): `M = -mu_r R* kn dn sign(w)`, with the
//!   elastic normal force kn dn; no state. It chatters about w = 0 once the grain has
//!   stopped rolling (the torque flips each step).
//! - [`Epsd2`] (LIGGGHTS `rolling_friction epsd2`): a torque spring of stiffness
//!   `kr = kt R*^2` (kt the tangential stiffness at this step), loaded incrementally:
//!   `m += kr w dt`, capped at `mu_r R* |Fn|`, `M = -m`. A stopped grain rests on the
//!   spring instead of chattering.
//! - [`Sds`] (LAMMPS `pair granular ... rolling sds k g mu`): a rolling displacement
//!   `s += R* w dt`, a force `f = -k s - g R* w` capped at `mu_r |Fn|` (the displacement
//!   is then set to the one that gives the capped force), `M = R* f`. With g = 0 and
//!   `k = kt` constant (the linear spring) it is EPSD2.
//!
//! [`NoRolling`] is every other scene's: the kernel has no term for it.

use simba::simd::SimdValue;

use crate::physics::dim::{Dim, Plane};
use crate::physics::lanes::{LANES, Lanes, Real, gather, k, pick};

/// What a rolling law needs of one contact (or one per lane) at one step.
#[derive(Clone, Copy, Debug)]
pub struct RollingInput<R: Real = f64, D: Dim = Plane> {
    /// Relative spin w_i - w_j as the law sees it, rad/s.
    pub w: D::Spin<R>,
    /// Reduced radius R* (the grain's radius on a flat wall), m.
    pub r_star: R,
    /// Tangential stiffness at this step, N/m (EPSD2's kr = kt R*^2).
    pub kt: R,
    /// Elastic normal force kn dn, N (CDT).
    pub elastic_normal: R,
    /// Normal force (with damping, after the clamp), N: the cap's.
    pub normal: R,
    /// Rolling friction coefficient mu_r of the pair.
    pub mu: R,
    /// Time step, s.
    pub dt: R,
}

/// A rolling-resistance law, compiled into the contact kernel (written once for one
/// contact and for four in lanes, without branches on the data). The laws are the
/// plane's (a torque about z); in space only [`NoRolling`] so far.
pub trait Rolling<D: Dim = Plane>: Copy + Send + Sync + std::fmt::Debug + 'static {
    /// Its name in `explain`.
    const NAME: &'static str;
    /// False: no rolling torque at all.
    const ON: bool;
    /// The state a contact carries from step to step (one per lane with `R = Lanes`).
    type History<R: Real>: Copy + Default + Send + Sync + std::fmt::Debug;
    /// A contact's state as a checkpoint stores it (the same numbers).
    type Saved: serde::Serialize + serde::de::DeserializeOwned;
    fn save(h: Self::History<f64>) -> Self::Saved;
    fn load(s: Self::Saved) -> Self::History<f64>;
    /// Four contacts' states in lanes.
    fn gather(h: [&Self::History<f64>; LANES]) -> Self::History<Lanes>;
    /// Lane `l` of a state in lanes.
    fn lane(h: &Self::History<Lanes>, l: usize) -> Self::History<f64>;
    /// What a contact's energy accounting keeps for the rolling torque (`()` without),
    /// and four contacts' of it in lanes.
    type Energy: RollingEnergy<f64, D::Spin<f64>> + InLanes<Lanes: RollingEnergy<Lanes, D::Spin<Lanes>>> + PartialEq + serde::Serialize + serde::de::DeserializeOwned;
    /// The torque on grain i, N m (j gets the opposite), advancing the state `h`.
    fn torque<R: Real>(&self, h: &mut Self::History<R>, inp: &RollingInput<R, D>) -> D::Spin<R>;
    /// The law and its parameters, for `explain` and checkpoints.
    fn label(&self) -> String {
        Self::NAME.to_string()
    }
}

/// The rolling torque's part of a contact's energy memory
/// ([`crate::physics::contact::EnergyMemory`]): its previous value and the work it took
/// from the grains since the ledger last took it. A contact without rolling resistance
/// keeps `()`: no room, no work. `S` is the torque's and spin's type: a number about z in
/// the plane (the default), a vector in space ([`crate::physics::dim::Dim::Spin`]).
pub trait RollingEnergy<R: Real, S = R>: Copy + Default + Send + Sync + std::fmt::Debug {
    /// One step of torque `m` on grain i (N m) against the relative spin `w` (rad/s) over
    /// `dt` (s): the trapezoid rule's work, as every term of the ledger.
    fn step(&mut self, m: S, w: S, dt: R);
    /// The contact ended over this step (the torque fell to 0): close the integral and
    /// forget the previous torque; the work stays to be taken.
    fn release(&mut self, w: S, dt: R);
    /// The work taken from the grains since last taken, J; left at 0.
    fn take(&mut self) -> R;
    /// The work taken, J (unchanged).
    fn taken(&self) -> R;
}

/// A value of one contact that four contacts keep in SIMD lanes.
pub trait InLanes: Sized {
    type Lanes;
    /// Four contacts' values in lanes.
    fn gather(x: [&Self; LANES]) -> Self::Lanes;
    /// Lane `l` of them.
    fn lane(x: &Self::Lanes, l: usize) -> Self;
}

impl InLanes for () {
    type Lanes = ();
    #[inline(always)]
    fn gather(_: [&(); LANES]) {}
    #[inline(always)]
    fn lane(_: &(), _: usize) {}
}

impl InLanes for RollingMemory {
    type Lanes = RollingMemory<Lanes>;
    #[inline(always)]
    fn gather(e: [&RollingMemory; LANES]) -> RollingMemory<Lanes> {
        RollingMemory { m_prev: gather(|l| e[l].m_prev), taken: gather(|l| e[l].taken) }
    }
    #[inline(always)]
    fn lane(e: &RollingMemory<Lanes>, l: usize) -> RollingMemory {
        RollingMemory { m_prev: e.m_prev.extract(l), taken: e.taken.extract(l) }
    }
}

impl<R: Real, S> RollingEnergy<R, S> for () {
    #[inline(always)]
    fn step(&mut self, _: S, _: S, _: R) {}
    #[inline(always)]
    fn release(&mut self, _: S, _: R) {}
    #[inline(always)]
    fn take(&mut self) -> R {
        R::zero()
    }
    #[inline(always)]
    fn taken(&self) -> R {
        R::zero()
    }
}

/// The rolling torque's energy memory of one contact (or one per lane).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RollingMemory<R = f64> {
    /// The previous step's torque on grain i, N m.
    pub m_prev: R,
    /// Work the torques took from the grains since the ledger last took it, J.
    pub taken: R,
}

impl<R: Real> RollingEnergy<R> for RollingMemory<R> {
    #[inline(always)]
    fn step(&mut self, m: R, w: R, dt: R) {
        // The torques' power on the two grains is M (w_i - w_j).
        self.taken -= k::<R>(0.5) * (self.m_prev + m) * w * dt;
        self.m_prev = m;
    }
    #[inline(always)]
    fn release(&mut self, w: R, dt: R) {
        self.taken -= k::<R>(0.5) * self.m_prev * w * dt;
        self.m_prev = R::zero();
    }
    #[inline(always)]
    fn take(&mut self) -> R {
        std::mem::replace(&mut self.taken, R::zero())
    }
    #[inline(always)]
    fn taken(&self) -> R {
        self.taken
    }
}

/// No rolling resistance.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoRolling;

impl<D: Dim> Rolling<D> for NoRolling {
    const NAME: &'static str = "";
    const ON: bool = false;
    type Energy = ();
    type History<R: Real> = ();
    type Saved = ();
    fn save(_: ()) {}
    fn load(_: ()) {}
    #[inline(always)]
    fn gather(_: [&(); LANES]) {}
    #[inline(always)]
    fn lane(_: &(), _: usize) {}
    #[inline(always)]
    fn torque<R: Real>(&self, _: &mut (), _: &RollingInput<R, D>) -> D::Spin<R> {
        D::spin_zero()
    }
}

/// Constant directional torque (LIGGGHTS `rolling_friction cdt`).
#[derive(Clone, Copy, Debug, Default)]
pub struct Cdt;

impl Rolling for Cdt {
    const NAME: &'static str = "CDT rolling";
    const ON: bool = true;
    type Energy = RollingMemory;
    type History<R: Real> = ();
    type Saved = ();
    fn save(_: ()) {}
    fn load(_: ()) {}
    #[inline(always)]
    fn gather(_: [&(); LANES]) {}
    #[inline(always)]
    fn lane(_: &(), _: usize) {}
    #[inline(always)]
    fn torque<R: Real>(&self, _: &mut (), inp: &RollingInput<R>) -> R {
        // LIGGGHTS' order of operations: w (mu kn dn R* / |w|).
        let m = inp.w * (inp.mu * inp.elastic_normal * inp.r_star / inp.w.simd_abs());
        -pick(inp.w.simd_eq(R::zero()), R::zero(), m)
    }
}

/// The torque spring's limit: `m` scaled down to `cap` (>= 0) in magnitude, the same
/// bits when it is within.
#[inline(always)]
fn capped<R: Real>(m: R, cap: R) -> R {
    let mag = m.simd_abs();
    pick(mag.simd_gt(cap), m * (cap / mag), m)
}

/// Elastic-plastic torque spring (LIGGGHTS `rolling_friction epsd2`). The state is the
/// spring's torque m, N m.
#[derive(Clone, Copy, Debug, Default)]
pub struct Epsd2;

impl Rolling for Epsd2 {
    const NAME: &'static str = "EPSD2 rolling";
    const ON: bool = true;
    type Energy = RollingMemory;
    type History<R: Real> = R;
    type Saved = f64;
    fn save(h: f64) -> f64 {
        h
    }
    fn load(s: f64) -> f64 {
        s
    }
    #[inline(always)]
    fn gather(h: [&f64; LANES]) -> Lanes {
        gather(|l| *h[l])
    }
    #[inline(always)]
    fn lane(h: &Lanes, l: usize) -> f64 {
        h.extract(l)
    }
    #[inline(always)]
    fn torque<R: Real>(&self, m: &mut R, inp: &RollingInput<R>) -> R {
        let kr = inp.kt * inp.r_star * inp.r_star;
        let trial = *m + inp.w * (inp.dt * kr);
        *m = capped(trial, inp.normal.simd_abs() * inp.r_star * inp.mu);
        -*m
    }
}

/// Spring-dashpot-slider on the rolling displacement (LAMMPS `rolling sds`), of
/// stiffness `k` (N/m) and damping `g` (kg/s). The state is the rolling displacement
/// s, m (LAMMPS keeps it as a vector in the tangent plane, projected and rescaled to
/// its length when the normal turns: in the plane, the same scalar).
#[derive(Clone, Copy, Debug)]
pub struct Sds {
    /// Stiffness k, N/m.
    pub k: f64,
    /// Damping coefficient g, kg/s.
    pub g: f64,
}

impl Rolling for Sds {
    const NAME: &'static str = "SDS rolling";
    const ON: bool = true;
    type Energy = RollingMemory;
    type History<R: Real> = R;
    type Saved = f64;
    fn save(h: f64) -> f64 {
        h
    }
    fn load(s: f64) -> f64 {
        s
    }
    #[inline(always)]
    fn gather(h: [&f64; LANES]) -> Lanes {
        gather(|l| *h[l])
    }
    #[inline(always)]
    fn lane(h: &Lanes, l: usize) -> f64 {
        h.extract(l)
    }
    #[inline(always)]
    fn torque<R: Real>(&self, s: &mut R, inp: &RollingInput<R>) -> R {
        let (kr, g) = (k::<R>(self.k), k::<R>(self.g));
        let vr = inp.r_star * inp.w;
        *s += vr * inp.dt;
        let f = -(kr * *s) - g * vr;
        let cap = inp.mu * inp.normal.simd_abs();
        let mag = f.simd_abs();
        let fc = f * (cap / mag);
        // Sliding: the displacement that gives the capped force; none (and no force)
        // when the displacement is 0, as LAMMPS.
        let (slide, still) = (mag.simd_gt(cap), s.simd_eq(R::zero()));
        *s = pick(slide, pick(still, *s, k::<R>(-1.0 / self.k) * (fc + g * vr)), *s);
        let f = pick(slide, pick(still, R::zero(), fc), f);
        inp.r_star * f
    }
    fn label(&self) -> String {
        format!("SDS rolling(k {} N/m, g {} kg/s)", self.k, self.g)
    }
}
