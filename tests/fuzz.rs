//! Fuzzing the scene: the built-in scenes (and variants that hold the other enum
//! variants) mutated field by field, types, ranges, extremes, deletions, duplicates and
//! broken text, then parsed, built within a memory budget, run for a bounded number of
//! steps into an output folder and exported. Every case must end in a refusal that names
//! its field, a diagnosed stop, or a run; and whatever ends it:
//! - no panic (a panic fails the property),
//! - no allocation beyond the budget (a counting allocator measures the peak),
//! - no run beyond the step bound,
//! - no number that is not finite in the summary or in any file written.
//!
//! `cargo test` runs `FUZZ_CASES` cases (default 1000, a few seconds); CI runs more
//! (`.ci/run`). A failure prints the case (base, mutations, seed, broken text) that
//! reproduces it: `FUZZ_CASE=2,1,9139556803309287229,2 cargo test --test fuzz`.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use grainlab::scene::limits::Limits;
use grainlab::study::run::{RunOptions, run_report};
use grainlab::{Error, Scene};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::{Value, json};

/// The allocator, counting the bytes live and their peak.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            if new_size >= layout.size() {
                let now = LIVE.fetch_add(new_size - layout.size(), Ordering::Relaxed) + new_size - layout.size();
                PEAK.fetch_max(now, Ordering::Relaxed);
            } else {
                LIVE.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
            }
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The memory budget of every case: 16 MiB (at most about 16 000 grains).
const BUDGET: u64 = 16 << 20;
/// What a case may allocate beyond the budget: the budget's estimate counts what a run
/// keeps; a frame's text, the export's decks and the packing's transient lists come on
/// top, each a few times the grains' count in bytes.
const SLACK: usize = 16 << 20;
/// The most steps a case runs.
const STEPS: f64 = 300.0;

