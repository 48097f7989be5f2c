//! Neighbours: when to rebuild the Verlet list (a grain moved more than half the skin
//! since the last build) and the rebuild itself, from the cell list
//! ([`crate::kernels::cells`]) into the list ([`crate::kernels::pairs`]).

use crate::kernels::cells::cell_pairs;
use crate::kernels::threads::Threads;
use crate::physics::boundary::Boundary;
use crate::physics::dim::{Dim, Plane};

/// Cell-list builder and the skin bookkeeping, in the plane (the default `D`) or space.
#[derive(Clone, Debug)]
pub struct Neighbours<D: Dim = Plane> {
    /// Skin, m.
    pub skin: f64,
    /// Positions at the last build.
    x_at_build: Vec<D::Vector<f64>>,
    /// Number of builds so far.
    pub builds: u64,
    cell_start: Vec<u32>,
    cell_items: Vec<u32>,
    /// Set by the stages that move grains (the drift, the walls) when one of them has
    /// moved more than half the skin since the last build; cleared by the build.
    pub moved_far: bool,
}

impl<D: Dim> Neighbours<D> {
    pub fn new(skin: f64) -> Self {
        Neighbours { skin, x_at_build: Vec::new(), builds: 0, cell_start: Vec::new(), cell_items: Vec::new(), moved_far: false }
    }

    /// Half the skin, squared: a grain that has moved this far (squared) since the last
    /// build may have a new neighbour, m^2.
    pub fn limit(&self) -> f64 {
        0.25 * self.skin * self.skin
    }

    /// Positions at the last build (empty before the first).
    pub fn at_build(&self) -> &[D::Vector<f64>] {
        &self.x_at_build
    }

    /// True when the list must be rebuilt: there is none for these `n` grains yet, or a
    /// grain has moved more than half the skin ([`Neighbours::moved_far`], set with
    /// [`Boundary::any_moved_beyond`]).
    pub fn needs_rebuild(&self, n: usize) -> bool {
        self.x_at_build.len() != n || self.moved_far
    }

    /// Take the state a checkpoint saved: the positions at the last build, the number of
    /// builds, and whether a grain has moved far since ([`crate::engine::snapshot`]).
    pub fn restore(&mut self, at_build: Vec<D::Vector<f64>>, builds: u64, moved_far: bool) {
        self.x_at_build = at_build;
        self.builds = builds;
        self.moved_far = moved_far;
    }

    /// Build the pair list with the cell list.
    pub fn build(&mut self, x: &[D::Vector<f64>], r: &[f64], n_free: usize, boundary: &Boundary<D>, threads: &Threads) -> Vec<[u32; 2]> {
        self.builds += 1;
        self.moved_far = false;
        self.x_at_build.clear();
        self.x_at_build.extend_from_slice(x);
        cell_pairs(x, r, n_free, boundary, self.skin, &mut self.cell_start, &mut self.cell_items, threads)
    }
}
