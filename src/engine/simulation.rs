//! The simulation: a world and the pipeline of stages that advances it, with a timer per
//! stage, behind the [`Engine`] trait (one dynamic call per step, whatever the contact
//! model), which hands observers a read-only [`View`].

use std::time::{Duration, Instant};

use crate::engine::world::{MotionChange, Stage, View, World};
use crate::error::Error;
use crate::physics::boundary::Boundary;
use crate::physics::contact::ContactLaw;
use crate::engine::world::{SpinOf, VectorOf};
use crate::physics::dim::{Dim, Plane};
use serde::Serialize;
use serde::de::DeserializeOwned;
use crate::physics::energy::EnergyRow;
use crate::physics::particles::Particles;
use crate::physics::walls::Wall;

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
        let stored = world.ledger_now();
        world.initial_energy = a + b + c + stored.elastic_normal + stored.elastic_tangential;
        let timers = vec![Duration::ZERO; stages.len()];
        Ok(Simulation { world, stages, timers })
    }

    /// Advance one step.
    #[inline]
    pub fn step(&mut self) -> Result<(), Error> {
        self.advance(true)
    }

    /// Advance one step; with `look` false nothing will look at the grains' velocities
    /// (or spins) before the next step, so the final half kick may be left to the next
    /// drift (the same bits: [`crate::engine::integrate`]). After an error the state is whole.
    #[inline]
    pub fn advance(&mut self, look: bool) -> Result<(), Error> {
        self.world.step += 1;
        self.world.kick.defer = !look;
        for (s, t) in self.stages.iter_mut().zip(self.timers.iter_mut()) {
            let t0 = Instant::now();
            let done = s.run(&mut self.world);
            *t += t0.elapsed();
            if done.is_err() {
                crate::engine::integrate::settle(&mut self.world);
            }
            done?;
        }
        Ok(())
    }

    /// The stage names in order.
    pub fn stage_names(&self) -> Vec<String> {
        self.stages.iter().map(|s| s.name()).collect()
    }
    /// The stages in order.
    pub fn stages(&self) -> &[Box<dyn Stage<L>>] {
        &self.stages
    }
    pub(crate) fn stages_mut(&mut self) -> &mut [Box<dyn Stage<L>>] {
        &mut self.stages
    }
    /// Time spent in each stage so far.
    pub fn timings(&self) -> Vec<(String, Duration)> {
        self.stage_names().into_iter().zip(self.timers.iter().cloned()).collect()
    }
}

impl<L: ContactLaw> Simulation<L> {
    /// Change the walls' motion and control and gravity, between two steps. The grains'
    /// pending half kick is given first. A wall's prescribed motion is a drive: the
    /// kinetic energy the balance counts for it (a loaded wall's y motion) changes by what
    /// the drive does, so that change is booked as the walls' work and the balance stays
    /// closed across the change. The glued grains take the new velocity in the next drift.
    /// A change is the plane's protocols' (x and y; in space its gravity lies in x-y:
    /// protocols in space are for later, issue 30).
    pub fn change_motion(&mut self, c: &MotionChange) {
        use crate::physics::walls::Control;
        let w = &mut self.world;
        crate::engine::integrate::settle(w);
        for (wall, m) in w.walls.iter_mut().zip(&c.walls) {
            let before = wall.kinetic();
            if let Some(control) = m.control {
                wall.control = control;
                if control == Control::Fixed {
                    wall.v[1] = 0.0;
                }
            }
            if let Some(vx) = m.velocity_x {
                wall.v[0] = vx;
            }
            if let Some(vy) = m.velocity_y {
                wall.v[1] = vy;
            }
            if w.energy {
                w.ledger.walls += wall.kinetic() - before;
            }
        }
        if let Some(g) = c.gravity {
            w.gravity = g.lift::<L::D>();
        }
    }
}

