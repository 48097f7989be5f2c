//! Initial packings: seeded radii and a dense random packing by overlap relaxation.
//!
//! Grains are dropped at random into a region sized for a target packing fraction and
//! pushed apart pair by pair until no overlap exceeds a tiny tolerance. The result is a
//! dense, disordered packing that the confining wall compresses only a little, so a
//! shear run does not start with a violent collapse.

use std::marker::PhantomData;

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, LogNormal, Normal};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::error::{Error, check};
use crate::kernels::cells::{bin_into_cells, cells_along};
use crate::physics::boundary::Boundary;
use crate::physics::dim::{Dim, Space, Vec2};
use crate::scene::limits::MAX_PACKING_OVERLAP;

/// A distribution of radii, m. Normal and lognormal draws are truncated to [min, max].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum RadiusDist {
    Fixed { radius: f64 },
    Uniform { min: f64, max: f64 },
    Normal { mean: f64, std: f64, min: f64, max: f64 },
    Lognormal { median: f64, sigma: f64, min: f64, max: f64 },
}

impl RadiusDist {
    pub fn validate(&self, at: &str) -> Result<(), Error> {
        let (lo, hi) = self.bounds();
        check(lo.is_finite() && lo > 0.0, at, "min", lo, "> 0 m")?;
        check(hi.is_finite() && hi >= lo, at, "max", hi, ">= min")?;
        if let RadiusDist::Normal { mean, std, .. } = *self {
            check(mean.is_finite(), at, "mean", mean, "finite m")?;
            check(std.is_finite() && std >= 0.0, at, "std", std, ">= 0 m")?;
        }
        if let RadiusDist::Lognormal { median, sigma, .. } = *self {
            check(median.is_finite() && median > 0.0, at, "median", median, "> 0 m")?;
            check(sigma.is_finite() && sigma >= 0.0, at, "sigma", sigma, ">= 0")?;
        }
        Ok(())
    }
    /// Smallest and largest possible radius, m.
    pub fn bounds(&self) -> (f64, f64) {
        match *self {
            RadiusDist::Fixed { radius } => (radius, radius),
            RadiusDist::Uniform { min, max } | RadiusDist::Normal { min, max, .. } | RadiusDist::Lognormal { min, max, .. } => (min, max),
        }
    }
    /// `count` radii from a ChaCha8 stream seeded with `seed`.
    pub fn sample(&self, count: usize, seed: u64) -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let (lo, hi) = self.bounds();
        (0..count)
            .map(|_| match *self {
                RadiusDist::Fixed { radius } => radius,
                RadiusDist::Uniform { min, max } => {
                    if max > min {
                        rng.random_range(min..max)
                    } else {
                        min
                    }
                }
                RadiusDist::Normal { mean, std, .. } => {
                    let d = Normal::new(mean, std).expect("validated");
                    d.sample(&mut rng).clamp(lo, hi)
                }
                RadiusDist::Lognormal { median, sigma, .. } => {
                    let d = LogNormal::new(median.ln(), sigma).expect("validated");
                    d.sample(&mut rng).clamp(lo, hi)
                }
            })
            .collect()
    }
}

/// Sweeps every relaxation has room for. Past them it goes on, up to [`MAX_SWEEPS`],
/// only while an overlap is above [`MAX_PACKING_OVERLAP`] of the smallest radius, until
/// it is under half of that: large dense packings relax slowly (the built-in shear cell
/// widened to 10^5 grains at packing fraction 0.75 left 2.35e-2 after 2000 sweeps,
/// 1.13e-2 after 3000, 1.2e-4 after 11 000; each sweep about 7 ms there).
pub const SWEEPS: usize = 2000;

/// Most sweeps of a relaxation.
pub const MAX_SWEEPS: usize = 20_000;

/// Place grains of radii `r` in the rectangle `[x0, x1] x [y0, y1]` (periodic in x when
/// `periodic`), randomly, then relax the overlaps. Returns the centres.
///
/// Each sweep pushes every overlapping pair apart along its normal, split by size, all
/// pushes of a sweep summed before the grains move. A grain's sum takes its partners in
/// the order of their index: the order of the pair list sorted by (i, j) that the
/// relaxation was first written with (`scatter_packing` in the tests below, whose bits
/// a test checks), so a packing does not depend on how the sweep is organised. Here
/// each grain gathers its pushes from a list of its partners, with the grains stored
/// along a Z curve; a pair clearly apart is passed over without a square root; and the
/// partners are found again only when a grain has moved half the skin since (the first
/// version summed the largest move of every sweep, an upper bound that called for a new
/// list every three or four sweeps at 10^5 grains). The sweeps are written once for the
/// plane and space ([`relaxed_packing_space`]); in the plane they are the operations, in
/// the order, of the 2D code they replaced, so a plane packing keeps its bits.
pub fn relaxed_packing(r: &[f64], x0: f64, x1: f64, y0: f64, y1: f64, periodic: bool, seed: u64) -> Vec<Vec2> {
    let boundary: Boundary = if periodic { Boundary::periodic_x(x0, x1 - x0) } else { Boundary::open() };
    let x = random_places(r, x0, x1, y0, y1, periodic, seed);
    let r_max = r.iter().cloned().fold(0.0, f64::max);
    // Storage along a Z curve of the first places.
    let index = morton_order(&x, x0, y0, 2.0 * r_max);
    relax(&x, r, &index, [x0, y0, 0.0], [x1, y1, 0.0], &boundary).x
}

