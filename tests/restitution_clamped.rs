//! The damping that returns e under the clamp `Fn >= 0` (`model.damping =
//! "clamped_restitution"`), e = 0, and the damped stability limit, against closed forms.
//!
//! The closed form (src/physics/restitution.rs, docs/model.md): Hertz with
//! `gn = 2 sqrt(5/6) b sqrt(Sn m*)` maps onto the linear spring-dashpot
//! `w'' + 2 b w' + w = 0` (`w ~ x^(5/4)`, `dtau ~ x^(1/4) dt`, `dw/dtau` the normal speed),
//! so both laws part at the same speed for the same b: without the clamp
//! `e = exp(-pi b / sqrt(1 - b^2))`, with it `e = exp(-2 b acos(b) / sqrt(1 - b^2))`
//! (continued past b = 1 with acosh). Checked here three ways: the Hertz equation
//! integrated numerically (not through the mapping), grainlab's head-on impacts under both
//! laws converging to the input e, and a grain on a wall.

use grainlab::physics::material::Material;
use grainlab::physics::restitution::{beta, clamped_beta, clamped_restitution};
use grainlab::scene::builtin::{head_on_under, on_rigid_plane};
use grainlab::scene::{DampingSpec, NormalLaw, Scene, TangentialSpec, TimeStepRule};
use grainlab::study::run::{RunOptions, run_scene};
use grainlab::{Error, build};

const R: f64 = 1e-3;
const GIVEN: NormalLaw = NormalLaw::HookeStiffness { kn: 2.0e5, kt: 1.5e5 };

fn glass(e: f64) -> Material {
    Material { restitution: e, ..Material::default() }
}

/// The clamped Hertz contact `x'' = -max(0, x^(3/2) + sqrt(5) b x^(1/4) x')` from `x = 0`,
/// `x' = 1`, integrated by fourth-order Runge-Kutta in `s = t^(1/4)` (in which the start,
/// `x ~ t`, is smooth) until the force reaches 0 on the way out: the speed the grains part
/// at. Written here independently of the library's closed form.
fn hertz_clamped_integrated(b: f64) -> f64 {
    let rhs = |s: f64, x: f64, v: f64| {
        let q = x.max(0.0).sqrt();
        let f = x.max(0.0) * q + 5f64.sqrt() * b * q.sqrt() * v;
        let j = 4.0 * s * s * s;
        (j * v, -j * f, f)
    };
    let step = |s: f64, x: f64, v: f64, h: f64| {
        let (a1, b1, _) = rhs(s, x, v);
        let (a2, b2, _) = rhs(s + 0.5 * h, x + 0.5 * h * a1, v + 0.5 * h * b1);
        let (a3, b3, _) = rhs(s + 0.5 * h, x + 0.5 * h * a2, v + 0.5 * h * b2);
        let (a4, b4, _) = rhs(s + h, x + h * a3, v + h * b3);
        let (x1, v1) = (x + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4), v + h / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4));
        (x1, v1, rhs(s + h, x1, v1).2)
    };
    let ds = 1e-4;
    let (mut s, mut x, mut v) = (0.0, 0.0, 1.0);
    while s < 4.0 {
        let (x1, v1, f1) = step(s, x, v, ds);
        if f1 < 0.0 && v1 < 0.0 {
            // The force's zero inside this step, by bisection on the step size.
            let (mut lo, mut hi, mut v_at) = (0.0, ds, v1);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                let (_, vm, fm) = step(s, x, v, mid);
                if fm < 0.0 {
                    (hi, v_at) = (mid, vm);
                } else {
                    lo = mid;
                }
            }
            return -v_at;
        }
        (s, x, v) = (s + ds, x1, v1);
    }
    panic!("b = {b}: the force never reached 0");
}

#[test]
fn the_hertz_contact_integrated_matches_the_closed_form() {
    // The integration's own error at ds = 1e-4 in s is below 1e-11 (halving ds changes the
    // result by less); 1e-9 bounds it, far below any difference a wrong mapping would make
    // (the unclamped and clamped forms differ by 0.12 at b = 0.45).
    for b in [0.01, 0.1, 0.2155, 0.456, 0.7312, 1.0, 1.5, 4.807] {
        let (n, c) = (hertz_clamped_integrated(b), clamped_restitution(b));
        assert!((n - c).abs() < 1e-9, "b = {b}: integrated {n}, closed form {c}");
    }
    // The figures for the default beta(e) under the clamp: 0.2 -> 0.325, 0.8 -> 0.808.
    assert!((clamped_restitution(-beta(0.2)) - 0.3249).abs() < 1e-4);
    assert!((clamped_restitution(-beta(0.8)) - 0.8081).abs() < 1e-4);
}

