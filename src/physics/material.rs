//! Materials and the pair mixing rules of the Hertz-Mindlin law.
//!
//! Every quantity is SI. The mixing rules are those of LIGGGHTS 3.8 (and YADE since
//! 2023.02): `E* = 1/((1-nu1^2)/E1 + (1-nu2^2)/E2)`,
//! `G* = 1/(2(2-nu1)(1+nu1)/E1 + 2(2-nu2)(1+nu2)/E2)`. A pair's restitution and
//! friction are the smaller of the two materials' values (YADE takes the smaller friction
//! angle; LIGGGHTS needs a per-pair matrix, which the exporter writes from this rule).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::error::{Error, check};

/// sqrt(5/6): the factor of Tsuji's viscoelastic damping
/// ([`crate::physics::contact::damping`]), which the pair coefficients fold in.
pub const SQRT_FIVE_SIXTHS: f64 = 0.912_870_929_175_276_9;

/// One grain or wall material.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// A name for output and exported decks. Default `"glass"`.
    #[serde(default = "default_name")]
    pub name: String,
    /// Young's modulus E, Pa, > 0. Default 63e9 (soda-lime glass).
    #[serde(default = "default_e")]
    pub youngs_modulus: f64,
    /// Poisson's ratio nu, in [0, 0.5). Default 0.2.
    #[serde(default = "default_nu")]
    pub poisson_ratio: f64,
    /// Density rho, kg/m^3, > 0. Default 2500.
    #[serde(default = "default_rho")]
    pub density: f64,
    /// Normal coefficient of restitution e, in [0, 1]. Default 0.9. e = 0 (perfectly
    /// plastic) gives beta = -1, critical damping: without the clamp the grains stay
    /// together (the overlap fades, they never part); the clamped damping
    /// (`model.damping = "clamped_restitution"`) cannot reach it and refuses it.
    #[serde(default = "default_e_rest")]
    pub restitution: f64,
    /// Coulomb friction coefficient mu, >= 0. Default 0.5.
    #[serde(default = "default_mu")]
    pub friction: f64,
    /// Work of adhesion w (the energy per unit area it takes to part two surfaces in
    /// contact, twice the surface energy of a like pair), J/m^2, >= 0. Default 0: no
    /// cohesion. Above 0 the contact law adds DMT cohesion: a constant attraction
    /// `2 pi w R*` while the grains overlap ([`crate::physics::contact::cohesion`]). A
    /// pair takes the geometric mean `sqrt(w1 w2)`. Left out of written scenes when 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub work_of_adhesion: f64,
    /// Rolling friction coefficient mu_r, >= 0, dimensionless: the largest rolling torque
    /// is `mu_r R* |Fn|` (LIGGGHTS' `coefficientRollingFriction`, LAMMPS' `mu_roll`). Read
    /// only when `model.rolling` names a law
    /// ([`crate::physics::contact::rolling`]). A pair takes the smaller. Default 0; left
    /// out of written scenes when 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub rolling_friction: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

fn default_name() -> String {
    "glass".into()
}
fn default_e() -> f64 {
    63e9
}
fn default_nu() -> f64 {
    0.2
}
fn default_rho() -> f64 {
    2500.0
}
fn default_e_rest() -> f64 {
    0.9
}
fn default_mu() -> f64 {
    0.5
}

impl Default for Material {
    fn default() -> Self {
        Material {
            name: default_name(),
            youngs_modulus: default_e(),
            poisson_ratio: default_nu(),
            density: default_rho(),
            restitution: default_e_rest(),
            friction: default_mu(),
            work_of_adhesion: 0.0,
            rolling_friction: 0.0,
        }
    }
}

impl Material {
    /// Check every field against its allowed range; `at` is the field path for messages.
    pub fn validate(&self, at: &str) -> Result<(), Error> {
        let e = self.youngs_modulus;
        check(e.is_finite() && e > 0.0, at, "youngs_modulus", e, "> 0 Pa")?;
        let nu = self.poisson_ratio;
        check((0.0..0.5).contains(&nu), at, "poisson_ratio", nu, "[0, 0.5)")?;
        let rho = self.density;
        check(rho.is_finite() && rho > 0.0, at, "density", rho, "> 0 kg/m^3")?;
        let r = self.restitution;
        check((0.0..=1.0).contains(&r), at, "restitution", r, "[0, 1] (0: the grains never part, with the default damping)")?;
        let mu = self.friction;
        check(mu.is_finite() && mu >= 0.0, at, "friction", mu, ">= 0")?;
        let w = self.work_of_adhesion;
        check(w.is_finite() && w >= 0.0, at, "work_of_adhesion", w, ">= 0 J/m^2")?;
        let mr = self.rolling_friction;
        check(mr.is_finite() && mr >= 0.0, at, "rolling_friction", mr, ">= 0")?;
        Ok(())
    }

