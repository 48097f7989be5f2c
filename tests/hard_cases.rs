//! Hard cases that must stay numerically stable: extreme speeds and restitutions,
//! grazing and rolling contacts, wide size distributions, high confinement, periodic
//! contacts, and time steps at and beyond the stability limit. Each asserts no NaN, no
//! energy created beyond the integrator's error, Coulomb's law, and bounded overlaps,
//! with the reason for each bound.

use grainlab::physics::contact::LeverArm;
use grainlab::physics::dim::Vec2;
use grainlab::error::Error;
use grainlab::physics::material::{Material, PairMaterial, hertz_max_overlap};
use grainlab::observe::impact::ImpactSummary;
use grainlab::scene::pack::RadiusDist;
use grainlab::output::summary::Summary;
use grainlab::study::run::{RunOptions, run_scene};
use grainlab::scene::*;
use grainlab::scene::builtin::{head_on, oblique, shear};
use grainlab::{Engine, build};

const R: f64 = 1e-3;

fn glass(e: f64) -> Material {
    Material { restitution: e, ..Material::default() }
}

fn run(s: &Scene) -> Summary {
    run_scene(s, &RunOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", s.name))
}

fn impact(s: &Scene) -> ImpactSummary {
    let out = run(s);
    let i = out.impact.expect("the grains touched and separated");
    for v in [i.restitution_normal, i.max_overlap_m, i.peak_force_n, i.contact_time_s, i.rebound_spin_rad_s] {
        assert!(v.is_finite(), "{}: {i:?}", s.name);
    }
    i
}

#[test]
fn a_50_m_s_glass_impact_is_hertzian_and_scale_free() {
    // At 50 m/s the Hertz overlap is 4.6% of the radius (under the 10% watchdog bound);
    // with dt scaled by t_c the discrete problem is the same at every speed, so the
    // realised restitution equals the 1 m/s value to rounding (1e-9), and the peak
    // overlap matches closed form like at 1 m/s (0.5% at t_c/200, as in impacts.rs).
    let g = glass(1.0);
    let (m, e) = (4.0 / 3.0 * std::f64::consts::PI * R.powi(3) * g.density, PairMaterial::mix(&g, &g).e_star);
    let fast = impact(&head_on(glass(1.0), R, 50.0, 200.0));
    let dmax = hertz_max_overlap(m / 2.0, R / 2.0, e, 50.0);
    assert!(dmax / R < 0.1 && fast.max_overlap_m / R < 0.1);
    assert!((fast.max_overlap_m - dmax).abs() / dmax < 5e-3, "{} vs {dmax}", fast.max_overlap_m);
    let damped_fast = impact(&head_on(glass(0.5), R, 50.0, 50.0));
    let damped_slow = impact(&head_on(glass(0.5), R, 1.0, 50.0));
    assert!((damped_fast.restitution_normal - damped_slow.restitution_normal).abs() < 1e-9);
    assert!(damped_fast.momentum_error_rel < 1e-12);
}

#[test]
fn extreme_restitutions_stay_physical() {
    // e = 0.05: heavy damping (gn close to critical at small overlaps). Without the clamp
    // the realised e converges to the input at first order in dt/t_c; at t_c/500 within
    // 5e-3 (the envelope C dt/t_c with C = 2.5 measured for e = 0.05 from t_c/50 to
    // t_c/2000 is steeper than at e = 0.5 because the damping is). The energy balance
    // closes to 1e-4 (O(dt^2)). e = 1: kinetic energy comes back to 1e-4 at t_c/50.
    for (e, steps, tol) in [(0.05, 500.0, 5e-3), (0.05, 2000.0, 1.25e-3)] {
        let s = head_on(glass(e), R, 1.0, steps);
        let out = run(&s);
        let i = out.impact.unwrap();
        assert!((i.restitution_normal - e).abs() < tol, "e = {e} at t_c/{steps}: {}", i.restitution_normal);
        assert!(out.energy.unwrap().max_residual_rel < 1e-4);
    }
    let i = impact(&head_on(glass(1.0), R, 1.0, 50.0));
    assert!((i.restitution_normal.powi(2) - 1.0).abs() < 1e-4, "{}", i.restitution_normal);
}

#[test]
fn near_grazing_impact_slides_throughout_and_obeys_coulomb_exactly() {
    // At 89 degrees tan(89) = 57 > (7/2) mu (1 + e): the contact slides from the first
    // step to the last, so the tangential impulse is exactly mu times the normal impulse
    // (with the clamp, Fn >= 0 throughout): |dv_t| = mu (v_n,in + v_n,out) to rounding.
    for tangential in [TangentialSpec::TotalDisplacement, TangentialSpec::IncrementalForce] {
        let mut s = oblique(glass(0.9), R, 1.0, 89.0, tangential, 200.0);
        s.model.limit_force = true;
        let i = impact(&s);
        let a = 89f64.to_radians();
        let (vn_in, vt_in) = (a.cos(), a.sin());
        let vn_out = i.rebound_normal_velocity_m_s;
        let dvt = vt_in - i.rebound_tangential_velocity_m_s;
        let mu = 0.5;
        assert!((dvt - mu * (vn_in + vn_out)).abs() < 1e-9 * vt_in, "{tangential:?}: dvt {dvt} vs {}", mu * (vn_in + vn_out));
        // The spin the friction gave: I dw = r dp_t.
        let spin = 5.0 / 2.0 * dvt / R;
        assert!((i.rebound_spin_rad_s.abs() - spin).abs() < 1e-3 * spin, "{} vs {spin}", i.rebound_spin_rad_s);
    }
}

/// A grain of radius R at rest in its static overlap on a flat wall under gravity, sliding at v0.
fn sliding_grain(tangential: TangentialSpec, v0: f64, duration: f64) -> Scene {
    let g = 9.81;
    let mat = glass(0.5);
    let m = 4.0 / 3.0 * std::f64::consts::PI * R.powi(3) * mat.density;
    let e = PairMaterial::mix(&mat, &mat).e_star;
    let dn = (3.0 * m * g / (4.0 * e * R.sqrt())).powf(2.0 / 3.0);
    let mut s = oblique(mat, R, 1.0, 0.0, tangential, 50.0);
    s.name = "rolling".into();
    s.grains = Grains::List(vec![GrainSpec { x: [0.0, R - dn].into(), v: [v0, 0.0].into(), omega: 0.0.into(), r: R, material: 0 }]);
    s.gravity = [0.0, -g].into();
    s.duration = duration;
    s.analysis = Analysis::None;
    s.model.lever_arm = LeverArm::RadiusMinusHalfOverlap;
    s
}

#[test]
fn sliding_turns_into_rolling_at_five_sevenths_and_keeps_rolling() {
    // A sphere sliding at v0 with no spin: friction mu m g slows it and spins it up until
    // v = w r, at v = 5/7 v0 after t* = 2 v0 / (7 mu g) (closed form, I = 2/5 m r^2).
    // Checked within 1e-3 (the contact's tangential spring and the lever r - dn/2 with
    // dn/r ~ 1e-6 perturb it far less); then 10 t* of rolling with tangential history: the
    // speed stays 5/7 v0 to 1e-3 and the spring does not wind up. Coulomb at every step:
    // |Ft| <= mu Fn (to 1e-6 relative: while sliding Ft is the cap, and while rolling the
    // damping term acts on a vanishing slip velocity).
    let (v0, mu, g) = (0.1, 0.5, 9.81);
    let t_star = 2.0 * v0 / (7.0 * mu * g);
    for tangential in [TangentialSpec::TotalDisplacement, TangentialSpec::IncrementalForce] {
        let s = sliding_grain(tangential, v0, 11.0 * t_star);
        let mut b = build(&s).unwrap();
        let e = b.engine.as_mut();
        let total = (s.duration / e.dt()).ceil() as u64;
        let m = e.particles().m[0];
        let mut worst: f64 = 0.0;
        let mut at_t_star = f64::NAN;
        for k in 1..=total {
            e.step().unwrap();
            let p = e.particles();
            let f = p.f[0] - m * Vec2::new(0.0, -g);
            assert!(f.x.is_finite() && f.y > 0.0, "{tangential:?} step {k}: contact lost or NaN: {f:?}");
            worst = worst.max(f.x.abs() / (mu * f.y));
            if at_t_star.is_nan() && e.time() >= 1.2 * t_star {
                at_t_star = p.v[0].x;
            }
        }
        let p = e.particles();
        assert!(worst <= 1.0 + 1e-6, "{tangential:?}: |Ft|/(mu Fn) reached {worst}");
        assert!((at_t_star - 5.0 / 7.0 * v0).abs() < 1e-3 * v0, "{tangential:?}: {at_t_star} after t*");
        assert!((p.v[0].x - 5.0 / 7.0 * v0).abs() < 1e-3 * v0, "{tangential:?}: {} after rolling", p.v[0].x);
        assert!((p.omega[0] * R + p.v[0].x).abs() < 1e-3 * v0, "{tangential:?}: not rolling: w r = {}", p.omega[0] * R);
        let en = e.energy_row();
        assert!(en.residual_j.abs() < 1e-3 * en.put_in(), "{tangential:?}: {en:?}");
    }
}

fn short_shear(duration: f64) -> Scene {
    let mut s = shear();
    s.duration = duration;
    s.output.frames = 0;
    s
}

fn assert_stable(out: &Summary, what: &str) {
    // The watchdog stops a run at an overlap of 10% of the smaller radius or a non-finite
    // state: completing means neither happened. The balance closes to 1e-3 of the energy
    // put in (the bound of tests/shear.rs, the integrator's O(dt^2) error at t_c/50).
    assert_eq!(out.status, "completed", "{what}: {:?}", out.error);
    let en = out.energy.as_ref().unwrap();
    assert!(en.max_residual_rel < 1e-3, "{what}: residual {}", en.max_residual_rel);
    let s = out.shear.as_ref().unwrap();
    assert!(s.shear_stress_pa.mean.is_finite() && s.normal_stress_pa.mean.is_finite(), "{what}");
}

#[test]
fn a_size_ratio_of_ten_shears_stably() {
    // Radii from 0.1 to 1 mm: dt follows the smallest grains (t_c/50 at 0.5 m/s), the cell
    // list is sized for the largest.
    let mut s = short_shear(5e-4);
    if let Grains::Pack(p) = &mut s.grains {
        p.count = 400;
        p.radius = RadiusDist::Uniform { min: 0.1e-3, max: 1.0e-3 };
    }
    assert_stable(&run(&s), "size ratio 10");
}

#[test]
fn ten_times_the_confining_stress_shears_stably() {
    // 1 MPa instead of 0.1 MPa: overlaps grow by 10^(2/3) ~ 4.6x and stay well under 10%
    // of a radius; the wall stress settles towards the load.
    let mut s = short_shear(2e-3);
    if let Some(w) = &mut s.walls {
        w.top.control = ControlSpec::Pressure(1e6);
    }
    assert_stable(&run(&s), "1 MPa");
}

#[test]
fn grains_collide_across_the_periodic_boundary_as_anywhere_else() {
    // The same head-on impact placed across x = 0 of a periodic cell [0, 0.01): the
    // minimum image makes it the same problem. Positions near 0.01 m round at 1e-18 m
    // instead of 1e-19 m, on overlaps of 1e-6 m: results agree to 1e-9, not bit for bit.
    let plain = head_on(glass(0.5), R, 1.0, 200.0);
    let mut wrapped = plain.clone();
    wrapped.domain.periodic_x = Some([0.0, 0.01]);
    if let Grains::List(g) = &mut wrapped.grains {
        for grain in g.iter_mut() {
            grain.x[0] = grain.x[0].rem_euclid(0.01);
        }
    }
    let (a, b) = (impact(&plain), impact(&wrapped));
    assert!((a.restitution_normal - b.restitution_normal).abs() < 1e-9, "{} vs {}", a.restitution_normal, b.restitution_normal);
    assert!((a.peak_force_n - b.peak_force_n).abs() < 1e-9 * a.peak_force_n);
    assert!(b.momentum_error_rel < 1e-12);
}

#[test]
fn time_steps_at_and_beyond_the_stability_limit() {
    // Just under the limit the run completes and conserves energy; just over it the scene
    // is refused with an error naming time_step dt and the limit; forced far beyond it,
    // the run stops with a diagnosis naming the step and the grains, never NaN output.
    let base = head_on(glass(1.0), R, 1.0, 200.0);
    let limit = build(&base).unwrap().time_step.stability_limit_s;
    let with_dt = |dt: f64, force: bool| {
        let mut s = base.clone();
        s.time_step.rule = TimeStepRule::Fixed { dt };
        s.time_step.characteristic_speed = Some(1.0);
        s.time_step.allow_unstable = force;
        s
    };
    let edge = impact(&with_dt(0.95 * limit, false));
    assert!((edge.restitution_normal.powi(2) - 1.0).abs() < 0.05, "{}", edge.restitution_normal);
    match run_scene(&with_dt(1.05 * limit, false), &RunOptions::default()) {
        Err(Error::Invalid { field, allowed, .. }) => {
            assert!(field.contains("dt") && allowed.contains("stability limit"), "{field}: {allowed}");
        }
        other => panic!("expected a refusal, got {other:?}"),
    }
    let dir = tempfile::tempdir().unwrap();
    let opts = RunOptions { out: Some(dir.path().to_path_buf()), ..RunOptions::default() };
    match run_scene(&with_dt(20.0 * limit, true), &opts) {
        Err(e @ Error::Unstable { .. }) => {
            let msg = e.to_string();
            assert!(msg.contains("step") && msg.contains("grain"), "{msg}");
            let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap()).unwrap();
            assert_eq!(summary["status"], "stopped");
        }
        other => panic!("expected a stopped run, got {other:?}"),
    }
}

