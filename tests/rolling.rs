//! Rolling resistance (`model.rolling`, `materials[].rolling_friction`) against closed
//! forms (src/physics/contact/rolling.rs).
//!
//! **A grain rolling on a plane.** A grain of mass m, radius r and moment of inertia I
//! rolls without slipping on a flat wall under gravity g with speed v (spin w = -v/r).
//! The rolling torque `M = mu_r r m g` (R* = r on a wall, Fn = m g at rest on it)
//! opposes the spin; the friction force F at the contact keeps the rolling:
//! `m v' = F`, `I w' = r F + M`, `v' = -r w'`, so `v' = -mu_r g / (1 + I/(m r^2))`:
//! the grain decelerates uniformly, at `mu_r g / 1.4` for a sphere in the plane and
//! `mu_r g / 1.5` for a disk, and stops at `t = v0 / |v'|` (it keeps rolling as long
//! as `|F| = m |v'| < mu m g`). CDT's torque is `mu_r r kn dn`, the elastic force kn dn
//! = m g at rest; EPSD2's and SDS's springs reach their cap `mu_r r |Fn|` within a few
//! contact times and slide there while the grain rolls.

use grainlab::physics::dim::GrainShape;
use grainlab::physics::material::{Material, PairMaterial};
use grainlab::scene::builtin::on_rigid_plane;
use grainlab::scene::{Analysis, GrainSpec, Grains, RollingSpec, TangentialSpec};

const R: f64 = 1e-3;
const G: f64 = 9.81;
const MU_R: f64 = 0.1;

/// A glass grain of `shape` resting on a rigid plane (at its static Hertz overlap under
/// gravity), rolling at `v0` (m/s) along +x with rolling resistance `law`: the scene,
/// its grain's mass and moment of inertia.
fn rolling_grain(law: RollingSpec, shape: GrainShape, v0: f64, duration: f64) -> (grainlab::Scene, f64, f64) {
    let grain = Material { restitution: 0.5, rolling_friction: MU_R, ..Material::default() };
    let mut s = on_rigid_plane(grain.clone(), shape, R, 0.05, 0.0, 0.0, 50.0, TangentialSpec::TotalDisplacement);
    let m = shape.mass(R, grain.density);
    let e_star = PairMaterial::mix(&grain, &s.materials[1]).e_star;
    let dn = (m * G / (4.0 / 3.0 * e_star * R.sqrt())).powf(2.0 / 3.0);
    s.grains = Grains::List(vec![GrainSpec { x: [0.0, R - dn].into(), v: [v0, 0.0].into(), omega: (-v0 / R).into(), r: R, material: 0 }]);
    s.gravity = [0.0, -G].into();
    s.model.rolling = law;
    s.analysis = Analysis::None;
    s.duration = duration;
    (s, m, shape.inertia(R, m))
}

/// The grain's velocity and spin at times `at` (s).
fn track(s: &grainlab::Scene, at: &[f64]) -> Vec<(f64, f64)> {
    let built = grainlab::build(s).expect("the scene builds");
    let mut engine = built.engine;
    let dt = engine.dt();
    let mut out = Vec::new();
    let mut step = 0u64;
    for &t in at {
        let target = (t / dt).round() as u64;
        while step < target {
            engine.step().expect("the run goes on");
            step += 1;
        }
        let p = engine.particles();
        out.push((p.v[0].x, p.omega[0]));
    }
    out
}

#[test]
fn a_grain_rolling_on_a_plane_decelerates_as_the_closed_form_says() {
    let v0 = 0.01;
    for law in [RollingSpec::Cdt, RollingSpec::Epsd2, RollingSpec::Sds { stiffness: 1e5, damping: 0.0 }] {
        for shape in [GrainShape::SphereInPlane, GrainShape::Disk { thickness: 1e-3 }] {
            let (s, m, i) = rolling_grain(law, shape, v0, 0.02);
            let a = MU_R * G / (1.0 + i / (m * R * R));
            // Between 0.1 and 0.8 of the time to stop: the speed falls linearly.
            let t_stop = v0 / a;
            let (t1, t2) = (0.1 * t_stop, 0.8 * t_stop);
            let vs = track(&s, &[t1, t2]);
            let measured = (vs[0].0 - vs[1].0) / (t2 - t1);
            println!("{law:?} {shape:?}: deceleration {measured} m/s^2, closed form {a}, rel {:e}", (measured - a).abs() / a);
            // Rolling without slipping at both times.
            for &(v, w) in &vs {
                assert!((v + w * R).abs() < 1e-3 * v0, "{law:?} {shape:?}: slips (v = {v}, w r = {})", w * R);
            }
            // Within 1e-4: the start's transients (the springs loading, the normal
            // force settling from the closed-form static overlap) shift the speed by a
            // little; measured 1.5e-5 (sphere), 3.3e-6 (disk), every law alike.
            assert!((measured - a).abs() <= 1e-4 * a, "{law:?} {shape:?}: deceleration {measured} m/s^2, closed form {a}");
        }
    }
}

