//! Grain state as a struct of arrays: the hot loops stream over each field.
//!
//! Free grains come first (`0..n_free`); grains glued into rough walls follow. Wall
//! grains are moved by their wall, never by the integrator.

use crate::physics::dim::Vec2;

#[derive(Clone, Debug, Default)]
pub struct Particles {
    /// Position, m.
    pub x: Vec<Vec2>,
    /// Velocity, m/s.
    pub v: Vec<Vec2>,
    /// Spin about z, rad/s.
    pub omega: Vec<f64>,
    /// Force, N.
    pub f: Vec<Vec2>,
    /// Torque about z, N m.
    pub torque: Vec<f64>,
    /// Radius, m.
    pub r: Vec<f64>,
    /// Mass, kg.
    pub m: Vec<f64>,
    /// Moment of inertia about z, kg m^2.
    pub inertia: Vec<f64>,
    /// Material index into the scene's material list.
    pub material: Vec<u16>,
    /// Number of free grains (the first ones).
    pub n_free: usize,
}

impl Particles {
    pub fn len(&self) -> usize {
        self.x.len()
    }
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Append one grain at rest.
    #[allow(clippy::too_many_arguments)]
    pub fn push(&mut self, x: Vec2, v: Vec2, omega: f64, r: f64, m: f64, inertia: f64, material: u16) {
        self.x.push(x);
        self.v.push(v);
        self.omega.push(omega);
        self.f.push(Vec2::zeros());
        self.torque.push(0.0);
        self.r.push(r);
        self.m.push(m);
        self.inertia.push(inertia);
        self.material.push(material);
    }

    /// Translational kinetic energy of the free grains, J.
    pub fn kinetic_translation(&self) -> f64 {
        (0..self.n_free).map(|i| 0.5 * self.m[i] * self.v[i].norm_squared()).sum()
    }
    /// Rotational kinetic energy of the free grains, J.
    pub fn kinetic_rotation(&self) -> f64 {
        (0..self.n_free).map(|i| 0.5 * self.inertia[i] * self.omega[i] * self.omega[i]).sum()
    }
    /// Total momentum of the free grains, kg m/s.
    pub fn momentum(&self) -> Vec2 {
        (0..self.n_free).map(|i| self.m[i] * self.v[i]).sum()
    }
}
