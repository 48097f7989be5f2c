//! What a run measures, from a read-only view of the state ([`crate::engine::world::View`]):
//! the energy balance's summary, impacts, wall stresses, the packing inside (stress
//! tensor, coordination, fabric) and its profiles across the gap, block-averaged statistics.
//! May use: `engine` (its view and time step), `physics`, `scene`, `error`.

pub mod energy;
pub mod impact;
pub mod packing;
pub mod profiles;
pub mod stats;
pub mod stress;
