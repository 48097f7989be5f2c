//! Bad input and faults: every scene the issue found to crash, hang, allocate without
//! bound, write NaN or run inconsistent is refused before anything is allocated, with its
//! field, value and what is allowed, or runs to a diagnosed stop with finite outputs.
//! Each test says what the build before the hardening (f706540) did with the same scene,
//! run as a scene file with its release binary: a panic, an abort, a hang (no end within
//! 30 s), NaN in a "completed" run's files, a silent run, or a stop whose message did not
//! name the cause.

use assert_cmd::Command;
use grainlab::scene::limits::Limits;
use grainlab::scene::Grains;
use grainlab::scene::builtin::builtin;
use grainlab::{Error, Scene};
use serde_json::{Value, json};

/// The build's refusal of `scene` as text (within a 1 GiB budget).
fn refusal(scene: &Scene) -> String {
    match grainlab::build_limited(scene, 1, &Limits::with_memory(1 << 30)) {
        Ok(_) => panic!("scene `{}` was accepted", scene.name),
        Err(e) => e.to_string(),
    }
}

/// `scene` with a change made to its JSON, parsed and validated like a scene file.
fn changed(name: &str, change: impl Fn(&mut Value)) -> Result<Scene, Error> {
    let mut v: Value = serde_json::from_str(&builtin(name).unwrap().to_json()).unwrap();
    change(&mut v);
    Scene::from_json(&v.to_string())
}

/// The refusal of a changed built-in, at parsing or at the build.
fn refused(name: &str, change: impl Fn(&mut Value)) -> String {
    match changed(name, change) {
        Err(e) => e.to_string(),
        Ok(s) => refusal(&s),
    }
}

fn assert_names(msg: &str, parts: &[&str]) {
    for p in parts {
        assert!(msg.contains(p), "`{p}` missing from: {msg}");
    }
}

// --- Panics on accepted scenes ---

#[test]
fn an_impact_without_a_pair_or_a_flat_wall_is_refused() {
    // Old build: panicked in the impact observer (one grain, no wall); ran three grains
    // to "completed", measuring grains 0 and 1 as if alone.
    // One grain and no wall: the impact observer panicked looking for the wall.
    let msg = refused("oblique", |s| s["walls"] = Value::Null);
    assert_names(&msg, &["analysis = impact", "flat wall"]);
    // Three grains: which pair?
    let msg = refused("collision", |s| {
        let mut g = s["grains"]["list"][0].clone();
        g["x"] = json!([0.0, 0.01]);
        s["grains"]["list"].as_array_mut().unwrap().push(g);
    });
    assert_names(&msg, &["analysis = impact", "3 grains"]);
}

#[test]
fn an_empty_grain_file_is_refused() {
    // Old build: panicked (build.rs, the smallest grain of none).
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("empty.txt");
    std::fs::write(&path, "# no grains\n\n").unwrap();
    let msg = refused("collision", |s| {
        s["grains"] = json!({"file": {"path": path.to_str().unwrap()}});
        s["analysis"] = "none".into();
    });
    assert_names(&msg, &["grains.file.path", "at least one grain"]);
}

#[test]
fn a_pack_count_near_two_to_the_64_is_refused_by_its_memory_estimate() {
    // Old build: panicked (capacity overflow).
    let msg = refused("shear", |s| s["grains"]["pack"]["count"] = json!(u64::MAX - 5));
    assert_names(&msg, &["grains.pack.count = 18446744073709551610", "memory budget of 1.0 GiB", "EiB for grains"]);
}

#[test]
fn a_negative_lognormal_median_is_refused() {
    // Old build: panicked in the radius sampling.
    let msg = refused("shear", |s| s["grains"]["pack"]["radius"] = json!({"lognormal": {"median": -1e-3, "sigma": 0.2, "min": 4e-4, "max": 6e-4}}));
    assert_names(&msg, &["grains.pack.radius.median = -0.001", "> 0 m"]);
}

#[test]
fn pack_ranges_that_overflow_to_infinity_are_refused() {
    // Old build: refused the first with `count >= about inf`; hung on the second.
    // x_max - x_min overflows to infinity.
    let msg = refused("shear", |s| {
        s["grains"]["pack"]["x"] = json!([-1.7e308, 1.7e308]);
        s["domain"]["periodic_x"] = Value::Null;
        s["analysis"] = "none".into();
    });
    assert_names(&msg, &["grains.pack.x", "finite x_min < x_max"]);
    let msg = refused("shear", |s| s["domain"]["periodic_x"] = json!([-1.7e308, 1.7e308]));
    assert_names(&msg, &["domain.periodic_x", "finite x_min < x_max"]);
}

