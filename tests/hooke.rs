//! The linear spring-dashpot (`model.normal` hooke and hooke_stiffness) against its
//! closed forms.
//!
//! For two grains of reduced mass m* on a spring kn with the damping
//! `gn = -2 beta(e) sqrt(m* kn)`, the overlap obeys `m* x'' + gn x' + kn x = 0` from
//! `x = 0`, `x' = v`: `x(t) = v / omega_d exp(-zeta omega_0 t) sin(omega_d t)` with
//! `omega_0 = sqrt(kn / m*)`, `zeta = -beta`, `omega_d = omega_0 sqrt(1 - beta^2)`. The
//! contact ends at `x = 0` (the force may turn attractive) after
//! `t_c = pi / omega_d`, with the rebound speed `v exp(-zeta omega_0 t_c) = v e` exactly:
//! `beta = ln e / sqrt(ln^2 e + pi^2)` makes `exp(beta pi / sqrt(1 - beta^2)) = e`.
//! Elastic (e = 1): largest overlap `v / omega_0`, peak force `kn v / omega_0`.

use grainlab::observe::impact::ImpactSummary;
use grainlab::physics::material::{Material, PairMaterial, beta};
use grainlab::scene::NormalLaw;
use grainlab::scene::builtin::head_on_under;
use grainlab::study::run::{RunOptions, run_scene};

const R: f64 = 1e-3;

fn glass(e: f64) -> Material {
    Material { restitution: e, ..Material::default() }
}

fn impact(law: NormalLaw, e: f64, v: f64, steps: f64) -> ImpactSummary {
    let s = head_on_under(law, glass(e), R, v, steps);
    let out = run_scene(&s, &RunOptions::default()).expect("the run completes");
    out.impact.expect("the grains collided and separated")
}

/// Reduced mass of two equal glass grains of radius R (sphere-in-plane), and the pair's
/// materials.
fn reduced() -> (f64, PairMaterial) {
    let g = glass(1.0);
    let m = 4.0 / 3.0 * std::f64::consts::PI * R.powi(3) * g.density;
    (m / 2.0, PairMaterial::mix(&g, &g))
}

/// LIGGGHTS `model hooke`'s stiffness, written out here from its documented formula
/// (independently of src/physics/contact/normal.rs).
fn derived_kn(vc: f64) -> f64 {
    let (m, pm) = reduced();
    let r_star = R / 2.0;
    16.0 / 15.0 * r_star.sqrt() * pm.e_star * (15.0 * m * vc * vc / (16.0 * r_star.sqrt() * pm.e_star)).powf(0.2)
}

const GIVEN: NormalLaw = NormalLaw::HookeStiffness { kn: 2.0e5, kt: 1.5e5 };

#[test]
fn elastic_spring_matches_its_closed_form() {
    // At t_c/400 the sampled peaks (refined by a parabola) and the interpolated contact
    // start and end are good to O((dt/t_c)^2) ~ 1e-5; 1e-3 leaves room for the parabola
    // fit of a sine's top. Velocity Verlet on a linear oscillator conserves a modified
    // energy: e^2 - 1 is O((omega dt)^2) ~ 6e-5 at most at this step, bounded here by 1e-4.
    let (m, _) = reduced();
    for (law, kn) in [(NormalLaw::Hooke { characteristic_velocity: 1.0 }, derived_kn(1.0)), (GIVEN, 2.0e5)] {
        for v in [0.1, 1.0, 10.0] {
            let s = impact(law, 1.0, v, 400.0);
            let omega = (kn / m).sqrt();
            let rel = |a: f64, b: f64| (a - b).abs() / b;
            assert!(rel(s.max_overlap_m, v / omega) < 1e-3, "{law:?} v = {v}: overlap {} vs {}", s.max_overlap_m, v / omega);
            assert!(rel(s.peak_force_n, kn * v / omega) < 1e-3, "{law:?} v = {v}: force {} vs {}", s.peak_force_n, kn * v / omega);
            let tc = std::f64::consts::PI / omega;
            assert!(rel(s.contact_time_s, tc) < 1e-3, "{law:?} v = {v}: contact time {} vs {tc}", s.contact_time_s);
            assert!((s.restitution_normal.powi(2) - 1.0).abs() < 1e-4, "{law:?} v = {v}: e^2 = {}", s.restitution_normal.powi(2));
        }
    }
}

