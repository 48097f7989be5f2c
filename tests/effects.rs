//! Effects derived from the scene's values (docs/model.md, "Effects"): a switch the
//! scene's numbers imply gives the bits of the same switch declared. Each test runs two
//! scenes that differ only in how the effect is turned off and requires identical
//! energy.csv and walls.csv (bytes), the same pipeline, and the same time step: the
//! derived switch must select exactly the declared one's kernel and stages.

use grainlab::physics::material::Material;
use grainlab::scene::builtin;
use grainlab::scene::{Scene, TangentialSpec};
use grainlab::{RunOptions, run_scene};

/// The shear cell, short (400 steps at its dt), with the energy ledger and a row every
/// 20 steps: enough contacts, releases and wall motion to tell two kernels apart.
fn short_shear() -> Scene {
    let mut s = builtin::shear_cell(200, 0.008);
    s.duration = 400.0 * 5.8e-8;
    s.output.samples = 20;
    s.output.frames = 0;
    s.output.energy = true;
    s
}

/// Run `scene` into a fresh folder; its energy.csv and walls.csv, pipeline and dt.
fn outputs(scene: &Scene) -> (Vec<u8>, Vec<u8>, String, f64) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let summary = run_scene(scene, &RunOptions { out: Some(out.clone()), ..Default::default() }).unwrap();
    let read = |f: &str| std::fs::read(out.join(f)).unwrap();
    (read("energy.csv"), read("walls.csv"), summary.pipeline, summary.time_step.dt_s)
}

fn with_friction(mut s: Scene, mu: f64) -> Scene {
    for m in &mut s.materials {
        m.friction = mu;
    }
    s
}

#[test]
fn friction_zero_everywhere_runs_the_declared_frictionless_kernel_bit_for_bit() {
    // Declared: the frictionless law (its materials keep mu = 0.5, which it never reads).
    let mut declared = short_shear();
    declared.model.tangential = TangentialSpec::Frictionless;
    // Derived: LIGGGHTS' history law asked for, but mu = 0 on every material, so no
    // tangential force can arise (|Ft| <= mu Fn = 0).
    let derived = with_friction(short_shear(), 0.0);
    assert_eq!(derived.model.tangential, TangentialSpec::TotalDisplacement);
    let (a, b) = (outputs(&declared), outputs(&derived));
    assert!(a.2.contains("Frictionless") && a.2.contains("VelocityVerlet(x, v)"), "{}", a.2);
    assert_eq!(a.2, b.2, "pipelines");
    assert_eq!(a.3, b.3, "time steps");
    assert!(a.0 == b.0, "energy.csv differs");
    assert!(a.1 == b.1, "walls.csv differs");
    // The comparison can tell kernels apart: with mu = 0.5 the grains rub, and the
    // files differ.
    let rubbing = outputs(&short_shear());
    assert!(rubbing.0 != a.0 && rubbing.2.contains("TotalDisplacementHistory"), "{}", rubbing.2);
    // And the derived switch is said so.
    let built = grainlab::build(&derived).unwrap();
    let table = built.explain_effects();
    let line = table.lines().find(|l| l.contains("friction (tangential force)")).unwrap();
    assert!(line.contains(" off ") && line.contains("derived: friction = 0"), "{line}");
    let line = table.lines().find(|l| l.contains("rotation")).unwrap();
    assert!(line.contains(" off ") && line.contains("derived"), "{line}");
}

#[test]
fn friction_on_one_material_that_can_touch_keeps_the_tangential_law() {
    // The walls' glued grains have their own material with mu = 0.5, the free grains
    // mu = 0: the pair grain-on-wall has min(0, 0.5) = 0, so still no friction anywhere.
    let mut s = with_friction(short_shear(), 0.0);
    s.materials.push(Material { name: "steel".into(), friction: 0.5, ..s.materials[0].clone() });
    if let Some(w) = s.walls.as_mut() {
        w.bottom.material = 1;
        w.top.material = 1;
    }
    let built = grainlab::build(&s).unwrap();
    assert!(built.explain().contains("Frictionless"), "{}", built.explain());
    // The free grains rub on each other: the tangential law stays.
    let s = with_friction(short_shear(), 0.3);
    let built = grainlab::build(&s).unwrap();
    assert!(built.explain().contains("TotalDisplacementHistory"), "{}", built.explain());
}

#[test]
fn restitution_one_on_every_pair_that_can_touch_is_undamped_bit_for_bit() {
    // Every material in use elastic: undamped, whatever an unused material says.
    let mut elastic = short_shear();
    elastic.materials[0].restitution = 1.0;
    let mut with_unused = elastic.clone();
    with_unused.materials.push(Material { name: "putty".into(), restitution: 0.1, ..elastic.materials[0].clone() });
    let (a, b) = (outputs(&elastic), outputs(&with_unused));
    assert!(a.2.contains("Undamped"), "{}", a.2);
    assert_eq!(a.2, b.2, "pipelines");
    assert!(a.0 == b.0, "energy.csv differs");
    assert!(a.1 == b.1, "walls.csv differs");
}
