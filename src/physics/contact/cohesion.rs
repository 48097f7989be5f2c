//! Cohesion of a contact: none, or DMT (Derjaguin, Muller and Toporov 1975).
//!
//! [`Dmt`]: while two bodies overlap (dn > 0) the normal force is the normal law's
//! elastic force less a constant attraction, `Fn = kn dn - gn vn - F0` with the pull-off
//! force `F0 = 2 pi w R*` (w the pair's work of adhesion,
//! [`crate::physics::material::Material::work_of_adhesion`]). The attraction is the
//! force of the potential `-F0 dn`, which is 0 at first touch: the contact stores
//! `U_n - F0 dn` (U_n the normal law's elastic energy), and an undamped impact returns
//! its speed. Damping makes impacts slower than a sticking speed end with the grains
//! stuck together. The Coulomb cap is `mu |Fn + 2 F0|` (LAMMPS `pair granular dmt`,
//! whose `Fncrit` is the same with the elastic force in place of Fn: the two agree
//! without damping). LAMMPS writes w as `4 pi gamma R*` with gamma = w/2, the surface
//! energy of one surface.
//!
//! [`NoCohesion`] is every other scene's: the kernel has no term for it.

/// A cohesion model, compiled into the contact kernel.
pub trait Cohesion: Copy + Default + Send + Sync + std::fmt::Debug + 'static {
    /// Its name in `explain`.
    const NAME: &'static str;
    /// False: no attraction at all.
    const ON: bool;
}

/// No cohesion.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoCohesion;

impl Cohesion for NoCohesion {
    const NAME: &'static str = "";
    const ON: bool = false;
}

/// DMT cohesion: a constant attraction `2 pi w R*` while the bodies overlap.
#[derive(Clone, Copy, Debug, Default)]
pub struct Dmt;

impl Cohesion for Dmt {
    const NAME: &'static str = "DMT cohesion";
    const ON: bool = true;
}
