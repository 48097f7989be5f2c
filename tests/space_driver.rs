//! The contact kernel's driver written once for the plane and space (issue 30): each
//! touching pair's input gathered from the grains' arrays, the law run one pair or four
//! in SIMD lanes, the forces and torques handed out (`compute_pairs`).
//!
//! - the contact sweep sorts out the touching pairs and their separations as a direct
//!   test of each pair does, bit for bit, in the plane and space;
//! - in space, four pairs in lanes give each pair the bits it gets alone, over several
//!   steps of history, with the energy memories (every tangential law but micro-slip);
//! - the plane's packing placed at z = 0 gives the plane's forces, torques, histories
//!   and energy memories bit for bit;
//! - a packing rotated by any rotation gets its forces and torques rotated (1e-12 of the
//!   largest force: the rounding of a rotated position, 1e-16 of the grain size, over an
//!   overlap 1e-3 of it, grows tenfold through Hertz's sqrt).

use grainlab::kernels::cells::cell_pairs;
use grainlab::kernels::driver::{PairOut, PairSlices, PairView, compute_pairs};
use grainlab::kernels::pairs::PairList;
use grainlab::kernels::sweep::sort_pairs_portable;
use grainlab::kernels::threads::Threads;
use grainlab::physics::boundary::Boundary;
use grainlab::physics::contact::cohesion::NoCohesion;
use grainlab::physics::contact::damping::Viscoelastic;
use grainlab::physics::contact::model::Held;
use grainlab::physics::contact::normal::Hertz;
use grainlab::physics::contact::rolling::NoRolling;
use grainlab::physics::contact::tangential::{Frictionless, IncrementalForce, Tangential, TotalDisplacement, TotalForceCap, TotalForceCapSpringKept};
use grainlab::physics::contact::{ContactModel, EnergyMemory, LeverArm, ModelOptions};
use grainlab::physics::dim::{Dim, Plane, Space};
use grainlab::physics::material::{BetaRule, Material, PairTable};
use grainlab::physics::particles::Particles;
use nalgebra::{Rotation3, Unit, Vector2, Vector3};

/// A reproducible stream of numbers in [0, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn sym(&mut self) -> f64 {
        2.0 * self.next() - 1.0
    }
}

/// `n` glass grains of radius 0.8 to 1.2 mm (spheres: m = 4/3 pi r^3 rho, I = 2/5 m
/// r^2) at positions `x`, with random velocities up to 0.5 m/s and spins up to 500 rad/s
/// (the plane's about z).
fn grains<D: Dim>(x: Vec<D::Vector<f64>>, rng: &mut Lcg, v: impl Fn(&mut Lcg) -> D::Vector<f64>, w: impl Fn(&mut Lcg) -> D::Spin<f64>) -> Particles<D> {
    let mut p = Particles::<D>::default();
    let rho = Material::default().density;
    for x in x {
        let r = 1e-3 * (0.8 + 0.4 * rng.next());
        let m = 4.0 / 3.0 * std::f64::consts::PI * r * r * r * rho;
        p.push(x, v(rng), w(rng), r, m, 0.4 * m * r * r, 0);
    }
    p.n_free = p.len();
    p
}

/// What a run of the driver left: each step's outputs, in list order, and the pairs'
/// states and energy memories at the end.
struct Run<T: Tangential<D>, D: Dim> {
    outs: Vec<Vec<PairOut<D>>>,
    hist: Vec<Held<T, NoRolling, f64, D>>,
    energy: Vec<EnergyMemory<f64, (), D>>,
}

