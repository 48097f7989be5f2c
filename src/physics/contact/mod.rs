//! Per-contact physics: the normal laws (Hertz, the linear spring), damping, tangential formulations, and
//! their named combinations.

pub mod cohesion;
pub mod damping;
pub mod model;
pub mod normal;
pub mod record;
pub mod rolling;
pub mod tangential;

pub use record::{ContactRecord, Partner};
pub use model::{ContactForce, ContactHistory, EnergyMemory, ContactInput, ContactLaw, ContactModel, LeverArm, ModelOptions};
