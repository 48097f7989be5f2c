//! The command line: run, explain, scenes, and refusals that name the field.

use assert_cmd::Command;
use predicates::prelude::*;
use serde_json::Value;

fn grainlab() -> Command {
    Command::cargo_bin("grainlab").unwrap()
}

fn builtin_json(name: &str) -> Value {
    let out = grainlab().args(["scenes", name]).output().unwrap();
    assert!(out.status.success());
    serde_json::from_slice(&out.stdout).expect("scenes NAME prints JSON")
}

#[test]
fn scenes_lists_the_builtins_and_prints_one_that_runs_back() {
    grainlab().arg("scenes").assert().success().stdout(predicate::str::contains("collision").and(predicate::str::contains("oblique")).and(predicate::str::contains("shear")));
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("c.json");
    std::fs::write(&file, serde_json::to_string(&builtin_json("collision")).unwrap()).unwrap();
    grainlab().args(["run", file.to_str().unwrap(), "--quiet"]).assert().success();
}

#[test]
fn explain_prints_the_pipeline_in_one_line_then_every_effect() {
    grainlab()
        .args(["explain", "collision"])
        .assert()
        .success()
        // The pipeline on the first line.
        .stdout(predicate::function(|s: &str| s.lines().next().is_some_and(|l| l.contains("Contacts<Hertz, Viscoelastic, TotalDisplacementHistory>") && l.contains("t_c/200"))))
        // Then one line per effect, on or off, with why: the ledger and the observers too.
        .stdout(predicate::function(|s: &str| {
            let on = |name: &str, state: &str| s.lines().any(|l| l.trim_start().starts_with(name) && l.contains(&format!(" {state} ")));
            on("friction", "on") && on("energy ledger", "on") && on("impact observer", "on") && on("walls", "off") && on("gravity", "off") && on("ParaView frames", "off")
        }));
}

#[test]
fn run_writes_summary_and_series_with_units() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    grainlab().args(["run", "collision", "--quiet", "--out", out.to_str().unwrap()]).assert().success();
    let summary: Value = serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    // e = 0.5 at 200 steps per contact: realised e a few 1e-4 below the input.
    let e = summary["impact"]["restitution_normal"].as_f64().unwrap();
    assert!(e > 0.499 && e < 0.5, "{e}");
    let energy = std::fs::read_to_string(out.join("energy.csv")).unwrap();
    let header = energy.lines().next().unwrap();
    assert!(header.starts_with("time_s,kinetic_translation_j") && header.ends_with("residual_j"), "{header}");
    let curve = std::fs::read_to_string(out.join("force_overlap.csv")).unwrap();
    assert_eq!(curve.lines().next().unwrap(), "time_s,overlap_m,normal_force_n");
    assert!(curve.lines().count() > 100);
}

#[test]
fn shear_run_writes_wall_stresses_and_paraview_frames() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    grainlab().args(["run", "shear", "--quiet", "--duration", "1e-4", "--out", out.to_str().unwrap()]).assert().success();
    let walls = std::fs::read_to_string(out.join("walls.csv")).unwrap();
    let header = walls.lines().next().unwrap();
    assert!(header.contains("shear_stress_pa") && header.contains("normal_stress_pa"), "{header}");
    let pvd = std::fs::read_to_string(out.join("grains.pvd")).unwrap();
    assert!(pvd.contains("frames/grains_00000.vtp"));
    // XML, then the arrays appended raw.
    let vtp = String::from_utf8_lossy(&std::fs::read(out.join("frames/grains_00000.vtp")).unwrap()).into_owned();
    assert!(vtp.contains("<VTKFile type=\"PolyData\"") && vtp.contains("NumberOfPoints=\"10"), "{}", &vtp[..200]);
}

/// A collision scene with one field changed must be refused: non-zero exit, a message
/// naming the field, the value and the range, and no output directory.
fn refused(change: impl Fn(&mut Value), field: &str, range: &str) {
    refused_scene("collision", change, field, range);
}

/// [`refused`] for the built-in scene `name`.
fn refused_scene(name: &str, change: impl Fn(&mut Value), field: &str, range: &str) {
    let mut s = builtin_json(name);
    change(&mut s);
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("bad.json");
    std::fs::write(&file, serde_json::to_string(&s).unwrap()).unwrap();
    let out = dir.path().join("out");
    grainlab()
        .args(["run", file.to_str().unwrap(), "--quiet", "--out", out.to_str().unwrap()])
        .assert()
        .failure()
        .stderr(predicate::str::contains(field).and(predicate::str::contains(range)));
    assert!(!out.exists(), "a refused scene wrote {}", out.display());
}

