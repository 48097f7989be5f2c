//! Hertz normal contact: stiffnesses from the overlap.
//!
//! `kn = 4/3 E* sqrt(R* dn)` (secant stiffness, F = kn dn), `Sn = 2 E* sqrt(R* dn)`
//! (tangent stiffness dF/d dn), `kt = St = 8 G* sqrt(R* dn)` (Mindlin's tangential
//! stiffness without micro-slip).

use crate::physics::lanes::{Real, k};

/// Stiffnesses of one Hertz contact at overlap `dn` (or of one contact per lane).
#[derive(Clone, Copy, Debug)]
pub struct HertzStiffness<R = f64> {
    /// Normal secant stiffness kn, N/m.
    pub kn: R,
    /// Normal tangent stiffness Sn, N/m.
    pub sn: R,
    /// Tangential stiffness kt = St, N/m.
    pub kt: R,
    /// sqrt(R* dn), m (the damping coefficients grow with its square root).
    pub root: R,
}

impl<R: Real> HertzStiffness<R> {
    #[inline(always)]
    pub fn new(e_star: R, g_star: R, r_star: R, dn: R) -> Self {
        let sqrtval = (r_star * dn).simd_sqrt();
        let sn = k::<R>(2.0) * e_star * sqrtval;
        let kt = k::<R>(8.0) * g_star * sqrtval;
        HertzStiffness { kn: k::<R>(4.0 / 3.0) * e_star * sqrtval, sn, kt, root: sqrtval }
    }
}

/// Elastic energy stored in a Hertz contact, `2/5 kn dn^2`, J.
#[inline(always)]
pub fn hertz_energy<R: Real>(kn: R, dn: R) -> R {
    k::<R>(0.4) * kn * dn * dn
}
