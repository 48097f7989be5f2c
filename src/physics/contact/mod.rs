//! Per-contact physics: the Hertz normal law, damping, tangential formulations, and
//! their named combinations.

pub mod damping;
pub mod model;
pub mod normal;
pub mod tangential;

pub use model::{ContactForce, ContactHistory, EnergyMemory, ContactInput, ContactLaw, ContactModel, LeverArm, ModelOptions};