// --- Allocation without bound, and hangs ---

#[test]
fn a_far_away_grain_is_refused_instead_of_sizing_a_grid() {
    // Old build: aborted allocating 145 GB for the cell grid.
    // The cell grid was sized from the grains' spread: this asked for 145 GB.
    let msg = refused("collision", |s| s["grains"]["list"][1]["x"] = json!([1e300, 0.0]));
    assert_names(&msg, &["grains.list[1] = at (1e300, 0) m", "within 1e3 m of the origin"]);
}

#[test]
fn grains_far_apart_within_the_bounds_run_in_memory_proportional_to_their_number() {
    // Not a defect of the old build (its coarsened grid held this one): the sorted cell
    // list that replaces the coarsening, at work in a run.
    // 50 grains in a row, and one 500 m away (within 1e6 radii): the grid would have
    // needed 10^11 cells; the sparse cell list needs none. Neighbours still found: grains
    // 0 and 1 touch and push apart.
    let mut s = builtin("collision").unwrap();
    s.analysis = grainlab::scene::Analysis::None;
    if let Grains::List(g) = &mut s.grains {
        let mut far = g[1].clone();
        far.x = [500.0, 0.0].into();
        far.v = [0.0, 0.0].into();
        for k in 0..50 {
            let mut q = far.clone();
            q.x = [0.01 * k as f64, 0.5].into();
            g.push(q);
        }
        g.push(far);
    }
    let out = grainlab::study::run::run_scene(&s, &Default::default()).unwrap();
    assert_eq!(out.status, "completed");
}

#[test]
fn counts_that_would_not_fit_are_refused_with_the_estimate() {
    // Old build: hung on the tiny rough radius and on the samples (writing NaN rows),
    // ran the 300 materials (the n^2 table was never bounded).
    // Tiny rough grains: 4e10 wall grains.
    let msg = refused("shear", |s| s["walls"]["bottom"]["surface"] = json!({"rough": {"radius": 5e-13}}));
    assert_names(&msg, &["walls.bottom.surface.rough.radius", "memory budget", "for wall grains"]);
    // Materials: the pair table is n^2.
    let msg = refused("collision", |s| {
        let m = s["materials"][0].clone();
        s["materials"] = Value::Array(vec![m; 300]);
    });
    assert_names(&msg, &["materials = 300 materials", "1 to 256 materials"]);
    // Samples kept in memory for a long run.
    let msg = refused("shear", |s| {
        s["output"]["samples"] = json!(u64::MAX);
        s["duration"] = json!(1e4);
    });
    assert_names(&msg, &["output.samples", "for rows"]);
}

#[test]
fn a_time_step_of_zero_or_infinity_is_refused() {
    // Old build: hung at E = 1e300 and dt = 1e-300 and at an impact speed of 1e300,
    // aborted at 1e-300 m/s; E = 1e-300 and rho = 1e300 were refused as `dt = inf s
    // is outside the allowed range <= 3.7e118 s` (and 7.7e112 s).
    // Moduli and densities at the edge of the range: a contact time of infinity or 0.
    for (field, value) in [("youngs_modulus", 1e-300), ("youngs_modulus", 1e300), ("density", 1e300)] {
        let msg = refused("collision", |s| s["materials"][0][field] = json!(value));
        assert_names(&msg, &["time_step = t_c", "finite and > 0"]);
    }
    // An impact speed at the edge of the range: the contact time it sets is infinite or 0.
    for speed in [1e-300, 1e300] {
        let msg = refused("collision", |s| s["time_step"]["rule"]["steps_per_contact"]["impact_speed"] = json!(speed));
        assert_names(&msg, &["time_step = t_c", "finite and > 0"]);
    }
    // A step so small that the run would never end.
    let msg = refused("collision", |s| s["time_step"]["rule"] = json!({"fixed": {"dt": 1e-300}}));
    assert_names(&msg, &["duration", "at most 1e12 steps"]);
}

