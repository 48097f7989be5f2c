//! Protocols in stages (issue 27, item 1): a scene's `stages` change the walls' motion
//! and control and gravity at their starts; outputs name the stage of each row, and the
//! summary has one block per stage.

use grainlab::engine::world::{MotionChange, WallMotion};
use grainlab::physics::walls::Control;
use grainlab::scene::builtin::shear_cell;
use grainlab::scene::{ControlSpec, Scene, StageSpec, StageWalls, WallChange};
use grainlab::study::run::{RunOptions, run_scene};

/// A 200-grain shear cell (0.008 m) whose walls start at rest under 100 kPa.
fn small_cell() -> Scene {
    let mut s = shear_cell(200, 0.008);
    let w = s.walls.as_mut().unwrap();
    w.bottom.velocity_x = 0.0;
    w.top.velocity_x = 0.0;
    s.output.frames = 0;
    s
}

fn stage(name: &str, duration: f64, bottom: WallChange, top: WallChange) -> StageSpec {
    StageSpec { name: name.into(), duration, walls: StageWalls { bottom, top }, average: true, ..StageSpec::default() }
}

fn vx(v: f64) -> WallChange {
    WallChange { velocity_x: Some(v), ..WallChange::default() }
}

/// Changing the walls' motion between two steps books the change of the kinetic energy
/// the balance counts for them (a loaded wall's y motion) as the walls' work, so the
/// balance's residual does not move at the change: taken straight before and after,
/// the residuals agree to rounding (1e-12 of the energy put in), while the wall's
/// kinetic energy that a change to fixed control removes is far larger.
#[test]
fn a_change_of_control_keeps_the_balance_closed() {
    let s = small_cell();
    let mut built = grainlab::build(&s).unwrap();
    let e = built.engine.as_mut();
    for _ in 0..3000 {
        e.step().unwrap();
    }
    let before = e.energy_row();
    let wall_ke = e.walls()[1].kinetic();
    assert!(wall_ke > 1e-6 * before.put_in(), "the loaded wall moves: {wall_ke:e} J against {:e} J put in", before.put_in());
    let hold = MotionChange { walls: [WallMotion { velocity_x: Some(-0.5), ..WallMotion::default() }, WallMotion { velocity_x: Some(0.5), control: Some(Control::Fixed), ..WallMotion::default() }], gravity: None };
    e.change_motion(&hold);
    let after = e.energy_row();
    assert_eq!(after.kinetic_walls_j, 0.0);
    assert!((after.residual_j - before.residual_j).abs() < 1e-12 * before.put_in(), "residual {:e} -> {:e} J", before.residual_j, after.residual_j);
    // And back under the load, with the shear running: the balance closes over the next
    // steps as it does in an unstaged shear run (O(dt^2): 1e-3 of the input at 50 steps
    // per contact).
    let load = MotionChange { walls: [WallMotion::default(), WallMotion { control: Some(Control::Load { force: 1e5 * 0.008 * 1e-3 }), ..WallMotion::default() }], gravity: None };
    e.change_motion(&load);
    for _ in 0..3000 {
        e.step().unwrap();
    }
    let row = e.energy_row();
    assert!(row.residual_j.abs() < 1e-3 * row.put_in(), "{row:?}");
    assert_eq!(e.walls()[0].v.x, -0.5);
}

