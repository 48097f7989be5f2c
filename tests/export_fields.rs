//! The exporter is exact or refuses by name: every leaf of the scene schema has a decision
//! for each reference code in src/workbench/export/fields.rs, and the exporter keeps it.
//!
//! The schema comes from the scene types themselves (schemars), so a field added to the
//! scene without a decision fails `every_schema_leaf_has_a_decision_and_no_decision_is_stale`.
//! `the_exporter_keeps_every_decision` then changes each field of a set of base scenes
//! (the built-ins, shrunk, and variants that hold the other enum variants): numbers x1.1
//! or x0.9 until the scene validates, integers +-1, booleans flipped, strings extended,
//! each other unit variant of an enum; and a few hand-made variants for the variants with
//! data. Each changed scene is built and stepped by the engine and exported for both codes,
//! and:
//! - where the engine's run changes (dt, steps, or the state after 60 steps), the export
//!   must change too or refuse the scene naming the field: no silent drop, whatever the
//!   table says;
//! - "written": some change of the field changes the exported files;
//! - "refused": some change is refused with a message naming the field's path (and a
//!   field that is only refused never changes the files);
//! - "differs": some deck carries a `# Differs:` line naming the field, and every such
//!   line names a field whose decision has a note;
//! - "outside": no change of the field changes the files.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use grainlab::Scene;
use grainlab::workbench::export::fields::{self, FIELDS};
use grainlab::workbench::export::{Code, export_files};
use serde_json::{Value, json};

const CODES: [Code; 3] = [Code::Liggghts, Code::Yade, Code::Lammps];

/// What the values of a leaf are.
#[derive(Clone, Debug, PartialEq)]
enum Kind {
    Number,
    Integer,
    Bool,
    Text,
    /// A unit variant of an enum, with every unit variant's name.
    Choice(Vec<String>),
    /// A fixed-length array of numbers (a vector), changed one element at a time.
    Numbers,
    /// One of several kinds (an untagged enum, `"auto"` or a number): a change may move
    /// to any of them.
    Either(Vec<Kind>),
}

fn resolve<'a>(root: &'a Value, node: &'a Value) -> &'a Value {
    match node.get("$ref").and_then(Value::as_str) {
        Some(r) => resolve(root, &root["$defs"][r.trim_start_matches("#/$defs/")]),
        None => node,
    }
}

fn join(path: &str, key: &str) -> String {
    if path.is_empty() { key.to_string() } else { format!("{path}.{key}") }
}

/// The node's type, a nullable `["number", "null"]` taken as its non-null type.
fn type_of(node: &Value) -> Option<&str> {
    match node.get("type")? {
        Value::String(s) => Some(s.as_str()),
        Value::Array(a) => a.iter().filter_map(Value::as_str).find(|t| *t != "null"),
        _ => None,
    }
}

fn is_object(root: &Value, node: &Value) -> bool {
    let node = resolve(root, node);
    type_of(node) == Some("object") || node.get("oneOf").is_some() || node.get("properties").is_some()
}

/// Every leaf of the schema under `node` at `path`.
fn leaves(root: &Value, node: &Value, path: &str, out: &mut BTreeMap<String, Kind>) {
    let node = resolve(root, node);
    if let Some(any) = node.get("anyOf").and_then(Value::as_array) {
        let alts: Vec<&Value> = any.iter().filter(|a| a.get("type") != Some(&json!("null"))).collect();
        let mut kinds = Vec::new();
        for alt in &alts {
            let mut one = BTreeMap::new();
            leaves(root, alt, path, &mut one);
            // An alternative that is a leaf itself joins the others; its fields below (an
            // enum's variants with data) are leaves of their own.
            kinds.extend(one.remove(path));
            out.extend(one);
        }
        match kinds.len() {
            0 => {}
            1 => drop(out.insert(path.to_string(), kinds.pop().unwrap())),
            _ => drop(out.insert(path.to_string(), Kind::Either(kinds))),
        }
        return;
    }
    if let Some(one) = node.get("oneOf").and_then(Value::as_array) {
        let mut units = Vec::new();
        for alt in one {
            let alt = resolve(root, alt);
            if let Some(c) = alt.get("const").and_then(Value::as_str) {
                units.push(c.to_string());
            } else if let Some(e) = alt.get("enum").and_then(Value::as_array) {
                units.extend(e.iter().map(|v| v.as_str().expect("string enum").to_string()));
            } else {
                // A variant with data, `{"variant": ...}`.
                let props = alt["properties"].as_object().expect("a variant with data is an object");
                assert_eq!(props.len(), 1, "{path}: {alt}");
                let (name, inner) = props.iter().next().unwrap();
                leaves(root, inner, &join(path, name), out);
            }
        }
        if !units.is_empty() {
            out.insert(path.to_string(), Kind::Choice(units));
        }
        return;
    }
    match type_of(node) {
        Some("object") => {
            for (k, v) in node["properties"].as_object().expect("properties") {
                leaves(root, v, &join(path, k), out);
            }
        }
        Some("array") => {
            if is_object(root, &node["items"]) {
                leaves(root, &node["items"], &format!("{path}[]"), out);
            } else {
                assert_eq!(type_of(resolve(root, &node["items"])), Some("number"), "{path}");
                out.insert(path.to_string(), Kind::Numbers);
            }
        }
        Some("number") => drop(out.insert(path.to_string(), Kind::Number)),
        Some("integer") => drop(out.insert(path.to_string(), Kind::Integer)),
        Some("boolean") => drop(out.insert(path.to_string(), Kind::Bool)),
        Some("string") => drop(out.insert(path.to_string(), Kind::Text)),
        other => panic!("{path}: a schema node of type {other:?}: {node}"),
    }
}

