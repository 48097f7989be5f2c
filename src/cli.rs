//! The command line: `grainlab run|explain|scenes`.

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
    },
    /// Print the step pipeline of a scene in one line, with dt and steps per contact.
    Explain { scene: String },
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
        Command::Run { scene, out, duration, quiet } => {
            let scene = load_scene(&scene)?;
            if let Some(d) = duration {
                grainlab::error::check(d.is_finite() && d > 0.0, "", "--duration", d, "> 0 s")?;
            }
            let built = build(&scene)?;
            eprintln!("{}", built.explain());
            let opts = RunOptions { out: out.clone(), progress: !quiet, duration };
            let summary = grainlab::run::run_built(&scene, built, &opts)?;
            eprint!("{}", timing_table(&summary));
            println!("{}", serde_json::to_string_pretty(&summary).expect("serialisable"));
            if let Some(dir) = out {
                eprintln!("wrote {}", dir.display());
            }
            let _ = run_scene;
            Ok(())
        }
        Command::Explain { scene } => {
            let scene = load_scene(&scene)?;
            println!("{}", build(&scene)?.explain());
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

pub fn main() -> ExitCode {
    match execute(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
