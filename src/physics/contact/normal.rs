//! The normal law of a contact: its stiffnesses from the overlap, and the elastic energy
//! it stores. Two families, each a compile-time sub-model of [`super::ContactModel`]:
//!
//! - [`Hertz`]: `kn = 4/3 E* sqrt(R* dn)` (secant stiffness, F = kn dn),
//!   `Sn = 2 E* sqrt(R* dn)` (tangent stiffness dF/d dn), `kt = St = 8 G* sqrt(R* dn)`
//!   (Mindlin's tangential stiffness without micro-slip); stored energy `2/5 kn dn^2`.
//! - [`Hooke`]: a linear spring, `F = kn dn`, `Sn = kn`, constant in the overlap; stored
//!   energy `1/2 kn dn^2`. Either given (`kn`, `kt` in N/m, LIGGGHTS `model
//!   hooke/stiffness`) or derived per pair from a characteristic velocity `vc` (LIGGGHTS
//!   `model hooke`): `kn = kt = 16/15 sqrt(R*) E* (15 m* vc^2 / (16 sqrt(R*) E*))^(1/5)`,
//!   the stiffness whose linear contact has the Hertz maximum overlap at impact speed vc.
//!
//! [`NormalLaw`] is the scene's choice (`model.normal`), with the scalar formulas the time
//! step rules need: the elastic contact time and the stiffnesses at the largest overlap of
//! an impact.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::physics::lanes::{Real, k};
use crate::physics::material::{PairMaterial, hertz_contact_time, hertz_max_overlap};

/// Stiffnesses of one contact at overlap `dn` (or of one contact per lane).
#[derive(Clone, Copy, Debug)]
pub struct Stiffness<R = f64> {
    /// Normal secant stiffness kn, N/m: the elastic normal force is kn dn.
    pub kn: R,
    /// Normal tangent stiffness Sn = dF/d dn, N/m.
    pub sn: R,
    /// Tangential stiffness kt, N/m.
    pub kt: R,
    /// sqrt(R* dn), m (Hertz: the viscoelastic damping grows with its square root; 0 for
    /// Hooke, whose damping does not read it).
    pub root: R,
}

impl<R: Real> Stiffness<R> {
    /// The Hertz-Mindlin stiffnesses of moduli `e_star`, `g_star` (Pa), reduced radius
    /// `r_star` (m) at overlap `dn` (m).
    #[inline(always)]
    pub fn new(e_star: R, g_star: R, r_star: R, dn: R) -> Self {
        let sqrtval = (r_star * dn).simd_sqrt();
        let sn = k::<R>(2.0) * e_star * sqrtval;
        let kt = k::<R>(8.0) * g_star * sqrtval;
        Stiffness { kn: k::<R>(4.0 / 3.0) * e_star * sqrtval, sn, kt, root: sqrtval }
    }
}

/// Elastic energy stored in a Hertz contact, `2/5 kn dn^2`, J.
#[inline(always)]
pub fn hertz_energy<R: Real>(kn: R, dn: R) -> R {
    k::<R>(0.4) * kn * dn * dn
}

/// A normal law, compiled into the contact kernel.
pub trait Normal: Copy + Send + Sync + std::fmt::Debug + 'static {
    /// Its name in `explain`.
    const NAME: &'static str;
    /// The stiffnesses of a contact of materials `pm`, reduced radius `r_star` (m) and
    /// square root of the reduced mass `sqrt_m_star` (kg^1/2) at overlap `dn` (m).
    fn stiffness<R: Real>(&self, pm: &PairMaterial<R>, r_star: R, sqrt_m_star: R, dn: R) -> Stiffness<R>;
    /// The elastic energy a contact of secant stiffness `kn` (N/m) stores at overlap `dn`
    /// (m), J.
    fn energy(kn: f64, dn: f64) -> f64;
    /// The law and its parameters in one word or a few, for `explain` and checkpoints.
    fn label(&self) -> String {
        Self::NAME.to_string()
    }
}

/// Hertz's normal law with Mindlin's tangential stiffness.
#[derive(Clone, Copy, Debug, Default)]
pub struct Hertz;

