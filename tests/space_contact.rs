//! The contact model written once for the plane and for space (issue 30): one grain
//! meeting a flat wall, integrated by velocity Verlet with the model's force, in a
//! harness that is itself generic over the dimension (`impact::<D, T>`), so the plane and
//! space runs are one source too.
//!
//! - restricted to the plane (wall normal, velocity in x-y, spin about z), the space
//!   model gives the plane's rebound exactly, with every tangential law;
//! - a whole impact rotated by any rotation rebounds rotated (to 1e-10: rounding);
//! - an oblique impact whose slip is not in the x-y plane keeps the gross-sliding
//!   identities of the rigid-body impulses: dv_t = -mu J_n / m along the slip, and
//!   dw = (r mu J_n / I) n x t, to 1e-9 (the 2D suites' bound for these identities);
//! - a damped head-on impact along a direction out of the plane restitutes as the same
//!   impact along x in the plane, to 1e-10 (the overlap's rounding).

use grainlab::physics::contact::damping::{Undamped, Viscoelastic};
use grainlab::physics::contact::cohesion::NoCohesion;
use grainlab::physics::contact::model::Held;
use grainlab::physics::contact::normal::Hertz;
use grainlab::physics::contact::rolling::NoRolling;
use grainlab::physics::contact::tangential::{Frictionless, IncrementalForce, Tangential, TotalDisplacement, TotalForceCap, TotalForceCapSpringKept};
use grainlab::physics::contact::{ContactHistory, ContactInput, ContactModel, LeverArm, ModelOptions};
use grainlab::physics::energy::EnergyLedger;
use grainlab::physics::dim::{Dim, Plane, Space};
use grainlab::physics::material::{Material, PairMaterial};
use nalgebra::{Rotation3, Unit, Vector2, Vector3};

/// A bead of 1 mm radius of the default material (glass-like: E = 63 GPa, nu = 0.2,
/// 2500 kg/m^3, e = 0.9, mu = 0.5).
const R: f64 = 1e-3;

fn bead() -> (f64, f64, PairMaterial) {
    let m = Material::default();
    let mass = 4.0 / 3.0 * std::f64::consts::PI * R * R * R * m.density;
    (mass, 0.4 * mass * R * R, PairMaterial::mix(&m, &m))
}

/// What a rebound left: centre velocity and spin, the normal impulse (N s), the energy
/// ledger the contact kept (its `touch` and `release`), and the kinetic energies before
/// and after (J).
#[derive(Debug)]
struct Rebound<D: Dim> {
    v: D::Vector<f64>,
    w: D::Spin<f64>,
    jn: f64,
    ledger: EnergyLedger,
    e0: f64,
    e1: f64,
}

impl<D: Dim> Rebound<D> {
    /// The energy balance's residual (src/physics/energy.rs) over the whole impact,
    /// relative to the energy put in: the wall is fixed, so no wall work, and after the
    /// release no spring holds any energy.
    fn residual(&self) -> f64 {
        let l = &self.ledger;
        assert!(l.elastic_normal == 0.0 && l.elastic_tangential == 0.0, "{l:?}");
        (self.e1 - self.e0 + l.normal_damping + l.tangential_damping + l.friction - l.tangential_model) / self.e0
    }
}