    /// Shear modulus G = E / (2 (1 + nu)), Pa.
    pub fn shear_modulus(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }
}

pub use crate::physics::restitution::beta;
use crate::physics::restitution::clamped_beta;

/// How a pair's damping `beta` follows from its restitution e.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BetaRule {
    /// `beta(e)`, which returns e when the normal force may turn attractive at the end of
    /// contact (the default damping).
    #[default]
    Free,
    /// The beta that returns e under the clamp `Fn >= 0`, for either normal law
    /// ([`crate::physics::restitution::clamped_beta`]; `model.damping =
    /// "clamped_restitution"`).
    Clamped,
}

impl BetaRule {
    /// The pair's beta for restitution `e` (validation has refused e = 0 for the clamped
    /// rule, which has no finite beta; it falls back to beta(e) there).
    pub fn beta(self, e: f64) -> f64 {
        match self {
            BetaRule::Free => beta(e),
            BetaRule::Clamped => clamped_beta(e).unwrap_or_else(|| beta(e)),
        }
    }
}

/// The mixed properties of one material pair (`R = Lanes`: of four pairs, one per lane).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairMaterial<R = f64> {
    /// Effective Young's modulus E*, Pa.
    pub e_star: R,
    /// Effective shear modulus G*, Pa.
    pub g_star: R,
    /// Restitution of the pair (the smaller one).
    pub restitution: R,
    /// beta(e) of the pair.
    pub beta: R,
    /// Friction coefficient of the pair (the smaller one).
    pub friction: R,
    /// `-2 sqrt(5/6) beta sqrt(2 E*)`, Pa^1/2: the viscoelastic normal damping is
    /// `gn = viscous_n sqrt(m*) (R* dn)^(1/4)` ([`crate::physics::contact::damping`]).
    pub viscous_n: R,
    /// `-2 sqrt(5/6) beta sqrt(8 G*)`, Pa^1/2: `gt = viscous_t sqrt(m*) (R* dn)^(1/4)`.
    pub viscous_t: R,
    /// `2 pi w` with w the pair's work of adhesion, N/m: the DMT pull-off force is
    /// `pulloff R*` ([`crate::physics::contact::cohesion`]).
    pub pulloff: R,
    /// Rolling friction coefficient mu_r of the pair (the smaller one).
    pub rolling_friction: R,
}

impl PairMaterial<crate::physics::lanes::Lanes> {
    /// Four pairs' properties in lanes.
    #[inline(always)]
    pub fn gather(pm: [&PairMaterial; crate::physics::lanes::LANES]) -> Self {
        use crate::physics::lanes::gather;
        PairMaterial {
            e_star: gather(|l| pm[l].e_star),
            g_star: gather(|l| pm[l].g_star),
            restitution: gather(|l| pm[l].restitution),
            beta: gather(|l| pm[l].beta),
            friction: gather(|l| pm[l].friction),
            viscous_n: gather(|l| pm[l].viscous_n),
            viscous_t: gather(|l| pm[l].viscous_t),
            pulloff: gather(|l| pm[l].pulloff),
            rolling_friction: gather(|l| pm[l].rolling_friction),
        }
    }
}

impl PairMaterial {
    /// The pair's work of adhesion w, J/m^2 (from [`PairMaterial::pulloff`] = 2 pi w).
    pub fn work_of_adhesion(&self) -> f64 {
        self.pulloff / (2.0 * std::f64::consts::PI)
    }

    /// The pair's properties with the default damping's `beta(e)` ([`BetaRule::Free`]).
    pub fn mix(a: &Material, b: &Material) -> Self {
        Self::mix_with(a, b, BetaRule::Free)
    }

    /// The pair's properties with the scene's rule for beta (`Scene::model.beta_rule()`).
    pub fn mix_with(a: &Material, b: &Material, rule: BetaRule) -> Self {
        let (e1, n1, e2, n2) = (a.youngs_modulus, a.poisson_ratio, b.youngs_modulus, b.poisson_ratio);
        let e_star = 1.0 / ((1.0 - n1 * n1) / e1 + (1.0 - n2 * n2) / e2);
        let g_star = 1.0 / (2.0 * (2.0 - n1) * (1.0 + n1) / e1 + 2.0 * (2.0 - n2) * (1.0 + n2) / e2);
        let restitution = a.restitution.min(b.restitution);
        let beta = rule.beta(restitution);
        let c = -2.0 * SQRT_FIVE_SIXTHS * beta;
        let (viscous_n, viscous_t) = (c * (2.0 * e_star).sqrt(), c * (8.0 * g_star).sqrt());
        let pulloff = 2.0 * std::f64::consts::PI * (a.work_of_adhesion * b.work_of_adhesion).sqrt();
        PairMaterial { e_star, g_star, restitution, beta, friction: a.friction.min(b.friction), viscous_n, viscous_t, pulloff, rolling_friction: a.rolling_friction.min(b.rolling_friction) }
    }
}

