//! Neighbours: a cell list builds a Verlet list with a skin; contact history survives
//! every rebuild.
//!
//! A pair (i < j) is listed when its gap is below the skin: `|x_i - x_j| < r_i + r_j +
//! skin` (minimum image in x when periodic). The list stays valid until some grain has
//! moved more than half the skin since the build. Pairs of two wall grains are never
//! listed. The list is sorted, so the histories of the old list are carried over to the
//! new one with one merge.

use crate::boundary::Boundary;
use crate::contact::EnergyMemory;
use crate::dim::Vec2;
use crate::threads::Threads;

/// The Verlet list and the history of each listed pair.
#[derive(Clone, Debug, Default)]
pub struct PairList<H> {
    /// Listed pairs, i < j, sorted (set by [`PairList::replace`] only).
    pub pairs: Pairs,
    /// What each pair's kernel would otherwise divide out at every step, parallel to `pairs`.
    pub consts: Vec<PairConst>,
    /// `(r_i + r_j)^2` of each pair, m^2, parallel to `pairs`: the pair touches when its
    /// distance squared is below (the contact sweep reads only this, the positions and
    /// `active`).
    pub reach: Vec<f64>,
    /// Tangential state of each pair, parallel to `pairs`.
    pub hist: Vec<H>,
    /// Energy memory of each pair, parallel to `pairs` when `keep_energy`, else empty.
    pub energy: Vec<EnergyMemory>,
    /// True while the pair is (or was at the previous step) touching, parallel to `pairs`.
    pub active: Vec<bool>,
    /// Keep the energy memory (the run has the energy ledger on).
    pub keep_energy: bool,
    /// The arrays of the list before the last rebuild, kept for the next one to fill:
    /// new arrays at every rebuild cost their page faults again (a quarter of the
    /// rebuild's time at 20 000 grains).
    pub(crate) spare: Spare<H>,
}

/// Spare per-pair arrays ([`PairList::replace`] swaps them with the list's).
#[derive(Clone, Debug, Default)]
pub(crate) struct Spare<H> {
    hist: Vec<H>,
    active: Vec<bool>,
    energy: Vec<EnergyMemory>,
}

/// The constants of a listed pair, computed once per neighbour-list build.
#[derive(Clone, Copy, Debug, Default)]
pub struct PairConst {
    /// Reduced radius R* = r_i r_j / (r_i + r_j), m.
    pub r_star: f64,
    /// Square root of the reduced mass m* = m_i m_j / (m_i + m_j), kg^1/2.
    pub sqrt_m_star: f64,
    /// 1 / min(r_i, r_j), 1/m (overlap ratio for the watchdog).
    pub inv_r_min: f64,
}

impl<H: Copy + Default + Send + Sync> PairList<H> {
    /// Replace the pairs, keeping the history of every pair that stays listed, and
    /// compute their constants from the radii `r` and masses `m`; on `threads`, each
    /// taking a stretch of the new list (the old list is sorted too, so a stretch finds
    /// where its histories start by bisection and merges from there).
    pub fn replace(&mut self, new_pairs: Vec<[u32; 2]>, r: &[f64], m: &[f64], threads: &Threads) {
        let np = new_pairs.len();
        self.consts.resize(np, PairConst::default());
        self.reach.resize(np, 0.0);
        // Every entry is written below (kept or not).
        let Spare { mut hist, mut active, mut energy } = std::mem::take(&mut self.spare);
        hist.resize(np, H::default());
        active.resize(np, false);
        energy.resize(if self.keep_energy { np } else { 0 }, EnergyMemory::default());
        let old = Carried { pairs: &self.pairs.list, hist: &self.hist, active: &self.active, energy: &self.energy };
        let new_part = (&new_pairs[..], &mut self.consts[..], &mut self.reach[..]);
        if self.keep_energy {
            threads.split(np, (new_part, (&mut hist[..], &mut active[..], &mut energy[..])), |((new, consts, reach), (hist, active, energy))| {
                constants(new, consts, reach, r, m);
                old.carry(new, hist, active, Some(energy));
            });
        } else {
            threads.split(np, (new_part, (&mut hist[..], &mut active[..])), |((new, consts, reach), (hist, active))| {
                constants(new, consts, reach, r, m);
                old.carry(new, hist, active, None);
            });
        }
        self.pairs = Pairs { top: new_pairs.iter().fold(0, |t, p| t.max(p[0].max(p[1]) as usize + 1)), list: new_pairs };
        self.spare = Spare { hist: std::mem::replace(&mut self.hist, hist), active: std::mem::replace(&mut self.active, active), energy: std::mem::replace(&mut self.energy, energy) };
    }
    /// Number of pairs currently touching (active history).
    pub fn touching(&self) -> usize {
        self.active.iter().filter(|&&a| a).count()
    }
}

