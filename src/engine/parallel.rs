//! Contact forces on several threads (feature `parallel`), bit for bit the same as on one.
//!
//! Floating-point sums depend on their order, so the parallel stage keeps the serial
//! order of every addition. The Verlet list is sorted with i < j in each pair, and the
//! serial loop adds to a grain g first its pairs (m, g), m < g, in list order, then its
//! pairs (g, j). The free grains (stored along a Z curve, so index ranges are compact in
//! space) are split into one index range per thread, balanced by the pairs' expected cost
//! (listed pairs, the touching ones and the cross pairs below weighted: [`TOUCHING_COST`],
//! [`CROSS_COST`]) and by how fast each thread got through its range's cost last time
//! ([`rebalanced`]; the ranges are cut at each new list, and once [`FIRST_TIMING`] steps
//! into the first); the pairs whose first grain is in a range are a contiguous part of
//! the list, with their histories.
//!
//! The rough walls' grains come last in the index space and own no pairs; every range
//! has pairs with them. They belong to the first thread: their sequences begin with the
//! first range's pairs, which it adds as they come, and the other threads keep what their
//! pairs do to those grains, in list order, for the first thread to add after its own.
//! The pairs that join two ranges of free grains ("cross" pairs, a few along each cut)
//! belong to the thread of their first grain.
//!
//! In one hand-over per step, each thread (1) computes its cross pairs and publishes what
//! they did, (2) sorts out the touching pairs of the rest of its part, (3) adds to its
//! grains the cross pairs from earlier ranges (they are first in every grain's sequence;
//! it waits for their threads to publish, which they do first thing), (4) computes its
//! touching pairs four at a time, adding each result as it comes, in list order (or
//! keeping it, for a wall's grain on a thread after the first), (5) adds its own cross
//! pairs to their first grains (a grain's pairs (g, j) with j in a later range come after
//! its other pairs with free grains), then its pairs with the rough walls' grains to their
//! first grains (those grains have the largest indices of all, so these pairs end the
//! sequence; added in (4), before the cross pairs, they made the bits depend on where the
//! ranges were cut, which follows the threads' timings), and publishes what it kept for
//! the walls' grains; (6) the first thread adds those, range by range. Then the largest
//! overlap is picked as the serial loop would. Each pair adds its energy terms to its own
//! sums, which the ledger adds in list order when it takes them: no order to restore.
//! `tests/parallel.rs` checks identical bits with 1, 2 and 3 threads.
//!
//! Were the walls' grains the last thread's (as in the per-grain stages), the other
//! ranges' pairs with them would be cross pairs: at 100 000 grains about 2500 a step on
//! the first thread, which took it 58 ms per 1000 steps to compute apart and 9 ms to add,
//! and the last thread 25-29 ms to add to the walls' grains. Owned by the first thread,
//! the threads' summed time in the stage is 2-4% lower (timed per thread).

use crate::engine::world::{Stage, World};
use crate::error::Error;
use crate::kernels::driver::{PairOut, PairSlices, PairView, compute_pairs};
use crate::kernels::sweep::sort_pairs;
use crate::kernels::threads::Threads;
use crate::physics::contact::ContactModel;
use crate::physics::contact::cohesion::Cohesion;
use crate::physics::contact::rolling::Rolling;
use crate::physics::contact::damping::Damping;
use crate::physics::contact::normal::Normal;
use crate::physics::contact::tangential::Tangential;
use crate::physics::dim::{Plane, Vec2};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// What a touching pair costs the contact stage, in listed pairs: each listed pair is
/// swept, each touching one also goes through the kernel. At 5000 grains on one thread
/// (AVX-512 sweep) the profile gives about 1.1 ns per listed pair for the sweep and 8.3 ns
/// per touching pair for the kernel. Balancing the threads' parts by listed pairs alone
/// left the first thread 5% more touching pairs and 7% more time at 20 000 grains; with
/// this weight (touching counted at the list's build) both took the same time within 2%.
const TOUCHING_COST: usize = 8;

/// What a cross pair costs its thread on top of an own pair, in listed pairs. The thread
/// owning its first grain sorts it out and computes it before its own pairs, one by one
/// and scattered through the list: 12-20 ns per cross pair at 20 000-100 000 grains
/// (timed per thread), against about 5 ns for a listed pair in the sweep and kernel.
const CROSS_COST: usize = 10;

