//! Outputs that lose nothing: the output folder is grainlab's (a reused folder never mixes
//! two runs), SIGINT/SIGTERM end a run with everything written, an unwritable summary
//! goes to stdout, a closed pipe ends quietly, and each class of failure has its exit
//! code (README, "The output folder, interruption and exit codes").

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

const BIN: &str = env!("CARGO_BIN_EXE_grainlab");

const BAD_INPUT: i32 = 2;
const IO_FAILURE: i32 = 3;
const UNSTABLE: i32 = 4;
const INTERRUPTED: i32 = 130;

fn grainlab(args: &[&str]) -> Output {
    Command::new(BIN).args(args).stdin(Stdio::null()).output().unwrap()
}

fn code(o: &Output) -> i32 {
    o.status.code().unwrap_or_else(|| panic!("killed by a signal: {}", String::from_utf8_lossy(&o.stderr)))
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The built-in scene `name` with `change` applied, written to `dir/file`.
fn scene_file(dir: &Path, name: &str, file: &str, change: impl Fn(&mut Value)) -> PathBuf {
    let out = grainlab(&["scenes", name]);
    assert_eq!(code(&out), 0);
    let mut v: Value = serde_json::from_slice(&out.stdout).unwrap();
    change(&mut v);
    let path = dir.join(file);
    std::fs::write(&path, serde_json::to_string(&v).unwrap()).unwrap();
    path
}

/// Every file under `dir`, relative with `/`, sorted.
fn files(dir: &Path) -> Vec<String> {
    fn walk(root: &Path, d: &Path, out: &mut Vec<String>) {
        for e in std::fs::read_dir(d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                out.push(p.strip_prefix(root).unwrap().to_str().unwrap().replace('\\', "/"));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// Every file of `dir` with its bytes.
fn contents(dir: &Path) -> Vec<(String, Vec<u8>)> {
    files(dir).into_iter().map(|f| (f.clone(), std::fs::read(dir.join(&f)).unwrap())).collect()
}

fn json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The files the manifest of `dir` lists, sorted.
fn listed(dir: &Path) -> Vec<String> {
    let m = json(&dir.join("manifest.json"));
    let mut l: Vec<String> = m["files"].as_array().expect("files").iter().map(|f| f["path"].as_str().unwrap().to_string()).collect();
    l.sort();
    l
}

#[test]
fn a_reused_folder_is_refused_and_overwrite_leaves_only_the_new_run() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let twenty = scene_file(tmp.path(), "shear", "twenty.json", |v| v["output"]["frames"] = 20.into());
    let five = scene_file(tmp.path(), "shear", "five.json", |v| v["output"]["frames"] = 5.into());
    let run = |scene: &Path, extra: &[&str]| {
        let mut args = vec!["run", s(scene), "--quiet", "--duration", "1e-4", "--out", s(&out)];
        args.extend_from_slice(extra);
        grainlab(&args)
    };
    let first = run(&twenty, &[]);
    assert_eq!(code(&first), 0, "{}", stderr(&first));
    let before = contents(&out);
    let frames = |dir: &Path| files(dir).iter().filter(|f| f.starts_with("frames/")).count();
    assert!(frames(&out) > 10, "{:?}", files(&out));
    // Every file of the first run is in its manifest.
    let mut written = listed(&out);
    written.push("manifest.json".into());
    written.sort();
    assert_eq!(files(&out), written);

    // Again into the same folder: refused, nothing touched.
    let again = run(&five, &[]);
    assert_eq!(code(&again), BAD_INPUT, "{}", stderr(&again));
    assert!(stderr(&again).contains("--overwrite"), "{}", stderr(&again));
    assert!(contents(&out) == before, "a refused run changed the folder");

    // With --overwrite: only the second run's files remain (6 frames, not 21).
    let second = run(&five, &["--overwrite"]);
    assert_eq!(code(&second), 0, "{}", stderr(&second));
    let n = frames(&out);
    assert!(n <= 6, "{n} frames: {:?}", files(&out));
    let pvd = std::fs::read_to_string(out.join("grains.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), n);
    let mut written = listed(&out);
    written.push("manifest.json".into());
    written.sort();
    assert_eq!(files(&out), written, "files the second run did not write");
    let manifest = json(&out.join("manifest.json"));
    assert_eq!(manifest["status"], "completed");
    for f in manifest["files"].as_array().unwrap() {
        let bytes = std::fs::read(out.join(f["path"].as_str().unwrap())).unwrap();
        assert_eq!(f["bytes"].as_u64(), Some(bytes.len() as u64), "{f}");
        assert_eq!(f["crc32"].as_str().unwrap(), format!("{:08x}", crc32(&bytes)), "{f}");
    }
}

/// CRC-32 (IEEE), bit by bit: the manifest's checksum, computed independently.
fn crc32(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in bytes {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 { (c >> 1) ^ 0xEDB8_8320 } else { c >> 1 };
        }
    }
    !c
}

#[test]
fn a_folder_with_files_grainlab_did_not_write_is_refused_and_left_as_it_was() {
    let tmp = tempfile::tempdir().unwrap();
    // A folder of someone else's files, with or without --overwrite.
    let theirs = tmp.path().join("theirs");
    std::fs::create_dir(&theirs).unwrap();
    std::fs::write(theirs.join("notes.txt"), "mine").unwrap();
    for extra in [&[][..], &["--overwrite"][..]] {
        let mut args = vec!["run", "collision", "--quiet", "--out", s(&theirs)];
        args.extend_from_slice(extra);
        let o = grainlab(&args);
        assert_eq!(code(&o), BAD_INPUT, "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("notes.txt"), "{}", stderr(&o));
        assert_eq!(files(&theirs), ["notes.txt"]);
    }
    // A folder grainlab wrote, with a file of someone else's added: --overwrite refuses
    // too, and deletes nothing.
    let mixed = tmp.path().join("mixed");
    assert_eq!(code(&grainlab(&["run", "shear", "--quiet", "--duration", "1e-4", "--out", s(&mixed)])), 0);
    std::fs::write(mixed.join("frames").join("plot.png"), "png").unwrap();
    let before = contents(&mixed);
    let o = grainlab(&["run", "shear", "--quiet", "--duration", "1e-4", "--out", s(&mixed), "--overwrite"]);
    assert_eq!(code(&o), BAD_INPUT, "{}", stderr(&o));
    assert!(stderr(&o).contains("plot.png"), "{}", stderr(&o));
    assert!(contents(&mixed) == before, "a refused run changed the folder");
    // A file grainlab wrote and someone changed is not deleted either.
    let changed = tmp.path().join("changed");
    assert_eq!(code(&grainlab(&["run", "collision", "--quiet", "--out", s(&changed)])), 0);
    std::fs::write(changed.join("summary.json"), "{}").unwrap();
    let o = grainlab(&["run", "collision", "--quiet", "--out", s(&changed), "--overwrite"]);
    assert_eq!(code(&o), BAD_INPUT, "{}", stderr(&o));
    assert!(stderr(&o).contains("summary.json"), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(changed.join("summary.json")).unwrap(), "{}");
    // An export follows the same rule.
    let o = grainlab(&["export", "liggghts", "oblique", "--out", s(&theirs)]);
    assert_eq!(code(&o), BAD_INPUT, "{}", stderr(&o));
    assert_eq!(files(&theirs), ["notes.txt"]);
    let deck = tmp.path().join("deck");
    assert_eq!(code(&grainlab(&["export", "liggghts", "oblique", "--out", s(&deck)])), 0);
    assert_eq!(code(&grainlab(&["export", "yade", "oblique", "--out", s(&deck)])), BAD_INPUT);
    assert_eq!(code(&grainlab(&["export", "yade", "oblique", "--out", s(&deck), "--overwrite"])), 0);
    assert!(!deck.join("in.liggghts").exists(), "the first export's deck is still there");
    assert!(deck.join("yade.py").exists());
}

fn start_shear(out: &Path) -> Child {
    Command::new(BIN)
        .args(["run", "shear", "--quiet", "--out", s(out)])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Lines of the energy series, under its temporary name while the run goes.
fn energy_lines(out: &Path) -> usize {
    ["energy.csv.part", "energy.csv"].iter().filter_map(|f| std::fs::read_to_string(out.join(f)).ok()).map(|t| t.lines().count()).max().unwrap_or(0)
}

/// Wait until the run has written `n` lines of its energy series (it is stepping).
fn wait_for_rows(child: &mut Child, out: &Path, n: usize) {
    let t0 = Instant::now();
    while energy_lines(out) < n {
        assert!(child.try_wait().unwrap().is_none(), "the run ended before it was interrupted");
        assert!(t0.elapsed() < Duration::from_secs(300), "no rows after 300 s");
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn signal(child: &Child, sig: i32) {
    assert_eq!(unsafe { libc::kill(child.id() as i32, sig) }, 0);
}

/// The child's output once it has exited (at most `secs` s).
fn finish(mut child: Child, secs: u64) -> Output {
    let t0 = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if t0.elapsed() > Duration::from_secs(secs) {
            child.kill().unwrap();
            panic!("still running {secs} s after the signal");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// The numbers of a CSV series: a header and at least `min` rows of finite numbers.
fn csv_rows(path: &Path, min: usize) -> usize {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let rows: Vec<&str> = text.lines().skip(1).collect();
    assert!(rows.len() >= min, "{}: {} rows", path.display(), rows.len());
    for r in &rows {
        for v in r.split(',') {
            let x: f64 = v.parse().unwrap_or_else(|_| panic!("{}: `{r}`", path.display()));
            assert!(x.is_finite(), "{}: `{r}`", path.display());
        }
    }
    rows.len()
}

fn interrupted_with(sig: i32) {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let mut child = start_shear(&out);
    wait_for_rows(&mut child, &out, 8);
    signal(&child, sig);
    let o = finish(child, 60);
    assert_eq!(code(&o), INTERRUPTED, "{}", stderr(&o));
    assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["status"], "interrupted", "{summary}");
    assert!(summary["error"].as_str().unwrap().contains("interrupted"), "{summary}");
    let steps = summary["steps"].as_u64().unwrap();
    assert!(steps > 0);
    for q in [&summary["simulated_time_s"], &summary["particle_steps_per_s"], &summary["energy"]["final_row"]["kinetic_translation_j"], &summary["shear"]["stress_ratio"]["mean"]] {
        assert!(q.as_f64().is_some_and(f64::is_finite), "{q} in {summary}");
    }
    let printed: Value = serde_json::from_slice(&o.stdout).expect("the summary on stdout");
    assert_eq!(printed["status"], "interrupted");
    let energy = csv_rows(&out.join("energy.csv"), 8);
    csv_rows(&out.join("walls.csv"), 7);
    // The last energy row is the state the run stopped in.
    let last = std::fs::read_to_string(out.join("energy.csv")).unwrap().lines().last().unwrap().to_string();
    let t_last: f64 = last.split(',').next().unwrap().parse().unwrap();
    assert_eq!(t_last, summary["simulated_time_s"].as_f64().unwrap(), "{energy} rows, last `{last}`");
    let manifest = json(&out.join("manifest.json"));
    assert_eq!(manifest["status"], "interrupted");
    let mut written = listed(&out);
    written.push("manifest.json".into());
    written.sort();
    assert_eq!(files(&out), written, "temporary or unlisted files");
}

#[test]
fn sigint_ends_the_run_with_everything_written() {
    interrupted_with(libc::SIGINT);
}

#[test]
fn sigterm_ends_the_run_with_everything_written() {
    interrupted_with(libc::SIGTERM);
}

/// A run killed outright keeps its series under their temporary names, listed in a
/// manifest that says it was running; `--overwrite` clears them.
#[test]
fn a_killed_run_keeps_its_rows_and_its_folder_can_be_overwritten() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let mut child = start_shear(&out);
    wait_for_rows(&mut child, &out, 5);
    signal(&child, libc::SIGKILL);
    let _ = finish(child, 60);
    assert!(csv_rows(&out.join("energy.csv.part"), 4) >= 4);
    assert!(!out.join("summary.json").exists());
    let manifest = json(&out.join("manifest.json"));
    assert_eq!(manifest["status"], "running");
    assert!(listed(&out).contains(&"energy.csv.part".to_string()), "{manifest}");
    let again = grainlab(&["run", "shear", "--quiet", "--duration", "1e-4", "--out", s(&out)]);
    assert_eq!(code(&again), BAD_INPUT, "{}", stderr(&again));
    let again = grainlab(&["run", "shear", "--quiet", "--duration", "1e-4", "--out", s(&out), "--overwrite"]);
    assert_eq!(code(&again), 0, "{}", stderr(&again));
    let mut written = listed(&out);
    written.push("manifest.json".into());
    written.sort();
    assert_eq!(files(&out), written);
    assert!(!out.join("energy.csv.part").exists());
}

/// The folder removed while the run goes: the run stops at the next file it cannot write,
/// the summary goes to stdout, and the exit code is the I/O failure's.
#[test]
fn an_unwritable_summary_goes_to_stdout_with_the_io_exit_code() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let mut child = start_shear(&out);
    wait_for_rows(&mut child, &out, 4);
    std::fs::remove_dir_all(&out).unwrap();
    let o = finish(child, 300);
    assert_eq!(code(&o), IO_FAILURE, "{}", stderr(&o));
    let printed: Value = serde_json::from_slice(&o.stdout).expect("the summary on stdout");
    assert!(printed["steps"].as_u64().unwrap() > 0);
    assert!(stderr(&o).contains("summary.json"), "{}", stderr(&o));
    assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
}

/// `grainlab scenes shear | head -3`: stdout closed before the command writes to it.
#[test]
fn a_closed_pipe_ends_quietly() {
    let closed = || {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        writer
    };
    for args in [&["scenes", "shear"][..], &["scenes"], &["explain", "collision"], &["run", "collision", "--quiet"]] {
        let o = Command::new(BIN).args(args).stdout(closed()).stderr(Stdio::piped()).output().unwrap();
        assert_eq!(code(&o), 0, "{args:?}: {}", stderr(&o));
        assert!(!stderr(&o).contains("panicked"), "{args:?}: {}", stderr(&o));
    }
    // stderr closed too: the refusal's exit code, no panic (101).
    let o = Command::new(BIN).args(["run", "no-such-scene"]).stdout(closed()).stderr(closed()).output().unwrap();
    assert_eq!(code(&o), BAD_INPUT);
    let o = Command::new(BIN).args(["run", "collision"]).stdout(closed()).stderr(closed()).output().unwrap();
    assert_eq!(code(&o), 0);
}

#[test]
fn each_class_of_failure_has_its_exit_code() {
    let tmp = tempfile::tempdir().unwrap();
    let bad = |args: &[&str], says: &str| {
        let o = grainlab(args);
        assert_eq!(code(&o), BAD_INPUT, "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(says), "{args:?}: {}", stderr(&o));
    };
    // Bad command-line values say "invalid option", not "invalid scene".
    bad(&["run", "shear", "--threads", "0"], "invalid option: --threads = 0");
    bad(&["run", "collision", "--duration", "0"], "invalid option: --duration = 0");
    bad(&["sweep", "collision", "--steps", "0.5"], "invalid option: --steps = 0.5");
    bad(&["sweep", "collision", "--steps", "100", "--variants", "colour"], "invalid option: --variants = colour");
    bad(&["sweep", "collision", "--stiffness", "0.1,-1"], "invalid option: --stiffness = -1");
    bad(&["sweep", "collision", "--steps", "50,100", "--stiffness", "0.1,1"], "one lever per sweep");
    bad(&["sweep", "collision", "--steps", "50", "--repeats", "0"], "invalid option: --repeats = 0");
    bad(&["sweep", "shear", "--steps", "50", "--seeds", "4"], "invalid option: --seeds = 4");
    bad(&["run", "no-such-scene"], "neither a scene file nor a built-in");
    bad(&["run", "collision", "--no-such-flag"], "--no-such-flag");
    let restitution = scene_file(tmp.path(), "collision", "bad.json", |v| v["materials"][0]["restitution"] = 1.5.into());
    bad(&["run", s(&restitution)], "invalid scene: materials[0].restitution = 1.5");
    // I/O: the output folder cannot be made (a file stands where its parent should be).
    let file = tmp.path().join("file");
    std::fs::write(&file, "x").unwrap();
    let o = grainlab(&["run", "collision", "--quiet", "--out", s(&file.join("out"))]);
    assert_eq!(code(&o), IO_FAILURE, "{}", stderr(&o));
    // Unstable: stopped with a diagnosis; the summary says so.
    let unstable = scene_file(tmp.path(), "collision", "unstable.json", |v| {
        v["time_step"] = serde_json::json!({"rule": {"fixed": {"dt": 2e-5}}, "characteristic_speed": 1.0, "allow_unstable": true});
    });
    let out = tmp.path().join("unstable");
    let o = grainlab(&["run", s(&unstable), "--quiet", "--out", s(&out)]);
    assert_eq!(code(&o), UNSTABLE, "{}", stderr(&o));
    assert!(stderr(&o).contains("run stopped at step"), "{}", stderr(&o));
    assert_eq!(json(&out.join("summary.json"))["status"], "stopped");
    let printed: Value = serde_json::from_slice(&o.stdout).expect("the summary on stdout");
    assert_eq!(printed["status"], "stopped");
    // Other failures: reference output that cannot be read (a case folder whose
    // case.json is not one).
    let case = tmp.path().join("case");
    std::fs::create_dir(&case).unwrap();
    std::fs::write(case.join("case.json"), "{}").unwrap();
    std::fs::write(case.join("export.json"), "{}").unwrap();
    let o = grainlab(&["digest", s(&case), "liggghts", s(tmp.path())]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert_eq!(code(&grainlab(&["run", "collision", "--quiet"])), 0);
}

/// The library's run with a stop request (what the signal handler sets) and a
/// summary.json that cannot be written (a folder stands in its place): the summary comes
/// back with the I/O error, everything else is written, and the manifest says so.
#[test]
fn a_stopped_run_returns_its_summary_when_summary_json_cannot_be_written() {
    use grainlab::study::run::{RunOptions, run_report};
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let scene = grainlab::scene::builtin::builtin("shear").unwrap();
    let built = grainlab::build(&scene).unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let opts = RunOptions { out: Some(out.clone()), stop: Some(stop.clone()), ..RunOptions::default() };
    let run = std::thread::spawn(move || run_report(&scene, built, &opts));
    let t0 = Instant::now();
    while energy_lines(&out) < 4 {
        assert!(!run.is_finished(), "the run ended before it was stopped");
        assert!(t0.elapsed() < Duration::from_secs(300));
        std::thread::sleep(Duration::from_millis(20));
    }
    std::fs::create_dir_all(out.join("summary.json").join("in-the-way")).unwrap();
    stop.store(true, Ordering::Relaxed);
    let report = run.join().unwrap().expect("the run started");
    assert_eq!(report.summary.status, "interrupted");
    assert!(matches!(report.ending, Some(grainlab::Error::Interrupted { .. })), "{:?}", report.ending);
    assert!(matches!(report.write_error, Some(grainlab::Error::Io { .. })), "{:?}", report.write_error);
    assert_eq!(report.unwritten, ["summary.json"]);
    assert!(report.summary.energy.as_ref().unwrap().final_row.kinetic_translation_j.is_finite());
    csv_rows(&out.join("energy.csv"), 4);
    csv_rows(&out.join("walls.csv"), 3);
    assert_eq!(json(&out.join("manifest.json"))["status"], "interrupted");
    assert_eq!(report.into_result().unwrap_err().exit_code(), IO_FAILURE as u8);
}

/// The README's table and `grainlab --help` list exactly the codes of `error::exit`.
#[test]
fn the_exit_codes_are_documented() {
    use grainlab::error::exit;
    let mut codes = vec![exit::SUCCESS, exit::OTHER, exit::BAD_INPUT, exit::IO_FAILURE, exit::UNSTABLE, exit::INTERRUPTED];
    codes.sort();
    assert_eq!(codes, [0, 1, BAD_INPUT as u8, IO_FAILURE as u8, UNSTABLE as u8, INTERRUPTED as u8]);
    let readme = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    let section = &readme[readme.find("| exit code | meaning |").expect("the README's table")..];
    let mut table: Vec<u8> = section.lines().skip(2).take_while(|l| l.starts_with('|')).map(|l| l.split('|').nth(1).unwrap().trim().parse().unwrap()).collect();
    table.sort();
    assert_eq!(table, codes);
    let help = String::from_utf8(grainlab(&["--help"]).stdout).unwrap();
    for c in codes {
        assert!(help.lines().any(|l| l.trim_start().starts_with(&format!("{c} "))), "{c} in\n{help}");
    }
}
