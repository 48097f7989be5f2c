//! The reference workbench: the cases grainlab is checked on, the reading of the
//! reference codes' output, and the comparison.
//!
//! A case is a scene plus the codes it is compared with. `grainlab cases` writes every
//! case under `reference/cases/<case>/`: `scene.json`, `case.json`, and what `grainlab
//! export` writes for each code (the deck, `grainlab.data`, `export.json`).
//! `scripts/regen-reference` runs each deck and hands its raw output to `grainlab
//! digest`, which measures it with the engine's own observers (the same estimator on
//! both sides) into `expected/<code>/`. `grainlab compare` and `tests/workbench.rs` run
//! the engine on each case and hold it to the committed numbers. The exporter
//! ([`export`]) writes any scene as a LIGGGHTS deck, a YADE script or a LAMMPS deck, exactly or
//! not at all. May use: everything below it (`study`, `output`, `observe`, `engine`, `scene`,
//! `physics`).

pub mod cases;
pub mod compare;
pub mod digest;
pub mod export;
pub mod frozen;

pub use cases::*;
pub use compare::*;
pub use digest::*;