/// What a pair did to a rough wall's grain (`o.grain` counted from the first wall grain):
/// added to that grain (`walls`: the first thread's forces and torques of those grains,
/// and with `torque` the torque too) or kept for the first thread (`out`). Out of line:
/// about one touching pair in 40 reaches a wall's grain, and the kernel's loop kept the
/// sink inline only while it was small (with this code inline, each thread took 25% longer).
#[cold]
#[inline(never)]
fn to_wall(torque: bool, walls: &mut Option<(&mut [Vec2], &mut [f64])>, out: &mut Vec<WallOut>, o: WallOut) {
    match walls {
        Some((fw, tw)) => o.onto(fw, tw, torque),
        None => out.push(o),
    }
}

/// One thread's working lists.
#[derive(Default)]
struct Scratch {
    touching: Vec<u32>,
    sep: Vec<Vec2>,
    released: Vec<u32>,
    /// Largest overlap ratio of the part and its pair index.
    worst: (f64, usize),
    /// What the thread's cross pairs did this step, in slot order.
    cross_out: Vec<PairOut>,
    /// What the thread's pairs did to rough walls' grains this step, in list order (the
    /// threads after the first: the first owns those grains).
    wall_out: Vec<WallOut>,
    /// What the thread's pairs with rough walls' grains did to their first grains, in list
    /// order, added after the thread's cross pairs: a wall's grains have the largest
    /// indices, so a grain's pairs with them end its sequence, after its cross pairs.
    wall_first: Vec<(u32, PairOut)>,
    /// Time the thread worked in this stage since the ranges were last cut (not counting
    /// waits for other threads).
    busy: Duration,
}

/// What a pair did to its second grain, a rough wall's grain.
#[derive(Clone, Copy)]
struct WallOut {
    grain: u32,
    force: Vec2,
    torque: f64,
}

impl WallOut {
    /// Add it to its grain's force in `fw` (and with `torque` its torque in `tw`): the
    /// first thread's parts for the walls' grains.
    #[inline(always)]
    fn onto(&self, fw: &mut [Vec2], tw: &mut [f64], torque: bool) {
        let g = self.grain as usize;
        fw[g] -= self.force;
        if torque {
            tw[g] -= self.torque;
        }
    }
}

/// Whether a pair of a range ending at grain `end` whose second grain is `j` joins it to
/// a later range: the list is sorted, so a range's pairs are those whose first grain it
/// holds and the second grain comes later; it is in a later range if it is past the
/// range's end and a free grain (pairs with a rough wall's grain are not cross pairs: see
/// the module's notes).
fn joins_later_range(j: u32, end: usize, n_free: usize) -> bool {
    (end..n_free).contains(&(j as usize))
}

/// Publishes an empty result if the thread unwinds before it publishes its own.
struct Publish<'a, 'b, X>(&'a OnceLock<&'b [X]>);

impl<X> Drop for Publish<'_, '_, X> {
    fn drop(&mut self) {
        let _ = self.0.set(&[]);
    }
}

/// What another thread published, once it has (it does so early in its step); the time
/// spent waiting for it is added to `waited`.
fn wait<'b, X>(cell: &OnceLock<&'b [X]>, waited: &mut Duration) -> &'b [X] {
    if let Some(v) = cell.get() {
        return v;
    }
    let start = Instant::now();
    let mut spins = 0u32;
    loop {
        if let Some(v) = cell.get() {
            *waited += start.elapsed();
            return v;
        }
        spins += 1;
        if spins < 1 << 12 {
            std::hint::spin_loop();
        } else {
            std::thread::yield_now();
        }
    }
}

