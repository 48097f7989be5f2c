//! Periodic boundary in x (or none).
//!
//! Without periodicity `period = 0` and `inv_period = 0`, so the minimum-image formula
//! `dx - period * round(dx / period)` is the identity: no branch in the hot loop.

use nalgebra::Vector2;

use crate::physics::dim::Vec2;
use crate::physics::lanes::Real;

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
    /// 1 / period, 1/m (0 if not periodic).
    pub fn inv_period(&self) -> f64 {
        self.inv_period
    }
    pub fn is_periodic(&self) -> bool {
        self.period > 0.0
    }
    /// The minimum image of a separation vector (or of four, in lanes).
    #[inline(always)]
    pub fn image<R: Real>(&self, mut d: Vector2<R>) -> Vector2<R> {
        let s = nearest_integer(d.x * R::splat(self.inv_period));
        d.x -= R::splat(self.period) * s;
        d
    }
    /// True when one of the grains at `x` has moved more than `limit` (a squared
    /// distance, m^2) from `at`, its position at the last neighbour-list build, measured
    /// through the periodic image. A full sweep without an early exit, so that it
    /// vectorises; the stages that move grains call it on what they moved.
    #[inline(always)]
    pub fn any_moved_beyond(&self, x: &[Vec2], at: &[Vec2], limit: f64) -> bool {
        x.iter().zip(at).fold(false, |far, (a, b)| far | (self.image(a - b).norm_squared() > limit))
    }
    /// Whether any of the positions `x` is outside the periodic cell (false without
    /// periodicity). A full sweep without an early exit, so that it vectorises.
    #[inline(always)]
    pub fn any_outside(&self, x: &[Vec2]) -> bool {
        if !self.is_periodic() {
            return false;
        }
        x.iter().fold(false, |out, x| out | self.beyond(x.x - self.x_min))
    }
    /// Whether a position `xr` from the left edge of the periodic cell is not in
    /// [0, period) (true for every non-zero `xr` without periodicity).
    #[inline(always)]
    fn beyond(&self, xr: f64) -> bool {
        !(xr >= 0.0 && xr < self.period)
    }
    /// Bring a position back into [x_min, x_min + period).
    #[inline(always)]
    pub fn wrap(&self, x: &mut Vec2) {
        let xr = x.x - self.x_min;
        let v = xr * self.inv_period;
        let s: f64 = nearest_integer(v);
        let s = if s > v { s - 1.0 } else { s };
        // Inside already (almost always), the position keeps its bits. A select, not a
        // branch around a store: the drift loop vectorises with a blend (with AVX-512 the
        // conditional store compiled to a masked scatter, four grains at a time).
        let outside = self.period > 0.0 && self.beyond(xr);
        x.x = if outside { x.x - s * self.period } else { x.x };
    }
}

/// The integer nearest to `v` (ties to even), with two additions instead of a call to
/// the C library's `round` (baseline x86-64 has no rounding instruction; this sits in
/// the innermost loop). Exact for every finite `v`: from 2^51 on, `v` is an integer.
#[inline(always)]
pub fn nearest_integer<R: Real>(v: R) -> R {
    let shift = R::splat(ROUND_SHIFT);
    crate::physics::lanes::pick(v.simd_abs().simd_lt(R::splat(ROUND_EXACT_FROM)), (v + shift) - shift, v)
}

/// 1.5 * 2^52: adding it to a number below 2^51 in magnitude leaves no fractional bits,
/// so the sum is rounded to an integer ([`nearest_integer`]).
pub const ROUND_SHIFT: f64 = 6_755_399_441_055_744.0;
/// 2^51: from here on every `f64` is an integer ([`nearest_integer`] returns it as is).
pub const ROUND_EXACT_FROM: f64 = 2_251_799_813_685_248.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_integer_matches_round_away_from_ties() {
        use simba::simd::SimdValue;
        for &v in &[0.0f64, 0.49, 0.51, -0.49, -0.51, 1.2, -1.7, 3.0, -3.0, 1e10 + 0.3, -1e10 - 0.7, 1e300, -1e300, 4503599627370497.0] {
            assert_eq!(nearest_integer(v), v.round(), "{v}");
            let lanes: crate::physics::lanes::Lanes = nearest_integer(crate::physics::lanes::Lanes::splat(v));
            assert_eq!(lanes.extract(2), v.round(), "{v} in lanes");
        }
        assert_eq!(nearest_integer(2.5f64), 2.0);
        assert_eq!(nearest_integer(-0.5f64).abs(), 0.0);
    }

    #[test]
    fn wrap_and_image() {
        let b = Boundary::periodic_x(-1.0, 4.0);
        for &(x, want) in &[(-1.0, -1.0), (2.999, 2.999), (3.0, -1.0), (3.5, -0.5), (-1.5, 2.5), (11.25, -0.75)] {
            let mut p = Vec2::new(x, 0.0);
            b.wrap(&mut p);
            assert!((p.x - want).abs() < 1e-12, "{x} -> {} (want {want})", p.x);
        }
        assert_eq!(b.image(Vec2::new(3.0, 1.0)), Vec2::new(-1.0, 1.0));
        assert_eq!(b.image(Vec2::new(-2.9, 0.0)).x, -2.9 + 4.0);
        assert_eq!(Boundary::open().image(Vec2::new(7.0, 1.0)), Vec2::new(7.0, 1.0));
    }
}
