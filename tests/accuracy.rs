//! Accuracy against cost: the sweep, and the accuracy-targeted time step.

use grainlab::scene::AccuracyQuantity;
use grainlab::study::accuracy::{calibrate, ladder};
use grainlab::build;
use grainlab::physics::material::{Material, PairMaterial, hertz_contact_time_exact, hertz_max_overlap};
use grainlab::study::run::{RunOptions, run_scene};
use grainlab::scene::TimeStepRule;
use grainlab::scene::builtin::head_on;
use grainlab::study::sweep::{Step, SweepPlan, sweep};

fn glass(e: f64) -> Material {
    Material { restitution: e, ..Material::default() }
}

fn restitution(steps: f64) -> f64 {
    run_scene(&head_on(glass(0.5), 1e-3, 1.0, steps), &RunOptions::default()).unwrap().impact.unwrap().restitution_normal
}

#[test]
fn the_accuracy_rule_picks_the_largest_step_that_meets_the_tolerance() {
    // Independently of the calibration's own bookkeeping: rerun the impact at the chosen
    // step and at 8192 steps per contact; the error is within the tolerance, and the next
    // coarser step of the ladder misses it (else the choice was not the largest dt).
    for tol in [1e-2, 1e-3, 3e-4] {
        let cal = calibrate(&glass(0.5), 1e-3, 1.0, false, AccuracyQuantity::Restitution, tol).unwrap();
        let converged = restitution(8192.0);
        let err = (restitution(cal.steps_per_contact) - converged).abs();
        assert!(err <= tol, "tol {tol}: t_c/{} gives {err}", cal.steps_per_contact);
        let l = ladder();
        let k = l.iter().position(|&n| n == cal.steps_per_contact).unwrap();
        if k > 0 {
            assert!(cal.ladder[..k].iter().any(|&(_, e)| e > tol), "tol {tol}: a coarser step met it too");
        }
    }
}

#[test]
fn a_scene_can_ask_for_an_accuracy_and_explain_says_what_was_chosen() {
    let mut s = head_on(glass(0.5), 1e-3, 1.0, 50.0);
    s.time_step.rule = TimeStepRule::Accuracy { quantity: AccuracyQuantity::Restitution, tolerance: 1e-3, impact_speed: 1.0 };
    let b = build(&s).unwrap();
    let note = b.time_step.accuracy.expect("the rule is reported");
    assert!(note.measured_error <= 1e-3);
    assert!(b.explain().contains("restitution error (abs) <= 1e-3"), "{}", b.explain());
    // Too tight a tolerance is refused, naming the field and what can be reached.
    s.time_step.rule = TimeStepRule::Accuracy { quantity: AccuracyQuantity::Restitution, tolerance: 1e-12, impact_speed: 1.0 };
    let err = build(&s).err().expect("refused").to_string();
    assert!(err.contains("time_step.rule.accuracy.tolerance"), "{err}");
}

fn collision_plan(steps: &[f64], stiffness: &[f64]) -> SweepPlan {
    SweepPlan { steps: steps.iter().map(|&n| Step::PerContact(n)).collect(), stiffness: stiffness.to_vec(), repeats: 3, ..SweepPlan::default() }
}

#[test]
fn the_time_step_sweep_measures_errors_against_a_richardson_reference_it_can_trust() {
    // The reference comes from t_c/400 and t_c/800, finer than any listed row: no row
    // reads an error of 0. Without the clamp the continuous-time law returns the input
    // e exactly, an independent value the reference must match within the uncertainty it
    // states. The restitution's error wobbles with the contact's phase between steps
    // (tests/impacts.rs: about 0.1 dt/t_c at most), so no order is believed there; the
    // contact time converges cleanly at the first order that detecting a contact at
    // whole steps gives.
    let s = head_on(glass(0.5), 1e-3, 1.0, 50.0);
    let rows = sweep(&s, &collision_plan(&[25.0, 50.0, 100.0, 200.0], &[]), &Default::default(), |_| {}).unwrap();
    assert_eq!(rows.len(), 4);
    for r in &rows {
        assert!(r.restitution_err.unwrap() > 0.0, "{r:?}");
        assert!(r.restitution_err_input.unwrap() < 0.15 / r.steps_per_contact, "{r:?}");
        assert_eq!((r.timings, r.runs), (3, 1));
        assert!(r.wall_time_min_s <= r.wall_time_s && r.wall_time_s <= r.wall_time_max_s && r.wall_time_min_s > 0.0);
        assert_eq!(r.reference_runs, "t_c/400, t_c/800");
    }
    let r = &rows[3];
    let (reference, u) = (r.restitution_reference.unwrap(), r.restitution_reference_uncertainty.unwrap());
    assert!((reference - 0.5).abs() <= u && u < 5e-4, "reference {reference} +- {u}");
    let order = r.contact_time_order.unwrap_or_else(|| panic!("no order measured: {r:?}"));
    assert!((0.8..1.3).contains(&order), "order {order}");
    // A shear quantity does not apply to an impact: empty, not NaN.
    assert!(rows.iter().all(|r| r.stress_ratio.is_none() && r.stress_ratio_err.is_none() && r.stiffness_number.is_none()));
    assert!(rows[0].energy_residual_rel > rows[3].energy_residual_rel);
}