/// The base scenes, as JSON.
fn bases(dir: &Path) -> Vec<Value> {
    use grainlab::scene::builtin;
    let json = |s: &Scene| serde_json::to_value(s).unwrap();
    let mut out: Vec<Value> = ["collision", "oblique"].iter().map(|n| json(&builtin::builtin(n).unwrap())).collect();
    // The seed's shear cell, smaller (200 grains), so that a case takes milliseconds.
    let mut shear = builtin::shear_cell(200, 0.008);
    shear.output.frames = 3;
    out.push(json(&shear));
    // A protocol in that cell: every stage field set, each stage a few dozen steps.
    let mut staged = json(&shear);
    staged.as_object_mut().unwrap().remove("duration");
    staged["stages"] = json!([
        {"name": "held", "duration": 4e-6, "walls": {"bottom": {"velocity_x": -0.5, "velocity_y": 0.0, "control": "fixed"}, "top": {"velocity_x": 0.5, "velocity_y": -0.01, "control": "fixed"}}, "gravity": [0.0, -9.81], "samples": 3, "frames": 1, "average": false},
        {"name": "loaded", "duration": 4e-6, "walls": {"top": {"control": {"pressure": 1e5}}}},
        {"duration": 1e-5, "walls": {"bottom": {"velocity_x": -1.0}, "top": {"velocity_x": 1.0}}, "gravity": [0.0, 0.0]}
    ]);
    out.push(staged);
    let mut pair = json(&builtin::oblique_pair(grainlab::physics::material::Material::default(), 1e-3, 1.0, 30.0, grainlab::scene::TangentialSpec::IncrementalForce, 50.0));
    pair["model"]["limit_force"] = true.into();
    pair["gravity"] = json!([0.0, -9.81]);
    out.push(pair);
    // Micro-slip's beds of springs, in the oblique impact.
    let mut micro = json(&builtin::builtin("oblique").unwrap());
    micro["model"]["tangential"] = "mindlin_deresiewicz".into();
    out.push(micro);
    let mut flat = json(&shear);
    flat["walls"]["bottom"]["surface"] = "flat".into();
    flat["walls"]["top"]["surface"] = "flat".into();
    flat["walls"]["top"]["control"] = "fixed".into();
    flat["walls"]["top"]["y"] = json!(0.03);
    flat["grains"]["pack"]["radius"] = json!({"lognormal": {"median": 5e-4, "sigma": 0.1, "min": 4e-4, "max": 6e-4}});
    flat["model"]["general_damping"] = json!(50.0);
    out.push(flat);
    let mut accurate = json(&builtin::builtin("collision").unwrap());
    accurate["time_step"]["rule"] = json!({"accuracy": {"quantity": "peak_force", "tolerance": 1e-2, "impact_speed": 1.0}});
    accurate["grain_shape"] = json!({"disk": {"thickness": 1e-3}});
    out.push(accurate);
    // Grains from a file.
    let file = dir.join("grains.txt");
    std::fs::write(&file, "# x y z r\n0 0.002 0 0.001\n0.0025 0.002 0 0.001\n0.005 0.002 0 0.001\n").unwrap();
    let mut from_file = json(&builtin::builtin("oblique").unwrap());
    from_file["grains"] = json!({"file": {"path": file.to_str().unwrap(), "columns": "x y z r"}});
    from_file["analysis"] = "none".into();
    from_file["gravity"] = json!([0.0, -9.81]);
    from_file["time_step"]["rule"] = json!({"rayleigh_fraction": {"fraction": 0.2}});
    out.push(from_file);
    let mut seed = json(&builtin::builtin("collision").unwrap());
    seed["time_step"]["rule"] = json!({"seed_rule": {"factor": 0.1, "reference_overlap": 0.01}});
    seed["domain"]["periodic_x"] = json!([-0.01, 0.01]);
    seed["materials"].as_array_mut().unwrap().push(json!({"name": "steel", "youngs_modulus": 2e11, "poisson_ratio": 0.3, "density": 7800.0, "restitution": 0.8, "friction": 0.2}));
    seed["grains"]["list"][1]["material"] = 1.into();
    out.push(seed);
    // The linear spring: derived per pair in the shear cell (under load, between rough
    // walls), given on a pair of grains with the seed's time-step rule.
    let mut spring_shear = json(&shear);
    spring_shear["model"]["normal"] = json!({"hooke": {"characteristic_velocity": 0.5}});
    out.push(spring_shear);
    let mut spring_pair = json(&builtin::oblique_pair(grainlab::physics::material::Material::default(), 1e-3, 1.0, 30.0, grainlab::scene::TangentialSpec::TotalDisplacement, 50.0));
    spring_pair["model"]["normal"] = json!({"hooke_stiffness": {"kn": 2e5, "kt": 1.5e5}});
    spring_pair["time_step"]["rule"] = json!({"seed_rule": {"factor": 0.1, "reference_overlap": 0.01}});
    out.push(spring_pair);
    // LAMMPS' Tsuji damping in the loaded shear cell.
    let mut tsuji = json(&shear);
    tsuji["model"]["damping"] = "tsuji".into();
    out.push(tsuji);
    // DMT cohesion in the loaded shear cell (strong: a pull-off force near the contact
    // forces of 100 kPa), and on a pair of grains under the given spring.
    let mut dmt = json(&shear);
    for m in dmt["materials"].as_array_mut().unwrap() {
        m["work_of_adhesion"] = json!(20.0);
    }
    out.push(dmt);
    let mut dmt_pair = json(&builtin::builtin("collision").unwrap());
    dmt_pair["materials"][0]["work_of_adhesion"] = json!(1.0);
    dmt_pair["model"]["normal"] = json!({"hooke_stiffness": {"kn": 2e5, "kt": 1.5e5}});
    out.push(dmt_pair);
    // Rolling resistance: EPSD2 in the loaded shear cell, SDS on an oblique pair under the
    // given spring.
    let mut rolling = json(&shear);
    rolling["model"]["rolling"] = "epsd2".into();
    for m in rolling["materials"].as_array_mut().unwrap() {
        m["rolling_friction"] = json!(0.1);
    }
    out.push(rolling);
    let mut rolling_pair = json(&builtin::oblique_pair(grainlab::physics::material::Material::default(), 1e-3, 1.0, 30.0, grainlab::scene::TangentialSpec::TotalDisplacement, 50.0));
    rolling_pair["model"]["normal"] = json!({"hooke_stiffness": {"kn": 2e5, "kt": 1.5e5}});
    rolling_pair["model"]["rolling"] = json!({"sds": {"stiffness": 1e5, "damping": 1e-3}});
    rolling_pair["materials"][0]["rolling_friction"] = json!(0.2);
    rolling_pair["grains"]["list"][0]["omega"] = json!(300.0);
    out.push(rolling_pair);
    // 3D: the shear box smaller (150 spheres in a 4 x 4 mm cell periodic in x and z), a
    // flat-walled box open in z under gravity, and two spheres meeting off centre, one
    // spinning about a skew axis.
    let mut box3d = json(&builtin::builtin("shear3d").unwrap());
    box3d["domain"] = json!({"periodic_x": [0.0, 0.004], "periodic_z": [0.0, 0.004]});
    box3d["grains"]["pack"]["count"] = json!(150);
    box3d["grains"]["pack"]["x"] = json!([0.0, 0.004]);
    box3d["grains"]["pack"]["z"] = json!([0.0, 0.004]);
    box3d["output"]["frames"] = json!(3);
    out.push(box3d.clone());
    let mut open3d = box3d;
    open3d["domain"] = json!({"periodic_x": [0.0, 0.004]});
    open3d["walls"]["bottom"]["surface"] = "flat".into();
    open3d["walls"]["top"]["surface"] = "flat".into();
    open3d["walls"]["top"]["control"] = "fixed".into();
    open3d["walls"]["top"]["y"] = json!(0.03);
    open3d["gravity"] = json!([0.0, -9.81, 1.0]);
    open3d["model"]["tangential"] = "incremental_force".into();
    out.push(open3d);
    out.push(json!({"name": "pair3d", "dimension": 3,
        "grains": {"list": [{"x": [0.0, 0.0, 0.0], "v": [0.5, 0.3, 0.4], "omega": [10.0, -20.0, 5.0], "r": 0.001},
                            {"x": [0.0025, 0.0015, 0.002], "v": [-0.5, -0.3, -0.4], "r": 0.001}]},
        "model": {"tangential": "total_force_cap", "general_damping": 10.0},
        "time_step": {"rule": {"steps_per_contact": {"steps": 50, "impact_speed": 1.0}}},
        "duration": 0.004, "output": {"samples": 10, "frames": 2}, "analysis": "impact"}));
    // The built-in oblique impact on a wall in space (its tangent out of the x-y plane).
    out.push(json(&builtin::builtin("oblique3d").unwrap()));
    out
}