#[test]
fn bad_scenes_are_refused_with_the_field_and_the_range() {
    refused(|s| s["materials"][0]["restitution"] = 1.5.into(), "materials[0].restitution = 1.5", "[0, 1]");
    refused(|s| s["materials"][0]["restitution"] = (-0.1).into(), "materials[0].restitution = -0.1", "[0, 1]");
    refused(|s| s["materials"][0]["poisson_ratio"] = 0.5.into(), "materials[0].poisson_ratio = 0.5", "[0, 0.5)");
    refused(|s| s["materials"][0]["youngs_modulus"] = (-1.0).into(), "materials[0].youngs_modulus = -1", "> 0 Pa");
    refused(|s| s["materials"][0]["friction"] = (-0.1).into(), "materials[0].friction = -0.1", ">= 0");
    refused(|s| s["duration"] = 0.0.into(), "duration = 0", "> 0 s");
    refused(|s| s["grains"]["list"][1]["r"] = 0.0.into(), "grains.list[1].r = 0", "> 0 m");
    refused(|s| s["time_step"]["rule"] = serde_json::json!({"fixed": {"dt": 1e-3}}), "time_step.dt", "stability limit");
    refused(|s| s["colour"] = "red".into(), "unknown field `colour`", "expected one of");
}

/// A pack with too few grains to fill its x range one grain high is refused with the
/// count it needs (it had panicked inside the packing).
#[test]
fn a_pack_lower_than_a_grain_is_refused_with_the_count_it_needs() {
    let range = ">= about 40 (to fill x = [0, 0.04] m at packing_fraction 0.75 at least one grain diameter high)";
    refused_scene("shear", |s| s["grains"]["pack"]["count"] = 1.into(), "grains.pack.count = 1", range);
}

#[test]
fn an_unknown_scene_lists_the_builtins() {
    grainlab().args(["run", "no-such-scene", "--quiet"]).assert().failure().stderr(predicate::str::contains("collision, oblique, shear"));
}

#[test]
fn export_writes_a_deck_the_particle_file_and_its_description() {
    let dir = tempfile::tempdir().unwrap();
    for (code, deck) in [("liggghts", "in.liggghts"), ("yade", "yade.py")] {
        let out = dir.path().join(code);
        grainlab().args(["export", code, "oblique", "--out", out.to_str().unwrap()]).assert().success();
        let text = std::fs::read_to_string(out.join(deck)).unwrap();
        assert!(text.contains("grainlab") && text.contains("grains.data"), "{deck}");
        let data = std::fs::read_to_string(out.join("grains.data")).unwrap();
        assert!(data.contains("1 atoms") && data.contains("Atoms") && data.contains("Velocities"));
        let info: Value = serde_json::from_str(&std::fs::read_to_string(out.join("export.json")).unwrap()).unwrap();
        assert_eq!(info["analysis"], "impact");
    }
}

#[test]
fn export_refuses_what_the_reference_code_cannot_express() {
    // YADE's Ip2 takes one damping ratio for all pairs: two restitutions are refused, and
    // nothing is written.
    let mut s = builtin_json("collision");
    let mut m2 = s["materials"][0].clone();
    m2["restitution"] = 0.3.into();
    s["materials"].as_array_mut().unwrap().push(m2);
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("two.json");
    std::fs::write(&file, serde_json::to_string(&s).unwrap()).unwrap();
    let out = dir.path().join("out");
    grainlab()
        .args(["export", "yade", file.to_str().unwrap(), "--out", out.to_str().unwrap()])
        .assert()
        .failure()
        .stderr(predicate::str::contains("restitution"));
    assert!(!out.exists());
}

/// A thread count this build cannot give is refused up front, naming `--threads` and what
/// it allows: 0 for a run, 1 for the hand-over probe (which needs two threads), and more
/// than 1 in a build without the `parallel` feature (which this test build is, unless
/// the suite runs with `--features parallel`).
#[test]
fn thread_counts_this_build_cannot_give_are_refused_with_the_range() {
    let mut cases = vec![(vec!["run", "shear", "--threads", "0"], ">= 1"), (vec!["handover", "--threads", "1"], ">= 2")];
    if !cfg!(feature = "parallel") {
        cases.push((vec!["run", "shear", "--threads", "2"], "1 (this build has no `parallel` feature"));
        cases.push((vec!["handover", "--threads", "2"], "none (this build has no `parallel` feature"));
    }
    for (args, allowed) in cases {
        let out = grainlab().args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} ran");
        assert!(err.contains("--threads") && err.contains(allowed), "{args:?}: {err}");
    }
}

