//! A snapshot of everything a simulation carries from one step to the next, so that a
//! run restored from it continues with the same bits as the run that never stopped
//! (`grainlab resume`; the checkpoint file around it is [`crate::output::checkpoint`]).
//! Written once for the plane and space: the grains' vectors and spins are saved as
//! their dimension has them (in the plane `Vec2` and `f64`, so the plane's checkpoints
//! keep their bytes).
//!
//! What evolves, and so is saved: the grains' positions, velocities, spins, forces and
//! torques (the forces of the last step feed the next step's first half kick); each
//! wall's control, position, shift and velocity and its forces of this and the last step;
//! the Verlet list as it is (its pairs in order, each pair's tangential history, energy
//! memory and contact flag: a list built again would be another list, so other sums);
//! the flat walls' contact histories; the positions at the last neighbour build, the
//! number of builds and the rebuild flag; the energy ledger and the energy at the start;
//! gravity (a protocol's stage may change it); the step count; the largest overlap of
//! the step; a final half kick left to the next drift; and what the stages carry
//! ([`Stage::carried`]: the general damping's previous forces). Everything else (radii,
//! masses, materials, the contact law, the domain, the time step) comes from building
//! the same scene again, and is checked against the snapshot where a mismatch could go
//! unseen: the model, the stages, the grain counts, the time step's bits and a checksum
//! of the radii and masses. The run has no random generator after the build (the
//! packing's is used up there), so there is none to save.

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::engine::simulation::Simulation;
use crate::engine::world::{PendingKick, SpinOf, State, VectorOf, Zeroed};
use crate::physics::contact::model::{Memory, Saved};
use crate::physics::contact::{ContactHistory, ContactLaw};
use crate::physics::energy::EnergyLedger;
use crate::physics::walls::Control;

/// One wall's evolving state (`V`: a vector of the world's dimension).
#[derive(Serialize, Deserialize)]
struct WallState<V> {
    control: Control,
    y: f64,
    x_shift: f64,
    v: V,
    force: V,
    force_prev: V,
}

/// A simulation's evolving state; `S` is a contact's state as saved and `E` its energy
/// memory ([`crate::physics::contact::model::Saved`], [`crate::physics::contact::model::Memory`]),
/// `V` a vector and `W` a spin of the world's dimension (in the plane `Vec2` and `f64`:
/// the plane's checkpoints keep their bytes).
#[derive(Serialize, Deserialize)]
struct Snapshot<S, E, V, W> {
    /// What must match the simulation it is restored into.
    model: String,
    stages: Vec<String>,
    grains: usize,
    free: usize,
    dt_bits: u64,
    /// CRC-32 of the radii and masses, as bytes.
    radii_masses: u32,
    step: u64,
    x: Vec<V>,
    v: Vec<V>,
    omega: Vec<W>,
    f: Vec<V>,
    torque: Vec<W>,
    walls: Vec<WallState<V>>,
    /// `wall_hist[wall][grain]`, `wall_active[wall][grain]`.
    wall_hist: Vec<Vec<(S, E)>>,
    wall_active: Vec<Vec<bool>>,
    pairs: Vec<[u32; 2]>,
    hist: Vec<S>,
    energy: Vec<E>,
    active: Vec<bool>,
    at_build: Vec<V>,
    builds: u64,
    moved_far: bool,
    ledger: EnergyLedger,
    initial_energy: f64,
    gravity: V,
    max_overlap: (f64, usize, usize),
    pending: Option<(f64, bool)>,
    zeroed: (usize, usize),
    carried: Vec<Vec<f64>>,
}

/// A stage's name without what the thread count changes in it: a run saved on one
/// thread resumes on two.
fn stage_kind(name: &str) -> &str {
    if name.starts_with("PairContacts") { "PairContacts" } else { name }
}

fn radii_masses(r: &[f64], m: &[f64]) -> u32 {
    let mut h = crc32fast::Hasher::new();
    h.update(bytemuck::cast_slice(r));
    h.update(bytemuck::cast_slice(m));
    h.finalize()
}

