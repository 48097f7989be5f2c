//! `summary.json`: what a run did (its status, model, pipeline, time step, steps and
//! timings) and what it measured (the energy balance, an impact, the wall stresses),
//! and the stage timing table printed after a run.

use serde::Serialize;

use crate::engine::timestep::TimeStepInfo;
use crate::observe::energy::EnergySummary;
use crate::observe::impact::ImpactSummary;
use crate::observe::stress::ShearSummary;

/// The time one stage took over a run, and its share of the step.
#[derive(Clone, Debug, Serialize)]
pub struct StageTime {
    pub stage: String,
    pub seconds: f64,
    pub share: f64,
}

/// One stage of a protocol in the summary.
#[derive(Clone, Debug, Serialize)]
pub struct StageSummary {
    pub name: String,
    /// Simulated time at the stage's start, s.
    pub start_s: f64,
    /// ... and at its last row, s.
    pub end_s: f64,
    /// Steps the stage takes.
    pub steps: u64,
    /// Rows of the wall series it wrote.
    pub rows: usize,
    /// Whether its wall stresses are averaged (the scene's `stages[k].average`).
    pub averaged: bool,
    /// Its wall stresses' time averages (analysis shear, averaged, at least 4 rows).
    pub shear: Option<ShearSummary>,
}

/// A run's summary (`summary.json`, also printed on stdout).
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub scene: String,
    pub status: String,
    pub error: Option<String>,
    pub model: String,
    pub pipeline: String,
    pub time_step: TimeStepInfo,
    pub grains: usize,
    pub steps: u64,
    pub simulated_time_s: f64,
    pub wall_time_s: f64,
    pub particle_steps_per_s: f64,
    pub energy: Option<EnergySummary>,
    pub impact: Option<ImpactSummary>,
    /// Why an impact scene has no `impact`: the bodies never touched, or had not parted
    /// when the run ended (absent otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub impact_note: Option<String>,
    /// The wall stresses' time averages: of the run, or of a protocol's last averaged
    /// stage (each stage's are in `stages`).
    pub shear: Option<ShearSummary>,
    /// A protocol's stages, one block each (none for a scene without stages).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub stages: Vec<StageSummary>,
    pub stage_timing: Vec<StageTime>,
    /// What produced the run: grainlab's version and commit, the command line, the CPU,
    /// the threads, the start and end ([`crate::output::provenance`]).
    pub provenance: crate::output::provenance::Provenance,
}

/// The stage timing table as text.
pub fn timing_table(s: &Summary) -> String {
    let mut out = format!("{:<28} {:>10} {:>7}\n", "stage", "time (s)", "share");
    for t in &s.stage_timing {
        out += &format!("{:<28} {:>10.3} {:>6.1}%\n", t.stage, t.seconds, 100.0 * t.share);
    }
    out += &format!(
        "{} grains x {} steps in {:.2} s: {:.2} M particle-steps/s\n",
        s.grains,
        s.steps,
        s.wall_time_s,
        s.particle_steps_per_s / 1e6
    );
    out
}

/// The run in one line, for a person (and the shear intervals' warning, if any, after it): how it ended, tau/sigma with its 95% interval and
/// the normal stress (shear), the restitution coefficient (impact), the energy balance's
/// largest residual, and the rate.
pub fn headline(s: &Summary) -> String {
    let mut parts = vec![format!("{}: {}", s.scene, s.status)];
    if let Some(sh) = &s.shear {
        if let Some(r) = &sh.stress_ratio {
            parts.push(format!("tau/sigma = {:.3} +- {:.3} (95%, {} blocks)", r.mean, r.ci95, r.blocks));
        }
        parts.push(format!("sigma = {:.3e} Pa", sh.normal_stress_pa.mean));
    }
    if let Some(i) = &s.impact {
        parts.push(format!("e_n = {:.4}", i.restitution_normal));
    }
    if let Some(n) = &s.impact_note {
        parts.push(format!("impact: {n}"));
    }
    if let Some(e) = &s.energy {
        parts.push(format!("energy residual {:.1e} of the input", e.max_residual_rel));
    }
    parts.push(format!("{} grains x {} steps in {:.1} s", s.grains, s.steps, s.wall_time_s));
    let mut line = parts.join("; ");
    if let Some(w) = s.shear.as_ref().and_then(|sh| sh.warning.as_ref()) {
        line += &format!("\nwarning: {w}");
    }
    line
}
