//! The command line: `grainlab run|explain|scenes|...` (`grainlab --help` lists them all).

use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use clap::{Parser, Subcommand};
use grainlab::Error;
use grainlab::build_limited;
use grainlab::physics::dim::Space;
use grainlab::scene::Dimension;
use grainlab::error::exit;
use grainlab::scene::limits::Limits;
use grainlab::output::{csv::CsvSeries, folder::OutFolder};
use grainlab::output::summary::timing_table;
use grainlab::study::run::{RunOptions, RunReport, run_report, run_scene};
use grainlab::scene::builtin::BUILTIN;

#[derive(Parser)]
#[command(name = "grainlab", version, about = "A 2D Hertz-Mindlin DEM engine, checked against LIGGGHTS, YADE and LAMMPS", after_help = EXIT_CODES)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Memory a scene may ask for (e.g. 512M, 8G): scenes whose estimate exceeds it are
    /// refused before anything is allocated. Default: half the machine's memory.
    #[arg(long, global = true, value_parser = grainlab::scene::limits::parse_bytes)]
    memory_budget: Option<u64>,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene (a built-in name or a JSON file).
    Run {
        scene: String,
        /// Output folder for summary.json, CSV series and ParaView frames: a new or
        /// empty folder, or one grainlab wrote (see --overwrite); its manifest.json lists
        /// what grainlab wrote.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Delete the files an earlier grainlab command wrote in --out (those its
        /// manifest.json lists) before the run. A folder holding anything else is refused.
        #[arg(long)]
        overwrite: bool,
        /// Override the scene's duration, s.
        #[arg(long)]
        duration: Option<f64>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        /// Threads for the contact forces (needs the `parallel` feature); results are
        /// bit-identical to one thread.
        #[arg(long, default_value_t = 1)]
        threads: usize,
        /// Write a checkpoint (checkpoint.bin in --out, replaced each time) every this
        /// much simulated time, s; `grainlab resume DIR` continues the run from it, bit
        /// for bit. A stop request (SIGINT, SIGTERM) writes one whatever this says.
        #[arg(long, value_name = "SECONDS_SIMULATED")]
        checkpoint_every: Option<f64>,
    },
    /// Continue an interrupted or killed run from its output folder's checkpoint: the
    /// folder then holds what the run that never stopped would have written (energy.csv,
    /// walls.csv, frames: the same bytes).
    Resume {
        /// The run's output folder (its --out).
        dir: PathBuf,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        /// Threads for the contact forces (default: the run's; the bits do not depend on it).
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Time the thread pool's hand-over with no work (feature `parallel`): the fixed cost
    /// of every stage on several threads, on this host now. Prints JSON, nanoseconds.
    Handover {
        #[arg(long, default_value_t = 2)]
        threads: usize,
        #[arg(long, default_value_t = 20000)]
        samples: usize,
    },
    /// Print the step pipeline of a scene in one line, with dt and steps per contact.
    Explain { scene: String },
    /// Write an equivalent LIGGGHTS deck, YADE script or LAMMPS deck, the shared particle file and
    /// export.json into a directory.
    Export {
        code: grainlab::workbench::export::Code,
        #[arg(required_unless_present = "explain_fields")]
        scene: Option<String>,
        /// Output folder: new, empty, or one grainlab wrote (see --overwrite).
        #[arg(long, required_unless_present = "explain_fields")]
        out: Option<PathBuf>,
        /// Delete the files an earlier grainlab command wrote in --out first.
        #[arg(long)]
        overwrite: bool,
        /// A timing deck: record nothing, print the loop time (scripts/bench-peers).
        #[arg(long)]
        bench: bool,
        /// Print what each scene field becomes in this code's deck (what it cannot
        /// express first) and write nothing.
        #[arg(long, conflicts_with_all = ["scene", "out", "bench"])]
        explain_fields: bool,
    },
    /// Run a shear cell for --steps steps and write the state its last step's contacts
    /// were computed from (scene.txt, grains.txt, history.txt) and those contacts
    /// (contacts.txt), for the reference codes to evaluate without moving
    /// (scripts/frozen/, src/workbench/frozen.rs).
    Freeze {
        scene: String,
        #[arg(long)]
        steps: u64,
        /// Output folder: new, empty, or one grainlab wrote (see --overwrite).
        #[arg(long)]
        out: PathBuf,
        /// Delete the files an earlier grainlab command wrote in --out first.
        #[arg(long)]
        overwrite: bool,
    },
    /// Write the workbench cases (scene, case.json, decks) under a root folder.
    Cases {
        #[arg(long, default_value = "reference/cases")]
        root: PathBuf,
        /// Only cases whose name contains this.
        #[arg(long)]
        filter: Option<String>,
    },
    /// Measure a reference code's raw output (series.txt or walls.txt in RUN_DIR) into
    /// CASE_DIR/expected/CODE/.
    Digest { case_dir: PathBuf, code: grainlab::workbench::export::Code, run_dir: PathBuf },
    /// Run the engine on every committed case and compare it with the reference data.
    Compare {
        #[arg(long, default_value = "reference/cases")]
        root: PathBuf,
        #[arg(long)]
        filter: Option<String>,
        /// Write the comparison table as CSV here.
        #[arg(long)]
        csv: Option<PathBuf>,
    },
    /// Run a scene over one lever, the time step or the grains' stiffness (and model
    /// variants), and write one CSV row per run: dt, overlap, stiffness number, cost
    /// (median of repeated timings), and errors against a reference from runs beyond the
    /// listed range (Richardson-extrapolated in dt, or extrapolated to rigid grains), and
    /// against closed forms.
    Sweep {
        scene: String,
        /// Steps per Hertz contact time, comma-separated (e.g. 25,50,100,200).
        #[arg(long, value_delimiter = ',')]
        steps: Vec<f64>,
        /// Fractions of the Rayleigh time, comma-separated.
        #[arg(long, value_delimiter = ',')]
        rayleigh: Vec<f64>,
        /// Scales of every material's Young's modulus, comma-separated (e.g.
        /// 0.001,0.01,0.1,1): two or more make stiffness the lever, at the scene's time
        /// step rule or one listed step.
        #[arg(long, value_delimiter = ',')]
        stiffness: Vec<f64>,
        /// Timed runs of each point of a deterministic scene; the cost is their median.
        #[arg(long, default_value_t = 1)]
        repeats: usize,
        /// Packing seeds (A..B or a list): every point an ensemble over them, its values
        /// ensemble means with 95% intervals from the run-to-run spread.
        #[arg(long)]
        seeds: Option<String>,
        /// Model variant families: tangential, clamp, lever (comma-separated).
        #[arg(long, value_delimiter = ',')]
        variants: Vec<String>,
        /// Override the scene's duration, s.
        #[arg(long)]
        duration: Option<f64>,
        /// CSV file to write (default: stdout).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Run a shear scene over several packing seeds and report each quantity's ensemble
    /// mean with a 95% interval from the run-to-run spread, beside each run's own block
    /// interval. Prints JSON.
    Ensemble {
        scene: String,
        /// The packing seeds: A..B (both included) or a comma-separated list.
        #[arg(long)]
        seeds: String,
        /// Override the scene's duration, s.
        #[arg(long)]
        duration: Option<f64>,
        /// Threads for each run (needs the `parallel` feature); bit-identical to one.
        #[arg(long, default_value_t = 1)]
        threads: usize,
        /// Output folder for ensemble.json (the rules of `run --out`).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Delete what an earlier grainlab command wrote in --out first.
        #[arg(long)]
        overwrite: bool,
    },
    /// List the built-in scenes, or print one as JSON.
    Scenes { name: Option<String> },
}

/// The exit codes, for `grainlab --help` (`grainlab::error::exit`; README, "The output
/// folder, interruption and exit codes").
const EXIT_CODES: &str = "Exit codes:
  0    success
  1    other failure (e.g. compare with comparisons outside their bound)
  2    bad input: a scene, a field an export cannot express, an option value, or an
       output folder grainlab may not use
  3    I/O failure (a summary that could not be written is on stdout)
  4    run stopped unstable, with a diagnosis
  130  interrupted by SIGINT or SIGTERM, everything written";

/// A flag that SIGINT and SIGTERM set: the run then ends after the step under way and
/// writes everything (`status: "interrupted"`). A second signal ends the process at once,
/// with the same exit code.
fn interrupt_flag() -> Result<Arc<AtomicBool>, Error> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let flag = Arc::new(AtomicBool::new(false));
    for sig in [SIGINT, SIGTERM] {
        let failed = |e| Error::io(format!("installing a handler for signal {sig}"), e);
        // First the exit, which sees the flag only a first signal has set.
        signal_hook::flag::register_conditional_shutdown(sig, exit::INTERRUPTED.into(), Arc::clone(&flag)).map_err(failed)?;
        signal_hook::flag::register(sig, Arc::clone(&flag)).map_err(failed)?;
    }
    Ok(flag)
}