#[test]
fn the_energy_balance_closes_with_rolling_resistance_in_the_shear_cell() {
    // The rolling torques' work, M (w_i - w_j) dt by the trapezoid rule like every other
    // term, enters the ledger as `dissipated_rolling_j`: the balance closes within 1e-3
    // of the energy put in (tests/shear.rs' bound), and the rolling term is a real share
    // of the dissipation (mu_r = 0.1). Measured (1 ms of the shear cell, t_c/50):
    // residual 9.3e-5 (CDT), 9.6e-5 (EPSD2), 9.1e-5 (SDS) against 1.3e-4 without
    // rolling resistance; the rolling torques take 36-37% of the dissipation.
    use grainlab::study::run::{RunOptions, run_scene};
    for law in [RollingSpec::Cdt, RollingSpec::Epsd2, RollingSpec::Sds { stiffness: 1e5, damping: 1e-3 }] {
        let mut s = grainlab::scene::builtin::shear();
        s.duration = 1e-3;
        s.output.frames = 0;
        s.model.rolling = law;
        for m in &mut s.materials {
            m.rolling_friction = MU_R;
        }
        let out = run_scene(&s, &RunOptions::default()).unwrap();
        assert!(out.model.contains("rolling"), "{}", out.model);
        let en = out.energy.unwrap();
        let row = en.final_row;
        println!("{law:?}: residual {:e} of the input; rolling {:e} J of {:e} J dissipated", en.max_residual_rel, row.dissipated_rolling_j, row.dissipated());
        assert!(en.max_residual_rel < 1e-3, "{law:?}: residual {:e}", en.max_residual_rel);
        assert!(row.dissipated_rolling_j > 1e-3 * row.dissipated(), "{law:?}: rolling took {:e} J of {:e} J", row.dissipated_rolling_j, row.dissipated());
    }
}

#[test]
fn rolling_resistance_is_refused_where_it_is_not_compiled_and_by_the_codes_without_it() {
    use grainlab::workbench::export::{Code, export_files};
    let (mut s, _, _) = rolling_grain(RollingSpec::Epsd2, GrainShape::SphereInPlane, 0.01, 1e-3);
    s.gravity = [0.0, 0.0].into();
    let refusal = |s: &grainlab::Scene, code: Code| export_files(s, code, false, &Default::default()).err().map(|e| e.to_string());
    // LIGGGHTS has CDT and EPSD2, LAMMPS SDS, YADE none: each refuses the others by name.
    assert_eq!(refusal(&s, Code::Liggghts), None);
    for code in [Code::Lammps, Code::Yade] {
        let e = refusal(&s, code).expect("refused");
        assert!(e.contains(&format!("export to {}: model.rolling = \"epsd2\" cannot be expressed", code.name())), "{e}");
    }
    s.model.rolling = RollingSpec::Sds { stiffness: 1e5, damping: 0.0 };
    assert_eq!(refusal(&s, Code::Lammps), None);
    assert!(refusal(&s, Code::Liggghts).expect("refused").contains("model.rolling = \"sds\""));
    // Validation: the compiled combinations, and the SDS parameters' ranges.
    for (what, change) in [
        ("incremental_force", Box::new(|s: &mut grainlab::Scene| s.model.tangential = TangentialSpec::IncrementalForce) as Box<dyn Fn(&mut grainlab::Scene)>),
        ("tsuji", Box::new(|s: &mut grainlab::Scene| s.model.damping = grainlab::scene::DampingSpec::Tsuji)),
        ("rotation", Box::new(|s: &mut grainlab::Scene| s.model.rotation = false)),
        ("work_of_adhesion", Box::new(|s: &mut grainlab::Scene| s.materials[0].work_of_adhesion = 1.0)),
    ] {
        let mut t = s.clone();
        change(&mut t);
        let e = grainlab::Scene::from_json(&t.to_json()).expect_err("not compiled").to_string();
        assert!(e.contains("model.rolling") && e.contains(what), "{e}");
    }
    s.model.rolling = RollingSpec::Sds { stiffness: 0.0, damping: 0.0 };
    let e = grainlab::Scene::from_json(&s.to_json()).expect_err("k = 0").to_string();
    assert!(e.contains("model.rolling.sds.stiffness") && e.contains("> 0 N/m"), "{e}");
    s.model.rolling = RollingSpec::Epsd2;
    s.materials[0].rolling_friction = -0.1;
    let e = grainlab::Scene::from_json(&s.to_json()).expect_err("negative").to_string();
    assert!(e.contains("materials[0].rolling_friction") && e.contains(">= 0"), "{e}");
}
