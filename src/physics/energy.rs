//! The energy balance (seed sections V.2 and VI.2).
//!
//! Every work term is a trapezoidal integral of the force over the displacement of the
//! step, which is the discrete counterpart of the velocity-Verlet kinetic energy: the
//! balance then closes to O(dt^2), and a term that is missing or inconsistent (a torque
//! that does not match the contact-point velocity, a wall force not counted) shows up
//! at once in the residual.
//!
//! `residual = (E_kin + E_rot + E_wall + U_n + U_t) - E_0 + D_n + D_t + D_slip + D_general + D_roll
//!             - W_t - W_walls - W_load - W_gravity`
//! where `W_t` ("tangential model work") is the energy the tangential spring gains
//! because its stiffness kt(dn) and its frame change under it. It is a property of the
//! contact laws (neither LIGGGHTS' nor YADE's tangential spring is conservative), not a
//! numerical error, and it is the seed's source of energy growth.
//!
//! Per contact and step, `W_t` gains `U_t - U_t,prev + E_slip + W_spring`, where
//! `W_spring` is the trapezoidal work of the elastic tangential force over the contact
//! displacement. The `U_t` differences add up over a contact's life to the energy its
//! spring holds now (a released contact's spring holds none), so the ledger keeps
//! `W_t - U_t` (the sum of `E_slip + W_spring`) and adds the stored `U_t` when it is
//! read: the same quantity, with fewer roundings, and no stored energy computed at the
//! steps nobody looks at.
//!
//! Where the pair contacts' terms go: each listed pair sums its own ([`EnergySums`], in
//! its energy memory), with no order between pairs to keep; at each neighbour-list
//! rebuild and whenever the ledger is read, the pairs' sums are added in list order.
//! The sums are therefore the same on any number of threads, and the kernel adds to
//! nothing that another pair adds to.

use serde::{Deserialize, Serialize};

/// Running totals, J. Dissipations are positive when energy leaves the grains.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct EnergyLedger {
    /// Energy dissipated by normal damping (and by the clamp, if any), J.
    pub normal_damping: f64,
    /// Energy dissipated by tangential damping, J.
    pub tangential_damping: f64,
    /// Energy dissipated by sliding friction, J.
    pub friction: f64,
    /// Energy dissipated by the general (viscous, per-grain) damping, J.
    pub general_damping: f64,
    /// Work taken from the grains by the rolling resistance's torques, J: dissipated, or
    /// held for a while by a rolling spring (EPSD2, SDS) that is not sliding. Each contact
    /// keeps its own in its energy memory's rolling part, taken as the other sums are.
    pub rolling: f64,
    /// Energy the tangential springs gained from stiffness and frame changes, less the
    /// elastic energy they hold now (the sum of `E_slip + W_spring`, see the module), J.
    pub tangential_model: f64,
    /// Work done on the grains by the walls' prescribed motion, J.
    pub walls: f64,
    /// Work done by the confining load on the top wall, J.
    pub load: f64,
    /// Work done by gravity, J.
    pub gravity: f64,
    /// Elastic energy stored in normal springs now, J: in the world's ledger, the flat
    /// walls' contacts of this step (recomputed each step); the pairs' is added when the
    /// ledger is read.
    pub elastic_normal: f64,
    /// Elastic energy stored in tangential springs now, J (as `elastic_normal`).
    pub elastic_tangential: f64,
}

impl EnergyLedger {
    /// Start a step: the stored energies are sums over the current contacts.
    pub fn begin_step(&mut self) {
        self.elastic_normal = 0.0;
        self.elastic_tangential = 0.0;
    }
    /// Add a contact's (or many contacts') sums.
    #[inline]
    pub fn add(&mut self, s: &EnergySums) {
        self.normal_damping += s.normal_damping;
        self.tangential_damping += s.tangential_damping;
        self.friction += s.friction;
        self.tangential_model += s.tangential_model;
    }
    /// The tangential model's work `W_t`: what the ledger keeps plus the elastic energy
    /// the tangential springs hold now, J.
    pub fn tangential_model_work(&self) -> f64 {
        self.tangential_model + self.elastic_tangential
    }
}

