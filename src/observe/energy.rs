//! The energy balance's summary: the largest residual of a run, and how much energy the
//! tangential springs created against what the scene put in (the ledger itself, term by
//! term, is [`crate::physics::energy`]).

use serde::Serialize;

use crate::physics::energy::EnergyRow;

#[derive(Clone, Debug, Serialize)]
pub struct EnergySummary {
    pub final_row: EnergyRow,
    /// Largest |residual| over the run relative to the energy put in (initial energy +
    /// the magnitudes of all work terms).
    pub max_residual_rel: f64,
    /// Energy the tangential springs created (the tangential model work W_t) relative to
    /// the energy the scene put in from outside (initial energy, walls, load, gravity).
    /// It grows with dt at first order; above [`TANGENTIAL_WORK_WARNING`] the springs,
    /// not the walls, drive the flow, and the run says so.
    pub tangential_work_share: f64,
    /// A warning when `tangential_work_share` is too large, else none.
    pub warning: Option<String>,
}

/// Tangential model work, as a share of the external energy input, above which a run
/// warns: half. The shear cell shows 0.2 at t_c/50, 0.8 at t_c/12.5 and 5 at t_c/5
/// (docs/accuracy-cost.md).
pub const TANGENTIAL_WORK_WARNING: f64 = 0.5;

pub fn energy_summary(row: EnergyRow, max_residual_rel: f64, dt: f64) -> EnergySummary {
    let external = row.initial_j + row.work_walls_j.abs() + row.work_load_j.abs() + row.work_gravity_j.abs();
    let share = if external > 0.0 { row.tangential_model_work_j / external } else { 0.0 };
    let warning = (share > TANGENTIAL_WORK_WARNING).then(|| {
        format!(
            "the tangential springs created {:.0}% as much energy as the scene put in (tangential model work {:.3e} J): the time step {:.3e} s is too coarse for the tangential law; use more steps per contact, or add model.general_damping",
            100.0 * share,
            row.tangential_model_work_j,
            dt
        )
    });
    EnergySummary { final_row: row, max_residual_rel, tangential_work_share: share, warning }
}
