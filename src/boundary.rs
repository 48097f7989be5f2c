//! Periodic boundary in x (or none).
//!
//! Without periodicity `period = 0` and `inv_period = 0`, so the minimum-image formula
//! `dx - period * round(dx / period)` is the identity: no branch in the hot loop.

use crate::dim::Vec2;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Boundary {
    /// Left edge of the periodic cell, m.
    pub x_min: f64,
    /// Length of the periodic cell in x, m (0 if not periodic).
    pub period: f64,
    inv_period: f64,
}

impl Boundary {
    pub fn open() -> Self {
        Boundary { x_min: 0.0, period: 0.0, inv_period: 0.0 }
    }
    pub fn periodic_x(x_min: f64, length: f64) -> Self {
        Boundary { x_min, period: length, inv_period: 1.0 / length }
    }
    pub fn is_periodic(&self) -> bool {
        self.period > 0.0
    }
    /// The minimum image of a separation vector.
    #[inline(always)]
    pub fn image(&self, mut d: Vec2) -> Vec2 {
        d.x -= self.period * (d.x * self.inv_period).round();
        d
    }
    /// Bring a position back into [x_min, x_min + period).
    #[inline(always)]
    pub fn wrap(&self, x: &mut Vec2) {
        if self.period > 0.0 {
            let s = ((x.x - self.x_min) * self.inv_period).floor();
            x.x -= s * self.period;
        }
    }
}