impl Normal for Hertz {
    const NAME: &'static str = "Hertz";
    #[inline(always)]
    fn stiffness<R: Real>(&self, pm: &PairMaterial<R>, r_star: R, _: R, dn: R) -> Stiffness<R> {
        Stiffness::new(pm.e_star, pm.g_star, r_star, dn)
    }
    #[inline(always)]
    fn energy(kn: f64, dn: f64) -> f64 {
        hertz_energy(kn, dn)
    }
}

/// The linear spring: stiffnesses given, or derived per pair from a characteristic
/// velocity (one predictable branch on the rule, the same for every contact).
#[derive(Clone, Copy, Debug)]
pub enum Hooke {
    /// `kn = kt = 16/15 sqrt(R*) E* (15 m* vc^2 / (16 sqrt(R*) E*))^(1/5)`; holds vc,
    /// m/s.
    Derived { vc: f64 },
    /// Given stiffnesses, N/m.
    Given { kn: f64, kt: f64 },
}

impl Normal for Hooke {
    const NAME: &'static str = "Hooke";
    #[inline(always)]
    fn stiffness<R: Real>(&self, pm: &PairMaterial<R>, r_star: R, sqrt_m_star: R, _: R) -> Stiffness<R> {
        match *self {
            Hooke::Given { kn, kt } => Stiffness { kn: k(kn), sn: k(kn), kt: k(kt), root: R::zero() },
            Hooke::Derived { vc } => {
                let (sqrtval, vc) = (r_star.simd_sqrt(), k::<R>(vc));
                let m_star = sqrt_m_star * sqrt_m_star;
                let arg = k::<R>(15.0) * m_star * vc * vc / (k::<R>(16.0) * sqrtval * pm.e_star);
                let kn = k::<R>(16.0 / 15.0) * sqrtval * pm.e_star * fifth_root(arg);
                Stiffness { kn, sn: kn, kt: kn, root: R::zero() }
            }
        }
    }
    #[inline(always)]
    fn energy(kn: f64, dn: f64) -> f64 {
        0.5 * kn * dn * dn
    }
    fn label(&self) -> String {
        match *self {
            Hooke::Derived { vc } => format!("Hooke(vc {vc} m/s)"),
            Hooke::Given { kn, kt } => format!("Hooke(kn {kn} N/m, kt {kt} N/m)"),
        }
    }
}

/// `x^(1/5)` lane by lane, with the scalar `powf` in each (the same bits alone or in lanes).
#[inline(always)]
fn fifth_root<R: Real>(x: R) -> R {
    let mut out = x;
    for l in 0..R::LANES {
        out.replace(l, x.extract(l).powf(0.2));
    }
    out
}

/// The scene's normal law (`model.normal`). Default `"hertz"`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum NormalLaw {
    /// Hertz: `kn = 4/3 E* sqrt(R* dn)`, `kt = 8 G* sqrt(R* dn)`, with the viscoelastic
    /// damping `beta(e)` (the default).
    #[default]
    Hertz,
    /// Linear spring with stiffnesses derived per pair from the materials and a
    /// characteristic velocity (LIGGGHTS `model hooke`):
    /// `kn = kt = 16/15 sqrt(R*) E* (15 m* vc^2 / (16 sqrt(R*) E*))^(1/5)`, and the
    /// damping that gives the pair's restitution e exactly.
    Hooke {
        /// vc, m/s, > 0: the speed at which the spring's largest overlap equals Hertz's.
        characteristic_velocity: f64,
    },
    /// Linear spring with given stiffnesses (LIGGGHTS `model hooke/stiffness`), and the
    /// damping that gives the pair's restitution e exactly.
    HookeStiffness {
        /// Normal stiffness kn, N/m, > 0.
        kn: f64,
        /// Tangential stiffness kt, N/m, > 0.
        kt: f64,
    },
}

impl NormalLaw {
    /// True for the default (left out of written scenes).
    pub fn is_hertz(&self) -> bool {
        *self == NormalLaw::Hertz
    }

    /// The linear spring this law compiles to, if it is one.
    pub fn hooke(&self) -> Option<Hooke> {
        match *self {
            NormalLaw::Hertz => None,
            NormalLaw::Hooke { characteristic_velocity: vc } => Some(Hooke::Derived { vc }),
            NormalLaw::HookeStiffness { kn, kt } => Some(Hooke::Given { kn, kt }),
        }
    }

