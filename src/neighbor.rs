//! Neighbours: a cell list builds a Verlet list with a skin; contact history survives
//! every rebuild.
//!
//! A pair (i < j) is listed when its gap is below the skin: `|x_i - x_j| < r_i + r_j +
//! skin` (minimum image in x when periodic). The list stays valid until some grain has
//! moved more than half the skin since the build. Pairs of two wall grains are never
//! listed. The list is sorted, so the histories of the old list are carried over to the
//! new one with one merge.

use crate::boundary::Boundary;
use crate::contact::ContactHistory;
use crate::dim::Vec2;

/// The Verlet list and the history of each listed pair.
#[derive(Clone, Debug, Default)]
pub struct PairList<H> {
    /// Listed pairs, i < j, sorted.
    pub pairs: Vec<[u32; 2]>,
    /// What each pair's kernel would otherwise divide out at every step, parallel to `pairs`.
    pub consts: Vec<PairConst>,
    /// History of each pair, parallel to `pairs`.
    pub hist: Vec<ContactHistory<H>>,
}

/// The constants of a listed pair, computed once per neighbour-list build.
#[derive(Clone, Copy, Debug, Default)]
pub struct PairConst {
    /// Reduced radius R* = r_i r_j / (r_i + r_j), m.
    pub r_star: f64,
    /// Reduced mass m* = m_i m_j / (m_i + m_j), kg.
    pub m_star: f64,
    /// 1 / min(r_i, r_j), 1/m (overlap ratio for the watchdog).
    pub inv_r_min: f64,
}

impl<H: Copy + Default> PairList<H> {
    /// Replace the pairs, keeping the history of every pair that stays listed, and
    /// compute their constants from the radii `r` and masses `m`.
    pub fn replace(&mut self, new_pairs: Vec<[u32; 2]>, r: &[f64], m: &[f64]) {
        self.consts.clear();
        self.consts.extend(new_pairs.iter().map(|&[i, j]| {
            let (i, j) = (i as usize, j as usize);
            PairConst { r_star: crate::material::reduced(r[i], r[j]), m_star: crate::material::reduced(m[i], m[j]), inv_r_min: 1.0 / r[i].min(r[j]) }
        }));
        let mut hist = vec![ContactHistory::default(); new_pairs.len()];
        let mut k = 0;
        for (slot, p) in hist.iter_mut().zip(&new_pairs) {
            while k < self.pairs.len() && self.pairs[k] < *p {
                k += 1;
            }
            if k < self.pairs.len() && self.pairs[k] == *p {
                *slot = self.hist[k];
            }
        }
        self.pairs = new_pairs;
        self.hist = hist;
    }
    /// Number of pairs currently touching (active history).
    pub fn touching(&self) -> usize {
        self.hist.iter().filter(|h| h.active).count()
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
}

impl Neighbours {
    pub fn new(skin: f64) -> Self {
        Neighbours { skin, x_at_build: Vec::new(), builds: 0, cell_start: Vec::new(), cell_items: Vec::new() }
    }

    /// True when some grain has moved more than half the skin since the last build.
    /// A full sweep without an early exit, so that it vectorises.
    pub fn needs_rebuild(&self, x: &[Vec2], boundary: &Boundary, threads: &crate::threads::Threads) -> bool {
        if self.x_at_build.len() != x.len() {
            return true;
        }
        let limit = 0.25 * self.skin * self.skin;
        let moved = std::sync::atomic::AtomicBool::new(false);
        threads.split(x.len(), (x, &self.x_at_build[..]), |(x, at_build)| {
            let far = x.iter().zip(at_build).fold(false, |far, (a, b)| far | (boundary.image(a - b).norm_squared() > limit));
            if far {
                moved.store(true, std::sync::atomic::Ordering::Relaxed);
            }
        });
        moved.into_inner()
    }