#[test]
fn the_elastic_references_agree_with_hertz_in_closed_form() {
    // e = 1: the references of the peak force, largest overlap and contact time, each
    // extrapolated from the sweep's own runs, against Hertz's closed forms (the contact
    // time's constant exact, 2.86829...): within the uncertainty each reference states,
    // and that uncertainty small (Verlet's second order at t_c/1600 leaves ~1e-7).
    let s = head_on(glass(1.0), 1e-3, 1.0, 50.0);
    let rows = sweep(&s, &collision_plan(&[100.0, 200.0, 400.0], &[]), &Default::default(), |_| {}).unwrap();
    let r = &rows[2];
    let m = glass(1.0);
    let (mass, e_star) = (4.0 / 3.0 * std::f64::consts::PI * 1e-9 * m.density, PairMaterial::mix(&m, &m).e_star);
    let d = hertz_max_overlap(mass / 2.0, 5e-4, e_star, 1.0);
    let hertz = [4.0 / 3.0 * e_star * 5e-4f64.sqrt() * d.powf(1.5), d, hertz_contact_time_exact(mass / 2.0, 5e-4, e_star, 1.0)];
    let refs = [
        ("peak force", r.peak_force_reference, r.peak_force_reference_uncertainty),
        ("max overlap", r.max_overlap_reference, r.max_overlap_reference_uncertainty),
        ("contact time", r.contact_time_reference, r.contact_time_reference_uncertainty),
    ];
    for ((name, reference, u), closed) in refs.into_iter().zip(hertz) {
        let (reference, u) = (reference.unwrap(), u.unwrap());
        assert!((reference - closed).abs() <= u.max(1e-12 * closed) && u / closed < 1e-5, "{name}: reference {reference} +- {u}, Hertz {closed}");
    }
    // The exact constant of the contact time against the rounded one of the time step rules.
    approx::assert_relative_eq!(hertz_contact_time_exact(1.0, 1.0, 1.0, 1.0), 2.868, max_relative = 2e-4);
}

#[test]
fn softer_grains_leave_the_collision_restitution_alone_and_scale_its_overlap_as_hertz_says() {
    // Hertz with the beta(e) damping has no stiffness in its dimensionless form: at a
    // fixed number of steps per contact the restitution is the same for any E (to the
    // discretisation wobble, ~1e-5 at t_c/2000), and the overlap scales as E^(-2/5).
    let s = head_on(glass(0.5), 1e-3, 1.0, 2000.0);
    let mut plan = collision_plan(&[2000.0], &[1e-3, 0.1, 1.0]);
    plan.duration = Some(1.0); // the run stops at separation
    let rows = sweep(&s, &plan, &Default::default(), |_| {}).unwrap();
    assert_eq!(rows.len(), 3);
    let e: Vec<f64> = rows.iter().map(|r| r.restitution.unwrap()).collect();
    assert!(e.iter().all(|x| (x - e[2]).abs() < 1e-4), "{e:?}");
    let ratio = rows[0].overlap_rel.unwrap() / rows[2].overlap_rel.unwrap();
    approx::assert_relative_eq!(ratio, 1000f64.powf(0.4), max_relative = 1e-3);
    // The rigid limit of the restitution: extrapolated from x2 and x4, and the input e
    // within its stated uncertainty; a peak force has no rigid limit (empty).
    let r = &rows[2];
    assert_eq!(r.reference_runs, "stiffness x2, stiffness x4");
    let (reference, u) = (r.restitution_reference.unwrap(), r.restitution_reference_uncertainty.unwrap());
    assert!((reference - 0.5).abs() <= u + 1e-4 && u < 1e-3, "{reference} +- {u}");
    assert!(rows.iter().all(|r| r.peak_force_reference.is_none() && r.peak_force_err_rel.is_none()));
    // Without --duration the impact of the softest grains outlasts the scene's duration
    // (set for glass): refused, naming the option, not a row of empty values.
    let err = sweep(&s, &collision_plan(&[2000.0], &[1e-3, 1.0]), &Default::default(), |_| {}).unwrap_err().to_string();
    assert!(err.contains("--duration") && err.contains("stiffness x0.001"), "{err}");
}