/// Place spheres of radii `r` (m) in the box `x * y * z` (each `[lo, hi]`, m), periodic
/// in x and in z when asked (never in y, the axis of the walls), randomly, then relax
/// the overlaps as [`relaxed_packing`] does in the plane: the same push, sweep and stop
/// rule, over cells in space (a grain's partners in its cell and the 26 around it).
/// Returns the centres, in the order of `r`.
///
/// On a periodic axis a sphere is first placed anywhere in the range and its centre is
/// returned wrapped into `[lo, hi)`; on a closed axis it stays at least its radius
/// inside each face. The caller makes each closed side at least the largest diameter
/// wide (a narrower one panics in the clamp) and each periodic one two diameters (a
/// sphere must not meet its own image), as the scene's checks do for the plane's region.
/// The cells are bounded as the plane's, about 4n + 64 of them, however large and empty
/// the box. The first places come from their own ChaCha8 stream of `seed` (not the
/// plane's), so that no plane packing's draws repeat.
pub fn relaxed_packing_space(r: &[f64], x: [f64; 2], y: [f64; 2], z: [f64; 2], periodic_x: bool, periodic_z: bool, seed: u64) -> Vec<Vector3<f64>> {
    relax_space(r, x, y, z, periodic_x, periodic_z, seed).x
}

/// [`relaxed_packing_space`], with how the relaxation ended.
fn relax_space(r: &[f64], x: [f64; 2], y: [f64; 2], z: [f64; 2], periodic_x: bool, periodic_z: bool, seed: u64) -> Relaxed<Space> {
    let boundary = Boundary::<Space>::periodic(periodic_x.then_some((x[0], x[1] - x[0])), periodic_z.then_some((z[0], z[1] - z[0])));
    let (lo, hi) = ([x[0], y[0], z[0]], [x[1], y[1], z[1]]);
    let places = random_places_in(r, lo, hi, &boundary, seed ^ SPACE_STREAM);
    let r_max = r.iter().cloned().fold(0.0, f64::max);
    let index = morton_order_space(&places, lo, 2.0 * r_max);
    relax(&places, r, &index, lo, hi, &boundary)
}

/// What the seed of a packing in space is mixed with (the fractional bits of sqrt(2); the
/// plane's are those of the golden ratio).
const SPACE_STREAM: u64 = 0x6a09_e667_f3bc_c908;

/// What a relaxation leaves: the centres in the caller's order (m), how many sweeps it
/// took, and the largest overlap its last sweep found before it moved the grains (m).
struct Relaxed<D: Dim> {
    x: Vec<D::Vector<f64>>,
    #[cfg_attr(not(test), allow(dead_code))]
    sweeps: usize,
    #[cfg_attr(not(test), allow(dead_code))]
    worst: f64,
}

/// The sweeps of [`relaxed_packing`] and [`relaxed_packing_space`], from the first places
/// `x` (caller's order, m) of grains of radii `r` (m) in the box `lo..hi` (per axis x, y,
/// z, m; z unused in the plane), closed on the axes where `boundary` is not periodic.
/// The grains are stored in the order `index` (grain k of the sweep is grain `index[k]`
/// of the caller).
fn relax<D: Dim>(x: &[D::Vector<f64>], r: &[f64], index: &[usize], lo: [f64; 3], hi: [f64; 3], boundary: &Boundary<D>) -> Relaxed<D> {
    let n = x.len();
    let r_min = r.iter().cloned().fold(f64::INFINITY, f64::min);
    let r_max = r.iter().cloned().fold(0.0, f64::max);
    let index: Vec<u32> = index.iter().map(|&i| i as u32).collect();
    let mut xs: Vec<D::Vector<f64>> = index.iter().map(|&i| x[i as usize]).collect();
    let rs: Vec<f64> = index.iter().map(|&i| r[i as usize]).collect();
    // Candidate partners within a skin, found again when a grain has moved more than half
    // of it since they were found (a partner's push is zero unless the pair overlaps, so
    // any list that holds every overlapping pair gives the same sums).
    let skin = 0.2 * r_min;
    let grid = Grid::<D>::new(lo, hi, periodic_axes(boundary), 2.0 * r_max + skin, n);
    let mut partners = Partners::default();
    let mut at = Vec::new();
    let mut far = true;
    let mut moves = vec![D::zero(); n];
    let mut last = (0, 0.0);
    for sweep in 1..=MAX_SWEEPS {
        if far {
            partners.find(&grid, &xs, &rs, &index, boundary, skin);
            at.clone_from(&xs);
        }
        let mut worst: f64 = 0.0;
        for (g, m) in moves.iter_mut().enumerate() {
            let mut sum = D::zero();
            for &q in partners.of(g) {
                let q = q as usize;
                // The pair (i, j) with i < j in the caller's order, as the sorted list had it.
                let first = index[g] < index[q];
                let (i, j) = if first { (g, q) } else { (q, g) };
                let d = boundary.image(xs[i] - xs[j]);
                // Apart for certain (by a margin far above rounding): no push, and no
                // square root to find it out. The exact test below decides the rest.
                let touch = rs[i] + rs[j];
                if D::norm_squared(d) > touch * touch * (1.0 + 1e-9) {
                    continue;
                }
                if let Some((overlap, on_i, on_j)) = push::<D>(d, rs[i], rs[j], r_min) {
                    worst = worst.max(overlap);
                    if first {
                        sum += on_i;
                    } else {
                        sum -= on_j;
                    }
                }
            }
            *m = sum;
        }
        apply_moves(&mut xs, &moves, &rs, lo, hi, boundary);
        far = boundary.any_moved_beyond(&xs, &at, 0.25 * skin * skin);
        last = (sweep, worst);
        // Converged; or, at the sweeps every packing has, no overlap above what a run may
        // start with (the packings of the first versions, which stopped there); or, past
        // them, settled below half of that.
        if worst < 1e-4 * r_min || (sweep == SWEEPS && worst < MAX_PACKING_OVERLAP * r_min) || (sweep > SWEEPS && worst < 0.5 * MAX_PACKING_OVERLAP * r_min) {
            break;
        }
    }
    let mut out = vec![D::zero(); n];
    for (&i, p) in index.iter().zip(xs) {
        out[i as usize] = p;
    }
    Relaxed { x: out, sweeps: last.0, worst: last.1 }
}

