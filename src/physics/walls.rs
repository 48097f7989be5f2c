//! Plane walls normal to y: the bottom wall (grains above it) and the top wall (grains
//! below it). A wall is flat (a frictional plane, same contact law with R* = r and
//! m* = m) or rough (a row of grains glued to it). It slides in x at a prescribed
//! velocity, and in y it is either held (fixed gap) or carries a constant normal load
//! as a body of stated mass (`M y'' = F_grains,y - F_load`), the equivalent of a
//! LIGGGHTS `fix aveforce` on a rigid wall.

use std::ops::Range;

use crate::physics::dim::{Dim, Plane};

/// What the grains touch.
#[derive(Clone, Debug, PartialEq)]
pub enum Surface {
    /// A plane at `y`.
    Flat,
    /// Grains `grains` (indices into the particle arrays) glued to the wall.
    Rough { grains: Range<usize> },
}

/// How the wall moves in y.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Control {
    /// Held at its position (fixed gap).
    Fixed,
    /// Pushed towards the grains by a constant force, N.
    Load { force: f64 },
}

/// A wall of a world in the plane (the default `D`) or in space: in both it is normal
/// to y, and slides in the plane it lies in.
#[derive(Clone, Debug)]
pub struct Wall<D: Dim = Plane> {
    /// "bottom" or "top".
    pub name: &'static str,
    pub surface: Surface,
    pub control: Control,
    /// +1 for the bottom wall (grains on its +y side), -1 for the top wall.
    pub side: f64,
    /// Position of the plane (flat) or displacement of the glued row from its start
    /// (rough) in y, m.
    pub y: f64,
    /// Displacement in x since the start, m.
    pub x_shift: f64,
    /// Velocity, m/s: x (and z) prescribed, y from the load (or 0).
    pub v: D::Vector<f64>,
    /// Mass that the load accelerates, kg.
    pub mass: f64,
    /// Radius of a rough wall's glued grains (its contact surface lies this far from `y`
    /// towards the grains), 0 for a flat wall, m.
    pub glued_radius: f64,
    /// Material index of the wall's surface (a flat wall's contacts mix it with the
    /// grain's; a rough wall's glued grains carry it themselves).
    pub material: usize,
    /// Force of the grains on the wall at this step, N.
    pub force: D::Vector<f64>,
    /// ... and at the previous step.
    pub force_prev: D::Vector<f64>,
}

impl<D: Dim> Wall<D> {
    /// The external force along y on the wall from its load, N.
    pub fn load_y(&self) -> f64 {
        match self.control {
            Control::Fixed => 0.0,
            Control::Load { force } => self.side * force,
        }
    }
    /// Kinetic energy of the wall's own y motion (load-controlled walls), J.
    pub fn kinetic(&self) -> f64 {
        match self.control {
            Control::Fixed => 0.0,
            Control::Load { .. } => 0.5 * self.mass * self.v[1] * self.v[1],
        }
    }
    pub fn is_flat(&self) -> bool {
        self.surface == Surface::Flat
    }
    /// Where the grains touch the wall in y: its plane, or the far side of its glued
    /// grains (`y` is their centres' line), m.
    pub fn contact_surface(&self) -> f64 {
        self.y + self.side * self.glued_radius
    }
}

/// A rough wall's grains and their rigid move this step.
pub struct Glued<D: Dim = Plane> {
    /// The grains (indices into the particle arrays).
    pub grains: std::ops::Range<usize>,
    /// Displacement this step, m.
    pub d: D::Vector<f64>,
    /// Velocity, m/s.
    pub v: D::Vector<f64>,
}

impl<D: Dim> Glued<D> {
    /// The grains of `wall` if it is rough, and its move over `dt` at its velocity now (the
    /// product [`crate::engine::stages::MoveWalls`] moved the wall by, so the grains keep their
    /// place on it to the bit).
    pub fn of(wall: &Wall<D>, dt: f64) -> Option<Glued<D>> {
        match &wall.surface {
            Surface::Rough { grains } => Some(Glued { grains: grains.clone(), d: wall.v * dt, v: wall.v }),
            Surface::Flat => None,
        }
    }

    /// Move grains `x` (some of this wall's, with their velocities `v` and positions `at`
    /// at the neighbour list's build) with the wall, back into the periodic cell; whether
    /// one has moved more than `limit` (squared) since the build.
    pub fn follow(&self, x: &mut [D::Vector<f64>], v: &mut [D::Vector<f64>], at: &[D::Vector<f64>], b: &crate::physics::boundary::Boundary<D>, limit: f64) -> bool {
        // As slices, so that the loops vectorise; and the wrap (a chain of roundings per
        // grain) only when a grain has left the cell, which leaves the same bits as
        // wrapping every grain (`Boundary::wrap` keeps the bits of a grain inside).
        x.iter_mut().for_each(|x| *x += self.d);
        if b.any_outside(x) {
            x.iter_mut().for_each(|x| b.wrap(x));
        }
        v.fill(self.v);
        b.any_moved_beyond(x, at, limit)
    }
}
