//! Dimensions: the [`Dim`] trait that lets one source serve the plane and space, its two
//! instances [`Plane`] (2D, every engine today) and [`Space`] (3D: the contact laws so
//! far, issue 30), and what a "2D grain" weighs.
//!
//! In the plane, grains move in the xy-plane and spin about z. The force law is the
//! 3D Hertz-Mindlin law in every case; what differs between the two grain shapes is
//! only mass and moment of inertia, exactly as in the reference codes:
//! - [`GrainShape::SphereInPlane`] (default): spheres whose centres stay in the plane,
//!   m = 4/3 pi r^3 rho, I = 2/5 m r^2 (a LIGGGHTS 3D monolayer, YADE `blockedDOFs='zXY'`);
//! - [`GrainShape::Disk`]: cylinders of a stated thickness t, m = pi r^2 t rho,
//!   I = 1/2 m r^2 (LIGGGHTS `dimension 2` with t = 1 m).

use std::f64::consts::PI;
use std::fmt::Debug;
use std::ops::{Add, AddAssign, Div, Index, IndexMut, Mul, Neg, Sub, SubAssign};

use nalgebra::{Vector2, Vector3};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::physics::lanes::{Lanes, Real, gather, pick};

/// The number of dimensions as a type, after rapier's and nalgebra's `dim2`/`dim3`: the
/// vector and spin types of one contact (`R = f64`) or four in lanes (`R = Lanes`), and
/// the few operations whose form depends on the dimension (cross products, the turn of
/// a contact frame). Code generic over `D: Dim` is written once and compiled for each;
/// with [`Plane`] it is the same operations, in the same order, as the 2D code it
/// replaced, so 2D keeps its bits (tests/properties.rs).
pub trait Dim: Copy + Default + Debug + Send + Sync + 'static {
    /// Number of space dimensions.
    const D: usize;
    /// `"plane"` or `"space"`, for messages.
    const NAME: &'static str;
    /// A vector (position, velocity, force: m, m/s, N).
    type Vector<R: Real>: Copy
        + Default
        + Debug
        + Send
        + Sync
        + Add<Output = Self::Vector<R>>
        + Sub<Output = Self::Vector<R>>
        + Neg<Output = Self::Vector<R>>
        + Mul<R, Output = Self::Vector<R>>
        + Div<R, Output = Self::Vector<R>>
        + AddAssign
        + SubAssign
        + Index<usize, Output = R>
        + IndexMut<usize>;
    /// A spin or a torque: a number about z in the plane, a vector in space (rad/s, N m).
    type Spin<R: Real>: Copy + Default + Debug + Send + Sync + Add<Output = Self::Spin<R>> + Sub<Output = Self::Spin<R>> + Mul<R, Output = Self::Spin<R>>;
    /// What turns a contact about its normal: the pair's spin sum `w_i + w_j` in space
    /// (rad/s); `()` in the plane, where every spin is perpendicular to the normal.
    type Twist<R: Real>: Copy + Default + Debug + Send + Sync;
    /// A vector as a checkpoint stores it (the same numbers).
    type Saved: Copy + Debug + serde::Serialize + serde::de::DeserializeOwned;
    fn zero<R: Real>() -> Self::Vector<R>;
    fn dot<R: Real>(a: Self::Vector<R>, b: Self::Vector<R>) -> R;
    fn norm_squared<R: Real>(a: Self::Vector<R>) -> R;
    fn norm<R: Real>(a: Self::Vector<R>) -> R;
    /// `a` where `mask` holds, else `b`, lane by lane.
    fn pick<R: Real>(mask: R::SimdBool, a: Self::Vector<R>, b: Self::Vector<R>) -> Self::Vector<R>;
    /// Vector lanes filled from `f(lane)`.
    fn gather(f: impl Fn(usize) -> Self::Vector<f64>) -> Self::Vector<Lanes>;
    /// One lane of a vector of lanes.
    fn lane(v: &Self::Vector<Lanes>, l: usize) -> Self::Vector<f64>;
    /// Spin lanes filled from `f(lane)`.
    fn gather_spin(f: impl Fn(usize) -> Self::Spin<f64>) -> Self::Spin<Lanes>;
    /// One lane of a spin of lanes.
    fn spin_lane(w: &Self::Spin<Lanes>, l: usize) -> Self::Spin<f64>;
    /// What turns a contact about its normal ([`Dim::Twist`]) from the pair's spin sum
    /// `w_i + w_j`: itself in space, nothing in the plane.
    fn twist<R: Real>(spin_sum: Self::Spin<R>) -> Self::Twist<R>;
    fn save(v: Self::Vector<f64>) -> Self::Saved;
    fn load(s: Self::Saved) -> Self::Vector<f64>;
    /// `w x a`: the velocity of a point at `a` from the centre of a grain spinning at `w`.
    fn spin_cross<R: Real>(w: Self::Spin<R>, a: Self::Vector<R>) -> Self::Vector<R>;
    /// `a x b` (a torque from an arm and a force).
    fn cross<R: Real>(a: Self::Vector<R>, b: Self::Vector<R>) -> Self::Spin<R>;
    /// `a x w` for a vector and a spin: with `w = a_i w_i + a_j w_j` and `a` the normal
    /// from j to i, the spins' part of the velocity of i's contact point relative to j's.
    fn cross_spin<R: Real>(a: Self::Vector<R>, w: Self::Spin<R>) -> Self::Vector<R>;
    /// No spin, no torque.
    fn spin_zero<R: Real>() -> Self::Spin<R>;
    /// `a . b` of two spins (or a torque and a spin: a power, W).
    fn spin_dot<R: Real>(a: Self::Spin<R>, b: Self::Spin<R>) -> R;
    /// `c |w|^2`: with `c = I/2` (kg m^2) the rotational kinetic energy of a grain of
    /// isotropic inertia, J (in the plane `(c w) w`, the 2D code's order).
    fn spin_kinetic<R: Real>(c: R, w: Self::Spin<R>) -> R;
    /// A vector with every component `c` (a per-component factor of the integrator).
    fn splat(c: f64) -> Self::Vector<f64>;
    /// A spin with every component `c`.
    fn spin_splat(c: f64) -> Self::Spin<f64>;
    /// The components of vectors as they are stored (x, y, x, y, ... or x, y, z, ...):
    /// loops over them vectorise without splitting a vector into registers and back.
    fn flat(v: &[Self::Vector<f64>]) -> &[f64];
    fn flat_mut(v: &mut [Self::Vector<f64>]) -> &mut [f64];
    /// The components of spins as they are stored.
    fn spin_flat(w: &[Self::Spin<f64>]) -> &[f64];
    fn spin_flat_mut(w: &mut [Self::Spin<f64>]) -> &mut [f64];
    /// A vector attached to a contact (YADE's elastic shear force) carried along as the
    /// contact frame turns during one step, to first order as YADE's `ScGeom::rotate`:
    /// `f -= f x (n_prev x n)`, then about the old normal by the pair's mean spin along
    /// it, `f -= f x (dt/2 (n_prev . spin_sum) n_prev)`, with `spin_sum = w_i + w_j`
    /// (rad/s). In the plane every spin is along z, perpendicular to every normal, so the
    /// second turn is none.
    fn turn<R: Real>(f: Self::Vector<R>, n_prev: Self::Vector<R>, n: Self::Vector<R>, spin_sum: Self::Twist<R>, dt: R) -> Self::Vector<R>;
    /// The plane's own arrays when `Self` is the plane, `None` in space. Where the plane
    /// has hand-written wide kernels (AVX2, AVX-512: the contact sweep, the drift and
    /// the kicks), code written once over `D` hands them its arrays through these and
    /// runs its own loop in space; the choice is made at compile time.
    fn plane_vectors(v: &[Self::Vector<f64>]) -> Option<&[Vec2]>;
    fn plane_vectors_mut(v: &mut [Self::Vector<f64>]) -> Option<&mut [Vec2]>;
    fn plane_vec_mut(v: &mut Vec<Self::Vector<f64>>) -> Option<&mut Vec<Vec2>>;
    fn plane_spins(w: &[Self::Spin<f64>]) -> Option<&[f64]>;
    fn plane_spins_mut(w: &mut [Self::Spin<f64>]) -> Option<&mut [f64]>;
    /// The number of components of a spin: 1 in the plane, 3 in space.
    const SPIN: usize;
    /// A spin `w` about z (rad/s): the plane's number, `[0, 0, w]` in space.
    fn spin_about_z(w: f64) -> Self::Spin<f64>;
    /// A spin of three components (rad/s): in the plane its z component (a scene's
    /// validation refuses one with others in 2D).
    fn spin_of(w: [f64; 3]) -> Self::Spin<f64>;
    /// A spin's components (one in the plane, three in space), as a scene writes them.
    fn spin_components(w: &Self::Spin<f64>) -> &[f64];
}

