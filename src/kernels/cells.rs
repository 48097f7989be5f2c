//! Cell lists: which grains are near which, from their positions alone. A grid of cells
//! at least one contact reach wide (dense, or sorted by cell when the grains are far
//! apart), the pair search over it (listed when the gap is below the skin, minimum image
//! in x when periodic, never two wall grains), and the largest overlap. Uses physics.

use crate::kernels::threads::Threads;
use crate::physics::boundary::Boundary;
use crate::physics::dim::Vec2;

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

/// The overlapping pairs (not both wall grains) of a state: their mean overlap over the
/// pair's mean radius, `mean(dn / ((r_i + r_j) / 2))`, and their count; `None` when no
/// pair overlaps. The price of soft grains in a packing (about the inverse of the
/// stiffness number under a confining stress).
pub fn mean_overlap(x: &[Vec2], r: &[f64], n_free: usize, boundary: &Boundary) -> Option<(f64, usize)> {
    if x.len() < 2 {
        return None;
    }
    let (mut cs, mut ci) = (Vec::new(), Vec::new());
    let cells = CellList::new(x, r, boundary, 0.0, &mut cs, &mut ci);
    let (mut sum, mut count) = (0.0, 0usize);
    for i in 0..x.len() {
        cells.candidates(i, |j| {
            if j > i && (i < n_free || j < n_free) {
                let dn = r[i] + r[j] - boundary.image(x[i] - x[j]).norm();
                if dn > 0.0 {
                    sum += dn / (0.5 * (r[i] + r[j]));
                    count += 1;
                }
            }
            true
        });
    }
    (count > 0).then(|| (sum / count as f64, count))
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