/// An overlap (m) and the pushes that part the pair (m): [`push`].
type Parting<D> = (f64, <D as Dim>::Vector<f64>, <D as Dim>::Vector<f64>);

/// The overlap of two grains of radii `ri`, `rj` at separation `d` (from j to i), and
/// the pushes that part them: `+on_i` on i, `-on_j` on j, split by size, a little more
/// than needed to converge quickly; `None` if they do not overlap.
#[inline(always)]
fn push<D: Dim>(d: D::Vector<f64>, ri: f64, rj: f64, r_min: f64) -> Option<Parting<D>> {
    let dist = D::norm(d).max(1e-12 * r_min);
    let overlap = ri + rj - dist;
    (overlap > 0.0).then(|| {
        let n = d / dist;
        let wi = rj * rj / (ri * ri + rj * rj);
        // Each component the product of the first version's `0.55 * overlap * wi * n`:
        // the scalar is formed first, and a product of two numbers does not depend on
        // their order.
        (overlap, n * (0.55 * overlap * wi), n * (0.55 * overlap * (1.0 - wi)))
    })
}

/// Along which axes (x, y, z) `boundary` is periodic: never y, nor z in the plane.
fn periodic_axes<D: Dim>(boundary: &Boundary<D>) -> [bool; 3] {
    [boundary.is_periodic(), false, D::D == 3 && boundary.is_periodic_z()]
}

/// Move the grains by a sweep's pushes, kept at least their radius inside the box
/// `lo..hi` (m, per axis) on its closed axes, wrapped on its periodic ones.
fn apply_moves<D: Dim>(x: &mut [D::Vector<f64>], moves: &[D::Vector<f64>], r: &[f64], lo: [f64; 3], hi: [f64; 3], boundary: &Boundary<D>) {
    let periodic = periodic_axes(boundary);
    for ((p, &m), &ri) in x.iter_mut().zip(moves).zip(r) {
        *p += m;
        for a in 0..D::D {
            if !periodic[a] {
                p[a] = p[a].clamp(lo[a] + ri, hi[a] - ri);
            }
        }
        // The identity along an axis that is not periodic.
        boundary.wrap(p);
    }
}

/// The random first places of [`relaxed_packing`], in index order.
fn random_places(r: &[f64], x0: f64, x1: f64, y0: f64, y1: f64, periodic: bool, seed: u64) -> Vec<Vec2> {
    let boundary: Boundary = if periodic { Boundary::periodic_x(x0, x1 - x0) } else { Boundary::open() };
    random_places_in(r, [x0, y0, 0.0], [x1, y1, 0.0], &boundary, seed ^ 0x9e37_79b9_7f4a_7c15)
}

/// Random places, in index order, for grains of radii `r` (m) in the box `lo..hi` (m, per
/// axis): anywhere along a periodic axis, at least a radius inside each face of a closed
/// one; the coordinates of a grain drawn one after the other (x, y, z) from a ChaCha8
/// stream seeded with `seed`.
fn random_places_in<D: Dim>(r: &[f64], lo: [f64; 3], hi: [f64; 3], boundary: &Boundary<D>, seed: u64) -> Vec<D::Vector<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let periodic = periodic_axes(boundary);
    r.iter()
        .map(|&ri| {
            let mut p = D::zero();
            for a in 0..D::D {
                let (l, h) = if periodic[a] { (lo[a], hi[a]) } else { (lo[a] + ri, (hi[a] - ri).max(lo[a] + ri)) };
                p[a] = rng.random_range(l..=h);
            }
            p
        })
        .collect()
}

/// Square-ish (cube-ish in space) cells over the packing's box, at least `reach` wide (so
/// that a grain's partners are in its cell and the 8, in space 26, around it), periodic
/// along the boundary's periodic axes.
struct Grid<D: Dim> {
    /// Where the grid starts along each axis, m.
    origin: [f64; 3],
    /// The width of a cell along each axis, m.
    width: [f64; 3],
    /// Cells along each axis (1 along an axis the dimension does not have).
    count: [usize; 3],
    periodic: [bool; 3],
    dim: PhantomData<D>,
}