#[test]
fn a_grain_file_that_never_ends_is_refused_unread() {
    // Old build: read /dev/zero until memory ran out (a hang); a folder gave an I/O error.
    for path in ["/dev/zero", "/tmp"] {
        let msg = refused("collision", |s| {
            s["grains"] = json!({"file": {"path": path}});
            s["analysis"] = "none".into();
        });
        assert_names(&msg, &["grains.file.path", "a regular file"]);
    }
}

// --- NaN in the outputs of "completed" runs ---

#[test]
fn a_huge_spin_or_wall_speed_is_refused_not_run_to_nan() {
    // Old build: the spin ran to "completed" with 78 NaN rows; the wall speed aborted
    // allocating 1.1 TB.
    let msg = refused("collision", |s| s["grains"]["list"][1]["omega"] = json!(1e300));
    assert_names(&msg, &["grains.list[1].omega = 1e300 rad/s", "0.05 of the smallest radius"]);
    let msg = refused("shear", |s| s["walls"]["top"]["velocity_x"] = json!(1e300));
    assert_names(&msg, &["walls.top.velocity_x = 1e300", "per step"]);
}

#[test]
fn stress_ratio_at_zero_normal_stress_is_an_empty_cell_not_nan() {
    // Old build: tau/sigma = 0/0 = NaN in every walls.csv row.
    // The built-in oblique impact has walls but no normal stress: tau/sigma = 0/0.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    Command::cargo_bin("grainlab").unwrap().args(["run", "oblique", "--quiet", "--out", out.to_str().unwrap()]).assert().success();
    let walls = std::fs::read_to_string(out.join("walls.csv")).unwrap();
    assert!(walls.lines().nth(1).unwrap().ends_with(",0.0,0.0,"), "{}", walls.lines().nth(1).unwrap());
    for f in ["walls.csv", "energy.csv", "force_overlap.csv", "summary.json"] {
        let text = numbers_text(&out.join(f));
        assert!(!text.contains("nan") && !text.contains("inf,") && !text.contains(",inf"), "{f} holds a non-finite number");
    }
}

#[test]
fn a_run_that_goes_unstable_stops_with_a_diagnosis_and_finite_outputs() {
    // Five times the stability limit, allowed: the collision blows up. The run stops,
    // names the step and a grain, blames the time step, and writes only finite numbers.
    let dir = tempfile::tempdir().unwrap();
    let scene = changed("collision", |s| {
        // The stability limit is 1.77e-6 s here.
        s["time_step"] = json!({"rule": {"fixed": {"dt": 9e-6}}, "allow_unstable": true});
        s["analysis"] = "none".into();
        s["duration"] = json!(1e-4);
        s["output"]["samples"] = json!(1000);
    })
    .unwrap();
    let out = dir.path().join("out");
    let opts = grainlab::study::run::RunOptions { out: Some(out.clone()), ..Default::default() };
    let err = grainlab::study::run::run_scene(&scene, &opts).unwrap_err().to_string();
    assert_names(&err, &["run stopped at step", "grain", "stability limit", "time_step.allow_unstable is set"]);
    for f in ["energy.csv", "summary.json"] {
        let text = numbers_text(&out.join(f));
        assert!(!text.contains("nan") && !text.contains("inf"), "{f}: {text}");
    }
}

// --- Inconsistent scenes accepted without a word ---

#[test]
fn a_top_wall_below_the_bottom_wall_is_refused() {
    // Old build: ran the first to "completed" (276 NaN rows, a negative gap), stopped
    // the second at step 1 on an overlap, advising a smaller time step.
    let msg = refused("shear", |s| {
        s["walls"]["top"]["y"] = json!(-0.01);
        s["walls"]["top"]["control"] = "fixed".into();
    });
    assert_names(&msg, &["walls.top.y = -0.01", "above the bottom wall"]);
    // Above the bottom wall, but below the packing it must hold.
    let msg = refused("shear", |s| s["walls"]["top"]["y"] = json!(0.005));
    assert_names(&msg, &["walls.top.y = 0.005", "the packing fills"]);
}

#[test]
fn rough_wall_grains_larger_than_the_cell_are_refused() {
    // Old build: hung.
    let msg = refused("shear", |s| s["walls"]["bottom"]["surface"] = json!({"rough": {"radius": 0.03}}));
    assert_names(&msg, &["walls.bottom.surface.rough.radius = 0.03", "half the periodic cell"]);
}