/// One grain of radius `R` meeting the flat wall through the origin with unit normal `n`
/// (into the grain), starting just clear of it at velocity `v0` and spin `w0`; the wall
/// neither moves nor spins, so the pair's spin sum is the grain's (`twist`). Velocity
/// Verlet at dt = 2e-9 s (about t_c / 400), until the grain has left.
fn impact<D: Dim, T: Tangential<D>>(model: &ContactModel<Hertz, impl grainlab::physics::contact::damping::Damping, T, NoCohesion, NoRolling, D>, n: D::Vector<f64>, v0: D::Vector<f64>, w0: D::Spin<f64>, twist: impl Fn(D::Spin<f64>) -> D::Twist<f64>) -> Rebound<D> {
    let (m, inertia, pm) = bead();
    let dt = 2e-9;
    let mut x = n * (R + 1e-9);
    let (mut v, mut w) = (v0, w0);
    let kinetic = |v: D::Vector<f64>, w: D::Spin<f64>| 0.5 * m * D::norm_squared(v) + D::spin_kinetic(0.5 * inertia, w);
    let e0 = kinetic(v0, w0);
    let mut h: ContactHistory<Held<T, NoRolling, f64, D>, (), D> = Default::default();
    let mut ledger = EnergyLedger::default();
    let (mut f, mut torque) = (D::zero::<f64>(), D::spin_zero::<f64>());
    let mut jn = 0.0;
    let mut touched = false;
    for _ in 0..1_000_000 {
        v += f * (0.5 * dt / m);
        w = w + torque * (0.5 * dt / inertia);
        x += v * dt;
        let dn = R - D::dot(x, n);
        if dn <= 0.0 {
            // Free flight (no force, so no second half kick); after the contact, the end:
            // the contact is released over this step (its integrals closed with the
            // velocity of its contact point now).
            if touched {
                model.release::<true>(v + D::cross_spin(n, w * R), n, w, dt, &mut h.state, &mut h.energy);
                ledger.add(&h.energy.sums);
                ledger.begin_step();
                return Rebound { v, w, jn, ledger, e0, e1: kinetic(v, w) };
            }
            (f, torque) = (D::zero(), D::spin_zero());
            continue;
        }
        touched = true;
        let c = ContactInput::<f64, D> { n, dn, r_star: R, sqrt_m_star: m.sqrt(), v_rel: v, spin: w * R, dt, tangential_scale: 1.0, roll: w, roll_scale: 1.0, twist: twist(w) };
        ledger.begin_step();
        let s = model.touch::<true>(&c, &pm, &mut h, &mut ledger);
        f = s.force;
        // The tangential force acts at the contact point, -R n from the centre.
        torque = D::cross(n * -R, s.tangential);
        // The normal impulse of this step's force (half in this kick, half in the next).
        jn += s.normal * dt;
        v += f * (0.5 * dt / m);
        w = w + torque * (0.5 * dt / inertia);
    }
    panic!("the grain never left the wall");
}

fn opts() -> ModelOptions {
    ModelOptions { limit_force: false, lever_arm: LeverArm::Radius }
}

/// The same oblique impact in the plane and in space restricted to it.
fn restricted<T: Tangential<Plane> + Tangential<Space>>() {
    let (a, vn, vt, w0) = (0.4f64, 0.3, 0.7, -300.0);
    let n2 = Vector2::new(a.cos(), a.sin());
    let t2 = Vector2::new(-n2.y, n2.x);
    let v2 = n2 * -vn + t2 * vt;
    let plane = ContactModel::<Hertz, Viscoelastic, T, NoCohesion, NoRolling, Plane>::new(opts(), Hertz);
    let space = ContactModel::<Hertz, Viscoelastic, T, NoCohesion, NoRolling, Space>::new(opts(), Hertz);
    let p = impact::<Plane, T>(&plane, n2, v2, w0, |_| ());
    let lift = |v: Vector2<f64>| Vector3::new(v.x, v.y, 0.0);
    let s = impact::<Space, T>(&space, lift(n2), lift(v2), Vector3::new(0.0, 0.0, w0), |w| w);
    let name = <T as Tangential<Plane>>::NAME;
    assert!(s.v == lift(p.v) && s.w == Vector3::new(0.0, 0.0, p.w) && s.jn == p.jn, "{name}: plane {p:?}, space {s:?}");
    // Its energy ledger too, term by term, bit for bit (the kinetic energy rounds
    // differently: c |w|^2 in space, (c w) w in the plane).
    assert!(s.ledger == p.ledger && (s.e1 / p.e1 - 1.0).abs() < 1e-15, "{name}: plane {:?}, space {:?}", p.ledger, s.ledger);
    // It was an impact: the grain rebounds (and turns, with friction).
    assert!(p.v.dot(&n2) > 0.0 && (p.w != w0) == <T as Tangential<Plane>>::FRICTION, "{name}: {p:?}");
}

#[test]
fn space_restricted_to_the_plane_rebounds_as_the_plane() {
    restricted::<Frictionless>();
    restricted::<TotalDisplacement>();
    restricted::<IncrementalForce>();
    restricted::<TotalForceCap>();
    restricted::<TotalForceCapSpringKept>();
}