/// Every subtree of the bases: what a node may be replaced with (a well-formed value of
/// another field: the type confusions and variant swaps a person makes).
fn snippets(bases: &[Value]) -> Vec<Value> {
    fn walk(v: &Value, out: &mut Vec<Value>) {
        out.push(v.clone());
        match v {
            Value::Object(m) => m.values().for_each(|x| walk(x, out)),
            Value::Array(a) => a.iter().for_each(|x| walk(x, out)),
            _ => {}
        }
    }
    let mut out = Vec::new();
    bases.iter().for_each(|b| walk(b, &mut out));
    out.extend(
        [
            json!({"pressure": 1e5}),
            json!({"rough": {"radius": 5e-4}}),
            json!({"fixed": {"dt": 1e-7}}),
            json!({"steps_per_contact": {"steps": 50, "impact_speed": 1}}),
            json!({"uniform": {"min": 4e-4, "max": 6e-4}}),
            json!({"normal": {"mean": 5e-4, "std": 1e-4, "min": 4e-4, "max": 6e-4}}),
            json!({"fixed": {"radius": 5e-4}}),
            "incremental_force".into(),
            "frictionless".into(),
            "radius_minus_half_overlap".into(),
            "yade".into(),
            "impact".into(),
            "shear".into(),
            "none".into(),
            "x y r".into(),
        ],
    );
    out
}

/// Numbers at the edges: zero, signs, the smallest and largest, integers past 2^53 and
/// 2^64, and values of typical size.
const EXTREMES: &[f64] = &[0.0, -0.0, -1.0, 1.0, 2.0, 0.5, 1e-300, 5e-324, 1e300, 1.7976931348623157e308, -1.7976931348623157e308, 9007199254740993.0, 1.8446744073709552e19, 1e-9, 1e9, 3.0, 1000.0];

/// All JSON pointers of a value's nodes.
fn pointers(v: &Value, at: String, out: &mut Vec<String>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                let p = format!("{at}/{}", k.replace('~', "~0").replace('/', "~1"));
                out.push(p.clone());
                pointers(x, p, out);
            }
        }
        Value::Array(a) => {
            for (k, x) in a.iter().enumerate() {
                let p = format!("{at}/{k}");
                out.push(p.clone());
                pointers(x, p, out);
            }
        }
        _ => {}
    }
}