/// Mixed properties for every pair of materials, indexed `[i * n + j]`.
#[derive(Clone, Debug)]
pub struct PairTable {
    n: usize,
    pairs: Vec<PairMaterial>,
}

impl PairTable {
    pub fn new(materials: &[Material], rule: BetaRule) -> Self {
        let n = materials.len();
        let mut pairs = Vec::with_capacity(n * n);
        for a in materials {
            for b in materials {
                pairs.push(PairMaterial::mix_with(a, b, rule));
            }
        }
        PairTable { n, pairs }
    }
    /// The one pair of a scene with one material.
    pub fn single(&self) -> Option<&PairMaterial> {
        if self.n == 1 { self.pairs.first() } else { None }
    }
    #[inline(always)]
    pub fn get(&self, i: usize, j: usize) -> &PairMaterial {
        &self.pairs[i * self.n + j]
    }
    pub fn iter(&self) -> impl Iterator<Item = &PairMaterial> {
        self.pairs.iter()
    }
}

/// Reduced radius R* = r1 r2 / (r1 + r2), m.
pub fn reduced(a: f64, b: f64) -> f64 {
    a * b / (a + b)
}

/// Hertz contact duration of an elastic impact, `t_c = 2.868 (m*^2 / (R* E*^2 v))^(1/5)`, s.
pub fn hertz_contact_time(m_star: f64, r_star: f64, e_star: f64, v: f64) -> f64 {
    2.868 * (m_star * m_star / (r_star * e_star * e_star * v)).powf(0.2)
}

/// Hertz contact duration of an elastic impact with its constant in closed form:
/// `t_c = 2 (15/16)^(2/5) sqrt(pi) Gamma(7/5) / Gamma(9/10) (m*^2 / (R* E*^2 v))^(1/5)`,
/// s (the constant is 2.86829...; [`hertz_contact_time`] rounds it to 2.868, which the
/// time step rules keep so that their time steps stay what they were). From the energy
/// integral: `t_c = 2 (dn_max / v) int_0^1 (1 - u^(5/2))^(-1/2) du`, the integral a Beta
/// function.
pub fn hertz_contact_time_exact(m_star: f64, r_star: f64, e_star: f64, v: f64) -> f64 {
    use statrs::function::gamma::gamma;
    let c = 2.0 * (15.0f64 / 16.0).powf(0.4) * std::f64::consts::PI.sqrt() * gamma(1.4) / gamma(0.9);
    c * (m_star * m_star / (r_star * e_star * e_star * v)).powf(0.2)
}

/// Maximum overlap of an elastic Hertz impact, `(15 m* v^2 / (16 E* sqrt R*))^(2/5)`, m.
pub fn hertz_max_overlap(m_star: f64, r_star: f64, e_star: f64, v: f64) -> f64 {
    (15.0 * m_star * v * v / (16.0 * e_star * r_star.sqrt())).powf(0.4)
}

/// Rayleigh wave time of a grain, `pi r sqrt(rho/G) / (0.1631 nu + 0.8766)`, s.
pub fn rayleigh_time(radius: f64, m: &Material) -> f64 {
    std::f64::consts::PI * radius * (m.density / m.shear_modulus()).sqrt() / (0.1631 * m.poisson_ratio + 0.8766)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn equal_materials_mix_to_the_textbook_values() {
        // For two equal materials E* = E / (2 (1 - nu^2)) and G* = G / (2 (2 - nu)).
        let g = Material::default();
        let p = PairMaterial::mix(&g, &g);
        assert_relative_eq!(p.e_star, 63e9 / (2.0 * 0.96), max_relative = 1e-15);
        assert_relative_eq!(p.g_star, g.shear_modulus() / (2.0 * 1.8), max_relative = 1e-15);
    }

    #[test]
    fn beta_is_zero_at_e_one_and_tends_to_minus_one() {
        assert_eq!(beta(1.0), 0.0);
        assert!(beta(1e-12) < -0.99);
        // ln 0.5 = -0.693..., beta = -0.2155...
        assert_relative_eq!(beta(0.5), -0.2155, epsilon = 1e-4);
    }
}
