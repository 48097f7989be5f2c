//! What accuracy costs in time: a scene run over a list of time steps and model
//! variants, one row per run (`grainlab sweep`).
//!
//! Errors are measured against the converged run (the finest time step of the same
//! variant) and, where one exists, against closed form: the input restitution (the
//! continuous-time law returns it exactly without the clamp) and, for an elastic impact,
//! Hertz's largest overlap, peak force and contact time.

use std::time::Instant;

use serde::Serialize;

use crate::error::Error;
use crate::output::summary::Summary;
use crate::physics::contact::LeverArm;
use crate::physics::material::{PairMaterial, hertz_contact_time, hertz_max_overlap};
use crate::scene::{Analysis, Grains, Scene, TangentialSpec, TimeStepRule};
use crate::study::run::{RunOptions, run_scene};

/// A model variant: the scene as given, or with one setting changed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum Variant {
    Scene,
    Tangential(TangentialSpec),
    Clamp(bool),
    Lever(LeverArm),
}

impl Variant {
    pub fn label(&self) -> String {
        match self {
            Variant::Scene => "scene".into(),
            Variant::Tangential(t) => format!("tangential={}", serde_json::to_value(t).unwrap().as_str().unwrap_or("?")),
            Variant::Clamp(c) => format!("limit_force={c}"),
            Variant::Lever(l) => format!("lever_arm={}", serde_json::to_value(l).unwrap().as_str().unwrap_or("?")),
        }
    }
    fn apply(&self, s: &mut Scene) {
        match *self {
            Variant::Scene => {}
            Variant::Tangential(t) => s.model.tangential = t,
            Variant::Clamp(c) => s.model.limit_force = c,
            Variant::Lever(l) => s.model.lever_arm = l,
        }
    }
    /// The variants a family name stands for (`tangential`, `clamp`, `lever`).
    pub fn family(name: &str) -> Result<Vec<Variant>, Error> {
        Ok(match name {
            "tangential" => vec![
                Variant::Tangential(TangentialSpec::TotalDisplacement),
                Variant::Tangential(TangentialSpec::IncrementalForce),
                Variant::Tangential(TangentialSpec::Frictionless),
            ],
            "clamp" => vec![Variant::Clamp(false), Variant::Clamp(true)],
            "lever" => vec![Variant::Lever(LeverArm::Radius), Variant::Lever(LeverArm::RadiusMinusHalfOverlap), Variant::Lever(LeverArm::Yade)],
            _ => {
                return Err(Error::BadOption { option: "--variants".into(), value: name.into(), allowed: "tangential, clamp, lever".into() });
            }
        })
    }
}

/// A time step setting of the sweep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Step {
    PerContact(f64),
    Rayleigh(f64),
}

/// One run of the sweep. A quantity that does not apply (an impact's in a shear run, an
/// error against a closed form the scene has none of) is empty.
#[derive(Clone, Debug, Serialize)]
pub struct SweepRow {
    pub variant: String,
    pub rule: String,
    pub dt_s: f64,
    pub steps_per_contact: f64,
    pub steps: u64,
    pub wall_time_s: f64,
    pub ns_per_particle_step: f64,
    pub energy_residual_rel: Option<f64>,
    // Impacts.
    pub restitution: Option<f64>,
    pub restitution_err_converged: Option<f64>,
    pub restitution_err_input: Option<f64>,
    pub peak_force_n: Option<f64>,
    pub peak_force_err_converged_rel: Option<f64>,
    pub peak_force_err_hertz_rel: Option<f64>,
    pub max_overlap_m: Option<f64>,
    pub max_overlap_err_converged_rel: Option<f64>,
    pub max_overlap_err_hertz_rel: Option<f64>,
    pub contact_time_s: Option<f64>,
    pub contact_time_err_converged_rel: Option<f64>,
    pub contact_time_err_hertz_rel: Option<f64>,
    // Shear.
    pub stress_ratio: Option<f64>,
    pub stress_ratio_ci95: Option<f64>,
    pub stress_ratio_err_converged: Option<f64>,
}

/// |a - b| / |b| where both are known.
fn rel(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    Some((a? - b?).abs() / b?.abs()).filter(|e| e.is_finite())
}

/// |a - b| where both are known.
fn abs_diff(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    Some((a? - b?).abs())
}

