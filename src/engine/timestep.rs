//! Choosing the time step, and the stability limit it must respect.
//!
//! The reference contact for every estimate is the most demanding one a scene has: the
//! smallest grain against another like it, and against a flat wall when there is one.
//! - Contact time at speed v: Hertz `t_c = 2.868 (m*^2 / (R* E*^2 v))^(1/5)`, the linear
//!   spring `pi sqrt(m*/kn)` (elastic, whatever v).
//! - Stability of velocity Verlet: `dt < 2 (sqrt(1 + zeta^2) - zeta) / omega` for each
//!   contact oscillation (`2 / omega` undamped), with `omega_n^2 = Sn / m*` and, with
//!   friction, `omega_t^2 = kt (1/m_i + 1/m_j + a_i^2/I_i + a_j^2/I_j)`, both stiffnesses
//!   taken at the maximum overlap of an impact at the characteristic speed, and their
//!   damping ratios `zeta = g / (2 sqrt(k m))`: normal `sqrt(5/6) |beta|` (Hertz, against
//!   Sn) or `|beta|` (spring), tangential the same times `sqrt(m* (1/m_i + ...))`; Tsuji
//!   `alpha / 2 sqrt(kn / Sn)` and `alpha / 2 sqrt(m* (1/m_i + ...))`. The bound is the
//!   leapfrog's with the damping force at the half-step velocity (the iteration matrix's
//!   trace condition; its determinant condition, `omega dt < 1/zeta`, is looser): it
//!   matters for strong damping, e.g. the clamped damping's |beta| = 4.8 at e = 0.01 has
//!   zeta = 4.4 and a limit of 0.22 / omega.
//! - Rayleigh time of the smallest grain: `pi r sqrt(rho/G) / (0.1631 nu + 0.8766)`.

use serde::Serialize;

use crate::error::{Error, check};
use crate::physics::contact::normal::NormalLaw;
use crate::physics::material::{Material, PairMaterial, rayleigh_time};
use crate::scene::{ModelSpec, TimeStepRule};

/// A reference contact: reduced radius and mass, the pair's moduli, and the inverse
/// tangential mass of the contact point.
#[derive(Clone, Copy, Debug)]
pub struct RefContact {
    pub r_star: f64,
    pub m_star: f64,
    pub pair: PairMaterial,
    /// 1/m_i + 1/m_j + a_i^2/I_i + a_j^2/I_j, 1/kg.
    pub inv_tangential_mass: f64,
}

impl RefContact {
    /// Two like grains of radius `r`, mass `m` and moment of inertia `i`, of one material
    /// (`pair` mixes it with itself).
    pub fn twin(r: f64, m: f64, i: f64, pair: PairMaterial) -> Self {
        RefContact { r_star: r / 2.0, m_star: m / 2.0, pair, inv_tangential_mass: 2.0 / m + 2.0 * r * r / i }
    }
    /// Two grains `a` and `b`, each (radius, mass, moment of inertia), whose materials
    /// `pair` mixes.
    pub fn grains(a: (f64, f64, f64), b: (f64, f64, f64), pair: PairMaterial) -> Self {
        RefContact {
            r_star: crate::physics::material::reduced(a.0, b.0),
            m_star: crate::physics::material::reduced(a.1, b.1),
            pair,
            inv_tangential_mass: 1.0 / a.1 + 1.0 / b.1 + a.0 * a.0 / a.2 + b.0 * b.0 / b.2,
        }
    }
    /// A grain of radius `r`, mass `m`, moment of inertia `i` against a flat wall (R* = r,
    /// m* = m).
    pub fn wall(r: f64, m: f64, i: f64, pair: PairMaterial) -> Self {
        RefContact { r_star: r, m_star: m, pair, inv_tangential_mass: 1.0 / m + r * r / i }
    }
}

/// The chosen time step and what it means.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct TimeStepInfo {
    /// Time step, s.
    pub dt_s: f64,
    /// Elastic contact time of the reference contact at the characteristic speed, s.
    pub contact_time_s: f64,
    /// Steps per contact, t_c / dt.
    pub steps_per_contact: f64,
    /// Stability limit 2 / omega_max, s.
    pub stability_limit_s: f64,
    /// Rayleigh time of the smallest grain, s.
    pub rayleigh_time_s: f64,
    /// Speed used for t_c and the stability limit, m/s.
    pub characteristic_speed_m_s: f64,
    /// The accuracy target that chose dt, if the rule was `accuracy`.
    pub accuracy: Option<AccuracyNote>,
}