/// Grain-grain contacts on the run's thread pool.
pub struct ParallelPairForces<const ENERGY: bool, const SPIN: bool> {
    threads: Threads,
    /// Grain index bounds of the ranges of free grains, `threads + 1` entries (the last
    /// is `n_free`; the rough walls' grains after it belong to the first thread).
    bounds: Vec<usize>,
    /// Number of grains the tables were made for.
    grains: usize,
    /// Pair index bounds of the ranges' parts of the list.
    pair_bounds: Vec<usize>,
    /// The pairs joining two ranges, in list order (a pair's slot is its place here),
    /// and the same as indices into their range's part of the list.
    cross: Vec<u32>,
    cross_in_part: Vec<u32>,
    /// Slot bounds of each range's cross pairs (those whose first grain it owns).
    cross_bounds: Vec<usize>,
    /// For each range, the slots of the cross pairs whose second grain is in it, in list order.
    incoming: Vec<Vec<u32>>,
    scratch: Vec<Scratch>,
    /// Neighbour-list build the tables belong to.
    built_for: u64,
    /// Each range's share of the modelled cost ([`rebalanced`]), and the cost it got.
    shares: Vec<f64>,
    range_cost: Vec<usize>,
    /// Steps since the ranges were cut, and whether they have been cut from timings yet.
    since_cut: usize,
    timed: bool,
}

/// Steps after which the ranges are cut again if the list lasts that long and they have
/// not been cut from the threads' timings yet: the first list's cut is the cost model's
/// alone, and a short run may not see a second list.
const FIRST_TIMING: usize = 100;

/// Where to cut the per-pair energy memories for list parts cut at `bounds`:
/// the same places with the energy ledger, else nowhere (they are empty).
fn energy_cuts<const ENERGY: bool>(bounds: &[usize]) -> Vec<usize> {
    if ENERGY { bounds.to_vec() } else { vec![0; bounds.len()] }
}

/// `v` cut at `bounds` (from 0 to `v.len()`) into consecutive parts.
fn cut<'a, T>(mut v: &'a mut [T], bounds: &[usize]) -> Vec<&'a mut [T]> {
    let mut parts = Vec::with_capacity(bounds.len());
    for w in bounds.windows(2) {
        let (a, b) = std::mem::take(&mut v).split_at_mut(w[1] - w[0]);
        parts.push(a);
        v = b;
    }
    parts
}

/// The listed pairs `slots` (list indices, ascending, all in the list part from `k0`)
/// sorted out as [`sort_pairs`] sorts out a stretch of the list: the first `nt` of
/// `touching` (with their separations in `sep`) and the first `nr` of `released`, as
/// indices into the part; `(nt, nr)` returned.
#[allow(clippy::too_many_arguments)]
fn sort_listed<L: crate::physics::contact::ContactLaw>(view: &PairView<'_, L>, pairs: &[[u32; 2]], reach: &[f64], active: &[bool], k0: usize, slots: &[u32], touching: &mut Vec<u32>, sep: &mut Vec<Vec2>, released: &mut Vec<u32>) -> (usize, usize) {
    let (x, b) = (&view.p.x, view.boundary);
    let (mut nt, mut nr) = (0, 0);
    let len = touching.len().max(slots.len());
    touching.resize(len, 0);
    sep.resize(len, Vec2::zeros());
    released.resize(len, 0);
    for &k in slots {
        let k = k as usize;
        let [i, j] = pairs[k].map(|g| g as usize);
        let d = b.image(x[i] - x[j]);
        if d.norm_squared() < reach[k] {
            (touching[nt], sep[nt]) = ((k - k0) as u32, d);
            nt += 1;
        } else if active[k - k0] {
            released[nr] = (k - k0) as u32;
            nr += 1;
        }
    }
    (nt, nr)
}

/// The range of grain `g` for range bounds `b` (or of slot `g` for slot bounds).
fn range_of(g: usize, b: &[usize]) -> usize {
    b.partition_point(|&x| x <= g) - 1
}

/// Bounds of grain ranges, one per entry of `shares`, holding about those fractions of the
/// total cost (`cost` per grain; the shares add up to 1).
fn balanced(cost: &[usize], shares: &[f64]) -> Vec<usize> {
    let n = cost.len();
    let mut cumulative = vec![0usize; n + 1];
    for g in 0..n {
        cumulative[g + 1] = cumulative[g] + cost[g];
    }
    let mut bounds = vec![0];
    let mut before = 0.0;
    for share in &shares[..shares.len() - 1] {
        before += share;
        let target = (cumulative[n] as f64 * before).round() as usize;
        let g = cumulative.partition_point(|&c| c < target).min(n);
        bounds.push(g.max(*bounds.last().unwrap()));
    }
    bounds.push(n);
    bounds
}