#[test]
fn general_damping_dissipates_and_the_balance_still_closes() {
    // The seed's general damping (F = -c m v, M = -c I w) takes energy out of a sliding
    // grain; its dissipation is a term of the balance, which still closes to 1e-3 (the
    // bound of the shear tests: trapezoid integrals, O(dt^2)).
    let mut s = sliding_grain(TangentialSpec::TotalDisplacement, 0.1, 2e-3);
    s.model.general_damping = Some(50.0);
    s.output.energy = true;
    let out = run(&s);
    let en = out.energy.unwrap();
    assert!(en.final_row.dissipated_general_damping_j > 0.0, "{:?}", en.final_row);
    assert!(en.max_residual_rel < 1e-3, "{}", en.max_residual_rel);
    let e: &dyn Engine = &*build(&s).unwrap().engine;
    assert!(e.stage_names().iter().any(|n| n.starts_with("GeneralDamping")));
}

/// The shear cell for `ms` milliseconds with a tangential formulation at t_c/`steps`.
fn shear_at(tangential: TangentialSpec, steps: f64, ms: f64) -> Summary {
    let mut s = short_shear(ms * 1e-3);
    s.model.tangential = tangential;
    s.time_step.rule = TimeStepRule::StepsPerContact { steps, impact_speed: 0.5 };
    s.time_step.allow_unstable = true;
    run(&s)
}