/// One mutation of the scene `v`, as `rng` picks it.
fn mutate(v: &mut Value, rng: &mut ChaCha8Rng, snippets: &[Value]) {
    let mut ps = Vec::new();
    pointers(v, String::new(), &mut ps);
    if ps.is_empty() {
        return;
    }
    // Mostly a number (most fields are), else any node.
    let numbers: Vec<&String> = ps.iter().filter(|p| v.pointer(p).is_some_and(Value::is_number)).collect();
    let p = if !numbers.is_empty() && rng.random_bool(0.75) { numbers[rng.random_range(0..numbers.len())].clone() } else { ps[rng.random_range(0..ps.len())].clone() };
    let (parent, key) = p.rsplit_once('/').unwrap();
    let action = rng.random_range(0..10);
    let node = v.pointer_mut(&p).unwrap();
    match (action, &*node) {
        // Numbers: an extreme, a scale by a power of ten, a negation.
        (0..=6, Value::Number(n)) => {
            let x = n.as_f64().unwrap_or(1.0);
            // An integer field (a count, an index, a seed) mostly stays an integer.
            if n.is_u64() && rng.random_bool(0.7) {
                let big = [0u64, 1, 2, 3, 7, 255, 256, 1000, 65535, 65536, 1 << 32, 1 << 53, u64::MAX - 1, u64::MAX];
                *node = json!(big[rng.random_range(0..big.len())]);
                return;
            }
            let y = match rng.random_range(0..3) {
                0 => EXTREMES[rng.random_range(0..EXTREMES.len())],
                1 => x * 10f64.powi(rng.random_range(-30..=30)),
                _ => -x,
            };
            *node = if y.fract() == 0.0 && y.abs() < 1.8e19 && rng.random_bool(0.5) {
                if y >= 0.0 { json!(y as u64) } else { json!(y as i64) }
            } else {
                serde_json::Number::from_f64(y).map_or(Value::Null, Value::Number)
            };
        }
        (0..=1, Value::Bool(b)) => *node = Value::Bool(!b),
        // Arrays: an element more (a duplicate), fewer, none.
        (0..=3, Value::Array(a)) if !a.is_empty() => {
            let mut a = a.clone();
            match rng.random_range(0..3) {
                0 => {
                    let k = rng.random_range(0..a.len());
                    a.push(a[k].clone());
                }
                1 => {
                    a.pop();
                }
                _ => a.clear(),
            }
            *node = Value::Array(a);
        }
        // Another field's value (a type confusion, or another enum variant).
        (4..=6, _) => *node = snippets[rng.random_range(0..snippets.len())].clone(),
        // A value of another type.
        (7, _) => *node = [json!("text"), json!(null), json!([]), json!({}), json!(true), json!(1e308)][rng.random_range(0..6)].clone(),
        // Deleted.
        _ => {
            match v.pointer_mut(parent) {
                Some(Value::Object(m)) => {
                    m.remove(&key.replace("~1", "/").replace("~0", "~"));
                }
                Some(Value::Array(a)) => {
                    let k: usize = key.parse().unwrap();
                    if k < a.len() {
                        a.remove(k);
                    }
                }
                _ => {}
            }
        }
    }
}

/// How a case ended.
#[derive(Debug, Default)]
struct Tally {
    /// Parse refusals by what they say (the message without its path and position).
    parse_kinds: std::collections::BTreeMap<String, usize>,
    /// Refused when read: syntax, types, a field's range.
    parse: usize,
    /// The diagnoses of the runs that stopped.
    stops: Vec<String>,
    /// Refused by the build: consistency, the budget.
    refused: usize,
    completed: usize,
    stopped: usize,
    exported: usize,
    export_refused: usize,
}

/// Every number in the CSV files, the frames and the index of `dir` is finite (a CSV
/// cell may be empty: an undefined quantity).
fn assert_files_finite(dir: &Path) {
    let mut files = Vec::new();
    for e in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        if e.path().is_dir() {
            files.extend(std::fs::read_dir(e.path()).unwrap().flatten().map(|f| f.path()));
        } else {
            files.push(e.path());
        }
    }
    for f in files {
        if f.extension().is_some_and(|e| e == "vtp") {
            // Binary arrays: every value read back.
            for (name, values) in common::read_vtp(&f) {
                assert!(values.iter().all(|v| v.is_finite()), "{}: {name} holds a number that is not finite", f.display());
            }
        } else {
            assert_finite_text(&f.display().to_string(), &std::fs::read_to_string(&f).unwrap());
        }
    }
}