/// The constants and reach of pairs `new` (radii `r`, masses `m`).
fn constants(new: &[[u32; 2]], consts: &mut [PairConst], reach: &mut [f64], r: &[f64], m: &[f64]) {
    for ((&[i, j], c), re) in new.iter().zip(consts).zip(reach) {
        let (i, j) = (i as usize, j as usize);
        *c = PairConst { r_star: crate::material::reduced(r[i], r[j]), sqrt_m_star: crate::material::reduced(m[i], m[j]).sqrt(), inv_r_min: 1.0 / r[i].min(r[j]) };
        let radsum = r[i] + r[j];
        *re = radsum * radsum;
    }
}

/// What the old list carries over to the new one: its pairs (sorted) and their states.
struct Carried<'a, H> {
    pairs: &'a [[u32; 2]],
    hist: &'a [H],
    active: &'a [bool],
    /// Empty without the energy ledger.
    energy: &'a [EnergyMemory],
}

impl<H: Copy + Default> Carried<'_, H> {
    /// The states of the pairs of the sorted stretch `new`: those listed before keep
    /// theirs, the others start afresh (every entry is written).
    fn carry(&self, new: &[[u32; 2]], hist: &mut [H], active: &mut [bool], mut energy: Option<&mut [EnergyMemory]>) {
        let old = self.pairs;
        let mut k = new.first().map_or(0, |first| old.partition_point(|p| p < first));
        for (m, p) in new.iter().enumerate() {
            while k < old.len() && old[k] < *p {
                k += 1;
            }
            let kept = k < old.len() && old[k] == *p;
            hist[m] = if kept { self.hist[k] } else { H::default() };
            active[m] = kept && self.active[k];
            if let Some(e) = energy.as_deref_mut() {
                e[m] = if kept { self.energy[k] } else { EnergyMemory::default() };
            }
        }
    }
}

/// The pairs of a [`PairList`] (read as a slice) and their largest grain index.
#[derive(Clone, Debug, Default)]
pub struct Pairs {
    list: Vec<[u32; 2]>,
    /// One more than the largest grain index in `list` (0 if none).
    top: usize,
}

impl std::ops::Deref for Pairs {
    type Target = [[u32; 2]];
    fn deref(&self) -> &[[u32; 2]] {
        &self.list
    }
}

impl Pairs {
    /// The pairs with what the list knows of them: every grain index is below `top`.
    pub fn checked(&self) -> CheckedPairs<'_> {
        CheckedPairs { pairs: &self.list, top: self.top }
    }
}

/// A pair list (or a part of one) whose largest grain index is known, so that
/// per-grain arrays can be read at its pairs' grains without a bounds check per read:
/// the contact sweep and kernel read up to eight grain values per pair, and a check
/// costs a compare and a branch each (about 7% of the sweep's instructions).
#[derive(Clone, Copy, Debug)]
pub struct CheckedPairs<'a> {
    pairs: &'a [[u32; 2]],
    top: usize,
}

impl<'a> CheckedPairs<'a> {
    /// The pairs.
    #[inline(always)]
    pub fn pairs(self) -> &'a [[u32; 2]] {
        self.pairs
    }
    #[inline(always)]
    pub fn len(self) -> usize {
        self.pairs.len()
    }
    #[inline(always)]
    pub fn is_empty(self) -> bool {
        self.pairs.is_empty()
    }
    /// A part of the list.
    #[inline(always)]
    pub fn part(self, range: std::ops::Range<usize>) -> Self {
        CheckedPairs { pairs: &self.pairs[range], top: self.top }
    }
    /// A per-grain array, to read at the pairs' grains; it must cover every grain of the
    /// list (panics otherwise).
    #[inline(always)]
    pub fn of<T: Copy>(self, a: &'a [T]) -> GrainValues<'a, T> {
        assert!(a.len() >= self.top, "per-grain array of {} for grain indices up to {}", a.len(), self.top);
        GrainValues { pairs: self.pairs, a }
    }
}

