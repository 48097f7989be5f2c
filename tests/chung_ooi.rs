//! Chung & Ooi (2011), "Benchmark tests for verifying discrete element modelling codes at
//! particle impact level", Granular Matter 13:643-656: tests 1 to 8, for sphere-in-plane
//! grains and for disks, against their closed forms (docs/benchmarks.md derives them).
//!
//! Inputs as public implementations state them (Kratos DEMApplication's
//! `DEM3D_chung_ooi_tests`, YADE's example scripts, LAMMPS' `unittest/granular`), see
//! docs/benchmarks.md. A "rigid plane" is a flat wall of a material 1e30 Pa stiff
//! ([`builtin::on_rigid_plane`]): E* and G* then differ from the grain's own E/(1 - nu^2)
//! and E/(2(2 - nu)(1 + nu)) by 1e-19 relative.
//!
//! Gross sliding: while a contact slides, LIGGGHTS' and YADE's formulations give a
//! tangential force of exactly mu |Fn| (no damping), along the tangent line, and so does
//! the spring-kept cap (its total force at the cap; LAMMPS' law keeps the dashpot's force
//! in its spring). With the normal force
//! clamped at Fn >= 0 (`limit_force`), the tangential impulse is then exactly mu times
//! the normal impulse: the grain's tangential velocity changes by mu times its normal
//! velocity change, and its spin by kappa / r times that (kappa = m r^2 / I: 5/2 for the
//! sphere in the plane, 2 for the disk), step by step, so to rounding. Without the clamp
//! the normal force turns attractive at the end of a damped contact, |Fn| exceeds Fn
//! there, and the identity fails by design (issue 32's LAMMPS-like law caps it); these
//! tests clamp wherever e < 1.
//!
//! Against the paper itself: its curves as Kratos digitised them (tests/data/chung_ooi_paper),
//! by Kratos' measure and bounds where the contact slides.

use grainlab::physics::dim::GrainShape;
use grainlab::physics::material::{Material, PairMaterial, hertz_contact_time, hertz_contact_time_exact, hertz_max_overlap};
use grainlab::observe::impact::ImpactSummary;
use grainlab::scene::*;
use grainlab::study::run::{RunOptions, run_scene};

fn material(e: f64, nu: f64, rho: f64, restitution: f64, friction: f64) -> Material {
    Material { name: "grain".into(), youngs_modulus: e, poisson_ratio: nu, density: rho, restitution, friction, work_of_adhesion: 0.0, rolling_friction: 0.0 }
}

/// The two grain shapes, each with its kappa = m r^2 / I.
fn shapes() -> [(GrainShape, f64); 2] {
    [(GrainShape::SphereInPlane, 2.5), (GrainShape::Disk { thickness: 1e-3 }, 2.0)]
}

/// [`builtin::on_rigid_plane`] with the clamp as given and the torque arm r (the closed
/// forms' lever).
#[allow(clippy::too_many_arguments)]
fn on_plane(grain: Material, shape: GrainShape, r: f64, vn: f64, vt: f64, omega: f64, steps: f64, tangential: TangentialSpec, clamp: bool) -> Scene {
    let mut s = builtin::on_rigid_plane(grain, shape, r, vn, vt, omega, steps, tangential);
    s.model.limit_force = clamp;
    s.model.lever_arm = grainlab::physics::contact::LeverArm::Radius;
    s
}

/// Two grains `a` and `b` (radius, material, shape) meeting head-on along x at relative
/// speed `v`, grain 0 from the left, with spins `w0`, `w1` and tangential (y) velocity
/// `vy0` of grain 0; 10.5 steps of t_c/`steps` before contact.
#[allow(clippy::too_many_arguments)]
fn pair(a: (f64, Material), b: (f64, Material), shape: GrainShape, v: f64, vy0: f64, w: [f64; 2], steps: f64, clamp: bool) -> Scene {
    let mut s = builtin::head_on(a.1.clone(), a.0, v, steps);
    let (ma, mb) = (shape.mass(a.0, a.1.density), shape.mass(b.0, b.1.density));
    let pm = PairMaterial::mix(&a.1, &b.1);
    let m_star = ma * mb / (ma + mb);
    let r_star = a.0 * b.0 / (a.0 + b.0);
    let tc = hertz_contact_time(m_star, r_star, pm.e_star, v);
    let dt = tc / steps;
    let gap = 10.5 * v * dt;
    // Momentum zero: grain 0 at +v mb/(ma+mb), grain 1 at -v ma/(ma+mb).
    s.materials = vec![a.1, b.1];
    s.grain_shape = shape;
    s.grains = Grains::List(vec![
        GrainSpec { x: [-a.0 - gap / 2.0, 0.0].into(), v: [v * mb / (ma + mb), vy0].into(), omega: w[0].into(), r: a.0, material: 0 },
        GrainSpec { x: [b.0 + gap / 2.0, 0.0].into(), v: [-v * ma / (ma + mb), 0.0].into(), omega: w[1].into(), r: b.0, material: 1 },
    ]);
    s.time_step.rule = TimeStepRule::Fixed { dt };
    s.duration = 2.0 * gap / v + 3.0 * tc;
    s.model.limit_force = clamp;
    s.model.lever_arm = grainlab::physics::contact::LeverArm::Radius;
    s
}

