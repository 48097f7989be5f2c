//! What a run measures: the energy balance, impacts, wall stresses.

pub mod energy;
pub mod impact;
pub mod stress;