#[test]
fn grains_that_would_tunnel_through_each_other_in_a_step_are_refused() {
    // Old build: stopped at step 1 on an overlap of 0.126, advising a smaller time step.
    // 4000 m/s at the collision's dt: 1.3e-4 m a step, more than a radius per eight steps.
    let msg = refused("collision", |s| s["grains"]["list"][0]["v"] = json!([4000.0, 0.0]));
    assert_names(&msg, &["grains.list[0].v = [4000, 0] m/s", "0.05 of the smallest radius"]);
}

#[test]
fn an_impact_that_can_never_happen_is_refused() {
    // Old build: ran both to "completed" with no impact measured.
    // Moving apart.
    let msg = refused("collision", |s| {
        s["grains"]["list"][0]["v"] = json!([-0.5, 0.0]);
        s["grains"]["list"][1]["v"] = json!([0.5, 0.0]);
    });
    assert_names(&msg, &["analysis = impact", "not approaching"]);
    // Away from the wall, with nothing to pull it back.
    let msg = refused("oblique", |s| s["grains"]["list"][0]["v"] = json!([0.7, 0.7]));
    assert_names(&msg, &["analysis = impact", "not moving towards the bottom wall"]);
}

#[test]
fn a_periodic_cell_narrower_than_its_packing_is_refused() {
    // Old build: stopped at step 1 on an overlap of 2.1 radii, advising a smaller time step.
    let msg = refused("shear", |s| s["domain"]["periodic_x"] = json!([0.0, 0.02]));
    assert_names(&msg, &["grains.pack.x = [0.0, 0.04]", "inside the periodic cell [0, 0.02]"]);
    // A cell shorter than two grain diameters cannot see a grain's two images.
    let msg = refused("collision", |s| {
        s["domain"]["periodic_x"] = json!([-0.0019, 0.0019]);
    });
    assert_names(&msg, &["domain.periodic_x", "4 r_max"]);
}

#[test]
fn a_packing_the_relaxation_cannot_free_of_overlaps_is_refused_with_the_fix() {
    // Old build: ran to "completed" from overlaps of up to half a radius.
    // Radii 0.4-0.6 mm at 0.8, 200 grains: after all its 20 000 sweeps the relaxation
    // leaves overlaps of 2.5e-2 of a radius. (Wide lognormal radii at 0.8, refused while
    // the relaxation stopped at 2000 sweeps, relax with the sweeps it may now add.)
    let msg = refused("shear", |s| {
        s["grains"]["pack"]["packing_fraction"] = json!(0.8);
        s["grains"]["pack"]["radius"] = json!({"uniform": {"min": 4e-4, "max": 6e-4}});
        s["grains"]["pack"]["count"] = json!(200);
    });
    assert_names(&msg, &["grains.pack.packing_fraction = 0.8", "lower packing_fraction"]);
}

#[test]
fn listed_grains_created_overlapping_are_refused() {
    // Old build: stopped at step 1 on the overlap (and on 10.9 radii into the wall).
    let msg = refused("collision", |s| s["grains"]["list"][1]["x"] = json!([0.0005, 0.0]));
    assert_names(&msg, &["grains.list[0]", "grains.list[1] overlaps it by"]);
    // Below the flat bottom wall.
    let msg = refused("oblique", |s| s["grains"]["list"][0]["x"] = json!([0.0, -0.01]));
    assert_names(&msg, &["walls.bottom.y = 0", "below every grain's centre"]);
}

#[test]
fn a_load_the_grains_cannot_carry_or_the_wall_cannot_follow_is_refused() {
    // Old build: stopped at step 7 and step 1 on overlaps, advising a smaller time step.
    let msg = refused("shear", |s| s["walls"]["top"]["control"] = json!({"pressure": 1e9}));
    assert_names(&msg, &["walls.top.control.pressure = 1000000000 Pa", "at most"]);
    let msg = refused("shear", |s| s["walls"]["top"]["mass"] = json!(1e-12));
    assert_names(&msg, &["walls.top.mass = 0.000000000001 kg", "cannot follow"]);
}

// --- Messages that mislead ---

