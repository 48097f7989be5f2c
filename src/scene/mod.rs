//! The scene: what is simulated. The scene file and its validation field by field
//! ([`spec`], re-exported here; the numbers that depend on the dimension in [`coords`]), the built-in scenes and the loader ([`builtin`]), grain
//! files ([`grains`]), seeded packings ([`pack`]), and what a scene may ask of the
//! machine ([`limits`]).
//! May use: `physics`, `kernels` (the packing's cell list), `error`.

pub mod builtin;
pub mod coords;
pub mod grains;
pub mod limits;
pub mod pack;
pub mod spec;
pub mod validate;

pub use spec::*;