/// `steps` calls of the driver on the grains as they are (the contacts' histories grow:
/// the contact points slide), every touching pair at once (`alone` false: four in lanes
/// where there are four) or each pair in a call of its own (`alone`: the one-pair path).
fn drive<T: Tangential<D>, D: Dim>(p: &Particles<D>, b: Boundary<D>, steps: usize, alone: bool) -> Run<T, D> {
    let model = ContactModel::<Hertz, Viscoelastic, T, NoCohesion, NoRolling, D>::new(ModelOptions { limit_force: false, lever_arm: LeverArm::RadiusMinusHalfOverlap }, Hertz);
    let table = PairTable::new(&[Material::default()], BetaRule::Free);
    let view = PairView { p, boundary: b, law: model, pair_table: &table, dt: 2e-8 };
    let mut list = PairList::<Held<T, NoRolling, f64, D>, ()>::default();
    list.replace(cell_pairs(&p.x, &p.r, p.n_free, &b, 0.0, &mut Vec::new(), &mut Vec::new(), &Threads::serial()), &p.r, &p.m, &Threads::serial());
    let np = list.pairs.len();
    let mut energy = vec![EnergyMemory::<f64, (), D>::default(); np];
    let sep: Vec<D::Vector<f64>> = list.pairs.iter().map(|&[i, j]| b.image(p.x[i as usize] - p.x[j as usize])).collect();
    let touching: Vec<u32> = (0..np as u32).filter(|&k| D::norm(sep[k as usize]) < p.r[list.pairs[k as usize][0] as usize] + p.r[list.pairs[k as usize][1] as usize]).collect();
    let seps: Vec<D::Vector<f64>> = touching.iter().map(|&k| sep[k as usize]).collect();
    assert!(touching.len() > 40, "{} touching pairs: too few to mean anything", touching.len());
    // The contact sweep (four pairs' distances in lanes, then one by one) sorts out the
    // same pairs with the same separations, bit for bit.
    let (mut t, mut s, mut rel) = (Vec::new(), Vec::new(), Vec::new());
    let (nt, nr) = sort_pairs_portable(&p.x, &b, list.pairs.checked(), &list.reach, &list.active, &[], &mut t, &mut s, &mut rel);
    assert!(t[..nt] == touching[..] && nr == 0 && s[..nt].iter().zip(&seps).all(|(a, c)| bits::<D>(*a) == bits::<D>(*c)), "the sweep's {nt} touching pairs against {}", touching.len());
    let mut outs = Vec::new();
    for _ in 0..steps {
        let mut out = vec![PairOut::<D>::default(); np];
        let parts: Vec<(&[u32], &[D::Vector<f64>])> = if alone { touching.chunks(1).zip(seps.chunks(1)).collect() } else { vec![(&touching[..], &seps[..])] };
        for (t, s) in parts {
            let slices = PairSlices::<T, NoRolling, D> { pairs: list.pairs.checked(), consts: &list.consts, hist: &mut list.hist, energy: &mut energy, active: &mut list.active };
            compute_pairs::<Hertz, Viscoelastic, T, NoCohesion, NoRolling, D, true, true>(&view, slices, t, s, &[], |k, _, o| out[k] = o);
        }
        outs.push(out);
    }
    Run { outs, hist: list.hist, energy }
}

fn bits<D: Dim>(v: D::Vector<f64>) -> Vec<u64> {
    D::flat(&[v]).iter().map(|x| x.to_bits()).collect()
}
fn spin_bits<D: Dim>(w: D::Spin<f64>) -> Vec<u64> {
    D::spin_flat(&[w]).iter().map(|x| x.to_bits()).collect()
}
fn memory_bits<D: Dim>(e: &EnergyMemory<f64, (), D>) -> Vec<u64> {
    let s = &e.sums;
    let mut b = vec![e.fd_prev.to_bits(), s.normal_damping.to_bits(), s.tangential_damping.to_bits(), s.friction.to_bits(), s.tangential_model.to_bits()];
    b.extend(bits::<D>(e.fte_prev));
    b.extend(bits::<D>(e.ftd_prev));
    b
}

/// A box of spheres, periodic in x and z, dense enough that many overlap.
fn box_of_spheres(rng: &mut Lcg) -> (Particles<Space>, Boundary<Space>) {
    let side = 9e-3;
    let x = (0..150).map(|_| Vector3::new(rng.next(), rng.next(), rng.next()) * side).collect();
    let p = grains::<Space>(x, rng, |g| Vector3::new(g.sym(), g.sym(), g.sym()) * 0.5, |g| Vector3::new(g.sym(), g.sym(), g.sym()) * 500.0);
    (p, Boundary::<Space>::periodic(Some((0.0, side)), Some((0.0, side))))
}

fn lanes_alone<T: Tangential<Space>>() {
    let (p, b) = box_of_spheres(&mut Lcg(7));
    let (lanes, alone) = (drive::<T, Space>(&p, b, 4, false), drive::<T, Space>(&p, b, 4, true));
    for (s, (a, c)) in lanes.outs.iter().zip(&alone.outs).enumerate() {
        for (k, (a, c)) in a.iter().zip(c).enumerate() {
            let same = bits::<Space>(a.force) == bits::<Space>(c.force) && a.torque.iter().zip(&c.torque).all(|(x, y)| spin_bits::<Space>(*x) == spin_bits::<Space>(*y)) && a.ratio.to_bits() == c.ratio.to_bits();
            assert!(same, "{}: step {s}, pair {k}: in lanes {a:?}, alone {c:?}", T::NAME);
        }
    }
    for (k, (a, c)) in lanes.energy.iter().zip(&alone.energy).enumerate() {
        assert!(memory_bits(a) == memory_bits(c), "{}: pair {k}'s energy memory: {a:?} against {c:?}", T::NAME);
        assert!(format!("{:?}", lanes.hist[k]) == format!("{:?}", alone.hist[k]), "{}: pair {k}'s history", T::NAME);
    }
    // Something was computed: forces, and with friction torques about more than z.
    let last = lanes.outs.last().unwrap();
    assert!(last.iter().filter(|o| o.force.norm() > 0.0).count() > 40);
    assert!(!T::FRICTION || last.iter().any(|o| o.torque[0].x != 0.0 && o.torque[0].y != 0.0));
}

