//! Running a scene: the step loop, the observers, the outputs, the progress bar and the
//! stage timing table.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use serde::{Deserialize, Serialize};

use crate::engine::build::Built;
use crate::engine::simulation::Engine;
use crate::engine::world::View;
use crate::physics::dim::{Plane, Space};
use crate::engine::timestep::step_count;
use crate::engine::world::MotionChange;
use crate::study::protocol::{Phase, phases};
use crate::error::Error;
use crate::observe::energy::energy_summary;
use crate::observe::impact::{ImpactObserver, Impacts};
use crate::observe::packing::{PackingRow, packing_row, packing_summary};
use crate::observe::profiles::{LayerProfile, ProfileSample, layer_count, mean_diameter, profile_sample, profile_summary};
use crate::observe::stats::Blocking;
use crate::observe::stress::{ShearSummary, WallAverager, WallRow, stress_estimates};
use crate::output::checkpoint::{CHECKPOINT, Checkpoint};
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
    /// Simulated time between checkpoints (`--checkpoint-every`), s: `checkpoint.bin` in
    /// the output folder (needed) is replaced at every step that is a multiple of the
    /// rate rounded to steps, and `grainlab resume` continues from it bit for bit. With
    /// an output folder, a stop request writes one too, whatever the rate. Default: none.
    pub checkpoint_every: Option<f64>,
    /// End the run after this step as a stop request would (checkpointed, `interrupted`):
    /// a run cut into parts of a known length, and the restart tests' stops.
    pub stop_after_step: Option<u64>,
}


/// The run's output series and frames in its folder (none without one).
pub struct Outputs {
    folder: Option<OutFolder>,
    energy: Option<CsvSeries>,
    walls: Option<CsvSeries>,
    /// packing.csv: the packing's stress, coordination and fabric at each sample (the
    /// scene's `output.contacts`).
    packing: Option<CsvSeries>,
    vtk: Option<VtkSeries>,
}

impl Outputs {
    /// Write a frame, with the contacts the step recorded when `contacts`.
    fn frame<D: Running>(&mut self, e: &dyn Engine<D>, contacts: bool) -> Result<(), Error> {
        match (self.vtk.as_mut(), self.folder.as_mut()) {
            (Some(v), Some(f)) => D::frame(v, &e.view(), contacts, f),
            _ => Ok(()),
        }
    }
}