fn run(s: &Scene) -> ImpactSummary {
    run_scene(s, &RunOptions::default()).expect("the run completes").impact.expect("the impact completed")
}

/// With `CHUNG_OOI_OUT` set (scripts/benchmark-docs), each test writes its rows there as
/// `<test>.csv` (`shape,form,x,quantity,grainlab,closed_form`) for the plots of
/// docs/benchmarks.md; the closed form is empty where there is none.
struct Rows {
    test: &'static str,
    lines: Vec<String>,
}

impl Rows {
    fn new(test: &'static str) -> Self {
        Rows { test, lines: vec!["shape,form,x,quantity,grainlab,closed_form".into()] }
    }
    fn add(&mut self, shape: GrainShape, form: &str, x: f64, quantity: &str, value: f64, closed: Option<f64>) {
        let shape = match shape {
            GrainShape::Disk { .. } => "disk",
            _ => "sphere_in_plane",
        };
        self.lines.push(format!("{shape},{form},{x},{quantity},{value:e},{}", closed.map_or(String::new(), |c| format!("{c:e}"))));
    }
}

impl Drop for Rows {
    fn drop(&mut self) {
        if let Some(dir) = std::env::var_os("CHUNG_OOI_OUT") {
            let path = std::path::Path::new(&dir).join(format!("{}.csv", self.test));
            std::fs::write(&path, self.lines.join("\n") + "\n").expect("the rows are written");
        }
    }
}

/// The five frictional formulations: LIGGGHTS', YADE's, LAMMPS' (the cap on the total
/// tangential force, issue 32), the cap on the total with the spring kept (Kratos' rule)
/// and Mindlin-Deresiewicz micro-slip.
const FORMS: [TangentialSpec; 5] = [TangentialSpec::TotalDisplacement, TangentialSpec::IncrementalForce, TangentialSpec::TotalForceCap, TangentialSpec::TotalForceCapSpringKept, TangentialSpec::MindlinDeresiewicz];

fn form_name(form: TangentialSpec) -> &'static str {
    form.name()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Tests 1 and 2: elastic normal impacts against Hertz. At t_c/400 the sampled peaks
/// (refined by a parabola) and the interpolated start and end of contact are good to
/// O((dt/t_c)^2) ~ 1e-5, bounded here by 1e-3 (the paper's own criterion is visual);
/// the contact time against the exact constant 2.86829 (not 2.868).
fn assert_hertz(s: &ImpactSummary, m_star: f64, r_star: f64, e_star: f64, v: f64, what: &str) {
    let d = hertz_max_overlap(m_star, r_star, e_star, v);
    let f = 4.0 / 3.0 * e_star * r_star.sqrt() * d.powf(1.5);
    let tc = hertz_contact_time_exact(m_star, r_star, e_star, v);
    assert!(rel(s.max_overlap_m, d) < 1e-3, "{what}: overlap {} vs {d}", s.max_overlap_m);
    assert!(rel(s.peak_force_n, f) < 1e-3, "{what}: force {} vs {f}", s.peak_force_n);
    assert!(rel(s.contact_time_s, tc) < 1e-3, "{what}: contact time {} vs {tc}", s.contact_time_s);
    assert!((s.restitution_normal - 1.0).abs() < 1e-4, "{what}: e = {}", s.restitution_normal);
}

/// The measured and closed-form peaks and contact time of material `k` (1 or 2).
#[allow(clippy::too_many_arguments)]
fn hertz_rows(rows: &mut Rows, shape: GrainShape, k: f64, s: &ImpactSummary, m_star: f64, r_star: f64, e_star: f64, v: f64) {
    let d = hertz_max_overlap(m_star, r_star, e_star, v);
    rows.add(shape, "", k, "max_overlap_m", s.max_overlap_m, Some(d));
    rows.add(shape, "", k, "peak_force_n", s.peak_force_n, Some(4.0 / 3.0 * e_star * r_star.sqrt() * d.powf(1.5)));
    rows.add(shape, "", k, "contact_time_s", s.contact_time_s, Some(hertz_contact_time_exact(m_star, r_star, e_star, v)));
}