/// No `nan` or `inf` in `text` that starts a word (the words of an output's text, `info`
/// aside, hold neither): a number that is not finite, however it is spelt.
fn assert_finite_text(name: &str, text: &str) {
    let lower = text.to_ascii_lowercase();
    for bad in ["nan", "inf"] {
        let found = lower.match_indices(bad).any(|(k, _)| {
            let before = lower[..k].chars().last().unwrap_or(' ');
            !before.is_ascii_alphabetic() && !lower[k..].starts_with("info")
        });
        assert!(!found, "{name} holds `{bad}`:\n{}", &text[..text.len().min(2000)]);
    }
}

/// Exercise one mutated scene text.
fn exercise(text: &str, dir: &Path, export: bool, tally: &mut Tally, case: &str) -> Result<(), TestCaseError> {
    // Through the command line's loader: a scene file (bounded read, relative paths).
    let file = dir.join("scene.json");
    std::fs::write(&file, text).unwrap();
    let limits = Limits::with_memory(BUDGET);
    let scene = match grainlab::scene::builtin::load(file.to_str().unwrap(), &limits) {
        Ok(s) => s,
        Err(e) => {
            tally.parse += 1;
            let what = match &e {
                Error::Parse { what, .. } => what.split(" at line").next().unwrap_or("").chars().take(40).collect(),
                other => other.to_string().chars().take(40).collect(),
            };
            *tally.parse_kinds.entry(what).or_default() += 1;
            prop_assert!(!e.to_string().is_empty());
            return Ok(());
        }
    };
    match scene.dimension {
        grainlab::scene::Dimension::Two => run_case(&scene, grainlab::build_limited(&scene, 1, &limits), dir, tally, case)?,
        grainlab::scene::Dimension::Three => run_case(&scene, grainlab::build_in::<grainlab::physics::dim::Space>(&scene, 1, &limits), dir, tally, case)?,
    }
    if export {
        for code in [grainlab::workbench::export::Code::Liggghts, grainlab::workbench::export::Code::Yade, grainlab::workbench::export::Code::Lammps] {
            match grainlab::workbench::export::export_files(&scene, code, false, &limits) {
                Ok(files) => {
                    tally.exported += 1;
                    for (name, text) in files {
                        assert_finite_text(name, &text);
                    }
                }
                Err(e) => {
                    tally.export_refused += 1;
                    prop_assert!(!e.to_string().is_empty());
                }
            }
        }
    }
    Ok(())
}

/// Run a built case (in the plane or in space) into `dir/out` within the step bound, or
/// count its refusal.
fn run_case<D: grainlab::study::run::Running>(scene: &Scene, built: Result<grainlab::Built<D>, Error>, dir: &Path, tally: &mut Tally, case: &str) -> Result<(), TestCaseError> {
    let built = match built {
        Ok(b) => b,
        Err(e) => {
            tally.refused += 1;
            if let Error::Invalid { field, value, allowed } = &e {
                prop_assert!(!field.is_empty() && !value.is_empty() && !allowed.is_empty(), "{e}");
            }
            return Ok(());
        }
    };
    let dt = built.time_step.dt_s;
    prop_assert!(dt.is_finite() && dt > 0.0, "dt = {dt}");
    let duration = scene.duration.min(STEPS * dt);
    let out = dir.join("out");
    let opts = RunOptions { out: Some(out.clone()), overwrite: true, duration: Some(duration), ..Default::default() };
    let report = run_report(scene, built, &opts).map_err(|e| TestCaseError::fail(format!("the run did not start: {e}")))?;
    let s = &report.summary;
    prop_assert!(s.steps as f64 <= STEPS + 1.0, "{} steps", s.steps);
    prop_assert!(grainlab::finite::non_finite_column(s).is_none(), "summary: {:?} not finite", grainlab::finite::non_finite_column(s));
    prop_assert!(report.write_error.is_none(), "{:?}", report.write_error);
    match &report.ending {
        None => tally.completed += 1,
        Some(Error::Unstable { what, advice, .. }) => {
            prop_assert!(!what.is_empty() && !advice.is_empty());
            tally.stopped += 1;
            tally.stops.push(format!("[{case}] {what} -- {advice}"));
        }
        Some(e) => return Err(TestCaseError::fail(format!("the run ended with {e}"))),
    }
    assert_files_finite(&out);
    Ok(())
}

