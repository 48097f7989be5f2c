//! The world: everything that evolves (grains, contacts, walls, the integrator's
//! factors), the [`Stage`] trait of what acts on it once per step, and the read-only
//! [`View`] that observers and outputs get. The pipeline that runs the stages is
//! [`crate::engine::simulation`].

use crate::engine::neighbor::Neighbours;
use crate::error::{Error, Shown};
use crate::kernels::pairs::PairList;
use crate::physics::boundary::Boundary;
use crate::physics::contact::model::Held;
use crate::physics::contact::rolling::Rolling;
use crate::physics::contact::{ContactHistory, ContactLaw, ContactRecord};
use crate::physics::dim::{Dim, Plane};
use crate::physics::energy::{EnergyLedger, EnergyRow};
use crate::physics::material::PairTable;
use crate::physics::particles::Particles;
use crate::physics::walls::Wall;

/// A contact law's dimension ([`Plane`] or [`crate::physics::dim::Space`]).
pub type DimOf<L> = <L as ContactLaw>::D;
/// A vector of a contact law's dimension, m (m/s, N).
pub type VectorOf<L> = <DimOf<L> as Dim>::Vector<f64>;
/// A spin (torque) of a contact law's dimension, rad/s (N m).
pub type SpinOf<L> = <DimOf<L> as Dim>::Spin<f64>;
/// A contact law's state of one contact ([`Held`]: tangential and rolling).
pub type State<L> = Held<<L as ContactLaw>::Tang, <L as ContactLaw>::Roll, f64, DimOf<L>>;
/// The rolling torque's part of a contact's energy memory under a contact law.
pub type RollEnergy<L> = <<L as ContactLaw>::Roll as Rolling<DimOf<L>>>::Energy;
/// History type of a contact law.
pub type Hist<L> = ContactHistory<State<L>, RollEnergy<L>, DimOf<L>>;

/// Everything that evolves, in the contact law's dimension (`L::D`: the plane or space).
pub struct World<L: ContactLaw> {
    pub p: Particles<L::D>,
    pub boundary: Boundary<L::D>,
    pub law: L,
    pub pair_table: PairTable,
    pub pairs: PairList<State<L>, RollEnergy<L>, L::D>,
    pub walls: Vec<Wall<L::D>>,
    /// History of each free grain against each flat wall: `wall_hist[wall][grain]`.
    pub wall_hist: Vec<Vec<Hist<L>>>,
    /// Whether each free grain is touching each flat wall: `wall_active[wall][grain]`.
    pub wall_active: Vec<Vec<bool>>,
    pub neighbours: Neighbours<L::D>,
    pub ledger: EnergyLedger,
    /// Gravity, m/s^2.
    pub gravity: VectorOf<L>,
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
    pub threads: crate::kernels::threads::Threads,
    /// The half-kick factors of the integrator.
    pub kick: KickFactors<L::D>,
    /// The region the grains must stay in ([`crate::engine::domain`]).
    pub domain: crate::engine::domain::Domain<L::D>,
    /// What the build knew that helps diagnose a failed run.
    pub context: crate::engine::domain::Context,
    /// How many of the first grains have zero forces (and torques) already this step:
    /// the drift sets the free grains' to zero once it has used them, and
    /// [`crate::engine::stages::ClearForces`] clears the rest (then sets these back to 0).
    pub zeroed: Zeroed,
    /// The contacts of one step, recorded when a run asks ([`Probe`]).
    pub probe: Probe,
}