fn schema() -> Value {
    serde_json::to_value(schemars::schema_for!(Scene)).unwrap()
}

fn schema_leaves() -> BTreeMap<String, Kind> {
    let root = schema();
    let mut out = BTreeMap::new();
    leaves(&root, &root, "", &mut out);
    out
}

#[test]
fn every_schema_leaf_has_a_decision_and_no_decision_is_stale() {
    let schema: BTreeSet<String> = schema_leaves().into_keys().collect();
    let table: BTreeSet<String> = FIELDS.iter().map(|f| f.path.to_string()).collect();
    let missing: Vec<_> = schema.difference(&table).collect();
    let stale: Vec<_> = table.difference(&schema).collect();
    assert!(missing.is_empty(), "scene fields without an export decision in src/workbench/export/fields.rs: {missing:?}");
    assert!(stale.is_empty(), "decisions in src/workbench/export/fields.rs for no scene field: {stale:?}");
    // The walk sees what the issue names, enum variants' fields included.
    for p in ["materials[].restitution", "grains.pack.radius.lognormal.sigma", "walls.top.control.pressure", "time_step.rule.accuracy.tolerance", "grain_shape"] {
        assert!(schema.contains(p), "{p}");
    }
}

/// A leaf as it occurs in a scene: normalised path, JSON pointer, kind.
#[derive(Clone, Debug)]
struct Present {
    path: String,
    pointer: String,
    kind: Kind,
}

/// The leaves holding a value (not null) in `value`.
fn present(root: &Value, node: &Value, value: &Value, path: &str, pointer: &str, out: &mut Vec<Present>) {
    if value.is_null() {
        return;
    }
    let node = resolve(root, node);
    if let Some(any) = node.get("anyOf").and_then(Value::as_array) {
        let alts: Vec<&Value> = any.iter().filter(|a| a.get("type") != Some(&json!("null"))).collect();
        if alts.len() > 1 {
            // An untagged enum of leaves: the leaf with every alternative's kind.
            let mut one = BTreeMap::new();
            leaves(root, node, path, &mut one);
            if let Some(kind) = one.remove(path) {
                out.push(Present { path: path.to_string(), pointer: pointer.to_string(), kind });
                return;
            }
        }
        return present(root, alts[0], value, path, pointer, out);
    }
    if let Some(one) = node.get("oneOf").and_then(Value::as_array) {
        match value {
            Value::String(_) => {
                let mut units = BTreeMap::new();
                leaves(root, node, path, &mut units);
                out.push(Present { path: path.to_string(), pointer: pointer.to_string(), kind: units.remove(path).unwrap() });
            }
            Value::Object(o) => {
                let (name, inner) = o.iter().next().unwrap();
                let alt = one.iter().map(|a| resolve(root, a)).find(|a| a.get("properties").and_then(|p| p.get(name)).is_some()).unwrap();
                present(root, &alt["properties"][name], inner, &join(path, name), &format!("{pointer}/{name}"), out);
            }
            _ => panic!("{path}: {value}"),
        }
        return;
    }
    match type_of(node) {
        Some("object") => {
            for (k, v) in value.as_object().unwrap() {
                present(root, &node["properties"][k], v, &join(path, k), &format!("{pointer}/{k}"), out);
            }
        }
        Some("array") if is_object(root, &node["items"]) => {
            for (i, v) in value.as_array().unwrap().iter().enumerate() {
                present(root, &node["items"], v, &format!("{path}[]"), &format!("{pointer}/{i}"), out);
            }
        }
        _ => {
            let mut one = BTreeMap::new();
            leaves(root, node, path, &mut one);
            out.push(Present { path: path.to_string(), pointer: pointer.to_string(), kind: one.remove(path).unwrap() });
        }
    }
}

/// Candidate changes of a number: x1.1, x0.9, x1.1^2, ...; from zero, small steps.
fn number_candidates(v: f64) -> Vec<f64> {
    if v == 0.0 {
        return vec![0.1, -0.1, 1e-3, -1e-3, 1.0];
    }
    (1..=6).flat_map(|k| [v * 1.1f64.powi(k), v * 0.9f64.powi(k)]).collect()
}

/// Candidate values for the leaf at `at` (each a whole new value of the leaf).
fn candidates(at: &Present, v: &Value) -> Vec<Vec<Value>> {
    candidates_of(&at.kind, v)
}

fn candidates_of(kind: &Kind, v: &Value) -> Vec<Vec<Value>> {
    match kind {
        // Each alternative's changes from this value, or (another alternative) its values.
        Kind::Either(kinds) => kinds
            .iter()
            .flat_map(|k| match k {
                Kind::Integer if !v.is_u64() => vec![vec![json!(10)]],
                Kind::Number if !v.is_number() => vec![vec![json!(1.0)]],
                Kind::Choice(units) if !v.is_string() => units.iter().map(|u| vec![json!(u)]).collect(),
                Kind::Integer | Kind::Number if !v.is_number() => Vec::new(),
                Kind::Choice(_) if !v.is_string() => Vec::new(),
                // A spin about z stays a number (three components are a 3D scene's).
                Kind::Numbers if !v.is_array() => Vec::new(),
                k => candidates_of(k, v),
            })
            .collect(),
        Kind::Number => vec![number_candidates(v.as_f64().unwrap()).into_iter().map(|x| json!(x)).collect()],
        Kind::Integer => {
            let n = v.as_u64().unwrap();
            vec![[Some(n + 1), n.checked_sub(1)].into_iter().flatten().map(|x| json!(x)).collect()]
        }
        Kind::Bool => vec![vec![json!(!v.as_bool().unwrap())]],
        Kind::Text => vec![vec![json!(format!("{}-changed", v.as_str().unwrap()))]],
        // Each other unit variant is a change of its own.
        Kind::Choice(units) => units.iter().filter(|u| v.as_str() != Some(u.as_str())).map(|u| vec![json!(u)]).collect(),
        // One element at a time: each element is a change of its own.
        Kind::Numbers => {
            let a = v.as_array().unwrap();
            (0..a.len())
                .map(|i| {
                    number_candidates(a[i].as_f64().unwrap())
                        .into_iter()
                        .map(|x| {
                            let mut b = a.clone();
                            b[i] = json!(x);
                            Value::Array(b)
                        })
                        .collect()
                })
                .collect()
        }
    }
}