/// An oblique impact in space, out of every coordinate plane, and the same rotated (the
/// first returned).
fn rotated<T: Tangential<Space>>() -> Rebound<Space> {
    let n = Vector3::new(1.0, 2.0, 2.0) / 3.0;
    let t = n.cross(&Vector3::new(0.3, -0.2, 1.0)).normalize();
    let v0 = n * -0.3 + t * 0.5;
    let w0 = Vector3::new(100.0, -250.0, 80.0);
    let model = ContactModel::<Hertz, Viscoelastic, T, NoCohesion, NoRolling, Space>::new(opts(), Hertz);
    let a = impact::<Space, T>(&model, n, v0, w0, |w| w);
    let q = Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(-0.4, 0.7, 0.2)), 2.1);
    let b = impact::<Space, T>(&model, q * n, q * v0, q * w0, |w| w);
    // Rounding: the overlap is the difference of R and x.n (1e-3 m against about 1e-6
    // m), so each step's rounding is 1e-16 R / dn = 1e-13 of it, over some 1e3 steps
    // (the contact time over dt): 1e-10 (measured 3.5e-12).
    let (dv, dw) = ((q * a.v - b.v).norm() / a.v.norm(), (q * a.w - b.w).norm() / a.w.norm());
    assert!(dv < 1e-10 && dw < 1e-10 && (a.jn / b.jn - 1.0).abs() < 1e-10, "{}: |Q v - v(Q)| / |v| = {dv:e}, spin {dw:e}", T::NAME);
    // The ledger is a scalar record: the same in both frames, to the same rounding
    // relative to the energy put in.
    let (la, lb) = (&a.ledger, &b.ledger);
    for (x, y) in [(la.normal_damping, lb.normal_damping), (la.tangential_damping, lb.tangential_damping), (la.friction, lb.friction), (la.tangential_model, lb.tangential_model)] {
        assert!((x - y).abs() < 1e-10 * a.e0, "{}: ledger {la:?} against rotated {lb:?}", T::NAME);
    }
    a
}

/// The energy balance of a velocity-Verlet impact closes to O(dt^2): measured 3.7e-9 of
/// the energy put in with damping, 3.8e-11 without, at about 400 steps per contact;
/// bound 1e-6, where a term missing or inconsistent with the torque (a wrong arm or
/// sign in the contact velocity) leaves percents: in space, with every tangential law, the slip and the contact frame
/// out of the x-y plane, and the ledger's terms each doing something.
fn balance<D: Dim, T: Tangential<D>>(r: &Rebound<D>, damped: bool, sliding: bool) {
    let (res, l) = (r.residual(), &r.ledger);
    assert!(res.abs() < 1e-6, "{}: residual {res:e} of {} J; {l:?}", T::NAME, r.e0);
    // Not an empty ledger: damping took some, and friction some wherever it slid.
    assert!(!damped || (l.normal_damping > 1e-3 * r.e0 && (!T::FRICTION || l.tangential_damping > 0.0)), "{}: {l:?}", T::NAME);
    assert!(!sliding || l.friction > 1e-2 * r.e0, "{}: {l:?}", T::NAME);
}

#[test]
fn the_energy_ledger_closes_in_space() {
    balance::<Space, TotalDisplacement>(&rotated::<TotalDisplacement>(), true, false);
    balance::<Space, IncrementalForce>(&rotated::<IncrementalForce>(), true, false);
    balance::<Space, TotalForceCap>(&rotated::<TotalForceCap>(), true, false);
    balance::<Space, TotalForceCapSpringKept>(&rotated::<TotalForceCapSpringKept>(), true, false);
    balance::<Space, Frictionless>(&rotated::<Frictionless>(), true, false);
}

#[test]
fn a_rotated_impact_rebounds_rotated() {
    rotated::<TotalDisplacement>();
    rotated::<IncrementalForce>();
    rotated::<TotalForceCap>();
    rotated::<TotalForceCapSpringKept>();
}

