//! Head-on impacts against closed-form Hertz theory and conservation laws.

use grainlab::physics::material::{Material, PairMaterial, hertz_contact_time, hertz_max_overlap};
use grainlab::observe::impact::ImpactSummary;
use grainlab::study::run::{RunOptions, run_scene};
use grainlab::scene::builtin::head_on;

const R: f64 = 1e-3;

fn glass(e: f64) -> Material {
    Material { restitution: e, ..Material::default() }
}

fn impact(e: f64, v: f64, steps: f64, clamp: bool) -> ImpactSummary {
    let mut s = head_on(glass(e), R, v, steps);
    s.model.limit_force = clamp;
    let out = run_scene(&s, &RunOptions::default()).expect("the run completes");
    out.impact.expect("the grains collided and separated")
}

/// Reduced quantities of two equal glass beads of radius R.
fn reduced() -> (f64, f64, f64) {
    let g = glass(1.0);
    let m = 4.0 / 3.0 * std::f64::consts::PI * R.powi(3) * g.density;
    (m / 2.0, R / 2.0, PairMaterial::mix(&g, &g).e_star)
}

#[test]
fn elastic_impact_matches_closed_form_hertz() {
    // At dt = t_c/200 the sampled peaks (refined by a parabola) and the interpolated
    // contact start and end are accurate to O((dt/t_c)^2) ~ 1e-4: 0.5% is the issue's
    // bound and leaves room; the Hertz constant 2.868 itself is given to 4 digits.
    let (m, r, e) = reduced();
    for v in [0.1, 1.0, 10.0] {
        let s = impact(1.0, v, 200.0, false);
        let dmax = hertz_max_overlap(m, r, e, v);
        let fmax = 4.0 / 3.0 * e * r.sqrt() * dmax.powf(1.5);
        let tc = hertz_contact_time(m, r, e, v);
        let rel = |a: f64, b: f64| (a - b).abs() / b;
        assert!(rel(s.max_overlap_m, dmax) < 5e-3, "v = {v}: overlap {} vs {dmax}", s.max_overlap_m);
        assert!(rel(s.peak_force_n, fmax) < 5e-3, "v = {v}: force {} vs {fmax}", s.peak_force_n);
        assert!(rel(s.contact_time_s, tc) < 5e-3, "v = {v}: contact time {} vs {tc}", s.contact_time_s);
        // Velocity Verlet is symplectic: an elastic impact gives back its kinetic energy up
        // to the integrator's O(dt^2) error, far below 1e-4 at 200 steps per contact.
        assert!((s.restitution_normal.powi(2) - 1.0).abs() < 1e-4, "v = {v}: e^2 = {}", s.restitution_normal.powi(2));
    }
}

#[test]
fn realised_restitution_converges_to_the_input_without_the_clamp() {
    // The damping sees a half-step velocity: the error in e is first order in dt/t_c,
    // with a wobble from where the end of contact falls within a step. Without the
    // clamp the continuous-time law returns exactly e, so the error must stay inside a
    // first-order envelope C dt/t_c (C = 0.15 measured at e = 0.5 from t_c/25 to
    // t_c/2000, where the largest |error| n is 0.117), and at t_c/500 be below 2e-3
    // (the bound).
    let e_in = 0.5;
    let err = |n: f64| (impact(e_in, 1.0, n, false).restitution_normal - e_in).abs();
    for n in [50.0, 100.0, 200.0, 500.0, 1000.0] {
        assert!(err(n) < 0.15 / n, "t_c/{n}: error {}", err(n));
    }
    assert!(err(500.0) < 2e-3);
    assert!(err(1000.0) < err(50.0) / 5.0, "no convergence: {} vs {}", err(1000.0), err(50.0));
}

#[test]
fn the_clamp_raises_the_realised_restitution() {
    // With Fn >= 0 enforced, the attractive tail of the damped force is cut off, so less
    // energy is dissipated: realised e is higher, markedly so for small e.
    for e_in in [0.1, 0.5, 0.9] {
        let free = impact(e_in, 1.0, 500.0, false).restitution_normal;
        let clamped = impact(e_in, 1.0, 500.0, true).restitution_normal;
        assert!(clamped > free, "e = {e_in}: clamped {clamped} <= unclamped {free}");
    }
    let free = impact(0.1, 1.0, 500.0, false).restitution_normal;
    let clamped = impact(0.1, 1.0, 500.0, true).restitution_normal;
    assert!(clamped - free > 0.01, "e = 0.1: the clamp changed e by only {}", clamped - free);
}

