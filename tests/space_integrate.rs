//! The integrator's loops written once for the plane and space (issue 30): velocity
//! Verlet's half kicks and drift over the components of the grains' vectors and spins
//! (`drift_free`, `kick_components`, `KickFactors`), as the engine's stages run them.
//!
//! - under a constant force and torque, velocity Verlet is exact: x = x0 + v0 t + F t^2
//!   / (2 m) and w = w0 + M t / I, along every axis in space (to rounding, 1e-12);
//! - a plane run restricted from space (z = 0, spins about z) is the plane's, bit for
//!   bit, with the pending kick given in the drift (`TWICE`) or on its own.

use grainlab::engine::integrate::{drift_free, kick_components};
use grainlab::engine::world::KickFactors;
use grainlab::physics::dim::{Dim, Plane, Space, Vec2};
use grainlab::physics::particles::Particles;
use nalgebra::Vector3;

/// Three spheres of radius 1 mm (glass, 2500 kg/m^3), each with its own start.
fn grains<D: Dim>(x: &[D::Vector<f64>], v: &[D::Vector<f64>], w: &[D::Spin<f64>]) -> Particles<D> {
    let mut p = Particles::<D>::default();
    for k in 0..x.len() {
        let r = 1e-3 * (1.0 + 0.5 * k as f64);
        let m = 4.0 / 3.0 * std::f64::consts::PI * r * r * r * 2500.0;
        p.push(x[k], v[k], w[k], r, m, 0.4 * m * r * r, 0);
    }
    p.n_free = x.len();
    p
}

/// `steps` velocity-Verlet steps of dt under forces and torques `force(p)` (set anew
/// each step, as the contact stage does), with the final half kick left to the next
/// drift (`defer`) or given each step.
fn run<D: Dim>(p: &mut Particles<D>, dt: f64, steps: usize, defer: bool, force: impl Fn(&Particles<D>) -> (Vec<D::Vector<f64>>, Vec<D::Spin<f64>>)) {
    let mut k = KickFactors::<D>::default();
    k.update(p, dt);
    let (mut f, mut t) = force(p);
    let mut pending = false;
    for _ in 0..steps {
        let spin = (&mut p.omega[..], &mut t[..], &k.dtfi[..]);
        if pending {
            drift_free::<D, true, true>((&mut p.v, &mut p.x, &mut f, &k.dtfm2), spin, dt);
        } else {
            drift_free::<D, true, false>((&mut p.v, &mut p.x, &mut f, &k.dtfm2), spin, dt);
        }
        (f, t) = force(p);
        if defer {
            pending = true;
        } else {
            kick_components::<D, true>(&mut p.v, &f, &k.dtfm2, (&mut p.omega, &t, &k.dtfi));
        }
    }
    if pending {
        kick_components::<D, true>(&mut p.v, &f, &k.dtfm2, (&mut p.omega, &t, &k.dtfi));
    }
}

#[test]
fn constant_force_and_torque_in_space_are_integrated_exactly() {
    let x0 = [Vector3::new(0.1, 0.2, 0.3), Vector3::new(-0.4, 0.0, 2.0), Vector3::zeros()];
    let v0 = [Vector3::new(1.0, -2.0, 0.5), Vector3::zeros(), Vector3::new(0.0, 0.0, -3.0)];
    let w0 = [Vector3::new(10.0, 0.0, -5.0), Vector3::new(0.0, 7.0, 0.0), Vector3::zeros()];
    let force = Vector3::new(2e-4, -9.81e-4, 3e-4);
    let torque = Vector3::new(-1e-9, 2e-9, 5e-10);
    let (dt, steps) = (1e-5, 2000);
    for defer in [false, true] {
        let mut p = grains::<Space>(&x0, &v0, &w0);
        run(&mut p, dt, steps, defer, |p| (vec![force; p.len()], vec![torque; p.len()]));
        let t = dt * steps as f64;
        for i in 0..p.len() {
            let (m, inertia) = (p.m[i], p.inertia[i]);
            let x = x0[i] + v0[i] * t + force * (0.5 * t * t / m);
            let v = v0[i] + force * (t / m);
            let w = w0[i] + torque * (t / inertia);
            // Rounding only: 2000 steps of a few roundings each, relative to the scale.
            assert!((p.x[i] - x).norm() < 1e-12 * x.norm().max(1.0), "grain {i}: x {:?}, exact {x:?}", p.x[i]);
            assert!((p.v[i] - v).norm() < 1e-12 * v.norm(), "grain {i}: v {:?}, exact {v:?}", p.v[i]);
            assert!((p.omega[i] - w).norm() < 1e-12 * w.norm(), "grain {i}: w {:?}, exact {w:?}", p.omega[i]);
        }
    }
}

#[test]
fn space_restricted_to_the_plane_integrates_as_the_plane() {
    // A force that depends on the position (a spring to the origin) and a torque on
    // the spin, so that every step's kick differs.
    let x2 = [Vec2::new(0.1, 0.2), Vec2::new(-0.3, 0.05), Vec2::new(0.0, -0.2)];
    let v2 = [Vec2::new(1.0, -2.0), Vec2::new(0.0, 0.3), Vec2::new(-0.7, 0.0)];
    let w2 = [10.0, -4.0, 0.0];
    let lift = |v: &Vec2| Vector3::new(v.x, v.y, 0.0);
    for defer in [false, true] {
        let mut p = grains::<Plane>(&x2, &v2, &w2);
        run(&mut p, 1e-5, 3000, defer, |p| (p.x.iter().map(|x| *x * -0.05).collect(), p.omega.iter().map(|w| -1e-10 * w - 2e-11).collect()));
        let mut s = grains::<Space>(&x2.map(|v| lift(&v)), &v2.map(|v| lift(&v)), &w2.map(|w| Vector3::new(0.0, 0.0, w)));
        run(&mut s, 1e-5, 3000, defer, |p| (p.x.iter().map(|x| *x * -0.05).collect(), p.omega.iter().map(|w| Vector3::new(0.0, 0.0, -1e-10 * w.z - 2e-11)).collect()));
        for i in 0..3 {
            assert!(s.x[i] == lift(&p.x[i]) && s.v[i] == lift(&p.v[i]) && s.omega[i] == Vector3::new(0.0, 0.0, p.omega[i]), "grain {i}, defer {defer}");
        }
        // It moved: the test compares something.
        assert!((p.x[0] - x2[0]).norm() > 1e-3 && (p.omega[0] - w2[0]).abs() > 0.0);
        assert_eq!(p.kinetic_translation(), s.kinetic_translation());
    }
}