#[test]
fn a_sweep_moves_one_lever_and_refuses_what_it_cannot_run() {
    let s = head_on(glass(0.5), 1e-3, 1.0, 50.0);
    let limits = Default::default();
    let refused = |plan: SweepPlan, option: &str| {
        let err = sweep(&s, &plan, &limits, |_| {}).unwrap_err().to_string();
        assert!(err.contains(option), "{option}: {err}");
    };
    refused(collision_plan(&[], &[]), "--steps");
    refused(collision_plan(&[50.0, 100.0], &[0.1, 1.0]), "one lever per sweep");
    refused(collision_plan(&[50.0], &[0.0, 1.0]), "--stiffness");
    refused(SweepPlan { repeats: 0, ..collision_plan(&[50.0], &[]) }, "--repeats");
    refused(SweepPlan { seeds: vec![3], ..collision_plan(&[50.0], &[]) }, "--seeds");
    // Seeds need a packing: an ensemble of a listed pair is refused by the ensemble.
    refused(SweepPlan { seeds: vec![1, 2], ..collision_plan(&[50.0], &[]) }, "grains.pack");
}

#[test]
fn softening_a_sheared_packing_raises_its_overlap_as_the_stiffness_number_falls() {
    // 300 grains, 1.5 ms, 3 packings per point: at the same confining stress a contact's
    // overlap over radius goes as (F / (E* r^2))^(2/3), so softening E by 0.03 raises the
    // mean overlap by 0.03^(-2/3) = 10.4 and lowers the stiffness number (E*/sigma)^(2/3)
    // by as much. The force distribution of two packings is not the same one (25% for the
    // overlap); sigma is the wall's measured load, which at 1.5 ms is still settling, the
    // soft packing's more (11% apart here; 0.1% at 40 ms in
    // docs/accuracy-cost/shear-stiffness.csv): 15% for the stiffness number.
    let scene = grainlab::scene::builtin::shear_cell(300, 0.012);
    let plan = SweepPlan { stiffness: vec![0.03, 1.0], seeds: vec![1, 2, 3], duration: Some(1.5e-3), ..SweepPlan::default() };
    let mut heard = Vec::new();
    let rows = sweep(&scene, &plan, &Default::default(), |line| heard.push(line.to_string())).unwrap();
    // Two listed points and two references, each of three runs told as they end.
    let points = heard.iter().filter(|l| l.contains(" listed ") || l.contains(" reference ")).count();
    let runs = heard.iter().filter(|l| l.trim_start().starts_with("seed ")).count();
    assert_eq!((rows.len(), points, runs), (2, 4, 12), "{heard:?}");
    let (soft, glass) = (&rows[0], &rows[1]);
    let expected = 0.03f64.powf(-2.0 / 3.0);
    let overlap = soft.overlap_rel.unwrap() / glass.overlap_rel.unwrap();
    assert!((overlap / expected - 1.0).abs() < 0.25, "overlap ratio {overlap}, Hertz {expected}");
    let kappa = glass.stiffness_number.unwrap() / soft.stiffness_number.unwrap();
    assert!((kappa / expected - 1.0).abs() < 0.15, "stiffness number ratio {kappa}");
    assert!(glass.overlap_rel.unwrap() < 2e-3, "glass at 100 kPa: {:?}", glass.overlap_rel);
    // Ensemble rows: three runs each, timed by their median, with intervals.
    for r in &rows {
        assert_eq!((r.runs, r.timings), (3, 3));
        assert!(r.stress_ratio_ci95.unwrap() > 0.0 && r.packing_fraction_ci95.unwrap() > 0.0);
        assert!(r.stress_ratio_reference_uncertainty.unwrap() > 0.0, "{r:?}");
    }
}