/// A per-grain array read at the grains of a [`CheckedPairs`] list.
#[derive(Clone, Copy, Debug)]
pub struct GrainValues<'a, T> {
    pairs: &'a [[u32; 2]],
    a: &'a [T],
}

impl<T: Copy> GrainValues<'_, T> {
    /// The values of the two grains of pair `k`.
    #[inline(always)]
    pub fn at(self, k: usize) -> (T, T) {
        self.of_pair(self.pairs[k])
    }
    /// The values of the two grains of each of the four pairs from `k` on (one bounds
    /// check for the four).
    #[inline(always)]
    pub fn four(self, k: usize) -> [(T, T); 4] {
        let q: &[[u32; 2]; 4] = self.pairs[k..k + 4].try_into().expect("four pairs");
        std::array::from_fn(|l| self.of_pair(q[l]))
    }
    /// The start of the per-grain array: every grain index of the list's pairs is an
    /// offset within it (for code that reads several grains with one instruction).
    #[inline(always)]
    pub fn as_ptr(self) -> *const T {
        self.a.as_ptr()
    }
    #[inline(always)]
    fn of_pair(self, [i, j]: [u32; 2]) -> (T, T) {
        // SAFETY: the pair is one of the list's, whose grain indices are all below `top`
        // (PairList::replace), and `a` is at least `top` long (CheckedPairs::of).
        unsafe { (*self.a.get_unchecked(i as usize), *self.a.get_unchecked(j as usize)) }
    }
}

/// Cell-list builder and the skin bookkeeping.
#[derive(Clone, Debug)]
pub struct Neighbours {
    /// Skin, m.
    pub skin: f64,
    /// Positions at the last build.
    x_at_build: Vec<Vec2>,
    /// Number of builds so far.
    pub builds: u64,
    cell_start: Vec<u32>,
    cell_items: Vec<u32>,
    /// Set by the stages that move grains (the drift, the walls) when one of them has
    /// moved more than half the skin since the last build; cleared by the build.
    pub moved_far: bool,
}

impl Neighbours {
    pub fn new(skin: f64) -> Self {
        Neighbours { skin, x_at_build: Vec::new(), builds: 0, cell_start: Vec::new(), cell_items: Vec::new(), moved_far: false }
    }

    /// Half the skin, squared: a grain that has moved this far (squared) since the last
    /// build may have a new neighbour, m^2.
    pub fn limit(&self) -> f64 {
        0.25 * self.skin * self.skin
    }

    /// Positions at the last build (empty before the first).
    pub fn at_build(&self) -> &[Vec2] {
        &self.x_at_build
    }

    /// True when one of the grains at `x` has moved more than half the skin from `at`
    /// (its position at the last build). A full sweep without an early exit, so that it
    /// vectorises; the stages that move grains call it on what they moved.
    #[inline(always)]
    pub fn moved(x: &[Vec2], at: &[Vec2], boundary: &Boundary, limit: f64) -> bool {
        x.iter().zip(at).fold(false, |far, (a, b)| far | (boundary.image(a - b).norm_squared() > limit))
    }

    /// True when the list must be rebuilt: there is none for these `n` grains yet, or a
    /// grain has moved more than half the skin ([`Neighbours::moved_far`]).
    pub fn needs_rebuild(&self, n: usize) -> bool {
        self.x_at_build.len() != n || self.moved_far
    }

    /// Build the pair list with the cell list.
    pub fn build(&mut self, x: &[Vec2], r: &[f64], n_free: usize, boundary: &Boundary, threads: &Threads) -> Vec<[u32; 2]> {
        self.builds += 1;
        self.moved_far = false;
        self.x_at_build.clear();
        self.x_at_build.extend_from_slice(x);
        cell_pairs(x, r, n_free, boundary, self.skin, &mut self.cell_start, &mut self.cell_items, threads)
    }
}

#[inline(always)]
fn listed(d: Vec2, ri: f64, rj: f64, skin: f64) -> bool {
    let c = ri + rj + skin;
    d.norm_squared() < c * c
}