/// Two dimensions: grains in the xy-plane spinning about z (every engine today).
#[derive(Clone, Copy, Debug, Default)]
pub struct Plane;

/// Three dimensions: spheres in space, spins about any axis.
#[derive(Clone, Copy, Debug, Default)]
pub struct Space;

/// The methods of [`Dim`] that both vector types have from nalgebra: the same calls as
/// the 2D code made before it was generic.
macro_rules! nalgebra_vector {
    ($v:ident) => {
        #[inline(always)]
        fn zero<R: Real>() -> $v<R> {
            $v::zeros()
        }
        #[inline(always)]
        fn dot<R: Real>(a: $v<R>, b: $v<R>) -> R {
            a.dot(&b)
        }
        #[inline(always)]
        fn norm_squared<R: Real>(a: $v<R>) -> R {
            a.norm_squared()
        }
        #[inline(always)]
        fn norm<R: Real>(a: $v<R>) -> R {
            a.norm()
        }
        fn save(v: $v<f64>) -> $v<f64> {
            v
        }
        #[inline(always)]
        fn splat(c: f64) -> $v<f64> {
            $v::repeat(c)
        }
        #[inline(always)]
        fn flat(v: &[$v<f64>]) -> &[f64] {
            bytemuck::cast_slice(v)
        }
        #[inline(always)]
        fn flat_mut(v: &mut [$v<f64>]) -> &mut [f64] {
            bytemuck::cast_slice_mut(v)
        }
        fn load(s: $v<f64>) -> $v<f64> {
            s
        }
    };
}