/// Write `scene` to a file in `dir` and export it to `code` into `dir/out`.
fn export_json(dir: &std::path::Path, code: &str, scene: &Value) -> assert_cmd::assert::Assert {
    let file = dir.join(format!("{code}.json"));
    std::fs::write(&file, serde_json::to_string(scene).unwrap()).unwrap();
    let out = dir.join(format!("out-{code}"));
    // The same folder serves several exports in a test: each replaces the last.
    grainlab().args(["export", code, file.to_str().unwrap(), "--out", out.to_str().unwrap(), "--overwrite"]).assert()
}

fn deck_of(dir: &std::path::Path, code: &str, scene: &Value) -> String {
    export_json(dir, code, scene).success();
    std::fs::read_to_string(dir.join(format!("out-{code}")).join(if code == "yade" { "yade.py" } else { "in.liggghts" })).unwrap()
}

#[test]
fn export_refuses_general_damping_by_name() {
    // The engine drags every free grain (F = -c m v, M = -c I w); neither LIGGGHTS'
    // `fix viscous` (one gamma per type, no torque) nor YADE's damping (Cundall's, not
    // viscous) is that drag. The deck used to come out as the undamped one.
    let mut s = builtin_json("collision");
    s["model"]["general_damping"] = 0.1.into();
    let dir = tempfile::tempdir().unwrap();
    for code in ["liggghts", "yade"] {
        export_json(dir.path(), code, &s).failure().stderr(predicate::str::contains(format!("export to {code}: model.general_damping = 0.1 cannot be expressed")));
        assert!(!dir.path().join(format!("out-{code}")).exists());
    }
}

#[test]
fn export_to_yade_blocks_spin_without_rotation() {
    // model.rotation = false: the free grains must not spin in YADE either (the script
    // used to be byte-identical to the rotating one).
    let dir = tempfile::tempdir().unwrap();
    let mut s = builtin_json("oblique");
    let spinning = deck_of(dir.path(), "yade", &s);
    s["model"]["rotation"] = false.into();
    let fixed = deck_of(dir.path(), "yade", &s);
    assert!(!spinning.contains("'zXYZ'") && fixed.contains("O.bodies[i].state.blockedDOFs = 'zXYZ'"), "{fixed}");
    let liggghts = deck_of(dir.path(), "liggghts", &s);
    assert!(liggghts.contains("fix integrate free nve\n"), "{liggghts}");
}

#[test]
fn export_writes_or_refuses_the_loaded_walls_mass() {
    // The shear cell's loaded top wall with twice its glued grains' mass: YADE sets the
    // clump's mass; LIGGGHTS moves the row as its atoms and refuses by name. Both decks
    // used to be the default-mass ones.
    let mut s = builtin_json("shear");
    s["grains"]["pack"]["count"] = 60.into();
    s["grains"]["pack"]["x"] = serde_json::json!([0.0, 0.004]);
    s["domain"]["periodic_x"] = serde_json::json!([0.0, 0.004]);
    let dir = tempfile::tempdir().unwrap();
    let default = deck_of(dir.path(), "yade", &s);
    // Four glued grains of radius 0.5 mm (L = 4 mm): 4 x 4/3 pi r^3 x 2500 kg/m^3.
    let glued = 4.0 * 4.0 / 3.0 * std::f64::consts::PI * 0.5e-3f64.powi(3) * 2500.0;
    s["walls"]["top"]["mass"] = (2.0 * glued).into();
    let heavy = deck_of(dir.path(), "yade", &s);
    assert!(!default.contains("c.mass"), "{default}");
    // The mass as the scene gives it (to the last bits serde_json's parser keeps).
    let line = heavy.lines().find_map(|l| l.strip_prefix("c.mass = ")).unwrap_or_else(|| panic!("no clump mass:\n{heavy}"));
    let m: f64 = line.split_whitespace().next().unwrap().parse().unwrap();
    assert!((m / (2.0 * glued) - 1.0).abs() < 1e-15 && line.ends_with("# walls.top.mass, kg"), "{line}");
    export_json(dir.path(), "liggghts", &s).failure().stderr(predicate::str::contains("export to liggghts: walls.top.mass = ").and(predicate::str::contains("cannot be expressed")));
}

