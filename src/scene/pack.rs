//! Initial packings: seeded radii and a dense random packing by overlap relaxation.
//!
//! Grains are dropped at random into a region sized for a target packing fraction and
//! pushed apart pair by pair until no overlap exceeds a tiny tolerance. The result is a
//! dense, disordered packing that the confining wall compresses only a little, so a
//! shear run does not start with a violent collapse.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, LogNormal, Normal};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::error::{Error, check};
use crate::kernels::cells::{bin_into_cells, cells_along};
use crate::physics::boundary::Boundary;
use crate::physics::dim::Vec2;
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
/// list every three or four sweeps at 10^5 grains).
pub fn relaxed_packing(r: &[f64], x0: f64, x1: f64, y0: f64, y1: f64, periodic: bool, seed: u64) -> Vec<Vec2> {
    let boundary = if periodic { Boundary::periodic_x(x0, x1 - x0) } else { Boundary::open() };
    let x = random_places(r, x0, x1, y0, y1, periodic, seed);
    let n = x.len();
    let r_min = r.iter().cloned().fold(f64::INFINITY, f64::min);
    let r_max = r.iter().cloned().fold(0.0, f64::max);
    // Storage along a Z curve of the first places: grain k of the sweep is grain
    // `index[k]` of the caller.
    let index: Vec<u32> = morton_order(&x, x0, y0, 2.0 * r_max).into_iter().map(|i| i as u32).collect();
    let mut xs: Vec<Vec2> = index.iter().map(|&i| x[i as usize]).collect();
    let rs: Vec<f64> = index.iter().map(|&i| r[i as usize]).collect();
    // Candidate partners within a skin, found again when a grain has moved more than half
    // of it since they were found (a partner's push is zero unless the pair overlaps, so
    // any list that holds every overlapping pair gives the same sums).
    let skin = 0.2 * r_min;
    let grid = Grid::new(x0, x1, y0, y1, periodic, 2.0 * r_max + skin, n);
    let mut partners = Partners::default();
    let mut at = Vec::new();
    let mut far = true;
    let mut moves = vec![Vec2::zeros(); n];
    for sweep in 1..=MAX_SWEEPS {
        if far {
            partners.find(&grid, &xs, &rs, &index, &boundary, skin);
            at.clone_from(&xs);
        }
        let mut worst: f64 = 0.0;
        for (g, m) in moves.iter_mut().enumerate() {
            let mut sum = Vec2::zeros();
            for &q in partners.of(g) {
                let q = q as usize;
                // The pair (i, j) with i < j in the caller's order, as the sorted list had it.
                let first = index[g] < index[q];
                let (i, j) = if first { (g, q) } else { (q, g) };
                let d = boundary.image(xs[i] - xs[j]);
                // Apart for certain (by a margin far above rounding): no push, and no
                // square root to find it out. The exact test below decides the rest.
                let touch = rs[i] + rs[j];
                if d.norm_squared() > touch * touch * (1.0 + 1e-9) {
                    continue;
                }
                if let Some((overlap, on_i, on_j)) = push(d, rs[i], rs[j], r_min) {
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
        apply_moves(&mut xs, &moves, &rs, [x0, x1, y0, y1], &boundary);
        far = boundary.any_moved_beyond(&xs, &at, 0.25 * skin * skin);
        // Converged; or, at the sweeps every packing has, no overlap above what a run may
        // start with (the packings of the first versions, which stopped there); or, past
        // them, settled below half of that.
        if worst < 1e-4 * r_min || (sweep == SWEEPS && worst < MAX_PACKING_OVERLAP * r_min) || (sweep > SWEEPS && worst < 0.5 * MAX_PACKING_OVERLAP * r_min) {
            break;
        }
    }
    let mut out = vec![Vec2::zeros(); n];
    for (&i, p) in index.iter().zip(xs) {
        out[i as usize] = p;
    }
    out
}

/// The overlap of two grains of radii `ri`, `rj` at separation `d` (from j to i), and
/// the pushes that part them: `+on_i` on i, `-on_j` on j, split by size, a little more
/// than needed to converge quickly; `None` if they do not overlap.
#[inline(always)]
fn push(d: Vec2, ri: f64, rj: f64, r_min: f64) -> Option<(f64, Vec2, Vec2)> {
    let dist = d.norm().max(1e-12 * r_min);
    let overlap = ri + rj - dist;
    (overlap > 0.0).then(|| {
        let n = d / dist;
        let wi = rj * rj / (ri * ri + rj * rj);
        (overlap, 0.55 * overlap * wi * n, 0.55 * overlap * (1.0 - wi) * n)
    })
}

/// Move the grains by a sweep's pushes, kept inside the rectangle `[x0, x1, y0, y1]`
/// (in x wrapped instead where `boundary` is periodic).
fn apply_moves(x: &mut [Vec2], moves: &[Vec2], r: &[f64], [x0, x1, y0, y1]: [f64; 4], boundary: &Boundary) {
    for ((p, m), &ri) in x.iter_mut().zip(moves).zip(r) {
        *p += m;
        p.y = p.y.clamp(y0 + ri, y1 - ri);
        if boundary.is_periodic() {
            boundary.wrap(p);
        } else {
            p.x = p.x.clamp(x0 + ri, x1 - ri);
        }
    }
}

/// The random first places of [`relaxed_packing`], in index order.
fn random_places(r: &[f64], x0: f64, x1: f64, y0: f64, y1: f64, periodic: bool, seed: u64) -> Vec<Vec2> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x9e37_79b9_7f4a_7c15);
    r.iter()
        .map(|&ri| {
            let (lo, hi) = if periodic { (x0, x1) } else { (x0 + ri, (x1 - ri).max(x0 + ri)) };
            Vec2::new(rng.random_range(lo..=hi), rng.random_range((y0 + ri)..=(y1 - ri).max(y0 + ri)))
        })
        .collect()
}

/// Square-ish cells over the packing's rectangle, at least `reach` wide (so that a
/// grain's partners are in its cell and the eight around it), periodic in x when asked.
struct Grid {
    x0: f64,
    y0: f64,
    wx: f64,
    wy: f64,
    nx: usize,
    ny: usize,
    periodic: bool,
}

impl Grid {
    fn new(x0: f64, x1: f64, y0: f64, y1: f64, periodic: bool, reach: f64, n: usize) -> Self {
        let (lx, ly) = ((x1 - x0).max(reach), (y1 - y0).max(reach));
        // Counted in floating point, so that no region overflows an integer.
        let (mut fx, mut fy) = (cells_along(lx, reach), cells_along(ly, reach));
        // Keep the grid modest when the grains are few and far apart.
        let max_cells = (4 * n + 64) as f64;
        if fx * fy > max_cells {
            let s = (fx * fy / max_cells).sqrt().ceil();
            (fx, fy) = ((fx / s).floor().max(1.0), (fy / s).floor().max(1.0));
            // A side that was one cell already takes no share of the cut: the other
            // takes it all (a tall, narrow region asked for 9e8 rows of one cell).
            fy = fy.min((max_cells / fx).floor()).max(1.0);
            fx = fx.min((max_cells / fy).floor()).max(1.0);
        }
        let (mut nx, ny) = (fx as usize, fy as usize);
        // A periodic row of fewer than three cells would meet itself: one cell then.
        if periodic && nx < 3 {
            nx = 1;
        }
        Grid { x0, y0, wx: lx / nx as f64, wy: ly / ny as f64, nx, ny, periodic }
    }

    /// The cell of a place (places outside go to the nearest edge cell; in a periodic x
    /// the place is wrapped first).
    fn cell(&self, p: &Vec2) -> (usize, usize) {
        let mut xr = p.x - self.x0;
        if self.periodic {
            let l = self.wx * self.nx as f64;
            xr -= l * (xr / l).floor();
        }
        (((xr / self.wx).max(0.0) as usize).min(self.nx - 1), (((p.y - self.y0) / self.wy).max(0.0) as usize).min(self.ny - 1))
    }

    /// The cells around (cx, cy), itself included, each once: up to nine, in `out`;
    /// returns how many.
    fn around(&self, cx: usize, cy: usize, out: &mut [usize; 9]) -> usize {
        let (nx, ny) = (self.nx as isize, self.ny as isize);
        let mut cols = [0isize; 3];
        let mut nc = 0;
        if nx < 3 {
            for x in 0..nx {
                cols[nc] = x;
                nc += 1;
            }
        } else {
            for o in -1..=1 {
                let x = cx as isize + o;
                if self.periodic || (0..nx).contains(&x) {
                    cols[nc] = x.rem_euclid(nx);
                    nc += 1;
                }
            }
        }
        let mut m = 0;
        for y in (cy as isize - 1..=cy as isize + 1).filter(|y| (0..ny).contains(y)) {
            for &x in &cols[..nc] {
                out[m] = (y * nx + x) as usize;
                m += 1;
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
    fn find(&mut self, grid: &Grid, x: &[Vec2], r: &[f64], index: &[u32], boundary: &Boundary, skin: f64) {
        let cells: Vec<u32> = x.iter().map(|p| grid.cell(p)).map(|(cx, cy)| (cy * grid.nx + cx) as u32).collect();
        bin_into_cells(&cells, grid.nx * grid.ny, &mut self.cell_start, &mut self.cell_items);
        self.start.clear();
        self.list.clear();
        self.start.push(0);
        let mut around = [0; 9];
        for (g, &c) in cells.iter().enumerate() {
            let from = self.list.len();
            let c = c as usize;
            let m = grid.around(c % grid.nx, c / grid.nx, &mut around);
            for &d in &around[..m] {
                for &q in &self.cell_items[self.cell_start[d] as usize..self.cell_start[d + 1] as usize] {
                    let q = q as usize;
                    let reach = r[g] + r[q] + skin;
                    if q != g && boundary.image(x[g] - x[q]).norm_squared() < reach * reach {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::cells::cell_pairs;
    use crate::kernels::threads::Threads;

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
}