impl Dim for Plane {
    const D: usize = 2;
    const NAME: &'static str = "plane";
    const SPIN: usize = 1;
    #[inline(always)]
    fn plane_vectors(v: &[Vec2]) -> Option<&[Vec2]> {
        Some(v)
    }
    #[inline(always)]
    fn plane_vectors_mut(v: &mut [Vec2]) -> Option<&mut [Vec2]> {
        Some(v)
    }
    #[inline(always)]
    fn plane_vec_mut(v: &mut Vec<Vec2>) -> Option<&mut Vec<Vec2>> {
        Some(v)
    }
    #[inline(always)]
    fn plane_spins(w: &[f64]) -> Option<&[f64]> {
        Some(w)
    }
    #[inline(always)]
    fn plane_spins_mut(w: &mut [f64]) -> Option<&mut [f64]> {
        Some(w)
    }
    type Vector<R: Real> = Vector2<R>;
    type Spin<R: Real> = R;
    type Twist<R: Real> = ();
    type Saved = Vector2<f64>;
    nalgebra_vector!(Vector2);
    #[inline(always)]
    fn pick<R: Real>(mask: R::SimdBool, a: Vector2<R>, b: Vector2<R>) -> Vector2<R> {
        crate::physics::lanes::pick2(mask, a, b)
    }
    #[inline(always)]
    fn gather(f: impl Fn(usize) -> Vector2<f64>) -> Vector2<Lanes> {
        crate::physics::lanes::gather2(f)
    }
    #[inline(always)]
    fn lane(v: &Vector2<Lanes>, l: usize) -> Vector2<f64> {
        crate::physics::lanes::lane2(v, l)
    }
    #[inline(always)]
    fn gather_spin(f: impl Fn(usize) -> f64) -> Lanes {
        gather(f)
    }
    #[inline(always)]
    fn spin_lane(w: &Lanes, l: usize) -> f64 {
        use simba::simd::SimdValue;
        w.extract(l)
    }
    #[inline(always)]
    fn twist<R: Real>(_: R) {}
    #[inline(always)]
    fn spin_cross<R: Real>(w: R, a: Vector2<R>) -> Vector2<R> {
        Vector2::new(-w * a.y, w * a.x)
    }
    #[inline(always)]
    fn cross<R: Real>(a: Vector2<R>, b: Vector2<R>) -> R {
        cross(a, b)
    }
    #[inline(always)]
    fn cross_spin<R: Real>(a: Vector2<R>, w: R) -> Vector2<R> {
        Vector2::new(a.y, -a.x) * w
    }
    #[inline(always)]
    fn spin_zero<R: Real>() -> R {
        R::zero()
    }
    #[inline(always)]
    fn spin_dot<R: Real>(a: R, b: R) -> R {
        a * b
    }
    #[inline(always)]
    fn spin_kinetic<R: Real>(c: R, w: R) -> R {
        c * w * w
    }
    #[inline(always)]
    fn spin_splat(c: f64) -> f64 {
        c
    }
    #[inline(always)]
    fn spin_flat(w: &[f64]) -> &[f64] {
        w
    }
    #[inline(always)]
    fn spin_flat_mut(w: &mut [f64]) -> &mut [f64] {
        w
    }
    fn spin_about_z(w: f64) -> f64 {
        w
    }
    fn spin_of(w: [f64; 3]) -> f64 {
        w[2]
    }
    fn spin_components(w: &f64) -> &[f64] {
        std::slice::from_ref(w)
    }
    #[inline(always)]
    fn turn<R: Real>(f: Vector2<R>, n_prev: Vector2<R>, n: Vector2<R>, _spin_sum: (), _dt: R) -> Vector2<R> {
        // The axis n_prev x n is along z, and f - f x (s z) = f + (-f_y, f_x) s.
        let s = cross(n_prev, n);
        f + Vector2::new(-f.y, f.x) * s
    }
}