/// What running a scene does differently in the plane and in space: the ParaView frames
/// (the plane's carry the contacts), the observers that are the plane's so far (the
/// packing's inside: a 3D scene's validation refuses `output.contacts` by name), and the
/// volume the grains' solid fraction is of. The run loop is written once
/// ([`drive`]).
pub trait Running: crate::engine::build::Building + Impacts {
    fn frame(vtk: &mut VtkSeries, e: &View<'_, Self>, contacts: bool, folder: &mut OutFolder) -> Result<(), Error>;
    /// The packing's row and the profiles' sample of the contacts recorded now (the plane's).
    fn inside(st: &mut LoopState<Self>, e: &View<'_, Self>, out: &mut Outputs, stage: &str, length: f64, depth: f64) -> Result<(), Error>;
    /// The cell's measure between the walls a gap apart, per the grains' measure
    /// ([`crate::engine::build::Building::measure`]): its area in the plane (length x
    /// gap), its volume in space (length x depth x gap).
    fn cell_measure(length: f64, depth: f64, gap: f64) -> f64;
}

impl Running for Plane {
    fn frame(vtk: &mut VtkSeries, e: &View<'_>, contacts: bool, folder: &mut OutFolder) -> Result<(), Error> {
        vtk.frame(e, contacts, folder)
    }
    fn inside(st: &mut LoopState, v: &View<'_>, out: &mut Outputs, stage: &str, length: f64, depth: f64) -> Result<(), Error> {
        if let Some(row) = packing_row(v, length, depth) {
            if let Some(s) = out.packing.as_mut() {
                s.row_in(stage, &row)?;
            }
            st.packing_rows.push(row);
        }
        if let Some(n) = st.profile_layers.or_else(|| layer_count(v)) {
            st.profile_layers = Some(n);
            st.profile_rows.extend(profile_sample(v, n, length, depth));
        }
        Ok(())
    }
    fn cell_measure(length: f64, _: f64, gap: f64) -> f64 {
        length * gap
    }
}

impl Running for Space {
    fn frame(vtk: &mut VtkSeries, e: &View<'_, Space>, _: bool, folder: &mut OutFolder) -> Result<(), Error> {
        vtk.frame_of(e, folder)
    }
    // A 3D scene's validation refuses `output.contacts`: no observer to feed.
    fn inside(_: &mut LoopState<Space>, _: &View<'_, Space>, _: &mut Outputs, _: &str, _: f64, _: f64) -> Result<(), Error> {
        Ok(())
    }
    fn cell_measure(length: f64, depth: f64, gap: f64) -> f64 {
        length * depth * gap
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

/// Build and run a scene, in the plane or in space (its `dimension`).
pub fn run_scene(scene: &Scene, opts: &RunOptions) -> Result<Summary, Error> {
    match scene.dimension {
        crate::scene::Dimension::Two => run_built(scene, crate::study::accuracy::build_limited(scene, 1, &opts.limits)?, opts),
        crate::scene::Dimension::Three => run_built(scene, crate::study::accuracy::build_in::<Space>(scene, 1, &opts.limits)?, opts),
    }
}

/// Run an engine built from `scene`. A run that stops early (unstable, interrupted, or an
/// output it cannot write) still writes everything it can, `summary.json` says what
/// happened, and the error is returned; [`run_report`] returns the summary with it.
pub fn run_built<D: Running>(scene: &Scene, built: Built<D>, opts: &RunOptions) -> Result<Summary, Error> {
    run_report(scene, built, opts)?.into_result()
}

/// Run an engine built from `scene` and report how it ended ([`RunReport`]). An error
/// here means the run did not start (its output folder refused or not writable).
pub fn run_report<D: Running>(scene: &Scene, built: Built<D>, opts: &RunOptions) -> Result<RunReport, Error> {
    drive(scene, built, opts, None)
}

/// Continue the run whose output folder is `dir` from its checkpoint ([`CHECKPOINT`]),
/// on `threads` (default: the run's), with `opts`' progress, stop flag, limits and
/// command (its folder, duration and checkpoint rate are the run's). The resumed run
/// writes energy.csv, walls.csv and the frames byte for byte as the run that never
/// stopped would have (`tests/restart.rs`). Refused, with nothing changed in `dir`, if
/// the checkpoint is damaged, of another build or format, or of another run than the
/// folder's scene.
pub fn resume(dir: &Path, threads: Option<usize>, opts: &RunOptions) -> Result<RunReport, Error> {
    let file = dir.join(CHECKPOINT);
    let c = Checkpoint::read(&file, opts.limits.memory_bytes)?;
    let shown = file.display().to_string();
    let refuse = |why: String| Err(Error::Checkpoint { file: shown.clone(), why });
    if (c.grainlab.as_str(), c.commit.as_str()) != (env!("CARGO_PKG_VERSION"), env!("GRAINLAB_COMMIT")) {
        return refuse(format!(
            "was written by grainlab {} (commit {}), this is {} (commit {}): a run resumes bit for bit only on the build that started it",
            c.grainlab,
            c.commit,
            env!("CARGO_PKG_VERSION"),
            env!("GRAINLAB_COMMIT")
        ));
    }
    let scene = Scene::from_json(&c.scene)?;
    match scene.dimension {
        crate::scene::Dimension::Two => resume_in::<Plane>(dir, scene, c, threads, opts),
        crate::scene::Dimension::Three => resume_in::<Space>(dir, scene, c, threads, opts),
    }
}

/// [`resume`] in the checkpoint's dimension.
fn resume_in<D: Running>(dir: &Path, scene: Scene, c: Checkpoint, threads: Option<usize>, opts: &RunOptions) -> Result<RunReport, Error>
where
    D::Vector<f64>: serde::Serialize + serde::de::DeserializeOwned,
    D::Spin<f64>: serde::Serialize + serde::de::DeserializeOwned,
{
    let shown = dir.join(CHECKPOINT).display().to_string();
    let refuse = |why: String| Err(Error::Checkpoint { file: shown.clone(), why });
    let run_scene = c.duration.map_or_else(|| scene.clone(), |d| scene.truncated(d));
    let theirs = crate::scene::limits::read_bounded(&dir.join(RESOLVED_SCENE), opts.limits.file_bytes(), RESOLVED_SCENE)?;
    if theirs != resolved_json(&run_scene) {
        return refuse(format!("belongs to another run than this folder's {RESOLVED_SCENE} (the scenes differ)"));
    }
    let state: LoopState<D> = match postcard::from_bytes(&c.run) {
        Ok(s) => s,
        Err(e) => return refuse(format!("its run state does not decode ({e})")),
    };
    let mut built = crate::study::accuracy::build_in::<D>(&scene, threads.unwrap_or(c.threads), &opts.limits)?;
    if let Err(why) = built.engine.restore(&c.engine) {
        return refuse(why);
    }
    // Everything checked: the folder is taken back and its series cut to the checkpoint.
    let mut folder = OutFolder::reopen(dir, &VtkSeries::files_of(&state.frames))?;
    let energy = state.energy_bytes.map(|b| folder.resume_series("energy.csv", b)).transpose()?;
    let walls = state.walls_bytes.map(|b| folder.resume_series("walls.csv", b)).transpose()?;
    let packing = state.packing_bytes.map(|b| folder.resume_series("packing.csv", b)).transpose()?;
    let vtk = if state.frames.is_empty() { None } else { Some(VtkSeries::resume(state.frames.clone(), &mut folder)?) };
    let opts = RunOptions { out: Some(dir.to_path_buf()), duration: c.duration, checkpoint_every: opts.checkpoint_every.or(c.every_s), ..opts.clone() };
    let outputs = Outputs { folder: Some(folder), energy, walls, packing, vtk };
    drive(&scene, built, &opts, Some((outputs, state)))
}

/// The resolved scene's file as a run writes it.
fn resolved_json(scene: &Scene) -> String {
    serde_json::to_string_pretty(&resolved(scene, scene.duration)).expect("serialisable") + "\n"
}

/// What the run loop carries besides the engine, saved in a checkpoint: the observers'
/// accumulators, the rows so far, what the outputs hold, and the run's clock.
#[derive(Default, Serialize, Deserialize)]
#[serde(bound = "")]
pub struct LoopState<D: Impacts = Plane> {
    walls_avg: WallAverager,
    wall_rows: Vec<WallRow>,
    /// The rows each stage ended at (an index into `wall_rows`), as the stages end.
    stage_ends: Vec<usize>,
    /// The largest energy residual so far, as a fraction of the energy put in.
    max_res: f64,
    /// The last energy row recorded (of a state that passed its checks): the summary's,
    /// so that a run stopped on a state gone wrong reports the last one that was not.
    last_row: Option<EnergyRow>,
    impact: Option<ImpactObserver<D>>,
    /// Bytes of energy.csv and walls.csv written (none: the run writes no such series).
    energy_bytes: Option<u64>,
    walls_bytes: Option<u64>,
    packing_bytes: Option<u64>,
    /// The packing rows and the profiles' samples so far (the scene's `output.contacts`),
    /// and the profiles' number of layers, fixed at the first sample.
    packing_rows: Vec<PackingRow>,
    profile_rows: Vec<ProfileSample>,
    profile_layers: Option<usize>,
    /// The frames written (time, s; file): none when the run writes none (a run that
    /// does has written its first before any checkpoint).
    frames: Vec<(f64, String)>,
    /// When the run started (seconds since the Unix epoch), and the wall-clock time its
    /// earlier parts took, s.
    started_unix_s: f64,
    wall_time_s: f64,
    /// Steps at which the run was resumed.
    resumed: Vec<u64>,
}

impl<D: Running> LoopState<D> {
    /// Record the energy balance now (with the ledger on): its residual, and a row of
    /// energy.csv.
    fn record_energy(&mut self, e: &dyn Engine<D>, out: &mut Outputs, stage: &str, energy_on: bool) -> Result<(), Error> {
        if energy_on {
            let row = e.energy_row();
            self.max_res = self.max_res.max(row.residual_j.abs() / row.put_in().max(f64::MIN_POSITIVE));
            self.last_row = Some(row);
            if let Some(w) = out.energy.as_mut() {
                w.row_in(stage, &row)?;
            }
        }
        Ok(())
    }

    /// Record a sample: the energy row, the walls' row (forces averaged since the last),
    /// and with `inside` (the contacts recorded at this step) the packing row and the
    /// profiles' sample.
    #[allow(clippy::too_many_arguments)]
    fn sample(&mut self, e: &dyn Engine<D>, out: &mut Outputs, stage: &str, energy_on: bool, inside: bool, length: f64, depth: f64) -> Result<(), Error> {
        self.record_energy(e, out, stage, energy_on)?;
        if let Some(row) = self.walls_avg.row(&e.view(), length, depth) {
            if let Some(w) = out.walls.as_mut() {
                w.row_in(stage, &row)?;
            }
            self.wall_rows.push(row);
        }
        if inside {
            D::inside(self, &e.view(), out, stage, length, depth)?;
        }
        Ok(())
    }
}

/// `--checkpoint-every`'s value (s of simulated time), if given, checked: above 0, and
/// with an output folder (`out`) to write in.
pub fn check_checkpoint_every(every: Option<f64>, out: bool) -> Result<(), Error> {
    let Some(s) = every else { return Ok(()) };
    crate::error::check_option(s.is_finite() && s > 0.0, "--checkpoint-every", s, "> 0 s of simulated time")?;
    crate::error::check_option(out, "--checkpoint-every", s, "with an output folder (--out) to write the checkpoints in")
}

/// What a checkpoint records besides the states: the run's scene as built (encoded at
/// the first checkpoint), its `--duration`, and the rate.
struct Checkpointing<'a> {
    scene: &'a Scene,
    json: std::cell::OnceCell<String>,
    duration: Option<f64>,
    every_s: Option<f64>,
    /// Steps between checkpoints (none: only a stop request writes one).
    every: Option<u64>,
}

impl Checkpointing<'_> {
    /// Write `checkpoint.bin` for the state after this step: the series flushed and synced
    /// first (the checkpoint holds their lengths), then the checkpoint, synced and renamed.
    fn write<D: Running>(&self, e: &dyn Engine<D>, out: &mut Outputs, st: &mut LoopState<D>, wall_time_s: f64) -> Result<(), Error> {
        let Some(folder) = out.folder.as_mut() else { return Ok(()) };
        st.energy_bytes = out.energy.as_mut().map(|s| s.written(true)).transpose()?;
        st.walls_bytes = out.walls.as_mut().map(|s| s.written(true)).transpose()?;
        st.packing_bytes = out.packing.as_mut().map(|s| s.written(true)).transpose()?;
        st.frames = out.vtk.as_ref().map(|v| v.frames().to_vec()).unwrap_or_default();
        let before = std::mem::replace(&mut st.wall_time_s, wall_time_s);
        let run = postcard::to_stdvec(&*st).expect("the run state encodes");
        st.wall_time_s = before;
        let c = Checkpoint {
            grainlab: env!("CARGO_PKG_VERSION").into(),
            commit: env!("GRAINLAB_COMMIT").into(),
            scene: self.json.get_or_init(|| serde_json::to_string(&resolved(self.scene, self.scene.duration)).expect("serialisable")).clone(),
            duration: self.duration,
            threads: e.threads(),
            every_s: self.every_s,
            step: e.steps(),
            time_s: e.time(),
            engine: e.save(),
            run,
        };
        folder.write_synced(CHECKPOINT, &c.encode())
    }
}

/// The run loop, from the start or (`resumed`: the outputs reopened and the loop's state;
/// the engine restored) from a checkpoint.
fn drive<D: Running>(scene: &Scene, mut built: Built<D>, opts: &RunOptions, resumed: Option<(Outputs, LoopState<D>)>) -> Result<RunReport, Error> {
    let duration = opts.duration.unwrap_or(scene.duration);
    let dt = built.time_step.dt_s;
    // The build checked the scene's duration; an override is checked here, and cuts a
    // protocol short.
    step_count(duration, dt, if opts.duration.is_some() { "--duration" } else { "duration" })?;
    check_checkpoint_every(opts.checkpoint_every, opts.out.is_some())?;
    let every = opts.checkpoint_every.map(|s| ((s / dt).round() as u64).max(1));
    let checkpointing = Checkpointing { scene, json: std::cell::OnceCell::new(), duration: opts.duration, every_s: opts.checkpoint_every, every };
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
    // The packing inside: contacts recorded at samples and frames.
    let inside = scene.output.contacts;
    let now = std::time::SystemTime::now();
    let fresh = resumed.is_none();
    let (mut outputs, mut st) = match resumed {
        Some((outputs, mut st)) => {
            st.resumed.push(built.engine.steps());
            (outputs, st)
        }
        None => {
            let mut outputs = Outputs { folder: None, energy: None, walls: None, packing: None, vtk: None };
            if let Some(dir) = &opts.out {
                let mut folder = OutFolder::claim(dir, opts.overwrite, &format!("run {}", scene.name))?;
                // The scene as it runs: the folder alone repeats the run.
                folder.write(RESOLVED_SCENE, resolved_json(scene).as_bytes())?;
                if energy_on {
                    outputs.energy = Some(folder.series("energy.csv")?);
                }
                if !built.engine.walls().is_empty() {
                    outputs.walls = Some(folder.series("walls.csv")?);
                    if inside {
                        outputs.packing = Some(folder.series("packing.csv")?);
                    }
                }
                if phases.iter().any(|p| p.frame_every.is_some()) {
                    outputs.vtk = Some(VtkSeries::new(&mut folder)?);
                }
                outputs.folder = Some(folder);
            }
            let st = LoopState {
                impact: (scene.analysis == Analysis::Impact).then(ImpactObserver::default),
                started_unix_s: now.duration_since(std::time::UNIX_EPOCH).map_or(0.0, |d| d.as_secs_f64()),
                ..LoopState::default()
            };
            (outputs, st)
        }
    };
    let started = std::time::UNIX_EPOCH + std::time::Duration::from_secs_f64(st.started_unix_s);
    let pipeline = built.explain();
    let e = built.engine.as_mut();
    // Where the run starts: step 0, or the checkpoint's step.
    let k0 = e.steps();
    let first_stage = phases.first().map_or("", |p| p.name.as_str());
    // Why the run stops early, if it does, and the first output that failed besides.
    let mut error: Option<Error> = None;
    if fresh {
        if let Some(o) = st.impact.as_mut() {
            o.start(&e.view());
        }
        error = st.record_energy(e, &mut outputs, first_stage, energy_on).and_then(|()| outputs.frame(e, false)).err();
    }
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
    let mut next_line = k0 * 10 / total.max(1) + 1;
    let bar = if opts.progress && !lines {
        let b = ProgressBar::new(total);
        b.set_style(ProgressStyle::with_template("{msg} [{bar:40}] {percent}% {elapsed_precise} eta {eta}").expect("template").progress_chars("=> "));
        b.set_message(scene.name.clone());
        b.set_position(k0);
        b.reset_eta();
        Some(b)
    } else {
        None
    };
    let t0 = Instant::now();
    let (length, depth) = (built.length, built.depth);
    let phases_run: &[Phase] = if error.is_none() { &phases } else { &[] };
    // The phase the run is in (its index), for a stage cut short.
    let mut reached = 0;
    'run: for (index, phase) in phases_run.iter().enumerate() {
        // A resumed run skips the phases done, and the change of the one it is in.
        if phase.last() <= k0 {
            continue;
        }
        reached = index;
        let stage = phase.name.as_str();
        if phase.first >= k0 && phase.change != MotionChange::default() {
            e.change_motion(&phase.change);
        }
        let shown = if stage.is_empty() { scene.name.clone() } else { format!("{} [{stage}]", scene.name) };
        for j in (k0.max(phase.first) - phase.first + 1)..=phase.steps {
            let k = phase.first + j;
            // A stop request makes this step the last: checkpointed, and sampled like the
            // last of the run.
            let stopping = stop.is_some_and(|s| s.load(Ordering::Relaxed)) || opts.stop_after_step == Some(k);
            let sample = j % phase.sample_every == 0 || j == phase.steps;
            let frame = phase.frame_every.is_some_and(|every| j % every == 0);
            let checkpoint = (checkpointing.every.is_some_and(|n| k % n == 0) && k < total) || (stopping && outputs.folder.is_some());
            // Whether anything below looks at the grains after this step: else the step's
            // final half kick is left to the next one's drift.
            let look = sample || frame || checkpoint || stopping || st.impact.is_some();
            if (sample || frame || stopping) && inside {
                e.want_contacts();
            }
            if let Err(err) = e.advance(look) {
                error = Some(err);
                break 'run;
            }
            if let Some(o) = st.impact.as_mut() {
                // The observer records every step (its curve is an output): every step's
                // state is checked first, cheap for the one or two grains of an impact.
                if let Err(err) = e.health() {
                    error = Some(err);
                    break 'run;
                }
                o.observe(&e.view());
            }
            st.walls_avg.accumulate(&e.view());
            // Nothing is written of a state that failed its check: outputs hold only
            // finite numbers, and the stop is diagnosed in the summary.
            if (sample || frame || checkpoint || stopping)
                && let Err(err) = e.health()
            {
                error = Some(err);
                break 'run;
            }
            if sample {
                or_stop!('run, st.sample(e, &mut outputs, stage, energy_on, inside, length, depth));
            }
            if frame {
                or_stop!('run, outputs.frame(e, inside));
            }
            if j == phase.steps {
                st.stage_ends.push(st.wall_rows.len());
            }
            // The state after this step and everything written of it, before a stop's
            // own sample: the resumed run goes on as if the stop had not been.
            if checkpoint {
                let so_far = st.wall_time_s + t0.elapsed().as_secs_f64();
                or_stop!('run, checkpointing.write(e, &mut outputs, &mut st, so_far));
            }
            if k % 1000 == 0
                && let Some(b) = &bar
            {
                b.set_position(k);
                b.set_message(progress_message(&shown, e.time(), st.wall_rows.last()));
            }
            // Without a terminal, a line at each tenth of the run.
            if lines && k * 10 >= next_line * total {
                next_line = k * 10 / total + 1;
                let secs = t0.elapsed().as_secs_f64();
                let eta = secs * (total - k) as f64 / (k - k0) as f64;
                let _ = writeln!(std::io::stderr().lock(), "{}: {}% of {} steps, {secs:.1} s, eta {eta:.1} s", progress_message(&shown, e.time(), st.wall_rows.last()), 100 * k / total, total);
            }
            if stopping {
                if !sample {
                    or_stop!('run, st.sample(e, &mut outputs, stage, energy_on, inside, length, depth));
                }
                error = Some(Error::Interrupted { step: e.steps(), time: e.time() });
                break 'run;
            }
            if st.impact.as_ref().is_some_and(|o| o.finished()) {
                match e.health() {
                    Err(err) => error = Some(err),
                    Ok(()) => or_note!("energy.csv", st.record_energy(e, &mut outputs, stage, energy_on)),
                }
                break 'run;
            }
        }
    }
    // A stage cut short ends at the last row.
    if st.stage_ends.len() <= reached {
        st.stage_ends.push(st.wall_rows.len());
    }
    let wall_time = st.wall_time_s + t0.elapsed().as_secs_f64();
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let timings = e.timings();
    let total_t: f64 = timings.iter().map(|t| t.1.as_secs_f64()).sum::<f64>().max(f64::MIN_POSITIVE);
    let stage_timing = timings.iter().map(|(s, d)| StageTime { stage: s.clone(), seconds: d.as_secs_f64(), share: d.as_secs_f64() / total_t }).collect();
    let mut stages = Vec::new();
    let mut shear = None;
    // The profiles of the last averaged stretch (profiles.csv), with the free grains'
    // mean diameter and density for the inertial number.
    let mut profiles: Option<Vec<LayerProfile>> = None;
    let (diameter, density) = {
        let p = e.particles();
        let volume: f64 = (0..p.n_free).map(|i| p.m[i] / scene.materials[p.material[i] as usize].density).sum();
        (mean_diameter(p), p.m[..p.n_free].iter().sum::<f64>() / volume)
    };
    let blocking = Blocking::from(scene.statistics.blocks);
    let mut from = 0;
    for (phase, &to) in phases.iter().zip(&st.stage_ends) {
        let rows = &st.wall_rows[from..to];
        let mut averaged = (scene.analysis == Analysis::Shear && phase.average && rows.len() >= 4).then(|| shear_summary(rows, e.particles(), length, depth, &scene.statistics));
        // The end state is the last stage's: its overlaps are that stage's.
        if let Some(a) = averaged.as_mut().filter(|_| to == st.wall_rows.len()) {
            let p = e.particles();
            a.mean_overlap_rel = crate::kernels::cells::mean_overlap(&p.x, &p.r, p.n_free, &e.boundary()).map(|m| m.0);
        }
        if let Some(a) = averaged.as_mut() {
            // The packing's rows and profiles over the walls' averaging window.
            let end = rows.last().map_or(f64::INFINITY, |r| r.time_s);
            let within = |t: f64| t >= a.averaged_from_s && t <= end;
            let kept: Vec<PackingRow> = st.packing_rows.iter().filter(|r| within(r.time_s)).copied().collect();
            a.packing = packing_summary(&kept, blocking);
            let samples: Vec<ProfileSample> = st.profile_rows.iter().filter(|r| within(r.time_s)).cloned().collect();
            profiles = profile_summary(&samples, blocking, diameter, density).or(profiles);
        }
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
    provenance.resumed_at_steps.clone_from(&st.resumed);
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
        energy: energy_on.then(|| energy_summary(st.last_row.unwrap_or_else(|| e.energy_row()), st.max_res, dt)),
        impact: st.impact.as_ref().and_then(|o| o.summary()),
        impact_note: st.impact.as_ref().and_then(|o| o.unfinished()).map(String::from),
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
        for (series, name) in [(outputs.energy.take(), "energy.csv"), (outputs.walls.take(), "walls.csv"), (outputs.packing.take(), "packing.csv")] {
            if let Some(s) = series {
                or_note!(name, folder.close_series(s, name));
            }
        }
        if let Some(o) = st.impact.as_ref() {
            or_note!("force_overlap.csv", folder.write_series("force_overlap.csv", &o.curve));
        }
        if let Some(rows) = &profiles {
            or_note!("profiles.csv", folder.write_series("profiles.csv", rows));
        }
        // A completed run has nothing to resume: its checkpoint goes.
        if error.is_none() {
            or_note!(CHECKPOINT, folder.remove(CHECKPOINT));
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
fn shear_summary<D: Running>(rows: &[WallRow], p: &crate::physics::particles::Particles<D>, length: f64, depth: f64, statistics: &crate::scene::StatisticsSpec) -> ShearSummary {
    let solid: f64 = (0..p.n_free).map(|i| D::measure(p.r[i])).sum();
    let gap = rows.last().map_or(f64::NAN, |r| r.gap_m);
    stress_estimates(rows, Some(solid / D::cell_measure(length, depth, gap)).filter(|f| f.is_finite()), statistics)
}

