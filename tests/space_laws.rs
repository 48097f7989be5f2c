//! The tangential laws written once for the plane and for space (issue 30's first step,
//! src/physics/dim.rs): checks of the 3D instantiation on single contacts.
//!
//! - restricted to the plane (normal and velocities in x-y, spins about z), the space
//!   laws give the plane's numbers exactly, step by step: one source, not a copy;
//! - frame indifference: the same contact history rotated by any rotation gives the
//!   rotated forces (to rounding);
//! - in space the history lives in the tangent plane: LIGGGHTS' total displacement is
//!   projected onto it (its length shrinks by the cosine of the turn), LAMMPS' is turned
//!   at its old length;
//! - YADE's increments turn with the contact about the normal too (its `ScGeom::rotate`,
//!   to first order): a rigid twist of the pair turns the stored force by N atan(w dt) and
//!   stretches it by (1 + (w dt)^2)^(N/2), the first-order rotation's own closed form;
//! - gross sliding along a tangent that is not in the x-y plane: the force is mu |Fn|
//!   against the slip;
//! - four contacts in SIMD lanes give each its own bits in space too.

use grainlab::physics::contact::tangential::{IncrementalForce, Tangential, TangentialForce, TangentialInput, TotalDisplacement, TotalForceCap, TotalForceCapSpringKept};
use grainlab::physics::dim::{Dim, Plane, Space};
use grainlab::physics::lanes::{LANES, Lanes};
use nalgebra::{Rotation3, Unit, Vector2, Vector3};
use proptest::prelude::*;

/// A contact's inputs at step `s` of a drive in the plane: the normal turns at `turn`
/// rad/step from `a0`, the tangential velocity along the tangent swings about `v0`, the
/// stiffness and the cap breathe (as a Hertz contact's do).
#[derive(Clone, Copy, Debug)]
struct PlaneDrive {
    a0: f64,
    turn: f64,
    v0: f64,
    kt: f64,
    gt: f64,
    cap: f64,
    dt: f64,
}

impl PlaneDrive {
    fn at(&self, s: usize) -> (Vector2<f64>, Vector2<f64>, f64, f64) {
        let s = s as f64;
        let a = self.a0 + self.turn * s;
        let n = Vector2::new(a.cos(), a.sin());
        let t = Vector2::new(-n.y, n.x);
        let vt = t * (self.v0 * (0.3 * s).sin() + 0.2 * self.v0);
        (n, vt, self.kt * (1.0 + 0.5 * (0.1 * s).sin()), self.cap * (1.0 + 0.5 * (0.07 * s).cos()))
    }
}

fn drive() -> impl Strategy<Value = PlaneDrive> {
    (0.0..6.3f64, -0.02..0.02f64, 0.01..2.0f64, 1e3..1e7f64, 0.0..5.0f64, 1e-3..10.0f64).prop_map(|(a0, turn, v0, kt, gt, cap)| PlaneDrive { a0, turn, v0, kt, gt, cap, dt: 1e-5 })
}

fn lift(v: Vector2<f64>) -> Vector3<f64> {
    Vector3::new(v.x, v.y, 0.0)
}

/// Runs law `T` for `steps` steps in the plane and in space (the same drive, lifted to
/// z = 0, spins about z of `spin_sum`), and asserts every force equal.
fn restricted_equals_plane<T: Tangential<Plane> + Tangential<Space>>(d: &PlaneDrive, spin_sum: f64, steps: usize) -> Result<(), TestCaseError> {
    let mut h2 = <<T as Tangential<Plane>>::History<f64>>::default();
    let mut h3 = <<T as Tangential<Space>>::History<f64>>::default();
    for s in 0..steps {
        let (n, vt, kt, cap) = d.at(s);
        let i2 = TangentialInput::<f64, Plane> { n, vt, kt, gt: d.gt, cap, dt: d.dt, twist: () };
        let i3 = TangentialInput::<f64, Space> { n: lift(n), vt: lift(vt), kt, gt: d.gt, cap, dt: d.dt, twist: Vector3::new(0.0, 0.0, spin_sum) };
        let f2: TangentialForce<f64, Plane> = <T as Tangential<Plane>>::force(&mut h2, &i2);
        let f3: TangentialForce<f64, Space> = <T as Tangential<Space>>::force(&mut h3, &i3);
        // Exactly equal (== treats the two zeros alike: in space a product with a zero z
        // may carry the other sign of zero).
        prop_assert!(f3.elastic == lift(f2.elastic) && f3.damping == lift(f2.damping) && f3.slip_energy == f2.slip_energy, "{} step {}: plane {:?}, space {:?}", <T as Tangential<Plane>>::NAME, s, f2, f3);
    }
    Ok(())
}