#[test]
fn four_pairs_in_lanes_give_each_its_bits_in_space() {
    lanes_alone::<Frictionless>();
    lanes_alone::<TotalDisplacement>();
    lanes_alone::<IncrementalForce>();
    lanes_alone::<TotalForceCap>();
    lanes_alone::<TotalForceCapSpringKept>();
}

fn restricted<T: Tangential<Plane> + Tangential<Space>>() {
    let mut rng = Lcg(11);
    let side = 1.6e-2;
    let x2: Vec<Vector2<f64>> = (0..120).map(|_| Vector2::new(rng.next(), rng.next()) * side).collect();
    let lift = |v: &Vector2<f64>| Vector3::new(v.x, v.y, 0.0);
    let x3 = x2.iter().map(lift).collect();
    let p2 = grains::<Plane>(x2, &mut Lcg(3), |g| Vector2::new(g.sym(), g.sym()) * 0.5, |g| g.sym() * 500.0);
    let p3 = grains::<Space>(x3, &mut Lcg(3), |g| Vector3::new(g.sym(), g.sym(), 0.0) * 0.5, |g| Vector3::new(0.0, 0.0, g.sym() * 500.0));
    let (b2, b3) = (Boundary::<Plane>::periodic_x(0.0, side), Boundary::<Space>::periodic(Some((0.0, side)), None));
    let (a, c) = (drive::<T, Plane>(&p2, b2, 4, false), drive::<T, Space>(&p3, b3, 4, false));
    for (s, (a, c)) in a.outs.iter().zip(&c.outs).enumerate() {
        for (k, (a, c)) in a.iter().zip(c).enumerate() {
            let same = c.force == lift(&a.force) && c.torque == [Vector3::new(0.0, 0.0, a.torque[0]), Vector3::new(0.0, 0.0, a.torque[1])] && a.ratio == c.ratio;
            assert!(same, "{}: step {s}, pair {k}: plane {a:?}, space {c:?}", <T as Tangential<Plane>>::NAME);
        }
    }
    for (k, (e2, e3)) in a.energy.iter().zip(&c.energy).enumerate() {
        let (b2, b3) = (memory_bits(e2), memory_bits(e3));
        // The space memory has a z component per vector, 0: drop it and compare.
        let b3: Vec<u64> = b3[..5].iter().chain(&b3[5..7]).chain(&b3[8..10]).cloned().collect();
        assert!(b2 == b3 && e3.fte_prev.z == 0.0, "pair {k}: plane {e2:?}, space {e3:?}");
    }
}

#[test]
fn space_restricted_to_the_plane_gives_the_plane_forces() {
    restricted::<Frictionless>();
    restricted::<TotalDisplacement>();
    restricted::<IncrementalForce>();
    restricted::<TotalForceCap>();
    restricted::<TotalForceCapSpringKept>();
}

fn rotated<T: Tangential<Space>>() {
    // Open boundaries: a periodic box is not rotation invariant.
    let mut rng = Lcg(5);
    let x: Vec<Vector3<f64>> = (0..150).map(|_| Vector3::new(rng.next(), rng.next(), rng.next()) * 9e-3).collect();
    let p = grains::<Space>(x, &mut Lcg(9), |g| Vector3::new(g.sym(), g.sym(), g.sym()) * 0.5, |g| Vector3::new(g.sym(), g.sym(), g.sym()) * 500.0);
    let q = Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(0.3, -0.8, 0.5)), 1.3);
    let mut pq = p.clone();
    for i in 0..p.len() {
        (pq.x[i], pq.v[i], pq.omega[i]) = (q * p.x[i], q * p.v[i], q * p.omega[i]);
    }
    let (a, c) = (drive::<T, Space>(&p, Boundary::open(), 3, false), drive::<T, Space>(&pq, Boundary::open(), 3, false));
    let scale = a.outs[0].iter().map(|o| o.force.norm()).fold(0.0, f64::max);
    let arm = 1.2e-3;
    for (s, (a, c)) in a.outs.iter().zip(&c.outs).enumerate() {
        for (k, (a, c)) in a.iter().zip(c).enumerate() {
            let (df, dt) = ((q * a.force - c.force).norm(), (q * a.torque[0] - c.torque[0]).norm().max((q * a.torque[1] - c.torque[1]).norm()));
            assert!(df < 1e-12 * scale && dt < 1e-12 * scale * arm, "{}: step {s}, pair {k}: |Q F - F(Q)| = {df:e}, torque {dt:e} (forces up to {scale:e} N)", T::NAME);
        }
    }
}

#[test]
fn a_rotated_packing_gets_rotated_forces() {
    rotated::<Frictionless>();
    rotated::<TotalDisplacement>();
    rotated::<IncrementalForce>();
    rotated::<TotalForceCap>();
    rotated::<TotalForceCapSpringKept>();
}