#[test]
fn test_1_two_equal_spheres_head_on_follow_hertz() {
    // R = 10 mm, +-10 m/s; glass (48 GPa, 0.20, 2800 kg/m^3) and limestone (20 GPa, 0.25,
    // 2500 kg/m^3), e = 1.
    let mut rows = Rows::new("test_1");
    for (name, mat) in [("glass", material(48e9, 0.2, 2800.0, 1.0, 0.0)), ("limestone", material(20e9, 0.25, 2500.0, 1.0, 0.0))] {
        for (shape, _) in shapes() {
            let r = 0.01;
            let s = pair((r, mat.clone()), (r, mat.clone()), shape, 20.0, 0.0, [0.0, 0.0], 400.0, false);
            let imp = run(&s);
            let m = shape.mass(r, mat.density);
            let k = if name == "glass" { 1.0 } else { 2.0 };
            hertz_rows(&mut rows, shape, k, &imp, m / 2.0, r / 2.0, PairMaterial::mix(&mat, &mat).e_star, 20.0);
            assert_hertz(&imp, m / 2.0, r / 2.0, PairMaterial::mix(&mat, &mat).e_star, 20.0, &format!("{name} {shape:?}"));
        }
    }
}

#[test]
fn test_2_a_sphere_on_a_rigid_plane_follows_hertz() {
    // R = 0.1 m at 0.2 m/s; aluminium (70 GPa, 0.30, 2699) and magnesium (40 GPa, 0.35,
    // 1800), e = 1: m* = m, R* = r, E* = E / (1 - nu^2).
    let mut rows = Rows::new("test_2");
    for (name, mat) in [("Al", material(70e9, 0.3, 2699.0, 1.0, 0.0)), ("Mg", material(40e9, 0.35, 1800.0, 1.0, 0.0))] {
        for (shape, _) in shapes() {
            let r = 0.1;
            let s = on_plane(mat.clone(), shape, r, 0.2, 0.0, 0.0, 400.0, TangentialSpec::Frictionless, false);
            let imp = run(&s);
            let e_star = mat.youngs_modulus / (1.0 - mat.poisson_ratio * mat.poisson_ratio);
            hertz_rows(&mut rows, shape, if name == "Al" { 1.0 } else { 2.0 }, &imp, shape.mass(r, mat.density), r, e_star, 0.2);
            assert_hertz(&imp, shape.mass(r, mat.density), r, e_star, 0.2, &format!("{name} {shape:?}"));
        }
    }
}

#[test]
fn test_3_the_realised_restitution_is_the_input_one() {
    // R = 2.5 mm at 3.9 m/s on a rigid plane, Al2O3 (380 GPa, 0.23, 4000) and cast iron
    // (100 GPa, 0.25, 7000), e from 0.1 to 1. Without the clamp the beta(e) damping
    // returns e exactly in continuous time; at t_c/1000 the realised e is within a
    // first-order envelope 0.3 dt/t_c (measured n |error|: 0.25 at e = 0.1, 0.21 at 0.3,
    // 0.10 at 0.5, 0.006 at 0.9, the same for both materials and shapes: the error depends
    // on dt/t_c and e alone).
    let mut rows = Rows::new("test_3");
    for mat in [material(380e9, 0.23, 4000.0, 1.0, 0.0), material(100e9, 0.25, 7000.0, 1.0, 0.0)] {
        for (shape, _) in shapes() {
            for e in [0.1, 0.3, 0.5, 0.7, 0.9, 1.0] {
                let s = on_plane(Material { restitution: e, ..mat.clone() }, shape, 2.5e-3, 3.9, 0.0, 0.0, 1000.0, TangentialSpec::Frictionless, false);
                let imp = run(&s);
                rows.add(shape, if mat.youngs_modulus > 2e11 { "Al2O3" } else { "cast_iron" }, e, "restitution_normal", imp.restitution_normal, Some(e));
                assert!((imp.restitution_normal - e).abs() < 0.3 / 1000.0, "E = {} {shape:?} e = {e}: realised {}", mat.youngs_modulus, imp.restitution_normal);
            }
        }
    }
}

#[test]
fn test_3_under_the_clamp_the_clamped_damping_returns_the_input_restitution() {
    // Test 3 with the force clamp (YADE's law, LIGGGHTS `limitForce on`): beta(e) returns
    // more than e there (closed form exp(-2 b acos(b) / sqrt(1 - b^2)), b = |beta(e)|:
    // 0.1 gives 0.253), while model.damping = "clamped_restitution" returns the input e
    // within the same first-order envelope 0.3 dt/t_c at t_c/1000 (tests/restitution_clamped.rs
    // measures its convergence). e = 0.1 to 0.9, both materials and shapes.
    let mut rows = Rows::new("test_3_clamped");
    for mat in [material(380e9, 0.23, 4000.0, 1.0, 0.0), material(100e9, 0.25, 7000.0, 1.0, 0.0)] {
        for (shape, _) in shapes() {
            for e in [0.1, 0.3, 0.5, 0.7, 0.9] {
                let grain = Material { restitution: e, ..mat.clone() };
                let mut s = on_plane(grain.clone(), shape, 2.5e-3, 3.9, 0.0, 0.0, 1000.0, TangentialSpec::Frictionless, true);
                s.model.damping = grainlab::scene::DampingSpec::ClampedRestitution;
                let imp = run(&s);
                rows.add(shape, if mat.youngs_modulus > 2e11 { "Al2O3" } else { "cast_iron" }, e, "restitution_normal", imp.restitution_normal, Some(e));
                assert!((imp.restitution_normal - e).abs() < 0.3 / 1000.0, "E = {} {shape:?} e = {e}: realised {}", mat.youngs_modulus, imp.restitution_normal);
                // The default damping's beta(e) under the clamp: its own closed form.
                let plain = run(&on_plane(grain, shape, 2.5e-3, 3.9, 0.0, 0.0, 1000.0, TangentialSpec::Frictionless, true));
                let closed = grainlab::physics::restitution::clamped_restitution(-grainlab::physics::restitution::beta(e));
                rows.add(shape, if mat.youngs_modulus > 2e11 { "Al2O3_beta_e" } else { "cast_iron_beta_e" }, e, "restitution_normal", plain.restitution_normal, Some(closed));
                assert!((plain.restitution_normal - closed).abs() < 0.3 / 1000.0, "beta(e) under the clamp at e = {e}: realised {}, closed form {closed}", plain.restitution_normal);
                assert!(e != 0.1 || closed > 0.25, "{closed}");
            }
        }
    }
}