    /// Its name for messages and explain.
    pub fn name(&self) -> &'static str {
        match self {
            NormalLaw::Hertz => "hertz",
            NormalLaw::Hooke { .. } => "hooke",
            NormalLaw::HookeStiffness { .. } => "hooke_stiffness",
        }
    }

    /// The stiffnesses of a contact of materials `pm`, reduced radius `r_star` (m) and
    /// reduced mass `m_star` (kg) at overlap `dn` (m).
    pub fn stiffness(&self, pm: &PairMaterial, r_star: f64, m_star: f64, dn: f64) -> Stiffness {
        match self.hooke() {
            None => Hertz.stiffness(pm, r_star, m_star.sqrt(), dn),
            Some(h) => h.stiffness(pm, r_star, m_star.sqrt(), dn),
        }
    }

    /// The elastic (undamped) contact time of a head-on impact at speed `v` (m/s), s:
    /// Hertz `2.868 (m*^2 / (R* E*^2 v))^(1/5)`, the linear spring `pi sqrt(m*/kn)`.
    pub fn contact_time(&self, pm: &PairMaterial, r_star: f64, m_star: f64, v: f64) -> f64 {
        match self {
            NormalLaw::Hertz => hertz_contact_time(m_star, r_star, pm.e_star, v),
            _ => std::f64::consts::PI * (m_star / self.stiffness(pm, r_star, m_star, 0.0).kn).sqrt(),
        }
    }

    /// The largest overlap of an elastic head-on impact at speed `v` (m/s), m: Hertz
    /// `(15 m* v^2 / (16 E* sqrt R*))^(2/5)`, the linear spring `v sqrt(m*/kn)`.
    pub fn max_overlap(&self, pm: &PairMaterial, r_star: f64, m_star: f64, v: f64) -> f64 {
        match self {
            NormalLaw::Hertz => hertz_max_overlap(m_star, r_star, pm.e_star, v),
            _ => v * (m_star / self.stiffness(pm, r_star, m_star, 0.0).kn).sqrt(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::material::Material;
    use simba::simd::SimdValue;

    /// The derived linear spring has the Hertz maximum overlap at the characteristic
    /// velocity: energy 1/2 m* v^2 = 1/2 kn d^2 and Hertz's d = (15 m* v^2 / (16 E* sqrt R*))^(2/5)
    /// give kn = m* v^2 / d^2, the closed form LIGGGHTS writes differently.
    #[test]
    fn derived_spring_matches_hertz_overlap_at_its_velocity() {
        let pm = PairMaterial::mix(&Material::default(), &Material::default());
        let (r_star, m_star, v) = (0.5e-3, 2.6e-6, 0.7);
        let law = NormalLaw::Hooke { characteristic_velocity: v };
        let d_hooke = law.max_overlap(&pm, r_star, m_star, v);
        let d_hertz = NormalLaw::Hertz.max_overlap(&pm, r_star, m_star, v);
        // Both closed forms in double precision: a few ulps apart.
        assert!((d_hooke / d_hertz - 1.0).abs() < 1e-14, "{d_hooke} {d_hertz}");
    }

    /// The lanes give each contact the bits it gets alone.
    #[test]
    fn derived_spring_in_lanes_is_bitwise_the_scalar() {
        use crate::physics::lanes::{LANES, Lanes, gather};
        let pm = PairMaterial::mix(&Material::default(), &Material::default());
        let h = Hooke::Derived { vc: 0.7 };
        let r = [1e-3, 2e-3, 0.7e-3, 5e-4];
        let m: [f64; 4] = [1e-6, 3e-6, 2e-6, 7e-7];
        let lanes = h.stiffness(&PairMaterial::gather([&pm; LANES]), gather(|l| r[l]), gather(|l| m[l].sqrt()), Lanes::splat(0.0));
        for l in 0..LANES {
            let one = h.stiffness(&pm, r[l], m[l].sqrt(), 0.0);
            assert_eq!(lanes.kn.extract(l).to_bits(), one.kn.to_bits());
        }
    }
}