/// Set when stdout's reader has gone (`grainlab scenes shear | head -3`).
static STDOUT_CLOSED: AtomicBool = AtomicBool::new(false);

/// Write to stdout. A closed pipe is not an error: what follows is dropped and the
/// command finishes its work and exits with its own code (0 for a listing), quietly. Any
/// other failure (a full disk behind `> file`) is an I/O error.
fn to_stdout(text: std::fmt::Arguments) -> Result<(), Error> {
    if STDOUT_CLOSED.load(Ordering::Relaxed) {
        return Ok(());
    }
    let mut out = std::io::stdout().lock();
    match out.write_fmt(text).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) => {
            STDOUT_CLOSED.store(true, Ordering::Relaxed);
            if e.kind() == std::io::ErrorKind::BrokenPipe { Ok(()) } else { Err(Error::io("stdout", e)) }
        }
    }
}

/// `println!` through [`to_stdout`]: `say!(...)?`.
macro_rules! say {
    ($($arg:tt)*) => { to_stdout(format_args!("{}\n", format_args!($($arg)*))) };
}

/// `eprintln!` that does not panic when stderr is closed: a message nobody can read is
/// dropped.
macro_rules! note {
    ($($arg:tt)*) => {{
        let _ = writeln!(std::io::stderr().lock(), $($arg)*);
    }};
}

