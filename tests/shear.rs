//! The shear cell: energy balance and the confining stress.

use grainlab::study::run::{RunOptions, run_scene};
use grainlab::scene::ControlSpec;
use grainlab::scene::builtin::shear;

#[test]
fn energy_balance_closes_in_a_short_shear_run() {
    // Every work term is a trapezoidal integral consistent with velocity Verlet: the
    // residual is the integrator's O(dt^2) error, bounded by 1e-3 of the energy put in
    // (the bound) at the default 50 steps per contact.
    let mut s = shear();
    s.duration = 1e-3;
    s.output.frames = 0;
    let out = run_scene(&s, &RunOptions::default()).unwrap();
    let en = out.energy.unwrap();
    assert!(en.max_residual_rel < 1e-3, "{en:?}");
    // The walls did work and it went somewhere.
    assert!(en.final_row.work_walls_j > 0.0);
    assert!(en.final_row.dissipated_friction_j > 0.0);
}

#[test]
fn the_loaded_wall_carries_the_requested_stress() {
    // Averaged over the second half of a short run, the normal stress the grains exert on
    // the walls equals the applied pressure within its 95% interval plus 10% (the wall is
    // still settling; the interval's blocks are cut from the measured autocorrelation).
    let mut s = shear();
    s.duration = 4e-3;
    s.output.frames = 0;
    let p = match s.walls.as_ref().unwrap().top.control {
        ControlSpec::Pressure(p) => p,
        _ => unreachable!(),
    };
    let out = run_scene(&s, &RunOptions::default()).unwrap();
    let sh = out.shear.unwrap();
    let sigma = sh.normal_stress_pa;
    assert!((sigma.mean - p).abs() < sigma.ci95 + 0.1 * p, "{sigma:?} vs {p}");
    let ratio = sh.stress_ratio.expect("tau/sigma is defined under a load");
    assert!(ratio.mean > 0.1 && ratio.mean < 0.5, "{ratio:?}");
}