/// All pairs closer than the skin, by brute force (for tests and tiny systems).
pub fn brute_force_pairs(x: &[Vec2], r: &[f64], n_free: usize, boundary: &Boundary, skin: f64) -> Vec<[u32; 2]> {
    let mut out = Vec::new();
    for i in 0..x.len() {
        for j in i + 1..x.len() {
            if i >= n_free && j >= n_free {
                continue;
            }
            if listed(boundary.image(x[i] - x[j]), r[i], r[j], skin) {
                out.push([i as u32, j as u32]);
            }
        }
    }
    out
}

/// Counting sort of grains into cells: grain i is in cell `cells[i]` (of `ncell`); the
/// grains of cell c are `cell_items[cell_start[c]..cell_start[c + 1]]`, in index order.
pub fn bin_into_cells(cells: &[u32], ncell: usize, cell_start: &mut Vec<u32>, cell_items: &mut Vec<u32>) {
    cell_start.clear();
    cell_start.resize(ncell + 1, 0);
    for &c in cells {
        cell_start[c as usize + 1] += 1;
    }
    for c in 0..ncell {
        cell_start[c + 1] += cell_start[c];
    }
    cell_items.clear();
    cell_items.resize(cells.len(), 0);
    let mut fill = cell_start[..ncell].to_vec();
    for (i, &c) in cells.iter().enumerate() {
        cell_items[fill[c as usize] as usize] = i as u32;
        fill[c as usize] += 1;
    }
}

/// All pairs closer than the skin, with a cell list. Sorted, i < j. Each of `threads`
/// lists the pairs (i, j > i) of its own grains i, already in order, so the parts join
/// into the sorted list with no sort.
#[allow(clippy::too_many_arguments)]
pub fn cell_pairs(
    x: &[Vec2],
    r: &[f64],
    n_free: usize,
    boundary: &Boundary,
    skin: f64,
    cell_start: &mut Vec<u32>,
    cell_items: &mut Vec<u32>,
    threads: &Threads,
) -> Vec<[u32; 2]> {
    let n = x.len();
    if n < 2 {
        return Vec::new();
    }
    let cells = CellList::new(x, r, boundary, skin, cell_start, cell_items);
    // Each grain with the grains of higher index in its cell and the eight around it.
    let pairs_of = |i: usize, out: &mut Vec<[u32; 2]>| {
        let start = out.len();
        cells.candidates(i, |j| {
            if j > i && (i < n_free || j < n_free) && listed(boundary.image(x[i] - x[j]), r[i], r[j], skin) {
                out.push([i as u32, j as u32]);
            }
            true
        });
        out[start..].sort_unstable();
    };
    let bounds = threads.bounds(n);
    let mut parts: Vec<Vec<[u32; 2]>> = (0..threads.count()).map(|_| Vec::new()).collect();
    threads.each(parts.iter_mut().collect(), |t, out: &mut Vec<[u32; 2]>| {
        out.reserve(3 * (bounds[t + 1] - bounds[t]));
        for i in bounds[t]..bounds[t + 1] {
            pairs_of(i, out);
        }
    });
    if parts.len() == 1 {
        return parts.pop().unwrap_or_default();
    }
    parts.concat()
}

/// The pair (i < j, not both wall grains) whose overlap is the largest fraction of the
/// smaller radius, with that fraction: `None` when no pair overlaps. Stops at the first
/// pair above `stop` (a scene's grains may all sit at one point: listing the
/// overlapping pairs could take n^2 memory, this never takes more than the cell list).
pub fn largest_overlap(x: &[Vec2], r: &[f64], n_free: usize, boundary: &Boundary, stop: f64) -> Option<(usize, usize, f64)> {
    if x.len() < 2 {
        return None;
    }
    let (mut cs, mut ci) = (Vec::new(), Vec::new());
    let cells = CellList::new(x, r, boundary, 0.0, &mut cs, &mut ci);
    let mut worst: Option<(usize, usize, f64)> = None;
    for i in 0..x.len() {
        let mut go_on = true;
        cells.candidates(i, |j| {
            if j > i && (i < n_free || j < n_free) {
                let ratio = (r[i] + r[j] - boundary.image(x[i] - x[j]).norm()) / r[i].min(r[j]);
                if ratio > 0.0 && worst.is_none_or(|w| ratio > w.2) {
                    worst = Some((i, j, ratio));
                    go_on = ratio <= stop;
                }
            }
            go_on
        });
        if !go_on {
            break;
        }
    }
    worst
}