/// A drive in space: the normal wanders over the sphere, the tangential velocity is the
/// tangent part of a turning vector, spins about any axis.
#[derive(Clone, Copy, Debug)]
struct SpaceDrive {
    a0: f64,
    b0: f64,
    rate: (f64, f64),
    v0: f64,
    kt: f64,
    gt: f64,
    cap: f64,
    spin: (f64, f64, f64),
}

impl SpaceDrive {
    fn at(&self, s: usize) -> TangentialInput<f64, Space> {
        let s = s as f64;
        let (a, b) = (self.a0 + self.rate.0 * s, self.b0 + self.rate.1 * s);
        let n = Vector3::new(a.cos() * b.cos(), a.sin() * b.cos(), b.sin());
        let v = Vector3::new((0.3 * s).sin() + 0.2, (0.11 * s).cos(), 0.5 - (0.05 * s).sin()) * self.v0;
        let vt = v - n * n.dot(&v);
        let twist = Vector3::new(self.spin.0, self.spin.1, self.spin.2) * (1.0 + 0.3 * (0.2 * s).sin());
        TangentialInput { n, vt, kt: self.kt * (1.0 + 0.5 * (0.1 * s).sin()), gt: self.gt, cap: self.cap * (1.0 + 0.5 * (0.07 * s).cos()), dt: 1e-5, twist }
    }
}

fn space_drive() -> impl Strategy<Value = SpaceDrive> {
    (0.0..6.3f64, -1.5..1.5f64, (-0.02..0.02f64, -0.02..0.02f64), 0.01..2.0f64, 1e3..1e7f64, 0.0..5.0f64, 1e-3..10.0f64, (-1e3..1e3f64, -1e3..1e3f64, -1e3..1e3f64))
        .prop_map(|(a0, b0, rate, v0, kt, gt, cap, spin)| SpaceDrive { a0, b0, rate, v0, kt, gt, cap, spin })
}