impl Dim for Space {
    const D: usize = 3;
    const NAME: &'static str = "space";
    const SPIN: usize = 3;
    fn plane_vectors(_: &[Vector3<f64>]) -> Option<&[Vec2]> {
        None
    }
    fn plane_vectors_mut(_: &mut [Vector3<f64>]) -> Option<&mut [Vec2]> {
        None
    }
    fn plane_vec_mut(_: &mut Vec<Vector3<f64>>) -> Option<&mut Vec<Vec2>> {
        None
    }
    fn plane_spins(_: &[Vector3<f64>]) -> Option<&[f64]> {
        None
    }
    fn plane_spins_mut(_: &mut [Vector3<f64>]) -> Option<&mut [f64]> {
        None
    }
    type Vector<R: Real> = Vector3<R>;
    type Spin<R: Real> = Vector3<R>;
    type Twist<R: Real> = Vector3<R>;
    type Saved = Vector3<f64>;
    nalgebra_vector!(Vector3);
    #[inline(always)]
    fn pick<R: Real>(mask: R::SimdBool, a: Vector3<R>, b: Vector3<R>) -> Vector3<R> {
        Vector3::new(pick(mask, a.x, b.x), pick(mask, a.y, b.y), pick(mask, a.z, b.z))
    }
    #[inline(always)]
    fn gather(f: impl Fn(usize) -> Vector3<f64>) -> Vector3<Lanes> {
        Vector3::new(gather(|l| f(l).x), gather(|l| f(l).y), gather(|l| f(l).z))
    }
    #[inline(always)]
    fn lane(v: &Vector3<Lanes>, l: usize) -> Vector3<f64> {
        use simba::simd::SimdValue;
        Vector3::new(v.x.extract(l), v.y.extract(l), v.z.extract(l))
    }
    #[inline(always)]
    fn gather_spin(f: impl Fn(usize) -> Vector3<f64>) -> Vector3<Lanes> {
        Self::gather(f)
    }
    #[inline(always)]
    fn spin_lane(w: &Vector3<Lanes>, l: usize) -> Vector3<f64> {
        Self::lane(w, l)
    }
    #[inline(always)]
    fn twist<R: Real>(spin_sum: Vector3<R>) -> Vector3<R> {
        spin_sum
    }
    #[inline(always)]
    fn spin_cross<R: Real>(w: Vector3<R>, a: Vector3<R>) -> Vector3<R> {
        w.cross(&a)
    }
    #[inline(always)]
    fn cross<R: Real>(a: Vector3<R>, b: Vector3<R>) -> Vector3<R> {
        a.cross(&b)
    }
    #[inline(always)]
    fn cross_spin<R: Real>(a: Vector3<R>, w: Vector3<R>) -> Vector3<R> {
        a.cross(&w)
    }
    #[inline(always)]
    fn spin_zero<R: Real>() -> Vector3<R> {
        Vector3::zeros()
    }
    #[inline(always)]
    fn spin_dot<R: Real>(a: Vector3<R>, b: Vector3<R>) -> R {
        a.dot(&b)
    }
    #[inline(always)]
    fn spin_kinetic<R: Real>(c: R, w: Vector3<R>) -> R {
        c * w.norm_squared()
    }
    #[inline(always)]
    fn spin_splat(c: f64) -> Vector3<f64> {
        Vector3::repeat(c)
    }
    #[inline(always)]
    fn spin_flat(w: &[Vector3<f64>]) -> &[f64] {
        bytemuck::cast_slice(w)
    }
    #[inline(always)]
    fn spin_flat_mut(w: &mut [Vector3<f64>]) -> &mut [f64] {
        bytemuck::cast_slice_mut(w)
    }
    fn spin_about_z(w: f64) -> Vector3<f64> {
        Vector3::new(0.0, 0.0, w)
    }
    fn spin_of(w: [f64; 3]) -> Vector3<f64> {
        Vector3::from(w)
    }
    fn spin_components(w: &Vector3<f64>) -> &[f64] {
        w.as_slice()
    }
    #[inline(always)]
    fn turn<R: Real>(f: Vector3<R>, n_prev: Vector3<R>, n: Vector3<R>, spin_sum: Vector3<R>, dt: R) -> Vector3<R> {
        let f = f - f.cross(&n_prev.cross(&n));
        let twist = n_prev * (dt * crate::physics::lanes::k::<R>(0.5) * n_prev.dot(&spin_sum));
        f - f.cross(&twist)
    }
}


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