    /// Build the pair list with the cell list.
    pub fn build(&mut self, x: &[Vec2], r: &[f64], n_free: usize, boundary: &Boundary) -> Vec<[u32; 2]> {
        self.builds += 1;
        self.x_at_build.clear();
        self.x_at_build.extend_from_slice(x);
        cell_pairs(x, r, n_free, boundary, self.skin, &mut self.cell_start, &mut self.cell_items)
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

/// All pairs closer than the skin, with a cell list. Sorted, i < j.
pub fn cell_pairs(
    x: &[Vec2],
    r: &[f64],
    n_free: usize,
    boundary: &Boundary,
    skin: f64,
    cell_start: &mut Vec<u32>,
    cell_items: &mut Vec<u32>,
) -> Vec<[u32; 2]> {
    let n = x.len();
    if n < 2 {
        return Vec::new();
    }
    let r_max = r.iter().cloned().fold(0.0, f64::max);
    let cell = 2.0 * r_max + skin;
    let (mut lo, mut hi) = (Vec2::repeat(f64::INFINITY), Vec2::repeat(f64::NEG_INFINITY));
    for p in x {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let periodic = boundary.is_periodic();
    let (x0, lx) = if periodic { (boundary.x_min, boundary.period) } else { (lo.x, (hi.x - lo.x).max(cell)) };
    let ly = (hi.y - lo.y).max(cell);
    let mut nx = ((lx / cell).floor() as usize).max(1);
    if periodic && nx < 3 {
        nx = 1;
    }
    let ny = ((ly / cell).floor() as usize).max(1);
    // Keep the grid modest for sparse systems (a few grains far apart).
    let max_cells = 4 * n + 64;
    let (nx, ny) = if nx * ny > max_cells {
        let s = ((nx * ny) as f64 / max_cells as f64).sqrt().ceil() as usize;
        let nx2 = (nx / s).max(1);
        (if periodic && nx2 < 3 { 1 } else { nx2 }, (ny / s).max(1))
    } else {
        (nx, ny)
    };
    let (wx, wy) = (lx / nx as f64, ly / ny as f64);
    let cell_of = |p: &Vec2| -> usize {
        let mut xr = p.x - x0;
        if periodic {
            xr -= lx * (xr / lx).floor();
        }
        let cx = ((xr / wx) as usize).min(nx - 1);
        let cy = (((p.y - lo.y) / wy).max(0.0) as usize).min(ny - 1);
        cy * nx + cx
    };
    // Counting sort of grains into cells.
    let ncell = nx * ny;
    cell_start.clear();
    cell_start.resize(ncell + 1, 0);
    let cells: Vec<u32> = x.iter().map(|p| cell_of(p) as u32).collect();
    for &c in &cells {
        cell_start[c as usize + 1] += 1;
    }
    for c in 0..ncell {
        cell_start[c + 1] += cell_start[c];
    }
    cell_items.clear();
    cell_items.resize(n, 0);
    let mut fill = cell_start[..ncell].to_vec();
    for (i, &c) in cells.iter().enumerate() {
        cell_items[fill[c as usize] as usize] = i as u32;
        fill[c as usize] += 1;
    }
    // Half stencil: the cell itself, then right, upper-left, up, upper-right.
    let stencil: &[(isize, isize)] = if nx == 1 { &[(0, 1)] } else { &[(1, 0), (-1, 1), (0, 1), (1, 1)] };
    let mut out = Vec::new();
    let push = |i: u32, j: u32, out: &mut Vec<[u32; 2]>| {
        let (a, b) = if i < j { (i, j) } else { (j, i) };
        if (a as usize) >= n_free && (b as usize) >= n_free {
            return;
        }
        if listed(boundary.image(x[a as usize] - x[b as usize]), r[a as usize], r[b as usize], skin) {
            out.push([a, b]);
        }
    };
    for cy in 0..ny {
        for cx in 0..nx {
            let c = cy * nx + cx;
            let own = &cell_items[cell_start[c] as usize..cell_start[c + 1] as usize];
            for (k, &i) in own.iter().enumerate() {
                for &j in &own[k + 1..] {
                    push(i, j, &mut out);
                }
            }
            for &(ox, oy) in stencil {
                let ny2 = cy as isize + oy;
                if ny2 < 0 || ny2 >= ny as isize {
                    continue;
                }
                let mut nx2 = cx as isize + ox;
                if nx2 < 0 || nx2 >= nx as isize {
                    if !periodic {
                        continue;
                    }
                    nx2 = nx2.rem_euclid(nx as isize);
                }
                let d = ny2 as usize * nx + nx2 as usize;
                let other = &cell_items[cell_start[d] as usize..cell_start[d + 1] as usize];
                for &i in own {
                    for &j in other {
                        push(i, j, &mut out);
                    }
                }
            }
        }
    }
    out.sort_unstable();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn history_survives_a_rebuild_and_leaves_with_its_pair() {
        let mut list: PairList<f64> = PairList::default();
        let (r, m) = (vec![1.0; 5], vec![1.0; 5]);
        list.replace(vec![[0, 1], [0, 2], [3, 4]], &r, &m);
        for (k, h) in list.hist.iter_mut().enumerate() {
            h.tangential = k as f64 + 1.0;
            h.active = true;
        }
        // [0, 2] leaves, [1, 2] and [2, 3] arrive, the others stay.
        list.replace(vec![[0, 1], [1, 2], [2, 3], [3, 4]], &r, &m);
        assert_eq!(list.consts.len(), 4);
        assert_eq!(list.consts[1].r_star, 0.5);
        let kept: Vec<f64> = list.hist.iter().map(|h| h.tangential).collect();
        assert_eq!(kept, vec![1.0, 0.0, 0.0, 3.0]);
        assert_eq!(list.touching(), 2);
    }
}