#[test]
fn the_seeds_energy_growth_comes_from_the_tangential_springs_at_coarse_steps() {
    // The seed's shear cell gained energy. The balance shows where from: the tangential
    // model work W_t (the energy the tangential springs gain as kt(dn) and the contact
    // frame change under them). It is first order in dt for both formulations: in 3 ms
    // of shear it is 0.2-0.3 of the external input at t_c/50 (the default) and more than
    // 3x that at t_c/8, where the run warns; the balance closes either way (1e-2 at t_c/8,
    // 1e-3 at t_c/50: the integrator's error is O(dt^2)), so the growth is real model
    // energy, not a bookkeeping error, and finer steps remove it.
    for tangential in [TangentialSpec::TotalDisplacement, TangentialSpec::IncrementalForce] {
        let fine = shear_at(tangential, 50.0, 3.0);
        let coarse = shear_at(tangential, 8.0, 3.0);
        let (f, c) = (fine.energy.as_ref().unwrap(), coarse.energy.as_ref().unwrap());
        assert!(f.tangential_work_share < 0.4 && f.warning.is_none(), "{tangential:?} t_c/50: {}", f.tangential_work_share);
        assert!(c.tangential_work_share > 3.0 * f.tangential_work_share, "{tangential:?}: {} vs {}", c.tangential_work_share, f.tangential_work_share);
        assert!(c.tangential_work_share > 0.5 && c.warning.is_some(), "{tangential:?} t_c/8: {}", c.tangential_work_share);
        assert!(f.max_residual_rel < 1e-3 && c.max_residual_rel < 1e-2, "{tangential:?}: {} {}", f.max_residual_rel, c.max_residual_rel);
    }
}