/// The gross-sliding identities of one impact on the plane: grain 0's tangential velocity
/// changes by -mu times its normal velocity change (in the direction of the initial slip)
/// and its spin by kappa / r times that; 1e-9 relative leaves room for the rounding of
/// thousands of steps' sums (measured: 1e-13).
fn assert_gross_sliding(s: &Scene, imp: &ImpactSummary, kappa: f64, mu: f64, what: &str) {
    let (dvt, dw_r, closed, closed_w) = gross_sliding(s, imp, kappa, mu);
    let bound = if s.model.tangential == TangentialSpec::MindlinDeresiewicz { MICROSLIP_GROSS } else { 1e-9 };
    assert!(rel(dvt, closed) < bound, "{what}: dvt {dvt} vs -mu dvn {closed}");
    assert!(rel(dw_r, closed_w) < bound, "{what}: r dw {dw_r} vs -kappa mu dvn {closed_w}");
}

/// How close micro-slip comes to the gross-sliding identities: to rounding where the
/// contact slides clear of the threshold (measured 1e-13 and below), 3.9e-7 for the
/// sphere of test 5 at 65 degrees, 2% above it: there the contact point's slip comes to
/// rest as the grain leaves, and the springs that still hold less than their share of mu
/// |Fn| (micro-slip's stick zone) carry less than mu |Fn| for those steps.
const MICROSLIP_GROSS: f64 = 1e-6;

/// Grain 0's tangential velocity change and r times its spin change, and what gross
/// sliding gives for them: `(dvt, r dw, -mu dvn sign, -kappa mu dvn sign)`.
fn gross_sliding(s: &Scene, imp: &ImpactSummary, kappa: f64, mu: f64) -> (f64, f64, f64, f64) {
    let Grains::List(g) = &s.grains else { unreachable!() };
    let (v0, w0, r) = (g[0].v, g[0].omega.z(), g[0].r);
    let slip = (v0[0] + r * w0).signum();
    let dvn = imp.rebound_normal_velocity_m_s - v0[1];
    let dvt = imp.rebound_tangential_velocity_m_s - v0[0];
    let dw = imp.rebound_spin_rad_s - w0;
    assert!(dvn > 0.0);
    (dvt, dw * r, -slip * mu * dvn, -slip * kappa * mu * dvn)
}

