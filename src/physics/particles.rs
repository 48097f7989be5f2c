//! Grain state as a struct of arrays: the hot loops stream over each field.
//!
//! Free grains come first (`0..n_free`); grains glued into rough walls follow. Wall
//! grains are moved by their wall, never by the integrator.

use crate::physics::dim::{Dim, Plane};

/// The grains of a world in the plane (`D = Plane`, the default: spins and torques
/// about z) or in space (`Space`: spins and torques as vectors; every grain a sphere of
/// isotropic inertia).
#[derive(Clone, Debug, Default)]
pub struct Particles<D: Dim = Plane> {
    /// Position, m.
    pub x: Vec<D::Vector<f64>>,
    /// Velocity, m/s.
    pub v: Vec<D::Vector<f64>>,
    /// Spin (about z in the plane), rad/s.
    pub omega: Vec<D::Spin<f64>>,
    /// Force, N.
    pub f: Vec<D::Vector<f64>>,
    /// Torque (about z in the plane), N m.
    pub torque: Vec<D::Spin<f64>>,
    /// Radius, m.
    pub r: Vec<f64>,
    /// Mass, kg.
    pub m: Vec<f64>,
    /// Moment of inertia (about z in the plane; about any axis through the centre of
    /// a sphere), kg m^2.
    pub inertia: Vec<f64>,
    /// Material index into the scene's material list.
    pub material: Vec<u16>,
    /// Number of free grains (the first ones).
    pub n_free: usize,
}

impl<D: Dim> Particles<D> {
    pub fn len(&self) -> usize {
        self.x.len()
    }
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Append one grain at rest.
    #[allow(clippy::too_many_arguments)]
    pub fn push(&mut self, x: D::Vector<f64>, v: D::Vector<f64>, omega: D::Spin<f64>, r: f64, m: f64, inertia: f64, material: u16) {
        self.x.push(x);
        self.v.push(v);
        self.omega.push(omega);
        self.f.push(D::zero());
        self.torque.push(D::spin_zero());
        self.r.push(r);
        self.m.push(m);
        self.inertia.push(inertia);
        self.material.push(material);
    }

    /// Translational kinetic energy of the free grains, J.
    pub fn kinetic_translation(&self) -> f64 {
        (0..self.n_free).map(|i| 0.5 * self.m[i] * D::norm_squared(self.v[i])).sum()
    }
    /// Rotational kinetic energy of the free grains, J.
    pub fn kinetic_rotation(&self) -> f64 {
        (0..self.n_free).map(|i| D::spin_kinetic(0.5 * self.inertia[i], self.omega[i])).sum()
    }
    /// Total momentum of the free grains, kg m/s.
    pub fn momentum(&self) -> D::Vector<f64> {
        (0..self.n_free).fold(D::zero(), |p, i| p + self.v[i] * self.m[i])
    }
}
