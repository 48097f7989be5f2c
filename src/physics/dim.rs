//! The plane: vectors, the 2D cross product, and what a "2D grain" weighs.
//!
//! grainlab is 2D: grains move in the xy-plane and spin about z. The force law is the
//! 3D Hertz-Mindlin law in every case; what differs between the two grain shapes is
//! only mass and moment of inertia, exactly as in the reference codes:
//! - [`GrainShape::SphereInPlane`] (default): spheres whose centres stay in the plane,
//!   m = 4/3 pi r^3 rho, I = 2/5 m r^2 (a LIGGGHTS 3D monolayer, YADE `blockedDOFs='zXY'`);
//! - [`GrainShape::Disk`]: cylinders of a stated thickness t, m = pi r^2 t rho,
//!   I = 1/2 m r^2 (LIGGGHTS `dimension 2` with t = 1 m).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A vector in the plane, m (or m/s, N, ...).
pub type Vec2 = nalgebra::Vector2<f64>;

/// z-component of the cross product a x b (of one vector or of lanes of them).
#[inline(always)]
pub fn cross<R: crate::physics::lanes::Real>(a: nalgebra::Vector2<R>, b: nalgebra::Vector2<R>) -> R {
    a.x * b.y - a.y * b.x
}

/// (w z) x a for a spin w about z: the velocity of a point at `a` from the centre.
#[inline(always)]
pub fn spin_cross(w: f64, a: Vec2) -> Vec2 {
    Vec2::new(-w * a.y, w * a.x)
}

/// What a grain is in the third dimension.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema, Default)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum GrainShape {
    /// Spheres confined to the plane: m = 4/3 pi r^3 rho, I = 2/5 m r^2.
    #[default]
    SphereInPlane,
    /// Disks (cylinders) of thickness `thickness` m: m = pi r^2 t rho, I = 1/2 m r^2.
    Disk { thickness: f64 },
}

impl GrainShape {
    /// Mass, kg.
    pub fn mass(&self, r: f64, rho: f64) -> f64 {
        match *self {
            GrainShape::SphereInPlane => 4.0 / 3.0 * PI * r * r * r * rho,
            GrainShape::Disk { thickness } => PI * r * r * thickness * rho,
        }
    }
    /// Moment of inertia about z, kg m^2.
    pub fn inertia(&self, r: f64, m: f64) -> f64 {
        match *self {
            GrainShape::SphereInPlane => 0.4 * m * r * r,
            GrainShape::Disk { .. } => 0.5 * m * r * r,
        }
    }
    /// Out-of-plane size of a grain used to turn a wall force into a stress, m: the disk
    /// thickness, or for spheres the given mean diameter.
    pub fn depth(&self, mean_diameter: f64) -> f64 {
        match *self {
            GrainShape::SphereInPlane => mean_diameter,
            GrainShape::Disk { thickness } => thickness,
        }
    }
}