/// A cell list: square-ish cells at least one contact reach (`2 r_max + skin`) wide over
/// the grains' bounding box, so that a grain's partners are in its cell or the eight
/// around it. Dense (a counting sort into a grid) when the grid has no more cells than a
/// few per grain, which a packing always has; sparse (the grains sorted by cell, cells
/// found by bisection) when the grains are spread far apart, so that neither memory nor
/// time depends on how far apart they are.
struct CellList<'a> {
    periodic: bool,
    /// Columns and rows of the grid (each up to 2^31 in the sparse case).
    nx: u64,
    ny: u64,
    kind: Cells<'a>,
}

enum Cells<'a> {
    /// The cell of each grain (`cy * nx + cx`); the grains of cell c are
    /// `items[start[c]..start[c + 1]]`.
    Dense { cell: Vec<u32>, start: &'a [u32], items: &'a [u32] },
    /// The cell of each grain, the cells of the grains sorted by cell (`keys`) and the
    /// grains in that order (`items`).
    Sparse { cell: Vec<u64>, keys: Vec<u64>, items: Vec<u32> },
}

/// Most cells of a dense grid for `n` grains.
fn max_dense_cells(n: usize) -> f64 {
    (4 * n + 64) as f64
}

/// Most columns or rows a grid counts (2^31): grains beyond share the edge cells.
const MAX_CELLS_PER_AXIS: f64 = 2147483648.0;

/// How many cells at least `reach` wide fit along a length `l`: at least one, counted in
/// floating point (the count for a far-flung set of grains fits no integer), at most
/// [`MAX_CELLS_PER_AXIS`].
pub(crate) fn cells_along(l: f64, reach: f64) -> f64 {
    let c = (l / reach).floor();
    if c.is_finite() { c.clamp(1.0, MAX_CELLS_PER_AXIS) } else { MAX_CELLS_PER_AXIS }
}