/// Runs law `T` in space on a drive and on the same drive rotated by `q`; the forces
/// must be the rotated ones, to rounding relative to the cap.
fn indifferent<T: Tangential<Space>>(d: &SpaceDrive, q: &Rotation3<f64>, steps: usize) -> Result<(), TestCaseError> {
    let mut h = <<T as Tangential<Space>>::History<f64>>::default();
    let mut hq = <<T as Tangential<Space>>::History<f64>>::default();
    for s in 0..steps {
        let i = d.at(s);
        let iq = with(&i, q * i.n, q * i.vt, q * i.twist);
        let f = T::force(&mut h, &i);
        let fq = T::force(&mut hq, &iq);
        // Each step's rounding is 1e-16 of the force; a sliding step's division spreads it,
        // a few hundred steps add it up: 1e-12 of the largest force (the cap, or the
        // dashpot's gt |vt| when that is larger) says "the same force, rotated".
        let scale = i.cap.max(i.gt * i.vt.norm()).max(1e-300);
        let (de, dd) = ((q * f.elastic - fq.elastic).norm(), (q * f.damping - fq.damping).norm());
        prop_assert!(de <= 1e-12 * scale && dd <= 1e-12 * scale, "{} step {}: |Q F - F(Q)| = {:e}, {:e} against {:e}", T::NAME, s, de, dd, scale);
        prop_assert!((f.slip_energy - fq.slip_energy).abs() <= 1e-10 * f.slip_energy.abs().max(1e-30), "{} step {}: slip energy {:e} vs {:e}", T::NAME, s, f.slip_energy, fq.slip_energy);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn space_restricted_to_the_plane_gives_the_planes_numbers(d in drive(), spin_sum in -1e3..1e3f64) {
        restricted_equals_plane::<TotalDisplacement>(&d, spin_sum, 300)?;
        restricted_equals_plane::<IncrementalForce>(&d, spin_sum, 300)?;
        restricted_equals_plane::<TotalForceCap>(&d, spin_sum, 300)?;
        restricted_equals_plane::<TotalForceCapSpringKept>(&d, spin_sum, 300)?;
    }

    #[test]
    fn space_laws_are_frame_indifferent(d in space_drive(), axis in (-1.0..1.0f64, -1.0..1.0f64, 0.1..1.0f64), angle in -3.1..3.1f64) {
        let q = Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(axis.0, axis.1, axis.2)), angle);
        indifferent::<TotalDisplacement>(&d, &q, 300)?;
        indifferent::<IncrementalForce>(&d, &q, 300)?;
        indifferent::<TotalForceCap>(&d, &q, 300)?;
        indifferent::<TotalForceCapSpringKept>(&d, &q, 300)?;
    }

    #[test]
    fn four_lanes_give_each_space_contact_its_own_bits(d in [space_drive(), space_drive(), space_drive(), space_drive()], start in 0usize..200) {
        lanes_match::<TotalDisplacement>(&d, start)?;
        lanes_match::<IncrementalForce>(&d, start)?;
        lanes_match::<TotalForceCap>(&d, start)?;
        lanes_match::<TotalForceCapSpringKept>(&d, start)?;
    }
}

/// `i` with another normal, tangential velocity and twist (written out: the struct
/// update syntax through the dimension's associated types trips rustc 1.95: an internal compiler error).
fn with(i: &TangentialInput<f64, Space>, n: Vector3<f64>, vt: Vector3<f64>, twist: Vector3<f64>) -> TangentialInput<f64, Space> {
    TangentialInput { n, vt, kt: i.kt, gt: i.gt, cap: i.cap, dt: i.dt, twist }
}

fn bits(v: Vector3<f64>) -> [u64; 3] {
    [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]
}

/// Four drives run alone for `start` steps, then 50 steps side by side: alone and in
/// lanes, each lane's force and history bits are its contact's alone.
fn lanes_match<T: Tangential<Space>>(d: &[SpaceDrive; 4], start: usize) -> Result<(), TestCaseError> {
    let mut alone: [<T as Tangential<Space>>::History<f64>; LANES] = Default::default();
    for (l, h) in alone.iter_mut().enumerate() {
        for s in 0..start {
            T::force(h, &d[l].at(s));
        }
    }
    let mut lanes = T::gather([&alone[0], &alone[1], &alone[2], &alone[3]]);
    for s in start..start + 50 {
        let one: [TangentialInput<f64, Space>; LANES] = std::array::from_fn(|l| d[l].at(s));
        let g = |f: &dyn Fn(&TangentialInput<f64, Space>) -> f64| grainlab::physics::lanes::gather(|l| f(&one[l]));
        let inp = TangentialInput::<Lanes, Space> {
            n: Space::gather(|l| one[l].n),
            vt: Space::gather(|l| one[l].vt),
            kt: g(&|i| i.kt),
            gt: g(&|i| i.gt),
            cap: g(&|i| i.cap),
            dt: g(&|i| i.dt),
            twist: Space::gather(|l| one[l].twist),
        };
        let f = T::force(&mut lanes, &inp);
        for l in 0..LANES {
            let fa = T::force(&mut alone[l], &one[l]);
            use simba::simd::SimdValue;
            prop_assert_eq!(bits(Space::lane(&f.elastic, l)), bits(fa.elastic), "{} lane {} step {} elastic", T::NAME, l, s);
            prop_assert_eq!(bits(Space::lane(&f.damping, l)), bits(fa.damping), "{} lane {} step {} damping", T::NAME, l, s);
            prop_assert_eq!(f.slip_energy.extract(l).to_bits(), fa.slip_energy.to_bits(), "{} lane {} step {} slip", T::NAME, l, s);
            prop_assert_eq!(format!("{:?}", T::lane(&lanes, l)), format!("{:?}", alone[l]), "{} lane {} step {} history", T::NAME, l, s);
        }
    }
    Ok(())
}