/// In the plane and in space: the grains' vectors and spins are saved as they are.
impl<L: ContactLaw> Simulation<L>
where
    VectorOf<L>: Serialize + DeserializeOwned,
    SpinOf<L>: Serialize + DeserializeOwned,
{
    /// The evolving state, encoded (postcard).
    pub fn save(&self) -> Vec<u8> {
        let w = &self.world;
        let save = |h: &State<L>| L::save_state(*h);
        let s = Snapshot {
            model: w.law.describe(),
            stages: self.stage_names().iter().map(|n| stage_kind(n).to_string()).collect(),
            grains: w.p.len(),
            free: w.p.n_free,
            dt_bits: w.dt.to_bits(),
            radii_masses: radii_masses(&w.p.r, &w.p.m),
            step: w.step,
            x: w.p.x.clone(),
            v: w.p.v.clone(),
            omega: w.p.omega.clone(),
            f: w.p.f.clone(),
            torque: w.p.torque.clone(),
            walls: w.walls.iter().map(|k| WallState { control: k.control, y: k.y, x_shift: k.x_shift, v: k.v, force: k.force, force_prev: k.force_prev }).collect(),
            wall_hist: w.wall_hist.iter().map(|hs| hs.iter().map(|h| (save(&h.state), h.energy)).collect()).collect(),
            wall_active: w.wall_active.clone(),
            pairs: w.pairs.pairs.to_vec(),
            hist: w.pairs.hist.iter().map(save).collect(),
            energy: w.pairs.energy.clone(),
            active: w.pairs.active.clone(),
            at_build: w.neighbours.at_build().to_vec(),
            builds: w.neighbours.builds,
            moved_far: w.neighbours.moved_far,
            ledger: w.ledger,
            initial_energy: w.initial_energy,
            gravity: w.gravity,
            max_overlap: w.max_overlap,
            pending: w.kick.pending.map(|k| (k.dt, k.spin)),
            zeroed: (w.zeroed.forces, w.zeroed.torques),
            carried: self.stages().iter().map(|s| s.carried()).collect(),
        };
        postcard::to_stdvec(&s).expect("a snapshot encodes")
    }

    /// Take the state [`Simulation::save`] encoded, into a simulation built from the same
    /// scene. An error says what does not fit (found before anything changes, but for
    /// the pair list's and the stages' own checks: the simulation is then not to be run).
    pub fn restore(&mut self, bytes: &[u8]) -> Result<(), String> {
        let s: Snapshot<Saved<L>, Memory<L>, VectorOf<L>, SpinOf<L>> = postcard::from_bytes(bytes).map_err(|e| format!("its state does not decode for this contact model ({e})"))?;
        let w = &self.world;
        let n = w.p.len();
        let stages: Vec<String> = self.stage_names().iter().map(|n| stage_kind(n).to_string()).collect();
        let mismatch = |what: &str, saved: String, here: String| Err(format!("it was saved from a run with {what} {saved}, this scene builds {here}"));
        if s.model != w.law.describe() {
            return mismatch("the contact model", s.model, w.law.describe());
        }
        if s.stages != stages {
            return mismatch("the stages", s.stages.join(" > "), stages.join(" > "));
        }
        if (s.grains, s.free) != (n, w.p.n_free) {
            return mismatch("grains (all, free)", format!("{:?}", (s.grains, s.free)), format!("{:?}", (n, w.p.n_free)));
        }
        if s.dt_bits != w.dt.to_bits() {
            return mismatch("the time step", format!("{:e} s", f64::from_bits(s.dt_bits)), format!("{:e} s", w.dt));
        }
        if s.radii_masses != radii_masses(&w.p.r, &w.p.m) {
            return Err("it was saved from a run whose grains had other radii or masses".into());
        }
        let nf = w.p.n_free;
        let nw = w.walls.len();
        let per_grain = [s.x.len(), s.v.len(), s.omega.len(), s.f.len(), s.torque.len()];
        if per_grain.iter().any(|&k| k != n) || (!s.at_build.is_empty() && s.at_build.len() != n) {
            return Err(format!("its grain arrays have lengths {per_grain:?} (and {} positions at the last build), not {n}", s.at_build.len()));
        }
        if s.walls.len() != nw || s.wall_hist.len() != w.wall_hist.len() || s.wall_active.len() != w.wall_active.len() || s.wall_hist.iter().zip(&w.wall_hist).any(|(a, b)| a.len() != b.len()) || s.wall_active.iter().zip(&w.wall_active).any(|(a, b)| a.len() != b.len()) {
            return Err(format!("its walls or their contact histories do not fit {nw} walls and {nf} free grains"));
        }
        if s.carried.len() != self.stages().len() {
            return Err(format!("it carries the state of {} stages, this scene builds {}", s.carried.len(), self.stages().len()));
        }
        // Everything checked that can be before the world changes; the stages and the
        // pair list check their own parts, on copies first.
        let w = &mut self.world;
        let mut pairs = std::mem::take(&mut w.pairs);
        let restored = pairs.restore(s.pairs, s.hist.into_iter().map(L::load_state).collect(), s.active, s.energy, &w.p.r, &w.p.m);
        w.pairs = pairs;
        restored?;
        for (stage, c) in self.stages_mut().iter_mut().zip(&s.carried) {
            stage.restore(c)?;
        }
        let w = &mut self.world;
        w.step = s.step;
        (w.p.x, w.p.v, w.p.omega, w.p.f, w.p.torque) = (s.x, s.v, s.omega, s.f, s.torque);
        for (k, st) in w.walls.iter_mut().zip(s.walls) {
            (k.control, k.y, k.x_shift, k.v, k.force, k.force_prev) = (st.control, st.y, st.x_shift, st.v, st.force, st.force_prev);
        }
        w.wall_hist = s.wall_hist.into_iter().map(|hs| hs.into_iter().map(|(t, energy)| ContactHistory { state: L::load_state(t), energy }).collect()).collect();
        w.wall_active = s.wall_active;
        w.neighbours.restore(s.at_build, s.builds, s.moved_far);
        w.ledger = s.ledger;
        w.initial_energy = s.initial_energy;
        w.gravity = s.gravity;
        w.max_overlap = s.max_overlap;
        w.kick.pending = s.pending.map(|(dt, spin)| PendingKick { dt, spin });
        w.zeroed = Zeroed { forces: s.zeroed.0, torques: s.zeroed.1 };
        Ok(())
    }
}
