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

use crate::physics::lanes::Real;
use crate::physics::material::PairMaterial;

/// How the damping coefficients follow from the stiffnesses.
pub trait Damping: Copy + Default + Send + Sync + 'static {
    const NAME: &'static str;
    /// `(gn, gt)`, kg/s, from the pair's materials, `sqrt(m*)` (kg^1/2) and
    /// `sqrt(R* dn)` (m).
    fn coefficients<R: Real>(pm: &PairMaterial<R>, sqrt_m_star: R, root: R) -> (R, R);
}

pub use crate::physics::material::SQRT_FIVE_SIXTHS;

#[derive(Clone, Copy, Debug, Default)]
pub struct Viscoelastic;

impl Damping for Viscoelastic {
    const NAME: &'static str = "Viscoelastic";
    #[inline(always)]
    fn coefficients<R: Real>(pm: &PairMaterial<R>, sqrt_m_star: R, root: R) -> (R, R) {
        let s = sqrt_m_star * root.simd_sqrt();
        (pm.viscous_n * s, pm.viscous_t * s)
    }
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Undamped;

impl Damping for Undamped {
    const NAME: &'static str = "Undamped";
    #[inline(always)]
    fn coefficients<R: Real>(_: &PairMaterial<R>, _: R, _: R) -> (R, R) {
        (R::zero(), R::zero())
    }
}