/// A sticking contact whose normal is `n` and whose history was loaded by one step of
/// `vt`; then `steps` steps of a rigid twist (both grains spinning at `w` about `n`, so
/// the contact points move together: vt = 0) with time step `dt`. Returns the elastic
/// force before and after the twist.
fn twisted<T: Tangential<Space>>(n: Vector3<f64>, vt: Vector3<f64>, w: f64, dt: f64, steps: usize) -> (Vector3<f64>, Vector3<f64>) {
    let mut h = <<T as Tangential<Space>>::History<f64>>::default();
    let base = TangentialInput::<f64, Space> { n, vt, kt: 1e6, gt: 0.0, cap: 1e9, dt, twist: Vector3::zeros() };
    let f0 = T::force(&mut h, &base).elastic;
    let mut f = f0;
    for _ in 0..steps {
        f = T::force(&mut h, &with(&base, n, Vector3::zeros(), n * (2.0 * w))).elastic;
    }
    (f0, f)
}

#[test]
fn yades_increments_turn_with_a_twist_and_the_total_displacement_does_not() {
    let n = Vector3::new(1.0, 2.0, 2.0) / 3.0;
    // A tangent with a z component: t = n x (0, 0, 1) normalised, not in the x-y plane
    // once turned.
    let t = n.cross(&Vector3::z()).normalize();
    let (w, dt, steps) = (10.0, 1e-5, 10_000);
    let theta: f64 = w * dt;
    let (f0, f) = twisted::<IncrementalForce>(n, t * 0.3, w, dt, steps);
    // The angle turned about n, and the stretch of the first-order rotation: each step is
    // f -= f x (theta n), a turn by atan(theta) with a stretch sqrt(1 + theta^2).
    let angle = f0.cross(&f).dot(&n).atan2(f0.dot(&f));
    let expected = steps as f64 * theta.atan();
    assert!((angle - expected).abs() < 1e-9, "turned {angle} rad, expected N atan(w dt) = {expected}");
    let stretch = f.norm() / f0.norm();
    let closed = (1.0 + theta * theta).powf(steps as f64 / 2.0);
    // Rounding: 1e-16 a step over 1e4 steps.
    assert!((stretch / closed - 1.0).abs() < 1e-11, "stretch {stretch}, closed form {closed}");
    assert!(f.dot(&n).abs() < 1e-12 * f.norm(), "the force left the tangent plane: {}", f.dot(&n));
    // LIGGGHTS' total displacement (and LAMMPS') knows nothing of the twist: the contact
    // points do not move apart, so the history stays where it was in space.
    for (name, (g0, g)) in [("TotalDisplacement", twisted::<TotalDisplacement>(n, t * 0.3, w, dt, steps)), ("TotalForceCap", twisted::<TotalForceCap>(n, t * 0.3, w, dt, steps))] {
        assert!((g - g0).norm() <= 1e-15 * g0.norm(), "{name}: {g0:?} -> {g:?}");
    }
}

