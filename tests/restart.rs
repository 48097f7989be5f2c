//! Exact restart (issue 27, item 2): a run stopped at a checkpoint (a stop request, or a
//! process killed after a `--checkpoint-every` checkpoint) and resumed with `grainlab
//! resume` writes energy.csv, walls.csv, the frames and their index byte for byte as the
//! run that never stopped, on one thread or two; a damaged checkpoint, one of another
//! run or of another build, is refused and changes nothing in the folder.
//!
//! The reference for every comparison is the same scene run without a stop: the
//! conservation of bits is the claim, so the tolerance is zero.

use std::path::{Path, PathBuf};

use grainlab::output::checkpoint::{CHECKPOINT, Checkpoint};
use grainlab::scene::Scene;
use grainlab::study::run::{RunOptions, RunReport, resume, run_report};

/// The workbench's protocol (200 grains under 100 kPa, shear at +-0.5 m/s then +-1 m/s),
/// its first two stages made longer and sampled less often, with frames and contacts:
/// stages, a loaded wall, frames and rows all cross the stops.
fn protocol() -> Scene {
    let mut s = grainlab::workbench::cases::protocol_case();
    s.stages.truncate(2);
    s.stages[0].samples = Some(100);
    s.stages[0].duration = 4e-4;
    s.stages[1].duration = 8e-4;
    s.stages[1].samples = Some(40);
    s.duration = 1.2e-3;
    s.output.frames = 6;
    // The contacts' frames and packing.csv too.
    s.output.contacts = true;
    s
}

fn limits() -> grainlab::scene::limits::Limits {
    grainlab::scene::limits::Limits::machine()
}

/// Run `scene` into `dir` on `threads`, stopped after step `stop` if given.
fn run(scene: &Scene, dir: &Path, threads: usize, stop: Option<u64>) -> RunReport {
    let opts = RunOptions { out: Some(dir.to_path_buf()), stop_after_step: stop, ..RunOptions::default() };
    match scene.dimension {
        grainlab::scene::Dimension::Two => run_report(scene, grainlab::build_limited(scene, threads, &limits()).unwrap(), &opts).unwrap(),
        grainlab::scene::Dimension::Three => run_report(scene, grainlab::build_in::<grainlab::physics::dim::Space>(scene, threads, &limits()).unwrap(), &opts).unwrap(),
    }
}

/// Resume `dir` on `threads`, stopped again after step `stop` if given.
fn resumed(dir: &Path, threads: usize, stop: Option<u64>) -> RunReport {
    resume(dir, Some(threads), &RunOptions { stop_after_step: stop, ..RunOptions::default() }).unwrap()
}

/// The outputs a resumed run must give back byte for byte: every file but the summary
/// (its wall times and provenance differ), the manifest (which lists those) and the
/// resolved scene (written once).
fn outputs(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    for sub in ["", "frames"] {
        let Ok(entries) = std::fs::read_dir(dir.join(sub)) else { continue };
        for e in entries {
            let path = e.unwrap().path();
            let name = path.strip_prefix(dir).unwrap().display().to_string();
            if path.is_file() && !["summary.json", "manifest.json", "scene.resolved.json"].contains(&name.as_str()) {
                out.push((name, std::fs::read(&path).unwrap()));
            }
        }
    }
    out.sort();
    out
}

/// Every file of `dir` (name and bytes), to show a refusal changed nothing.
fn everything(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out: Vec<(String, Vec<u8>)> = Vec::new();
    for sub in ["", "frames"] {
        for e in std::fs::read_dir(dir.join(sub)).into_iter().flatten() {
            let path = e.unwrap().path();
            if path.is_file() {
                out.push((path.display().to_string(), std::fs::read(&path).unwrap()));
            }
        }
    }
    out.sort();
    out
}