/// A running simulation behind one dynamic call per step, whatever its contact model, in
/// the plane (`D = Plane`, the default: every scene so far) or in space.
pub trait Engine<D: Dim = Plane>: Send {
    fn step(&mut self) -> Result<(), Error>;
    /// One step, after which nothing looks at the grains' velocities or spins (`look`
    /// false) before the next: see [`Simulation::advance`].
    fn advance(&mut self, look: bool) -> Result<(), Error>;
    fn particles(&self) -> &Particles<D>;
    fn walls(&self) -> &[Wall<D>];
    fn boundary(&self) -> Boundary<D>;
    fn energy_row(&self) -> EnergyRow;
    fn steps(&self) -> u64;
    fn time(&self) -> f64;
    fn dt(&self) -> f64;
    /// Number of pairs touching now.
    fn touching(&self) -> usize;
    /// Number of neighbour-list builds so far.
    fn neighbour_builds(&self) -> u64;
    /// Threads the stages may use.
    fn threads(&self) -> usize;
    /// The stages in order.
    fn stage_names(&self) -> Vec<String>;
    fn timings(&self) -> Vec<(String, Duration)>;
    /// The contact model in one line.
    fn model(&self) -> String;
    /// The full state check ([`World::health`]).
    fn health(&self) -> Result<(), Error>;
    /// Change the walls' motion and gravity between two steps ([`Simulation::change_motion`]).
    fn change_motion(&mut self, c: &MotionChange);
    /// Everything the simulation carries from step to step, encoded
    /// ([`crate::engine::snapshot`]).
    fn save(&self) -> Vec<u8>;
    /// Take a state [`Engine::save`] encoded, of a simulation built from the same scene;
    /// an error says what does not fit.
    fn restore(&mut self, bytes: &[u8]) -> Result<(), String>;
    /// Ask for the contacts of the next step (recorded only where the scene's
    /// `output.contacts` put the `RecordContacts` stage in the pipeline).
    fn want_contacts(&mut self);
    /// The last record of the contacts: the step it is of (0: none), the contacts, and
    /// the state they were computed from.
    fn probe(&self) -> &crate::engine::world::Probe;
    /// A read-only view of the state, what observers and outputs read: the contacts are
    /// there when they are of this very step.
    fn view(&self) -> View<'_, D> {
        let probe = self.probe();
        let contacts = if probe.step == self.steps() && probe.step > 0 { &probe.contacts[..] } else { &[] };
        View { particles: self.particles(), contacts, walls: self.walls(), boundary: self.boundary(), time: self.time() }
    }
}

/// What observers, outputs and studies drive, in the plane or in space.
impl<L: ContactLaw> Engine<L::D> for Simulation<L>
where
    VectorOf<L>: Serialize + DeserializeOwned,
    SpinOf<L>: Serialize + DeserializeOwned,
{
    fn step(&mut self) -> Result<(), Error> {
        Simulation::step(self)
    }
    fn advance(&mut self, look: bool) -> Result<(), Error> {
        Simulation::advance(self, look)
    }
    fn particles(&self) -> &Particles<L::D> {
        &self.world.p
    }
    fn walls(&self) -> &[Wall<L::D>] {
        &self.world.walls
    }
    fn boundary(&self) -> Boundary<L::D> {
        self.world.boundary
    }
    fn energy_row(&self) -> EnergyRow {
        self.world.energy_row()
    }
    fn steps(&self) -> u64 {
        self.world.step
    }
    fn time(&self) -> f64 {
        self.world.time()
    }
    fn dt(&self) -> f64 {
        self.world.dt
    }
    fn touching(&self) -> usize {
        self.world.pairs.touching() + self.world.wall_active.iter().flatten().filter(|&&a| a).count()
    }
    fn neighbour_builds(&self) -> u64 {
        self.world.neighbours.builds
    }
    fn threads(&self) -> usize {
        self.world.threads.count()
    }
    fn stage_names(&self) -> Vec<String> {
        Simulation::stage_names(self)
    }
    fn timings(&self) -> Vec<(String, Duration)> {
        Simulation::timings(self)
    }
    fn model(&self) -> String {
        self.world.law.describe()
    }
    fn health(&self) -> Result<(), Error> {
        self.world.health()
    }
    fn change_motion(&mut self, c: &MotionChange) {
        Simulation::change_motion(self, c)
    }
    fn save(&self) -> Vec<u8> {
        Simulation::save(self)
    }
    fn restore(&mut self, bytes: &[u8]) -> Result<(), String> {
        Simulation::restore(self, bytes)
    }
    fn want_contacts(&mut self) {
        self.world.probe.wanted = true;
    }
    fn probe(&self) -> &crate::engine::world::Probe {
        &self.world.probe
    }
}
