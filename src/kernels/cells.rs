//! Cell lists: which grains are near which, from their positions alone. A grid of cells
//! at least one contact reach wide (dense, or sorted by cell when the grains are far
//! apart), the pair search over it (listed when the gap is below the skin, minimum image
//! in x when periodic, and in z in space, never two wall grains), and the largest
//! overlap. Written once for the plane and space ([`Dim`]: a grid of rows and columns,
//! or of layers of them). Uses physics.

use crate::kernels::threads::Threads;
use crate::physics::boundary::Boundary;
use crate::physics::dim::Dim;

#[inline(always)]
fn listed<D: Dim>(d: D::Vector<f64>, ri: f64, rj: f64, skin: f64) -> bool {
    let c = ri + rj + skin;
    D::norm_squared(d) < c * c
}

/// All pairs closer than the skin, by brute force (for tests and tiny systems).
pub fn brute_force_pairs<D: Dim>(x: &[D::Vector<f64>], r: &[f64], n_free: usize, boundary: &Boundary<D>, skin: f64) -> Vec<[u32; 2]> {
    let mut out = Vec::new();
    for i in 0..x.len() {
        for j in i + 1..x.len() {
            if i >= n_free && j >= n_free {
                continue;
            }
            if listed::<D>(boundary.image(x[i] - x[j]), r[i], r[j], skin) {
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
pub fn cell_pairs<D: Dim>(
    x: &[D::Vector<f64>],
    r: &[f64],
    n_free: usize,
    boundary: &Boundary<D>,
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
    // Each grain with the grains of higher index in its cell and the 8 (26) around it.
    let pairs_of = |i: usize, out: &mut Vec<[u32; 2]>| {
        let start = out.len();
        cells.candidates(i, |j| {
            if j > i && (i < n_free || j < n_free) && listed::<D>(boundary.image(x[i] - x[j]), r[i], r[j], skin) {
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
pub fn largest_overlap<D: Dim>(x: &[D::Vector<f64>], r: &[f64], n_free: usize, boundary: &Boundary<D>, stop: f64) -> Option<(usize, usize, f64)> {
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
                let ratio = (r[i] + r[j] - D::norm(boundary.image(x[i] - x[j]))) / r[i].min(r[j]);
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
pub fn mean_overlap<D: Dim>(x: &[D::Vector<f64>], r: &[f64], n_free: usize, boundary: &Boundary<D>) -> Option<(f64, usize)> {
    if x.len() < 2 {
        return None;
    }
    let (mut cs, mut ci) = (Vec::new(), Vec::new());
    let cells = CellList::new(x, r, boundary, 0.0, &mut cs, &mut ci);
    let (mut sum, mut count) = (0.0, 0usize);
    for i in 0..x.len() {
        cells.candidates(i, |j| {
            if j > i && (i < n_free || j < n_free) {
                let dn = r[i] + r[j] - D::norm(boundary.image(x[i] - x[j]));
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

/// A cell list: square-ish (cube-ish) cells at least one contact reach (`2 r_max +
/// skin`) wide over the grains' bounding box, so that a grain's partners are in its cell
/// or the 8 (in space 26) around it. Dense (a counting sort into a grid) when the grid
/// has no more cells than a few per grain, which a packing always has; sparse (the
/// grains sorted by cell, cells found by bisection) when the grains are spread far
/// apart, so that neither memory nor time depends on how far apart they are.
struct CellList<'a, D: Dim> {
    /// Along each axis (x, y, z; the first `D::D` of them): periodic, and the number of
    /// cells (each up to [`max_cells_per_axis`] in the sparse case).
    periodic: [bool; 3],
    count: [u64; 3],
    kind: Cells<'a>,
    dim: std::marker::PhantomData<D>,
}

enum Cells<'a> {
    /// The cell of each grain (`(cz * ny + cy) * nx + cx`); the grains of cell c are
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

/// Most columns or rows a grid counts (2^31 in the plane, 2^20 along each axis in space:
/// a cell's index fits a u64): grains beyond share the edge cells.
const MAX_CELLS_PER_AXIS: f64 = 2147483648.0;

/// [`MAX_CELLS_PER_AXIS`] for a grid of `d` axes.
fn max_cells_per_axis(d: usize) -> f64 {
    if d == 3 { 1048576.0 } else { MAX_CELLS_PER_AXIS }
}

/// How many cells at least `reach` wide fit along a length `l`: at least one, counted in
/// floating point (the count for a far-flung set of grains fits no integer), at most
/// [`MAX_CELLS_PER_AXIS`].
pub(crate) fn cells_along(l: f64, reach: f64) -> f64 {
    cells_along_of(l, reach, MAX_CELLS_PER_AXIS)
}

fn cells_along_of(l: f64, reach: f64, max: f64) -> f64 {
    let c = (l / reach).floor();
    if c.is_finite() { c.clamp(1.0, max) } else { max }
}

impl<'a, D: Dim> CellList<'a, D> {
    fn new(x: &[D::Vector<f64>], r: &[f64], boundary: &Boundary<D>, skin: f64, cell_start: &'a mut Vec<u32>, cell_items: &'a mut Vec<u32>) -> Self {
        let (n, d) = (x.len(), D::D);
        let r_max = r.iter().cloned().fold(0.0, f64::max);
        let reach = 2.0 * r_max + skin;
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in x {
            for a in 0..d {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let periodic = [boundary.is_periodic(), false, d == 3 && boundary.is_periodic_z()];
        let edges = [(boundary.x_min, boundary.period), (0.0, 0.0), (boundary.z_min, boundary.z_period)];
        // Along each axis: where the grid starts, how long it is, how many cells, how wide.
        let (mut origin, mut length, mut fcount, mut width) = ([0.0; 3], [1.0; 3], [1.0; 3], [1.0; 3]);
        for a in 0..d {
            (origin[a], length[a]) = if periodic[a] { edges[a] } else { (lo[a], (hi[a] - lo[a]).max(reach)) };
            fcount[a] = cells_along_of(length[a], reach, max_cells_per_axis(d));
            // A periodic row of fewer than three cells would meet itself: one cell then.
            if periodic[a] && fcount[a] < 3.0 {
                fcount[a] = 1.0;
            }
            width[a] = length[a] / fcount[a];
        }
        let count = fcount.map(|c| c as u64);
        let cell_of = |p: &D::Vector<f64>| -> u64 {
            let mut c = 0;
            for a in (0..d).rev() {
                let mut xr = p[a] - origin[a];
                if periodic[a] {
                    xr -= length[a] * (xr / length[a]).floor();
                }
                // `as` saturates (and takes NaN to 0): every grain gets a cell of the grid.
                let ca = ((xr / width[a]).max(0.0)) as u64;
                c = c * count[a] + ca.min(count[a] - 1);
            }
            c
        };
        let total: f64 = fcount[..d].iter().product();
        let kind = if total <= max_dense_cells(n) {
            // The grid has at most 4n + 64 cells: each index fits a u32.
            let cell: Vec<u32> = x.iter().map(|p| cell_of(p) as u32).collect();
            bin_into_cells(&cell, total as usize, cell_start, cell_items);
            Cells::Dense { cell, start: &cell_start[..], items: &cell_items[..] }
        } else {
            let cell: Vec<u64> = x.iter().map(cell_of).collect();
            let mut items: Vec<u32> = (0..n as u32).collect();
            items.sort_unstable_by_key(|&i| (cell[i as usize], i));
            Cells::Sparse { keys: items.iter().map(|&i| cell[i as usize]).collect(), cell, items }
        };
        CellList { periodic, count, kind, dim: std::marker::PhantomData }
    }

    /// Call `visit` with each grain of grain i's cell and the 8 (26) around it (i
    /// included), each cell once, in the order of their indices, until it returns false.
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
        // The cell's coordinates, x first.
        let mut at = [0i64; 3];
        let mut rest = c;
        for a in 0..D::D {
            at[a] = (rest % self.count[a]) as i64;
            rest /= self.count[a];
        }
        let mut around = [0u64; 27];
        let mut m = 0;
        // Each offset (-1, 0, 1 along each axis) as a number in base 3.
        'offsets: for k in 0..3usize.pow(D::D as u32) {
            let (mut code, mut index, mut scale) = (k, 0u64, 1u64);
            for a in 0..D::D {
                let n = self.count[a] as i64;
                let mut y = at[a] + (code % 3) as i64 - 1;
                code /= 3;
                if y < 0 || y >= n {
                    if !self.periodic[a] {
                        continue 'offsets;
                    }
                    y = y.rem_euclid(n);
                }
                index += y as u64 * scale;
                scale *= n as u64;
            }
            around[m] = index;
            m += 1;
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
