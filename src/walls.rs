//! Plane walls normal to y: the bottom wall (grains above it) and the top wall (grains
//! below it). A wall is flat (a frictional plane, same contact law with R* = r and
//! m* = m) or rough (a row of grains glued to it). It slides in x at a prescribed
//! velocity, and in y it is either held (fixed gap) or carries a constant normal load
//! as a body of stated mass (`M y'' = F_grains,y - F_load`), the equivalent of a
//! LIGGGHTS `fix aveforce` on a rigid wall.

use std::ops::Range;

use crate::dim::Vec2;

/// What the grains touch.
#[derive(Clone, Debug, PartialEq)]
pub enum Surface {
    /// A plane at `y`.
    Flat,
    /// Grains `grains` (indices into the particle arrays) glued to the wall.
    Rough { grains: Range<usize> },
}

/// How the wall moves in y.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Control {
    /// Held at its position (fixed gap).
    Fixed,
    /// Pushed towards the grains by a constant force, N.
    Load { force: f64 },
}

#[derive(Clone, Debug)]
pub struct Wall {
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
    /// Velocity, m/s: x prescribed, y from the load (or 0).
    pub v: Vec2,
    /// Mass that the load accelerates, kg.
    pub mass: f64,
    /// Force of the grains on the wall at this step, N.
    pub force: Vec2,
    /// ... and at the previous step.
    pub force_prev: Vec2,
}

impl Wall {
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
            Control::Load { .. } => 0.5 * self.mass * self.v.y * self.v.y,
        }
    }
    pub fn is_flat(&self) -> bool {
        self.surface == Surface::Flat
    }
}