#[test]
fn export_notes_where_the_kinematics_differ() {
    // The seed's lever arm r: LIGGGHTS uses r - dn/2, YADE its own ScGeom kinematics; both
    // decks say so, naming the field. (The YADE script used to say nothing.)
    let dir = tempfile::tempdir().unwrap();
    let s = builtin_json("oblique");
    for code in ["liggghts", "yade"] {
        let deck = deck_of(dir.path(), code, &s);
        assert!(deck.lines().any(|l| l.starts_with("# Differs: model.lever_arm = radius: ")), "{code}:\n{deck}");
    }
}

/// Names that run code when a deck pastes them into a comment as they are.
const HOSTILE: [&str; 2] = ["x\nimport os; os.system('touch PWNED') #", "x\nshell touch PWNED #"];

#[test]
fn a_scene_name_adds_no_line_to_a_deck() {
    // A line break in the name ended the comment: the rest was a YADE statement or a
    // LIGGGHTS command (`shell` runs a program). Each deck and grains.data must have as
    // many lines as with a plain name, and no line may begin with the payload.
    let dir = tempfile::tempdir().unwrap();
    let mut s = builtin_json("collision");
    for code in ["liggghts", "yade"] {
        s["name"] = "x".into();
        let plain = deck_of(dir.path(), code, &s);
        let plain_data = std::fs::read_to_string(dir.path().join(format!("out-{code}/grains.data"))).unwrap();
        for name in HOSTILE {
            s["name"] = name.into();
            let deck = deck_of(dir.path(), code, &s);
            let data = std::fs::read_to_string(dir.path().join(format!("out-{code}/grains.data"))).unwrap();
            assert_eq!(deck.lines().count(), plain.lines().count(), "{code} {name:?}:\n{deck}");
            assert_eq!(data.lines().count(), plain_data.lines().count(), "{code} {name:?}: grains.data");
            assert!(!deck.lines().any(|l| l.starts_with("import os") || l.starts_with("shell")), "{code}:\n{deck}");
        }
    }
}

/// Run the reference codes on decks exported from scenes with hostile names: nothing may
/// create the file, and each deck must still run. Needs `liggghts` and `yade` on PATH
/// (scripts/setup-reference-tools): `cargo test --test cli -- --ignored hostile`.
#[test]
#[ignore]
fn hostile_names_run_nothing_in_liggghts_and_yade() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = builtin_json("collision");
    for name in HOSTILE {
        s["name"] = name.into();
        for (code, program, args) in [("liggghts", "liggghts", vec!["-in", "in.liggghts"]), ("yade", "yade", vec!["-j1", "-n", "-x", "yade.py"])] {
            export_json(dir.path(), code, &s).success();
            let run_dir = dir.path().join(format!("out-{code}"));
            let out = std::process::Command::new(program).args(&args).current_dir(&run_dir).env("OMP_NUM_THREADS", "1").output().expect("the reference code is on PATH");
            assert!(!run_dir.join("PWNED").exists(), "{code} ran the name {name:?}");
            assert!(out.status.success(), "{code} failed on the deck of {name:?}:\n{}", String::from_utf8_lossy(&out.stderr));
            assert!(run_dir.join("series.txt").exists(), "{code} wrote no series.txt");
            std::fs::remove_dir_all(&run_dir).unwrap();
        }
    }
}

#[test]
fn export_lists_what_a_code_cannot_express() {
    // --explain-fields prints the table of one code, what it refuses first, and writes nothing.
    for (code, refused) in [("liggghts", "walls.top.mass:"), ("yade", "materials[].restitution:")] {
        let out = grainlab().args(["export", code, "--explain-fields"]).output().unwrap();
        assert!(out.status.success());
        let text = String::from_utf8(out.stdout).unwrap();
        let cannot = text.split("expressed approximately").next().unwrap();
        assert!(cannot.contains("cannot be expressed") && cannot.contains("  model.general_damping:") && cannot.contains(refused), "{code}:\n{text}");
        for f in grainlab::workbench::export::fields::FIELDS {
            assert!(text.contains(&format!("  {}", f.path)), "{code}: {} missing", f.path);
        }
    }
}