/// A scene grainlab accepts and builds (a change that fails here is no change to export).
fn valid(v: &Value) -> Option<Scene> {
    let s = Scene::from_json(&v.to_string()).ok()?;
    match s.dimension {
        grainlab::scene::Dimension::Two => drop(grainlab::build(&s).ok()?),
        grainlab::scene::Dimension::Three => drop(grainlab::build_in::<grainlab::physics::dim::Space>(&s, 1, &Default::default()).ok()?),
    }
    Some(s)
}

/// What the engine does with a scene: dt, steps, and every grain's and wall's state after
/// 60 steps (long enough for the impacts' contacts to begin, 10.5 steps in).
fn engine_run(s: &Scene) -> Vec<f64> {
    if s.dimension == grainlab::scene::Dimension::Three {
        return engine_run_in_space(s);
    }
    let mut b = grainlab::build(s).unwrap();
    let mut out = stepped(&mut b, s);
    let p = b.engine.particles();
    for i in 0..p.len() {
        out.extend([p.x[i].x, p.x[i].y, p.v[i].x, p.v[i].y, p.omega[i], p.r[i], p.m[i], p.inertia[i], p.material[i] as f64]);
    }
    for w in b.engine.walls() {
        out.extend([w.y, w.v.x, w.v.y, w.load_y()]);
        // A held wall's mass moves nothing.
        if w.load_y() != 0.0 {
            out.push(w.mass);
        }
    }
    out
}

/// [`engine_run`] of a 3D scene: dt, steps, and every grain's position, velocity and
/// spin (three components each) after 60 steps.
fn engine_run_in_space(s: &Scene) -> Vec<f64> {
    let mut b = grainlab::build_in::<grainlab::physics::dim::Space>(s, 1, &Default::default()).unwrap();
    let mut out = stepped(&mut b, s);
    let p = b.engine.particles();
    for i in 0..p.len() {
        out.extend(p.x[i].iter().chain(p.v[i].iter()).chain(p.omega[i].iter()).copied());
        out.extend([p.r[i], p.m[i]]);
    }
    out
}

/// Step a built scene 60 times: dt and the run's steps, then NaN if a step failed.
fn stepped<D: grainlab::physics::dim::Dim>(b: &mut grainlab::Built<D>, s: &Scene) -> Vec<f64> {
    let (steps, _) = grainlab::engine::timestep::schedule(s.duration, b.time_step.dt_s, s.output.samples);
    let mut out = vec![b.time_step.dt_s, steps as f64];
    for _ in 0..60 {
        if b.engine.step().is_err() {
            out.push(f64::NAN);
            break;
        }
    }
    out
}

fn same_run(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x == y || (x - y).abs() <= 1e-10 * (x.abs() + y.abs()))
}

type Export = Result<Vec<(&'static str, String)>, String>;

fn export(s: &Scene, code: Code) -> Export {
    export_files(s, code, false, &Default::default()).map_err(|e| e.to_string())
}

/// Whether a refusal names `path` (normalised), as a whole path.
fn names(message: &str, path: &str) -> bool {
    let m = fields::normalise(message);
    m.match_indices(path).any(|(k, _)| {
        let before = m[..k].chars().last();
        let after = m[k + path.len()..].chars().next();
        !before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '.') && !after.is_some_and(|c| c.is_alphanumeric() || c == '_')
    })
}

