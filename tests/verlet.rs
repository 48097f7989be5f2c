//! The Verlet list never misses a contact while a packing is sheared: the list is rebuilt
//! when a grain (free or on a rough wall) has moved half the skin, and the contact sweep
//! finds every touching pair among the listed ones.

use grainlab::build_with;
use grainlab::kernels::cells::{brute_force_pairs, mean_overlap};
use grainlab::scene::builtin::shear_cell;

#[test]
fn every_touching_pair_is_in_the_list_at_every_step() {
    let mut sim = build_with(&shear_cell(400, 0.016), 1).unwrap();
    let mut checked = 0;
    for step in 0..4000 {
        sim.engine.step().unwrap();
        if step % 5 == 0 {
            let p = sim.engine.particles();
            // Touching: closer than r_i + r_j (a list with no skin), by brute force.
            let touching = brute_force_pairs(&p.x, &p.r, p.n_free, &sim.engine.boundary(), 0.0).len();
            assert_eq!(sim.engine.touching(), touching, "step {step}: the engine has a different number of touching pairs");
            checked += 1;
        }
    }
    // Rebuilt several times over the run.
    assert!(sim.engine.neighbour_builds() > 3, "{} builds", sim.engine.neighbour_builds());
    assert!(checked == 800 && sim.engine.touching() > 200, "{} touching", sim.engine.touching());
    // The mean overlap over radius of the sheared packing (the sweep's price of soft
    // grains), from the cell list, against the same mean over the brute-force pairs.
    let p = sim.engine.particles();
    let b = sim.engine.boundary();
    let pairs = brute_force_pairs(&p.x, &p.r, p.n_free, &b, 0.0);
    let sum: f64 = pairs.iter().map(|&[i, j]| {
        let (i, j) = (i as usize, j as usize);
        (p.r[i] + p.r[j] - b.image(p.x[i] - p.x[j]).norm()) / (0.5 * (p.r[i] + p.r[j]))
    }).sum();
    let (mean, count) = mean_overlap(&p.x, &p.r, p.n_free, &b).unwrap();
    assert_eq!(count, pairs.len());
    approx::assert_relative_eq!(mean, sum / pairs.len() as f64, max_relative = 1e-12);
}

/// A step's final half kick left to the next drift (`advance(false)`, what the run loop
/// does at steps nothing looks at) gives the bits of kicking at the end of every step:
/// the drift adds the same two half kicks, rounded one at a time. With and without
/// rotation (the spins' kick is left too), and with the energy ledger, which sees the
/// half-step velocities in the contacts.
#[test]
fn a_final_kick_left_to_the_next_drift_gives_the_same_bits() {
    for rotation in [true, false] {
        let mut s = shear_cell(300, 0.012);
        s.model.rotation = rotation;
        let (mut a, mut b) = (build_with(&s, 1).unwrap(), build_with(&s, 1).unwrap());
        let mut behind = 0;
        for k in 1..=1500 {
            a.engine.step().unwrap();
            let look = k % 500 == 0;
            b.engine.advance(look).unwrap();
            let (pa, pb) = (a.engine.particles(), b.engine.particles());
            let same = |i: usize| pa.v[i].x.to_bits() == pb.v[i].x.to_bits() && pa.v[i].y.to_bits() == pb.v[i].y.to_bits() && pa.omega[i].to_bits() == pb.omega[i].to_bits();
            for i in 0..pa.len() {
                assert_eq!([pa.x[i].x.to_bits(), pa.x[i].y.to_bits()], [pb.x[i].x.to_bits(), pb.x[i].y.to_bits()], "rotation {rotation}, step {k}, grain {i}");
                assert!(same(i) || !look, "rotation {rotation}, step {k}, grain {i}");
            }
            // Between looks the velocities are half a kick behind (the kick was left).
            if !look && !(0..pa.n_free).all(same) {
                behind += 1;
            }
        }
        assert!(behind > 1400, "rotation {rotation}: velocities behind at {behind} of 1497 steps not looked at");
        let (ea, eb) = (a.engine.energy_row(), b.engine.energy_row());
        assert_eq!(ea.residual_j.to_bits(), eb.residual_j.to_bits());
        assert_eq!(ea.kinetic_translation_j.to_bits(), eb.kinetic_translation_j.to_bits());
    }
}
