//! One contact as it acted at one step, for observers: who touched whom, where, and
//! with what force. Recorded only when a run asks for it (the engine's `RecordContacts` stage).

use crate::physics::dim::Vec2;

/// What grain `i` touched.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Partner {
    /// Grain `j` (a free grain, or a grain glued to a rough wall when `j` >= the number
    /// of free grains).
    Grain(u32),
    /// Flat wall number `k` (0: bottom, 1: top).
    Wall(u32),
}

/// One touching contact at one step: the force grain `i` felt, split into its normal
/// and tangential parts, exactly as the contact stage applied it at that step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactRecord {
    pub i: u32,
    pub partner: Partner,
    /// Unit normal from the partner into grain i.
    pub normal: Vec2,
    /// Overlap, m.
    pub overlap: f64,
    /// From the partner's centre (minimum image) to grain i's centre, m; for a flat wall,
    /// from the contact point to grain i's centre.
    pub branch: Vec2,
    /// The contact point, m: between grains on the line of centres, in the middle of the
    /// overlap; with a flat wall, on the wall's plane.
    pub point: Vec2,
    /// Normal force along `normal`, N (positive: repulsive).
    pub normal_force: f64,
    /// Tangential force on grain i (elastic and viscous), N.
    pub tangential_force: Vec2,
    /// Its elastic part (after the Coulomb cap), N: what the contact's tangential state
    /// holds after this step (`-kt xi` for a total displacement xi, the incremental
    /// elastic force itself); the frozen-state cross-checks hand it to the reference codes.
    pub tangential_elastic: Vec2,
    /// The contact slid at this step: its elastic tangential force was cut to the
    /// Coulomb cap mu |Fn|.
    pub sliding: bool,
}

impl ContactRecord {
    /// The total force on grain i, N (the partner feels the opposite).
    pub fn force(&self) -> Vec2 {
        self.normal * self.normal_force + self.tangential_force
    }
}