#[test]
fn a_parse_error_names_the_field_path() {
    // Old build: `trailing characters at line 1 column 589`.
    // Three numbers are a 3D scene's vector: refused in 2D, naming the field and the way.
    let msg = changed("collision", |s| s["gravity"] = json!([0, -9.81, 0])).unwrap_err().to_string();
    assert_names(&msg, &["gravity = 3 numbers", "2 numbers [x, y] in a 2D scene", "\"dimension\": 3"]);
    // Four are no vector at all: refused when read, at the field's path.
    let msg = changed("collision", |s| s["gravity"] = json!([0, -9.81, 0, 1])).unwrap_err().to_string();
    assert_names(&msg, &["at `gravity`", "invalid length 4", "[x, y, z]"]);
    let msg = changed("collision", |s| s["grains"]["list"][1]["r"] = "big".into()).unwrap_err().to_string();
    assert_names(&msg, &["at `grains.list[1].r`", "expected f64"]);
}

#[test]
fn a_built_in_name_wins_over_a_folder_of_that_name() {
    // Old build: read the folder as the scene file (`Is a directory`).
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("collision")).unwrap();
    Command::cargo_bin("grainlab").unwrap().current_dir(dir.path()).args(["explain", "collision"]).assert().success();
    // A file of that name is ambiguous: refused, saying both.
    std::fs::write(dir.path().join("oblique"), builtin("oblique").unwrap().to_json()).unwrap();
    let out = Command::cargo_bin("grainlab").unwrap().current_dir(dir.path()).args(["explain", "oblique"]).output().unwrap();
    assert!(!out.status.success());
    assert_names(&String::from_utf8_lossy(&out.stderr), &["both a built-in scene and a file", "./oblique"]);
    Command::cargo_bin("grainlab").unwrap().current_dir(dir.path()).args(["explain", "./oblique"]).assert().success();
}

#[test]
fn grain_files_declare_their_columns_and_resolve_against_the_scene_file() {
    // Old build: read a line of four numbers as x y z r without a word, and looked for
    // the file in the working directory.
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("scenes");
    std::fs::create_dir(&sub).unwrap();
    // Two grains as `x y z r`: read as `x y r` by default they were silently misread.
    std::fs::write(sub.join("grains.txt"), "-0.00101 0 0 0.001\n0.00101 0 0 0.001\n").unwrap();
    let mut s: Value = serde_json::from_str(&builtin("collision").unwrap().to_json()).unwrap();
    s["grains"] = json!({"file": {"path": "grains.txt"}});
    s["analysis"] = "none".into();
    std::fs::write(sub.join("scene.json"), s.to_string()).unwrap();
    let run = || Command::cargo_bin("grainlab").unwrap().current_dir(dir.path()).args(["explain", "scenes/scene.json"]).output().unwrap();
    let out = run();
    assert!(!out.status.success());
    assert_names(&String::from_utf8_lossy(&out.stderr), &["grains.txt:1", "4 numbers where the columns are 3", "grains.file.columns = \"x y r\""]);
    // Declared, and found next to the scene file although the command runs elsewhere.
    s["grains"]["file"]["columns"] = "x y z r".into();
    std::fs::write(sub.join("scene.json"), s.to_string()).unwrap();
    let out = run();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn a_scene_that_fits_the_budget_runs_and_one_that_does_not_names_the_budget_flag() {
    // New: the budget itself.
    let s = builtin("shear").unwrap();
    let msg = match grainlab::build_limited(&s, 1, &Limits::with_memory(1 << 20)) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("1000 grains in 1 MiB"),
    };
    assert_names(&msg, &["grains.pack.count = 1000", "memory budget of 1.0 MiB", "--memory-budget"]);
    assert!(grainlab::build_limited(&s, 1, &Limits::with_memory(64 << 20)).is_ok());
    // The flag reaches the build.
    let out = Command::cargo_bin("grainlab").unwrap().args(["explain", "shear", "--memory-budget", "1M"]).output().unwrap();
    assert!(!out.status.success());
    assert_names(&String::from_utf8_lossy(&out.stderr), &["memory budget of 1.0 MiB"]);
}

/// A file's text, lower case, to search for non-finite numbers; for summary.json without
/// its provenance block, whose key and command line (paths) are words, not numbers.
fn numbers_text(path: &std::path::Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    if path.extension().is_some_and(|e| e == "json") {
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v.as_object_mut().unwrap().remove("provenance");
        return v.to_string().to_ascii_lowercase();
    }
    text.to_ascii_lowercase()
}
