//! Periodic boundary in x (or none); in space also in z (either or both).
//!
//! Without periodicity along an axis its `period = 0` and `inv_period = 0`, so the
//! minimum-image formula `dx - period * round(dx / period)` is the identity: no branch
//! in the hot loop. In the plane (the default `D`) the z axis does not exist: its
//! formula is not compiled.

use std::marker::PhantomData;

use crate::physics::dim::{Dim, Plane};
use crate::physics::lanes::Real;

/// The periodic cell of a world in the plane (`D = Plane`, the default) or in space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Boundary<D: Dim = Plane> {
    /// Left edge of the periodic cell, m.
    pub x_min: f64,
    /// Length of the periodic cell in x, m (0 if not periodic).
    pub period: f64,
    inv_period: f64,
    /// Back edge of the periodic cell in z, m (space only).
    pub z_min: f64,
    /// Length of the periodic cell in z, m (0 if not periodic; always 0 in the plane).
    pub z_period: f64,
    z_inv_period: f64,
    dim: PhantomData<D>,
}

impl<D: Dim> Boundary<D> {
    pub fn open() -> Self {
        Boundary { x_min: 0.0, period: 0.0, inv_period: 0.0, z_min: 0.0, z_period: 0.0, z_inv_period: 0.0, dim: PhantomData }
    }
    pub fn periodic_x(x_min: f64, length: f64) -> Self {
        Boundary { x_min, period: length, inv_period: 1.0 / length, ..Self::open() }
    }
    /// 1 / period, 1/m (0 if not periodic).
    pub fn inv_period(&self) -> f64 {
        self.inv_period
    }
    /// The same cell as the plane's, when `D` is the plane (`None` in space): for the
    /// plane's wide kernels ([`Dim::plane_vectors`]).
    #[inline(always)]
    pub fn plane(&self) -> Option<Boundary<Plane>> {
        (D::D == 2).then_some(Boundary { x_min: self.x_min, period: self.period, inv_period: self.inv_period, z_min: 0.0, z_period: 0.0, z_inv_period: 0.0, dim: PhantomData })
    }
    /// Periodic in x.
    pub fn is_periodic(&self) -> bool {
        self.period > 0.0
    }
    /// Periodic in z (never in the plane).
    pub fn is_periodic_z(&self) -> bool {
        self.z_period > 0.0
    }
    /// The minimum image of a separation vector (or of four, in lanes).
    #[inline(always)]
    pub fn image<R: Real>(&self, mut d: D::Vector<R>) -> D::Vector<R> {
        let s = nearest_integer(d[0] * R::splat(self.inv_period));
        d[0] -= R::splat(self.period) * s;
        if D::D == 3 {
            let s = nearest_integer(d[2] * R::splat(self.z_inv_period));
            d[2] -= R::splat(self.z_period) * s;
        }
        d
    }
    /// True when one of the grains at `x` has moved more than `limit` (a squared
    /// distance, m^2) from `at`, its position at the last neighbour-list build, measured
    /// through the periodic image. A full sweep without an early exit, so that it
    /// vectorises; the stages that move grains call it on what they moved.
    #[inline(always)]
    pub fn any_moved_beyond(&self, x: &[D::Vector<f64>], at: &[D::Vector<f64>], limit: f64) -> bool {
        x.iter().zip(at).fold(false, |far, (&a, &b)| far | (D::norm_squared(self.image(a - b)) > limit))
    }
    /// Whether any of the positions `x` is outside the periodic cell (false without
    /// periodicity). A full sweep without an early exit, so that it vectorises.
    #[inline(always)]
    pub fn any_outside(&self, x: &[D::Vector<f64>]) -> bool {
        let z = D::D == 3 && self.is_periodic_z();
        if !self.is_periodic() && !z {
            return false;
        }
        let x_out = self.is_periodic() && x.iter().fold(false, |out, x| out | beyond(x[0] - self.x_min, self.period));
        x_out || (z && x.iter().fold(false, |out, x| out | beyond(x[2] - self.z_min, self.z_period)))
    }
    /// Bring a position back into [x_min, x_min + period) (and in space into
    /// [z_min, z_min + z_period)).
    #[inline(always)]
    pub fn wrap(&self, x: &mut D::Vector<f64>) {
        x[0] = wrap_along(x[0], self.x_min, self.period, self.inv_period);
        if D::D == 3 {
            x[2] = wrap_along(x[2], self.z_min, self.z_period, self.z_inv_period);
        }
    }
}

impl Boundary<crate::physics::dim::Space> {
    /// Periodic in x over `[x_min, x_min + x_length)` and in z over `[z_min, z_min +
    /// z_length)`, m; a length of 0 leaves that axis open.
    pub fn periodic(x: Option<(f64, f64)>, z: Option<(f64, f64)>) -> Self {
        let mut b = x.map_or_else(Self::open, |(x_min, l)| Self::periodic_x(x_min, l));
        if let Some((z_min, l)) = z {
            (b.z_min, b.z_period, b.z_inv_period) = (z_min, l, 1.0 / l);
        }
        b
    }
}

/// Whether a position `xr` from the edge of a periodic cell of length `period` is not in
/// [0, period) (true for every non-zero `xr` without periodicity).
#[inline(always)]
fn beyond(xr: f64, period: f64) -> bool {
    !(xr >= 0.0 && xr < period)
}

/// A coordinate `x` brought back into [lo, lo + period) (unchanged without periodicity).
#[inline(always)]
fn wrap_along(x: f64, lo: f64, period: f64, inv_period: f64) -> f64 {
    let xr = x - lo;
    let v = xr * inv_period;
    let s: f64 = nearest_integer(v);
    let s = if s > v { s - 1.0 } else { s };
    // Inside already (almost always), the position keeps its bits. A select, not a
    // branch around a store: the drift loop vectorises with a blend (with AVX-512 the
    // conditional store compiled to a masked scatter, four grains at a time).
    let outside = period > 0.0 && beyond(xr, period);
    if outside { x - s * period } else { x }
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

    use crate::physics::dim::Vec2;

    #[test]
    fn wrap_and_image() {
        let b = Boundary::<Plane>::periodic_x(-1.0, 4.0);
        for &(x, want) in &[(-1.0, -1.0), (2.999, 2.999), (3.0, -1.0), (3.5, -0.5), (-1.5, 2.5), (11.25, -0.75)] {
            let mut p = Vec2::new(x, 0.0);
            b.wrap(&mut p);
            assert!((p.x - want).abs() < 1e-12, "{x} -> {} (want {want})", p.x);
        }
        assert_eq!(b.image(Vec2::new(3.0, 1.0)), Vec2::new(-1.0, 1.0));
        assert_eq!(b.image(Vec2::new(-2.9, 0.0)).x, -2.9 + 4.0);
        assert_eq!(Boundary::<Plane>::open().image(Vec2::new(7.0, 1.0)), Vec2::new(7.0, 1.0));
    }
}