#[test]
fn test_4_oblique_impacts_at_constant_speed() {
    // Al2O3, R = 2.5 mm, 3.9 m/s at 5 to 85 degrees from the normal, e = 0.98, mu = 0.092,
    // both tangential formulations, the clamp on. Sliding throughout when
    // tan(angle) >= (1 + kappa) mu (1 + e): from 33 degrees (sphere) and 29 (disk); there
    // the gross-sliding identities hold (measured: to 1e-13), and the tangential restitution of the contact
    // point is e_t = (1 + kappa) mu (1 + e) / tan(angle) - 1 with the realised e. At every
    // angle the rebound keeps the Coulomb bound |dvt| <= mu dvn within the tangential
    // damping's share (the capped elastic force plus damping while sticking: issue 32).
    let mat = material(380e9, 0.23, 4000.0, 0.98, 0.092);
    let mut rows = Rows::new("test_4");
    for form in FORMS {
        for (shape, kappa) in shapes() {
            for a in (1..=17).map(|k| 5.0 * k as f64) {
                let t = a.to_radians();
                let s = on_plane(mat.clone(), shape, 2.5e-3, 3.9 * t.cos(), 3.9 * t.sin(), 0.0, 500.0, form, true);
                let imp = run(&s);
                let what = format!("{form:?} {shape:?} {a} deg");
                let e = imp.restitution_normal;
                let sliding = t.tan() >= (1.0 + kappa) * 0.092 * (1.0 + e);
                let closed = sliding.then(|| (1.0 + kappa) * 0.092 * (1.0 + e) / t.tan() - 1.0);
                rows.add(shape, form_name(form), a, "tangential_restitution", imp.restitution_tangential.unwrap(), closed);
                let spin = sliding.then(|| -kappa * 0.092 * (1.0 + e) * t.cos());
                rows.add(shape, form_name(form), a, "spin_r_over_v", imp.rebound_spin_rad_s * 2.5e-3 / 3.9, spin);
                // Clear of the threshold by 10%: near it the slip reaches zero within the
                // last steps (the disk at 30 degrees, 3% above it, misses by 6e-5).
                let clear = t.tan() >= (1.0 + kappa) * 0.092 * (1.0 + e) * 1.1;
                if clear && form == TangentialSpec::TotalForceCap {
                    // LAMMPS' law keeps the dashpot's force in the spring on slip, and
                    // Hertz's kt grows while loading: the spring then pushes along the
                    // slip and the contact sticks for a few steps, so the friction impulse
                    // falls short of mu J (measured: 1.3e-5 to 5.0e-5 here, e = 0.98), and
                    // never exceeds it (the clamp holds Fn >= 0, so each step's friction
                    // force is at most mu Fn).
                    let (dvt, dw_r, closed, _) = gross_sliding(&s, &imp, kappa, 0.092);
                    assert!((-1e-4..1e-12).contains(&(dvt / closed - 1.0)), "{what}: dvt {dvt} vs -mu dvn {closed}");
                    assert!(rel(dw_r, kappa * dvt) < 1e-9, "{what}: r dw {dw_r} vs kappa dvt {}", kappa * dvt);
                } else if clear {
                    assert_gross_sliding(&s, &imp, kappa, 0.092, &what);
                    let et = imp.restitution_tangential.unwrap();
                    let closed = (1.0 + kappa) * 0.092 * (1.0 + e) / t.tan() - 1.0;
                    assert!((et - closed).abs() < 1e-9, "{what}: e_t {et} vs {closed}");
                }
                let dvn = imp.rebound_normal_velocity_m_s + 3.9 * t.cos();
                let dvt = imp.rebound_tangential_velocity_m_s - 3.9 * t.sin();
                assert!(dvt.abs() <= 0.092 * dvn * 1.01, "{what}: |dvt| {} > mu dvn {}", dvt.abs(), 0.092 * dvn);
            }
        }
    }
}

#[test]
fn test_5_constant_normal_and_varying_tangential_velocity() {
    // Steel (208 GPa, 0.30, 7850), R = 1e-5 m, vn = 5 m/s, vt = vn tan(angle), e = 1
    // (undamped: no attractive force, no clamp needed), mu = 0.3: sliding throughout
    // when tan(angle) >= (1 + kappa) mu (1 + e) = 2.1 (sphere), 1.8 (disk).
    let mat = material(208e9, 0.3, 7850.0, 1.0, 0.3);
    for form in FORMS {
        for (shape, kappa) in shapes() {
            for a in [65.0f64, 70.0, 75.0, 80.0, 85.0] {
                let t = a.to_radians();
                if t.tan() < (1.0 + kappa) * 0.3 * 2.0 * 1.02 {
                    continue;
                }
                let s = on_plane(mat.clone(), shape, 1e-5, 5.0, 5.0 * t.tan(), 0.0, 500.0, form, false);
                let imp = run(&s);
                assert_gross_sliding(&s, &imp, kappa, 0.3, &format!("{form:?} {shape:?} {a} deg"));
            }
        }
    }
}