/// An output folder alone repeats its run: `grainlab run DIR/scene.resolved.json` gives the
/// same bits (the scene as it ran, every default and the `--duration` override in it), and
/// the summary says what produced the run.
#[test]
fn an_output_folder_alone_repeats_its_run() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    // The shear cell, shortened from the command line, with frames: walls, energy, VTK.
    let mut scene = builtin_json("shear");
    scene["output"]["frames"] = serde_json::json!(2);
    let file = dir.path().join("shear.json");
    std::fs::write(&file, serde_json::to_string(&scene).unwrap()).unwrap();
    grainlab().args(["run", file.to_str().unwrap(), "--quiet", "--duration", "2e-5", "--out", a.to_str().unwrap()]).assert().success();
    let resolved = a.join("scene.resolved.json");
    let again: Value = serde_json::from_str(&std::fs::read_to_string(&resolved).unwrap()).unwrap();
    assert_eq!(again["duration"], serde_json::json!(2e-5), "the duration the run was given");
    assert_eq!(again["neighbor"]["skin"], scene["neighbor"]["skin"], "defaults written out");
    grainlab().args(["run", resolved.to_str().unwrap(), "--quiet", "--out", b.to_str().unwrap()]).assert().success();
    let mut compared = 0;
    for f in ["energy.csv", "walls.csv", "frames/grains_00000.vtp", "frames/grains_00001.vtp", "scene.resolved.json"] {
        let (x, y) = (std::fs::read(a.join(f)), std::fs::read(b.join(f)));
        if let (Ok(x), Ok(y)) = (x, y) {
            assert!(x == y, "{f} differs between the run and its repeat");
            compared += 1;
        }
    }
    assert!(compared >= 4, "the series, a frame and the scene compared");
    // The summary's provenance.
    let summary: Value = serde_json::from_str(&std::fs::read_to_string(a.join("summary.json")).unwrap()).unwrap();
    let p = &summary["provenance"];
    assert_eq!(p["grainlab"], serde_json::json!(env!("CARGO_PKG_VERSION")));
    assert!(p["commit"].as_str().is_some_and(|c| c == "unknown" || c.len() >= 40), "{p}");
    assert!(p["command"].as_array().is_some_and(|c| c.iter().any(|a| a == "--duration")), "{p}");
    assert!(p["cpu"].as_str().is_some_and(|c| !c.is_empty()) && p["threads"] == serde_json::json!(1), "{p}");
    let (start, end) = (p["started_utc"].as_str().unwrap(), p["ended_utc"].as_str().unwrap());
    assert!(start.ends_with('Z') && start.len() == 20 && end >= start, "{start} .. {end}");
    assert_eq!(p["scene_file"], serde_json::json!("scene.resolved.json"));
}

/// Without a terminal a run prints a progress line at each tenth (simulated time, latest
/// tau/sigma), and every run ends with one headline line before the JSON.
#[test]
fn a_run_reports_progress_lines_and_a_headline() {
    let out = grainlab().args(["run", "shear", "--duration", "2e-4"]).output().unwrap();
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    let progress: Vec<&str> = err.lines().filter(|l| l.starts_with("shear t = ") && l.contains("% of ")).collect();
    assert_eq!(progress.len(), 10, "{err}");
    assert!(progress.last().unwrap().contains("100% of"), "{err}");
    let headline = err.lines().find(|l| l.starts_with("shear: completed; tau/sigma = ")).unwrap_or_else(|| panic!("{err}"));
    let blocks = headline.split("(95%, ").nth(1).and_then(|s| s.split(" blocks)").next()).and_then(|n| n.parse::<usize>().ok());
    assert!(blocks.is_some_and(|b| (2..=100).contains(&b)) && headline.contains("sigma = ") && headline.contains("energy residual"), "{headline}");
    // --quiet: no progress, the headline still.
    let out = grainlab().args(["run", "shear", "--duration", "2e-4", "--quiet"]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("% of ") && err.contains("shear: completed;"), "{err}");
}

#[test]
fn freeze_refuses_what_the_reference_decks_cannot_load_by_field() {
    // The built-in shear cell has rough walls and a loaded top wall: a frozen state of it
    // could not be loaded as LIGGGHTS' primitive planes, so it is refused by name, and
    // nothing is written.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("f");
    grainlab().args(["freeze", "shear", "--steps", "10", "--out", out.to_str().unwrap()]).assert().code(2).stderr(predicate::str::contains("walls.bottom.surface"));
    assert!(!out.exists());
    grainlab().args(["freeze", "shear", "--steps", "0", "--out", out.to_str().unwrap()]).assert().code(2).stderr(predicate::str::contains("--steps"));
}