fn assert_same(reference: &Path, dir: &Path, what: &str) {
    let (a, b) = (outputs(reference), outputs(dir));
    let names = |v: &[(String, Vec<u8>)]| v.iter().map(|f| f.0.clone()).collect::<Vec<_>>();
    assert_eq!(names(&a), names(&b), "{what}: the same files");
    for ((name, x), (_, y)) in a.iter().zip(&b) {
        assert!(x == y, "{what}: {name} differs ({} and {} bytes)", x.len(), y.len());
    }
}

/// Steps of the protocol worth stopping at: right after a neighbour rebuild, at the last
/// step of the first stage (the resumed run makes the second stage's change), at the
/// second stage's first step, and at a step that is no sample, frame or stage end
/// (where the run that never stops leaves the final half kick to the next step).
fn stops(scene: &Scene) -> Vec<(&'static str, u64)> {
    let mut built = grainlab::build(scene).unwrap();
    let dt = built.time_step.dt_s;
    let first_stage = (scene.stages[0].duration / dt).ceil() as u64;
    let e = built.engine.as_mut();
    let mut rebuild = None;
    let mut builds = e.neighbour_builds();
    while rebuild.is_none() {
        e.step().unwrap();
        if e.neighbour_builds() > builds && e.steps() > 500 {
            rebuild = Some(e.steps());
        }
        builds = e.neighbour_builds();
    }
    vec![("a neighbour rebuild", rebuild.unwrap()), ("the end of a stage", first_stage), ("a stage's first step", first_stage + 1), ("a step without outputs", first_stage + 1237)]
}

#[test]
fn a_run_stopped_and_resumed_writes_what_the_run_that_never_stopped_writes() {
    let scene = protocol();
    let tmp = tempfile::tempdir().unwrap();
    let reference = tmp.path().join("reference");
    let r = run(&scene, &reference, 1, None);
    assert_eq!(r.summary.status, "completed");
    assert!(!reference.join(CHECKPOINT).exists(), "a completed run leaves no checkpoint");
    for (what, step) in stops(&scene) {
        let dir = tmp.path().join(format!("stop-{step}"));
        let stopped = run(&scene, &dir, 1, Some(step));
        assert_eq!((stopped.summary.status.as_str(), stopped.summary.steps), ("interrupted", step), "{what}");
        let done = resumed(&dir, 1, None);
        assert_eq!(done.summary.status, "completed", "{what}");
        assert_eq!(done.summary.provenance.resumed_at_steps, [step]);
        assert_same(&reference, &dir, &format!("stopped at {what} (step {step})"));
        // The summary's physics too: the same averages from the same rows.
        let json = |r: &RunReport| serde_json::to_string(&(&r.summary.shear, &r.summary.stages, &r.summary.energy)).unwrap();
        assert_eq!(json(&done), json(&r), "{what}");
    }
}

/// A run stopped twice, resumed twice.
#[test]
fn a_run_resumes_more_than_once() {
    let scene = protocol();
    let tmp = tempfile::tempdir().unwrap();
    let reference = tmp.path().join("reference");
    run(&scene, &reference, 1, None);
    let dir = tmp.path().join("twice");
    run(&scene, &dir, 1, Some(3000));
    assert_eq!(resumed(&dir, 1, Some(9001)).summary.status, "interrupted");
    let done = resumed(&dir, 1, None);
    assert_eq!(done.summary.provenance.resumed_at_steps, [3000, 9001]);
    assert_same(&reference, &dir, "stopped twice");
}

/// Two beads head-on, stopped half-way through their contact: the contact's state, the
/// impact observer's and its force-overlap curve carry across the stop. Likewise an
/// oblique impact under micro-slip, whose contact carries its bed of springs.
#[test]
fn an_impact_stopped_mid_contact_resumes_exactly() {
    stopped_mid_contact(grainlab::scene::builtin::builtin("collision").unwrap());
    let mut oblique = grainlab::scene::builtin::builtin("oblique").unwrap();
    oblique.model.tangential = grainlab::scene::TangentialSpec::MindlinDeresiewicz;
    stopped_mid_contact(oblique);
    // In space, under YADE's law (its contact frame's rotation carried across the stop).
    let mut oblique3d = grainlab::scene::builtin::builtin("oblique3d").unwrap();
    oblique3d.model.tangential = grainlab::scene::TangentialSpec::IncrementalForce;
    stopped_mid_contact(oblique3d);
}

