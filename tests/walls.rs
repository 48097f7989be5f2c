//! Walls and gravity: a grain comes to rest on a flat wall.

use grainlab::physics::material::Material;
use grainlab::study::run::{RunOptions, run_built};
use grainlab::scene::{Analysis, TangentialSpec};
use grainlab::scene::builtin::oblique;

#[test]
fn a_grain_settles_on_a_flat_wall_under_gravity() {
    // Dropped at 0.1 m/s with e = 0.3, it bounces and settles; at rest the wall carries
    // its weight (static equilibrium, to 1e-6 once the damped oscillation has died out)
    // and the energy balance, now with the work of gravity, closes to 1e-4 at 200 steps
    // per contact (the O(dt^2) residual is 4.6e-4 at 50 steps, so 1/16 of it here).
    let g = Material { restitution: 0.3, ..Material::default() };
    let mut s = oblique(g, 1e-3, 0.1, 0.0, TangentialSpec::TotalDisplacement, 200.0);
    s.gravity = [0.0, -9.81].into();
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

/// Each flat wall contacts the grains with its own material. A glass bead dropped head-on
/// onto a soft bottom wall, under a glass top wall it never touches: the rebound and the
/// contact time are those of the bead against the bottom wall's material. (The engine
/// had used the top wall's material for both walls: e = 0.9 and the glass contact time.)
#[test]
fn each_flat_wall_contacts_with_its_own_material() {
    use grainlab::physics::material::{PairMaterial, hertz_contact_time};
    let glass = Material { restitution: 0.9, ..Material::default() };
    let soft = Material { name: "soft".into(), youngs_modulus: 6.3e8, restitution: 0.3, ..Material::default() };
    let impact_on_bottom = |bead: &Material, bottom: &Material| {
        let mut s = oblique(bead.clone(), 1e-3, 1.0, 0.0, TangentialSpec::TotalDisplacement, 200.0);
        s.materials.push(bottom.clone());
        s.walls.as_mut().unwrap().bottom.material = 1;
        // The soft contact lasts several glass contact times; the run stops at separation.
        s.duration *= 10.0;
        let built = grainlab::build(&s).unwrap();
        let m = built.engine.particles().m[0];
        (run_built(&s, built, &RunOptions::default()).unwrap().impact.unwrap(), m)
    };
    // Damped: the realised e converges to the pair's input e (the smaller of the two,
    // 0.3) at O(dt/t_c); at 200 steps per contact it is within a few 1e-4 of it
    // (tests/impacts.rs), so 5e-3 leaves room and still tells 0.3 from 0.9.
    let (damped, _) = impact_on_bottom(&glass, &soft);
    assert!((damped.restitution_normal - 0.3).abs() < 5e-3, "e = {}", damped.restitution_normal);
    // Elastic: the contact lasts the Hertz time of the bead against the soft wall
    // (R* = r, m* = m, E* of glass and the soft material): 3.6 times the glass-wall
    // time here. Measured to well under 1% at 200 steps per contact (tests/impacts.rs
    // holds the closed form to 1e-3).
    let (bead, elastic) = (Material { restitution: 1.0, ..glass }, Material { restitution: 1.0, ..soft });
    let (hit, m) = impact_on_bottom(&bead, &elastic);
    let e_star = PairMaterial::mix(&bead, &elastic).e_star;
    let tc = hertz_contact_time(m, 1e-3, e_star, 1.0);
    assert!((hit.contact_time_s / tc - 1.0).abs() < 2e-3, "contact time {} s, Hertz {tc} s", hit.contact_time_s);
}