/// What one contact has added to the ledger since its sums were last taken (per lane:
/// of four contacts), J: dissipations positive, as in [`EnergyLedger`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EnergySums<R = f64> {
    /// Dissipated by normal damping (and by the clamp, if any), J.
    pub normal_damping: R,
    /// Dissipated by tangential damping, J.
    pub tangential_damping: R,
    /// Dissipated by sliding, J.
    pub friction: R,
    /// Tangential model work less the change of the stored tangential energy
    /// (`E_slip + W_spring`), J.
    pub tangential_model: R,
}

impl std::ops::Add for EnergySums {
    type Output = EnergySums;
    fn add(self, b: EnergySums) -> EnergySums {
        EnergySums {
            normal_damping: self.normal_damping + b.normal_damping,
            tangential_damping: self.tangential_damping + b.tangential_damping,
            friction: self.friction + b.friction,
            tangential_model: self.tangential_model + b.tangential_model,
        }
    }
}

impl EnergySums {
    /// The sums of many contacts' sums, in their order (four partial sums, the contacts
    /// at indices k = l mod 4 in partial sum l, then added as (0 + 1) + (2 + 3)): a fixed
    /// order, so the same bits on any number of threads.
    pub fn total<'a>(sums: impl Iterator<Item = &'a EnergySums>) -> EnergySums {
        let mut part = [EnergySums::default(); 4];
        for (k, s) in sums.enumerate() {
            part[k % 4] = part[k % 4] + *s;
        }
        (part[0] + part[1]) + (part[2] + part[3])
    }
}

/// One row of the energy time series, J.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct EnergyRow {
    pub time_s: f64,
    pub kinetic_translation_j: f64,
    pub kinetic_rotation_j: f64,
    pub kinetic_walls_j: f64,
    pub elastic_normal_j: f64,
    pub elastic_tangential_j: f64,
    pub dissipated_normal_damping_j: f64,
    pub dissipated_tangential_damping_j: f64,
    pub dissipated_friction_j: f64,
    pub dissipated_general_damping_j: f64,
    /// Taken by the rolling resistance's torques (0 without), J.
    pub dissipated_rolling_j: f64,
    pub tangential_model_work_j: f64,
    pub work_walls_j: f64,
    pub work_load_j: f64,
    pub work_gravity_j: f64,
    /// Kinetic and stored energy at t = 0, J.
    pub initial_j: f64,
    pub residual_j: f64,
}

impl EnergyRow {
    /// Total energy in the system now (kinetic + stored), J.
    pub fn stored(&self) -> f64 {
        self.kinetic_translation_j + self.kinetic_rotation_j + self.kinetic_walls_j + self.elastic_normal_j + self.elastic_tangential_j
    }
    /// Energy put in by external work and the tangential model so far, J.
    pub fn input(&self) -> f64 {
        self.work_walls_j + self.work_load_j + self.work_gravity_j + self.tangential_model_work_j
    }
    /// The scale the residual is judged against: the initial energy plus the magnitude
    /// of every work term, J.
    pub fn put_in(&self) -> f64 {
        self.initial_j + self.work_walls_j.abs() + self.work_load_j.abs() + self.work_gravity_j.abs() + self.tangential_model_work_j.abs()
    }
    /// Energy dissipated so far, J.
    pub fn dissipated(&self) -> f64 {
        self.dissipated_normal_damping_j + self.dissipated_tangential_damping_j + self.dissipated_friction_j + self.dissipated_general_damping_j + self.dissipated_rolling_j
    }
    pub fn new(time: f64, kin: (f64, f64, f64), ledger: &EnergyLedger, initial: f64) -> Self {
        let mut r = EnergyRow {
            time_s: time,
            kinetic_translation_j: kin.0,
            kinetic_rotation_j: kin.1,
            kinetic_walls_j: kin.2,
            elastic_normal_j: ledger.elastic_normal,
            elastic_tangential_j: ledger.elastic_tangential,
            dissipated_normal_damping_j: ledger.normal_damping,
            dissipated_tangential_damping_j: ledger.tangential_damping,
            dissipated_friction_j: ledger.friction,
            dissipated_general_damping_j: ledger.general_damping,
            dissipated_rolling_j: ledger.rolling,
            tangential_model_work_j: ledger.tangential_model_work(),
            work_walls_j: ledger.walls,
            work_load_j: ledger.load,
            work_gravity_j: ledger.gravity,
            initial_j: initial,
            residual_j: 0.0,
        };
        r.residual_j = r.stored() - r.initial_j + r.dissipated() - r.input();
        r
    }
}
