//! One step of the built-in shear cell, per contact model; and the neighbour rebuild.

use criterion::{Criterion, criterion_group, criterion_main};
use grainlab::boundary::Boundary;
use grainlab::build;
use grainlab::neighbor::cell_pairs;
use grainlab::scene::TangentialSpec;
use grainlab::scenes::shear;

fn shear_step(c: &mut Criterion) {
    let mut g = c.benchmark_group("shear_step_1000_grains");
    for (name, t, energy) in [
        ("liggghts_history", TangentialSpec::TotalDisplacement, false),
        ("liggghts_history+energy", TangentialSpec::TotalDisplacement, true),
        ("yade_mindlin", TangentialSpec::IncrementalForce, false),
        ("frictionless", TangentialSpec::Frictionless, false),
    ] {
        let mut s = shear();
        s.model.tangential = t;
        s.output.energy = energy;
        let mut built = build(&s).unwrap();
        // Let the packing settle into contact first.
        for _ in 0..2000 {
            built.engine.step().unwrap();
        }
        g.bench_function(name, |b| b.iter(|| built.engine.step().unwrap()));
    }
    g.finish();
}

fn neighbour_rebuild(c: &mut Criterion) {
    let s = shear();
    let built = build(&s).unwrap();
    let p = built.engine.particles();
    let b: Boundary = built.engine.boundary();
    let (mut cs, mut ci) = (Vec::new(), Vec::new());
    c.bench_function("cell_list_rebuild_1000_grains", |bch| bch.iter(|| cell_pairs(&p.x, &p.r, p.n_free, &b, 1e-4, &mut cs, &mut ci)));
}

criterion_group!(benches, shear_step, neighbour_rebuild);
criterion_main!(benches);