#[test]
fn momentum_is_conserved_in_every_two_body_collision() {
    // Forces on i and j are equal and opposite by construction: the total momentum
    // changes only by round-off, 1e-12 relative to m|v|.
    for e in [0.1, 0.5, 1.0] {
        for v in [0.01, 1.0, 10.0] {
            let s = impact(e, v, 50.0, false);
            assert!(s.momentum_error_rel < 1e-12, "e = {e}, v = {v}: {}", s.momentum_error_rel);
        }
    }
}

#[test]
fn restitution_depends_on_dt_over_tc_only() {
    // The reference notes' claim: with dt scaled by the Hertz contact time, the realised
    // e does not depend on the impact speed (Hertz's law is self-similar in v).
    let at = |v: f64| impact(0.3, v, 100.0, false).restitution_normal;
    let (a, b, c) = (at(0.01), at(1.0), at(10.0));
    assert!((a - b).abs() < 1e-9 && (b - c).abs() < 1e-9, "e at 0.01, 1, 10 m/s: {a} {b} {c}");
}

#[test]
fn energy_balance_closes_in_an_inelastic_impact() {
    // Kinetic energy lost equals the energy dissipated by damping, to the integrator's
    // O(dt^2) accuracy: 1e-4 of the initial energy at 200 steps per contact.
    let s = head_on(glass(0.5), R, 1.0, 200.0);
    let out = run_scene(&s, &RunOptions::default()).unwrap();
    let en = out.energy.unwrap();
    assert!(en.max_residual_rel < 1e-4, "{en:?}");
    let row = en.final_row;
    let lost = row.initial_j - row.kinetic_translation_j;
    assert!((row.dissipated_normal_damping_j - lost).abs() < 1e-4 * row.initial_j);
    // And the realised e says how much: 1 - e^2 of the initial energy.
    let e = out.impact.unwrap().restitution_normal;
    assert!(((1.0 - e * e) * row.initial_j - lost).abs() < 1e-9 * row.initial_j);
}

#[test]
fn a_sliding_oblique_impact_obeys_coulomb_exactly() {
    // At 60 degrees with mu = 0.1 the contact slides from first touch to separation
    // (kt xi / (mu Fn) starts at 6 G* tan(theta) / (mu E*) ~ 23 > 1 and never falls below
    // 1). With the clamp (Fn >= 0) every step's tangential impulse is mu times its normal
    // impulse, so the tangential velocity change is mu times the normal one and the spin
    // is m r dv_t / I, for LIGGGHTS' and YADE's formulations and for the cap on the
    // total with the spring kept (whose total force is mu |Fn| while sliding), and for
    // micro-slip (every spring at its share of mu |Fn|), to round-off.
    use grainlab::scene::TangentialSpec;
    use grainlab::scene::builtin::oblique;
    for t in [TangentialSpec::TotalDisplacement, TangentialSpec::IncrementalForce, TangentialSpec::TotalForceCapSpringKept, TangentialSpec::MindlinDeresiewicz] {
        let mut g = glass(0.9);
        g.friction = 0.1;
        let v = 1.0;
        let a = 60f64.to_radians();
        let mut s = oblique(g, R, v, 60.0, t, 200.0);
        s.model.limit_force = true;
        let out = run_scene(&s, &RunOptions::default()).unwrap().impact.unwrap();
        let dvn = out.rebound_normal_velocity_m_s + v * a.cos();
        let dvt = v * a.sin() - out.rebound_tangential_velocity_m_s;
        assert!((dvt - 0.1 * dvn).abs() < 1e-9 * dvn, "{t:?}: dv_t {dvt} vs mu dv_n {}", 0.1 * dvn);
        // Sphere: I = 2/5 m r^2, so w = -dv_t / (0.4 r) (clockwise for a grain moving +x).
        let w = -dvt / (0.4 * R);
        assert!((out.rebound_spin_rad_s - w).abs() < 1e-9 * w.abs(), "{t:?}: spin {} vs {w}", out.rebound_spin_rad_s);
    }
}
