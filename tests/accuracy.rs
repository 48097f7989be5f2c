//! Accuracy against cost: the sweep, and the accuracy-targeted time step.

use grainlab::scene::AccuracyQuantity;
use grainlab::study::accuracy::{calibrate, ladder};
use grainlab::build;
use grainlab::physics::material::Material;
use grainlab::study::run::{RunOptions, run_scene};
use grainlab::scene::TimeStepRule;
use grainlab::scene::builtin::head_on;
use grainlab::study::sweep::{Step, Variant, sweep};

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

#[test]
fn the_sweep_measures_errors_against_converged_and_closed_form() {
    // Without the clamp the realised e tends to the input e at first order: the sweep's
    // error against the input must stay in the envelope 0.15 dt/t_c (tests/impacts.rs),
    // and its error against its own finest run is zero there by definition.
    let s = head_on(glass(0.5), 1e-3, 1.0, 50.0);
    let steps: Vec<Step> = [50.0, 100.0, 200.0, 400.0].iter().map(|&n| Step::PerContact(n)).collect();
    let rows = sweep(&s, &steps, &[Variant::Scene], None, &Default::default(), |_| {}).unwrap();
    assert_eq!(rows.len(), 4);
    for r in &rows {
        assert!(r.restitution_err_input.unwrap() < 0.15 / r.steps_per_contact, "{r:?}");
        assert!(r.wall_time_s > 0.0 && r.ns_per_particle_step > 0.0);
    }
    assert_eq!(rows[3].restitution_err_converged, Some(0.0));
    // A shear quantity does not apply to an impact: empty, not NaN.
    assert!(rows.iter().all(|r| r.stress_ratio.is_none() && r.stress_ratio_err_converged.is_none()));
    assert!(rows[0].energy_residual_rel > rows[3].energy_residual_rel);
}
