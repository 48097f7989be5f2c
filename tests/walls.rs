//! Walls and gravity: a grain comes to rest on a flat wall.

use grainlab::material::Material;
use grainlab::run::{RunOptions, run_built};
use grainlab::scene::{Analysis, TangentialSpec};
use grainlab::scenes::oblique;

#[test]
fn a_grain_settles_on_a_flat_wall_under_gravity() {
    // Dropped at 0.1 m/s with e = 0.3, it bounces and settles; at rest the wall carries
    // its weight (static equilibrium, to 1e-6 once the damped oscillation has died out)
    // and the energy balance, now with the work of gravity, closes to 1e-4 at 200 steps
    // per contact (the O(dt^2) residual is 4.6e-4 at 50 steps, so 1/16 of it here).
    let g = Material { restitution: 0.3, ..Material::default() };
    let mut s = oblique(g, 1e-3, 0.1, 0.0, TangentialSpec::TotalDisplacement, 200.0);
    s.gravity = [0.0, -9.81];
    s.analysis = Analysis::None;
    s.duration = 0.05;
    let built = grainlab::build(&s).unwrap();
    let m = built.engine.particles().m[0];
    let out = run_built(&s, built, &RunOptions::default()).unwrap();
    let en = out.energy.unwrap();
    assert!(en.max_residual_rel < 1e-4, "{en:?}");
    assert!(en.final_row.work_gravity_j > 0.0);
    // The same run step by step, to read the final wall force.
    let mut built = grainlab::build(&s).unwrap();
    let steps = (s.duration / built.time_step.dt_s) as u64;
    for _ in 0..steps {
        built.engine.step().unwrap();
    }
    let wall = &built.engine.walls()[0];
    let weight = m * 9.81;
    assert!((-wall.force.y - weight).abs() < 1e-6 * weight, "wall carries {} N, weight {weight} N", -wall.force.y);
    assert!(built.engine.particles().v[0].norm() < 1e-6);
}
