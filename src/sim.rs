//! The simulation: a world (grains, contacts, walls) and the pipeline that advances it.

use std::time::{Duration, Instant};

use crate::boundary::Boundary;
use crate::contact::tangential::Tangential;
use crate::contact::{ContactHistory, ContactLaw};
use crate::dim::Vec2;
use crate::error::Error;
use crate::material::PairTable;
use crate::neighbor::{Neighbours, PairList};
use crate::observe::energy::{EnergyLedger, EnergyRow};
use crate::particles::Particles;
use crate::pipeline::Stage;
use crate::walls::Wall;

/// History type of a contact law.
pub type Hist<L> = ContactHistory<<<L as ContactLaw>::Tang as Tangential>::History>;

/// Everything that evolves.
pub struct World<L: ContactLaw> {
    pub p: Particles,
    pub boundary: Boundary,
    pub law: L,
    pub pair_table: PairTable,
    /// Material index of flat walls.
    pub wall_material: usize,
    pub pairs: PairList<<L::Tang as Tangential>::History>,
    pub walls: Vec<Wall>,
    /// History of each free grain against each flat wall: `wall_hist[wall][grain]`.
    pub wall_hist: Vec<Vec<Hist<L>>>,
    pub neighbours: Neighbours,
    pub ledger: EnergyLedger,
    pub gravity: Vec2,
    /// Time step, s.
    pub dt: f64,
    /// Steps done.
    pub step: u64,
    /// Largest overlap of this step as a fraction of the smaller radius, and where.
    pub max_overlap: (f64, usize, usize),
    /// Energy in the system at the start, J.
    pub initial_energy: f64,
}

impl<L: ContactLaw> World<L> {
    pub fn time(&self) -> f64 {
        self.step as f64 * self.dt
    }
    /// Kinetic energies (translation, rotation, walls), J.
    pub fn kinetic(&self) -> (f64, f64, f64) {
        (self.p.kinetic_translation(), self.p.kinetic_rotation(), self.walls.iter().map(Wall::kinetic).sum())
    }
    pub fn energy_row(&self) -> EnergyRow {
        EnergyRow::new(self.time(), self.kinetic(), &self.ledger, self.initial_energy)
    }
    pub(crate) fn unstable(&self, what: String) -> Error {
        Error::Unstable {
            step: self.step,
            time: self.time(),
            what,
            advice: format!(
                "reduce the time step (now {:.3e} s; try time_step.steps_per_contact with more steps), or check the scene for grains created overlapping",
                self.dt
            ),
        }
    }
}

/// A world and its pipeline, with a timer per stage.
pub struct Simulation<L: ContactLaw> {
    pub world: World<L>,
    stages: Vec<Box<dyn Stage<L>>>,
    timers: Vec<Duration>,
}

impl<L: ContactLaw> Simulation<L> {
    pub fn new(mut world: World<L>, stages: Vec<Box<dyn Stage<L>>>, setup: Vec<Box<dyn Stage<L>>>) -> Result<Self, Error> {
        // Forces at the initial positions, so that the first half kick has them. With
        // dt = 0 the stages move nothing and integrate no work: they only prime the
        // forces and the contacts' previous-step values of the energy integrals.
        let dt = world.dt;
        world.dt = 0.0;
        for mut s in setup {
            s.run(&mut world)?;
        }
        world.dt = dt;
        let (a, b, c) = world.kinetic();
        world.initial_energy = a + b + c + world.ledger.elastic_normal + world.ledger.elastic_tangential;
        let timers = vec![Duration::ZERO; stages.len()];
        Ok(Simulation { world, stages, timers })
    }

    /// Advance one step.
    #[inline]
    pub fn step(&mut self) -> Result<(), Error> {
        self.world.step += 1;
        for (s, t) in self.stages.iter_mut().zip(self.timers.iter_mut()) {
            let t0 = Instant::now();
            s.run(&mut self.world)?;
            *t += t0.elapsed();
        }
        Ok(())
    }

    /// The stage names in order.
    pub fn stage_names(&self) -> Vec<String> {
        self.stages.iter().map(|s| s.name()).collect()
    }
    /// Time spent in each stage so far.
    pub fn timings(&self) -> Vec<(String, Duration)> {
        self.stage_names().into_iter().zip(self.timers.iter().cloned()).collect()
    }
}
