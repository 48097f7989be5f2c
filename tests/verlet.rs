//! The Verlet list never misses a contact while a packing is sheared: the list is rebuilt
//! when a grain (free or on a rough wall) has moved half the skin, and the contact sweep
//! finds every touching pair among the listed ones.

use grainlab::build_with;
use grainlab::neighbor::brute_force_pairs;
use grainlab::scene::Grains;
use grainlab::scenes::shear;

#[test]
fn every_touching_pair_is_in_the_list_at_every_step() {
    let mut s = shear();
    let width = 0.016;
    if let Grains::Pack(p) = &mut s.grains {
        p.count = 400;
        p.x = [0.0, width];
    }
    s.domain.periodic_x = Some([0.0, width]);
    let mut sim = build_with(&s, 1).unwrap();
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
}
