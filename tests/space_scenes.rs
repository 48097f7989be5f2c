//! 3D scenes (issue 30): `"dimension": 3` read, checked and refused by name where space
//! does not have a feature yet; a plane scene lifted into space (`"dimension": 3` added,
//! every grain at z = 0) runs as the plane scene; a 3D shear box built from its scene
//! file runs, writes its outputs, carries its load and resumes bit for bit.
//!
//! Each bound is stated with its reason at the assertion.

mod common;

use grainlab::engine::build::Built;
use grainlab::physics::dim::{Plane, Space};
use grainlab::scene::{Dimension, Grains, GrainSpec, Scene};
use grainlab::study::run::{RunOptions, resume, run_report};

fn limits() -> grainlab::scene::limits::Limits {
    grainlab::scene::limits::Limits::machine()
}

fn plane(scene: &Scene) -> Built<Plane> {
    grainlab::build_limited(scene, 1, &limits()).unwrap()
}

fn space(scene: &Scene) -> Built<Space> {
    grainlab::build_in::<Space>(scene, 1, &limits()).unwrap()
}

/// `scene` with `"dimension": 3` (its analysis none: the impact observer is the plane's).
fn lifted(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    s.dimension = Dimension::Three;
    s.analysis = grainlab::scene::Analysis::None;
    s
}

/// Step a plane engine and the same scene's engine in space `steps` steps and require
/// every free and glued grain, wall and ledger-independent state to agree to the bit:
/// positions and velocities in x-y, spins about z; z parts exactly 0. The restriction
/// is exact (tests/space_run.rs): the space kernels do the plane's operations, in its
/// order, with zeros for the third components, so the bound is zero.
fn same_motion(name: &str, a: &mut Built<Plane>, b: &mut Built<Space>, steps: u64) {
    assert_eq!(a.time_step.dt_s.to_bits(), b.time_step.dt_s.to_bits(), "{name}: the time step");
    let mut contacts = 0;
    for k in 1..=steps {
        a.engine.advance(true).unwrap();
        b.engine.advance(true).unwrap();
        contacts += b.engine.touching();
        if k % 500 != 0 && k != steps {
            continue;
        }
        let (p, q) = (a.engine.particles(), b.engine.particles());
        assert_eq!(p.len(), q.len(), "{name}: grain count");
        for i in 0..p.len() {
            let (x, y) = (p.x[i], q.x[i]);
            let ok = x.x.to_bits() == y.x.to_bits() && x.y.to_bits() == y.y.to_bits() && y.z == 0.0;
            assert!(ok, "{name}: step {k}, grain {i} at {x:?} in the plane, {y:?} in space");
            let (u, w) = (p.v[i], q.v[i]);
            assert!(u.x.to_bits() == w.x.to_bits() && u.y.to_bits() == w.y.to_bits() && w.z == 0.0, "{name}: step {k}, grain {i} moves at {u:?} / {w:?}");
            let (s, t) = (p.omega[i], q.omega[i]);
            assert!(s.to_bits() == t.z.to_bits() && t.x == 0.0 && t.y == 0.0, "{name}: step {k}, grain {i} spins at {s} / {t:?}");
        }
        for (v, w) in a.engine.walls().iter().zip(b.engine.walls()) {
            assert_eq!((v.y.to_bits(), v.force.x.to_bits(), v.force.y.to_bits()), (w.y.to_bits(), w.force.x.to_bits(), w.force.y.to_bits()), "{name}: step {k}, the {} wall", v.name);
        }
    }
    // The runs did meet: contact-steps counted over the run.
    assert!(contacts > 0, "{name}: no contact in {steps} steps");
    eprintln!("{name}: {contacts} contact-steps over {steps} steps, the same to the bit");
}