impl<D: Dim> Grid<D> {
    fn new(lo: [f64; 3], hi: [f64; 3], periodic: [bool; 3], reach: f64, n: usize) -> Self {
        let d = D::D;
        let (mut length, mut f) = ([1.0; 3], [1.0; 3]);
        for a in 0..d {
            length[a] = (hi[a] - lo[a]).max(reach);
            // Counted in floating point, so that no region overflows an integer.
            f[a] = cells_along(length[a], reach);
        }
        // Keep the grid modest when the grains are few and far apart.
        let max_cells = (4 * n + 64) as f64;
        let total: f64 = f[..d].iter().product();
        if total > max_cells {
            let ratio = total / max_cells;
            let s = if d == 3 { ratio.cbrt() } else { ratio.sqrt() }.ceil();
            for c in &mut f[..d] {
                *c = (*c / s).floor().max(1.0);
            }
            // A side that was one cell already takes no share of the cut: the others
            // take it all (a tall, narrow region asked for 9e8 rows of one cell). The
            // last axis first; each side then leaves the product of all at most
            // `max_cells`.
            for a in (0..d).rev() {
                let others: f64 = (0..d).filter(|&b| b != a).map(|b| f[b]).product();
                f[a] = f[a].min((max_cells / others).floor()).max(1.0);
            }
        }
        let (mut count, mut width) = ([1; 3], [1.0; 3]);
        for a in 0..d {
            count[a] = f[a] as usize;
            // A periodic row of fewer than three cells would meet itself: one cell then.
            if periodic[a] && count[a] < 3 {
                count[a] = 1;
            }
            width[a] = length[a] / count[a] as f64;
        }
        Grid { origin: lo, width, count, periodic, dim: PhantomData }
    }

    /// How many cells the grid has.
    fn cells(&self) -> usize {
        self.count.iter().product()
    }

    /// The cell of a place, `(cz * ny + cy) * nx + cx` (places outside go to the nearest
    /// edge cell; along a periodic axis the place is wrapped first).
    fn cell(&self, p: &D::Vector<f64>) -> usize {
        let mut c = 0;
        for a in (0..D::D).rev() {
            let mut xr = p[a] - self.origin[a];
            if self.periodic[a] {
                let l = self.width[a] * self.count[a] as f64;
                xr -= l * (xr / l).floor();
            }
            c = c * self.count[a] + ((xr / self.width[a]).max(0.0) as usize).min(self.count[a] - 1);
        }
        c
    }

    /// The cells around cell `c`, itself included, each once: up to 27 (9 in the plane),
    /// in `out`; returns how many.
    fn around(&self, c: usize, out: &mut [usize; 27]) -> usize {
        // Along each axis the cell's row and the rows either side, each once: every row
        // of an axis of fewer than three, wrapped along a periodic axis.
        let (mut near, mut len) = ([[0usize; 3]; 3], [1usize; 3]);
        let mut rest = c;
        for a in 0..D::D {
            let n = self.count[a];
            let at = rest % n;
            rest /= n;
            len[a] = 0;
            if n < 3 {
                for (y, row) in near[a][..n].iter_mut().enumerate() {
                    *row = y;
                }
                len[a] = n;
            } else {
                for o in -1..=1 {
                    let y = at as isize + o;
                    if self.periodic[a] || (0..n as isize).contains(&y) {
                        near[a][len[a]] = y.rem_euclid(n as isize) as usize;
                        len[a] += 1;
                    }
                }
            }
        }
        let [nx, ny, _] = self.count;
        let mut m = 0;
        for &z in &near[2][..len[2]] {
            for &y in &near[1][..len[1]] {
                for &x in &near[0][..len[0]] {
                    out[m] = (z * ny + y) * nx + x;
                    m += 1;
                }
            }
        }
        m
    }
}

/// Each grain's candidate partners (storage indices), in the order of their index in
/// the caller's order, as one list cut per grain.
#[derive(Default)]
struct Partners {
    start: Vec<usize>,
    list: Vec<u32>,
    cell_start: Vec<u32>,
    cell_items: Vec<u32>,
}

impl Partners {
    fn of(&self, g: usize) -> &[u32] {
        &self.list[self.start[g]..self.start[g + 1]]
    }

    /// Every pair of grains closer than the sum of their radii plus `skin` (minimum image).
    fn find<D: Dim>(&mut self, grid: &Grid<D>, x: &[D::Vector<f64>], r: &[f64], index: &[u32], boundary: &Boundary<D>, skin: f64) {
        let cells: Vec<u32> = x.iter().map(|p| grid.cell(p) as u32).collect();
        bin_into_cells(&cells, grid.cells(), &mut self.cell_start, &mut self.cell_items);
        self.start.clear();
        self.list.clear();
        self.start.push(0);
        let mut around = [0; 27];
        for (g, &c) in cells.iter().enumerate() {
            let from = self.list.len();
            let m = grid.around(c as usize, &mut around);
            for &d in &around[..m] {
                for &q in &self.cell_items[self.cell_start[d] as usize..self.cell_start[d + 1] as usize] {
                    let q = q as usize;
                    let reach = r[g] + r[q] + skin;
                    if q != g && D::norm_squared(boundary.image(x[g] - x[q])) < reach * reach {
                        self.list.push(q as u32);
                    }
                }
            }
            self.list[from..].sort_unstable_by_key(|&q| index[q as usize]);
            self.start.push(self.list.len());
        }
    }
}

/// Order grains along a Z (Morton) curve of square cells of side `cell`, so that grains
/// near in space are near in memory: the contact loop then streams through the arrays
/// instead of jumping across them, which keeps the cost per grain flat as N grows. Returns
/// the permutation (new position k holds old grain `perm[k]`).
pub fn morton_order(x: &[Vec2], x0: f64, y0: f64, cell: f64) -> Vec<usize> {
    fn spread(mut v: u64) -> u64 {
        v &= 0xffff_ffff;
        v = (v | (v << 16)) & 0x0000_ffff_0000_ffff;
        v = (v | (v << 8)) & 0x00ff_00ff_00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333_3333_3333;
        (v | (v << 1)) & 0x5555_5555_5555_5555
    }
    let key = |p: &Vec2| {
        let cx = ((p.x - x0) / cell).max(0.0) as u64;
        let cy = ((p.y - y0) / cell).max(0.0) as u64;
        spread(cx) | (spread(cy) << 1)
    };
    let mut perm: Vec<usize> = (0..x.len()).collect();
    perm.sort_by_key(|&i| (key(&x[i]), i));
    perm
}

