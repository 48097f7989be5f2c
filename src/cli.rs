//! The command line: `grainlab run|explain|scenes|...` (`grainlab --help` lists them all).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use grainlab::run::{RunOptions, run_scene, timing_table};
use grainlab::scenes::{BUILTIN, builtin};
use grainlab::{Error, Scene, build};

#[derive(Parser)]
#[command(name = "grainlab", version, about = "A 2D Hertz-Mindlin DEM engine, checked against LIGGGHTS and YADE")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene (a built-in name or a JSON file).
    Run {
        scene: String,
        /// Output directory for summary.json, CSV series and ParaView frames.
        #[arg(long)]
        out: Option<PathBuf>,
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
    /// Write an equivalent LIGGGHTS deck or YADE script, the shared particle file and
    /// export.json into a directory.
    Export {
        code: grainlab::export::Code,
        #[arg(required_unless_present = "explain_fields")]
        scene: Option<String>,
        #[arg(long, required_unless_present = "explain_fields")]
        out: Option<PathBuf>,
        /// A timing deck: record nothing, print the loop time (scripts/bench-peers).
        #[arg(long)]
        bench: bool,
        /// Print what each scene field becomes in this code's deck (what it cannot
        /// express first) and write nothing.
        #[arg(long, conflicts_with_all = ["scene", "out", "bench"])]
        explain_fields: bool,
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
    Digest { case_dir: PathBuf, code: grainlab::export::Code, run_dir: PathBuf },
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
    /// Run a scene over a list of time steps (and model variants) and write one CSV row
    /// per run: dt, cost, and errors against the converged run and closed form.
    Sweep {
        scene: String,
        /// Steps per Hertz contact time, comma-separated (e.g. 25,50,100,200).
        #[arg(long, value_delimiter = ',')]
        steps: Vec<f64>,
        /// Fractions of the Rayleigh time, comma-separated.
        #[arg(long, value_delimiter = ',')]
        rayleigh: Vec<f64>,
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
    /// List the built-in scenes, or print one as JSON.
    Scenes { name: Option<String> },
}

/// A built-in scene by name, or a scene file.
pub fn load_scene(arg: &str) -> Result<Scene, Error> {
    let path = std::path::Path::new(arg);
    if path.exists() {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(arg, e))?;
        return Scene::from_json(&text);
    }
    builtin(arg).ok_or_else(|| {
        let names: Vec<&str> = BUILTIN.iter().map(|b| b.0).collect();
        Error::Scene(format!("`{arg}` is neither a scene file nor a built-in scene ({})", names.join(", ")))
    })
}

fn execute(cli: Cli) -> Result<(), Error> {
    match cli.command {
        Command::Run { scene, out, duration, quiet, threads } => {
            let scene = load_scene(&scene)?;
            if let Some(d) = duration {
                grainlab::error::check(d.is_finite() && d > 0.0, "", "--duration", d, "> 0 s")?;
            }
            let built = grainlab::build_with(&scene, threads)?;
            eprintln!("{}", built.explain());
            let opts = RunOptions { out: out.clone(), progress: !quiet, duration };
            let summary = grainlab::run::run_built(&scene, built, &opts)?;
            eprint!("{}", timing_table(&summary));
            if let Some(w) = summary.energy.as_ref().and_then(|e| e.warning.as_ref()) {
                eprintln!("warning: {w}");
            }
            println!("{}", serde_json::to_string_pretty(&summary).expect("serialisable"));
            if let Some(dir) = out {
                eprintln!("wrote {}", dir.display());
            }
            let _ = run_scene;
            Ok(())
        }
        Command::Handover { threads, samples } => {
            println!("{}", serde_json::to_string_pretty(&grainlab::threads::hand_over_summary(threads, samples)?).expect("numbers serialise"));
            Ok(())
        }
        Command::Explain { scene } => {
            let scene = load_scene(&scene)?;
            println!("{}", build(&scene)?.explain());
            Ok(())
        }
        Command::Export { code, scene, out, bench, explain_fields } => {
            if explain_fields {
                print!("{}", grainlab::export::fields::explain(code));
                return Ok(());
            }
            let (Some(scene), Some(out)) = (scene, out) else { unreachable!("clap requires SCENE and --out without --explain-fields") };
            let scene = load_scene(&scene)?;
            for path in grainlab::export::export_with(&scene, code, &out, bench)? {
                println!("{}", path.display());
            }
            Ok(())
        }
        Command::Cases { root, filter } => {
            let n = grainlab::workbench::write_cases(&root, filter.as_deref())?;
            eprintln!("wrote {n} cases under {}", root.display());
            Ok(())
        }
        Command::Digest { case_dir, code, run_dir } => {
            let out = grainlab::workbench::digest(&case_dir, code, &run_dir)?;
            println!("{}", out.display());
            Ok(())
        }
        Command::Compare { root, filter, csv } => compare(&root, filter.as_deref(), csv.as_deref()),
        Command::Sweep { scene, steps, rayleigh, variants, duration, out } => {
            use grainlab::sweep::{Step, Variant, sweep};
            let scene = load_scene(&scene)?;
            let mut st: Vec<Step> = steps.iter().map(|&n| Step::PerContact(n)).collect();
            st.extend(rayleigh.iter().map(|&f| Step::Rayleigh(f)));
            for s in &st {
                let (ok, v) = match *s {
                    Step::PerContact(n) => (n.is_finite() && n >= 1.0, n),
                    Step::Rayleigh(f) => (f > 0.0 && f <= 1.0, f),
                };
                grainlab::error::check(ok, "", if matches!(s, Step::PerContact(_)) { "--steps" } else { "--rayleigh" }, v, ">= 1 steps per contact, or a Rayleigh fraction in (0, 1]")?;
            }
            let mut vars = vec![Variant::Scene];
            for f in &variants {
                vars.extend(Variant::family(f)?);
            }
            let rows = sweep(&scene, &st, &vars, duration, |r| eprintln!("{:<28} {:<16} dt = {:.3e} s  {:.1} ns/particle-step", r.variant, r.rule, r.dt_s, r.ns_per_particle_step))?;
            match out {
                Some(path) => {
                    let mut w = grainlab::output::csv::CsvSeries::create(&path)?;
                    for r in &rows {
                        w.row(r)?;
                    }
                    eprintln!("wrote {}", path.display());
                }
                None => {
                    let mut w = csv::Writer::from_writer(std::io::stdout());
                    for r in &rows {
                        w.serialize(r).map_err(|e| Error::Other(e.to_string()))?;
                    }
                }
            }
            Ok(())
        }
        Command::Scenes { name: None } => {
            for (n, d) in BUILTIN {
                println!("{n:<10} {d}");
            }
            Ok(())
        }
        Command::Scenes { name: Some(n) } => {
            let s = load_scene(&n)?;
            println!("{}", s.to_json());
            Ok(())
        }
    }
}

fn compare(root: &std::path::Path, filter: Option<&str>, csv: Option<&std::path::Path>) -> Result<(), Error> {
    use grainlab::workbench::{case_dirs, compare_case};
    let mut rows = Vec::new();
    for dir in case_dirs(root) {
        if filter.is_some_and(|f| !dir.to_string_lossy().contains(f)) {
            continue;
        }
        rows.extend(compare_case(&dir)?);
    }
    println!("{:<40} {:<9} {:<32} {:>14} {:>14} {:>10} {:>9} pass", "case", "code", "quantity", "engine", "reference", "diff", "bound");
    for r in &rows {
        let (d, kind) = if r.relative { (r.rel_diff, "rel") } else { (r.abs_diff, "abs") };
        println!(
            "{:<40} {:<9} {:<32} {:>14.7e} {:>14.7e} {:>10.2e} {:>5.0e} {kind} {}",
            r.case,
            r.code.name(),
            r.quantity,
            r.engine,
            r.reference,
            d,
            r.tolerance,
            if r.pass { "yes" } else { "NO" }
        );
    }
    let failed = rows.iter().filter(|r| !r.pass).count();
    eprintln!("{} comparisons, {} outside their bound", rows.len(), failed);
    if let Some(path) = csv {
        let mut w = grainlab::output::csv::CsvSeries::create(path)?;
        for r in &rows {
            w.row(r)?;
        }
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
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