#[test]
fn test_6_varying_initial_spin() {
    // Al (70 GPa, 0.33, 2700), R = 0.1 m, vn = 0.2 m/s, vt = 0, spin w0, e = 0.5,
    // mu = 0.4, the clamp on: the contact point slips at r w0; sliding throughout when
    // r |w0| / vn >= (1 + kappa) mu (1 + e) (2.1 for the sphere at e = 0.5, more at the
    // clamp's realised e); in gross sliding the rebound tangential velocity would be
    // -mu dvn sign(w0) and the spin drop kappa mu dvn / r.
    let mat = material(70e9, 0.33, 2700.0, 0.5, 0.4);
    let mut rows = Rows::new("test_6");
    for form in FORMS {
        for (shape, kappa) in shapes() {
            for ratio in [-10.0, -4.0, 3.0, 5.0, 10.0] {
                let s = on_plane(mat.clone(), shape, 0.1, 0.2, 0.0, ratio * 0.2 / 0.1, 500.0, form, true);
                let imp = run(&s);
                let e = imp.restitution_normal;
                rows.add(shape, form_name(form), ratio, "vt_over_vn", imp.rebound_tangential_velocity_m_s / 0.2, Some(-ratio.signum() * 0.4 * (1.0 + e)));
                rows.add(shape, form_name(form), ratio, "spin_r_over_vn", imp.rebound_spin_rad_s * 0.1 / 0.2, Some(ratio - ratio.signum() * kappa * 0.4 * (1.0 + e)));
                assert!(f64::abs(ratio) >= (1.0 + kappa) * 0.4 * (1.0 + imp.restitution_normal));
                let what = format!("{form:?} {shape:?} r w0 / vn = {ratio}");
                // At the paper's e = 0.5 the friction impulse exceeds mu J: the damping
                // force resists the approach from the first step, so the cap mu |Fn| starts
                // above the elastic tangential force and the contact sticks at first, when
                // the tangential damping -gt vt adds to it (measured excess: 7.4-8.8% with
                // total displacement, 13-14% with incremental force). Asserted: the excess
                // is that known one (0 to 15%) and the spin follows the tangential impulse
                // (r dw = kappa dvt) to rounding.
                let (dvt, dw_r, closed, _) = gross_sliding(&s, &imp, kappa, 0.4);
                let excess = dvt / closed - 1.0;
                if form == TangentialSpec::TotalForceCapSpringKept {
                    // The cap on the total with the spring kept: the total tangential
                    // force is mu |Fn| at every sliding step and the contact slides from
                    // the first (the dashpot alone exceeds the cap there), so the
                    // identities hold to rounding under damped Hertz (measured: 2.2e-16
                    // sphere, 1.6e-15 disk).
                    assert_gross_sliding(&s, &imp, kappa, 0.4, &what);
                } else if form == TangentialSpec::MindlinDeresiewicz {
                    // Micro-slip caps the total as the spring-kept cap: every spring at its
                    // share of mu |Fn| in gross sliding (measured: 2.2e-16 sphere, 1.6e-15
                    // disk).
                    assert!(excess.abs() < 1e-9, "{what}: friction impulse {excess:e} from mu J");
                } else if form == TangentialSpec::TotalForceCap {
                    // LAMMPS' law caps the total, so the impulse never exceeds mu J (the
                    // clamp holds Fn >= 0); but it keeps the dashpot's force in the spring
                    // on slip, and Hertz's kt (and gt, as sqrt(kt)) grow while loading: the
                    // spring then pushes along the slip and the contact sticks for a while,
                    // 9.2-15.4% short of mu J (measured). With the linear spring (kt and gt
                    // constant) nothing is left over and the identities hold to rounding.
                    assert!((-0.2..1e-12).contains(&excess), "{what}: friction impulse {excess:e} from mu J");
                    let mut s = on_plane(mat.clone(), shape, 0.1, 0.2, 0.0, ratio * 0.2 / 0.1, 500.0, form, true);
                    s.model.normal = NormalLaw::HookeStiffness { kn: 2e8, kt: 1.5e8 };
                    let imp = run(&s);
                    assert_gross_sliding(&s, &imp, kappa, 0.4, &format!("{what}, the given spring"));
                } else {
                    assert!((0.0..0.15).contains(&excess), "{what}: friction impulse {excess:e} above mu J");
                }
                assert!(rel(dw_r, kappa * dvt) < 1e-9, "{what}: r dw {dw_r} vs kappa dvt {}", kappa * dvt);
                // Undamped (e = 1), the contact slides from the first step and the
                // identities hold to rounding.
                let s = on_plane(Material { restitution: 1.0, ..mat.clone() }, shape, 0.1, 0.2, 0.0, ratio * 0.2 / 0.1, 500.0, form, true);
                let imp = run(&s);
                if f64::abs(ratio) >= (1.0 + kappa) * 0.4 * 2.0 * 1.1 {
                    assert_gross_sliding(&s, &imp, kappa, 0.4, &format!("{what}, e = 1"));
                }
            }
        }
    }
}

#[test]
fn test_7_two_equal_spheres_with_opposite_spins_feel_no_tangential_force() {
    // Al, R = 0.1 m, +-0.2 m/s head-on, spins w and -w: the contact points move together
    // (r w + r (-w) = 0), so there is no tangential force at all: the spins and the
    // tangential velocities come out exactly as they went in, for both formulations.
    let mat = material(70e9, 0.33, 2700.0, 0.5, 0.4);
    for form in FORMS {
        for (shape, _) in shapes() {
            let mut s = pair((0.1, mat.clone()), (0.1, mat.clone()), shape, 0.4, 0.0, [3.0, -3.0], 500.0, true);
            s.model.tangential = form;
            let imp = run(&s);
            assert_eq!(imp.rebound_spin_rad_s, 3.0, "{form:?} {shape:?}");
            assert_eq!(imp.rebound_tangential_velocity_m_s, 0.0, "{form:?} {shape:?}");
        }
    }
}