/// The contact record of one step: set `wanted` before the step, and the scene's
/// `RecordContacts` stage (present only when the scene's `output.contacts` asks for it)
/// fills `contacts` with every touching contact as the contact stages apply it at that
/// step, then clears `wanted`. Without the stage nothing is recorded and nothing costs.
#[derive(Clone, Debug, Default)]
pub struct Probe {
    pub wanted: bool,
    pub contacts: Vec<ContactRecord>,
    /// The step the contacts are of (0: none recorded yet).
    pub step: u64,
    /// What the contact stages computed them from: every grain's position, velocity and
    /// spin, and each wall's contact surface height and velocity, as they were then
    /// (a frame's state is the step's end; the contacts see the velocities half a kick
    /// before it). The frozen-state cross-checks give these to the reference codes.
    pub x: Vec<crate::physics::dim::Vec2>,
    pub v: Vec<crate::physics::dim::Vec2>,
    pub omega: Vec<f64>,
    pub walls: Vec<(f64, crate::physics::dim::Vec2)>,
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
        EnergyRow::new(self.time(), self.kinetic(), &self.ledger_now(), self.initial_energy)
    }
    /// The energy ledger as it stands: the world's (walls, gravity, general damping, and
    /// the pairs' sums taken at each neighbour-list rebuild), plus the listed pairs' sums
    /// and the elastic energy of each touching pair now, both in list order (the same
    /// bits on any number of threads). O(listed pairs): read at output samples.
    pub fn ledger_now(&self) -> EnergyLedger {
        let mut l = self.ledger;
        let list = &self.pairs;
        if !list.keep_energy {
            return l;
        }
        l.add(&list.energy_sums());
        l.rolling += list.rolling_taken();
        let p = &self.p;
        for (k, (&[i, j], e)) in list.pairs.iter().zip(&list.energy).enumerate() {
            if !list.active[k] {
                continue;
            }
            let (i, j) = (i as usize, j as usize);
            let dn = p.r[i] + p.r[j] - <L::D as Dim>::norm(self.boundary.image(p.x[i] - p.x[j]));
            if dn > 0.0 {
                let pm = self.pair_table.get(p.material[i] as usize, p.material[j] as usize);
                let (un, ut) = self.law.stored_energy(pm, list.consts[k].r_star, list.consts[k].sqrt_m_star, dn, e.fte_prev);
                l.elastic_normal += un;
                l.elastic_tangential += ut;
            }
        }
        l
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
                let speed2 = |i: usize| <L::D as Dim>::norm_squared(p.v[i]);
                let fastest = (0..p.n_free).max_by(|&a, &b| speed2(a).total_cmp(&speed2(b))).unwrap_or(0);
                return Err(self.unstable(format!(
                    "the energy balance no longer closes: residual {:.3e} J is {:.1}% of the energy put in ({:.3e} J); the fastest grain, {fastest}, moves at {:.3e} m/s",
                    row.residual_j,
                    100.0 * row.residual_j.abs() / scale,
                    scale,
                    speed2(fastest).sqrt()
                )));
            }
        }
        Ok(())
    }

    /// An error naming the first free grain whose position, velocity, spin or force is not
    /// finite (or whose kinetic energy overflows), or a wall whose state is not.
    pub fn check_finite(&self) -> Result<(), Error> {
        type D<L> = DimOf<L>;
        let p = &self.p;
        let x_ok = |i: usize| D::<L>::flat(std::slice::from_ref(&p.x[i])).iter().all(|c| c.is_finite());
        let v_ok = |i: usize| D::<L>::norm_squared(p.v[i]).is_finite();
        // A spin's square overflows (or is NaN) when a component is not finite.
        let w_ok = |i: usize| D::<L>::spin_dot(p.omega[i], p.omega[i]).is_finite();
        if let Some(i) = (0..p.n_free).find(|&i| !(x_ok(i) && v_ok(i) && w_ok(i))) {
            // Each quantity by value if it is finite, else in words: a diagnosis holds no
            // number that is not one.
            let say = |ok: bool, v: String| if ok { v } else { "not finite".to_string() };
            let x = say(x_ok(i), shown_components(D::<L>::flat(std::slice::from_ref(&p.x[i]))));
            let v = say(v_ok(i), shown_components(D::<L>::flat(std::slice::from_ref(&p.v[i]))));
            let w = D::<L>::spin_flat(std::slice::from_ref(&p.omega[i]));
            let w = say(w_ok(i), if let [w] = w { w.shown() } else { shown_components(w) });
            return Err(self.unstable_at(format!("grain {i} has a non-finite position, velocity or spin (x = {x} m, v = {v} m/s, omega = {w} rad/s)"), Some(i)));
        }
        if let Some(w) = self.walls.iter().find(|w| !(w.y.is_finite() && D::<L>::norm_squared(w.v).is_finite() && D::<L>::norm_squared(w.force).is_finite())) {
            return Err(self.unstable_at(format!("the {} wall's position, velocity or force is not finite", w.name), None));
        }
        Ok(())
    }

    /// The domain's check at a neighbour-list rebuild ([`crate::engine::domain::Domain::check`]).
    pub fn check_domain(&self) -> Result<(), Error> {
        use crate::engine::domain::Fault;
        let fault = self.domain.check(&self.p, &self.walls, self.neighbours.at_build(), &self.boundary, 0.5 * self.neighbours.skin);
        let Some(fault) = fault else { return Ok(()) };
        let p = &self.p;
        let who = |i: usize| if i < p.n_free { format!("grain {i}") } else { format!("grain {i} (glued to a rough wall)") };
        Err(match fault {
            Fault::Left { grain, at } => self.unstable_at(
                format!(
                    "{} left the domain: it is at ({}) m, moving at {:.3e} m/s",
                    who(grain),
                    at.iter().map(|c| format!("{c:.6e}")).collect::<Vec<_>>().join(", "),
                    <L::D as Dim>::norm(p.v[grain])
                ),
                Some(grain),
            ),
            Fault::Jumped { grain, moved } => self.unstable_at(
                format!(
                    "{} moved {moved:.3e} m in one step ({:.3} of the smallest radius, more than {}); it moves at {:.3e} m/s",
                    who(grain),
                    moved / self.p.r[..p.n_free].iter().cloned().fold(f64::INFINITY, f64::min),
                    crate::engine::consistency::MAX_STEP_MOVE,
                    <L::D as Dim>::norm(p.v[grain])
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
    /// likely cause ([`crate::engine::domain::Context::likely_cause`]).
    pub(crate) fn unstable_at(&self, what: String, grain: Option<usize>) -> Error {
        Error::Unstable {
            step: self.step,
            time: self.time(),
            what,
            advice: self.context.likely_cause(&self.p, &self.walls, self.gravity, self.dt, self.time(), grain, self.domain.max_step),
        }
    }
}

/// Numbers as `[a, b]` (or `[a, b, c]`), each [`Shown`].
fn shown_components(c: &[f64]) -> String {
    format!("[{}]", crate::error::shown_joined(c))
}

/// A change of the walls' motion and control and of gravity between two steps: what a
/// protocol's stage sets at its start ([`crate::engine::simulation::Simulation::change_motion`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MotionChange {
    /// The bottom and top walls' changes.
    pub walls: [WallMotion; 2],
    /// Gravity from now on, m/s^2 (a plane vector lifted into space with z = 0).
    pub gravity: Option<crate::scene::Coords>,
}

/// One wall's change; `None` leaves a field as it is.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WallMotion {
    /// Velocity in x, m/s.
    pub velocity_x: Option<f64>,
    /// Velocity in y under fixed control, m/s (a change to fixed control without it holds
    /// the wall: 0).
    pub velocity_y: Option<f64>,
    pub control: Option<crate::physics::walls::Control>,
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

/// A read-only view of a world's state at one time: what observers and outputs read
/// (they see neither the World nor the Engine).
#[derive(Clone, Copy)]
pub struct View<'a, D: Dim = Plane> {
    pub particles: &'a Particles<D>,
    /// The contacts of the last step that recorded them (empty unless the scene asks
    /// for contacts and the run wanted them at this step; always in space so far).
    pub contacts: &'a [ContactRecord],
    pub walls: &'a [Wall<D>],
    pub boundary: Boundary<D>,
    /// Simulated time, s.
    pub time: f64,
}

/// One stage of a time step.
pub trait Stage<L: ContactLaw>: Send {
    fn name(&self) -> String;
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error>;
    /// What the stage carries from one step to the next that its results depend on, for
    /// a checkpoint ([`crate::engine::snapshot`]); most stages carry nothing.
    fn carried(&self) -> Vec<f64> {
        Vec::new()
    }
    /// Take what [`Stage::carried`] gave, into a stage built from the same scene, and
    /// forget what it derived from the world it had (the world is now another): an error
    /// says what does not fit.
    fn restore(&mut self, carried: &[f64]) -> Result<(), String> {
        if carried.is_empty() { Ok(()) } else { Err(format!("{} carries nothing here, the checkpoint gave it {} numbers", self.name(), carried.len())) }
    }
}

/// The half-kick factors `dt/2 / m` and `dt/2 / I` of the free grains, divided out once
/// per time step value instead of at every step (the same division, so the same bits as
/// LIGGGHTS' `dtfm = dtf / rmass[i]`). One set per world (`World::kick`), shared by both
/// half kicks.
#[derive(Default)]
pub struct KickFactors<D: Dim = Plane> {
    dt: f64,
    /// dt/2 / m, s/kg.
    pub dtfm: Vec<f64>,
    /// dt/2 / m for each component of a grain's velocity (2 or 3 per grain), s/kg, as
    /// the velocities are stored (x, y, ...). A kick or drift over the components is
    /// then element by element, which compilers vectorise without splitting the vectors
    /// into an x and a y register and back.
    pub dtfm2: Vec<D::Vector<f64>>,
    /// dt/2 / I for each component of a grain's spin (one in the plane), s/(kg m^2).
    pub dtfi: Vec<D::Spin<f64>>,
    /// Leave this step's final half kick to the next drift: nothing looks at the grains'
    /// velocities before it ([`crate::engine::simulation::Simulation::advance`] sets it).
    pub defer: bool,
    /// The final half kick left to the next drift, if any: for time step `dt`, s, and
    /// with the spins (`spin`) or not. Until the drift (or [`crate::engine::integrate::settle`]) gives it, the free
    /// grains' velocities and spins are half a kick behind.
    pub pending: Option<PendingKick>,
}

/// A final half kick not given yet ([`KickFactors::pending`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PendingKick {
    /// Time step of the step it ends, s.
    pub dt: f64,
    /// It kicks the spins too.
    pub spin: bool,
}

impl<D: Dim> KickFactors<D> {
    /// Recompute for time step `dt` if it (or the number of free grains) changed.
    pub fn update(&mut self, p: &Particles<D>, dt: f64) {
        let n = p.n_free;
        if self.dt != dt || self.dtfm.len() != n {
            let dtf = 0.5 * dt;
            self.dt = dt;
            self.dtfm = p.m[..n].iter().map(|m| dtf / m).collect();
            self.dtfm2 = self.dtfm.iter().map(|&m| D::splat(m)).collect();
            self.dtfi = p.inertia[..n].iter().map(|i| D::spin_splat(dtf / i)).collect();
        }
    }
}