/// A `--duration` override: a finite time > 0 s.
fn check_duration(duration: Option<f64>) -> Result<(), Error> {
    match duration {
        Some(d) => grainlab::error::check_option(d.is_finite() && d > 0.0, "--duration", d, "> 0 s"),
        None => Ok(()),
    }
}

/// What `run` and `resume` print of a run: the stage timings, a warning, the headline,
/// then the summary on stdout; the run's error, if any.
fn report_run(report: RunReport, out: Option<&std::path::Path>) -> Result<(), Error> {
    let RunReport { summary, ending, write_error, unwritten } = report;
    note!("{}", timing_table(&summary).trim_end());
    if let Some(w) = summary.energy.as_ref().and_then(|e| e.warning.as_ref()) {
        note!("warning: {w}");
    }
    // The run in one line, before the JSON.
    note!("{}", grainlab::output::summary::headline(&summary));
    // Always printed: when summary.json could not be written, this is its copy.
    let printed = say!("{}", serde_json::to_string_pretty(&summary).expect("serialisable"));
    let dir = out.unwrap_or(std::path::Path::new("")).display();
    match (write_error, ending) {
        (Some(failed), ending) => {
            if let Some(end) = ending {
                note!("error: {end}");
            }
            note!("error: could not write {} in {dir}; the summary is on stdout", unwritten.join(", "));
            Err(failed)
        }
        (None, ending) => {
            if out.is_some() {
                note!("wrote {dir}");
            }
            ending.map_or(printed, Err)
        }
    }
}

/// Run a built scene (in the plane or in space): the pipeline first, then the run with
/// its stop flag, and the report.
fn run_in<D: grainlab::study::run::Running>(scene: &grainlab::Scene, built: grainlab::Built<D>, mut opts: RunOptions, out: Option<&std::path::Path>) -> Result<(), Error> {
    note!("{}", built.explain());
    opts.stop = Some(interrupt_flag()?);
    report_run(run_report(scene, built, &opts)?, out)
}

/// `explain`'s lines: the pipeline, then every effect.
fn explain<D: grainlab::physics::dim::Dim>(built: &grainlab::Built<D>) -> Result<(), Error> {
    say!("{}\n{}", built.explain(), built.explain_effects().trim_end())
}