/// A protocol of four stages (held, sheared, pulled apart at a prescribed velocity, back
/// under the load) runs with the energy balance closed throughout: the largest residual
/// over all rows under 1e-3 of the energy put in, the bound an unstaged shear run meets
/// at 50 steps per contact. Each stage has its block in the summary and its rows in
/// walls.csv and energy.csv, named in their first column, in order.
#[test]
fn stages_run_in_order_with_the_balance_closed() {
    let mut s = small_cell();
    s.stages = vec![
        StageSpec { average: false, ..stage("settle", 0.003, WallChange::default(), WallChange::default()) },
        stage("shear", 0.004, vx(-0.5), vx(0.5)),
        stage("lift", 0.001, WallChange::default(), WallChange { velocity_y: Some(0.05), control: Some(ControlSpec::Fixed), ..WallChange::default() }),
        stage("reload", 0.002, WallChange::default(), WallChange { control: Some(ControlSpec::Pressure(1e5)), ..WallChange::default() }),
    ];
    s.duration = 0.01;
    s.output.samples = 100;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let summary = run_scene(&s, &RunOptions { out: Some(out.clone()), ..RunOptions::default() }).unwrap();
    let en = summary.energy.as_ref().unwrap();
    assert!(en.max_residual_rel < 1e-3, "{en:?}");
    let names: Vec<&str> = summary.stages.iter().map(|st| st.name.as_str()).collect();
    assert_eq!(names, ["settle", "shear", "lift", "reload"]);
    assert!(summary.stages[0].shear.is_none(), "not averaged");
    let sheared = summary.stages[1].shear.as_ref().expect("the shear stage is averaged");
    // The top-level shear block is the last averaged stage's.
    assert_eq!(summary.shear.as_ref().unwrap().averaged_from_s, summary.stages[3].shear.as_ref().unwrap().averaged_from_s);
    // Sheared under 100 kPa: the mean normal stress is the load (to the block CI, and to
    // 10%: the top wall carries it on average), and the friction of glass on glass
    // (mu = 0.5 contacts) gives tau/sigma between 0.1 and 0.5.
    assert!((sheared.normal_stress_pa.mean - 1e5).abs() < 0.1e5, "{sheared:?}");
    let ratio = sheared.stress_ratio.as_ref().unwrap().mean;
    assert!((0.1..0.5).contains(&ratio), "tau/sigma = {ratio}");
    // Pulled apart at 0.05 m/s for 1 ms: the gap grew by 5e-5 m (fixed control moves the
    // wall at its prescribed velocity exactly).
    let walls = std::fs::read_to_string(out.join("walls.csv")).unwrap();
    let rows: Vec<Vec<&str>> = walls.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert!(walls.starts_with("stage,time_s,"));
    let gap_at = |name: &str, last: bool| {
        let r: Vec<&Vec<&str>> = rows.iter().filter(|r| r[0] == name).collect();
        let r = if last { r[r.len() - 1] } else { r[0] };
        (r[1].parse::<f64>().unwrap(), r[6].parse::<f64>().unwrap())
    };
    let (t0, g0) = gap_at("shear", true);
    let (t1, g1) = gap_at("lift", true);
    assert!(((g1 - g0) - 0.05 * (t1 - t0)).abs() < 1e-12, "gap {g0} -> {g1} over {} s", t1 - t0);
    // Every row names its stage, the stages in order, each with the rows its block counts.
    let mut seen: Vec<&str> = Vec::new();
    for r in &rows {
        if seen.last() != Some(&r[0]) {
            seen.push(r[0]);
        }
    }
    assert_eq!(seen, names);
    for st in &summary.stages {
        assert_eq!(rows.iter().filter(|r| r[0] == st.name).count(), st.rows, "{}", st.name);
    }
    let energy = std::fs::read_to_string(out.join("energy.csv")).unwrap();
    assert!(energy.starts_with("stage,time_s,"));
    assert_eq!(energy.lines().nth(1).unwrap().split(',').next(), Some("settle"), "the row at t = 0 is the first stage's");
}

/// A stage that changes nothing changes no bit: a run in two stages without changes ends
/// in the state of the same run without stages (the stage boundary only adds a sample,
/// and sampling leaves the bits as they are).
#[test]
fn a_stage_without_changes_changes_no_bit() {
    let mut plain = small_cell();
    let dt = grainlab::build(&plain).unwrap().time_step.dt_s;
    // 20 000 steps, 7000 + 13 000 in stages (the boundaries at ceil(t / dt)).
    plain.duration = 19_999.5 * dt;
    let mut staged = plain.clone();
    staged.stages = vec![stage("a", 6999.5 * dt, WallChange::default(), WallChange::default()), stage("b", 13_000.0 * dt, WallChange::default(), WallChange::default())];
    staged.duration = staged.stages.iter().map(|s| s.duration).sum();
    let run = |s: &Scene| grainlab::study::run::run_built(s, grainlab::build(s).unwrap(), &RunOptions::default()).unwrap();
    let (a, b) = (run(&plain), run(&staged));
    assert_eq!((a.steps, b.steps), (20_000, 20_000));
    assert_eq!(format!("{:?}", a.energy.unwrap().final_row), format!("{:?}", b.energy.unwrap().final_row));
}