#[test]
fn test_8_a_small_sphere_on_a_larger_denser_one() {
    // A small Al grain (R = 0.05 m) on a larger one (R = 0.1 m) ten times as dense, vn =
    // 0.2 m/s, spin on the small one, e = 0.5, mu = 0.4, the clamp on. Whatever the
    // masses, in gross sliding the small grain's own velocity and spin changes keep the
    // identities; with e = 1 (no damping) they do to the turning of the line of centres.
    let small = material(70e9, 0.33, 2700.0, 0.5, 0.4);
    let large = Material { density: 27000.0, ..small.clone() };
    for form in FORMS {
        for (shape, kappa) in shapes() {
            for w in [-40.0, 40.0] {
                let mut s = pair((0.05, small.clone()), (0.1, large.clone()), shape, 0.2, 0.0, [w, 0.0], 500.0, true);
                s.model.tangential = form;
                let imp = run(&s);
                // Head-on along x: n points from grain 1 to grain 0 (-x), t = (n.y, -n.x)
                // = (0, 1); grain 0 approaches at v0 . n = -v0x. The summary projects the
                // rebound on the line of centres at separation, which the tangential
                // motion has turned by about vt t_c / (r0 + r1) ~ 1e-4 rad: the identities
                // hold to that, not to rounding (1e-3 bound; measured below 3e-4).
                let Grains::List(g) = &s.grains else { unreachable!() };
                let (v0, r) = (g[0].v, g[0].r);
                let dvn = imp.rebound_normal_velocity_m_s + v0[0];
                let slip = (r * w).signum();
                let dvt = imp.rebound_tangential_velocity_m_s;
                let dw = imp.rebound_spin_rad_s - w;
                let what = format!("{form:?} {shape:?} w = {w}");
                // As in test 6, the paper's e = 0.5 gives a friction impulse above mu J
                // (measured 7.4% total displacement, 13% incremental force): asserted
                // within 0 to 15%, and the spin following the tangential impulse.
                let excess = dvt / (-slip * 0.4 * dvn) - 1.0;
                if form == TangentialSpec::TotalForceCapSpringKept {
                    // The cap on the total with the spring kept: mu J to the turning of
                    // the line of centres (measured -2.5e-4 sphere, -4.6e-5 disk), as the
                    // undamped contact below.
                    assert!(excess.abs() < 1e-3, "{what}: friction impulse {excess:e} from mu J");
                } else if form == TangentialSpec::MindlinDeresiewicz {
                    // Micro-slip: as the spring-kept cap (measured -2.5e-4 sphere, -4.6e-5
                    // disk).
                    assert!(excess.abs() < 1e-3, "{what}: friction impulse {excess:e} from mu J");
                } else if form == TangentialSpec::TotalForceCap {
                    // LAMMPS' law: at most mu J (within the 1e-3 of the turning line of
                    // centres), short of it as in test 6 (measured 9.2%).
                    assert!((-0.2..1e-3).contains(&excess), "{what}: friction impulse {excess:e} from mu J");
                } else {
                    assert!((0.0..0.15).contains(&excess), "{what}: friction impulse {excess:e} above mu J");
                }
                assert!(rel(dw * r, kappa * dvt) < 1e-3, "{what}: r dw {} vs kappa dvt {}", dw * r, kappa * dvt);
                assert_eq!(dw.signum(), -slip, "{what}: the spin slows");
                let e1 = |m: &Material| Material { restitution: 1.0, ..m.clone() };
                let mut s = pair((0.05, e1(&small)), (0.1, e1(&large)), shape, 0.2, 0.0, [w, 0.0], 500.0, true);
                s.model.tangential = form;
                let imp = run(&s);
                let dvn = imp.rebound_normal_velocity_m_s + v0[0];
                let dvt = imp.rebound_tangential_velocity_m_s;
                assert!(rel(dvt, -slip * 0.4 * dvn) < 1e-3, "{what}, e = 1: dvt {dvt} vs -mu dvn {}", -slip * 0.4 * dvn);
            }
        }
    }
}

/// One curve of the paper's figures as Kratos digitised them (tests/data/chung_ooi_paper,
/// cited there): its (x, y) points.
fn paper(file: &str, curve: &str) -> Vec<(f64, f64)> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/chung_ooi_paper").join(file);
    let text = std::fs::read_to_string(&path).expect("the digitised curves are committed");
    text.lines()
        .skip(1)
        .filter_map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[0] == curve).then(|| (f[1].parse().unwrap(), f[2].parse().unwrap()))
        })
        .collect()
}

/// Kratos' measure of a curve against the paper's: the sum of absolute differences over
/// the sum of the paper's absolute values.
fn kratos_error(ours: &[f64], paper: &[(f64, f64)]) -> f64 {
    ours.iter().zip(paper).map(|(a, (_, p))| (a - p).abs()).sum::<f64>() / paper.iter().map(|(_, p)| p.abs()).sum::<f64>()
}

/// Test 6 at the paper's abscissa x = 3.5 mu (1 + e) vn / |v_c0| (a sphere on a rigid
/// plane, spin only): beta = -v_c' / v_c0, the contact point's tangential restitution.
fn test_6_beta(x: f64, form: TangentialSpec, damping: DampingSpec) -> f64 {
    let mat = material(70e9, 0.33, 2700.0, 0.5, 0.4);
    let ratio = 3.5 * 0.4 * 1.5 / x;
    let mut s = on_plane(mat, GrainShape::SphereInPlane, 0.1, 0.2, 0.0, -ratio * 0.2 / 0.1, 500.0, form, true);
    s.model.damping = damping;
    let imp = run(&s);
    let vc0 = -ratio * 0.2;
    -(imp.rebound_tangential_velocity_m_s + 0.1 * imp.rebound_spin_rad_s) / vc0
}

