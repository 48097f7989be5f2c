//! Outputs that lose nothing: the output folder is grainlab's (a reused folder never mixes
//! two runs), SIGINT/SIGTERM end a run with everything written, an unwritable summary
//! goes to stdout, a closed pipe ends quietly, and each class of failure has its exit
//! code (README, "Exit codes").

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use serde_json::Value;

const BIN: &str = env!("CARGO_BIN_EXE_grainlab");

const BAD_INPUT: i32 = 2;
const IO_FAILURE: i32 = 3;
const UNSTABLE: i32 = 4;

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

fn json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
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
