//! Studies: a scene built and run with its observers and outputs ([`run`]), stage by
//! stage when it is a protocol ([`protocol`]), over the time
//! step or the grains' stiffness, against references beyond the swept range ([`sweep`]), over packing seeds ([`ensemble`]), and the accuracy calibration that resolves an
//! accuracy rule into a time step before the engine is built ([`accuracy`]).
//! May use: everything below it (`output`, `observe`, `engine`, `scene`, `kernels`,
//! `physics`).

pub mod accuracy;
pub mod ensemble;
pub mod protocol;
pub mod run;
pub mod sweep;

pub use accuracy::{build, build_in, build_limited, build_with};