/// The text of a case: `mutations` mutations of base `base` drawn from `seed`, the text
/// broken when `broken_text` is 0 (cut short) or 1 (a key given twice).
fn case_text(bases: &[Value], snippets: &[Value], base: usize, mutations: usize, seed: u64, broken_text: u8) -> String {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut v = bases[base].clone();
    for _ in 0..mutations {
        mutate(&mut v, &mut rng, snippets);
    }
    let mut text = v.to_string();
    if broken_text == 0 {
        text.truncate(rng.random_range(0..text.len()));
    } else if broken_text == 1 {
        text = text.replacen("{\"", "{\"duration\":1e-3,\"", 1);
    }
    text
}

fn cases() -> u32 {
    std::env::var("FUZZ_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(1000)
}

#[test]
fn mutated_scenes_are_refused_by_name_or_run_to_a_finite_end_within_budget() {
    let dir = tempfile::tempdir().unwrap();
    let bases = bases(dir.path());
    let snippets = snippets(&bases);
    // Every base runs as it is.
    let mut tally = Tally::default();
    for (k, b) in bases.iter().enumerate() {
        let built = Scene::from_json(&b.to_string()).and_then(|s| match s.dimension {
            grainlab::scene::Dimension::Two => grainlab::build_limited(&s, 1, &Limits::with_memory(BUDGET)).map(|_| ()),
            grainlab::scene::Dimension::Three => grainlab::build_in::<grainlab::physics::dim::Space>(&s, 1, &Limits::with_memory(BUDGET)).map(|_| ()),
        });
        assert!(built.is_ok(), "base {k}: {built:?}");
        exercise(&b.to_string(), dir.path(), true, &mut tally, "base").unwrap();
    }
    assert_eq!((tally.parse, tally.refused, tally.stopped), (0, 0, 0), "a base scene does not run: {tally:?}");
    let tally = std::cell::RefCell::new(Tally::default());
    let config = ProptestConfig { cases: cases(), failure_persistence: None, ..ProptestConfig::default() };
    // `FUZZ_CASE=base,mutations,seed,broken_text` (as a failure prints them) runs that
    // case alone and prints its scene.
    if let Ok(case) = std::env::var("FUZZ_CASE") {
        let n: Vec<u64> = case.split(',').map(|x| x.trim().parse().unwrap()).collect();
        let text = case_text(&bases, &snippets, n[0] as usize, n[1] as usize, n[2], n[3] as u8);
        eprintln!("{text}");
        exercise(&text, dir.path(), true, &mut tally.borrow_mut(), &case).unwrap();
        eprintln!("{:?}", tally.borrow());
        return;
    }
    proptest!(config, |(base in 0..bases.len(), mutations in 1usize..=3, seed in any::<u64>(), broken_text in 0u8..20)| {
        let text = case_text(&bases, &snippets, base, mutations, seed, broken_text);
        let start = LIVE.load(Ordering::Relaxed);
        PEAK.store(start, Ordering::Relaxed);
        exercise(&text, dir.path(), seed % 4 == 0, &mut tally.borrow_mut(), &format!("{base},{mutations},{seed},{broken_text}"))?;
        let extra = PEAK.load(Ordering::Relaxed).saturating_sub(start);
        prop_assert!(extra <= BUDGET as usize + SLACK, "allocated {extra} bytes over a budget of {BUDGET} (scene: {})", &text[..text.len().min(3000)]);
    });
    let t = tally.into_inner();
    eprintln!("fuzz: {} cases: {} refused when read (syntax, types, field ranges), {} refused by the build (consistency, budget), {} completed, {} stopped with a diagnosis; exports: {} written, {} refused", cases(), t.parse, t.refused, t.completed, t.stopped, t.exported, t.export_refused);
    if std::env::var_os("FUZZ_SHOW").is_some() {
        let mut kinds: Vec<_> = t.parse_kinds.iter().collect();
        kinds.sort_by_key(|k| std::cmp::Reverse(*k.1));
        eprintln!("parse refusals: {:?}", &kinds[..kinds.len().min(12)]);
        for stop in &t.stops {
            eprintln!("stopped: {stop}");
        }
    }
    // The mutations reach every ending, so the property is tested on each.
    assert!(t.refused > 0 && t.completed > 0, "{t:?}");
}
