//! Initial packings: seeded radii and a dense random packing by overlap relaxation.
//!
//! Grains are dropped at random into a region sized for a target packing fraction and
//! pushed apart pair by pair until no overlap exceeds a tiny tolerance. The result is a
//! dense, disordered packing that the confining wall compresses only a little, so a
//! shear run does not start with a violent collapse.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, LogNormal, Normal};
use serde::{Deserialize, Serialize};

use crate::boundary::Boundary;
use crate::dim::Vec2;
use crate::error::{Error, check};
use crate::neighbor::cell_pairs;
use crate::threads::Threads;

/// A distribution of radii, m. Normal and lognormal draws are truncated to [min, max].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
        if let RadiusDist::Normal { std, .. } = self {
            check(*std >= 0.0, at, "std", std, ">= 0 m")?;
        }
        if let RadiusDist::Lognormal { sigma, .. } = self {
            check(*sigma >= 0.0, at, "sigma", sigma, ">= 0")?;
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

/// Place grains of radii `r` in the rectangle `[x0, x1] x [y0, y1]` (periodic in x when
/// `periodic`), randomly, then relax the overlaps. Returns the centres.
pub fn relaxed_packing(r: &[f64], x0: f64, x1: f64, y0: f64, y1: f64, periodic: bool, seed: u64) -> Vec<Vec2> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x9e37_79b9_7f4a_7c15);
    let boundary = if periodic { Boundary::periodic_x(x0, x1 - x0) } else { Boundary::open() };
    let mut x: Vec<Vec2> = r
        .iter()
        .map(|&ri| {
            let (lo, hi) = if periodic { (x0, x1) } else { (x0 + ri, (x1 - ri).max(x0 + ri)) };
            Vec2::new(rng.random_range(lo..=hi), rng.random_range((y0 + ri)..=(y1 - ri).max(y0 + ri)))
        })
        .collect();
    let (mut cs, mut ci) = (Vec::new(), Vec::new());
    let r_min = r.iter().cloned().fold(f64::INFINITY, f64::min);
    // Candidate pairs within a skin, rebuilt when a grain may have crossed half of it.
    let skin = 0.2 * r_min;
    let mut pairs = Vec::new();
    let mut moved = f64::INFINITY;
    let mut moves = vec![Vec2::zeros(); x.len()];
    for _ in 0..2000 {
        if moved > 0.5 * skin {
            pairs = cell_pairs(&x, r, r.len(), &boundary, skin, &mut cs, &mut ci, &Threads::serial());
            moved = 0.0;
        }
        let mut worst: f64 = 0.0;
        moves.iter_mut().for_each(|m| *m = Vec2::zeros());
        for &[i, j] in &pairs {
            let (i, j) = (i as usize, j as usize);
            let d = boundary.image(x[i] - x[j]);
            let dist = d.norm().max(1e-12 * r_min);
            let overlap = r[i] + r[j] - dist;
            if overlap > 0.0 {
                worst = worst.max(overlap);
                let n = d / dist;
                // Split the push by size, a little more than needed to converge quickly.
                let wi = r[j] * r[j] / (r[i] * r[i] + r[j] * r[j]);
                moves[i] += 0.55 * overlap * wi * n;
                moves[j] -= 0.55 * overlap * (1.0 - wi) * n;
            }
        }
        moved += moves.iter().map(|m| m.norm()).fold(0.0, f64::max);
        for ((p, m), &ri) in x.iter_mut().zip(&moves).zip(r) {
            *p += m;
            p.y = p.y.clamp(y0 + ri, y1 - ri);
            if periodic {
                boundary.wrap(p);
            } else {
                p.x = p.x.clamp(x0 + ri, x1 - ri);
            }
        }
        if worst < 1e-4 * r_min {
            break;
        }
    }
    x
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
