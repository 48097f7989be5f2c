//! One contact or four at once: the contact law is written once, generic over its
//! number type, and compiled for `f64` (one contact) and for [`Lanes`] (four contacts
//! side by side in SIMD registers).
//!
//! Every operation the law uses (+, -, *, /, sqrt, comparisons, selects) is correctly
//! rounded lane by lane, so a contact computed in a lane gets the same bits as the same
//! contact computed alone: the four-wide kernel changes speed, not results
//! (`tests/properties.rs` checks it). The traits come from `simba`, nalgebra's own
//! SIMD abstraction; `Vector2<R>` is an ordinary nalgebra vector of lanes.

use nalgebra::Vector2;
use simba::simd::{SimdRealField, SimdValue};

/// Four `f64` lanes.
pub type Lanes = simba::simd::WideF64x4;
/// Number of lanes of [`Lanes`].
pub const LANES: usize = 4;

/// A number type the contact law is compiled for: `f64` or [`Lanes`].
pub trait Real: SimdRealField<Element = f64> + Copy + Default + Send + Sync + std::fmt::Debug {}
impl<T: SimdRealField<Element = f64> + Copy + Default + Send + Sync + std::fmt::Debug> Real for T {}

/// The constant `x` in every lane.
#[inline(always)]
pub fn k<R: Real>(x: f64) -> R {
    R::splat(x)
}

/// `a` where `mask` holds, else `b`.
#[inline(always)]
pub fn pick<R: Real>(mask: R::SimdBool, a: R, b: R) -> R {
    a.select(mask, b)
}

/// `a` where `mask` holds, else `b`, for vectors.
#[inline(always)]
pub fn pick2<R: Real>(mask: R::SimdBool, a: Vector2<R>, b: Vector2<R>) -> Vector2<R> {
    Vector2::new(a.x.select(mask, b.x), a.y.select(mask, b.y))
}

/// Lanes filled from `f(lane)`.
#[inline(always)]
pub fn gather(f: impl Fn(usize) -> f64) -> Lanes {
    Lanes::from([f(0), f(1), f(2), f(3)])
}

/// Vector lanes filled from `f(lane)`.
#[inline(always)]
pub fn gather2(f: impl Fn(usize) -> Vector2<f64>) -> Vector2<Lanes> {
    let v = [f(0), f(1), f(2), f(3)];
    Vector2::new(Lanes::from([v[0].x, v[1].x, v[2].x, v[3].x]), Lanes::from([v[0].y, v[1].y, v[2].y, v[3].y]))
}

/// One lane of a vector of lanes.
#[inline(always)]
pub fn lane2(v: &Vector2<Lanes>, l: usize) -> Vector2<f64> {
    Vector2::new(v.x.extract(l), v.y.extract(l))
}