/// The steps at which the impact's contact starts and ends.
fn contact_span<D: grainlab::physics::dim::Dim>(mut built: grainlab::engine::build::Built<D>) -> (u64, u64) {
    let e = built.engine.as_mut();
    while e.touching() == 0 {
        e.step().unwrap();
    }
    let first = e.steps();
    while e.touching() > 0 {
        e.step().unwrap();
    }
    (first, e.steps())
}

fn stopped_mid_contact(scene: Scene) {
    let (first, last) = match scene.dimension {
        grainlab::scene::Dimension::Two => contact_span(grainlab::build(&scene).unwrap()),
        grainlab::scene::Dimension::Three => contact_span(grainlab::build_in::<grainlab::physics::dim::Space>(&scene, 1, &limits()).unwrap()),
    };
    let mid = (first + last) / 2;
    assert!(mid > first + 50, "a contact of {} steps", last - first);
    let tmp = tempfile::tempdir().unwrap();
    let reference = tmp.path().join("reference");
    let r = run(&scene, &reference, 1, None);
    let dir = tmp.path().join("mid");
    run(&scene, &dir, 1, Some(mid));
    let done = resumed(&dir, 1, None);
    assert_same(&reference, &dir, "stopped mid-contact");
    assert!(outputs(&dir).iter().any(|f| f.0 == "force_overlap.csv"));
    assert_eq!(serde_json::to_string(&done.summary.impact).unwrap(), serde_json::to_string(&r.summary.impact).unwrap());
}

/// The bits do not depend on the thread count: a run stopped on two threads resumes on
/// one, and one stopped on one resumes on two, each as the one-thread run that never
/// stopped.
#[cfg(feature = "parallel")]
#[test]
fn a_run_resumes_exactly_on_another_number_of_threads() {
    let scene = protocol();
    let tmp = tempfile::tempdir().unwrap();
    let reference = tmp.path().join("reference");
    run(&scene, &reference, 1, None);
    let stops = stops(&scene);
    for (k, (from, to)) in [(2, 1), (1, 2)].into_iter().enumerate() {
        let (what, step) = stops[k];
        let dir = tmp.path().join(format!("threads-{from}-{to}"));
        run(&scene, &dir, from, Some(step));
        resumed(&dir, to, None);
        assert_same(&reference, &dir, &format!("stopped at {what} on {from} threads, resumed on {to}"));
    }
}

fn grainlab_cmd() -> assert_cmd::Command {
    assert_cmd::Command::cargo_bin("grainlab").unwrap()
}

/// A stopped run's folder, for the refusals.
fn stopped_folder(root: &Path, name: &str, scene: &Scene) -> PathBuf {
    let dir = root.join(name);
    run(scene, &dir, 1, Some(2000));
    dir
}