/// The scene with the clamp and the clamped damping, and time for a slow parting: at
/// e = 0.01 the grains leave the overlap the clamp releases them at with 1% of the
/// impact speed.
fn clamped(mut s: Scene) -> Scene {
    s.model.limit_force = true;
    s.model.damping = DampingSpec::ClampedRestitution;
    s.duration *= 10.0;
    s
}

fn realised(s: &Scene) -> f64 {
    let out = run_scene(s, &RunOptions::default()).expect("the run completes");
    out.impact.expect("the grains collided and separated").restitution_normal
}

#[test]
fn clamped_damping_returns_the_input_restitution_in_head_on_impacts() {
    // Velocity Verlet's error in e is first order in dt/t_c (the damping force acts on
    // the half-step velocity, and the contact's end falls between steps): measured
    // |e(N) - e| <= 0.27 / N at N = 1000 and 2000 steps per (elastic) contact time over
    // both laws and e = 0.01 to 0.95, bounded here by 0.3 / N. Where the error is not
    // lost in rounding (> 1e-5) it halves with the step (ratio measured 1.97-2.10), so
    // the Richardson extrapolation 2 e(2000) - e(1000) estimates the continuous-time
    // limit: measured within 2.1e-6 of the input e, bounded here by 5e-6. (The default
    // beta(e) under the clamp misses by up to 0.16: e = 0.01 gives 0.173.)
    for law in [NormalLaw::Hertz, GIVEN] {
        for e in [0.01, 0.05, 0.2, 0.5, 0.8, 0.95] {
            let err = |n: f64| realised(&clamped(head_on_under(law, glass(e), R, 1.0, n))) - e;
            let (e1, e2) = (err(1000.0), err(2000.0));
            assert!(e1.abs() <= 0.3 / 1000.0 && e2.abs() <= 0.3 / 2000.0, "{law:?} e = {e}: errors {e1:e} at t_c/1000, {e2:e} at t_c/2000");
            if e1.abs() > 1e-5 {
                let ratio = e1 / e2;
                assert!((1.8..=2.2).contains(&ratio), "{law:?} e = {e}: error ratio {ratio} (first order: 2)");
            }
            let limit = 2.0 * e2 - e1;
            assert!(limit.abs() <= 5e-6, "{law:?} e = {e}: extrapolated error {limit:e}");
        }
    }
}

#[test]
fn clamped_damping_returns_the_input_restitution_on_a_wall() {
    // A grain meeting a rigid wall head-on (m* = m, R* = r): the same closed form.
    for e in [0.1, 0.5, 0.9] {
        let s = clamped(on_rigid_plane(glass(e), Default::default(), R, 1.0, 0.0, 0.0, 2000.0, TangentialSpec::Frictionless));
        let got = realised(&s);
        assert!((got - e).abs() <= 0.3 / 2000.0, "e = {e}: realised {got}");
    }
}

#[test]
fn the_default_damping_under_the_clamp_realises_the_closed_form_of_its_beta() {
    // What the clamped damping corrects: beta(e) under the clamp gives the clamped closed
    // form at b = |beta(e)|, not e (first-order bound as above).
    for law in [NormalLaw::Hertz, GIVEN] {
        for e in [0.2, 0.8] {
            let mut s = head_on_under(law, glass(e), R, 1.0, 2000.0);
            s.model.limit_force = true;
            let (got, want) = (realised(&s), clamped_restitution(-beta(e)));
            assert!((got - want).abs() <= 1.0 / 2000.0, "{law:?} e = {e}: realised {got}, closed form {want}");
        }
    }
}