/// [`morton_order`] in space: grains ordered along a Z curve of cubic cells of side
/// `cell` (m) counted from `origin` (m), the bits of the cells' x, y and z interleaved
/// (21 of each, x lowest). Along an axis a grain before the origin shares the first
/// cell, and one 2^21 cells or more beyond it the last (the order is still a
/// permutation; only its locality suffers there). Returns the permutation (new position
/// k holds old grain `perm[k]`; grains in one cell in the order of their index).
pub fn morton_order_space(x: &[Vector3<f64>], origin: [f64; 3], cell: f64) -> Vec<usize> {
    const LAST: u64 = (1 << 21) - 1;
    fn spread(mut v: u64) -> u64 {
        v &= LAST;
        v = (v | (v << 32)) & 0x001f_0000_0000_ffff;
        v = (v | (v << 16)) & 0x001f_0000_ff00_00ff;
        v = (v | (v << 8)) & 0x100f_00f0_0f00_f00f;
        v = (v | (v << 4)) & 0x10c3_0c30_c30c_30c3;
        (v | (v << 2)) & 0x1249_2492_4924_9249
    }
    let key = |p: &Vector3<f64>| {
        // `as` saturates (and takes NaN to 0).
        let c = |a: usize| (((p[a] - origin[a]) / cell).max(0.0) as u64).min(LAST);
        spread(c(0)) | (spread(c(1)) << 1) | (spread(c(2)) << 2)
    };
    let mut perm: Vec<usize> = (0..x.len()).collect();
    perm.sort_by_key(|&i| (key(&x[i]), i));
    perm
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::cells::{brute_force_pairs, cell_pairs};
    use crate::kernels::threads::Threads;
    use crate::physics::dim::Plane;

    /// The plane's push, as the first relaxation called it.
    fn push(d: Vec2, ri: f64, rj: f64, r_min: f64) -> Option<(f64, Vec2, Vec2)> {
        super::push::<Plane>(d, ri, rj, r_min)
    }

    /// The plane's move of a sweep, in the rectangle `[x0, x1, y0, y1]`, as the first
    /// relaxation called it.
    fn apply_moves(x: &mut [Vec2], moves: &[Vec2], r: &[f64], [x0, x1, y0, y1]: [f64; 4], boundary: &Boundary) {
        super::apply_moves(x, moves, r, [x0, y0, 0.0], [x1, y1, 0.0], boundary)
    }

    /// The relaxation as first written: a sweep over the pair list sorted by (i, j), each
    /// push added to both grains as it comes. [`relaxed_packing`] must give its bits.
    fn scatter_packing(r: &[f64], x0: f64, x1: f64, y0: f64, y1: f64, periodic: bool, seed: u64) -> Vec<Vec2> {
        let boundary = if periodic { Boundary::periodic_x(x0, x1 - x0) } else { Boundary::open() };
        let mut x = random_places(r, x0, x1, y0, y1, periodic, seed);
        let (mut cs, mut ci) = (Vec::new(), Vec::new());
        let r_min = r.iter().cloned().fold(f64::INFINITY, f64::min);
        let skin = 0.2 * r_min;
        let mut pairs = Vec::new();
        let mut moved = f64::INFINITY;
        let mut moves = vec![Vec2::zeros(); x.len()];
        for sweep in 1..=MAX_SWEEPS {
            if moved > 0.5 * skin {
                pairs = cell_pairs(&x, r, r.len(), &boundary, skin, &mut cs, &mut ci, &Threads::serial());
                moved = 0.0;
            }
            let mut worst: f64 = 0.0;
            moves.iter_mut().for_each(|m| *m = Vec2::zeros());
            for &[i, j] in &pairs {
                let (i, j) = (i as usize, j as usize);
                let d = boundary.image(x[i] - x[j]);
                if let Some((overlap, on_i, on_j)) = push(d, r[i], r[j], r_min) {
                    worst = worst.max(overlap);
                    moves[i] += on_i;
                    moves[j] -= on_j;
                }
            }
            moved += moves.iter().map(|m| m.norm()).fold(0.0, f64::max);
            apply_moves(&mut x, &moves, r, [x0, x1, y0, y1], &boundary);
            if worst < 1e-4 * r_min || (sweep == SWEEPS && worst < MAX_PACKING_OVERLAP * r_min) || (sweep > SWEEPS && worst < 0.5 * MAX_PACKING_OVERLAP * r_min) {
                break;
            }
        }
        x
    }

    /// The gathered relaxation gives the scatter sweep's packing bit for bit: periodic
    /// and not, one grain to hundreds, equal and spread radii, dense (the first 2000 sweeps
    /// all used, and more) and loose, a periodic cell narrower than three grid cells, a tall column.
    #[test]
    fn gathered_relaxation_gives_the_scatter_sweeps_bits() {
        let uniform = RadiusDist::Uniform { min: 0.4e-3, max: 0.6e-3 };
        let spread = RadiusDist::Lognormal { median: 0.5e-3, sigma: 0.4, min: 0.1e-3, max: 2.0e-3 };
        let fixed = RadiusDist::Fixed { radius: 0.5e-3 };
        // (radii, count, x1, packing fraction, periodic, seed); x0 = y0 = 0.
        let cases = [
            (&uniform, 600, 0.024, 0.75, true, 1),
            (&uniform, 600, 0.024, 0.75, false, 2),
            (&spread, 400, 0.03, 0.8, true, 3),
            (&fixed, 300, 0.02, 0.85, true, 4),
            (&uniform, 200, 0.05, 0.3, false, 5),
            (&uniform, 40, 0.0025, 0.7, true, 6),
            (&uniform, 60, 0.004, 0.75, true, 7),
            (&uniform, 1, 0.0012, 0.5, true, 8),
            (&fixed, 2, 0.0012, 0.9, false, 9),
        ];
        for (k, &(dist, count, x1, fraction, periodic, seed)) in cases.iter().enumerate() {
            let r = dist.sample(count, seed);
            let area: f64 = r.iter().map(|r| std::f64::consts::PI * r * r).sum();
            let h = area / (fraction * x1);
            let (a, b) = (relaxed_packing(&r, 0.0, x1, 0.0, h, periodic, seed), scatter_packing(&r, 0.0, x1, 0.0, h, periodic, seed));
            let bits = |x: &[Vec2]| x.iter().map(|p| [p.x.to_bits(), p.y.to_bits()]).collect::<Vec<_>>();
            assert_eq!(bits(&a), bits(&b), "case {k}");
        }
    }

    /// Radii for the packings in space: equal, and spread uniformly over 0.4-0.6 mm.
    const FIXED: RadiusDist = RadiusDist::Fixed { radius: 0.5e-3 };
    const UNIFORM: RadiusDist = RadiusDist::Uniform { min: 0.4e-3, max: 0.6e-3 };

    /// The height (m) of an `lx` by `lz` box (m) that spheres of radii `r` fill to the
    /// volume fraction `fraction`, and not less than `least` (m).
    fn height(r: &[f64], lx: f64, lz: f64, fraction: f64, least: f64) -> f64 {
        let volume: f64 = r.iter().map(|r| 4.0 / 3.0 * std::f64::consts::PI * r * r * r).sum();
        (volume / (fraction * lx * lz)).max(least)
    }

    /// The periodic cell of a box in space, as [`relaxed_packing_space`] makes it.
    fn space_boundary(x: [f64; 2], z: [f64; 2], periodic_x: bool, periodic_z: bool) -> Boundary<Space> {
        Boundary::<Space>::periodic(periodic_x.then_some((x[0], x[1] - x[0])), periodic_z.then_some((z[0], z[1] - z[0])))
    }

    /// The largest overlap of any two spheres (m, 0 if none) and the largest over the
    /// pair's smaller radius, from every pair (minimum image on the periodic axes): the
    /// O(n^2) reference, which no cell grid takes part in.
    fn largest_overlaps(x: &[Vector3<f64>], r: &[f64], boundary: &Boundary<Space>) -> (f64, f64) {
        let (mut worst, mut ratio): (f64, f64) = (0.0, 0.0);
        for i in 0..x.len() {
            for j in i + 1..x.len() {
                let overlap = r[i] + r[j] - boundary.image(x[i] - x[j]).norm();
                worst = worst.max(overlap);
                ratio = ratio.max(overlap / r[i].min(r[j]));
            }
        }
        (worst, ratio)
    }

    /// Spheres relaxed in space touch no more than a run may start with: every pair's
    /// overlap (minimum image) is below `MAX_PACKING_OVERLAP` of its smaller radius, the
    /// bound of the stop rule, and below 1e-4 of the smallest radius when the last sweep
    /// found none above that (the stop rule measures before that sweep's moves, which
    /// part its pairs further: here they always left less than they found); every centre
    /// is in the box, on a closed axis at least its radius from each face (clamped there
    /// exactly; 1e-12 of the side allows for the rounding of `lo + r`), on a periodic one
    /// in `[lo, hi)` (wrapped: 1e-12 of the period likewise). Periodic in x and z, in x
    /// only, closed; equal and spread radii; volume fractions 0.55 and 0.3; one sphere,
    /// two forced near a closed box's diagonal (the only room they have: centres at most
    /// 1.39 mm apart for 1 mm), periodic sides of fewer than three cells, a few hundred
    /// and 2000 spheres. All but one converge; the spread radii at 0.55 between walls
    /// (case 2) stop at the 2000 sweeps with 1.7e-3 of the smallest radius left.
    #[test]
    fn spheres_relaxed_in_space_overlap_less_than_a_run_may_start_with_inside_their_box() {
        // (radii, count, x and z side (m), volume fraction, least height (m), periodic x, periodic z, seed)
        let cases = [
            (&UNIFORM, 300, 6e-3, 0.55, 0.0, true, true, 1),
            (&FIXED, 300, 6e-3, 0.55, 0.0, true, true, 2),
            (&UNIFORM, 300, 6e-3, 0.55, 0.0, true, false, 3),
            (&FIXED, 300, 6e-3, 0.3, 0.0, true, false, 4),
            (&UNIFORM, 300, 6e-3, 0.3, 0.0, false, false, 5),
            (&FIXED, 300, 6e-3, 0.3, 0.0, false, false, 6),
            (&UNIFORM, 40, 2.5e-3, 0.55, 0.0, true, true, 7),
            (&UNIFORM, 1, 3e-3, 0.3, 1.2e-3, true, true, 8),
            (&FIXED, 2, 1.8e-3, 0.18, 1.8e-3, false, false, 9),
            (&UNIFORM, 2000, 12e-3, 0.55, 0.0, true, true, 10),
            (&FIXED, 2000, 12e-3, 0.3, 0.0, false, false, 11),
        ];
        for (k, &(dist, count, side, fraction, least, periodic_x, periodic_z, seed)) in cases.iter().enumerate() {
            let r = dist.sample(count, seed);
            // The smallest radius drawn, as the relaxation's stop rule has it.
            let r_min = r.iter().cloned().fold(f64::INFINITY, f64::min);
            let h = height(&r, side, side, fraction, least);
            let (x, y, z) = ([-0.5 * side, 0.5 * side], [1e-3, 1e-3 + h], [0.0, side]);
            let relaxed = relax_space(&r, x, y, z, periodic_x, periodic_z, seed);
            let boundary = space_boundary(x, z, periodic_x, periodic_z);
            let (worst, ratio) = largest_overlaps(&relaxed.x, &r, &boundary);
            let converged = relaxed.worst < 1e-4 * r_min;
            assert!(ratio < MAX_PACKING_OVERLAP, "case {k}: an overlap of {ratio:e} of the smaller radius after {} sweeps", relaxed.sweeps);
            assert!(!converged || worst < 1e-4 * r_min, "case {k}: converged after {} sweeps, yet an overlap of {:e} r_min", relaxed.sweeps, worst / r_min);
            let periodic = [periodic_x, false, periodic_z];
            for (p, &ri) in relaxed.x.iter().zip(&r) {
                for (a, [lo, hi]) in [x, y, z].into_iter().enumerate() {
                    let tol = 1e-12 * (hi - lo);
                    if periodic[a] {
                        assert!(p[a] >= lo - tol && p[a] < hi + tol, "case {k}: {p:?} outside the period along axis {a}");
                    } else {
                        assert!(p[a] >= lo + ri - tol && p[a] <= hi - ri + tol, "case {k}: {p:?} of radius {ri} through a face along axis {a}");
                    }
                }
            }
        }
    }

    /// A packing in space is a function of its seed: the same seed gives the same bits;
    /// another puts the spheres elsewhere. Independent places in the 8 x 8 mm periodic
    /// square and 7.7 mm high box lie about 4 mm apart on average (x and z from the
    /// minimum image, up to half the period, y across the height), and the relaxation
    /// moves a sphere about a radius: a mean distance above a fifth of the side (1.6 mm)
    /// separates other places from a mere replay, and no centre may keep its bits.
    #[test]
    fn spheres_relaxed_in_space_are_a_function_of_their_seed() {
        let r = UNIFORM.sample(500, 3);
        let side = 8e-3;
        let h = height(&r, side, side, 0.55, 0.0);
        let (x, y, z) = ([0.0, side], [0.0, h], [0.0, side]);
        let a = relaxed_packing_space(&r, x, y, z, true, true, 7);
        let b = relaxed_packing_space(&r, x, y, z, true, true, 7);
        let c = relaxed_packing_space(&r, x, y, z, true, true, 8);
        let bits = |x: &[Vector3<f64>]| x.iter().map(|p| p.map(f64::to_bits)).collect::<Vec<_>>();
        assert_eq!(bits(&a), bits(&b));
        assert!(a.iter().zip(&c).all(|(p, q)| p != q), "a centre in the same place from another seed");
        let boundary = space_boundary(x, z, true, true);
        let mean = a.iter().zip(&c).map(|(&p, &q)| boundary.image(p - q).norm()).sum::<f64>() / a.len() as f64;
        assert!(mean > 0.2 * side, "centres from seeds 7 and 8 only {mean:e} m apart on average");
    }

    /// The cell grid in space finds a grain's partners exactly: each grain's list holds
    /// every grain within the sum of radii plus the skin (minimum image), the pairs that
    /// an O(n^2) search over all pairs (`brute_force_pairs`, no grid) lists, and no other,
    /// in the order of the caller's index. Unrelaxed places, overlapping at random, stored
    /// along the Z curve as the relaxation stores them: periodic in x and z (wrapping
    /// across the cells), closed, periodic sides of fewer than three cells (one cell),
    /// exactly three cells, a long rod periodic along it, and a huge sparse region whose
    /// grid stays within 4n + 64 cells.
    #[test]
    fn space_partners_are_every_pair_within_the_skin_as_a_brute_force_search_finds() {
        // (count, x, y, z (m), periodic x, periodic z, seed)
        let cases = [
            (400, [0.0, 6e-3], [0.0, 6e-3], [0.0, 6e-3], true, true, 1),
            (400, [0.0, 6e-3], [0.0, 6e-3], [-3e-3, 3e-3], false, false, 2),
            (300, [0.0, 6e-3], [0.0, 4e-3], [0.0, 6e-3], true, false, 3),
            (100, [0.0, 2.5e-3], [0.0, 6e-3], [0.0, 2.5e-3], true, true, 4),
            (200, [0.0, 3.9e-3], [0.0, 5e-3], [0.0, 3.9e-3], true, true, 5),
            (300, [0.0, 0.1], [0.0, 2e-3], [0.0, 2e-3], true, false, 6),
            (60, [0.0, 1.0], [0.0, 1.0], [0.0, 1e3], false, true, 7),
        ];
        for (k, &(count, x, y, z, periodic_x, periodic_z, seed)) in cases.iter().enumerate() {
            let r = UNIFORM.sample(count, seed);
            let boundary = space_boundary(x, z, periodic_x, periodic_z);
            let (lo, hi) = ([x[0], y[0], z[0]], [x[1], y[1], z[1]]);
            let places = random_places_in(&r, lo, hi, &boundary, seed);
            let (r_min, r_max) = UNIFORM.bounds();
            let skin = 0.2 * r_min;
            let index: Vec<u32> = morton_order_space(&places, lo, 2.0 * r_max).into_iter().map(|i| i as u32).collect();
            let xs: Vec<Vector3<f64>> = index.iter().map(|&i| places[i as usize]).collect();
            let rs: Vec<f64> = index.iter().map(|&i| r[i as usize]).collect();
            let grid = Grid::<Space>::new(lo, hi, periodic_axes(&boundary), 2.0 * r_max + skin, count);
            assert!(grid.cells() <= 4 * count + 64, "case {k}: {} cells for {count} grains", grid.cells());
            let mut partners = Partners::default();
            partners.find(&grid, &xs, &rs, &index, &boundary, skin);
            let mut want = vec![Vec::new(); count];
            for [i, j] in brute_force_pairs::<Space>(&places, &r, count, &boundary, skin) {
                want[i as usize].push(j);
                want[j as usize].push(i);
            }
            want.iter_mut().for_each(|w| w.sort_unstable());
            for (g, &i) in index.iter().enumerate() {
                let found: Vec<u32> = partners.of(g).iter().map(|&q| index[q as usize]).collect();
                assert_eq!(found, want[i as usize], "case {k}: the partners of grain {i}");
            }
            assert!(want.iter().any(|w| !w.is_empty()) || k == 6, "case {k}: no pairs to find");
        }
    }

    /// `morton_order_space` is a permutation that sorts along the Z curve: a hand-built set
    /// of unit cells in the order the interleaved bits (x lowest, then y, then z) give,
    /// with one place before the origin (its first cell, after the grain of lower index
    /// there) and one 10^9 cells along z (the last cell, beyond 2^21 cells); and random
    /// places in the order of a key built bit by bit.
    #[test]
    fn morton_order_space_is_a_permutation_along_the_z_curve() {
        let v = Vector3::new;
        let hand = [
            v(1.5, 1.5, 1.5), // cell (1, 1, 1): key 7
            v(0.5, 0.5, 0.5), // (0, 0, 0): 0
            v(1.5, 0.5, 0.5), // (1, 0, 0): 1
            v(0.5, 1.5, 0.5), // (0, 1, 0): 2
            v(0.5, 0.5, 1.5), // (0, 0, 1): 4
            v(2.5, 0.5, 0.5), // (2, 0, 0): 8
            v(-3.0, 0.2, 0.7), // before the origin in x: (0, 0, 0), 0, after grain 1
            v(0.5, 0.5, 1e9), // z beyond 2^21 cells: (0, 0, 2^21 - 1), the last
            v(1.5, 1.5, 0.5), // (1, 1, 0): 3
            v(0.5, 2.5, 0.5), // (0, 2, 0): 16
        ];
        assert_eq!(morton_order_space(&hand, [0.0; 3], 1.0), [1, 6, 2, 3, 8, 4, 0, 5, 9, 7]);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let places: Vec<Vector3<f64>> = (0..1000).map(|_| v(rng.random_range(-1.0..3e6), rng.random_range(-1.0..3e3), rng.random_range(-1.0..3.0))).collect();
        let perm = morton_order_space(&places, [0.0; 3], 0.7);
        let mut sorted = perm.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..1000).collect::<Vec<_>>(), "not a permutation");
        let key = |p: &Vector3<f64>| {
            let mut key = 0u64;
            for a in 0..3 {
                let c = ((p[a] / 0.7).max(0.0) as u64).min((1 << 21) - 1);
                for b in 0..21 {
                    key |= ((c >> b) & 1) << (3 * b + a);
                }
            }
            key
        };
        assert!(perm.windows(2).all(|w| (key(&places[w[0]]), w[0]) < (key(&places[w[1]]), w[1])), "not along the curve");
    }

    /// Relaxing 5000 spheres (radii 0.4-0.6 mm, volume fraction 0.55, periodic in x and z,
    /// 12 x 35 x 12 mm): how long it takes and the overlap it leaves. A measurement, run by
    /// hand: `cargo test --release --lib relaxing_5000 -- --ignored --nocapture`.
    #[test]
    #[ignore = "a timing, in release mode"]
    fn relaxing_5000_spheres_in_space() {
        let r = UNIFORM.sample(5000, 1);
        let side = 12e-3;
        let h = height(&r, side, side, 0.55, 0.0);
        let (x, y, z) = ([0.0, side], [0.0, h], [0.0, side]);
        let start = std::time::Instant::now();
        let relaxed = relax_space(&r, x, y, z, true, true, 1);
        let took = start.elapsed();
        let r_min = r.iter().cloned().fold(f64::INFINITY, f64::min);
        let (worst, ratio) = largest_overlaps(&relaxed.x, &r, &space_boundary(x, z, true, true));
        println!("5000 spheres in 12 x {:.2} x 12 mm: {took:?}, {} sweeps, last sweep's worst {:e} r_min; left: {:e} r_min, {ratio:e} of the smaller radius", h * 1e3, relaxed.sweeps, relaxed.worst / r_min, worst / r_min);
        assert!(ratio < MAX_PACKING_OVERLAP);
    }
}
