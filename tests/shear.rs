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

/// `statistics` is refused by name: its JSON path, the value and what is allowed.
#[test]
fn statistics_out_of_range_are_refused_by_name() {
    let scene = |statistics: serde_json::Value| {
        let mut v = serde_json::to_value(shear()).unwrap();
        v["statistics"] = statistics;
        grainlab::Scene::from_json(&v.to_string()).and_then(|s| s.validate().map(|()| s))
    };
    let refused = |statistics: serde_json::Value, expect: &str| {
        let e = scene(statistics).unwrap_err().to_string();
        assert!(e.contains(expect), "expected `{expect}` in: {e}");
    };
    refused(serde_json::json!({"average_from": 1.0}), "statistics.average_from = 1; allowed: a fraction of the averaged rows, 0 <= f < 1");
    refused(serde_json::json!({"blocks": 1}), "statistics.blocks = 1; allowed: \"auto\", or 2 to 1000 blocks");
    refused(serde_json::json!({"blocks": "many"}), "at `statistics.blocks`: invalid value: string \"many\", expected \"auto\" or a number of blocks (2 to 1000)");
    refused(serde_json::json!({"blocks": -3}), "expected \"auto\" or a number of blocks (2 to 1000)");
    let s = scene(serde_json::json!({"blocks": 12, "average_from": 0.25})).unwrap();
    assert_eq!((s.statistics.blocks, s.statistics.average_from), (grainlab::scene::BlocksSpec::Count(12), 0.25));
    assert_eq!(scene(serde_json::json!({})).unwrap().statistics, grainlab::scene::StatisticsSpec::default());
}

#[test]
fn the_arm_to_the_contact_point_keeps_the_energy_balance() {
    // lever_arm contact_point (YADE's ViscElPhys kinematics) puts one arm in the contact
    // velocity and in the torque (r - dn/2 between grains, r - dn on a flat wall), so the
    // torque's work is the tangential force's on the contact's motion and the ledger
    // closes: on an oblique impact on a flat wall (the linear spring, 30 deg, e = 0.9,
    // mu = 0.5, t_c/200: sticking, then sliding), within 5e-5 of the energy put in, as
    // the other consistent arms. Control: lever_arm yade (velocity arm r, torque arm
    // r - dn on a wall) leaves the O(dn/r) mismatch, over 10x more. Measured: contact_point
    // 1.61e-5, radius_minus_half_overlap 1.51e-5, radius 1.40e-5, yade 8.6e-4.
    use grainlab::physics::contact::LeverArm;
    let residual = |lever: LeverArm| {
        let form = grainlab::scene::TangentialSpec::IncrementalForce;
        let mut s = grainlab::scene::builtin::oblique(grainlab::physics::material::Material::default(), 1e-3, 1.0, 30.0, form, 200.0);
        s.model.lever_arm = lever;
        s.model.normal = grainlab::scene::NormalLaw::HookeStiffness { kn: 2e5, kt: 1.5e5 };
        run_scene(&s, &RunOptions::default()).unwrap().energy.unwrap().max_residual_rel
    };
    let (cp, y) = (residual(LeverArm::ContactPoint), residual(LeverArm::Yade));
    assert!(cp < 5e-5, "contact_point: residual {cp:e}");
    assert!(y > 10.0 * cp, "the control: yade's residual {y:e} against {cp:e}");
}

#[test]
fn lammps_tangential_law_keeps_the_energy_balance_in_a_short_shear_run() {
    // model.tangential = total_force_cap (LAMMPS' law: the cap on the total tangential
    // force, the dashpot's force kept in the spring on slip, the history rescaled when the
    // frame turns) splits its force into the spring's -kt xi and the dashpot's -gt vt:
    // the ledger closes as for the other formulations (1e-3 of the energy put in, the
    // issue's bound, with an energy-consistent arm: radius), also against the walls' and
    // the load's work alone. Friction takes what slips remove from the springs; a slip
    // that stores the dashpot's force loads the spring, which the ledger counts as the
    // law's own work W_t (measured in this 1 ms: W_t 9.7e-3 J against 6.4e-3 J from the
    // walls and the load; friction 7.8e-4 J, tangential damping 1.29e-2 J; residual
    // -1.0e-6 J, 1.6e-4 of the walls' and load's work).
    balance_closes_in_a_short_run(grainlab::scene::TangentialSpec::TotalForceCap);
}

/// 1 ms of the shear cell under `form` (arm radius): the ledger closes to 1e-3 of the
/// energy put in, also against the walls' and the load's work alone, and friction and the
/// tangential damping both dissipate.
fn balance_closes_in_a_short_run(form: grainlab::scene::TangentialSpec) {
    let mut s = shear();
    s.duration = 1e-3;
    s.output.frames = 0;
    s.model.tangential = form;
    let out = run_scene(&s, &RunOptions::default()).unwrap();
    let en = out.energy.unwrap();
    assert!(en.max_residual_rel < 1e-3, "{form:?}: {en:?}");
    let row = en.final_row;
    assert!(row.residual_j.abs() < 1e-3 * (row.work_walls_j + row.work_load_j), "{form:?}: {row:?}");
    assert!(row.dissipated_friction_j > 0.0 && row.dissipated_tangential_damping_j > 0.0, "{form:?}: {row:?}");
}

#[test]
fn spring_kept_force_cap_keeps_the_energy_balance_in_a_short_shear_run() {
    // model.tangential = total_force_cap_spring_kept (the cap on the total tangential
    // force, the spring's own displacement kept on slip, the dashpot taking the rest):
    // the ledger closes as for the other formulations (1e-3 of the energy put in, with the
    // energy-consistent arm: radius), against the walls' and the load's work alone.
    // Friction takes what slips remove from the springs; the dashpot's share of a sliding
    // force acts against the slip, so the tangential damping dissipates (measured in this
    // 1 ms: friction 4.45e-3 J, tangential damping 3.4e-4 J, W_t 8.6e-4 J (kt changing
    // under loaded springs) against 6.31e-3 J from the walls and the load; residual
    // -1.0e-6 J, 1.6e-4 of it).
    balance_closes_in_a_short_run(grainlab::scene::TangentialSpec::TotalForceCapSpringKept);
}

#[test]
fn micro_slip_keeps_the_energy_balance_in_a_short_shear_run() {
    // model.tangential = mindlin_deresiewicz (a bed of springs across each contact's Hertz
    // radius, each slipping at its share of mu |Fn|): the ledger closes as for the other
    // formulations (1e-3 of the energy put in), against the walls' and the load's work
    // alone. Friction takes what the springs' slips remove; the ledger's stored tangential
    // energy is |Ft|^2 / (2 kt), below the bed's, and W_t holds the difference (measured
    // in this 1 ms: friction 4.18e-3 J, tangential damping 3.4e-4 J, W_t 6.5e-4 J against
    // 6.11e-3 J from the walls and the load; residual -9.9e-7 J, 1.6e-4 of it).
    balance_closes_in_a_short_run(grainlab::scene::TangentialSpec::MindlinDeresiewicz);
}