/// Gross sliding throughout: a slip velocity of 5 vn, above the 3.5 mu (1 + e) vn = 3.5 vn
/// that the impact can take out of it (e = 1, mu = 0.5), along a tangent with a z part.
fn sliding<T: Tangential<Space>>() -> Rebound<Space> {
    let (m, inertia, pm) = bead();
    assert_eq!(pm.friction, 0.5, "the default material's friction");
    let n: Vector3<f64> = Vector3::new(0.2, 0.9, -0.4).normalize();
    let t: Vector3<f64> = n.cross(&Vector3::new(1.0, 0.0, 1.0)).normalize();
    assert!(t.z.abs() > 0.1 && t.dot(&n).abs() < 1e-15);
    let vn = 0.2;
    let v0 = n * -vn + t * (5.0 * vn);
    let model = ContactModel::<Hertz, Undamped, T, NoCohesion, NoRolling, Space>::new(opts(), Hertz);
    let r = impact::<Space, T>(&model, n, v0, Vector3::zeros(), |w| w);
    let friction = pm.friction * r.jn;
    // The centre: the friction impulse mu J_n against the slip, nothing else along the
    // tangent plane.
    let dv = r.v - v0;
    let dv_t = dv - n * dv.dot(&n);
    assert!((dv_t + t * (friction / m)).norm() < 1e-9 * friction / m, "{}: dv_t = {dv_t:?}, expected {:?}", T::NAME, -t * (friction / m));
    // The spin: the torque of that impulse at the contact point, (-R n) x (-mu J_n t).
    let expected = n.cross(&t) * (R * friction / inertia);
    assert!((r.w - expected).norm() < 1e-9 * expected.norm(), "{}: w = {:?}, expected {expected:?}", T::NAME, r.w);
    // And the normal impulse is the undamped Hertz rebound's, 2 m vn to discretisation.
    assert!((r.jn / (2.0 * m * vn) - 1.0).abs() < 1e-3, "{}: J_n = {}, 2 m vn = {}", T::NAME, r.jn, 2.0 * m * vn);
    r
}

#[test]
fn gross_sliding_out_of_the_plane_keeps_the_impulse_identities() {
    // And the ledger closes with friction taking its share (undamped: nothing else).
    balance::<Space, TotalDisplacement>(&sliding::<TotalDisplacement>(), false, true);
    balance::<Space, IncrementalForce>(&sliding::<IncrementalForce>(), false, true);
    balance::<Space, TotalForceCap>(&sliding::<TotalForceCap>(), false, true);
    balance::<Space, TotalForceCapSpringKept>(&sliding::<TotalForceCapSpringKept>(), false, true);
}

#[test]
fn a_damped_head_on_impact_out_of_the_plane_restitutes_as_in_the_plane() {
    let n3 = Vector3::new(-2.0, 1.0, 2.0) / 3.0;
    let vn = 0.5;
    let space = ContactModel::<Hertz, Viscoelastic, Frictionless, NoCohesion, NoRolling, Space>::new(opts(), Hertz);
    let plane = ContactModel::<Hertz, Viscoelastic, Frictionless, NoCohesion, NoRolling, Plane>::new(opts(), Hertz);
    let s = impact::<Space, Frictionless>(&space, n3, n3 * -vn, Vector3::zeros(), |w| w);
    let p = impact::<Plane, Frictionless>(&plane, Vector2::new(1.0, 0.0), Vector2::new(-vn, 0.0), 0.0, |_| ());
    let (es, ep) = (s.v.dot(&n3) / vn, p.v.x / vn);
    // The same one-dimensional impact; its rounding differs through the direction's
    // components, in an overlap that is the difference of R and x.n (1e-3 m against
    // about 1e-6 m): 1e-13 of it a step over some 1e3 steps, 1e-10 (measured 2.8e-12).
    assert!((es - ep).abs() < 1e-10, "e in space {es}, in the plane {ep}");
    // And it is the damped one: e well below 1 (glass, e = 0.9 by default).
    assert!(ep < 0.95 && ep > 0.85, "{ep}");
    // Nothing but the normal: no spin, no sideways velocity.
    assert!(s.w == Vector3::zeros() && (s.v - n3 * s.v.dot(&n3)).norm() < 1e-15 * vn);
}