#[test]
fn zero_restitution_keeps_the_grains_together_without_the_clamp() {
    // e = 0: beta = -1, critical damping. Without the clamp the overlap follows
    // `w = tau exp(-tau)` (Hertz through the mapping, the spring itself), which never returns
    // to 0: the grains stay in contact and their relative speed fades. After 20 contact
    // times they still touch and approach each other at less than 1e-3 of the impact speed.
    for law in [NormalLaw::Hertz, GIVEN] {
        let mut s = head_on_under(law, glass(0.0), R, 1.0, 200.0);
        s.duration *= 8.0;
        let out = run_scene(&s, &RunOptions::default()).expect("the run completes");
        assert!(out.impact.is_none(), "{law:?}: the grains parted at e = 0");
        assert!(out.impact_note.as_deref().is_some_and(|n| n.contains("still in contact")), "{:?}", out.impact_note);
        let mut built = build(&s).unwrap();
        let steps = (s.duration / built.engine.dt()) as u64;
        for _ in 0..steps {
            built.engine.step().unwrap();
        }
        let p = built.engine.particles();
        let (gap, dv) = (p.x[1].x - p.x[0].x - 2.0 * R, p.v[1].x - p.v[0].x);
        assert!(gap < 0.0, "{law:?}: the grains parted (gap {gap:e} m)");
        assert!(dv.abs() < 1e-3, "{law:?}: relative speed {dv} m/s after 20 contact times");
    }
}

#[test]
fn the_clamped_damping_is_refused_without_the_clamp_and_at_zero_restitution() {
    let mut s = head_on_under(NormalLaw::Hertz, glass(0.5), R, 1.0, 100.0);
    s.model.damping = DampingSpec::ClampedRestitution;
    match build(&s) {
        Err(Error::Invalid { field, allowed, .. }) => assert!(field == "model.damping" && allowed.contains("limit_force"), "{field}: {allowed}"),
        other => panic!("expected a refusal, got {:?}", other.err()),
    }
    let s = clamped(head_on_under(NormalLaw::Hertz, glass(0.0), R, 1.0, 100.0));
    match build(&s) {
        Err(Error::Invalid { field, allowed, .. }) => assert!(field == "materials[0].restitution" && allowed.contains("infinite damping"), "{field}: {allowed}"),
        other => panic!("expected a refusal, got {:?}", other.err()),
    }
    assert_eq!(clamped_beta(0.0), None);
}

#[test]
fn strong_damping_tightens_the_stability_limit() {
    // The clamped damping at e = 0.01 has |beta| = 4.81: zeta = sqrt(5/6) 4.81 = 4.39 on
    // the normal oscillation, whose velocity-Verlet limit 2 (sqrt(1 + zeta^2) - zeta) /
    // omega is 0.112 of the undamped 2 / omega. Just under the damped limit the run
    // completes with finite output; just over it the scene is refused naming dt and the
    // limit (where the undamped limit would have accepted it and the run diverged).
    let mut base = clamped(head_on_under(NormalLaw::Hertz, glass(0.01), R, 1.0, 200.0));
    base.model.tangential = TangentialSpec::Frictionless;
    let limit = build(&base).unwrap().time_step.stability_limit_s;
    let mut elastic = base.clone();
    elastic.materials[0].restitution = 1.0;
    let undamped = build(&elastic).unwrap().time_step.stability_limit_s;
    let zeta = 0.912_870_929_175_276_9 * 4.806_941_801_8;
    let want = (1.0 + zeta * zeta as f64).sqrt() - zeta;
    // Frictionless: the normal oscillation alone (with friction the tangential one, whose
    // zeta is sqrt(m* (1/m_i + ...)) = 1.87 times larger here, sets a tighter limit).
    assert!((limit / undamped - want).abs() < 1e-6 * want, "damped {limit:e} s, undamped {undamped:e} s, ratio {}", limit / undamped);
    let with_dt = |dt: f64| {
        let mut s = base.clone();
        s.time_step.rule = TimeStepRule::Fixed { dt };
        s.time_step.characteristic_speed = Some(1.0);
        s
    };
    let edge = run_scene(&with_dt(0.95 * limit), &RunOptions::default()).expect("under the damped limit the run completes");
    let e = edge.impact.expect("the grains part").restitution_normal;
    assert!(e.is_finite() && (0.0..1.0).contains(&e), "{e}");
    match run_scene(&with_dt(1.05 * limit), &RunOptions::default()) {
        Err(Error::Invalid { field, allowed, .. }) => assert!(field.contains("dt") && allowed.contains("stability limit"), "{field}: {allowed}"),
        other => panic!("expected a refusal, got {:?}", other.err()),
    }
}
