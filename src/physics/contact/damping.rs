//! Viscous damping of the contact, or none.
//!
//! [`Viscoelastic`]: `gn = -2 sqrt(5/6) beta sqrt(Sn m*)`, `gt = -2 sqrt(5/6) beta sqrt(St m*)`
//! with `beta = ln e / sqrt(ln^2 e + pi^2)` (Tsuji's form as in LIGGGHTS `model hertz`
//! and YADE `betan = betas = sqrt(5/6) |beta|`). The damping force is `-g v` along the
//! relative velocity. [`Undamped`] is what a scene with e = 1 everywhere gets: no
//! coefficients are computed at all.
//!
//! With `Sn = 2 E* sqrt(R* dn)` and `St = 8 G* sqrt(R* dn)` the coefficients factor as
//! `gn = cn sqrt(m*) (R* dn)^(1/4)` with `cn = -2 sqrt(5/6) beta sqrt(2 E*)` per material
//! pair ([`crate::physics::material::PairMaterial::viscous_n`]) and `sqrt(m*)` per grain pair
//! (computed once per neighbour-list build): one square root per contact and step instead
//! of two.
//!
//! [`TsujiFit`]: LAMMPS' `damping tsuji`, `gn = alpha(e) sqrt(m* kn)` with kn the secant
//! normal stiffness and alpha LAMMPS' polynomial fit ([`tsuji_alpha`]), for either normal
//! law; it does not return e.
//!
//! [`LinearRestitution`], for the linear spring ([`super::normal::Hooke`]):
//! `gn = -2 beta sqrt(m* kn)`, `gt = -2 beta sqrt(m* kt)`, the same beta(e). The linear
//! spring-dashpot `m* x'' + gn x' + kn x = 0` leaves contact (x = 0, the force allowed to
//! turn attractive) after `t_c = pi / (omega_0 sqrt(1 - beta^2))`, `omega_0 = sqrt(kn/m*)`,
//! with the rebound speed exactly e times the impact speed at every speed (LIGGGHTS
//! `model hooke` writes the same coefficient as `sqrt(4 m* kn / (1 + (pi / ln e)^2))`).

use crate::physics::contact::normal::Stiffness;
use crate::physics::lanes::{Real, k};
use crate::physics::material::PairMaterial;

/// How the damping coefficients follow from the stiffnesses.
pub trait Damping: Copy + Default + Send + Sync + 'static {
    const NAME: &'static str;
    /// `(gn, gt)`, kg/s, from the pair's materials, `sqrt(m*)` (kg^1/2) and the
    /// contact's stiffnesses.
    fn coefficients<R: Real>(pm: &PairMaterial<R>, sqrt_m_star: R, st: &Stiffness<R>) -> (R, R);
}

pub use crate::physics::material::SQRT_FIVE_SIXTHS;

#[derive(Clone, Copy, Debug, Default)]
pub struct Viscoelastic;

impl Damping for Viscoelastic {
    const NAME: &'static str = "Viscoelastic";
    #[inline(always)]
    fn coefficients<R: Real>(pm: &PairMaterial<R>, sqrt_m_star: R, st: &Stiffness<R>) -> (R, R) {
        let s = sqrt_m_star * st.root.simd_sqrt();
        (pm.viscous_n * s, pm.viscous_t * s)
    }
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Undamped;

impl Damping for Undamped {
    const NAME: &'static str = "Undamped";
    #[inline(always)]
    fn coefficients<R: Real>(_: &PairMaterial<R>, _: R, _: &Stiffness<R>) -> (R, R) {
        (R::zero(), R::zero())
    }
}

/// LAMMPS' `damping tsuji` coefficient of the restitution `e`, in LAMMPS' order of terms
/// (GRANULAR's pair_granular.cpp and fix_wall_gran.cpp, 29Sep2021: a fit after Tsuji et
/// al. 1992).
#[inline(always)]
pub fn tsuji_alpha<R: Real>(e: R) -> R {
    let (e2, e3) = (e * e, e * e * e);
    let (e4, e5, e6) = (e3 * e, e3 * e2, e3 * e3);
    k::<R>(1.2728) - k::<R>(4.2783) * e + k::<R>(11.087) * e2 - k::<R>(22.348) * e3 + k::<R>(27.467) * e4 - k::<R>(18.022) * e5 + k::<R>(4.8218) * e6
}

/// LAMMPS' `damping tsuji` (`model.damping = "tsuji"`): `gn = alpha(e) sqrt(m* kn)`,
/// `gt = alpha(e) sqrt(m* kt)` with the secant stiffnesses of the normal law and
/// [`tsuji_alpha`] of the pair's restitution. The realised restitution is not e (see
/// [`crate::scene::DampingSpec::Tsuji`]). With `SQRT2` (`model.damping =
/// "tsuji_sqrt2"`), LAMMPS' current `damping tsuji`, which multiplies the fit by sqrt(2)
/// "for effective mass convention (as in Tsuji 1992)" (its
/// src/GRANULAR/gran_sub_mod_damping.cpp): under Hertz it realises the input e within
/// 1.1e-3 ([`crate::scene::DampingSpec::TsujiSqrt2`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct TsujiFit<const SQRT2: bool = false>;

/// The factor on LAMMPS' Tsuji fit: 1 as LAMMPS 20220106 has it, sqrt(2) as its current
/// release.
pub fn tsuji_factor(sqrt2: bool) -> f64 {
    if sqrt2 { std::f64::consts::SQRT_2 } else { 1.0 }
}

impl<const SQRT2: bool> Damping for TsujiFit<SQRT2> {
    const NAME: &'static str = if SQRT2 { "Tsuji (x sqrt 2)" } else { "Tsuji" };
    #[inline(always)]
    fn coefficients<R: Real>(pm: &PairMaterial<R>, sqrt_m_star: R, st: &Stiffness<R>) -> (R, R) {
        // LAMMPS' order: the fit, times sqrt(2) when asked, then the mass and stiffness.
        let alpha = if SQRT2 { tsuji_alpha(pm.restitution) * k::<R>(std::f64::consts::SQRT_2) } else { tsuji_alpha(pm.restitution) };
        let c = alpha * sqrt_m_star;
        (c * st.kn.simd_sqrt(), c * st.kt.simd_sqrt())
    }
}

/// The linear spring's damping, which returns the pair's restitution exactly in
/// continuous time.
#[derive(Clone, Copy, Debug, Default)]
pub struct LinearRestitution;

impl Damping for LinearRestitution {
    const NAME: &'static str = "LinearRestitution";
    #[inline(always)]
    fn coefficients<R: Real>(pm: &PairMaterial<R>, sqrt_m_star: R, st: &Stiffness<R>) -> (R, R) {
        let c = k::<R>(-2.0) * pm.beta * sqrt_m_star;
        (c * st.kn.simd_sqrt(), c * st.kt.simd_sqrt())
    }
}
