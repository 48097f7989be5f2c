//! Accuracy-targeted time steps: the largest dt whose measured error meets a tolerance.
//!
//! A scene may ask for an accuracy (`time_step.rule = {"accuracy": {...}}`) instead of a
//! dt. The engine then measures the convergence of a head-on impact of two of the scene's
//! smallest grains at the stated impact speed, with the scene's contact model: it runs
//! the impact at steps per contact 8, 8 sqrt 2, 16, ... 4096 and at 8192 (taken as
//! converged), and picks the fewest steps per contact whose error, and the error of every
//! finer step in the ladder, is within the tolerance. The calibration costs a few
//! thousand two-grain steps (milliseconds) and `explain` reports its result.

use serde::Serialize;

use crate::engine::build::Built;
use crate::engine::timestep::AccuracyNote;
use crate::error::Error;
use crate::observe::impact::{ImpactObserver, ImpactSummary};
use crate::physics::material::Material;
use crate::scene::limits::Limits;
use crate::scene::{AccuracyQuantity, Scene, TimeStepRule};

/// The quantity `q` of an impact's summary.
fn value(q: AccuracyQuantity, s: &ImpactSummary) -> f64 {
    match q {
        AccuracyQuantity::Restitution => s.restitution_normal,
        AccuracyQuantity::PeakForce => s.peak_force_n,
        AccuracyQuantity::MaxOverlap => s.max_overlap_m,
        AccuracyQuantity::ContactTime => s.contact_time_s,
    }
}

/// The error of quantity `q` of `a` against the converged `b`: absolute for the
/// restitution, relative for the others.
pub fn error(q: AccuracyQuantity, a: &ImpactSummary, b: &ImpactSummary) -> f64 {
    let (x, y) = (value(q, a), value(q, b));
    match q {
        AccuracyQuantity::Restitution => (x - y).abs(),
        _ => (x - y).abs() / y.abs(),
    }
}

/// Step the engine of an impact scene until the impact is over (or the scene's duration
/// is), checking the whole state after every step as a run does: the observer then holds
/// the impact's summary and its force-overlap curve. The same steps and the same bits as
/// [`crate::study::run::run_scene`] on the scene, without its outputs; the calibration's
/// head-on impacts are run this way, each an engine of its own.
pub fn step_impact<D: crate::observe::impact::Impacts>(built: &mut Built<D>, scene: &Scene) -> Result<ImpactObserver<D>, Error> {
    let e = built.engine.as_mut();
    let (total, _) = crate::engine::timestep::schedule(scene.duration, e.dt(), scene.output.samples);
    let mut obs = ImpactObserver::default();
    obs.start(&e.view());
    for _ in 0..total {
        e.advance(true)?;
        e.health()?;
        obs.observe(&e.view());
        if obs.finished() {
            break;
        }
    }
    Ok(obs)
}

/// What the calibration found.
#[derive(Clone, Debug, Serialize)]
pub struct Calibration {
    pub quantity: AccuracyQuantity,
    pub tolerance: f64,
    /// The chosen steps per contact time (of the scene's normal law).
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
/// two grains of radius `r` and `material` at `speed`, with the clamp as given, under
/// the Hertz law.
pub fn calibrate(material: &Material, r: f64, speed: f64, limit_force: bool, quantity: AccuracyQuantity, tolerance: f64) -> Result<Calibration, Error> {
    calibrate_under(crate::scene::NormalLaw::Hertz, crate::scene::DampingSpec::Restitution, material, r, speed, limit_force, quantity, tolerance)
}

/// [`calibrate`] under the normal law `law` (steps per its contact time) and `damping`.
#[allow(clippy::too_many_arguments)]
pub fn calibrate_under(law: crate::scene::NormalLaw, damping: crate::scene::DampingSpec, material: &Material, r: f64, speed: f64, limit_force: bool, quantity: AccuracyQuantity, tolerance: f64) -> Result<Calibration, Error> {
    let run = |n: f64| -> Result<ImpactSummary, Error> {
        let mut s = crate::scene::builtin::head_on_under(law, material.clone(), r, speed, n);
        s.model.limit_force = limit_force;
        s.model.damping = damping;
        s.model.tangential = crate::scene::TangentialSpec::Frictionless;
        s.output.energy = false;
        s.time_step.allow_unstable = true;
        let mut built = crate::engine::build::build_limited(&s, 1, &Limits::machine())?;
        step_impact(&mut built, &s)?.summary().ok_or_else(|| Error::Other("calibration impact did not complete".into()))
    };
    let reference = run(CONVERGED)?;
    let mut ladder: Vec<(f64, f64)> = Vec::new();
    for n in self::ladder() {
        ladder.push((n, error(quantity, &run(n)?, &reference)));
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

/// Build a scene's engine, an accuracy rule resolved first: the calibration runs its
/// head-on impacts of the scene's smallest grains (each an engine of its own) and the
/// rule becomes the steps per contact it chose, which the engine's build then takes like
/// any other rule ([`crate::engine::build::build_limited`]); the time step reports the
/// calibration. Within the machine's default limits.
pub fn build(scene: &Scene) -> Result<Built, Error> {
    build_with(scene, 1)
}

/// [`build`] with the contact forces on `threads` threads (feature `parallel`).
pub fn build_with(scene: &Scene, threads: usize) -> Result<Built, Error> {
    build_limited(scene, threads, &Limits::machine())
}

/// [`build`] on `threads` threads within `limits` (a plane scene; [`build_in`] builds
/// either).
pub fn build_limited(scene: &Scene, threads: usize, limits: &Limits) -> Result<Built, Error> {
    build_in::<crate::physics::dim::Plane>(scene, threads, limits)
}

/// [`build_limited`] in the plane (`D = Plane`) or in space (`D = Space`). The
/// calibration's head-on impacts are the plane's: two spheres meeting head on move along
/// their line of centres, the same impact in either dimension.
pub fn build_in<D: crate::engine::build::Building>(scene: &Scene, threads: usize, limits: &Limits) -> Result<Built<D>, Error>
where
    D::Vector<f64>: serde::Serialize + serde::de::DeserializeOwned,
    D::Spin<f64>: serde::Serialize + serde::de::DeserializeOwned,
{
    let TimeStepRule::Accuracy { quantity, tolerance, impact_speed } = scene.time_step.rule else {
        return crate::engine::build::build_in::<D>(scene, threads, limits);
    };
    scene.validate()?;
    let (r, material) = scene.smallest_grain(limits)?;
    let cal = calibrate_under(scene.model.normal, scene.model.damping, &scene.materials[material], r, impact_speed, scene.model.limit_force, quantity, tolerance)?;
    let mut resolved = scene.clone();
    resolved.time_step.rule = TimeStepRule::StepsPerContact { steps: cal.steps_per_contact, impact_speed };
    let mut built = crate::engine::build::build_in::<D>(&resolved, threads, limits)?;
    built.time_step.accuracy = Some(AccuracyNote { quantity, tolerance, measured_error: cal.measured_error });
    Ok(built)
}