/// The built-in head-on collision and oblique impact on a wall, and an oblique impact of
/// a spinning sphere on a resting one, each lifted into space: the same motion to the
/// bit through the contact and after.
#[test]
fn plane_impacts_lifted_into_space_move_as_in_the_plane() {
    let glass = grainlab::physics::material::Material { restitution: 0.7, ..Default::default() };
    let mut pair = grainlab::scene::builtin::oblique_pair(glass.clone(), 1e-3, 1.0, 35.0, grainlab::scene::TangentialSpec::IncrementalForce, 100.0);
    if let Grains::List(list) = &mut pair.grains {
        list[0].omega = 150.0.into();
    }
    let cases = [
        ("collision", grainlab::scene::builtin::builtin("collision").unwrap()),
        ("oblique", grainlab::scene::builtin::builtin("oblique").unwrap()),
        ("oblique pair, spinning", pair),
    ];
    for (name, scene) in cases {
        let flat = { let mut s = scene.clone(); s.analysis = grainlab::scene::Analysis::None; s };
        let (mut a, mut b) = (plane(&flat), space(&lifted(&scene)));
        same_motion(name, &mut a, &mut b, 3000);
    }
}

/// A sheared packing lifted into space: the built-in shear cell's packed grains (the
/// first 150 above its bottom wall) as a list, between rough walls moving at +-0.5 m/s
/// under fixed control (a pressure acts on the wall's area, which in space is the cell's
/// x-z area, not the plane's depth), with gravity pulling them down: 20 000 steps of
/// packing and shear, the same to the bit with the total displacement and with YADE's
/// incremental force.
#[test]
fn a_plane_shear_lifted_into_space_moves_as_in_the_plane() {
    let source = grainlab::scene::builtin::builtin("shear").unwrap();
    let packed = plane(&source);
    let p = packed.engine.particles();
    let mut order: Vec<usize> = (0..p.n_free).collect();
    order.sort_by(|&i, &j| p.x[i].y.total_cmp(&p.x[j].y));
    let list: Vec<GrainSpec> = order[..150].iter().map(|&i| GrainSpec { x: [p.x[i].x, p.x[i].y].into(), v: [0.0, 0.0].into(), omega: 0.0.into(), r: p.r[i], material: 0 }).collect();
    let top = list.iter().map(|g| g.x[1] + g.r).fold(0.0, f64::max) + 0.5e-3;
    for tangential in [grainlab::scene::TangentialSpec::TotalDisplacement, grainlab::scene::TangentialSpec::IncrementalForce] {
        let mut s = source.clone();
        s.grains = Grains::List(list.clone());
        let walls = s.walls.as_mut().unwrap();
        walls.top.control = grainlab::scene::ControlSpec::Fixed;
        walls.top.y = Some(top);
        s.gravity = [0.0, -9.81].into();
        s.model.tangential = tangential;
        s.duration = 0.02;
        s.analysis = grainlab::scene::Analysis::None;
        let (mut a, mut b) = (plane(&s), space(&lifted(&s)));
        same_motion(tangential.name(), &mut a, &mut b, 20_000);
    }
}

/// Read a scene and return the refusal's text.
fn refused(json: &str) -> String {
    match Scene::from_json(json) {
        Ok(s) => match grainlab::build_in::<Space>(&s, 1, &limits()) {
            Ok(_) => panic!("accepted: {json}"),
            Err(e) => e.to_string(),
        },
        Err(e) => e.to_string(),
    }
}

