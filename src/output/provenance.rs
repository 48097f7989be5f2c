//! Provenance: what produced a run's outputs. Every output folder holds the scene as it
//! ran, every default filled in (`scene.resolved.json`: `grainlab run DIR/scene.resolved.json`
//! repeats the run bit for bit), and the summary's `provenance` block says which grainlab
//! (version and the commit it was built from), which command line, which CPU and how
//! many threads, and when it started and ended.

use std::time::SystemTime;

use serde::Serialize;

use crate::scene::{Grains, Scene};

/// The resolved scene's file name in an output folder.
pub const RESOLVED_SCENE: &str = "scene.resolved.json";

/// What produced a run (the summary's `provenance` block).
#[derive(Clone, Debug, Serialize)]
pub struct Provenance {
    /// grainlab's version (Cargo.toml).
    pub grainlab: String,
    /// The git commit the binary was built from, with `+modified` when the working tree
    /// had changes not committed; `unknown` for a build outside a git checkout.
    pub commit: String,
    /// The command line as given (empty when the run was started from the library).
    pub command: Vec<String>,
    /// The CPU (model name, family and model numbers, from /proc/cpuinfo).
    pub cpu: String,
    /// Threads the contact and per-grain stages used (the bits do not depend on it).
    pub threads: usize,
    /// Operating system and architecture.
    pub os: String,
    /// Start and end of the run, UTC (RFC 3339).
    pub started_utc: String,
    pub ended_utc: String,
    /// The scene as run, in the output folder (none without one).
    pub scene_file: Option<String>,
    /// The steps at which the run was resumed from a checkpoint (`grainlab resume`), in
    /// order; `started_utc` is the first part's start.
    pub resumed_at_steps: Vec<u64>,
}

impl Provenance {
    /// The provenance of a run started at `started`, on `threads`, by `command`.
    pub fn new(started: SystemTime, threads: usize, command: &[String], scene_file: Option<String>) -> Self {
        Provenance {
            grainlab: env!("CARGO_PKG_VERSION").into(),
            commit: env!("GRAINLAB_COMMIT").into(),
            command: command.to_vec(),
            cpu: crate::engine::effects::this_cpu(),
            threads,
            os: format!("{} {}", std::env::consts::OS, std::env::consts::ARCH),
            started_utc: utc(started),
            ended_utc: String::new(),
            scene_file,
            resumed_at_steps: Vec::new(),
        }
    }
    /// Note the end of the run, now.
    pub fn end(&mut self) {
        self.ended_utc = utc(SystemTime::now());
    }
}

/// A time as RFC 3339 UTC, to the second.
fn utc(t: SystemTime) -> String {
    humantime::format_rfc3339_seconds(t).to_string()
}

/// The scene as a run with `duration` (s) ran it: every default filled in (serialising
/// the parsed scene writes them all), the duration the run was given, and a grain file's
/// path made absolute, so that the file repeats the run from any working directory.
pub fn resolved(scene: &Scene, duration: f64) -> Scene {
    let mut s = scene.clone();
    s.duration = duration;
    if let Grains::File { path, .. } = &mut s.grains
        && let Ok(abs) = std::fs::canonicalize(&*path)
    {
        *path = abs.display().to_string();
    }
    s
}
