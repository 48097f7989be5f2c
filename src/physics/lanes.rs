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
///
/// On x86-64 with AVX the four values go into a register with AVX's own instructions
/// (two loads, two high-half loads and one insert for four values read from memory);
/// written portably, the compiler stored the lanes one value at a time and spilled
/// between them (in the contact kernel's gather of four pairs, 258 of 429 instructions
/// were scalar moves). With this and [`gather2`], whole runs at 5000 grains made 6-7%
/// more particle-steps per second (Zen 4). The same values either way: this only moves
/// data, and `tests/properties.rs` checks each lane against its contact alone.
#[inline(always)]
pub fn gather(f: impl Fn(usize) -> f64) -> Lanes {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
    {
        use std::arch::x86_64::*;
        // SAFETY: the build targets AVX; both types are four f64 in 32 bytes.
        unsafe { std::mem::transmute::<__m256d, Lanes>(_mm256_set_pd(f(3), f(2), f(1), f(0))) }
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
    Lanes::from([f(0), f(1), f(2), f(3)])
}

/// Vector lanes filled from `f(lane)`: the x of the four vectors in one register, the
/// y in another. With AVX, each vector is loaded whole and the four are transposed with
/// two inserts and two unpacks (see [`gather`]).
#[inline(always)]
pub fn gather2(f: impl Fn(usize) -> Vector2<f64>) -> Vector2<Lanes> {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
    {
        use std::arch::x86_64::*;
        // SAFETY: the build targets AVX; Vector2<f64> is two f64, Lanes four.
        unsafe {
            let v: [__m128d; 4] = std::array::from_fn(|l| std::mem::transmute::<[f64; 2], __m128d>(f(l).into()));
            // (x0 y0 x2 y2) and (x1 y1 x3 y3), then the x and the y of each.
            let a = _mm256_set_m128d(v[2], v[0]);
            let b = _mm256_set_m128d(v[3], v[1]);
            Vector2::new(std::mem::transmute::<__m256d, Lanes>(_mm256_unpacklo_pd(a, b)), std::mem::transmute::<__m256d, Lanes>(_mm256_unpackhi_pd(a, b)))
        }
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
    {
        let v = [f(0), f(1), f(2), f(3)];
        Vector2::new(Lanes::from([v[0].x, v[1].x, v[2].x, v[3].x]), Lanes::from([v[0].y, v[1].y, v[2].y, v[3].y]))
    }
}

/// One lane of a vector of lanes.
#[inline(always)]
pub fn lane2(v: &Vector2<Lanes>, l: usize) -> Vector2<f64> {
    Vector2::new(v.x.extract(l), v.y.extract(l))
}