/// Run `scene` at every step setting for every variant.
pub fn sweep(scene: &Scene, steps: &[Step], variants: &[Variant], duration: Option<f64>, limits: &crate::scene::limits::Limits, mut progress: impl FnMut(&SweepRow)) -> Result<Vec<SweepRow>, Error> {
    if steps.is_empty() {
        return Err(Error::BadOption { option: "--steps/--rayleigh".into(), value: "none".into(), allowed: "at least one time step".into() });
    }
    let speed = match scene.time_step.rule {
        TimeStepRule::StepsPerContact { impact_speed, .. } | TimeStepRule::Accuracy { impact_speed, .. } => impact_speed,
        _ => scene.time_step.characteristic_speed.unwrap_or(1.0),
    };
    let mut out = Vec::new();
    for v in variants {
        let mut runs: Vec<(SweepRow, Summary)> = Vec::new();
        for st in steps {
            let mut s = scene.clone();
            v.apply(&mut s);
            s.output.frames = 0;
            s.time_step.rule = match *st {
                Step::PerContact(n) => TimeStepRule::StepsPerContact { steps: n, impact_speed: speed },
                Step::Rayleigh(f) => TimeStepRule::RayleighFraction { fraction: f },
            };
            let t0 = Instant::now();
            let sum = run_scene(&s, &RunOptions { duration, limits: *limits, ..RunOptions::default() })?;
            let wall = t0.elapsed().as_secs_f64();
            let imp = sum.impact;
            let ratio = sum.shear.as_ref().and_then(|s| s.stress_ratio);
            let row = SweepRow {
                variant: v.label(),
                rule: match *st {
                    Step::PerContact(n) => format!("t_c/{n}"),
                    Step::Rayleigh(f) => format!("{f} t_Rayleigh"),
                },
                dt_s: sum.time_step.dt_s,
                steps_per_contact: sum.time_step.steps_per_contact,
                steps: sum.steps,
                wall_time_s: wall,
                ns_per_particle_step: 1e9 * wall / (sum.steps.max(1) as f64 * sum.grains.max(1) as f64),
                energy_residual_rel: sum.energy.as_ref().map(|e| e.max_residual_rel),
                restitution: imp.map(|i| i.restitution_normal),
                restitution_err_converged: None,
                restitution_err_input: None,
                peak_force_n: imp.map(|i| i.peak_force_n),
                peak_force_err_converged_rel: None,
                peak_force_err_hertz_rel: None,
                max_overlap_m: imp.map(|i| i.max_overlap_m),
                max_overlap_err_converged_rel: None,
                max_overlap_err_hertz_rel: None,
                contact_time_s: imp.map(|i| i.contact_time_s),
                contact_time_err_converged_rel: None,
                contact_time_err_hertz_rel: None,
                stress_ratio: ratio.map(|r| r.mean),
                stress_ratio_ci95: ratio.map(|r| r.ci95).filter(|c| c.is_finite()),
                stress_ratio_err_converged: None,
            };
            runs.push((row, sum));
        }
        // The converged run: the finest time step of this variant.
        let finest = runs.iter().enumerate().min_by(|a, b| a.1.0.dt_s.total_cmp(&b.1.0.dt_s)).map(|(k, _)| k).expect("non-empty");
        let conv = runs[finest].0.clone();
        let closed = closed_form(scene);
        for (mut row, _) in runs {
            if scene.analysis == Analysis::Impact {
                row.restitution_err_converged = abs_diff(row.restitution, conv.restitution);
                row.peak_force_err_converged_rel = rel(row.peak_force_n, conv.peak_force_n);
                row.max_overlap_err_converged_rel = rel(row.max_overlap_m, conv.max_overlap_m);
                row.contact_time_err_converged_rel = rel(row.contact_time_s, conv.contact_time_s);
                if let Some(c) = closed {
                    row.restitution_err_input = abs_diff(row.restitution, Some(c.restitution));
                    if c.restitution == 1.0 {
                        row.max_overlap_err_hertz_rel = rel(row.max_overlap_m, Some(c.max_overlap));
                        row.peak_force_err_hertz_rel = rel(row.peak_force_n, Some(c.peak_force));
                        row.contact_time_err_hertz_rel = rel(row.contact_time_s, Some(c.contact_time));
                    }
                }
            }
            if scene.analysis == Analysis::Shear {
                row.stress_ratio_err_converged = abs_diff(row.stress_ratio, conv.stress_ratio);
            }
            progress(&row);
            out.push(row);
        }
    }
    Ok(out)
}

#[derive(Clone, Copy)]
struct Closed {
    restitution: f64,
    max_overlap: f64,
    peak_force: f64,
    contact_time: f64,
}

/// Closed-form values for a two-grain head-on impact of equal sphere-in-plane grains.
fn closed_form(s: &Scene) -> Option<Closed> {
    let Grains::List(g) = &s.grains else { return None };
    if g.len() != 2 || g[0].r != g[1].r || g[0].material != g[1].material || s.walls.is_some() {
        return None;
    }
    let m = &s.materials[g[0].material];
    let v = ((g[0].v[0] - g[1].v[0]).powi(2) + (g[0].v[1] - g[1].v[1]).powi(2)).sqrt();
    let (r, mass) = (g[0].r, s.grain_shape.mass(g[0].r, m.density));
    let e = PairMaterial::mix(m, m).e_star;
    let (ms, rs) = (mass / 2.0, r / 2.0);
    let d = hertz_max_overlap(ms, rs, e, v);
    Some(Closed {
        restitution: m.restitution,
        max_overlap: d,
        peak_force: 4.0 / 3.0 * e * rs.sqrt() * d.powf(1.5),
        contact_time: hertz_contact_time(ms, rs, e, v),
    })
}