fn execute(cli: Cli) -> Result<(), Error> {
    let limits = cli.memory_budget.map_or_else(Limits::machine, Limits::with_memory);
    let load_scene = |arg: &str| grainlab::scene::builtin::load(arg, &limits);
    match cli.command {
        Command::Run { scene, out, overwrite, duration, quiet, threads, checkpoint_every } => {
            let scene = load_scene(&scene)?;
            check_duration(duration)?;
            // Refused before a long build (the run checks the same).
            grainlab::study::run::check_checkpoint_every(checkpoint_every, out.is_some())?;
            if let Some(dir) = &out {
                // Refused before a long build; the run claims the folder when it starts.
                OutFolder::check(dir, overwrite)?;
            }
            let opts = RunOptions { out: out.clone(), overwrite, progress: !quiet, duration, limits: limits.clone(), stop: None, command: std::env::args().collect(), checkpoint_every, ..RunOptions::default() };
            let _ = run_scene;
            match scene.dimension {
                Dimension::Two => run_in(&scene, build_limited(&scene, threads, &limits)?, opts, out.as_deref()),
                Dimension::Three => run_in(&scene, grainlab::study::accuracy::build_in::<Space>(&scene, threads, &limits)?, opts, out.as_deref()),
            }
        }
        Command::Resume { dir, quiet, threads } => {
            let opts = RunOptions { progress: !quiet, limits, stop: Some(interrupt_flag()?), command: std::env::args().collect(), ..RunOptions::default() };
            note!("resuming {}", dir.display());
            report_run(grainlab::study::run::resume(&dir, threads, &opts)?, Some(&dir))
        }
        Command::Handover { threads, samples } => {
            say!("{}", serde_json::to_string_pretty(&grainlab::kernels::threads::hand_over_summary(threads, samples)?).expect("numbers serialise"))
        }
        Command::Explain { scene } => {
            let scene = load_scene(&scene)?;
            match scene.dimension {
                Dimension::Two => explain(&build_limited(&scene, 1, &limits)?),
                Dimension::Three => explain(&grainlab::study::accuracy::build_in::<Space>(&scene, 1, &limits)?),
            }
        }
        Command::Export { code, scene, out, overwrite, bench, explain_fields } => {
            if explain_fields {
                return say!("{}", grainlab::workbench::export::fields::explain(code).trim_end());
            }
            let (Some(scene), Some(out)) = (scene, out) else { unreachable!("clap requires SCENE and --out without --explain-fields") };
            let scene = load_scene(&scene)?;
            let files = grainlab::workbench::export::export_files(&scene, code, bench, &limits)?;
            let mut folder = OutFolder::claim(&out, overwrite, &format!("export {} {}", code.name(), scene.name))?;
            for (name, text) in files {
                folder.write(name, text.as_bytes())?;
                say!("{}", out.join(name).display())?;
            }
            folder.finish("completed")
        }
        Command::Freeze { scene, steps, out, overwrite } => {
            let scene = load_scene(&scene)?;
            grainlab::error::check_option(steps >= 1, "--steps", steps, ">= 1")?;
            let f = grainlab::workbench::frozen::freeze(&scene, steps)?;
            let mut folder = OutFolder::claim(&out, overwrite, &format!("freeze {}", scene.name))?;
            for (name, text) in [("scene.txt", &f.scene_txt), ("grains.txt", &f.grains_txt), ("history.txt", &f.history_txt), ("contacts.txt", &f.contacts_txt)] {
                folder.write(name, text.as_bytes())?;
            }
            folder.finish("completed")?;
            say!("{}: {} contacts at step {steps}", out.display(), f.contacts.len())
        }
        Command::Cases { root, filter } => {
            let n = grainlab::workbench::write_cases(&root, filter.as_deref())?;
            note!("wrote {n} cases under {}", root.display());
            Ok(())
        }
        Command::Digest { case_dir, code, run_dir } => {
            let out = grainlab::workbench::digest(&case_dir, code, &run_dir)?;
            say!("{}", out.display())
        }
        Command::Compare { root, filter, csv } => compare(&root, filter.as_deref(), csv.as_deref()),
        Command::Sweep { scene, steps, rayleigh, stiffness, repeats, seeds, variants, duration, out } => {
            use grainlab::study::sweep::{Step, SweepPlan, Variant, sweep};
            let scene = load_scene(&scene)?;
            let mut st: Vec<Step> = steps.iter().map(|&n| Step::PerContact(n)).collect();
            st.extend(rayleigh.iter().map(|&f| Step::Rayleigh(f)));
            for s in &st {
                let (ok, v) = match *s {
                    Step::PerContact(n) => (n.is_finite() && n >= 1.0, n),
                    Step::Rayleigh(f) => (f > 0.0 && f <= 1.0, f),
                    Step::Scene => (true, 0.0),
                };
                grainlab::error::check_option(ok, if matches!(s, Step::PerContact(_)) { "--steps" } else { "--rayleigh" }, v, ">= 1 steps per contact, or a Rayleigh fraction in (0, 1]")?;
            }
            let mut vars = vec![Variant::Scene];
            for f in &variants {
                vars.extend(Variant::family(f)?);
            }
            let seeds = seeds.as_deref().map(grainlab::study::ensemble::parse_seeds).transpose()?.unwrap_or_default();
            let plan = SweepPlan { steps: st, stiffness, variants: vars, duration, repeats, seeds };
            let rows = sweep(&scene, &plan, &limits, |line| note!("{line}"))?;
            match out {
                Some(path) => {
                    let mut w = CsvSeries::staged(&path)?;
                    for r in &rows {
                        w.row(r)?;
                    }
                    w.finish()?;
                    note!("wrote {}", path.display());
                }
                None => {
                    let mut w = csv::Writer::from_writer(Vec::new());
                    for r in &rows {
                        w.serialize(r).map_err(|e| Error::Other(e.to_string()))?;
                    }
                    let text = w.into_inner().map_err(|e| Error::Other(e.to_string()))?;
                    to_stdout(format_args!("{}", String::from_utf8_lossy(&text)))?;
                }
            }
            Ok(())
        }
        Command::Ensemble { scene, seeds, duration, threads, out, overwrite } => {
            use grainlab::study::ensemble::{ensemble, parse_seeds};
            let scene = load_scene(&scene)?;
            let seeds = parse_seeds(&seeds)?;
            check_duration(duration)?;
            if let Some(dir) = &out {
                OutFolder::check(dir, overwrite)?;
            }
            let e = ensemble(&scene, &seeds, duration, threads, &limits, |r| {
                let ratio = r.stress_ratio.map(|x| format!("tau/sigma = {:.4} +- {:.4} (95%, {} blocks)", x.mean, x.ci95, x.blocks)).unwrap_or_else(|| "no tau/sigma".into());
                note!("seed {}: {}; {ratio}; {:.1} s", r.seed, r.status, r.wall_time_s);
            })?;
            if let Some(x) = &e.stress_ratio {
                let spread = x.spread_over_standard_error.map(|q| format!("; run-to-run spread {q:.2}x the runs' mean block standard error (about 1 if their intervals hold)")).unwrap_or_default();
                note!("{}: tau/sigma = {:.4} +- {:.4} (95%, from the spread of {} runs: std {:.4}){spread}", e.scene, x.mean, x.ci95, x.runs, x.std);
            }
            let text = serde_json::to_string_pretty(&e).expect("serialisable") + "\n";
            if let Some(dir) = &out {
                let mut folder = OutFolder::claim(dir, overwrite, &format!("ensemble {}", e.scene))?;
                folder.write("ensemble.json", text.as_bytes())?;
                folder.finish("completed")?;
                note!("wrote {}", dir.display());
            }
            to_stdout(format_args!("{text}"))
        }
        Command::Scenes { name: None } => {
            for (n, d) in BUILTIN {
                say!("{n:<10} {d}")?;
            }
            Ok(())
        }
        Command::Scenes { name: Some(n) } => {
            let s = load_scene(&n)?;
            say!("{}", s.to_json())
        }
    }
}