/// The shares of the modelled cost for the next cut's ranges, from the last cut's
/// `shares`, what the cost model gave each range (`cost`) and how long each thread worked
/// on its range since (`busy`). The cost model counts pairs; what a pair costs also
/// depends on where it is: at 20 000 grains the second range had fewer of its listed pairs
/// touching and its kernel took 11.1 ns per touching pair against the first range's 10.0
/// (timed per thread), so equal modelled shares left the second thread 11% more work
/// every step (0.823 s against 0.739 s of contact stage in 6000 steps). So each range gets
/// the cost its thread did per second last time, as a share of what all did: equal times
/// if the rates hold. No share rises by more than a quarter or falls by more than a fifth
/// per cut, so that a thread descheduled for a while on a shared host cannot throw the
/// next cut far off.
/// The shares only move the cut between threads: the forces, and their bits, are the same
/// for any cut.
fn rebalanced(shares: &[f64], cost: &[usize], busy: &[Duration]) -> Vec<f64> {
    if busy.iter().any(|b| b.is_zero()) || cost.contains(&0) {
        return shares.to_vec();
    }
    // Cost per second of each thread: the equal-time shares are proportional to it.
    let speed: Vec<f64> = cost.iter().zip(busy).map(|(&c, b)| c as f64 / b.as_secs_f64()).collect();
    let total: f64 = speed.iter().sum();
    let moved: Vec<f64> = shares.iter().zip(&speed).map(|(&s, &v)| (v / total).clamp(0.8 * s, 1.25 * s)).collect();
    let sum: f64 = moved.iter().sum();
    moved.iter().map(|s| s / sum).collect()
}

impl<const ENERGY: bool, const SPIN: bool> ParallelPairForces<ENERGY, SPIN> {
    pub fn new(threads: Threads) -> Self {
        let t = threads.count();
        ParallelPairForces {
            threads,
            bounds: Vec::new(),
            grains: 0,
            pair_bounds: Vec::new(),
            cross: Vec::new(),
            cross_in_part: Vec::new(),
            cross_bounds: Vec::new(),
            incoming: Vec::new(),
            scratch: (0..t).map(|_| Scratch::default()).collect(),
            built_for: u64::MAX,
            shares: vec![1.0 / t as f64; t],
            range_cost: vec![0; t],
            since_cut: 0,
            timed: false,
        }
    }

    /// The ranges and the cross pairs for a new list (`active`: which of its pairs touched
    /// at the last step).
    fn tables(&mut self, n: usize, n_free: usize, pairs: &[[u32; 2]], active: &[bool]) {
        // Per grain: the pairs it is first in (cumulative), and their expected cost.
        let (mut first, mut cost) = (vec![0usize; n + 1], vec![0usize; n]);
        for (p, &a) in pairs.iter().zip(active) {
            debug_assert!(p[0] < p[1]);
            first[p[0] as usize + 1] += 1;
            cost[p[0] as usize] += 1 + TOUCHING_COST * a as usize;
        }
        for g in 0..n {
            first[g + 1] += first[g];
        }
        // Ranges of free grains with about the same cost each (the grains of rough walls,
        // last in the index space, own no pairs). They stay close to the equal ranges of
        // the per-grain stages, so that each thread mostly works on the same grains. The
        // cross pairs cost their thread more (they are sorted out one by one and read the
        // grains of another thread): cut once, count them, cut again.
        let t = self.scratch.len();
        let busy: Vec<Duration> = self.scratch.iter_mut().map(|s| std::mem::take(&mut s.busy)).collect();
        if self.bounds.len() == self.shares.len() + 1 && self.grains == n && *self.bounds.last().unwrap() == n_free {
            self.shares = rebalanced(&self.shares, &self.range_cost, &busy);
            self.timed = true;
        }
        self.since_cut = 0;
        let cost = &mut cost[..n_free];
        let first_cut = balanced(cost, &self.shares);
        for b in first_cut.windows(2) {
            for p in &pairs[first[b[0]]..first[b[1]]] {
                if joins_later_range(p[1], b[1], n_free) {
                    cost[p[0] as usize] += CROSS_COST;
                }
            }
        }
        self.bounds = balanced(cost, &self.shares);
        self.grains = n;
        self.range_cost = self.bounds.windows(2).map(|b| cost[b[0]..b[1]].iter().sum()).collect();
        self.pair_bounds = self.bounds.iter().map(|&g| first[g]).collect();
        self.cross.clear();
        self.cross_in_part.clear();
        self.cross_bounds = vec![0];
        self.incoming = vec![Vec::new(); t];
        for r in 0..t {
            let (k0, end) = (self.pair_bounds[r], self.bounds[r + 1]);
            for (m, p) in pairs[k0..self.pair_bounds[r + 1]].iter().enumerate() {
                if joins_later_range(p[1], end, n_free) {
                    let rj = range_of(p[1] as usize, &self.bounds);
                    let slot = self.cross.len() as u32;
                    self.cross_in_part.push(m as u32);
                    self.cross.push((k0 + m) as u32);
                    self.incoming[rj].push(slot);
                }
            }
            self.cross_bounds.push(self.cross.len());
        }
    }
}