/// `--duration` cuts a protocol: the stages that begin before it run, the last one
/// shortened; the summary has their blocks only.
#[test]
fn a_shorter_duration_cuts_the_protocol() {
    let mut s = small_cell();
    s.stages = vec![stage("one", 0.001, WallChange::default(), WallChange::default()), stage("two", 0.001, vx(-0.5), vx(0.5)), stage("three", 0.001, vx(0.0), vx(0.0))];
    s.duration = 0.003;
    let summary = run_scene(&s, &RunOptions { duration: Some(0.0015), ..RunOptions::default() }).unwrap();
    let names: Vec<&str> = summary.stages.iter().map(|st| st.name.as_str()).collect();
    assert_eq!(names, ["one", "two"]);
    assert!((summary.simulated_time_s - 0.0015).abs() < 2.0 * summary.time_step.dt_s);
}

/// What a protocol may not say is refused before anything is built, by its path.
#[test]
fn bad_stages_are_refused_by_path() {
    let refused = |edit: &dyn Fn(&mut serde_json::Value), path: &str| {
        let mut v = serde_json::to_value(grainlab::scene::builtin::protocol()).unwrap();
        edit(&mut v);
        let err = Scene::from_json(&v.to_string()).and_then(|s| grainlab::build(&s).map(|_| ())).expect_err(path).to_string();
        assert!(err.contains(path), "{path}: {err}");
    };
    refused(&|v| v["stages"][1]["duration"] = 0.0.into(), "stages[1].duration");
    refused(&|v| v["stages"][2]["walls"]["bottom"]["control"] = serde_json::json!({"pressure": 1e5}), "stages[2].walls.bottom.control");
    refused(&|v| v["stages"][2]["walls"]["top"]["velocity_y"] = 0.1.into(), "stages[2].walls.top.velocity_y");
    refused(&|v| v["stages"][3]["name"] = "relax".into(), "stages[3].name");
    refused(&|v| v["stages"][0]["name"] = "a,b".into(), "stages[0].name");
    refused(&|v| v["duration"] = 1.0.into(), "duration");
    refused(&|v| v["stages"][3]["walls"]["top"]["velocity_x"] = 1e4.into(), "stages[3].walls.top.velocity_x");
    refused(&|v| v["stages"][1]["gravity"] = serde_json::json!([0.0, f64::MAX]), "stages[1].gravity");
    refused(&|v| v["stages"][1]["walls"]["top"]["control"] = serde_json::json!({"pressure": 1e12}), "stages[1].walls.top.control.pressure");
    refused(&|v| v["stages"][0]["samples"] = 0.into(), "stages[0].samples");
    refused(&|v| v["stages"][0]["bogus"] = 0.into(), "stages[0]");
    // Without a duration, the stages' sum.
    let mut v = serde_json::to_value(grainlab::scene::builtin::protocol()).unwrap();
    v.as_object_mut().unwrap().remove("duration");
    let s = Scene::from_json(&v.to_string()).unwrap();
    assert!((s.duration - 0.075).abs() < 1e-15);
}

/// `explain` prints the stages in the pipeline's line.
#[test]
fn explain_prints_the_stages() {
    let built = grainlab::build(&grainlab::scene::builtin::protocol()).unwrap();
    let line = built.explain();
    assert!(line.contains("stages: compress (0.01 s: not averaged) -> relax (0.005 s: not averaged) -> shear 0.5 (0.03 s: bottom vx -0.5 m/s; top vx 0.5 m/s) -> shear 2"), "{line}");
}

/// A wall changed to fixed control without a y velocity is held, in the exported decks as
/// in grainlab: the bottom row, started moving up, stops in y at the stage's start.
#[test]
fn exported_stages_hold_a_wall_changed_to_fixed() {
    use grainlab::workbench::export::{Code, export_files};
    let mut s = shear_cell(60, 0.004);
    s.output.frames = 0;
    s.walls.as_mut().unwrap().bottom.velocity_y = 1e-3;
    s.stages = vec![stage("held", 1e-5, WallChange { control: Some(ControlSpec::Fixed), ..WallChange::default() }, WallChange::default())];
    s.duration = 1e-5;
    let deck = |code| export_files(&s, code, false, &Default::default()).unwrap()[0].1.clone();
    let zero = "0.00000000000000000e0";
    assert!(deck(Code::Liggghts).contains(&format!("velocity bottom set NULL {zero} NULL units box")), "{}", deck(Code::Liggghts));
    // YADE's STAGES row: name, first, steps, bottom vx, bottom vy, ...
    let yade = deck(Code::Yade);
    let row = yade.lines().find(|l| l.starts_with("    (\"held\"")).expect("the stage's row");
    assert_eq!(row.split(", ").nth(4), Some(zero), "{row}");
}
