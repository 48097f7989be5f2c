//! Running a scene: the step loop, the observers, the outputs, the progress bar and the
//! stage timing table.

use std::io::Write as _;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};

use crate::engine::build::Built;
use crate::engine::simulation::Engine;
use crate::engine::timestep::step_count;
use crate::engine::world::MotionChange;
use crate::study::protocol::{Phase, phases};
use crate::error::Error;
use crate::observe::energy::energy_summary;
use crate::observe::impact::ImpactObserver;
use crate::observe::stress::{ShearSummary, WallAverager, WallRow, stress_estimates};
use crate::output::csv::CsvSeries;
use crate::output::folder::OutFolder;
use crate::output::provenance::{Provenance, RESOLVED_SCENE, resolved};
use crate::output::summary::{StageSummary, StageTime, Summary};
use crate::output::vtk::VtkSeries;
use crate::physics::energy::EnergyRow;
use crate::scene::{Analysis, Scene};

#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Output folder (created); nothing is written without one. It must be new, empty,
    /// or hold an earlier grainlab output and `overwrite` be set ([`OutFolder`]).
    pub out: Option<PathBuf>,
    /// Delete the files an earlier grainlab command listed in `out`'s manifest first.
    pub overwrite: bool,
    /// Show progress on stderr: a bar with the simulated time and the latest tau/sigma when
    /// stderr is a terminal, else a line at every tenth of the run.
    pub progress: bool,
    /// Override the scene's duration, s.
    pub duration: Option<f64>,
    /// What a scene [`run_scene`] builds may ask of the machine (default: half its memory).
    pub limits: crate::scene::limits::Limits,
    /// Set (by a SIGINT/SIGTERM handler, or a test) to end the run after the step under
    /// way: it then writes everything with `status: "interrupted"` and ends with
    /// [`Error::Interrupted`]. Read once a step (a relaxed atomic load).
    pub stop: Option<Arc<AtomicBool>>,
    /// The command line that started the run, for its provenance (empty from the library).
    pub command: Vec<String>,
}


struct Outputs {
    folder: Option<OutFolder>,
    energy: Option<CsvSeries>,
    walls: Option<CsvSeries>,
    vtk: Option<VtkSeries>,
}

impl Outputs {
    fn frame(&mut self, e: &dyn Engine) -> Result<(), Error> {
        match (self.vtk.as_mut(), self.folder.as_mut()) {
            (Some(v), Some(f)) => v.frame(&e.view(), f),
            _ => Ok(()),
        }
    }
}

/// How a run ended: its summary, also when it stopped early, and what went wrong.
#[derive(Debug)]
pub struct RunReport {
    pub summary: Summary,
    /// Why the run did not complete: a diagnosis ([`Error::Unstable`]), a stop request
    /// ([`Error::Interrupted`]) or an output it could not write while it went
    /// ([`Error::Io`]); the summary's `status` and `error` say the same.
    pub ending: Option<Error>,
    /// The first failure to write the outputs when the run ended (the series' renames,
    /// `force_overlap.csv`, `summary.json`, the manifest), after trying them all.
    pub write_error: Option<Error>,
    /// The outputs that failed then, in the order they were tried.
    pub unwritten: Vec<String>,
}

impl RunReport {
    /// The summary of a completed run whose outputs are all written, else the error: a
    /// write failure first (the folder is incomplete), then the ending.
    pub fn into_result(self) -> Result<Summary, Error> {
        let RunReport { summary, ending, write_error, .. } = self;
        match (write_error, ending) {
            (Some(err), _) | (None, Some(err)) => Err(err),
            (None, None) => Ok(summary),
        }
    }
}

/// Build and run a scene.
pub fn run_scene(scene: &Scene, opts: &RunOptions) -> Result<Summary, Error> {
    let built = crate::study::accuracy::build_limited(scene, 1, &opts.limits)?;
    run_built(scene, built, opts)
}

/// Run an engine built from `scene`. A run that stops early (unstable, interrupted, or an
/// output it cannot write) still writes everything it can, `summary.json` says what
/// happened, and the error is returned; [`run_report`] returns the summary with it.
pub fn run_built(scene: &Scene, built: Built, opts: &RunOptions) -> Result<Summary, Error> {
    run_report(scene, built, opts)?.into_result()
}