#[test]
fn general_damping_takes_out_the_energy_the_coarse_springs_put_in() {
    // At t_c/8 with the seed's general damping (c = 2000 1/s, an e-folding time of 0.5 ms
    // against a shear time of L/(2V) = 40 ms) the dissipation by the damping is of the
    // order of the tangential work, and the balance still closes to 1e-2 (the t_c/8 bound
    // above).
    let mut s = short_shear(3e-3);
    s.time_step.rule = TimeStepRule::StepsPerContact { steps: 8.0, impact_speed: 0.5 };
    s.time_step.allow_unstable = true;
    s.model.general_damping = Some(2000.0);
    let out = run(&s);
    let en = out.energy.unwrap();
    assert!(en.final_row.dissipated_general_damping_j > 0.1 * en.final_row.tangential_model_work_j, "{:?}", en.final_row);
    assert!(en.max_residual_rel < 1e-2, "{}", en.max_residual_rel);
}

// Longer runs of the same cases: `scripts/hard-cases` runs them (cargo test --release
// --test hard_cases -- --include-ignored), a few minutes in all.

#[test]
#[ignore = "long: run by scripts/hard-cases"]
fn long_size_ratio_ten_for_ten_milliseconds() {
    let mut s = short_shear(1e-2);
    if let Grains::Pack(p) = &mut s.grains {
        p.radius = RadiusDist::Uniform { min: 0.1e-3, max: 1.0e-3 };
    }
    assert_stable(&run(&s), "size ratio 10, 1000 grains, 10 ms");
}

