//! The physics: what a grain is (shape, mass, state; the dimension, [`dim::Dim`]), the materials and their mixing,
//! the contact laws composed from sub-models, walls, the periodic boundary, the energy
//! ledger, and the number types that run a law on one contact or four in SIMD lanes.
//! May use: `error`. Nothing here knows of scenes, engines or runs.

pub mod boundary;
pub mod contact;
pub mod dim;
pub mod energy;
pub mod lanes;
pub mod material;
pub mod particles;
pub mod restitution;
pub mod walls;