/// The paths that a deck's `# Differs:` lines name.
fn noted(files: &[(&'static str, String)]) -> Vec<String> {
    let deck = &files[0].1;
    deck.lines().filter_map(|l| l.strip_prefix("# Differs: ")).map(|l| fields::normalise(l.split([' ', ':']).next().unwrap())).collect()
}

/// A base scene: its name, its JSON, the leaves to change (path prefixes; all when
/// empty), and, for a variant of another base, the leaf the variant changes.
struct Base {
    name: &'static str,
    scene: Value,
    only: &'static [&'static str],
    variant_of: Option<(&'static str, &'static str)>,
}

fn json_of(s: &Scene) -> Value {
    serde_json::to_value(s).unwrap()
}

/// A second material, of restitution `e` (YADE takes one restitution for all pairs).
fn steel(e: f64) -> grainlab::physics::material::Material {
    grainlab::physics::material::Material { name: "steel".into(), youngs_modulus: 200e9, poisson_ratio: 0.3, density: 7800.0, restitution: e, friction: 0.3, work_of_adhesion: 0.0, rolling_friction: 0.0 }
}

fn bases(dir: &Path) -> Vec<Base> {
    use grainlab::scene::pack::RadiusDist;
    use grainlab::scene::*;
    use grainlab::scene::builtin;
    let collision = builtin::builtin("collision").unwrap();
    let oblique = builtin::builtin("oblique").unwrap();
    // 4 mm: YADE's periodic collider needs a cell of at least 4 r_max + 2 r_min (3.2 mm).
    let mut shear = builtin::shear_cell(60, 0.004);
    shear.output.frames = 0;
    // Written only when on: a base that holds it, for the walk to change.
    shear.output.contacts = true;
    let base = |name, s: &Scene| Base { name, scene: json_of(s), only: &[], variant_of: None };
    let focus = |name, s: &Scene, only| Base { name, scene: json_of(s), only, variant_of: None };
    let variant = |name, s: &Scene, of, leaf, only| Base { name, scene: json_of(s), only, variant_of: Some((of, leaf)) };
    let mut out = vec![base("collision", &collision), base("oblique", &oblique), base("shear", &shear)];
    // The dimension given (2 is left out of written scenes): set to 3, the same grains in
    // space, whose decks are the 3D ones.
    // (Its analysis none: the impact observer is the plane's, and a 3D scene asking for it
    // is refused when read.)
    let mut planar = json_of(&collision);
    planar["dimension"] = json!(2);
    planar["analysis"] = json!("none");
    out.push(Base { name: "collision, dimension given", scene: planar, only: &["dimension"], variant_of: None });
    // 3D scenes (analysis none, as above): two spheres meeting off centre, spinning about
    // skew axes, each vector and spin of three components; a sphere on the flat walls
    // with a z velocity; a small shear box periodic in x and z between rough lattices, the
    // top one loaded.
    let mut pair3d = json_of(&collision);
    pair3d["dimension"] = json!(3);
    pair3d["analysis"] = json!("none");
    let x0 = pair3d["grains"]["list"][0]["x"][0].as_f64().unwrap();
    pair3d["grains"]["list"][0]["x"] = json!([x0, 0.0, -0.2e-3]);
    pair3d["grains"]["list"][0]["v"] = json!([0.5, 0.0, 0.1]);
    pair3d["grains"]["list"][0]["omega"] = json!([10.0, -20.0, 5.0]);
    pair3d["grains"]["list"][1]["x"] = json!([-x0, 0.1e-3, 0.2e-3]);
    pair3d["grains"]["list"][1]["v"] = json!([-0.5, 0.0, -0.1]);
    pair3d["grains"]["list"][1]["omega"] = json!([0.0, 3.0, 0.0]);
    // Periodic along z: the open YADE script has no periodic cell (refused by name).
    let mut periodic = pair3d.clone();
    periodic["domain"]["periodic_z"] = json!([-0.01, 0.01]);
    out.push(Base { name: "pair3d-periodic-z", scene: periodic, only: &["domain.periodic_z"], variant_of: Some(("pair3d", "domain.periodic_z")) });
    out.push(Base { name: "pair3d", scene: pair3d, only: &["grains.list", "dimension"], variant_of: None });
    let mut wall3d = json_of(&oblique);
    wall3d["dimension"] = json!(3);
    wall3d["analysis"] = json!("none");
    let [x, y] = [0, 1].map(|k| wall3d["grains"]["list"][0]["x"][k].as_f64().unwrap());
    let [vx, vy] = [0, 1].map(|k| wall3d["grains"]["list"][0]["v"][k].as_f64().unwrap());
    wall3d["grains"]["list"][0]["x"] = json!([x, y, 0.0]);
    wall3d["grains"]["list"][0]["v"] = json!([vx, vy, 0.3]);
    out.push(Base { name: "wall3d", scene: wall3d, only: &["grains.list", "walls"], variant_of: None });
    let mut s = builtin::shear3d();
    s.domain = Domain { periodic_x: Some([0.0, 0.004]), periodic_z: Some([0.0, 0.004]) };
    if let Grains::Pack(p) = &mut s.grains {
        (p.count, p.x, p.z) = (40, [0.0, 0.004], Some([0.0, 0.004]));
    }
    s.duration = 2e-4;
    s.output.frames = 0;
    out.push(focus("shear3d", &s, &["dimension", "domain", "grains.pack", "walls"]));

    // Two materials (one restitution, as YADE needs), the second grain of the second.
    let mut s = collision.clone();
    s.materials.push(steel(0.5));
    if let Grains::List(l) = &mut s.grains {
        l[1].material = 1;
    }
    out.push(focus("collision-2mat", &s, &["materials", "grains.list"]));
    let mut s = oblique.clone();
    s.materials.push(steel(0.9));
    let w = s.walls.as_mut().unwrap();
    w.bottom.material = 1;
    w.top.material = 1;
    out.push(focus("oblique-2mat", &s, &["materials", "walls"]));
    let mut s = oblique.clone();
    s.model.rotation = false;
    out.push(focus("oblique-norot", &s, &["model", "grains.list"]));

    // Time step rules and their settings.
    let dt = grainlab::build(&collision).unwrap().time_step.dt_s;
    for (name, rule) in [
        ("collision-fixed", TimeStepRule::Fixed { dt: 0.9 * dt }),
        ("collision-rayleigh", TimeStepRule::RayleighFraction { fraction: 0.1 }),
        ("collision-seed", TimeStepRule::SeedRule { factor: 0.1, reference_overlap: 0.01 }),
        ("collision-accuracy", TimeStepRule::Accuracy { quantity: grainlab::scene::AccuracyQuantity::Restitution, tolerance: 1e-3, impact_speed: 1.0 }),
    ] {
        let mut s = collision.clone();
        s.time_step.rule = rule;
        s.time_step.characteristic_speed = Some(1.0);
        out.push(focus(name, &s, &["time_step"]));
    }

    // Packings of every radius distribution, and the pack's options set.
    for (name, radius) in [
        ("shear-fixed", RadiusDist::Fixed { radius: 0.5e-3 }),
        ("shear-normal", RadiusDist::Normal { mean: 0.5e-3, std: 0.05e-3, min: 0.4e-3, max: 0.6e-3 }),
        ("shear-lognormal", RadiusDist::Lognormal { median: 0.5e-3, sigma: 0.1, min: 0.4e-3, max: 0.6e-3 }),
    ] {
        let mut s = shear.clone();
        if let Grains::Pack(p) = &mut s.grains {
            p.radius = radius;
            p.y_min = Some(0.5e-3);
            p.packing_fraction = 0.7;
        }
        out.push(focus(name, &s, &["grains.pack"]));
    }
    // The walls' options set: a stress depth, the bottom wall's mass, a second material.
    let mut s = shear.clone();
    let top_mass = grainlab::build(&shear).unwrap().engine.walls()[1].mass;
    s.materials.push(grainlab::physics::material::Material { name: "glass2".into(), youngs_modulus: 70e9, ..shear.materials[0].clone() });
    let w = s.walls.as_mut().unwrap();
    w.thickness = Some(1e-3);
    w.bottom.mass = Some(top_mass);
    w.bottom.material = 1;
    out.push(focus("shear-walls", &s, &["walls", "materials", "grains.pack.material"]));
    // The loaded wall's mass, at its default (the glued grains' total: LIGGGHTS can
    // express that one).
    let mut s = shear.clone();
    s.walls.as_mut().unwrap().top.mass = Some(top_mass);
    out.push(focus("shear-mass", &s, &["walls.top.mass"]));
    let mut s = shear.clone();
    let w = s.walls.as_mut().unwrap();
    w.top.control = ControlSpec::Fixed;
    w.top.mass = Some(0.01);
    out.push(variant("shear-held-top", &s, "shear", "walls.top.control", &["walls"]));

    // Grains from a file (and the file a changed path names).
    let file = dir.join("grains.txt");
    std::fs::write(&file, "# x y r\n-1.0001e-3 0 1e-3\n1.0001e-3 0 1e-3\n").unwrap();
    std::fs::write(dir.join("grains.txt-changed"), "-1.0001e-3 0 1e-3\n1.0002e-3 0 1e-3\n").unwrap();
    let mut s = collision.clone();
    s.materials.push(steel(0.5));
    s.grains = Grains::File { path: file.to_str().unwrap().to_string(), columns: Default::default(), material: 0 };
    // A file's grains start at rest: no impact can happen.
    s.analysis = Analysis::None;
    out.push(focus("file", &s, &["grains.file"]));

    // Variants that hold the other enum variants and options, each a change of one leaf.
    // The linear spring: derived from a characteristic velocity (any grains), and given
    // (written for the two equal grains; refused where a pair of materials meets at two
    // reduced masses, as the packing's grains of several sizes do).
    // The default normal law, written out (written scenes leave it out).
    let mut hertz = json_of(&collision);
    hertz["model"]["normal"] = json!("hertz");
    out.push(Base { name: "collision-hertz", scene: hertz, only: &["model.normal"], variant_of: None });
    // The default damping, written out: the walk moves it to LAMMPS' Tsuji fit.
    let mut damped = json_of(&collision);
    damped["model"]["damping"] = json!("restitution");
    out.push(Base { name: "collision-damping", scene: damped, only: &["model.damping"], variant_of: None });
    // The same under the clamp, which the clamped damping requires: the walk moves it
    // there too.
    let mut clamped = json_of(&collision);
    clamped["model"]["damping"] = json!("restitution");
    clamped["model"]["limit_force"] = json!(true);
    out.push(Base { name: "collision-clamped-damping", scene: clamped, only: &["model.damping"], variant_of: None });
    // A restitution below LIGGGHTS' floor (0.05 < e), as a change of the collision's.
    let mut low = collision.clone();
    low.materials[0].restitution = 0.04;
    out.push(variant("collision-low-restitution", &low, "collision", "materials[].restitution", &["materials[].restitution"]));
    // The work of adhesion, written out at 0 (written scenes leave it out): the walk
    // moves it above 0, DMT cohesion (LAMMPS alone, Hertz only), on the Hertz pair and
    // under the given spring.
    let mut adhesion = json_of(&collision);
    adhesion["materials"][0]["work_of_adhesion"] = json!(0.0);
    out.push(Base { name: "collision-adhesion", scene: adhesion, only: &["materials"], variant_of: None });
    let mut s = collision.clone();
    s.model.normal = NormalLaw::HookeStiffness { kn: 2e5, kt: 1e5 };
    let mut adhesion = json_of(&s);
    adhesion["materials"][0]["work_of_adhesion"] = json!(0.0);
    out.push(Base { name: "collision-spring-adhesion", scene: adhesion, only: &["materials"], variant_of: None });
    // Rolling resistance on the oblique impact (a grain on flat walls): EPSD2 (LIGGGHTS)
    // and SDS (LAMMPS), with a rolling friction; the walk moves the law, its parameters
    // and the coefficient.
    let mut s = oblique.clone();
    s.model.rolling = RollingSpec::Epsd2;
    for m in &mut s.materials {
        m.rolling_friction = 0.1;
    }
    out.push(focus("oblique-rolling-epsd2", &s, &["model.rolling", "materials"]));
    s.model.rolling = RollingSpec::Sds { stiffness: 1e5, damping: 0.01 };
    out.push(variant("oblique-rolling-sds", &s, "oblique-rolling-epsd2", "model.rolling", &["model.rolling", "materials"]));
    let mut s = collision.clone();
    s.model.normal = NormalLaw::Hooke { characteristic_velocity: 1.0 };
    out.push(variant("collision-hooke", &s, "collision", "model.normal", &["model.normal"]));
    let mut s = collision.clone();
    s.model.normal = NormalLaw::HookeStiffness { kn: 2e5, kt: 1e5 };
    out.push(variant("collision-spring", &s, "collision", "model.normal", &["model.normal"]));
    let mut s = shear.clone();
    s.model.normal = NormalLaw::HookeStiffness { kn: 2e5, kt: 1e5 };
    out.push(variant("shear-spring", &s, "shear", "model.normal", &["model.normal"]));
    // The derived spring in the packing: LAMMPS takes one kn per pair of types, refused.
    let mut s = shear.clone();
    s.model.normal = NormalLaw::Hooke { characteristic_velocity: 1.0 };
    out.push(variant("shear-hooke", &s, "shear", "model.normal", &["model.normal"]));
    let mut s = collision.clone();
    s.model.general_damping = Some(0.1);
    out.push(variant("collision-damped", &s, "collision", "model.general_damping", &["model.general_damping"]));
    let mut s = collision.clone();
    s.gravity = [0.0, -9.81].into();
    out.push(variant("collision-gravity", &s, "collision", "gravity", &["gravity"]));
    let mut s = collision.clone();
    s.grain_shape = grainlab::physics::dim::GrainShape::Disk { thickness: 2e-3 };
    out.push(variant("collision-disk", &s, "collision", "grain_shape", &["grain_shape"]));
    let mut s = collision.clone();
    s.domain.periodic_x = Some([-0.01, 0.01]);
    out.push(variant("collision-periodic", &s, "collision", "domain.periodic_x", &["domain"]));
    let mut s = oblique.clone();
    let w = s.walls.as_mut().unwrap();
    w.bottom.surface = SurfaceSpec::Rough { radius: 1e-3 };
    w.bottom.y = Some(-1.5e-3);
    // The grain now hits a glued grain, not the flat (top) wall an impact analysis
    // watches: no impact to measure.
    s.analysis = Analysis::None;
    out.push(variant("oblique-rough-bottom", &s, "oblique", "walls.bottom.surface", &["walls.bottom"]));
    let mut s = oblique.clone();
    s.walls.as_mut().unwrap().top.surface = SurfaceSpec::Rough { radius: 1e-3 };
    out.push(variant("oblique-rough-top", &s, "oblique", "walls.top.surface", &["walls.top"]));
    let mut s = oblique.clone();
    s.walls.as_mut().unwrap().top.control = ControlSpec::Pressure(1e5);
    out.push(variant("oblique-loaded-top", &s, "oblique", "walls.top.control", &["walls.top.control"]));
    let mut s = shear.clone();
    s.walls.as_mut().unwrap().bottom.surface = SurfaceSpec::Flat;
    out.push(variant("shear-flat-bottom", &s, "shear", "walls.bottom.surface", &["walls.bottom.surface"]));
    let mut s = shear.clone();
    s.walls.as_mut().unwrap().top.surface = SurfaceSpec::Flat;
    out.push(variant("shear-flat-top", &s, "shear", "walls.top.surface", &["walls.top.surface"]));

    // A protocol: every stage field set, the walls at rest at the start. Its JSON leaves
    // the duration out (the stages' sum), so that a stage's duration may change.
    let mut s = shear.clone();
    let w = s.walls.as_mut().unwrap();
    w.bottom.velocity_x = 0.0;
    w.top.velocity_x = 0.0;
    let first = StageSpec {
        name: "held".into(),
        duration: 2e-5,
        walls: StageWalls {
            bottom: WallChange { velocity_x: Some(-0.5), velocity_y: Some(0.0), control: Some(ControlSpec::Fixed) },
            top: WallChange { velocity_x: Some(0.5), velocity_y: Some(1e-3), control: Some(ControlSpec::Fixed) },
        },
        gravity: Some([0.0, 0.0].into()),
        samples: Some(3),
        frames: Some(1),
        average: false,
    };
    let loaded = |control| StageSpec { name: "loaded".into(), duration: 2e-5, walls: StageWalls { top: WallChange { control: Some(control), ..WallChange::default() }, ..StageWalls::default() }, ..StageSpec::default() };
    s.stages = vec![first.clone(), loaded(ControlSpec::Pressure(1e5))];
    let staged = |s: &Scene| {
        let mut v = json_of(s);
        v.as_object_mut().unwrap().remove("duration");
        v
    };
    out.push(Base { name: "shear-staged", scene: staged(&s), only: &["stages"], variant_of: None });
    s.stages = vec![first.clone(), loaded(ControlSpec::Fixed)];
    out.push(Base { name: "shear-staged-held", scene: staged(&s), only: &[], variant_of: Some(("shear-staged", "stages[].walls.top.control")) });
    // A protocol beside flat walls: refused by both codes.
    let mut s = oblique.clone();
    s.analysis = Analysis::None;
    s.stages = vec![StageSpec { duration: s.duration, ..StageSpec::default() }];
    out.push(Base { name: "oblique-staged", scene: staged(&s), only: &["stages"], variant_of: None });
    out
}

/// What one change did for one code.
#[derive(Clone, Debug, PartialEq)]
enum Outcome {
    Identical,
    Changed,
    Refused(String),
    /// Refused before and after, for the same reason: no deck either way.
    StillRefused,
}

/// What one change did: to the engine's run, and to each code's export.
struct Probe {
    ran_differently: bool,
    outcomes: [Outcome; 3],
    notes: [Vec<String>; 3],
}

impl Probe {
    fn moved(&self) -> bool {
        self.ran_differently || self.outcomes.iter().any(|o| *o != Outcome::Identical)
    }
}

fn probe(before_run: &[f64], before: &[Export; 3], after: &Scene) -> Probe {
    let ran_differently = !same_run(before_run, &engine_run(after));
    let mut notes: [Vec<String>; 3] = Default::default();
    let outcomes = [0, 1, 2].map(|c| {
        let now = export(after, CODES[c]);
        if let Ok(files) = &now {
            notes[c] = noted(files);
        }
        match (&before[c], &now) {
            (Ok(a), Ok(b)) if a == b => Outcome::Identical,
            (Err(a), Err(b)) if a == b => Outcome::StillRefused,
            (_, Err(b)) => Outcome::Refused(b.clone()),
            _ => Outcome::Changed,
        }
    });
    Probe { ran_differently, outcomes, notes }
}

#[derive(Default)]
struct Tally {
    changed: usize,
    refused_by_name: usize,
    identical: usize,
}

/// What the walk found.
#[derive(Default)]
struct Walk {
    tally: BTreeMap<(String, usize), Tally>,
    notes: [BTreeSet<String>; 3],
    failures: Vec<String>,
    changes: usize,
}

impl Walk {
    fn record(&mut self, what: &str, path: &str, p: Probe) {
        self.changes += 1;
        for (c, outcome) in p.outcomes.into_iter().enumerate() {
            let code = CODES[c].name();
            let t = self.tally.entry((path.to_string(), c)).or_default();
            match outcome {
                Outcome::Identical => {
                    t.identical += 1;
                    if p.ran_differently {
                        self.failures.push(format!("{code}: {what}: the engine's run changes, the export does not (a silent drop)"));
                    }
                }
                Outcome::Changed => t.changed += 1,
                Outcome::StillRefused => {}
                Outcome::Refused(m) => {
                    if names(&m, path) {
                        t.refused_by_name += 1;
                    } else {
                        self.failures.push(format!("{code}: {what}: refused without naming {path}: {m}"));
                    }
                }
            }
        }
        for (c, n) in p.notes.into_iter().enumerate() {
            self.notes[c].extend(n);
        }
    }
}

#[test]
fn the_exporter_keeps_every_decision() {
    let root = schema();
    let dir = tempfile::tempdir().unwrap();
    let bases = bases(dir.path());
    let mut walk = Walk::default();
    let mut seen: BTreeSet<String> = BTreeSet::new();
    let by_name: BTreeMap<&str, &Base> = bases.iter().map(|b| (b.name, b)).collect();
    for b in &bases {
        let scene = Scene::from_json(&b.scene.to_string()).unwrap_or_else(|e| panic!("base {}: {e}", b.name));
        let run = engine_run(&scene);
        let exports = CODES.map(|c| export(&scene, c));
        for (c, e) in exports.iter().enumerate() {
            if let Ok(files) = e {
                walk.notes[c].extend(noted(files));
            }
        }
        let mut here = Vec::new();
        present(&root, &root, &b.scene, "", "", &mut here);
        seen.extend(here.iter().map(|p| p.path.clone()));
        // A variant is a change of one leaf of its parent.
        if let Some((of, leaf)) = b.variant_of {
            let parent = Scene::from_json(&by_name[of].scene.to_string()).unwrap();
            let parent_exports = CODES.map(|c| export(&parent, c));
            let p = probe(&engine_run(&parent), &parent_exports, &scene);
            walk.record(&format!("{of} -> {}", b.name), leaf, p);
        }
        for at in here.iter().filter(|p| b.only.is_empty() || b.only.iter().any(|o| p.path.starts_with(o))) {
            let old = b.scene.pointer(&at.pointer).unwrap().clone();
            for set in candidates(at, &old) {
                // The first valid candidate that changes the run or an export, else the
                // last valid one.
                let mut last = None;
                for v in set {
                    let mut s = b.scene.clone();
                    *s.pointer_mut(&at.pointer).unwrap() = v.clone();
                    let Some(after) = valid(&s) else { continue };
                    let p = probe(&run, &exports, &after);
                    let moved = p.moved();
                    last = Some((v, p));
                    if moved {
                        break;
                    }
                }
                if let Some((v, p)) = last {
                    walk.record(&format!("{}: {} {old} -> {v}", b.name, at.pointer), &at.path, p);
                }
            }
        }
    }

    let Walk { mut tally, notes, mut failures, changes } = walk;
    if std::env::var_os("EXPORT_FIELDS_TALLY").is_some() {
        for ((path, c), t) in &tally {
            println!("{} {path}: changed {}, refused by name {}, identical {}", CODES[*c].name(), t.changed, t.refused_by_name, t.identical);
        }
    }
    // Every leaf was seen with a value (one-value leaves aside, which validation pins).
    for f in FIELDS {
        if !seen.contains(f.path) && f.liggghts.one_value.is_none() {
            failures.push(format!("{}: no base scene holds a value: add one to bases()", f.path));
        }
    }
    // Each decision holds.
    for f in FIELDS {
        for (c, &code) in CODES.iter().enumerate() {
            let d = f.decision(code);
            let t = tally.remove(&(f.path.to_string(), c)).unwrap_or_default();
            let fail = |why: &str| format!("{} {}: {why} (changed {}, refused by name {}, identical {})", code.name(), f.path, t.changed, t.refused_by_name, t.identical);
            if d.written.is_some() && t.changed == 0 {
                failures.push(fail("\"written\", but no change of it changes the exported files"));
            }
            if d.refused.is_some() && t.refused_by_name == 0 {
                failures.push(fail("\"refused\", but no change of it is refused by name"));
            }
            if d.refused.is_none() && t.refused_by_name > 0 {
                failures.push(fail("refused by name, but the table has no refusal for it"));
            }
            if d.written.is_none() && d.differs.is_none() && t.changed > 0 {
                failures.push(fail("not written, but a change of it changes the exported files"));
            }
            if d.differs.is_some() && !notes[c].contains(f.path) {
                failures.push(fail("\"differs\", but no deck has a `# Differs:` line naming it"));
            }
            if d.outside.is_some() && (t.changed > 0 || t.refused_by_name > 0) {
                failures.push(fail("\"outside\" the physics, but changing it changes or refuses the export"));
            }
        }
    }
    // Every note names a field whose decision has one.
    for (c, &code) in CODES.iter().enumerate() {
        for p in &notes[c] {
            let ok = p == "grains" || fields::field(p).is_some_and(|f| f.decision(code).differs.is_some());
            if !ok {
                failures.push(format!("{}: a `# Differs: {p}` line, but src/workbench/export/fields.rs has no note for {p}", code.name()));
            }
        }
    }
    assert!(failures.is_empty(), "{} of the export decisions do not hold ({changes} changes tried):\n{}", failures.len(), failures.join("\n"));
    // The walk did change things: every base and most leaves.
    assert!(changes > 150, "only {changes} changes tried");
}

#[test]
fn one_value_fields_admit_no_other_value() {
    // The bottom wall never carries a load: scene validation refuses it, so the decks'
    // held bottom wall is the only case.
    let mut s = json_of(&grainlab::scene::builtin::shear_cell(60, 0.004));
    s["walls"]["bottom"]["control"] = json!({"pressure": 1e5});
    let e = Scene::from_json(&s.to_string()).expect_err("a loaded bottom wall is refused");
    assert!(e.to_string().contains("walls.bottom.control"), "{e}");
    // Nor at a protocol's stage.
    let mut s = json_of(&grainlab::scene::builtin::protocol());
    s["stages"][1]["walls"]["bottom"]["control"] = json!({"pressure": 1e5});
    let e = Scene::from_json(&s.to_string()).expect_err("a loaded bottom wall is refused");
    assert!(e.to_string().contains("stages[1].walls.bottom.control"), "{e}");
    // A 3D scene's own fields are refused in a 2D scene.
    let mut s = json_of(&grainlab::scene::builtin::shear_cell(60, 0.004));
    s["domain"]["periodic_z"] = json!([0.0, 0.004]);
    let e = Scene::from_json(&s.to_string()).expect_err("a periodic z in 2D is refused");
    assert!(e.to_string().contains("domain.periodic_z") && e.to_string().contains("dimension"), "{e}");
    let mut s = json_of(&grainlab::scene::builtin::shear_cell(60, 0.004));
    s["grains"]["pack"]["z"] = json!([0.0, 0.004]);
    let e = Scene::from_json(&s.to_string()).expect_err("a packing's z range in 2D is refused");
    assert!(e.to_string().contains("grains.pack.z") && e.to_string().contains("dimension"), "{e}");
    for f in FIELDS.iter().filter(|f| f.liggghts.one_value.is_some() || f.yade.one_value.is_some()) {
        assert!(f.path.starts_with("walls.bottom.control") || f.path.starts_with("stages[].walls.bottom.control"), "{}: a one-value field this test does not try", f.path);
    }
}

/// Export the collision with `name` for `code`.
fn named(name: &str, code: Code) -> Vec<(&'static str, String)> {
    let mut s = grainlab::scene::builtin::builtin("collision").unwrap();
    s.name = name.to_string();
    export_files(&s, code, false, &Default::default()).unwrap()
}

#[test]
fn a_scene_name_cannot_change_what_a_deck_does() {
    // Names that would add a command or a statement to a deck pasted as they are: a line
    // break followed by code, a LIGGGHTS `&` that continues a line onto the next, `$`
    // substitution, quotes, other line breaks of Python and of Unicode, non-ASCII text.
    // The deck of each must equal the deck of a plain name in every line but comments,
    // line for line; grains.data in its title line; export.json must keep the name as it is.
    let hostile = [
        "x\nimport os; os.system('touch PWNED') #",
        "x\nshell touch PWNED #",
        "x\nrun 0 &",
        "x &",
        "x&\n",
        "${x} $(1/0) $x \"q\" 'q' `q`",
        "x\rimport os\r\nprint(1)\u{b}\u{c}\u{85}\u{2028}",
        "Grün é ✓ \\",
    ];
    for code in CODES {
        let plain = named("x", code);
        for name in hostile {
            let files = named(name, code);
            for ((file, a), (_, b)) in plain.iter().zip(&files) {
                if *file == "export.json" {
                    let mut a: Value = serde_json::from_str(a).unwrap();
                    let b: Value = serde_json::from_str(b).unwrap();
                    assert_eq!(b["scene"], json!(name), "{}: export.json keeps the name", code.name());
                    a["scene"] = json!(name);
                    assert_eq!(a, b, "{} {name:?}: export.json", code.name());
                    continue;
                }
                let (la, lb): (Vec<&str>, Vec<&str>) = (a.lines().collect(), b.lines().collect());
                assert_eq!(la.len(), lb.len(), "{} {file} of {name:?} has other lines:\n{b}", code.name());
                for (k, (x, y)) in la.iter().zip(&lb).enumerate() {
                    if x == y {
                        continue;
                    }
                    let comment = if *file == "grains.data" { k == 0 } else { y.starts_with('#') && x.starts_with('#') };
                    assert!(comment, "{} {file} of {name:?}: line {} differs outside a comment: {y}", code.name(), k + 1);
                    assert!(y.chars().all(|c| c == ' ' || c.is_ascii_graphic()), "{} {file}: not printable ASCII: {y:?}", code.name());
                    assert!(!y.trim_end().ends_with('&'), "{} {file}: a line ending in `&` continues onto the next in LIGGGHTS: {y}", code.name());
                }
            }
        }
    }
}

#[test]
fn a_silently_dropped_setting_is_caught() {
    // The tests above compare exports with the engine's runs; this is the case the issue
    // found, by hand: general damping changes the engine's run (a drag from the first
    // step), so an export must refuse it by name rather than write the undamped deck.
    let mut s = grainlab::scene::builtin::builtin("collision").unwrap();
    let plain = engine_run(&s);
    s.model.general_damping = Some(100.0);
    assert!(!same_run(&plain, &engine_run(&s)), "general damping does not change the run");
    for code in CODES {
        let e = export(&s, code).expect_err("general damping exported");
        assert!(e.contains(&format!("export to {}: model.general_damping = 100 cannot be expressed", code.name())), "{e}");
    }
}
