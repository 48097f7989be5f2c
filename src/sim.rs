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
pub type Hist<L> = ContactHistory<<<L as ContactLaw>::Tang as Tangential>::History<f64>>;

/// Everything that evolves.
pub struct World<L: ContactLaw> {
    pub p: Particles,
    pub boundary: Boundary,
    pub law: L,
    pub pair_table: PairTable,
    pub pairs: PairList<<L::Tang as Tangential>::History<f64>>,
    pub walls: Vec<Wall>,
    /// History of each free grain against each flat wall: `wall_hist[wall][grain]`.
    pub wall_hist: Vec<Vec<Hist<L>>>,
    /// Whether each free grain is touching each flat wall: `wall_active[wall][grain]`.
    pub wall_active: Vec<Vec<bool>>,
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
    /// The energy ledger is kept (the kernels were compiled with it).
    pub energy: bool,
    /// The threads the per-grain stages and the contact stage may use.
    pub threads: crate::threads::Threads,
    /// The half-kick factors of the integrator.
    pub kick: crate::integrate::KickFactors,
    /// The region the grains must stay in ([`crate::domain`]).
    pub domain: crate::domain::Domain,
    /// What the build knew that helps diagnose a failed run.
    pub context: crate::domain::Context,
    /// How many of the first grains have zero forces (and torques) already this step:
    /// the drift sets the free grains' to zero once it has used them, and
    /// [`crate::pipeline::ClearForces`] clears the rest (then sets these back to 0).
    pub zeroed: Zeroed,
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
    /// A full check of the state, O(N): every grain finite, and (with the energy ledger)
    /// no energy created: the balance residual under [`MAX_RESIDUAL`] of the energy put
    /// in. The run loop calls it at every output sample and at the end of a run.
    pub fn health(&self) -> Result<(), Error> {
        let p = &self.p;
        self.check_finite()?;
        if self.energy {
            let row = self.energy_row();
            if let Some(term) = crate::finite::non_finite_column(&row) {
                return Err(self.unstable(format!("the energy balance's {term} is no longer finite")));
            }
            let scale = row.put_in();
            if scale > 0.0 && row.residual_j.abs() > MAX_RESIDUAL * scale {
                let fastest = (0..p.n_free).max_by(|&a, &b| p.v[a].norm_squared().total_cmp(&p.v[b].norm_squared())).unwrap_or(0);
                return Err(self.unstable(format!(
                    "the energy balance no longer closes: residual {:.3e} J is {:.1}% of the energy put in ({:.3e} J); the fastest grain, {fastest}, moves at {:.3e} m/s",
                    row.residual_j,
                    100.0 * row.residual_j.abs() / scale,
                    scale,
                    p.v[fastest].norm()
                )));
            }
        }
        Ok(())
    }

    /// An error naming the first free grain whose position, velocity, spin or force is not
    /// finite (or whose kinetic energy overflows), or a wall whose state is not.
    pub fn check_finite(&self) -> Result<(), Error> {
        let p = &self.p;
        let bad = |i: usize| !(p.x[i].x.is_finite() && p.x[i].y.is_finite() && p.v[i].norm_squared().is_finite() && p.omega[i].is_finite() && (p.omega[i] * p.omega[i]).is_finite());
        if let Some(i) = (0..p.n_free).find(|&i| bad(i)) {
            return Err(self.unstable_at(format!("grain {i} has a non-finite position, velocity or spin (x = {:?}, v = {:?}, omega = {})", p.x[i], p.v[i], p.omega[i]), Some(i)));
        }
        if let Some(w) = self.walls.iter().find(|w| !(w.y.is_finite() && w.v.norm_squared().is_finite() && w.force.norm_squared().is_finite())) {
            return Err(self.unstable_at(format!("the {} wall's position, velocity or force is not finite", w.name), None));
        }
        Ok(())
    }

    /// The domain's check at a neighbour-list rebuild ([`crate::domain::Domain::check`]).
    pub fn check_domain(&self) -> Result<(), Error> {
        use crate::domain::Fault;
        let fault = self.domain.check(&self.p, &self.walls, self.neighbours.at_build(), &self.boundary, 0.5 * self.neighbours.skin);
        let Some(fault) = fault else { return Ok(()) };
        let p = &self.p;
        let who = |i: usize| if i < p.n_free { format!("grain {i}") } else { format!("grain {i} (glued to a rough wall)") };
        Err(match fault {
            Fault::Left { grain, at } => self.unstable_at(
                format!("{} left the domain: it is at ({:.6e}, {:.6e}) m, moving at {:.3e} m/s", who(grain), at.x, at.y, p.v[grain].norm()),
                Some(grain),
            ),
            Fault::Jumped { grain, moved } => self.unstable_at(
                format!(
                    "{} moved {moved:.3e} m in one step ({:.3} of the smallest radius, more than {}); it moves at {:.3e} m/s",
                    who(grain),
                    moved / self.p.r[..p.n_free].iter().cloned().fold(f64::INFINITY, f64::min),
                    crate::consistency::MAX_STEP_MOVE,
                    p.v[grain].norm()
                ),
                Some(grain),
            ),
            Fault::WallsCrossed { gap } => self.unstable_at(format!("the top wall's contact surface came down to the bottom wall's (gap {gap:.3e} m)"), None),
            Fault::WallEscaped { y } => self.unstable_at(format!("the top wall rose to y = {y:.6e} m, ten gaps above where it started"), None),
        })
    }

    pub(crate) fn unstable(&self, what: String) -> Error {
        self.unstable_at(what, None)
    }

    /// A diagnosed stop: what went wrong (with grain `grain` to blame, if one is) and the
    /// likely cause ([`crate::domain::Context::likely_cause`]).
    pub(crate) fn unstable_at(&self, what: String, grain: Option<usize>) -> Error {
        Error::Unstable {
            step: self.step,
            time: self.time(),
            what,
            advice: self.context.likely_cause(&self.p, &self.walls, self.gravity, self.dt, self.time(), grain, self.domain.max_step),
        }
    }
}

/// The grains `0..forces` have zero forces, `0..torques` zero torques ([`World::zeroed`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct Zeroed {
    pub forces: usize,
    pub torques: usize,
}

/// Largest energy balance residual, as a fraction of the energy put in, before a run is
/// stopped: 50%. A stable run at 25 steps per contact shows 3e-3, and an impact at the
/// very edge of the stability limit (3.7 steps per contact) 12%; an unstable integration
/// creates many times the energy put in within a few steps.
pub const MAX_RESIDUAL: f64 = 0.5;

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
        self.advance(true)
    }

    /// Advance one step; with `look` false nothing will look at the grains' velocities
    /// (or spins) before the next step, so the final half kick may be left to the next
    /// drift (the same bits: [`crate::integrate`]). After an error the state is whole.
    #[inline]
    pub fn advance(&mut self, look: bool) -> Result<(), Error> {
        self.world.step += 1;
        self.world.kick.defer = !look;
        for (s, t) in self.stages.iter_mut().zip(self.timers.iter_mut()) {
            let t0 = Instant::now();
            let done = s.run(&mut self.world);
            *t += t0.elapsed();
            if done.is_err() {
                crate::integrate::settle(&mut self.world);
            }
            done?;
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