impl<'a> CellList<'a> {
    fn new(x: &[Vec2], r: &[f64], boundary: &Boundary, skin: f64, cell_start: &'a mut Vec<u32>, cell_items: &'a mut Vec<u32>) -> Self {
        let n = x.len();
        let r_max = r.iter().cloned().fold(0.0, f64::max);
        let reach = 2.0 * r_max + skin;
        let (mut lo, mut hi) = (Vec2::repeat(f64::INFINITY), Vec2::repeat(f64::NEG_INFINITY));
        for p in x {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let periodic = boundary.is_periodic();
        let (x0, lx) = if periodic { (boundary.x_min, boundary.period) } else { (lo.x, (hi.x - lo.x).max(reach)) };
        let ly = (hi.y - lo.y).max(reach);
        let (mut fx, fy) = (cells_along(lx, reach), cells_along(ly, reach));
        // A periodic row of fewer than three cells would meet itself: one cell then.
        if periodic && fx < 3.0 {
            fx = 1.0;
        }
        let (nx, ny) = (fx as u64, fy as u64);
        let (wx, wy) = (lx / fx, ly / fy);
        let cell_of = |p: &Vec2| -> u64 {
            let mut xr = p.x - x0;
            if periodic {
                xr -= lx * (xr / lx).floor();
            }
            // `as` saturates (and takes NaN to 0): every grain gets a cell of the grid.
            let cx = ((xr / wx) as u64).min(nx - 1);
            let cy = (((p.y - lo.y) / wy).max(0.0) as u64).min(ny - 1);
            cy * nx + cx
        };
        let kind = if fx * fy <= max_dense_cells(n) {
            // The grid has at most 4n + 64 cells: each index fits a u32.
            let cell: Vec<u32> = x.iter().map(|p| cell_of(p) as u32).collect();
            bin_into_cells(&cell, (nx * ny) as usize, cell_start, cell_items);
            Cells::Dense { cell, start: &cell_start[..], items: &cell_items[..] }
        } else {
            let cell: Vec<u64> = x.iter().map(cell_of).collect();
            let mut items: Vec<u32> = (0..n as u32).collect();
            items.sort_unstable_by_key(|&i| (cell[i as usize], i));
            Cells::Sparse { keys: items.iter().map(|&i| cell[i as usize]).collect(), cell, items }
        };
        CellList { periodic, nx, ny, kind }
    }

    /// Call `visit` with each grain of grain i's cell and the eight around it (i
    /// included), each cell once, until it returns false.
    #[inline]
    fn candidates(&self, i: usize, visit: impl FnMut(usize) -> bool) {
        match &self.kind {
            Cells::Dense { cell, start, items } => self.around(cell[i] as u64, visit, |d| &items[start[d as usize] as usize..start[d as usize + 1] as usize]),
            Cells::Sparse { cell, keys, items } => self.around(cell[i], visit, |d| &items[keys.partition_point(|&key| key < d)..keys.partition_point(|&key| key <= d)]),
        }
    }

    /// [`CellList::candidates`] around cell `c`, with `grains(d)` the grains of cell d.
    #[inline(always)]
    fn around<'g>(&self, c: u64, mut visit: impl FnMut(usize) -> bool, grains: impl Fn(u64) -> &'g [u32]) {
        let (cx, cy) = ((c % self.nx) as i64, (c / self.nx) as i64);
        let (nx, ny) = (self.nx as i64, self.ny as i64);
        let mut around = [0u64; 9];
        let mut m = 0;
        for oy in -1..=1 {
            let y = cy + oy;
            if y < 0 || y >= ny {
                continue;
            }
            for ox in -1..=1 {
                let mut xx = cx + ox;
                if xx < 0 || xx >= nx {
                    if !self.periodic {
                        continue;
                    }
                    xx = xx.rem_euclid(nx);
                }
                around[m] = (y * nx + xx) as u64;
                m += 1;
            }
        }
        let around = &mut around[..m];
        around.sort_unstable();
        for (k, &d) in around.iter().enumerate() {
            if k > 0 && around[k - 1] == d {
                continue;
            }
            for &j in grains(d) {
                if !visit(j as usize) {
                    return;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn history_survives_a_rebuild_and_leaves_with_its_pair() {
        let mut list: PairList<f64> = PairList { keep_energy: true, ..Default::default() };
        let (r, m) = (vec![1.0; 5], vec![1.0; 5]);
        list.replace(vec![[0, 1], [0, 2], [3, 4]], &r, &m, &Threads::serial());
        for (k, h) in list.hist.iter_mut().enumerate() {
            *h = k as f64 + 1.0;
            list.energy[k].ut_prev = 10.0 * (k as f64 + 1.0);
            list.active[k] = true;
        }
        // [0, 2] leaves, [1, 2] and [2, 3] arrive, the others stay.
        list.replace(vec![[0, 1], [1, 2], [2, 3], [3, 4]], &r, &m, &Threads::serial());
        assert_eq!(list.consts.len(), 4);
        assert_eq!(list.consts[1].r_star, 0.5);
        let kept: Vec<f64> = list.hist.clone();
        assert_eq!(kept, vec![1.0, 0.0, 0.0, 3.0]);
        let kept: Vec<f64> = list.energy.iter().map(|e| e.ut_prev).collect();
        assert_eq!(kept, vec![10.0, 0.0, 0.0, 30.0]);
        assert_eq!(list.touching(), 2);
    }

    #[test]
    fn checked_pairs_read_grain_values_and_refuse_short_arrays() {
        let mut list: PairList<f64> = PairList::default();
        let (r, m) = (vec![1.0; 6], vec![1.0; 6]);
        list.replace(vec![[0, 4], [1, 2], [2, 3]], &r, &m, &Threads::serial());
        let values = [10.0, 11.0, 12.0, 13.0, 14.0, 15.0];
        let checked = list.pairs.checked();
        assert_eq!(checked.of(&values).at(0), (10.0, 14.0));
        assert_eq!(checked.part(1..3).of(&values).at(1), (12.0, 13.0));
        // Grain 4 is listed: an array of four grains must be refused, not read past.
        let short = std::panic::catch_unwind(|| checked.of(&values[..4]).at(0));
        assert!(short.is_err());
    }
}