/// What a 3D scene does not have yet is refused by name (its JSON path, its value and
/// what is allowed), and what only a 3D scene has is refused in 2D.
#[test]
fn what_space_lacks_is_refused_by_name() {
    let grains = r#""grains": {"list": [{"x": [0, 0, 0], "r": 0.001}, {"x": [0.003, 0, 0], "v": [-1, 0, 0], "r": 0.001}]}"#;
    let ts = r#""time_step": {"rule": {"steps_per_contact": {"steps": 50, "impact_speed": 1}}}, "duration": 1e-3"#;
    let pack = |extra: &str| format!(r#"{{"name": "p", "dimension": 3, "grains": {{"pack": {{"count": 50, "radius": {{"fixed": {{"radius": 0.0005}}}}, "x": [0, 0.01], "y_min": 0 {extra}}}}}, {ts}}}"#);
    let cases: Vec<(String, &[&str])> = vec![
        (format!(r#"{{"name": "a", "dimension": 3, "grain_shape": {{"disk": {{"thickness": 0.001}}}}, {grains}, {ts}}}"#), &["grain_shape.disk", "spheres"]),
        (format!(r#"{{"name": "a", "dimension": 3, "model": {{"rolling": "cdt"}}, {grains}, {ts}}}"#), &["model.rolling", "\"cdt\"", "3D"]),
        (format!(r#"{{"name": "a", "dimension": 3, "model": {{"tangential": "mindlin_deresiewicz"}}, {grains}, {ts}}}"#), &["model.tangential", "mindlin_deresiewicz"]),
        (format!(r#"{{"name": "a", "dimension": 3, "output": {{"contacts": true}}, {grains}, {ts}}}"#), &["output.contacts", "true"]),
        (format!(r#"{{"name": "a", "dimension": 3, "grains": {{"file": {{"path": "g.txt"}}}}, {ts}}}"#), &["grains.file.columns", "\"x y r\"", "\"x y z r\""]),
        (pack(""), &["grains.pack.z", "none"]),
        (pack(r#", "z": [0, 0.01]"#), &["grains.pack.packing_fraction", "0.75", "volume fraction"]),
        (pack(r#", "z": [0, 0.01], "packing_fraction": 0.5, "seed": 2"#).replace("\"dimension\": 3, ", "").replace("\"name\": \"p\"", "\"name\": \"p\", \"dimension\": 2"), &["grains.pack.z", "dimension"]),
        (format!(r#"{{"name": "a", "dimension": 7, {grains}, {ts}}}"#), &["dimension", "2 (the plane) or 3 (space)"]),
        (format!(r#"{{"name": "a", {grains}, {ts}}}"#), &["grains.list[0].x", "3 numbers", "dimension"]),
        (format!(r#"{{"name": "a", "grains": {{"list": [{{"x": [0, 0], "omega": [1, 2, 3], "r": 0.001}}]}}, {ts}}}"#), &["grains.list[0].omega", "dimension"]),
        (format!(r#"{{"name": "a", "domain": {{"periodic_z": [0, 1]}}, "grains": {{"list": [{{"x": [0, 0], "r": 0.001}}]}}, {ts}}}"#), &["domain.periodic_z", "dimension"]),
        (format!(r#"{{"name": "a", "gravity": [0, -9.81, 1], "grains": {{"list": [{{"x": [0, 0], "r": 0.001}}]}}, {ts}}}"#), &["gravity", "3 numbers"]),
        (format!(r#"{{"name": "a", "dimension": 3, "grains": {{"list": [{{"x": [0, 0, 0, 1], "r": 0.001}}]}}, {ts}}}"#), &["grains.list[0].x", "[x, y, z]"]),
    ];
    for (json, words) in cases {
        let e = refused(&json);
        for w in words {
            assert!(e.contains(w), "{json}\nrefused as: {e}\nmissing: {w}");
        }
    }
    // A plane build refuses a 3D scene, naming the dimension.
    let s = Scene::from_json(&format!(r#"{{"name": "a", "dimension": 3, {grains}, {ts}}}"#)).unwrap();
    let e = grainlab::build_limited(&s, 1, &limits()).err().unwrap().to_string();
    assert!(e.contains("dimension") && e.contains('3'), "{e}");
    // The exporters write a 3D scene's decks (src/workbench/export: spheres in space, each
    // grain's z in grains.data; what they cannot express is refused by name there).
    for code in [grainlab::workbench::export::Code::Liggghts, grainlab::workbench::export::Code::Yade, grainlab::workbench::export::Code::Lammps] {
        let files = grainlab::workbench::export::export_files(&s, code, false, &limits()).unwrap();
        assert!(files.iter().any(|(name, text)| *name == "export.json" && text.contains("\"dimension\": 3")), "{}", code.name());
    }
}

/// Two spheres meeting off centre in space, one spinning about a skew axis, as a scene
/// file: the run completes, its momentum is what it started with (no walls, no
/// gravity: bound 1e-12 of m |v|, rounding over the contact's few hundred steps) and its
/// energy balance closes (residual below 1e-3 of the energy at 50 steps per contact:
/// velocity Verlet's error over one impact at that step, measured 1.0e-4).
#[test]
fn a_3d_impact_from_its_scene_file_keeps_its_momentum() {
    let json = r#"{ "name": "pair3d", "dimension": 3,
      "grains": {"list": [ {"x": [0, 0, 0], "v": [0.5, 0.3, 0.4], "omega": [10, -20, 5], "r": 0.001},
                           {"x": [0.0025, 0.0015, 0.002], "v": [-0.5, -0.3, -0.4], "r": 0.001} ]},
      "time_step": {"rule": {"steps_per_contact": {"steps": 50, "impact_speed": 1.0}}},
      "duration": 0.004, "output": {"samples": 10, "frames": 0} }"#;
    let scene = Scene::from_json(json).unwrap();
    let mut b = space(&scene);
    let p0 = b.engine.particles().clone();
    let momentum = |p: &grainlab::physics::particles::Particles<Space>| (0..p.n_free).map(|i| p.v[i] * p.m[i]).fold(nalgebra::Vector3::zeros(), |a, b| a + b);
    let before = momentum(&p0);
    let mut touched = false;
    for _ in 0..31_000 {
        b.engine.advance(true).unwrap();
        touched |= b.engine.touching() > 0;
    }
    let p = b.engine.particles();
    let scale = p.m[0] * 1.0;
    assert!(touched, "the spheres met");
    assert!((momentum(p) - before).norm() < 1e-12 * scale, "momentum {:?} -> {:?}", before, momentum(p));
    // The contact turned the spheres' velocities out of their line of approach: each
    // moves along z differently from how it came.
    assert!((p.v[0] - p0.v[0]).norm() > 0.1, "the impact changed grain 0's velocity: {:?}", p.v[0]);
    let row = b.engine.energy_row();
    assert!(row.residual_j.abs() < 1e-3 * row.initial_j, "energy residual {} of {}", row.residual_j, row.initial_j);
    let summary = grainlab::run_scene(&scene, &RunOptions::default()).unwrap();
    assert_eq!(summary.status, "completed");
}

/// The summary of `scene`'s run (an impact scene's: it has one).
fn impact_of(scene: &Scene) -> grainlab::ImpactSummary {
    let s = grainlab::run_scene(scene, &RunOptions::default()).unwrap();
    assert_eq!(s.status, "completed", "{}", scene.name);
    s.impact.unwrap_or_else(|| panic!("{}: no impact measured ({:?})", scene.name, s.impact_note))
}

/// The impact observer in space measures an impact in its own plane: a plane impact
/// turned out of the x-y plane gives the plane's summary. The built-in 3D head-on impact
/// (along the skew line (2, 1, 2)/3) and oblique impact on a wall (its tangential
/// velocity along (3, 0, 4)/5) against the plane's built-in `collision` and `oblique`;
/// an oblique impact of a spinning sphere on a resting one, under YADE's incremental
/// law (its tangential force turned with the contact frame, twist included), turned
/// about a skew axis; the same impact lifted into space untouched. Bound: 1e-9 of each
/// quantity's scale (the turned positions and velocities differ from the plane's in their
/// last bits, and the contact's few hundred steps carry that; measured below 1e-11); in
/// space nothing leaves the impact's plane, to the same bound.
#[test]
fn impacts_turned_out_of_the_plane_measure_as_in_the_plane() {
    let glass = grainlab::physics::material::Material { restitution: 0.7, ..Default::default() };
    let mut pair = grainlab::scene::builtin::oblique_pair(glass, 1e-3, 1.0, 35.0, grainlab::scene::TangentialSpec::IncrementalForce, 100.0);
    if let Grains::List(list) = &mut pair.grains {
        list[0].omega = 150.0.into();
    }
    let mut lifted_pair = pair.clone();
    lifted_pair.dimension = Dimension::Three;
    let builtin = |n: &str| grainlab::scene::builtin::builtin(n).unwrap();
    let cases = [
        ("collision3d", builtin("collision"), builtin("collision3d")),
        ("oblique3d", builtin("oblique"), builtin("oblique3d")),
        ("turned spinning pair", pair.clone(), grainlab::scene::builtin::turned(&pair, [1.0, 2.0, 3.0], 0.7)),
        ("lifted spinning pair", pair.clone(), lifted_pair),
    ];
    for (name, a, b) in cases {
        let (p, q) = (impact_of(&a), impact_of(&b));
        let v = p.impact_speed_m_s;
        let pairs = [
            ("impact speed", p.impact_speed_m_s, q.impact_speed_m_s, v),
            ("normal restitution", p.restitution_normal, q.restitution_normal, 1.0),
            ("tangential restitution", p.restitution_tangential.unwrap_or(0.0), q.restitution_tangential.unwrap_or(0.0), 1.0),
            ("rebound tangential velocity", p.rebound_tangential_velocity_m_s, q.rebound_tangential_velocity_m_s, v),
            ("rebound normal velocity", p.rebound_normal_velocity_m_s, q.rebound_normal_velocity_m_s, v),
            ("rebound spin", p.rebound_spin_rad_s, q.rebound_spin_rad_s, v / 1e-3),
            ("max overlap", p.max_overlap_m, q.max_overlap_m, p.max_overlap_m),
            ("peak force", p.peak_force_n, q.peak_force_n, p.peak_force_n),
            ("contact time", p.contact_time_s, q.contact_time_s, p.contact_time_s),
        ];
        assert_eq!(p.restitution_tangential.is_some(), q.restitution_tangential.is_some(), "{name}: a tangential restitution in both or neither");
        for (what, x, y, scale) in pairs {
            assert!((x - y).abs() <= 1e-9 * scale, "{name}: {what} {x} in the plane, {y} in space");
        }
        assert!(q.momentum_error_rel < 1e-12, "{name}: momentum error {}", q.momentum_error_rel);
        // Nothing leaves the impact's plane: grain 0's velocity along b and its spin about
        // t and n are 0 to the same bound (the plane's summary has none of them).
        assert!(p.rebound_binormal_velocity_m_s.is_none() && p.rebound_spin_tangential_rad_s.is_none() && p.rebound_spin_normal_rad_s.is_none(), "{name}: out-of-plane values in the plane");
        let out = [(q.rebound_binormal_velocity_m_s, v), (q.rebound_spin_tangential_rad_s, v / 1e-3), (q.rebound_spin_normal_rad_s, v / 1e-3)];
        for (x, scale) in out {
            assert!(x.is_some_and(|x| x.abs() <= 1e-9 * scale), "{name}: out of the impact's plane {out:?}");
        }
        eprintln!("{name}: e_n {} / {}, spin {} / {}", p.restitution_normal, q.restitution_normal, p.rebound_spin_rad_s, q.rebound_spin_rad_s);
    }
}

/// `scene` cut to `duration` with `frames` frames: a short 3D run for the outputs' tests.
fn short(scene: &Scene, duration: f64, samples: u64, frames: u64) -> Scene {
    let mut s = scene.clone();
    s.duration = duration;
    s.output.samples = samples;
    s.output.frames = frames;
    s
}

/// A 3D run stopped at a checkpoint and resumed writes energy.csv, walls.csv and its
/// frames byte for byte as the run that never stopped (the conservation of bits is the
/// claim: tolerance zero).
#[test]
fn a_3d_run_resumes_bit_for_bit() {
    let scene = short(&grainlab::scene::builtin::builtin("shear3d").unwrap(), 4e-4, 40, 4);
    let whole = tempfile::tempdir().unwrap();
    let cut = tempfile::tempdir().unwrap();
    let built = space(&scene);
    let steps = (scene.duration / built.time_step.dt_s).round() as u64;
    let r = run_report(&scene, built, &RunOptions { out: Some(whole.path().to_path_buf()), ..RunOptions::default() }).unwrap();
    assert!(r.ending.is_none(), "{:?}", r.ending);
    let r = run_report(&scene, space(&scene), &RunOptions { out: Some(cut.path().to_path_buf()), stop_after_step: Some(steps / 3), ..RunOptions::default() }).unwrap();
    assert!(matches!(r.ending, Some(grainlab::Error::Interrupted { .. })), "{:?}", r.ending);
    let r = resume(cut.path(), Some(1), &RunOptions::default()).unwrap();
    assert!(r.ending.is_none(), "{:?}", r.ending);
    for name in ["energy.csv", "walls.csv", "grains.pvd"] {
        assert_eq!(std::fs::read(whole.path().join(name)).unwrap(), std::fs::read(cut.path().join(name)).unwrap(), "{name}");
    }
    let frames = |d: &std::path::Path| {
        let mut f: Vec<_> = std::fs::read_dir(d.join("frames")).unwrap().map(|e| e.unwrap().path()).collect();
        f.sort();
        f.iter().map(|p| std::fs::read(p).unwrap()).collect::<Vec<_>>()
    };
    assert_eq!(frames(whole.path()), frames(cut.path()));
}

/// The built-in 3D shear box (2000 spheres, periodic x and z, rough lattices at -+0.5
/// m/s, 100 kPa on the top wall) run from its scene for 4 ms (69 000 steps):
/// - the top wall's momentum balance: over the second half the grains' mean force on it
///   is the load p L_x L_z plus its mass times its change of velocity over that time;
///   the wall's speed stays far below the ratio of load to mass times 2 ms, so the mean
///   normal stress is the applied 100 kPa within 5% (measured 0.2%, its 95% interval
///   1.6%);
/// - the shear stress is positive (the grains drag the bottom wall along -x, the top
///   along +x: tau = (F_bottom,x - F_top,x) / 2A > 0) and below the Coulomb bound mu
///   sigma of the grains' friction 0.5 (no cohesion, no rolling resistance: a granular
///   packing's macroscopic friction is below its contacts');
/// - the energy balance closes within 1e-3 of the energy put in (50 steps per contact);
/// - the ParaView frames hold the spheres with 3 coordinates each, spread over the cell
///   in z; walls.csv and energy.csv have a row per sample;
/// - walls.csv's z forces are the walls' whole z impulse on the grains (periodic in z,
///   no z drive or gravity): their rows, each an average over every step of its
///   interval, integrate to minus the grains' z momentum in the last frame (the first
///   is at rest), within 1e-4 of the z impulse's scale (the sum of the rows' |F_z| times
///   their intervals): velocity Verlet's half kicks at the two ends and the frame's
///   pending half kick differ from the rows' sum by a few steps' forces (measured 6e-6
///   of the scale; the two agree to 0.2% of the momentum itself, 6.15e-6 kg m/s).
#[test]
fn a_3d_shear_box_carries_its_load_and_writes_its_outputs() {
    let scene = short(&grainlab::scene::builtin::builtin("shear3d").unwrap(), 4e-3, 80, 2);
    let dir = tempfile::tempdir().unwrap();
    let summary = grainlab::run_scene(&scene, &RunOptions { out: Some(dir.path().to_path_buf()), ..RunOptions::default() }).unwrap();
    assert_eq!(summary.status, "completed");
    let shear = summary.shear.expect("a shear analysis");
    let (sigma, tau) = (shear.normal_stress_pa.mean, shear.shear_stress_pa.mean);
    eprintln!("sigma {sigma:.4e} Pa +- {:.2e}, tau {tau:.4e} Pa, tau/sigma {:.3}, packing fraction {:?}", shear.normal_stress_pa.ci95, tau / sigma, shear.packing_fraction);
    assert!((sigma / 1e5 - 1.0).abs() < 0.05, "normal stress {sigma} Pa against the 100 kPa load");
    assert!(tau > 0.0 && tau < 0.5 * sigma, "shear stress {tau} Pa under {sigma} Pa");
    let energy = summary.energy.expect("the ledger is on");
    assert!(energy.max_residual_rel < 1e-3, "energy residual {}", energy.max_residual_rel);
    let rows = |name: &str| std::fs::read_to_string(dir.path().join(name)).unwrap().lines().count() - 1;
    assert!(rows("walls.csv") >= 80 && rows("energy.csv") >= 81, "walls {} rows, energy {} rows", rows("walls.csv"), rows("energy.csv"));
    let last = common::read_vtp(&dir.path().join("frames/grains_00002.vtp"));
    let n = summary.grains + 200;
    assert_eq!(last["position_m"].len(), 3 * n, "every sphere, free and glued, with x, y, z");
    let z: Vec<f64> = last["position_m"].chunks(3).map(|c| c[2]).collect();
    assert!(z.iter().all(|z| (0.0..=0.01).contains(z)) && z.iter().any(|&z| z < 2e-3) && z.iter().any(|&z| z > 8e-3), "the spheres fill the cell in z");
    assert_eq!(last["spin_rad_s"].len(), 3 * n);
    // The z momentum of the spheres (glass, 2500 kg/m^3; the glued ones at rest along z).
    let pz: f64 = last["radius_m"].iter().zip(last["velocity_m_s"].chunks(3)).map(|(r, v)| 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3) * v[2]).sum();
    let walls = std::fs::read_to_string(dir.path().join("walls.csv")).unwrap();
    let mut lines = walls.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("walls.csv has no {name}: {header:?}"));
    let (t, bz, tz) = (col("time_s"), col("bottom_fz_n"), col("top_fz_n"));
    let (mut impulse, mut scale, mut t0) = (0.0, 0.0, 0.0);
    for l in lines {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap_or(f64::NAN)).collect();
        impulse -= (v[bz] + v[tz]) * (v[t] - t0);
        scale += (v[bz].abs() + v[tz].abs()) * (v[t] - t0);
        t0 = v[t];
    }
    eprintln!("z momentum {pz:e} kg m/s, the walls' z impulse on the grains {impulse:e} N s (scale {scale:e})");
    assert!(scale > 0.0 && (pz - impulse).abs() < 1e-4 * scale, "z momentum {pz:e} against the walls' z impulse {impulse:e} (scale {scale:e})");
}

/// A 3D scene's contact forces run on one thread: more is refused by name, not run
/// serially under a provenance that says otherwise.
#[test]
fn a_3d_scene_on_more_threads_is_refused_by_name() {
    let scene = grainlab::scene::builtin::builtin("shear3d").unwrap();
    let e = grainlab::build_in::<Space>(&scene, 2, &limits()).err().expect("refused").to_string();
    assert!(e.contains("--threads") && e.contains('2'), "{e}");
}

/// A periodic cell along z must hold its grains and be at least two diameters of the
/// largest long (a grain must not meet its own image), and hold a rough wall's glued
/// sphere: refused by name otherwise.
#[test]
fn a_periodic_z_too_short_or_missing_grains_is_refused_by_name() {
    let ts = r#""time_step": {"rule": {"steps_per_contact": {"steps": 50, "impact_speed": 1}}}, "duration": 1e-3"#;
    let grains = r#""grains": {"list": [{"x": [0, 0, 0.001], "r": 0.001}, {"x": [0.003, 0, 0.001], "v": [-1, 0, 0], "r": 0.001}]}"#;
    let e = refused(&format!(r#"{{"name": "a", "dimension": 3, "domain": {{"periodic_z": [0, 0.003]}}, {grains}, {ts}}}"#));
    assert!(e.contains("domain.periodic_z") && e.contains("4 r_max"), "{e}");
    let e = refused(&format!(r#"{{"name": "a", "dimension": 3, "domain": {{"periodic_z": [0.002, 0.01]}}, {grains}, {ts}}}"#));
    assert!(e.contains("domain.periodic_z") && e.contains("z = 0.001 m"), "{e}");
    let mut s = grainlab::scene::builtin::builtin("shear3d").unwrap();
    s.domain.periodic_z = Some([0.0, 0.0008]);
    if let Grains::Pack(p) = &mut s.grains {
        p.z = Some([0.0, 0.0008]);
    }
    s.walls.as_mut().unwrap().bottom.surface = grainlab::scene::SurfaceSpec::Rough { radius: 0.5e-3 };
    let e = s.validate().err().expect("refused").to_string();
    assert!(e.contains("walls.bottom.surface.rough.radius") && e.contains("along z"), "{e}");
}

/// A 3D scene's grains read from a file in `"x y z r"` columns are the spheres its list
/// would give: the built-in shear box's relaxed packing written to a file (Rust's
/// shortest round-trip decimals) and listed in the scene runs, 300 steps with its walls
/// sheared and loaded, to the same bits as the same spheres listed (the same numbers by
/// two routes: tolerance zero). The file's z is the sphere's: the spheres spread over
/// the cell along z (over half its 5 mm), which a reader that dropped z would have put
/// on top of each other (refused as overlapping). The exported decks' grains.data are
/// the listed scene's. A plane file's `"x y r"` is refused in space by name.
#[test]
fn a_3d_grain_file_gives_the_spheres_its_list_gives() {
    let base = grainlab::scene::builtin::shear_box(200, 0.005);
    let packed = space(&base);
    let p = packed.engine.particles();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("spheres.txt");
    let mut text = String::from("# x y z r, m\n");
    let mut list = Vec::new();
    for i in 0..p.n_free {
        let (x, r) = (p.x[i], p.r[i]);
        text.push_str(&format!("{} {} {} {}\n", x[0], x[1], x[2], r));
        list.push(serde_json::json!({"x": [x[0], x[1], x[2]], "r": r}));
    }
    std::fs::write(&file, text).unwrap();
    let (z_lo, z_hi) = (0..p.n_free).map(|i| p.x[i][2]).fold((f64::MAX, f64::MIN), |(a, b), z| (a.min(z), b.max(z)));
    assert!(z_hi - z_lo > 0.5 * 0.005, "the packing's z spread {z_lo}..{z_hi} m");
    let with = |grains: serde_json::Value| {
        let mut v: serde_json::Value = serde_json::from_str(&base.to_json()).unwrap();
        v["grains"] = grains;
        Scene::from_json(&v.to_string()).unwrap()
    };
    let filed = with(serde_json::json!({"file": {"path": file.to_str().unwrap(), "columns": "x y z r"}}));
    // The list from values, not from text: serde_json's default parse of a decimal can
    // be a unit in the last place off (its `float_roundtrip` feature reads exactly), Rust's
    // `str::parse`, the file's, is exact.
    let mut listed = filed.clone();
    listed.grains = serde_json::from_value(serde_json::json!({"list": list})).unwrap();
    let (mut a, mut b) = (space(&listed), space(&filed));
    assert_eq!(a.engine.particles().len(), b.engine.particles().len());
    for _ in 0..300 {
        a.engine.advance(true).unwrap();
        b.engine.advance(true).unwrap();
    }
    let (pa, pb) = (a.engine.particles(), b.engine.particles());
    assert!(b.engine.touching() > 0, "the spheres touch");
    for i in 0..pa.len() {
        assert_eq!((pa.x[i], pa.v[i], pa.omega[i]), (pb.x[i], pb.v[i], pb.omega[i]), "grain {i}");
    }
    // The exporters write the file's spheres as they write the listed ones.
    for code in [grainlab::workbench::export::Code::Liggghts, grainlab::workbench::export::Code::Yade, grainlab::workbench::export::Code::Lammps] {
        let data = |s: &Scene| grainlab::workbench::export::export_files(s, code, false, &limits()).unwrap().into_iter().find(|(name, _)| *name == "grains.data").map(|(_, text)| text);
        let (from_list, from_file) = (data(&listed), data(&filed));
        assert!(from_list.is_some(), "{}: grains.data", code.name());
        assert_eq!(from_list, from_file, "{}: grains.data", code.name());
    }
    let mut plane_cols = serde_json::to_value(&filed).unwrap();
    plane_cols["grains"]["file"]["columns"] = "x y r".into();
    let e = refused(&plane_cols.to_string());
    for w in ["grains.file.columns", "\"x y r\"", "\"x y z r\" in a 3D scene"] {
        assert!(e.contains(w), "refused as: {e}\nmissing: {w}");
    }
}
