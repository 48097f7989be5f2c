//! Property tests: the cell list finds exactly the pairs brute force finds, and the
//! four-lane contact kernel gives each contact the bits the one-contact kernel gives it.

use grainlab::physics::boundary::Boundary;
use grainlab::physics::dim::Vec2;
use grainlab::kernels::cells::{brute_force_pairs, cell_pairs};
use grainlab::kernels::threads::Threads;
use grainlab::physics::contact::rolling::{NoRolling, Rolling, RollingEnergy};
use proptest::prelude::*;

fn packing() -> impl Strategy<Value = (Vec<Vec2>, Vec<f64>, usize, bool, f64)> {
    (2usize..250, 1.0f64..10.0, any::<bool>(), 0.0f64..0.5, any::<u64>()).prop_flat_map(|(n, ratio, periodic, skin, _)| {
        let grains = prop::collection::vec((0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0), n);
        (grains, Just(ratio), Just(periodic), Just(skin), 0..=n)
            .prop_map(|(g, ratio, periodic, skin, n_free)| {
                // A box about the right size for a dense packing of n grains of radius
                // 0.01..0.01*ratio; some overlap, some touch across the periodic edge.
                let r: Vec<f64> = g.iter().map(|t| 0.01 * (1.0 + (ratio - 1.0) * t.2)).collect();
                let side = (r.iter().map(|r| 4.0 * r * r).sum::<f64>()).sqrt() * 1.2;
                let x = g.iter().map(|t| Vec2::new(t.0 * side, t.1 * side)).collect();
                (x, r, n_free, periodic, skin * 0.01)
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn cell_list_equals_brute_force((x, r, n_free, periodic, skin) in packing()) {
        let side = x.iter().map(|p| p.x).fold(0.0, f64::max) + 1e-9;
        let b: Boundary = if periodic { Boundary::periodic_x(0.0, side) } else { Boundary::open() };
        let brute = brute_force_pairs(&x, &r, n_free, &b, skin);
        let cells = cell_pairs(&x, &r, n_free, &b, skin, &mut Vec::new(), &mut Vec::new(), &Threads::serial());
        prop_assert_eq!(cells, brute);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// A few grains flung far away (up to 1e6 box sizes, in x and y): the grid would need
    /// far more cells than grains, so the cell list sorts the grains by cell instead of
    /// binning them into a dense grid; it must still find exactly the pairs brute force
    /// finds (and near the flung grains, which may touch each other, too).
    #[test]
    fn cell_list_equals_brute_force_with_grains_far_apart((x, r, n_free, _, skin) in packing(), far in prop::collection::vec((0usize..250, -6.0f64..6.0, -6.0f64..6.0), 1..4)) {
        let mut x = x;
        let side = x.iter().map(|p| p.x).fold(0.0, f64::max) + 1e-9;
        for (k, (i, ex, ey)) in far.iter().enumerate() {
            let i = i % x.len();
            // Two flung grains may land together: the second next to the first.
            x[i] = if k == 1 { x[far[0].0 % x.len()] + Vec2::new(r[i], 0.0) } else { Vec2::new(side * 10f64.powf(*ex), side * 10f64.powf(*ey)) };
        }
        let b: Boundary = Boundary::open();
        let brute = brute_force_pairs(&x, &r, n_free, &b, skin);
        let cells = cell_pairs(&x, &r, n_free, &b, skin, &mut Vec::new(), &mut Vec::new(), &Threads::serial());
        prop_assert_eq!(cells, brute);
    }
}

/// One contact's random state: overlap, normal angle, velocities, spin, history.
fn contact() -> impl Strategy<Value = [f64; 9]> {
    // Overlaps from 1e-9 to 1e-4 of a 0.5 mm grain; speeds up to 1 m/s; the history
    // from nothing to beyond the Coulomb cap, so that lanes mix sticking and sliding.
    (-9.0f64..-4.0, 0.0f64..6.3, -1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0, -1e-5f64..1e-5, -1e-5f64..1e-5, 0.0f64..6.3, 0.2f64..1.0)
        .prop_map(|(dn, a, vx, vy, w, hx, hy, b, rs)| [10f64.powf(dn) * 5e-4, a, vx, vy, 1e3 * w, hx, hy, b, rs])
}

#[allow(clippy::too_many_arguments)]
fn lanes_match_alone<N: grainlab::physics::contact::normal::Normal, D: grainlab::physics::contact::damping::Damping, T: grainlab::physics::contact::tangential::Tangential, Rr: Rolling>(
    normal: N,
    rolling: Rr,
    cs: &[[f64; 9]; 4],
    limit_force: bool,
    lever_arm: grainlab::physics::contact::LeverArm,
    hist: impl Fn(&[f64; 9]) -> T::History<f64>,
    bits: impl Fn(&T::History<f64>) -> Vec<u64>,
    rhist: impl Fn(&[f64; 9]) -> Rr::History<f64>,
    rbits: impl Fn(&Rr::History<f64>) -> Vec<u64>,
    rmem: impl Fn(&[f64; 9]) -> Rr::Energy,
    rmem_bits: impl Fn(&Rr::Energy) -> Vec<u64>,
) -> Result<(), TestCaseError> {
    use grainlab::physics::contact::{ContactInput, ContactModel, ModelOptions};
    use grainlab::physics::lanes::{Lanes, gather, gather2, lane2};
    use grainlab::physics::material::{Material, PairMaterial};
    use simba::simd::SimdValue;
    type M<N, D, T, Rr> = ContactModel<N, D, T, grainlab::physics::contact::cohesion::NoCohesion, Rr>;
    let model = M::<N, D, T, Rr>::with_rolling(ModelOptions { limit_force, lever_arm }, normal, rolling);
    let pm = PairMaterial::mix(&Material { rolling_friction: 0.05, ..Material::default() }, &Material::default());
    let input = |c: &[f64; 9]| ContactInput {
        n: Vec2::new(c[1].cos(), c[1].sin()),
        dn: c[0],
        r_star: 2.5e-4 * c[8],
        sqrt_m_star: (6.5e-7 * c[8]).sqrt(),
        v_rel: Vec2::new(c[2], c[3]),
        spin: 2.5e-4 * c[4],
        dt: 5.8e-8,
        tangential_scale: 1.0 + c[0] / 5e-4,
        roll: c[4] - c[2],
        roll_scale: 1.0 + c[0] / 2.5e-4,
        twist: (),
    };
    let alone: Vec<_> = cs.iter().map(|c| {
        let mut h = (hist(c), rhist(c));
        let s = model.force(&input(c), &pm, &mut h);
        (s, h)
    }).collect();
    let one: Vec<_> = cs.iter().map(input).collect();
    let lanes = ContactInput {
        n: gather2(|l| one[l].n),
        dn: gather(|l| one[l].dn),
        r_star: gather(|l| one[l].r_star),
        sqrt_m_star: gather(|l| one[l].sqrt_m_star),
        v_rel: gather2(|l| one[l].v_rel),
        spin: gather(|l| one[l].spin),
        dt: Lanes::splat(5.8e-8),
        tangential_scale: gather(|l| one[l].tangential_scale),
        roll: gather(|l| one[l].roll),
        roll_scale: gather(|l| one[l].roll_scale),
        twist: (),
    };
    let hs: Vec<_> = cs.iter().map(|c| (hist(c), rhist(c))).collect();
    let mut h = M::<N, D, T, Rr>::gather([&hs[0], &hs[1], &hs[2], &hs[3]]);
    let s = model.force(&lanes, &PairMaterial::gather([&pm; 4]), &mut h);
    for l in 0..4 {
        let f = lane2(&s.force, l);
        prop_assert_eq!(f.x.to_bits(), alone[l].0.force.x.to_bits(), "lane {} force x", l);
        prop_assert_eq!(f.y.to_bits(), alone[l].0.force.y.to_bits(), "lane {} force y", l);
        prop_assert_eq!(s.normal.extract(l).to_bits(), alone[l].0.normal.to_bits());
        let hl = M::<N, D, T, Rr>::lane(&h, l);
        prop_assert_eq!(bits(&hl.0), bits(&alone[l].1.0), "lane {} history", l);
        prop_assert_eq!(s.rolling.extract(l).to_bits(), alone[l].0.rolling.to_bits(), "lane {} rolling torque", l);
        prop_assert_eq!(rbits(&hl.1), rbits(&alone[l].1.1), "lane {} rolling history", l);
    }
    // The energy memory (previous values and sums), from a made-up previous step,
    // likewise.
    use grainlab::physics::contact::EnergyMemory;
    use grainlab::physics::energy::EnergySums;
    let memory = |c: &[f64; 9]| EnergyMemory::<f64, Rr::Energy> {
        fd_prev: c[2],
        fte_prev: Vec2::new(c[5], c[6]) * 1e3,
        ftd_prev: Vec2::new(c[3], c[4]),
        sums: EnergySums { normal_damping: 1e-9 * c[8], tangential_damping: 1e-9 * c[7], friction: 1e-9 * c[0].abs(), tangential_model: 1e-9 * c[1] },
        rolling: rmem(c),
    };
    let mem_bits = |m: &EnergyMemory<f64, Rr::Energy>| {
        let s = &m.sums;
        let r = &m.rolling;
        let bits = [m.fd_prev, m.fte_prev.x, m.fte_prev.y, m.ftd_prev.x, m.ftd_prev.y, s.normal_damping, s.tangential_damping, s.friction, s.tangential_model, r.taken()].map(f64::to_bits).to_vec();
        [bits, rmem_bits(r)].concat()
    };
    let mems: Vec<_> = cs.iter().map(memory).collect();
    let mut m = M::<N, D, T, Rr>::gather_energy([&mems[0], &mems[1], &mems[2], &mems[3]], true);
    model.energy_step(lanes.n, lanes.dt, &s, &mut m);
    for l in 0..4 {
        let mut alone_m = mems[l];
        model.energy_step(one[l].n, one[l].dt, &alone[l].0, &mut alone_m);
        prop_assert_eq!(mem_bits(&M::<N, D, T, Rr>::energy_lane(&m, l)), mem_bits(&alone_m), "lane {} energy memory", l);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn four_lanes_give_each_contact_its_own_bits(c0 in contact(), c1 in contact(), c2 in contact(), c3 in contact(), clamp in any::<bool>(), lever in 0usize..5) {
        use grainlab::physics::contact::LeverArm;
        use grainlab::physics::contact::tangential::{IncrementalForce, IncrementalState, MICROSLIP_SPRINGS, MicroSlip, MicroSlipState, TotalDisplacement, TotalForceCap, TotalForceCapSpringKept};
        use grainlab::physics::contact::damping::{LinearRestitution, TsujiFit, Viscoelastic};
        use grainlab::physics::contact::normal::{Hertz, Hooke};
        use grainlab::physics::contact::rolling::{Cdt, Epsd2, RollingMemory, Sds};
        let lever = [LeverArm::Radius, LeverArm::RadiusMinusHalfOverlap, LeverArm::Yade, LeverArm::ContactPoint, LeverArm::Lammps][lever];
        let cs = [c0, c1, c2, c3];
        let v = |v: &Vec2| vec![v.x.to_bits(), v.y.to_bits()];
        let incremental = |c: &[f64; 9]| IncrementalState { force: Vec2::new(c[5], c[6]) * 1e3, n_prev: Vec2::new(c[7].cos(), c[7].sin()) };
        let incremental_bits = |h: &IncrementalState| [v(&h.force), v(&h.n_prev)].concat();
        lanes_match_alone::<Hertz, Viscoelastic, TotalDisplacement, NoRolling>(Hertz, NoRolling, &cs, clamp, lever, |c| Vec2::new(c[5], c[6]), v, |_| (), |_| vec![], |_| (), |_| vec![])?;
        lanes_match_alone::<Hertz, Viscoelastic, IncrementalForce, NoRolling>(Hertz, NoRolling, &cs, clamp, lever, incremental, incremental_bits, |_| (), |_| vec![], |_| (), |_| vec![])?;
        // LAMMPS' law: a history off the tangent line (the frame turn, a select lane by
        // lane), sticking and sliding, with the restitution damping and Tsuji's.
        lanes_match_alone::<Hertz, Viscoelastic, TotalForceCap, NoRolling>(Hertz, NoRolling, &cs, clamp, lever, |c| Vec2::new(c[5], c[6]), v, |_| (), |_| vec![], |_| (), |_| vec![])?;
        lanes_match_alone::<Hertz, TsujiFit, TotalForceCap, NoRolling>(Hertz, NoRolling, &cs, clamp, lever, |c| Vec2::new(c[5], c[6]), v, |_| (), |_| vec![], |_| (), |_| vec![])?;
        // The cap on the total with the spring kept: sticking, sliding with the spring
        // below the cap (the dashpot takes the rest) and above it, lane by lane.
        lanes_match_alone::<Hertz, Viscoelastic, TotalForceCapSpringKept, NoRolling>(Hertz, NoRolling, &cs, clamp, lever, |c| Vec2::new(c[5], c[6]), v, |_| (), |_| vec![], |_| (), |_| vec![])?;
        // Micro-slip: beds from far finer to far coarser than the contact's radius (kt
        // from about 1e3 to 1e8 N/m here), so that lanes regrid differently (merging,
        // splitting, starting anew, or not at all), springs sticking and slipping.
        let micro = |c: &[f64; 9]| MicroSlipState {
            u: std::array::from_fn(|i| c[5] * (0.37 * i as f64 + c[6] * 1e5).sin()),
            cell: 10f64.powf(1.0 + c[7]),
            kt: 10f64.powf(2.0 + 6.0 * c[8]),
        };
        let micro_bits = |h: &MicroSlipState| h.u.iter().chain([&h.cell, &h.kt]).map(|x| x.to_bits()).collect::<Vec<u64>>();
        assert_eq!(MICROSLIP_SPRINGS, micro(&cs[0]).u.len());
        lanes_match_alone::<Hertz, Viscoelastic, MicroSlip, NoRolling>(Hertz, NoRolling, &cs, clamp, lever, micro, micro_bits, |_| (), |_| vec![], |_| (), |_| vec![])?;
        // The linear spring, derived per pair (a fifth root lane by lane) and given.
        for spring in [Hooke::Derived { vc: 0.8 }, Hooke::Given { kn: 3e5, kt: 2e5 }] {
            lanes_match_alone::<Hooke, LinearRestitution, TotalDisplacement, NoRolling>(spring, NoRolling, &cs, clamp, lever, |c| Vec2::new(c[5], c[6]), v, |_| (), |_| vec![], |_| (), |_| vec![])?;
            lanes_match_alone::<Hooke, LinearRestitution, IncrementalForce, NoRolling>(spring, NoRolling, &cs, clamp, lever, incremental, incremental_bits, |_| (), |_| vec![], |_| (), |_| vec![])?;
            lanes_match_alone::<Hooke, TsujiFit, TotalDisplacement, NoRolling>(spring, NoRolling, &cs, clamp, lever, |c| Vec2::new(c[5], c[6]), v, |_| (), |_| vec![], |_| (), |_| vec![])?;
            lanes_match_alone::<Hooke, LinearRestitution, TotalForceCap, NoRolling>(spring, NoRolling, &cs, clamp, lever, |c| Vec2::new(c[5], c[6]), v, |_| (), |_| vec![], |_| (), |_| vec![])?;
            lanes_match_alone::<Hooke, LinearRestitution, TotalForceCapSpringKept, NoRolling>(spring, NoRolling, &cs, clamp, lever, |c| Vec2::new(c[5], c[6]), v, |_| (), |_| vec![], |_| (), |_| vec![])?;
        }
        // Rolling resistance: the constant torque (a sign lane by lane), the torque
        // spring and LAMMPS' SDS, from states below and beyond their caps.
        let torque = |c: &[f64; 9]| 1e-6 * c[6] * 1e5;
        let roll_bits = |m: &f64| vec![m.to_bits()];
        let roll_mem = |c: &[f64; 9]| RollingMemory { m_prev: 1e-6 * c[5], taken: 1e-9 * c[6] };
        let roll_mem_bits = |m: &RollingMemory| vec![m.m_prev.to_bits(), m.taken.to_bits()];
        lanes_match_alone::<Hertz, Viscoelastic, TotalDisplacement, Cdt>(Hertz, Cdt, &cs, clamp, lever, |c| Vec2::new(c[5], c[6]), v, |_| (), |_| vec![], roll_mem, roll_mem_bits)?;
        lanes_match_alone::<Hertz, Viscoelastic, TotalDisplacement, Epsd2>(Hertz, Epsd2, &cs, clamp, lever, |c| Vec2::new(c[5], c[6]), v, torque, roll_bits, roll_mem, roll_mem_bits)?;
        lanes_match_alone::<Hertz, Viscoelastic, TotalDisplacement, Sds>(Hertz, Sds { k: 2e5, g: 0.01 }, &cs, clamp, lever, |c| Vec2::new(c[5], c[6]), v, |c| c[5], roll_bits, roll_mem, roll_mem_bits)?;
        lanes_match_alone::<Hooke, LinearRestitution, TotalDisplacement, Epsd2>(Hooke::Given { kn: 3e5, kt: 2e5 }, Epsd2, &cs, clamp, lever, |c| Vec2::new(c[5], c[6]), v, torque, roll_bits, roll_mem, roll_mem_bits)?;
        // LAMMPS' Tsuji damping (its polynomial of e lane by lane).
        lanes_match_alone::<Hertz, TsujiFit, TotalDisplacement, NoRolling>(Hertz, NoRolling, &cs, clamp, lever, |c| Vec2::new(c[5], c[6]), v, |_| (), |_| vec![], |_| (), |_| vec![])?;
    }
}
