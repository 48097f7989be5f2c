//! Hertz normal contact: stiffnesses from the overlap.
//!
//! `kn = 4/3 E* sqrt(R* dn)` (secant stiffness, F = kn dn), `Sn = 2 E* sqrt(R* dn)`
//! (tangent stiffness dF/d dn), `kt = St = 8 G* sqrt(R* dn)` (Mindlin's tangential
//! stiffness without micro-slip).

/// Stiffnesses of one Hertz contact at overlap `dn`.
#[derive(Clone, Copy, Debug)]
pub struct HertzStiffness {
    /// Normal secant stiffness kn, N/m.
    pub kn: f64,
    /// Normal tangent stiffness Sn, N/m.
    pub sn: f64,
    /// Tangential stiffness kt = St, N/m.
    pub kt: f64,
}

impl HertzStiffness {
    #[inline(always)]
    pub fn new(e_star: f64, g_star: f64, r_star: f64, dn: f64) -> Self {
        let sqrtval = (r_star * dn).sqrt();
        let sn = 2.0 * e_star * sqrtval;
        let kt = 8.0 * g_star * sqrtval;
        HertzStiffness { kn: 4.0 / 3.0 * e_star * sqrtval, sn, kt }
    }
}

/// Elastic energy stored in a Hertz contact, `2/5 kn dn^2`, J.
#[inline(always)]
pub fn hertz_energy(kn: f64, dn: f64) -> f64 {
    0.4 * kn * dn * dn
}