impl<N: Normal, Dm: Damping, T: Tangential, C: Cohesion, Rr: Rolling, const ENERGY: bool, const SPIN: bool> Stage<ContactModel<N, Dm, T, C, Rr>> for ParallelPairForces<ENERGY, SPIN> {
    fn name(&self) -> String {
        format!("PairContacts(parallel, {} threads)", self.scratch.len())
    }
    /// Nothing carried: the tables are cut again for the restored list (where the ranges
    /// are cut changes no bit of the results).
    fn restore(&mut self, carried: &[f64]) -> Result<(), String> {
        self.built_for = u64::MAX;
        if carried.is_empty() { Ok(()) } else { Err(format!("the parallel contact stage carries nothing, the checkpoint gave it {} numbers", carried.len())) }
    }
    fn run(&mut self, w: &mut World<ContactModel<N, Dm, T, C, Rr>>) -> Result<(), Error> {
        let (n, n_free) = (w.p.len(), w.p.n_free);
        let np = w.pairs.pairs.len();
        self.since_cut += 1;
        let first_timing = !self.timed && self.since_cut > FIRST_TIMING;
        if first_timing || self.built_for != w.neighbours.builds || self.pair_bounds.last() != Some(&np) || self.grains != n {
            self.tables(n, n_free, &w.pairs.pairs, &w.pairs.active);
            self.built_for = w.neighbours.builds;
        }
        let energy_bounds = energy_cuts::<ENERGY>(&self.pair_bounds);
        let mut f = std::mem::take(&mut w.p.f);
        let mut torque = std::mem::take(&mut w.p.torque);
        let view = PairView { p: &w.p, boundary: w.boundary, law: w.law, pair_table: &w.pair_table, dt: w.dt };
        let (checked, consts, reach) = (w.pairs.pairs.checked(), &w.pairs.consts, &w.pairs.reach);
        let pairs = checked.pairs();
        let (bounds, pb, cb) = (&self.bounds, &self.pair_bounds, &self.cross_bounds);
        let (cross, cross_in_part, incoming) = (&self.cross, &self.cross_in_part, &self.incoming);
        let threads = &self.threads;
        {
            // What each thread computed of its cross pairs, for the threads of their second
            // grains to read once it is there.
            let published: Vec<OnceLock<&[PairOut]>> = (0..self.scratch.len()).map(|_| OnceLock::new()).collect();
            // ... and what each thread after the first did to the rough walls' grains.
            let published_walls: Vec<OnceLock<&[WallOut]>> = (0..self.scratch.len()).map(|_| OnceLock::new()).collect();
            // The free grains' forces and torques in one part per range, the walls' grains'
            // (after the last range) to the first thread.
            let grain_bounds: Vec<usize> = bounds.iter().copied().chain([n]).collect();
            let (mut f_parts, mut torque_parts) = (cut(&mut f, &grain_bounds), cut(&mut torque, &grain_bounds));
            let mut walls = f_parts.pop().zip(torque_parts.pop());
            let parts = cut(&mut w.pairs.hist, pb)
                .into_iter()
                .zip(cut(&mut w.pairs.active, pb))
                .zip(cut(&mut w.pairs.energy, &energy_bounds))
                .zip(f_parts.into_iter().zip(torque_parts))
                .zip(self.scratch.iter_mut())
                .enumerate()
                .map(|(r, p)| (p, if r == 0 { walls.take() } else { None }));
            threads.each(parts.collect(), |r, (((((hist, active), energy), (fl, tl)), sc), mut walls)| {
                let start = Instant::now();
                let mut waited = Duration::ZERO;
                let (g0, part) = (bounds[r], pb[r]..pb[r + 1]);
                let Scratch { touching, sep, released, worst, cross_out, wall_out, wall_first, busy } = sc;
                // If this thread panics before it publishes, the others must not wait for it.
                let _guard = (Publish(&published[r]), Publish(&published_walls[r]));
                // (1) Our cross pairs first, as the serial stage does its pairs: sort out the
                // touching and released ones, then the touching ones four at a time.
                let slots = &cross[cb[r]..cb[r + 1]];
                let (nt, nr) = sort_listed(&view, pairs, reach, active, part.start, slots, touching, sep, released);
                cross_out.clear();
                cross_out.resize(slots.len(), PairOut::default());
                {
                    let list = PairSlices::<T, Rr> { pairs: checked.part(part.clone()), consts: &consts[part.clone()], hist: &mut *hist, energy: &mut *energy, active: &mut *active };
                    // Touching pairs come in list order, as the slots are.
                    let mut slot = 0;
                    let sink = |k: usize, _, o: PairOut| {
                        while slots[slot] as usize != part.start + k {
                            slot += 1;
                        }
                        cross_out[slot] = o;
                    };
                    compute_pairs::<N, Dm, T, C, Rr, Plane, ENERGY, SPIN>(&view, list, &touching[..nt], &sep[..nt], &released[..nr], sink);
                }
                let own_cross: &[PairOut] = cross_out;
                let _ = published[r].set(own_cross);
                // (2) Sort out the rest of our part.
                let (nt, nr) = sort_pairs(&view.p.x, &view.boundary, checked.part(part.clone()), &reach[part.clone()], active, &cross_in_part[cb[r]..cb[r + 1]], touching, sep, released);
                // (3) The cross pairs into our grains from earlier ranges: they are first in
                // each of those grains' sequences.
                for &s in &incoming[r] {
                    let s = s as usize;
                    // The thread whose cross pairs hold slot s.
                    let from = range_of(s, cb);
                    let o = &wait(&published[from], &mut waited)[s - cb[from]];
                    if o.ratio > 0.0 {
                        let g = pairs[cross[s] as usize][1] as usize - g0;
                        fl[g] -= o.force;
                        if T::FRICTION && SPIN {
                            tl[g] -= o.torque[1];
                        }
                    }
                }
                // (4) Our pairs, each force to its grains as the kernel hands it over; a rough
                // wall's grain belongs to the first thread, so the others keep what they do
                // to one for it, in list order.
                let list = PairSlices::<T, Rr> { pairs: checked.part(part.clone()), consts: &consts[part.clone()], hist, energy, active };
                wall_out.clear();
                wall_first.clear();
                let mut add = |(i, j): (usize, usize), o: &PairOut, own: bool| {
                    if own && j >= n_free {
                        // Its first grain's share after the cross pairs, below.
                        wall_first.push((i as u32, *o));
                    } else {
                        fl[i - g0] += o.force;
                        if T::FRICTION && SPIN {
                            tl[i - g0] -= o.torque[0];
                        }
                    }
                    if own {
                        if j < n_free {
                            fl[j - g0] -= o.force;
                            if T::FRICTION && SPIN {
                                tl[j - g0] -= o.torque[1];
                            }
                        } else {
                            to_wall(T::FRICTION && SPIN, &mut walls, wall_out, WallOut { grain: (j - n_free) as u32, force: o.force, torque: o.torque[1] });
                        }
                    }
                };
                let sink = |_, ij: (usize, usize), o: PairOut| add(ij, &o, true);
                let (ratio, kk) = compute_pairs::<N, Dm, T, C, Rr, Plane, ENERGY, SPIN>(&view, list, &touching[..nt], &sep[..nt], &released[..nr], sink);
                let mut best = if kk == usize::MAX { (0.0, usize::MAX) } else { (ratio, part.start + kk) };
                // (5) Our cross pairs' forces on our grains: a grain's pairs (g, j) with j in
                // a later range are the last of its sequence.
                for (&k, oc) in slots.iter().zip(own_cross) {
                    let k = k as usize;
                    if oc.ratio > 0.0 {
                        add((pairs[k][0] as usize, pairs[k][1] as usize), oc, false);
                        if oc.ratio > best.0 || (oc.ratio == best.0 && k < best.1) {
                            best = (oc.ratio, k);
                        }
                    }
                }
                // ... and after them its pairs with the rough walls' grains, which have the
                // largest indices of all: the end of its sequence.
                for &(i, o) in wall_first.iter() {
                    fl[i as usize - g0] += o.force;
                    if T::FRICTION && SPIN {
                        tl[i as usize - g0] -= o.torque[0];
                    }
                }
                let _ = published_walls[r].set(wall_out);
                // (6) The first thread: what the later ranges' pairs did to the rough walls'
                // grains, after its own (their pairs come later in the list).
                if let Some((fw, tw)) = &mut walls {
                    for from in &published_walls[1..] {
                        for o in wait(from, &mut waited) {
                            o.onto(fw, tw, T::FRICTION && SPIN);
                        }
                    }
                }
                *worst = best;
                *busy += start.elapsed().saturating_sub(waited);
            });
        }
        w.p.f = f;
        w.p.torque = torque;
        // The largest overlap as the serial loop picks it (the first of equal maxima). (The
        // energy terms are in each pair's sums: no order to restore.)
        let mut best = (0.0, usize::MAX);
        for &(ratio, k) in self.scratch.iter().map(|s| &s.worst) {
            if k != usize::MAX && (ratio > best.0 || (ratio == best.0 && k < best.1)) {
                best = (ratio, k);
            }
        }
        if best.1 != usize::MAX && best.0 > w.max_overlap.0 {
            let p = w.pairs.pairs[best.1];
            w.max_overlap = (best.0, p[0] as usize, p[1] as usize);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cut_gives_each_range_its_share_of_the_cost() {
        // Ten grains of cost 1 and one of cost 10 (20 in all): 30% is 6, reached with
        // grain 5; a quarter is 5, reached with grain 4; half is 10, reached with grain 9.
        let cost = [1, 1, 1, 1, 1, 1, 1, 1, 1, 10, 1];
        assert_eq!(balanced(&cost, &[0.3, 0.7]), vec![0, 6, 11]);
        assert_eq!(balanced(&cost, &[0.5, 0.5]), vec![0, 10, 11]);
        assert_eq!(balanced(&cost, &[0.25, 0.25, 0.5]), vec![0, 5, 10, 11]);
    }

    #[test]
    fn the_slower_thread_gets_less_cost_next_time() {
        let ms = Duration::from_millis;
        // Equal modelled cost, the second thread 10% slower: the shares go as the rates,
        // 1 : 1/1.1.
        let s = rebalanced(&[0.5, 0.5], &[1000, 1000], &[ms(100), ms(110)]);
        approx::assert_relative_eq!(s[0], 1.1 / 2.1, max_relative = 1e-12);
        approx::assert_relative_eq!(s[0] + s[1], 1.0, max_relative = 1e-12);
        // Equal times: the shares stay.
        let s = rebalanced(&[0.6, 0.4], &[1200, 800], &[ms(50), ms(50)]);
        approx::assert_relative_eq!(s[0], 0.6, max_relative = 1e-12);
        // A thread ten times slower (descheduled): a share rises by at most a quarter and
        // falls by at most a fifth (0.5 to 0.625 and 0.4, then scaled to add up to 1).
        let s = rebalanced(&[0.5, 0.5], &[1000, 1000], &[ms(10), ms(100)]);
        approx::assert_relative_eq!(s[0], 0.625 / 1.025, max_relative = 1e-12);
        // No timing yet: the shares stay.
        assert_eq!(rebalanced(&[0.5, 0.5], &[1000, 1000], &[ms(0), ms(100)]), vec![0.5, 0.5]);
    }
}
