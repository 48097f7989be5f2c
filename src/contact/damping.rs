//! Viscous damping of the contact, or none.
//!
//! [`Viscoelastic`]: `gn = -2 sqrt(5/6) beta sqrt(Sn m*)`, `gt = -2 sqrt(5/6) beta sqrt(St m*)`
//! with `beta = ln e / sqrt(ln^2 e + pi^2)` (Tsuji's form as in LIGGGHTS `model hertz`
//! and YADE `betan = betas = sqrt(5/6) |beta|`). The damping force is `-g v` along the
//! relative velocity. [`Undamped`] is what a scene with e = 1 everywhere gets: no
//! coefficients are computed at all.

use crate::lanes::{Real, k};

/// How the damping coefficients follow from the stiffnesses.
pub trait Damping: Copy + Default + Send + Sync + 'static {
    const NAME: &'static str;
    /// `(gn, gt)`, kg/s, from `beta`, the tangent stiffnesses `Sn`, `St` (N/m) and `m*` (kg).
    fn coefficients<R: Real>(beta: R, sn: R, st: R, m_star: R) -> (R, R);
}

/// sqrt(5/6).
pub const SQRT_FIVE_SIXTHS: f64 = 0.912_870_929_175_276_9;

#[derive(Clone, Copy, Debug, Default)]
pub struct Viscoelastic;

impl Damping for Viscoelastic {
    const NAME: &'static str = "Viscoelastic";
    #[inline(always)]
    fn coefficients<R: Real>(beta: R, sn: R, st: R, m_star: R) -> (R, R) {
        let c = k::<R>(-2.0 * SQRT_FIVE_SIXTHS) * beta;
        (c * (sn * m_star).simd_sqrt(), c * (st * m_star).simd_sqrt())
    }
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Undamped;

impl Damping for Undamped {
    const NAME: &'static str = "Undamped";
    #[inline(always)]
    fn coefficients<R: Real>(_: R, _: R, _: R, _: R) -> (R, R) {
        (R::zero(), R::zero())
    }
}