#[test]
#[ignore = "long: run by scripts/hard-cases"]
fn long_ten_times_the_confining_stress_for_the_whole_run() {
    // The full 50 ms at 1 MPa: the wall stress averages to the load within its interval
    // plus 2% (the top wall's inertia makes it oscillate about the load).
    let mut s = short_shear(5e-2);
    if let Some(w) = &mut s.walls {
        w.top.control = ControlSpec::Pressure(1e6);
    }
    let out = run(&s);
    assert_stable(&out, "1 MPa, 50 ms");
    let sigma = out.shear.unwrap().normal_stress_pa;
    assert!((sigma.mean - 1e6).abs() < sigma.ci95 + 2e4, "{sigma:?}");
}

#[test]
#[ignore = "long: run by scripts/hard-cases"]
fn long_rolling_for_a_second_keeps_its_speed_and_its_balance() {
    // A second of rolling after the slip (7.7 million steps) with both formulations: the
    // speed stays 5/7 v0 to 1e-3 and the balance closes to 1e-3; no drift of the spring.
    for tangential in [TangentialSpec::TotalDisplacement, TangentialSpec::IncrementalForce] {
        let s = sliding_grain(tangential, 0.1, 1.0);
        let out = run(&s);
        assert_eq!(out.status, "completed");
        assert!(out.energy.unwrap().max_residual_rel < 1e-3);
        let mut b = build(&s).unwrap();
        let e = b.engine.as_mut();
        for _ in 0..(1.0 / e.dt()) as u64 {
            e.step().unwrap();
        }
        let v = e.particles().v[0].x;
        assert!((v - 0.5 / 7.0).abs() < 1e-4, "{tangential:?}: {v}");
    }
}

#[test]
fn an_impact_on_a_grain_of_density_1e300_reports_finite_numbers() {
    // Found by the fuzzer: a glass bead hits a grain of density 1e300 kg/m^3 (4e291 kg)
    // under a body force of 1 m/s^2 along the line of centres. The momentum is finite, its
    // change is too (gravity's impulse, 1e286 N s), its square is not: the impact summary's
    // momentum error was infinite (the length taken as sqrt(x^2 + y^2)); now hypot. That
    // error is gravity's impulse over the momentum scale, 2 g t for grains at +-0.5 m/s.
    let mut s = head_on(glass(0.5), R, 1.0, 200.0);
    s.materials.push(Material { name: "heavy".into(), density: 1e300, ..glass(0.8) });
    if let Grains::List(g) = &mut s.grains {
        g[1].material = 1;
    }
    s.gravity = [-1.0, 0.0].into();
    let i = impact(&s);
    let t = s.duration;
    assert!(i.momentum_error_rel.is_finite() && i.momentum_error_rel > 0.0 && i.momentum_error_rel <= 2.0 * t * 1.01, "{i:?} (2 g t = {})", 2.0 * t);
}