/// Run an engine built from `scene` and report how it ended ([`RunReport`]). An error
/// here means the run did not start (its output folder refused or not writable).
pub fn run_report(scene: &Scene, mut built: Built, opts: &RunOptions) -> Result<RunReport, Error> {
    let duration = opts.duration.unwrap_or(scene.duration);
    let dt = built.time_step.dt_s;
    // The build checked the scene's duration; an override is checked here, and cuts a
    // protocol short.
    step_count(duration, dt, if opts.duration.is_some() { "--duration" } else { "duration" })?;
    let cut;
    let scene = if opts.duration.is_some() {
        cut = scene.truncated(duration);
        &cut
    } else {
        scene
    };
    let phases = phases(scene, dt, built.length, built.depth)?;
    let total = phases.last().map_or(0, Phase::last);
    let energy_on = scene.output.energy;
    let started = std::time::SystemTime::now();
    let mut outputs = Outputs { folder: None, energy: None, walls: None, vtk: None };
    if let Some(dir) = &opts.out {
        let mut folder = OutFolder::claim(dir, opts.overwrite, &format!("run {}", scene.name))?;
        // The scene as it runs: the folder alone repeats the run.
        folder.write(RESOLVED_SCENE, (serde_json::to_string_pretty(&resolved(scene, scene.duration)).expect("serialisable") + "\n").as_bytes())?;
        if energy_on {
            outputs.energy = Some(folder.series("energy.csv")?);
        }
        if !built.engine.walls().is_empty() {
            outputs.walls = Some(folder.series("walls.csv")?);
        }
        if phases.iter().any(|p| p.frame_every.is_some()) {
            outputs.vtk = Some(VtkSeries::new(&mut folder)?);
        }
        outputs.folder = Some(folder);
    }
    let pipeline = built.explain();
    let e = built.engine.as_mut();
    let mut impact = (scene.analysis == Analysis::Impact).then(ImpactObserver::default);
    if let Some(o) = impact.as_mut() {
        o.start(&e.view());
    }
    let mut walls_avg = WallAverager::default();
    let mut wall_rows: Vec<WallRow> = Vec::new();
    // The rows each stage ended at (an index into `wall_rows`), as the stages end.
    let mut stage_ends: Vec<usize> = Vec::new();
    let mut max_res: f64 = 0.0;
    let mut energy_rows = 0usize;
    // The last row recorded (of a state that passed its checks): the summary's, so that a
    // run stopped on a state gone wrong reports the last one that was not.
    let mut last_row: Option<EnergyRow> = None;
    let mut record_energy = |e: &dyn Engine, out: &mut Outputs, stage: &str| -> Result<(), Error> {
        if energy_on {
            let row = e.energy_row();
            max_res = max_res.max(row.residual_j.abs() / row.put_in().max(f64::MIN_POSITIVE));
            energy_rows += 1;
            last_row = Some(row);
            if let Some(w) = out.energy.as_mut() {
                w.row_in(stage, &row)?;
            }
        }
        Ok(())
    };
    // Why the run stops early, if it does, and the first output that failed besides.
    let first_stage = phases.first().map_or("", |p| p.name.as_str());
    let mut error: Option<Error> = record_energy(e, &mut outputs, first_stage).and_then(|()| outputs.frame(e)).err();
    let mut write_error: Option<Error> = None;
    let mut unwritten: Vec<String> = Vec::new();
    // An output that cannot be written stops the run; what it computed is summarised.
    macro_rules! or_stop {
        ($run:lifetime, $written:expr) => {
            if let Err(err) = $written {
                error = Some(err);
                break $run;
            }
        };
    }
    // An output that fails as the run ends anyway: named, and the others still written.
    macro_rules! or_note {
        ($name:expr, $written:expr) => {
            if let Err(err) = $written {
                unwritten.push($name.to_string());
                write_error.get_or_insert(err);
            }
        };
    }
    let stop = opts.stop.as_deref();
    use std::io::IsTerminal as _;
    let lines = opts.progress && !std::io::stderr().is_terminal();
    let mut next_line = 1;
    let bar = if opts.progress && !lines {
        let b = ProgressBar::new(total);
        b.set_style(ProgressStyle::with_template("{msg} [{bar:40}] {percent}% {elapsed_precise} eta {eta}").expect("template").progress_chars("=> "));
        b.set_message(scene.name.clone());
        Some(b)
    } else {
        None
    };
    let t0 = Instant::now();
    let phases_run: &[Phase] = if error.is_none() { &phases } else { &[] };
    'run: for phase in phases_run {
        let stage = phase.name.as_str();
        if phase.change != MotionChange::default() {
            e.change_motion(&phase.change);
        }
        let shown = if stage.is_empty() { scene.name.clone() } else { format!("{} [{stage}]", scene.name) };
        for j in 1..=phase.steps {
            let k = phase.first + j;
            // A stop request makes this step the last, sampled like the last of the run.
            let stopping = stop.is_some_and(|s| s.load(Ordering::Relaxed));
            let sample = j % phase.sample_every == 0 || j == phase.steps || stopping;
            let frame = phase.frame_every.is_some_and(|every| j % every == 0);
            // Whether anything below looks at the grains after this step: else the step's
            // final half kick is left to the next one's drift.
            let look = sample || frame || impact.is_some();
            if let Err(err) = e.advance(look) {
                error = Some(err);
                break 'run;
            }
            if let Some(o) = impact.as_mut() {
                // The observer records every step (its curve is an output): every step's
                // state is checked first, cheap for the one or two grains of an impact.
                if let Err(err) = e.health() {
                    error = Some(err);
                    break 'run;
                }
                o.observe(&e.view());
            }
            walls_avg.accumulate(&e.view());
            // Nothing is written of a state that failed its check: outputs hold only
            // finite numbers, and the stop is diagnosed in the summary.
            if (sample || frame)
                && let Err(err) = e.health()
            {
                error = Some(err);
                break 'run;
            }
            if sample {
                or_stop!('run, record_energy(e, &mut outputs, stage));
                if let Some(row) = walls_avg.row(&e.view(), built.length, built.depth) {
                    if let Some(w) = outputs.walls.as_mut() {
                        or_stop!('run, w.row_in(stage, &row));
                    }
                    wall_rows.push(row);
                }
            }
            if frame {
                or_stop!('run, outputs.frame(e));
            }
            if k % 1000 == 0
                && let Some(b) = &bar
            {
                b.set_position(k);
                b.set_message(progress_message(&shown, e.time(), wall_rows.last()));
            }
            // Without a terminal, a line at each tenth of the run.
            if lines && k * 10 >= next_line * total {
                next_line = k * 10 / total + 1;
                let secs = t0.elapsed().as_secs_f64();
                let eta = secs * (total - k) as f64 / k as f64;
                let _ = writeln!(std::io::stderr().lock(), "{}: {}% of {} steps, {secs:.1} s, eta {eta:.1} s", progress_message(&shown, e.time(), wall_rows.last()), 100 * k / total, total);
            }
            if stopping {
                error = Some(Error::Interrupted { step: e.steps(), time: e.time() });
                break 'run;
            }
            if impact.as_ref().is_some_and(|o| o.finished()) {
                match e.health() {
                    Err(err) => error = Some(err),
                    Ok(()) => or_note!("energy.csv", record_energy(e, &mut outputs, stage)),
                }
                break 'run;
            }
        }
        stage_ends.push(wall_rows.len());
    }
    // A stage cut short by a stop ends at the last row.
    if stage_ends.len() < phases.len() {
        stage_ends.push(wall_rows.len());
    }
    let wall_time = t0.elapsed().as_secs_f64();
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let timings = e.timings();
    let total_t: f64 = timings.iter().map(|t| t.1.as_secs_f64()).sum::<f64>().max(f64::MIN_POSITIVE);
    let stage_timing = timings.iter().map(|(s, d)| StageTime { stage: s.clone(), seconds: d.as_secs_f64(), share: d.as_secs_f64() / total_t }).collect();
    let mut stages = Vec::new();
    let mut shear = None;
    let mut from = 0;
    for (phase, &to) in phases.iter().zip(&stage_ends) {
        let rows = &wall_rows[from..to];
        let averaged = (scene.analysis == Analysis::Shear && phase.average && rows.len() >= 4).then(|| shear_summary(rows, e.particles(), built.length));
        if averaged.is_some() {
            shear.clone_from(&averaged);
        }
        if !phase.name.is_empty() {
            stages.push(StageSummary {
                name: phase.name.clone(),
                start_s: phase.first as f64 * dt,
                end_s: rows.last().map_or(phase.first as f64 * dt, |r| r.time_s),
                steps: phase.steps,
                rows: rows.len(),
                averaged: phase.average,
                shear: averaged,
            });
        }
        from = to;
    }
    let mut provenance = Provenance::new(started, e.threads(), &opts.command, opts.out.as_ref().map(|_| RESOLVED_SCENE.to_string()));
    provenance.end();
    let p = e.particles();
    let summary = Summary {
        scene: scene.name.clone(),
        status: match &error {
            None => "completed",
            Some(Error::Interrupted { .. }) => "interrupted",
            Some(_) => "stopped",
        }
        .into(),
        error: error.as_ref().map(|e| e.to_string()),
        model: e.model(),
        pipeline,
        time_step: built.time_step,
        grains: p.n_free,
        steps: e.steps(),
        simulated_time_s: e.time(),
        wall_time_s: wall_time,
        particle_steps_per_s: p.n_free as f64 * e.steps() as f64 / wall_time.max(1e-9),
        energy: energy_on.then(|| energy_summary(last_row.unwrap_or_else(|| e.energy_row()), max_res, dt)),
        impact: impact.as_ref().and_then(|o| o.summary()),
        shear,
        stages,
        stage_timing,
        provenance,
    };
    // Every number in the summary is finite (an undefined one is `None`): a number that is
    // not would be written as `null` without a word, so the run says so instead.
    let mut summary = summary;
    if let Some(field) = crate::finite::non_finite_column(&summary) {
        let what = format!("the summary's {field} is not finite (written as null): a fault of grainlab's checks, please report it with the scene");
        summary.status = "stopped".into();
        summary.error = Some(summary.error.map_or(what.clone(), |e| format!("{e}; {what}")));
        error.get_or_insert(Error::Other(what));
    }
    // Everything is tried even when one write fails; the first failure is kept.
    if let Some(folder) = outputs.folder.as_mut() {
        for (series, name) in [(outputs.energy.take(), "energy.csv"), (outputs.walls.take(), "walls.csv")] {
            if let Some(s) = series {
                or_note!(name, folder.close_series(s, name));
            }
        }
        if let Some(o) = impact.as_ref() {
            or_note!("force_overlap.csv", folder.write_series("force_overlap.csv", &o.curve));
        }
        or_note!("summary.json", folder.write("summary.json", (serde_json::to_string_pretty(&summary).expect("serialisable") + "\n").as_bytes()));
        or_note!("manifest.json", folder.finish(&summary.status));
    }
    Ok(RunReport { summary, ending: error, write_error, unwritten })
}

/// What the progress shows besides the steps: the scene, the simulated time and the latest
/// tau/sigma (with walls).
fn progress_message(name: &str, time: f64, row: Option<&WallRow>) -> String {
    let ratio = row.and_then(|r| r.stress_ratio).map(|x| format!(", tau/sigma {x:.3}")).unwrap_or_default();
    format!("{name} t = {time:.3e} s{ratio}")
}

/// The shear estimates of a run's wall rows, and the packing fraction at the last row (its
/// gap: of a state that passed its checks, also when the run stopped after it).
fn shear_summary(rows: &[WallRow], p: &crate::physics::particles::Particles, length: f64) -> ShearSummary {
    let area: f64 = (0..p.n_free).map(|i| std::f64::consts::PI * p.r[i] * p.r[i]).sum();
    let gap = rows.last().map_or(f64::NAN, |r| r.gap_m);
    stress_estimates(rows, Some(area / (length * gap)).filter(|f| f.is_finite()))
}

