//! The engine: a scene built into a world of grains and walls ([`world`]; [`build`],
//! after the checks of [`consistency`]) and the stages that step it ([`stages`],
//! [`integrate`]), run in order by the [`simulation`] behind the [`simulation::Engine`]
//! trait, which hands out a read-only [`world::View`]; the time step ([`timestep`]), the
//! neighbour-list rebuilds ([`neighbor`]), the domain's checks and diagnoses
//! ([`domain`]), the snapshot a checkpoint holds ([`snapshot`]), the contact stage on several threads (`parallel`, with the feature).
//! May use: `scene`, `kernels`, `physics`, `error`, `finite`. Inside, the order is
//! neighbor, domain, timestep, consistency < world < integrate < stages, parallel <
//! simulation < snapshot < build.

pub mod build;
pub mod consistency;
pub mod domain;
pub mod effects;
pub mod integrate;
pub mod neighbor;
#[cfg(feature = "parallel")]
pub mod parallel;
pub mod simulation;
pub mod snapshot;
pub mod stages;
pub mod timestep;
pub mod world;