/// Test 5 at the paper's abscissa x = tan(angle) / mu (steel, R = 10 um, vn = 5 m/s,
/// e = 1): the rebound spin r w' / (mu vn).
fn test_5_spin(x: f64, form: TangentialSpec) -> f64 {
    let mat = material(208e9, 0.3, 7850.0, 1.0, 0.3);
    let s = on_plane(mat, GrainShape::SphereInPlane, 1e-5, 5.0, 5.0 * 0.3 * x, 0.0, 500.0, form, false);
    let imp = run(&s);
    1e-5 * imp.rebound_spin_rad_s / (0.3 * 5.0)
}

#[test]
fn tests_5_and_6_meet_the_papers_curves_within_kratos_tolerance() {
    // The paper's curves (Kratos' digitisation), measured as Kratos measures them and
    // against its bounds: test 6's first six points (x = 0.19 to 1.21, beta; 3%), where
    // the contact slides, and test 5's finite-element points (the spin; 2%).
    // Test 6 with the variants that model what the paper assumes: the realised e is the
    // input 0.5 (the clamped damping) and the friction impulse mu J (the spring-kept cap,
    // micro-slip): measured 2.6% and 1.7%. Of the spring-kept cap's, 1.1 points come from
    // the sixth point (x = 1.21, past the sliding threshold, where the paper's micro-slip
    // acts: micro-slip's own gap there is 0.4 points) and 1.5 from the five sliding ones,
    // the digitisation's own scatter (the closed form x - 1 is 1.5% from them, and these
    // runs within 1.5e-4 of it). The other formulations miss it (15-37%: the friction
    // impulse is not mu J under damped Hertz), the control.
    // Test 5 is undamped (e = 1): every formulation slides alike at x = 7 to 19 (0.71%);
    // over the whole diagram, sticking regime included, micro-slip meets the
    // finite-element curve (measured 1.25%; 1.63% over the 13 points at x <= 5.7, where
    // the contact sticks for part of the impact), the no-slip springs do not (12-13% over
    // those points: their contact point keeps 0.96 of its slip velocity at small
    // angles, the finite element's and micro-slip's about 0.2).
    // The whole diagrams are written for the plots of docs/benchmarks.md; test 6's
    // sticking regime is not asserted (39-66% for every formulation: docs/benchmarks.md).
    let mut rows = Rows::new("paper");
    let t6 = paper("test6_beta.csv", "test6");
    for form in FORMS {
        let ours: Vec<f64> = t6.iter().map(|&(x, _)| test_6_beta(x, form, DampingSpec::ClampedRestitution)).collect();
        for (&(x, p), &b) in t6.iter().zip(&ours) {
            rows.add(GrainShape::SphereInPlane, form_name(form), x, "test6_beta", b, Some(p));
        }
        let err6 = kratos_error(&ours[..6], &t6[..6]);
        if matches!(form, TangentialSpec::TotalForceCapSpringKept | TangentialSpec::MindlinDeresiewicz) {
            assert!(err6 < 0.03, "test 6, {form:?}: {err6:e} of the paper's curve (Kratos' bound 3%)");
        } else {
            assert!(err6 > 0.1, "test 6, {form:?}: {err6:e}, the control: the friction impulse is not mu J here");
        }
    }
    let fem = paper("test5_spin.csv", "fem");
    let sliding = &fem[fem.len() - 4..];
    for form in FORMS {
        let ours: Vec<f64> = sliding.iter().map(|&(x, _)| test_5_spin(x, form)).collect();
        let err5 = kratos_error(&ours, sliding);
        assert!(err5 < 0.02, "test 5, {form:?}: {err5:e} of the paper's curve (Kratos' bound 2%)");
        // The whole diagram, sticking regime included: micro-slip models what the
        // finite-element reference computes (elastic spheres with Coulomb friction over
        // the contact area); the no-slip springs are the control.
        let whole: Vec<f64> = fem.iter().map(|&(x, _)| test_5_spin(x, form)).collect();
        let (err_whole, err_stick) = (kratos_error(&whole, &fem), kratos_error(&whole[..13], &fem[..13]));
        if form == TangentialSpec::MindlinDeresiewicz {
            assert!(err_whole < 0.02 && err_stick < 0.02, "test 5 whole diagram, micro-slip: {err_whole:e}, sticking part {err_stick:e} (Kratos' bound 2%)");
        } else {
            assert!(err_stick > 0.1, "test 5 sticking part, {form:?}: {err_stick:e}, the control: no-slip springs miss it");
        }
        for (&(x, p), &b) in fem.iter().zip(&whole) {
            rows.add(GrainShape::SphereInPlane, form_name(form), x, "test5_fem_spin", b, Some(p));
        }
        for &(x, p) in &paper("test5_spin.csv", "steel") {
            rows.add(GrainShape::SphereInPlane, form_name(form), x, "test5_spin", test_5_spin(x, form), Some(p));
        }
    }
}