/// `grainlab resume` refuses, with exit code 2, what it cannot continue exactly, and
/// changes nothing in the folder.
#[test]
fn damaged_foreign_and_other_builds_checkpoints_are_refused() {
    let scene = protocol();
    let tmp = tempfile::tempdir().unwrap();
    let dir = stopped_folder(tmp.path(), "run", &scene);
    let ckpt = dir.join(CHECKPOINT);
    let good = std::fs::read(&ckpt).unwrap();
    let refused = |bytes: &[u8], expect: &str| {
        std::fs::write(&ckpt, bytes).unwrap();
        let before = everything(&dir);
        let out = grainlab_cmd().args(["resume", "--quiet"]).arg(&dir).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{expect}: {err}");
        assert!(err.contains(expect), "expected `{expect}` in: {err}");
        assert!(everything(&dir) == before, "{expect}: the folder changed");
    };
    let mut flipped = good.clone();
    let middle = flipped.len() / 2;
    flipped[middle] ^= 0x40;
    refused(&flipped, "is corrupt");
    refused(&good[..good.len() - 100], "is truncated");
    refused(b"not a checkpoint", "is not a grainlab checkpoint");
    // Of another build: the same state, another commit.
    let mut c = Checkpoint::decode(&good, "c").unwrap();
    c.commit = "0123456789abcdef".into();
    refused(&c.encode(), "only on the build that started it");
    // Of another run: the checkpoint of a cell sheared faster, in this folder.
    let mut other = scene.clone();
    other.stages[1].duration = 9e-4;
    other.duration = 1.3e-3;
    let foreign = stopped_folder(tmp.path(), "other", &other);
    refused(&std::fs::read(foreign.join(CHECKPOINT)).unwrap(), "belongs to another run");
    // And a state of another model inside a well-formed checkpoint of this run.
    let mut c = Checkpoint::decode(&good, "c").unwrap();
    c.engine = Checkpoint::decode(&std::fs::read(foreign.join(CHECKPOINT)).unwrap(), "c").unwrap().engine;
    c.engine.truncate(c.engine.len() / 2);
    refused(&c.encode(), "does not decode");
    // The good one still resumes.
    std::fs::write(&ckpt, &good).unwrap();
    grainlab_cmd().args(["resume", "--quiet"]).arg(&dir).assert().success();
    // A completed run has nothing to resume.
    let out = grainlab_cmd().args(["resume", "--quiet"]).arg(&dir).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("is missing"));
}

/// `--checkpoint-every` needs a folder to write in and a rate above 0: refused before the
/// build, exit code 2.
#[test]
fn checkpoints_need_an_output_folder_and_a_rate() {
    let out = grainlab_cmd().args(["run", "collision", "--quiet", "--checkpoint-every", "1e-6"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--checkpoint-every = 0.000001; allowed: with an output folder"), "{}", String::from_utf8_lossy(&out.stderr));
    let tmp = tempfile::tempdir().unwrap();
    let out = grainlab_cmd().args(["run", "collision", "--quiet", "--checkpoint-every=0", "--out"]).arg(tmp.path().join("o")).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(!tmp.path().join("o").exists(), "nothing written");
}

/// The command line, killed: `grainlab run --checkpoint-every` killed with SIGKILL (no
/// chance to write anything more) after its first checkpoints, then `grainlab resume`,
/// gives the bytes of the run that was never killed.
#[test]
fn a_killed_run_resumes_from_its_last_periodic_checkpoint() {
    let mut scene = protocol();
    scene.stages[1].duration = 3.6e-3;
    scene.duration = 4e-3;
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("scene.json");
    std::fs::write(&file, serde_json::to_string(&scene).unwrap()).unwrap();
    let reference = tmp.path().join("reference");
    grainlab_cmd().args(["run", "--quiet", "--out"]).arg(&reference).arg(&file).assert().success();
    let dir = tmp.path().join("killed");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_grainlab"))
        .args(["run", "--quiet", "--checkpoint-every", "2e-4", "--out"])
        .arg(&dir)
        .arg(&file)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let t0 = std::time::Instant::now();
    // Killed once a checkpoint has been replaced by a later one.
    let step_of = |dir: &Path| std::fs::read(dir.join(CHECKPOINT)).ok().and_then(|b| Checkpoint::decode(&b, "c").ok()).map(|c| c.step);
    let first = loop {
        if let Some(s) = step_of(&dir) {
            break s;
        }
        assert!(child.try_wait().unwrap().is_none(), "the run ended before its first checkpoint");
        assert!(t0.elapsed().as_secs() < 300);
        std::thread::sleep(std::time::Duration::from_millis(5));
    };
    while step_of(&dir).is_none_or(|s| s == first) {
        assert!(child.try_wait().unwrap().is_none(), "the run ended before its second checkpoint");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let manifest: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["status"], "running", "killed while it ran");
    grainlab_cmd().args(["resume", "--quiet"]).arg(&dir).assert().success();
    assert_same(&reference, &dir, "killed after a periodic checkpoint");
}
