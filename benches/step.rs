//! The contact kernel alone, one step of the built-in shear cell per contact model, and
//! the neighbour rebuild.

use criterion::{Criterion, criterion_group, criterion_main};
use grainlab::physics::boundary::Boundary;
use grainlab::build;
use grainlab::kernels::cells::cell_pairs;
use grainlab::kernels::threads::Threads;
use grainlab::scene::TangentialSpec;
use grainlab::scene::builtin::shear;

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
    c.bench_function("cell_list_rebuild_1000_grains", |bch| bch.iter(|| cell_pairs(&p.x, &p.r, p.n_free, &b, 1e-4, &mut cs, &mut ci, &Threads::serial())));
}

fn contact_kernel(c: &mut Criterion) {
    use grainlab::physics::contact::model::{LiggghtsHertzHistory, LiggghtsHookeHistory, YadeMindlin};
    use grainlab::physics::contact::normal::{Hertz, Hooke};
    use grainlab::physics::contact::{ContactHistory, ContactInput, LeverArm, ModelOptions};
    use grainlab::physics::dim::Vec2;
    use grainlab::physics::material::{Material, PairMaterial};
    use grainlab::physics::energy::EnergyLedger;
    use std::hint::black_box;
    // A sticking glass-glass contact of two 0.5 mm beads at a typical shear-cell overlap.
    let pm = PairMaterial::mix(&Material::default(), &Material::default());
    let input: ContactInput<f64, grainlab::physics::dim::Plane> = ContactInput {
        n: Vec2::new(0.6, 0.8),
        dn: 1e-6,
        r_star: 2.5e-4,
        sqrt_m_star: 6.5e-7f64.sqrt(),
        v_rel: Vec2::new(1e-3, -2e-3),
        spin: 1e-4,
        dt: 5.8e-8,
        tangential_scale: 1.0,
        roll: 0.0,
        roll_scale: 1.0,
        twist: (),
    };
    let options = ModelOptions { limit_force: false, lever_arm: LeverArm::Radius };
    let mut ledger = EnergyLedger::default();
    let l: LiggghtsHertzHistory = LiggghtsHertzHistory::new(options, Hertz);
    let mut h = ContactHistory::default();
    c.bench_function("contact_kernel_liggghts_history", |b| b.iter(|| l.touch::<false>(black_box(&input), &pm, &mut h, &mut ledger)));
    // Four such contacts at once in SIMD lanes (one iteration = four contacts).
    {
        use grainlab::physics::lanes::{Lanes, gather, gather2};
        use simba::simd::SimdValue;
        let one = [input; 4];
        let lanes = ContactInput {
            n: gather2(|k| one[k].n),
            dn: gather(|k| one[k].dn * (1.0 + 0.1 * k as f64)),
            r_star: Lanes::splat(input.r_star),
            sqrt_m_star: Lanes::splat(input.sqrt_m_star),
            v_rel: gather2(|k| one[k].v_rel),
            spin: Lanes::splat(input.spin),
            dt: Lanes::splat(input.dt),
            tangential_scale: Lanes::splat(1.0),
            roll: Lanes::splat(0.0),
            roll_scale: Lanes::splat(1.0),
            twist: (),
        };
        let pml = PairMaterial::gather([&pm; 4]);
        let xi = grainlab::physics::dim::Vec2::zeros();
        // The contact's state: (tangential history, rolling state), () without rolling resistance.
        let mut h = (<grainlab::physics::contact::tangential::TotalDisplacement as grainlab::physics::contact::tangential::Tangential>::gather([&xi; 4]), ());
        c.bench_function("contact_kernel_liggghts_history_four_lanes", |b| b.iter(|| l.force(black_box(&lanes), &pml, &mut h)));
    }
    let y: YadeMindlin = YadeMindlin::new(options, Hertz);
    let mut h = ContactHistory::default();
    c.bench_function("contact_kernel_yade_mindlin", |b| b.iter(|| y.touch::<false>(black_box(&input), &pm, &mut h, &mut ledger)));
    // The linear spring, derived per pair (a fifth root per contact) and given.
    for (name, spring) in [("contact_kernel_hooke_derived", Hooke::Derived { vc: 1.0 }), ("contact_kernel_hooke_given", Hooke::Given { kn: 2e5, kt: 1.5e5 })] {
        let k: LiggghtsHookeHistory = LiggghtsHookeHistory::new(options, spring);
        let mut h = ContactHistory::default();
        c.bench_function(name, |b| b.iter(|| k.touch::<false>(black_box(&input), &pm, &mut h, &mut ledger)));
    }
}

criterion_group!(benches, contact_kernel, shear_step, neighbour_rebuild);
criterion_main!(benches);
