//! Contact forces on several threads (feature `parallel`), bit for bit the same as on one.
//!
//! Floating-point sums depend on their order, so the parallel stage keeps the serial
//! order everywhere it adds: (1) every pair computes its force, torques and energy terms
//! into its own slot, in parallel (pairs are independent given the positions); (2) every
//! grain adds the contributions of its pairs in increasing pair order, in parallel over
//! grains, from an adjacency list rebuilt with the Verlet list, which is exactly the
//! sequence of additions the serial loop makes to that grain; (3) the energy terms and
//! the largest overlap are gathered serially in pair order. `tests/parallel.rs` checks
//! that positions, velocities and energies are identical bits with 1 and 2 threads.

use rayon::prelude::*;

use crate::contact::damping::Damping;
use crate::contact::tangential::Tangential;
use crate::contact::ContactModel;
use crate::error::Error;
use crate::observe::energy::EnergyLedger;
use crate::pipeline::{PairOut, PairView, Stage, pair_contact};
use crate::sim::World;

/// Grain-grain contacts on a pool of `threads` threads.
pub struct ParallelPairForces<const ENERGY: bool> {
    pool: rayon::ThreadPool,
    threads: usize,
    out: Vec<PairOut>,
    ledgers: Vec<EnergyLedger>,
    /// Pairs of each grain, `adj[start[i]..start[i + 1]]`, as `k << 1 | (grain is second)`.
    start: Vec<u32>,
    adj: Vec<u32>,
    /// Neighbour-list build the adjacency belongs to.
    built_for: u64,
}

impl<const ENERGY: bool> ParallelPairForces<ENERGY> {
    pub fn new(threads: usize) -> Result<Self, Error> {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| Error::Other(format!("thread pool: {e}")))?;
        Ok(ParallelPairForces { pool, threads, out: Vec::new(), ledgers: Vec::new(), start: Vec::new(), adj: Vec::new(), built_for: u64::MAX })
    }

    fn adjacency(&mut self, n: usize, pairs: &[[u32; 2]]) {
        self.start.clear();
        self.start.resize(n + 1, 0);
        for p in pairs {
            self.start[p[0] as usize + 1] += 1;
            self.start[p[1] as usize + 1] += 1;
        }
        for i in 0..n {
            self.start[i + 1] += self.start[i];
        }
        let mut fill = self.start.clone();
        self.adj.clear();
        self.adj.resize(2 * pairs.len(), 0);
        for (k, p) in pairs.iter().enumerate() {
            for (side, &g) in p.iter().enumerate() {
                let slot = &mut fill[g as usize];
                self.adj[*slot as usize] = (k as u32) << 1 | side as u32;
                *slot += 1;
            }
        }
    }
}

impl<Dm: Damping, T: Tangential, const ENERGY: bool> Stage<ContactModel<Dm, T>> for ParallelPairForces<ENERGY> {
    fn name(&self) -> String {
        format!("PairContacts(parallel, {} threads)", self.threads)
    }
    fn run(&mut self, w: &mut World<ContactModel<Dm, T>>) -> Result<(), Error> {
        let n = w.p.len();
        let np = w.pairs.pairs.len();
        if self.built_for != w.neighbours.builds || self.start.len() != n + 1 {
            self.adjacency(n, &w.pairs.pairs);
            self.built_for = w.neighbours.builds;
        }
        self.out.resize(np, PairOut::default());
        if ENERGY {
            self.ledgers.resize(np, EnergyLedger::default());
        }
        let (out, ledgers, start, adj) = (&mut self.out, &mut self.ledgers, &self.start, &self.adj);
        let mut f = std::mem::take(&mut w.p.f);
        let mut torque = std::mem::take(&mut w.p.torque);
        let view = PairView { p: &w.p, boundary: w.boundary, law: w.law, pair_table: &w.pair_table, dt: w.dt };
        let pairs = &w.pairs.pairs;
        let hist = &mut w.pairs.hist;
        self.pool.install(|| {
            // (1) Every pair into its own slot.
            if ENERGY {
                pairs.par_iter().zip(hist.par_iter_mut()).zip(out.par_iter_mut()).zip(ledgers.par_iter_mut()).with_min_len(512).for_each(|(((pair, h), o), l)| {
                    *l = EnergyLedger::default();
                    *o = pair_contact::<Dm, T, ENERGY>(&view, *pair, h, l);
                });
            } else {
                pairs.par_iter().zip(hist.par_iter_mut()).zip(out.par_iter_mut()).with_min_len(512).for_each(|((pair, h), o)| {
                    let mut l = EnergyLedger::default();
                    *o = pair_contact::<Dm, T, ENERGY>(&view, *pair, h, &mut l);
                });
            }
            // (2) Every grain collects its pairs in pair order.
            let out = &*out;
            f.par_iter_mut().zip(torque.par_iter_mut()).enumerate().with_min_len(512).for_each(|(i, (fi, ti))| {
                for &e in &adj[start[i] as usize..start[i + 1] as usize] {
                    let o = &out[(e >> 1) as usize];
                    if o.ratio > 0.0 {
                        if e & 1 == 0 {
                            *fi += o.force;
                            if T::FRICTION {
                                *ti -= o.torque[0];
                            }
                        } else {
                            *fi -= o.force;
                            if T::FRICTION {
                                *ti -= o.torque[1];
                            }
                        }
                    }
                }
            });
        });
        w.p.f = f;
        w.p.torque = torque;
        // (3) Energy terms and the largest overlap, in pair order.
        let mut worst = w.max_overlap;
        for (k, o) in self.out.iter().enumerate() {
            if o.ratio > worst.0 {
                let p = w.pairs.pairs[k];
                worst = (o.ratio, p[0] as usize, p[1] as usize);
            }
        }
        w.max_overlap = worst;
        if ENERGY {
            for l in &self.ledgers {
                let g = &mut w.ledger;
                g.normal_damping += l.normal_damping;
                g.tangential_damping += l.tangential_damping;
                g.friction += l.friction;
                g.tangential_model += l.tangential_model;
                g.elastic_normal += l.elastic_normal;
                g.elastic_tangential += l.elastic_tangential;
            }
        }
        Ok(())
    }
}