/// Velocity Verlet's stability limit for an oscillation at `omega` (rad/s) with damping
/// ratio `zeta`, s.
fn verlet_limit(omega: f64, zeta: f64) -> f64 {
    2.0 * ((1.0 + zeta * zeta).sqrt() - zeta) / omega
}

/// The damping ratios (normal, tangential) of the reference contact `c` whose normal
/// stiffnesses are `kn` (secant) and `sn` (tangent).
fn damping_ratios(model: &ModelSpec, c: &RefContact, kn: f64, sn: f64) -> (f64, f64) {
    let tangential_mass = (c.m_star * c.inv_tangential_mass).sqrt();
    if let Some(factor) = model.damping.tsuji() {
        let half_alpha = 0.5 * crate::physics::contact::damping::tsuji_alpha(c.pair.restitution) * factor;
        return (half_alpha * (kn / sn).sqrt(), half_alpha * tangential_mass);
    }
    let zeta_n = if model.normal == NormalLaw::Hertz { crate::physics::material::SQRT_FIVE_SIXTHS * c.pair.beta.abs() } else { c.pair.beta.abs() };
    (zeta_n, zeta_n * tangential_mass)
}

/// Contact time, stability limit over the reference contacts at speed `v` under the
/// model's normal law and damping.
fn limits(model: &ModelSpec, refs: &[RefContact], v: f64, friction: bool) -> (f64, f64) {
    let law = &model.normal;
    let mut tc = f64::INFINITY;
    let mut limit = f64::INFINITY;
    for c in refs {
        tc = tc.min(law.contact_time(&c.pair, c.r_star, c.m_star, v));
        let dmax = law.max_overlap(&c.pair, c.r_star, c.m_star, v);
        let s = law.stiffness(&c.pair, c.r_star, c.m_star, dmax);
        let (zeta_n, zeta_t) = damping_ratios(model, c, s.kn, s.sn);
        limit = limit.min(verlet_limit((s.sn / c.m_star).sqrt(), zeta_n));
        if friction {
            limit = limit.min(verlet_limit((s.kt * c.inv_tangential_mass).sqrt(), zeta_t));
        }
    }
    (tc, limit)
}

/// The stability limit over the contacts `refs` at speed `v` under the model's normal law
/// and damping, s.
pub fn stability_limit(model: &ModelSpec, refs: &[RefContact], v: f64, friction: bool) -> f64 {
    limits(model, refs, v, friction).1
}

/// Apply the rule under the model's normal law and damping. `smallest` is the smallest grain's
/// (radius, mass, material).
#[allow(clippy::too_many_arguments)]
pub fn choose(
    model: &ModelSpec,
    rule: &TimeStepRule,
    characteristic_speed: Option<f64>,
    allow_unstable: bool,
    refs: &[RefContact],
    smallest: (f64, f64, &Material),
    friction: bool,
) -> Result<TimeStepInfo, Error> {
    let v = characteristic_speed.unwrap_or(match rule {
        TimeStepRule::StepsPerContact { impact_speed, .. } | TimeStepRule::Accuracy { impact_speed, .. } => *impact_speed,
        _ => 1.0,
    });
    let (tc, limit) = limits(model, refs, v, friction);
    let law = &model.normal;
    let rayleigh = rayleigh_time(smallest.0, smallest.2);
    // Moduli, densities or speeds at the edge of the floating-point range give a contact
    // time or limit of 0 or infinity, from which no time step follows.
    let positive = |t: f64| t.is_finite() && t > 0.0;
    if !(positive(tc) && positive(limit) && positive(rayleigh)) {
        return Err(Error::Invalid {
            field: "time_step".into(),
            value: format!("t_c = {tc:e} s, stability limit {limit:e} s, Rayleigh time {rayleigh:e} s of the smallest grain at {v} m/s"),
            allowed: "materials (moduli, densities), radii and speeds whose contact time scales are finite and > 0".into(),
        });
    }
    let dt = match *rule {
        TimeStepRule::Fixed { dt } => dt,
        TimeStepRule::StepsPerContact { steps, impact_speed } => limits(model, refs, impact_speed, friction).0 / steps,
        TimeStepRule::Accuracy { .. } => unreachable!("build() calibrates an accuracy rule into steps per contact first"),
        TimeStepRule::RayleighFraction { fraction } => fraction * rayleigh,
        TimeStepRule::SeedRule { factor, reference_overlap } => {
            let dn = reference_overlap * smallest.0;
            let k_max = refs.iter().map(|c| law.stiffness(&c.pair, c.r_star, c.m_star, dn).kn).fold(0.0, f64::max);
            factor * 2.0 * (smallest.1 / k_max).sqrt()
        }
    };
    if !allow_unstable {
        check(
            dt <= limit,
            "time_step",
            "dt",
            format!("{dt:.4e} s"),
            &format!(
                "<= {limit:.4e} s, the stability limit at {v} m/s (t_c = {tc:.4e} s; use more steps per contact, or set time_step.allow_unstable)"
            ),
        )?;
    }
    Ok(TimeStepInfo {
        dt_s: dt,
        contact_time_s: tc,
        steps_per_contact: tc / dt,
        stability_limit_s: limit,
        rayleigh_time_s: rayleigh,
        characteristic_speed_m_s: v,
        accuracy: None,
    })
}

