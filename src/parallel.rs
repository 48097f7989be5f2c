//! Contact forces on several threads (feature `parallel`), bit for bit the same as on one.
//!
//! Floating-point sums depend on their order, so the parallel stage keeps the serial
//! order of every addition. The Verlet list is sorted with i < j in each pair, so the
//! serial loop adds to grain g first the pairs (m, g), m < g, in list order, then the
//! pairs (g, j), which are contiguous in the list. The stage (1) computes every pair in
//! parallel, keeping its force and first torque in list order and writing its second
//! grain's share into that grain's own slot of a per-grain table (slots fixed at each
//! neighbour rebuild); (2) lets every grain, in parallel, add its second-side entries then
//! its contiguous first-side entries, both read sequentially: the serial sequence of
//! additions, grain by grain; (3) gathers the energy terms and the largest overlap in list
//! order. `tests/parallel.rs` checks identical bits with 1 and 2 threads.

use rayon::prelude::*;

use crate::contact::ContactModel;
use crate::contact::damping::Damping;
use crate::contact::tangential::Tangential;
use crate::dim::Vec2;
use crate::error::Error;
use crate::observe::energy::EnergyLedger;
use crate::pipeline::{PairOut, PairView, Stage, pair_contact};
use crate::sim::World;

/// A grain's share of a pair in which it is the second grain.
#[derive(Clone, Copy, Debug, Default)]
struct Second {
    force: Vec2,
    torque: f64,
    touching: bool,
}

/// Disjoint writes into a slice from parallel closures: each pair owns one slot.
#[derive(Clone, Copy)]
struct Slots(*mut Second);
unsafe impl Send for Slots {}
unsafe impl Sync for Slots {}

/// Grain-grain contacts on a pool of `threads` threads.
pub struct ParallelPairForces<const ENERGY: bool> {
    pool: rayon::ThreadPool,
    threads: usize,
    out: Vec<PairOut>,
    ledgers: Vec<EnergyLedger>,
    /// Pairs (g, j) of grain g: `first[g]..first[g + 1]` in the list.
    first: Vec<u32>,
    /// Entries of grain g as the second grain: `second[g]..second[g + 1]` in `seconds`.
    second: Vec<u32>,
    /// Slot in `seconds` of each pair.
    slot: Vec<u32>,
    seconds: Vec<Second>,
    /// Neighbour-list build the tables belong to.
    built_for: u64,
}

impl<const ENERGY: bool> ParallelPairForces<ENERGY> {
    pub fn new(threads: usize) -> Result<Self, Error> {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| Error::Other(format!("thread pool: {e}")))?;
        Ok(ParallelPairForces {
            pool,
            threads,
            out: Vec::new(),
            ledgers: Vec::new(),
            first: Vec::new(),
            second: Vec::new(),
            slot: Vec::new(),
            seconds: Vec::new(),
            built_for: u64::MAX,
        })
    }

    fn tables(&mut self, n: usize, pairs: &[[u32; 2]]) {
        self.first.clear();
        self.first.resize(n + 1, 0);
        self.second.clear();
        self.second.resize(n + 1, 0);
        for p in pairs {
            debug_assert!(p[0] < p[1]);
            self.first[p[0] as usize + 1] += 1;
            self.second[p[1] as usize + 1] += 1;
        }
        for g in 0..n {
            self.first[g + 1] += self.first[g];
            self.second[g + 1] += self.second[g];
        }
        let mut fill = self.second.clone();
        self.slot.clear();
        self.slot.extend(pairs.iter().map(|p| {
            let s = &mut fill[p[1] as usize];
            *s += 1;
            *s - 1
        }));
        self.seconds.clear();
        self.seconds.resize(pairs.len(), Second::default());
    }
}

impl<Dm: Damping, T: Tangential, const ENERGY: bool> Stage<ContactModel<Dm, T>> for ParallelPairForces<ENERGY> {
    fn name(&self) -> String {
        format!("PairContacts(parallel, {} threads)", self.threads)
    }
    fn run(&mut self, w: &mut World<ContactModel<Dm, T>>) -> Result<(), Error> {
        let n = w.p.len();
        let np = w.pairs.pairs.len();
        if self.built_for != w.neighbours.builds || self.first.len() != n + 1 || self.slot.len() != np {
            self.tables(n, &w.pairs.pairs);
            self.built_for = w.neighbours.builds;
        }
        self.out.resize(np, PairOut::default());
        if ENERGY {
            self.ledgers.resize(np, EnergyLedger::default());
        }
        let mut f = std::mem::take(&mut w.p.f);
        let mut torque = std::mem::take(&mut w.p.torque);
        let view = PairView { p: &w.p, boundary: w.boundary, law: w.law, pair_table: &w.pair_table, dt: w.dt };
        let (pairs, hist) = (&w.pairs.pairs, &mut w.pairs.hist);
        let (out, ledgers, slot) = (&mut self.out, &mut self.ledgers, &self.slot);
        let (first, second) = (&self.first, &self.second);
        let seconds = Slots(self.seconds.as_mut_ptr());
        self.pool.install(|| {
            // (1) Every pair: its own slot in list order, and its second grain's slot.
            let one = |k: usize, pair: &[u32; 2], h: &mut _, o: &mut PairOut, l: &mut EnergyLedger| {
                *o = pair_contact::<Dm, T, ENERGY>(&view, *pair, h, l);
                let s = Second { force: o.force, torque: o.torque[1], touching: o.ratio > 0.0 };
                // SAFETY: `slot` is a permutation of 0..np (built from the same list), so
                // every pair writes a different element, and nothing reads until the join.
                unsafe { *{ seconds }.0.add(slot[k] as usize) = s };
            };
            if ENERGY {
                pairs.par_iter().zip(hist.par_iter_mut()).zip(out.par_iter_mut()).zip(ledgers.par_iter_mut()).enumerate().with_min_len(1024).for_each(
                    |(k, (((pair, h), o), l))| {
                        *l = EnergyLedger::default();
                        one(k, pair, h, o, l);
                    },
                );
            } else {
                pairs.par_iter().zip(hist.par_iter_mut()).zip(out.par_iter_mut()).enumerate().with_min_len(1024).for_each(|(k, ((pair, h), o))| {
                    one(k, pair, h, o, &mut EnergyLedger::default());
                });
            }
            // (2) Every grain: its second-side entries, then its first-side pairs.
            let (out, seconds) = (&*out, unsafe { std::slice::from_raw_parts(seconds.0 as *const Second, np) });
            f.par_iter_mut().zip(torque.par_iter_mut()).enumerate().with_min_len(1024).for_each(|(g, (fg, tg))| {
                for s in &seconds[second[g] as usize..second[g + 1] as usize] {
                    if s.touching {
                        *fg -= s.force;
                        if T::FRICTION {
                            *tg -= s.torque;
                        }
                    }
                }
                for o in &out[first[g] as usize..first[g + 1] as usize] {
                    if o.ratio > 0.0 {
                        *fg += o.force;
                        if T::FRICTION {
                            *tg -= o.torque[0];
                        }
                    }
                }
            });
        });
        w.p.f = f;
        w.p.torque = torque;
        // (3) Energy terms and the largest overlap, in list order.
        let mut worst = w.max_overlap;
        for (k, o) in self.out.iter().enumerate() {
            if o.ratio > worst.0 {
                let p = w.pairs.pairs[k];
                worst = (o.ratio, p[0] as usize, p[1] as usize);
            }
        }
        w.max_overlap = worst;
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