#[test]
fn damped_spring_returns_the_input_restitution_and_contact_time() {
    // The damping sees a half-step velocity and the contact ends somewhere within a step:
    // the realised e is off by O(dt/t_c) with a wobble from that phase. In continuous
    // time the law returns the input e exactly, so the error must stay inside a
    // first-order envelope C dt/t_c (C = 0.6: the largest n |error| measured from t_c/125
    // to t_c/8000 for e = 0.2, 0.5, 0.9 is 0.53) and shrink with dt (at t_c/4000 under a
    // quarter of its t_c/250 value). The contact time's resolution is the interpolated
    // end of contact: within 1e-3 of pi / omega_d at t_c/1000.
    let (m, _) = reduced();
    for e_in in [0.2, 0.5, 0.9] {
        let err = |n: f64| impact(GIVEN, e_in, 1.0, n).restitution_normal - e_in;
        let errors: Vec<(f64, f64)> = [250.0, 1000.0, 4000.0].iter().map(|&n| (n, err(n))).collect();
        for &(n, e) in &errors {
            assert!(e.abs() < 0.6 / n, "e = {e_in}, t_c/{n}: error {e:.3e}");
        }
        assert!(errors[2].1.abs() < errors[0].1.abs() / 4.0, "e = {e_in}: no convergence {errors:?}");
        let fine = impact(GIVEN, e_in, 1.0, 1000.0);
        let b = beta(e_in);
        let omega_d = (2.0e5 / m).sqrt() * (1.0 - b * b).sqrt();
        let tc = std::f64::consts::PI / omega_d;
        assert!((fine.contact_time_s - tc).abs() < 1e-3 * tc, "e = {e_in}: contact time {} vs pi/omega_d {tc}", fine.contact_time_s);
    }
}

#[test]
fn a_linear_contact_does_not_depend_on_the_impact_speed() {
    // The linear law is scale-free in speed: at the same steps per contact (whose t_c
    // does not depend on v) and the same starting phase, every overlap and force scales
    // with v and the restitution and contact time stay what they were, up to rounding.
    // Hertz, by contrast, stiffens with v (t_c ~ v^(-1/5)).
    let slow = impact(GIVEN, 0.5, 0.1, 200.0);
    let fast = impact(GIVEN, 0.5, 10.0, 200.0);
    assert!((slow.restitution_normal - fast.restitution_normal).abs() < 1e-12, "{} vs {}", slow.restitution_normal, fast.restitution_normal);
    assert!((slow.contact_time_s / fast.contact_time_s - 1.0).abs() < 1e-12);
    assert!((fast.max_overlap_m / slow.max_overlap_m / 100.0 - 1.0).abs() < 1e-12);
}

#[test]
fn the_derived_spring_has_the_hertz_overlap_at_its_characteristic_velocity() {
    // LIGGGHTS' `model hooke` picks kn so that an elastic impact at vc presses in as far
    // as Hertz's would: compare the two laws' measured largest overlaps at v = vc.
    let vc = 0.5;
    let spring = impact(NormalLaw::Hooke { characteristic_velocity: vc }, 1.0, vc, 400.0);
    let hertz = impact(NormalLaw::Hertz, 1.0, vc, 400.0);
    assert!((spring.max_overlap_m / hertz.max_overlap_m - 1.0).abs() < 1e-3, "{} vs {}", spring.max_overlap_m, hertz.max_overlap_m);
}

#[test]
fn the_shear_cell_runs_on_the_linear_spring_and_its_energy_balance_closes() {
    // The energy ledger adds the spring's stored energy 1/2 kn dn^2: a ledger written for
    // Hertz (2/5 kn dn^2) would leave a residual of 1/10 kn dn^2 per contact, about 20% of
    // the stored energy. The built-in cell's own bound (the warning at 1e-3 relative)
    // must hold.
    let mut s = grainlab::scene::builtin::shear_cell(100, 0.004);
    s.model.normal = NormalLaw::Hooke { characteristic_velocity: 1.0 };
    s.duration = 0.02;
    s.output.frames = 0;
    let out = run_scene(&s, &RunOptions::default()).expect("the shear cell runs");
    let e = out.energy.expect("the ledger is on");
    assert!(e.max_residual_rel < 1e-3, "energy residual {}", e.max_residual_rel);
    let shear = out.shear.expect("a shear summary");
    assert!(shear.normal_stress_pa.mean > 0.0 && shear.shear_stress_pa.mean.is_finite());
}