/// Steps of a run of `duration` s at `dt`, and the steps per output sample: the schedule
/// every run follows, and that exported decks and calibrations copy.
pub fn schedule(duration: f64, dt: f64, samples: u64) -> (u64, u64) {
    let total = steps_of(duration, dt) as u64;
    (total, (total / samples.max(1)).max(1))
}

/// The steps of each stage of a protocol of stage `durations` (s) at `dt`: the stage
/// boundaries fall at the steps ceil(t / dt) of their times t (the stages' starts summed),
/// so the stages add up to the steps of their total duration, as a run without stages
/// takes. A stage shorter than a step may get none.
pub fn stage_steps(durations: impl Iterator<Item = f64>, dt: f64) -> Vec<u64> {
    let (mut t, mut at) = (0.0, 0u64);
    durations
        .map(|d| {
            t += d;
            let end = steps_of(t, dt) as u64;
            let n = end.saturating_sub(at);
            at = end;
            n
        })
        .collect()
}

/// The refusal of stage `k` of `duration` s that takes no step at `dt`.
pub fn stage_too_short(k: usize, duration: f64, dt: f64) -> Error {
    Error::Invalid {
        field: format!("stages[{k}].duration"),
        value: format!("{duration} s"),
        allowed: format!("a stage of at least one step (dt = {dt:.3e} s): it begins and ends within the same step"),
    }
}

/// The steps a run of `duration` s takes at `dt` (at least one), as a float: NaN or
/// infinite for a dt that is not finite and > 0 ([`step_count`] refuses those).
fn steps_of(duration: f64, dt: f64) -> f64 {
    (duration / dt).ceil().max(1.0)
}

/// The steps of a run of `duration` s at `dt`, refused when dt is not finite and > 0 or
/// the count exceeds [`crate::scene::limits::MAX_STEPS`] (`field` names what set the duration).
pub fn step_count(duration: f64, dt: f64, field: &str) -> Result<u64, Error> {
    let steps = steps_of(duration, dt);
    if !(dt.is_finite() && dt > 0.0) {
        return Err(Error::Invalid { field: "time_step".into(), value: format!("dt = {dt:e} s"), allowed: "a rule that gives a finite dt > 0 s (check the materials' moduli and densities and the speeds)".into() });
    }
    if !(steps <= crate::scene::limits::MAX_STEPS) {
        return Err(Error::Invalid {
            field: field.into(),
            value: format!("{duration} s"),
            allowed: format!("at most {:e} steps of dt = {dt:.3e} s (it asks for {steps:.3e}): a shorter duration or a larger time step", crate::scene::limits::MAX_STEPS),
        });
    }
    Ok(steps as u64)
}

/// What the calibration chose, as reported with the time step.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct AccuracyNote {
    pub quantity: crate::scene::AccuracyQuantity,
    pub tolerance: f64,
    pub measured_error: f64,
}