#[test]
fn the_history_lives_in_the_tangent_plane() {
    // A loaded contact whose normal turns about an axis tilted out of the x-y plane by
    // `phi` per step, no sliding, no tangential motion: LIGGGHTS' history is projected,
    // losing the factor cos(phi) per step where it is perpendicular to the axis; LAMMPS'
    // keeps its length.
    let axis = Vector3::new(0.3, -0.5, 0.8).normalize();
    let n0 = axis.cross(&Vector3::x()).normalize();
    let t = axis.cross(&n0);
    let phi: f64 = 2e-3;
    let steps = 500;
    // The cap (10 N) above the spring's 5 N, and low enough that LAMMPS' law sees the
    // turn (it turns its history only when the part along n would give more than 1e-10
    // of the cap).
    let load = TangentialInput::<f64, Space> { n: n0, vt: t * 0.5, kt: 1e6, gt: 0.0, cap: 10.0, dt: 1e-5, twist: Vector3::zeros() };
    let turning = |s: usize| with(&load, Rotation3::from_axis_angle(&Unit::new_normalize(axis), phi * s as f64) * n0, Vector3::zeros(), Vector3::zeros());
    let mut xi = Vector3::zeros();
    let first = <TotalDisplacement as Tangential<Space>>::force(&mut xi, &load).elastic.norm();
    let mut lammps = Vector3::zeros();
    <TotalForceCap as Tangential<Space>>::force(&mut lammps, &load);
    for s in 1..=steps {
        let inp = turning(s);
        let f = <TotalDisplacement as Tangential<Space>>::force(&mut xi, &inp).elastic;
        <TotalForceCap as Tangential<Space>>::force(&mut lammps, &inp);
        assert!(xi.dot(&inp.n).abs() < 1e-15 * xi.norm(), "step {s}: off the tangent plane by {}", xi.dot(&inp.n));
        assert!(lammps.dot(&inp.n).abs() < 1e-15 * lammps.norm(), "step {s}: LAMMPS' history off the tangent plane");
        if s == steps {
            // The history is along t (perpendicular to the axis and to n), so each
            // projection keeps cos(phi) of it.
            let closed = first * phi.cos().powi(steps as i32);
            assert!((f.norm() / closed - 1.0).abs() < 1e-12, "{} against {closed}", f.norm());
        }
    }
    assert!((lammps.norm() / (0.5 * 1e-5) - 1.0).abs() < 1e-12, "LAMMPS' history kept its length: {}", lammps.norm());
}

#[test]
fn gross_sliding_along_a_tangent_out_of_the_plane_is_mu_fn_against_the_slip() {
    let n: Vector3<f64> = Vector3::new(1.0, 1.0, 1.0).normalize();
    let t: Vector3<f64> = Vector3::new(1.0, -2.0, 1.0).normalize(); // perpendicular to n, with a z part
    assert!(t.dot(&n).abs() < 1e-15);
    // Spins perpendicular to n (a rolling pair): no twist about the normal.
    let inp = TangentialInput::<f64, Space> { n, vt: t * 0.2, kt: 1e6, gt: 0.5, cap: 2.0, dt: 1e-5, twist: Vector3::new(3.0, -3.0, 0.0) };
    fn settle<T: Tangential<Space>>(inp: &TangentialInput<f64, Space>) -> TangentialForce<f64, Space> {
        let mut h = <<T as Tangential<Space>>::History<f64>>::default();
        let mut f = TangentialForce::default();
        // kt vt dt = 2 N a step: at the 2 N cap after a few steps.
        for _ in 0..20 {
            f = T::force(&mut h, inp);
        }
        f
    }
    // LIGGGHTS' and YADE's laws: the spring at the cap, no damping while sliding; LAMMPS'
    // and the spring-kept cap: the total at the cap.
    for (name, f) in [
        ("TotalDisplacement", settle::<TotalDisplacement>(&inp)),
        ("IncrementalForce", settle::<IncrementalForce>(&inp)),
        ("TotalForceCap", settle::<TotalForceCap>(&inp)),
        ("TotalForceCapSpringKept", settle::<TotalForceCapSpringKept>(&inp)),
    ] {
        let total = f.elastic + f.damping;
        assert!((total + t * inp.cap).norm() < 1e-12 * inp.cap, "{name}: {total:?}, expected {:?}", -t * inp.cap);
    }
}