fn compare(root: &std::path::Path, filter: Option<&str>, csv: Option<&std::path::Path>) -> Result<(), Error> {
    let rows = grainlab::workbench::compare_all(root, filter)?;
    say!("{:<40} {:<9} {:<32} {:>14} {:>14} {:>10} {:>9} pass", "case", "code", "quantity", "engine", "reference", "diff", "bound")?;
    for r in &rows {
        let (d, kind) = (r.diff(), if r.relative { "rel" } else { "abs" });
        say!(
            "{:<40} {:<9} {:<32} {:>14.7e} {:>14.7e} {:>10.2e} {:>5.0e} {kind} {}",
            r.case,
            r.code.name(),
            r.quantity,
            r.engine,
            r.reference,
            d,
            r.tolerance,
            if r.pass { "yes" } else { "NO" }
        )?;
    }
    let failed = rows.iter().filter(|r| !r.pass).count();
    note!("{} comparisons, {} outside their bound", rows.len(), failed);
    if let Some(path) = csv {
        let mut w = CsvSeries::staged(path)?;
        for r in &rows {
            w.row(r)?;
        }
        w.finish()?;
    }
    if failed > 0 {
        return Err(Error::Other(format!("{failed} comparisons outside their bound")));
    }
    Ok(())
}

pub fn main() -> ExitCode {
    match execute(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            note!("error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
