//! Accuracy-targeted time steps: the largest dt whose measured error meets a tolerance.
//!
//! A scene may ask for an accuracy (`time_step.rule = {"accuracy": {...}}`) instead of a
//! dt. The engine then measures the convergence of a head-on impact of two of the scene's
//! smallest grains at the stated impact speed, with the scene's contact model: it runs
//! the impact at steps per contact 8, 8 sqrt 2, 16, ... 4096 and at 8192 (taken as
//! converged), and picks the fewest steps per contact whose error, and the error of every
//! finer step in the ladder, is within the tolerance. The calibration costs a few
//! thousand two-grain steps (milliseconds) and `explain` reports its result.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::error::Error;
use crate::material::Material;
use crate::observe::impact::ImpactSummary;
use crate::run::{RunOptions, run_scene};
use crate::scenes::head_on;

/// The measured quantity a tolerance applies to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum AccuracyQuantity {
    /// Realised normal restitution, absolute error.
    Restitution,
    /// Peak normal force, relative error.
    PeakForce,
    /// Largest overlap, relative error.
    MaxOverlap,
    /// Contact duration, relative error.
    ContactTime,
}

impl AccuracyQuantity {
    fn value(self, s: &ImpactSummary) -> f64 {
        match self {
            AccuracyQuantity::Restitution => s.restitution_normal,
            AccuracyQuantity::PeakForce => s.peak_force_n,
            AccuracyQuantity::MaxOverlap => s.max_overlap_m,
            AccuracyQuantity::ContactTime => s.contact_time_s,
        }
    }
    /// Error of `a` against the converged `b`.
    pub fn error(self, a: &ImpactSummary, b: &ImpactSummary) -> f64 {
        let (x, y) = (self.value(a), self.value(b));
        match self {
            AccuracyQuantity::Restitution => (x - y).abs(),
            _ => (x - y).abs() / y.abs(),
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            AccuracyQuantity::Restitution => "restitution error (abs)",
            AccuracyQuantity::PeakForce => "peak force error (rel)",
            AccuracyQuantity::MaxOverlap => "max overlap error (rel)",
            AccuracyQuantity::ContactTime => "contact time error (rel)",
        }
    }
}

/// What the calibration chose, as reported with the time step.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct AccuracyNote {
    pub quantity: AccuracyQuantity,
    pub tolerance: f64,
    pub measured_error: f64,
}

/// What the calibration found.
#[derive(Clone, Debug, Serialize)]
pub struct Calibration {
    pub quantity: AccuracyQuantity,
    pub tolerance: f64,
    /// The chosen steps per Hertz contact time.
    pub steps_per_contact: f64,
    /// The measured error there.
    pub measured_error: f64,
    /// The ladder: (steps per contact, error against the converged run).
    pub ladder: Vec<(f64, f64)>,
}

const CONVERGED: f64 = 8192.0;

/// Steps per contact of the calibration ladder, coarse to fine.
pub fn ladder() -> Vec<f64> {
    (0..=18).map(|k| 8.0 * 2f64.powf(k as f64 / 2.0)).collect()
}

/// Calibrate: the fewest steps per contact meeting `tolerance` for a head-on impact of
/// two grains of radius `r` and `material` at `speed`, with the clamp as given.
pub fn calibrate(material: &Material, r: f64, speed: f64, limit_force: bool, quantity: AccuracyQuantity, tolerance: f64) -> Result<Calibration, Error> {
    let run = |n: f64| -> Result<ImpactSummary, Error> {
        let mut s = head_on(material.clone(), r, speed, n);
        s.model.limit_force = limit_force;
        s.model.tangential = crate::scene::TangentialSpec::Frictionless;
        s.output.energy = false;
        s.time_step.allow_unstable = true;
        run_scene(&s, &RunOptions::default())?.impact.ok_or_else(|| Error::Other("calibration impact did not complete".into()))
    };
    let reference = run(CONVERGED)?;
    let mut ladder: Vec<(f64, f64)> = Vec::new();
    for n in self::ladder() {
        ladder.push((n, quantity.error(&run(n)?, &reference)));
    }
    // The coarsest n from which every finer ladder entry meets the tolerance.
    let mut chosen = None;
    for k in (0..ladder.len()).rev() {
        if ladder[k].1 <= tolerance {
            chosen = Some(k);
        } else {
            break;
        }
    }
    match chosen {
        Some(k) => Ok(Calibration { quantity, tolerance, steps_per_contact: ladder[k].0, measured_error: ladder[k].1, ladder }),
        None => {
            let (n, e) = *ladder.last().expect("non-empty ladder");
            Err(Error::Invalid {
                field: "time_step.rule.accuracy.tolerance".into(),
                value: format!("{tolerance:e}"),
                allowed: format!("> {e:.2e}, the error measured at t_c/{n:.0} (the finest step calibrated)"),
            })
        }
    }
}
