//! Contact forces on several threads (feature `parallel`), bit for bit the same as on one.
//!
//! Floating-point sums depend on their order, so the parallel stage keeps the serial
//! order of every addition. The Verlet list is sorted with i < j in each pair, and the
//! serial loop adds to a grain g first its pairs (m, g), m < g, in list order, then its
//! pairs (g, j). The grains (stored along a Z curve, so index ranges are compact in space)
//! are split into one index range per thread, balanced by pair count. (1) The few pairs
//! that join two ranges are computed first, in parallel, into their own slots. (2) Each
//! thread then adds to its grains the cross pairs that come from earlier ranges (they are
//! first in every grain's sequence), and runs the serial loop over the pairs whose first
//! grain is its own, taking the cross pairs' results where they fall in the list. (3) The
//! energy terms are merged in list order and the largest overlap picked as the serial
//! loop would. `tests/parallel.rs` checks identical bits with 1 and 2 threads.

use rayon::prelude::*;

use crate::contact::ContactModel;
use crate::contact::damping::Damping;
use crate::contact::tangential::Tangential;
use crate::error::Error;
use crate::observe::energy::EnergyLedger;
use crate::pipeline::{PairOut, PairView, Stage, pair_contact};
use crate::sim::{Hist, World};

/// A pointer that parallel closures may share: every use writes a different element.
#[derive(Clone, Copy)]
struct Shared<T>(*mut T);
unsafe impl<T> Send for Shared<T> {}
unsafe impl<T> Sync for Shared<T> {}

const NOT_CROSS: u32 = u32::MAX;

/// Grain-grain contacts on a pool of `threads` threads.
pub struct ParallelPairForces<const ENERGY: bool> {
    pool: rayon::ThreadPool,
    threads: usize,
    /// Grain index bounds of the ranges, `threads + 1` entries.
    bounds: Vec<usize>,
    /// Pairs (g, j) of grain g: `first[g]..first[g + 1]` in the list.
    first: Vec<usize>,
    /// The pairs joining two ranges, in list order, and each pair's slot among them.
    cross: Vec<u32>,
    cross_slot: Vec<u32>,
    cross_out: Vec<PairOut>,
    /// For each range, the slots of the cross pairs whose second grain is in it, in list order.
    incoming: Vec<Vec<u32>>,
    /// Energy terms of every pair, merged in list order (with the energy ledger only).
    ledgers: Vec<EnergyLedger>,
    /// Neighbour-list build the tables belong to.
    built_for: u64,
}

impl<const ENERGY: bool> ParallelPairForces<ENERGY> {
    pub fn new(threads: usize) -> Result<Self, Error> {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| Error::Other(format!("thread pool: {e}")))?;
        Ok(ParallelPairForces {
            pool,
            threads,
            bounds: Vec::new(),
            first: Vec::new(),
            cross: Vec::new(),
            cross_slot: Vec::new(),
            cross_out: Vec::new(),
            incoming: Vec::new(),
            ledgers: Vec::new(),
            built_for: u64::MAX,
        })
    }

    fn tables(&mut self, n: usize, pairs: &[[u32; 2]]) {
        self.first.clear();
        self.first.resize(n + 1, 0);
        for p in pairs {
            debug_assert!(p[0] < p[1]);
            self.first[p[0] as usize + 1] += 1;
        }
        for g in 0..n {
            self.first[g + 1] += self.first[g];
        }
        // Ranges with about the same number of pairs each.
        let t = self.threads;
        self.bounds.clear();
        self.bounds.push(0);
        for r in 1..t {
            let target = pairs.len() * r / t;
            let g = self.first.partition_point(|&c| c < target).min(n);
            self.bounds.push(g.max(*self.bounds.last().unwrap()));
        }
        self.bounds.push(n);
        let range_of = |g: usize, b: &[usize]| b.partition_point(|&x| x <= g) - 1;
        self.cross.clear();
        self.cross_slot.clear();
        self.incoming = vec![Vec::new(); t];
        for (k, p) in pairs.iter().enumerate() {
            let (ri, rj) = (range_of(p[0] as usize, &self.bounds), range_of(p[1] as usize, &self.bounds));
            if ri == rj {
                self.cross_slot.push(NOT_CROSS);
            } else {
                let slot = self.cross.len() as u32;
                self.cross_slot.push(slot);
                self.cross.push(k as u32);
                self.incoming[rj].push(slot);
            }
        }
        self.cross_out.clear();
        self.cross_out.resize(self.cross.len(), PairOut::default());
    }
}

impl<Dm: Damping, T: Tangential, const ENERGY: bool> Stage<ContactModel<Dm, T>> for ParallelPairForces<ENERGY> {
    fn name(&self) -> String {
        format!("PairContacts(parallel, {} threads)", self.threads)
    }
    fn run(&mut self, w: &mut World<ContactModel<Dm, T>>) -> Result<(), Error> {
        let n = w.p.len();
        let np = w.pairs.pairs.len();
        if self.built_for != w.neighbours.builds || self.first.len() != n + 1 || self.cross_slot.len() != np {
            self.tables(n, &w.pairs.pairs);
            self.built_for = w.neighbours.builds;
        }
        if ENERGY {
            self.ledgers.clear();
            self.ledgers.resize(np, EnergyLedger::default());
        }
        let mut f = std::mem::take(&mut w.p.f);
        let mut torque = std::mem::take(&mut w.p.torque);
        let view = PairView { p: &w.p, boundary: w.boundary, law: w.law, pair_table: &w.pair_table, dt: w.dt };
        let pairs = &w.pairs.pairs;
        let consts = &w.pairs.consts;
        let hist: Shared<Hist<ContactModel<Dm, T>>> = Shared(w.pairs.hist.as_mut_ptr());
        let ledgers = Shared(self.ledgers.as_mut_ptr());
        let (cross, cross_slot, incoming, bounds, first) = (&self.cross, &self.cross_slot, &self.incoming, &self.bounds, &self.first);
        let cross_out = &mut self.cross_out;
        let mut worsts: Vec<(f64, usize)> = vec![(0.0, usize::MAX); self.threads + 1];
        self.pool.install(|| {
            // (1) The pairs joining two ranges.
            cross.par_iter().zip(cross_out.par_iter_mut()).with_min_len(256).for_each(|(&k, o)| {
                let k = k as usize;
                // SAFETY: every pair index appears once in `cross`, and phase (2) does not
                // touch cross pairs' histories or ledgers: the writes are disjoint.
                let h = unsafe { &mut *{ hist }.0.add(k) };
                let mut local = EnergyLedger::default();
                let l = if ENERGY { unsafe { &mut *{ ledgers }.0.add(k) } } else { &mut local };
                *o = pair_contact::<Dm, T, ENERGY>(&view, pairs[k], &consts[k], h, l);
            });
            let cross_out = &*cross_out;
            // (2) Each range: incoming cross pairs, then the serial loop over its pairs.
            let mut f_parts = Vec::new();
            let mut t_parts = Vec::new();
            let (mut fr, mut tr) = (&mut f[..], &mut torque[..]);
            for r in 0..self.threads {
                let len = bounds[r + 1] - bounds[r];
                let (a, b) = std::mem::take(&mut fr).split_at_mut(len);
                let (c, d) = std::mem::take(&mut tr).split_at_mut(len);
                f_parts.push(a);
                t_parts.push(c);
                fr = b;
                tr = d;
            }
            f_parts.into_par_iter().zip(t_parts.into_par_iter()).zip(worsts.par_iter_mut()).enumerate().for_each(|(r, ((fl, tl), worst))| {
                let g0 = bounds[r];
                for &s in &incoming[r] {
                    let o = &cross_out[s as usize];
                    if o.ratio > 0.0 {
                        let g = pairs[cross[s as usize] as usize][1] as usize - g0;
                        fl[g] -= o.force;
                        if T::FRICTION {
                            tl[g] -= o.torque[1];
                        }
                    }
                }
                let mut best = (0.0, usize::MAX);
                for k in first[g0]..first[bounds[r + 1]] {
                    let pair = pairs[k];
                    let (i, j) = (pair[0] as usize - g0, pair[1] as usize);
                    let slot = cross_slot[k];
                    if slot != NOT_CROSS {
                        let o = &cross_out[slot as usize];
                        if o.ratio > 0.0 {
                            fl[i] += o.force;
                            if T::FRICTION {
                                tl[i] -= o.torque[0];
                            }
                            if o.ratio > best.0 {
                                best = (o.ratio, k);
                            }
                        }
                        continue;
                    }
                    // SAFETY: pair k's first grain is in this range and it is not a cross
                    // pair, so no other thread touches its history or ledger.
                    let h = unsafe { &mut *{ hist }.0.add(k) };
                    let mut local = EnergyLedger::default();
                    let l = if ENERGY { unsafe { &mut *{ ledgers }.0.add(k) } } else { &mut local };
                    let o = pair_contact::<Dm, T, ENERGY>(&view, pair, &consts[k], h, l);
                    if o.ratio > 0.0 {
                        let j = j - g0;
                        fl[i] += o.force;
                        fl[j] -= o.force;
                        if T::FRICTION {
                            tl[i] -= o.torque[0];
                            tl[j] -= o.torque[1];
                        }
                        if o.ratio > best.0 {
                            best = (o.ratio, k);
                        }
                    }
                }
                *worst = best;
            });
        });
        w.p.f = f;
        w.p.torque = torque;
        // (3) The largest overlap as the serial loop picks it (the first of equal maxima),
        // and the energy terms in list order.
        let mut best = (0.0, usize::MAX);
        for &(ratio, k) in &worsts {
            if k != usize::MAX && (ratio > best.0 || (ratio == best.0 && k < best.1)) {
                best = (ratio, k);
            }
        }
        if best.1 != usize::MAX && best.0 > w.max_overlap.0 {
            let p = w.pairs.pairs[best.1];
            w.max_overlap = (best.0, p[0] as usize, p[1] as usize);
        }
        if ENERGY {
            let g = &mut w.ledger;
            for l in &self.ledgers {
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
