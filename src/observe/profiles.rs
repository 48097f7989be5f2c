//! Profiles across the gap: the free grains between the walls' contact surfaces
//! ([`crate::physics::walls::Wall::contact_surface`]) cut into horizontal layers of
//! about one mean grain diameter each (their number fixed at the first sample, their
//! thickness following the gap), and in each layer at each sample:
//! - the mean x and y velocity (mass-weighted, grains by their centre), m/s;
//! - the solid fraction: the disks' area inside the layer (each disk cut exactly by the
//!   layer's lines) over the layer's area;
//! - the granular temperature `T = <|v - <v>|^2> / 2`, m^2/s^2 (mass-weighted, about the
//!   layer's mean velocity; per degree of freedom of the plane);
//! - the stress tensor, Pa, tension positive: the grains' stress times volume
//!   ([`crate::observe::packing::grain_stress_volumes`], by centre) less
//!   `m (v - <v>)(v - <v>)`, over the layer's volume L_x t h.
//!
//! [`profile_summary`] averages each over the samples of an averaging window with a 95%
//! interval from block averages, and derives each layer's shear rate (the centred
//! difference of the mean x velocity), pressure P = -(sigma_xx + sigma_yy) / 2 and
//! inertial number I = gamma_dot d / sqrt(P / rho) (d the free grains' mean diameter,
//! rho their density) and friction |sigma_yx| / P.

use serde::{Deserialize, Serialize};

use crate::engine::world::View;
use crate::observe::packing::grain_stress_volumes;
use crate::observe::stats::{Blocking, Estimate, estimate};
use crate::scene::limits::MAX_PROFILE_LAYERS;

/// The layers of one sample: their bounds and values.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct ProfileSample {
    pub time_s: f64,
    /// The bottom and top walls' contact surfaces, m.
    pub bottom_m: f64,
    pub top_m: f64,
    /// Per layer, bottom first: [vx, vy, solid fraction, temperature, sigma_xx,
    /// sigma_xy, sigma_yx, sigma_yy] ([`QUANTITIES`]).
    pub layers: Vec<[f64; QUANTITIES.len()]>,
}

/// The quantities of a layer, in [`ProfileSample::layers`]' order, with their units.
pub const QUANTITIES: [&str; 8] = ["velocity_x_m_s", "velocity_y_m_s", "solid_fraction", "granular_temperature_m2_s2", "sigma_xx_pa", "sigma_xy_pa", "sigma_yx_pa", "sigma_yy_pa"];

/// The free grains' mean diameter, m (0 without free grains).
pub fn mean_diameter<D: crate::physics::dim::Dim>(p: &crate::physics::particles::Particles<D>) -> f64 {
    if p.n_free == 0 { 0.0 } else { 2.0 * p.r[..p.n_free].iter().sum::<f64>() / p.n_free as f64 }
}

/// The number of layers for the gap between `v`'s walls: about one mean free-grain
/// diameter each, at least 1, at most [`MAX_PROFILE_LAYERS`] (the memory estimate's
/// bound); none without two walls or free grains.
pub fn layer_count(v: &View) -> Option<usize> {
    let p = v.particles;
    if v.walls.len() != 2 || p.n_free == 0 {
        return None;
    }
    let d = mean_diameter(p);
    let gap = v.walls[1].contact_surface() - v.walls[0].contact_surface();
    (gap > 0.0 && d > 0.0).then(|| ((gap / d).round().min(MAX_PROFILE_LAYERS as f64) as usize).clamp(1, p.n_free))
}

/// The area of a disk of radius `r` below the line `u` above its centre, m^2.
fn area_below(u: f64, r: f64) -> f64 {
    let u = u.clamp(-r, r);
    r * r * (std::f64::consts::FRAC_PI_2 + (u / r).asin()) + u * (r * r - u * u).max(0.0).sqrt()
}

/// The sample of `v` in `layers` layers, with the contacts recorded at this step
/// ([`View::contacts`]); the cell's length and depth, m. None without two walls with a
/// gap between them.
pub fn profile_sample(v: &View, layers: usize, length: f64, depth: f64) -> Option<ProfileSample> {
    let p = v.particles;
    if v.walls.len() != 2 || layers == 0 {
        return None;
    }
    let (lo, hi) = (v.walls[0].contact_surface(), v.walls[1].contact_surface());
    let h = (hi - lo) / layers as f64;
    if !(h > 0.0) {
        return None;
    }
    let layer_of = |y: f64| (((y - lo) / h).floor().max(0.0) as usize).min(layers - 1);
    let stress = grain_stress_volumes(v);
    // Per layer: mass, momentum, contact stress times volume, solid area.
    let mut mass = vec![0.0f64; layers];
    let mut mom = vec![[0.0f64; 2]; layers];
    let mut contact = vec![[0.0f64; 4]; layers];
    let mut area = vec![0.0f64; layers];
    for i in 0..p.n_free {
        let (x, r) = (p.x[i], p.r[i]);
        let k = layer_of(x.y);
        mass[k] += p.m[i];
        mom[k][0] += p.m[i] * p.v[i].x;
        mom[k][1] += p.m[i] * p.v[i].y;
        for (c, s) in contact[k].iter_mut().zip(stress[i]) {
            *c += s;
        }
        let (first, last) = (layer_of(x.y - r), layer_of(x.y + r));
        for (l, a) in area.iter_mut().enumerate().take(last + 1).skip(first) {
            let (bottom, top) = (lo + l as f64 * h, lo + (l + 1) as f64 * h);
            *a += area_below(top - x.y, r) - area_below(bottom - x.y, r);
        }
    }
    let mean: Vec<[f64; 2]> = (0..layers).map(|k| if mass[k] > 0.0 { [mom[k][0] / mass[k], mom[k][1] / mass[k]] } else { [0.0; 2] }).collect();
    let mut kinetic = vec![[0.0f64; 4]; layers];
    for i in 0..p.n_free {
        let k = layer_of(p.x[i].y);
        let u = [p.v[i].x - mean[k][0], p.v[i].y - mean[k][1]];
        for a in 0..2 {
            for b in 0..2 {
                kinetic[k][2 * a + b] += p.m[i] * u[a] * u[b];
            }
        }
    }
    let volume = length * depth * h;
    let rows = (0..layers)
        .map(|k| {
            let temperature = if mass[k] > 0.0 { 0.5 * (kinetic[k][0] + kinetic[k][3]) / mass[k] } else { 0.0 };
            let s = |c: usize| (contact[k][c] - kinetic[k][c]) / volume;
            [mean[k][0], mean[k][1], area[k] / (length * h), temperature, s(0), s(1), s(2), s(3)]
        })
        .collect();
    Some(ProfileSample { time_s: v.time, bottom_m: lo, top_m: hi, layers: rows })
}

/// One layer of a profile, time-averaged: a row of `profiles.csv`. Each quantity of
/// [`QUANTITIES`] has its mean and the half-width of its 95% interval (`_ci95`).
#[derive(Clone, Debug, Default, Serialize, PartialEq)]
pub struct LayerProfile {
    pub layer: usize,
    /// The layer's centre over the gap, from the bottom wall's contact surface (0) to
    /// the top wall's (1).
    pub y_over_gap: f64,
    /// The layer's centre, m (mean over the samples).
    pub y_m: f64,
    pub velocity_x_m_s: f64,
    pub velocity_x_m_s_ci95: f64,
    pub velocity_y_m_s: f64,
    pub velocity_y_m_s_ci95: f64,
    pub solid_fraction: f64,
    pub solid_fraction_ci95: f64,
    pub granular_temperature_m2_s2: f64,
    pub granular_temperature_m2_s2_ci95: f64,
    pub sigma_xx_pa: f64,
    pub sigma_xx_pa_ci95: f64,
    pub sigma_xy_pa: f64,
    pub sigma_xy_pa_ci95: f64,
    pub sigma_yx_pa: f64,
    pub sigma_yx_pa_ci95: f64,
    pub sigma_yy_pa: f64,
    pub sigma_yy_pa_ci95: f64,
    /// `d<vx>/dy`, 1/s: centred differences of the mean x velocity (one-sided at the walls).
    pub shear_rate_1_s: f64,
    /// -(sigma_xx + sigma_yy) / 2, Pa.
    pub pressure_pa: f64,
    /// gamma_dot d / sqrt(P / rho); empty where P is not positive.
    pub inertial_number: Option<f64>,
    /// The layer's friction mu = |sigma_yx| / P (mu(I) with [`LayerProfile::inertial_number`]);
    /// empty where P is not positive.
    pub friction: Option<f64>,
    /// Its 95% half-width: the ratio taken in each block (as many blocks as the fewer of
    /// sigma_yx's and P's automatic or fixed count, at least 2), Student's t over the
    /// block ratios; empty where a block's P is not positive. Checked against the
    /// run-to-run spread (1000-grain cell, 100 kPa, +-0.6 m/s, 4 packing seeds, 20 bulk
    /// layers): the spread over seeds is 1.11 (quartiles 0.89-1.42) times the interval
    /// over 1.96, where propagating the stresses' intervals gave 0.77 (docs/rheology.md).
    pub friction_ci95: Option<f64>,
}

/// The time-averaged profile of `samples` (all with the same number of layers), each
/// quantity's interval from block averages as `blocking` says; `diameter` the free
/// grains' mean diameter, m, and `density` their density, kg/m^3, for the inertial
/// number. None with fewer than 4 samples.
pub fn profile_summary(samples: &[ProfileSample], blocking: Blocking, diameter: f64, density: f64) -> Option<Vec<LayerProfile>> {
    let n = samples.first()?.layers.len();
    if samples.len() < 4 || n == 0 || samples.iter().any(|s| s.layers.len() != n) {
        return None;
    }
    let interval = (samples[samples.len() - 1].time_s - samples[0].time_s) / (samples.len() - 1) as f64;
    let mean_of = |f: &dyn Fn(&ProfileSample) -> f64| samples.iter().map(f).sum::<f64>() / samples.len() as f64;
    let (lo, hi) = (mean_of(&|s| s.bottom_m), mean_of(&|s| s.top_m));
    let h = (hi - lo) / n as f64;
    let mut out: Vec<LayerProfile> = (0..n)
        .map(|k| {
            let series = |q: usize| samples.iter().map(|s| s.layers[k][q]).collect::<Vec<_>>();
            let est = |q: usize| -> Estimate { estimate(&series(q), blocking, interval) };
            let q = |q: usize| {
                let e = est(q);
                (e.mean, e.ci95)
            };
            let (vx, vy, phi, t, sxx, sxy, syx, syy) = (q(0), q(1), q(2), q(3), q(4), q(5), q(6), q(7));
            let pressure: Vec<f64> = samples.iter().map(|s| -0.5 * (s.layers[k][4] + s.layers[k][7])).collect();
            let blocks = est(6).blocks.min(estimate(&pressure, blocking, interval).blocks);
            let friction_ci95 = ratio_interval(&series(6), &pressure, blocks);
            LayerProfile {
                layer: k,
                y_over_gap: (k as f64 + 0.5) / n as f64,
                y_m: lo + (k as f64 + 0.5) * h,
                velocity_x_m_s: vx.0,
                velocity_x_m_s_ci95: vx.1,
                velocity_y_m_s: vy.0,
                velocity_y_m_s_ci95: vy.1,
                solid_fraction: phi.0,
                solid_fraction_ci95: phi.1,
                granular_temperature_m2_s2: t.0,
                granular_temperature_m2_s2_ci95: t.1,
                sigma_xx_pa: sxx.0,
                sigma_xx_pa_ci95: sxx.1,
                sigma_xy_pa: sxy.0,
                sigma_xy_pa_ci95: sxy.1,
                sigma_yx_pa: syx.0,
                sigma_yx_pa_ci95: syx.1,
                sigma_yy_pa: syy.0,
                sigma_yy_pa_ci95: syy.1,
                pressure_pa: -0.5 * (sxx.0 + syy.0),
                friction_ci95,
                ..LayerProfile::default()
            }
        })
        .collect();
    for k in 0..n {
        let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
        let rate = if b > a { (out[b].velocity_x_m_s - out[a].velocity_x_m_s) / ((b - a) as f64 * h) } else { 0.0 };
        let l = &mut out[k];
        l.shear_rate_1_s = rate;
        let p = l.pressure_pa;
        l.inertial_number = (p > 0.0).then(|| rate.abs() * diameter / (p / density).sqrt()).filter(|i| i.is_finite());
        l.friction = (p > 0.0).then(|| l.sigma_yx_pa.abs() / p).filter(|m| m.is_finite());
    }
    Some(out)
}

/// The 95% half-width of |sum num| / sum den over `blocks` equal blocks (at least 2; a
/// remainder of samples goes to the last block): Student's t over the block ratios.
/// None where a block's `den` sum is not positive or fewer than 4 samples.
fn ratio_interval(num: &[f64], den: &[f64], blocks: usize) -> Option<f64> {
    let n = num.len().min(den.len());
    if n < 4 {
        return None;
    }
    let b = blocks.clamp(2, n / 2);
    let len = n / b;
    let mut ratios = Vec::with_capacity(b);
    for j in 0..b {
        let r = j * len..if j + 1 == b { n } else { (j + 1) * len };
        let d: f64 = den[r.clone()].iter().sum();
        if !(d > 0.0) {
            return None;
        }
        ratios.push(num[r].iter().sum::<f64>().abs() / d);
    }
    let m = ratios.iter().sum::<f64>() / b as f64;
    let sd = (ratios.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (b - 1) as f64).sqrt();
    Some(crate::observe::stats::t975(b - 1) * sd / (b as f64).sqrt()).filter(|x| x.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_disks_area_between_lines_is_exact() {
        // Whole disk, halves, and a strip through the centre: 2 (r^2 asin(u/r) + u
        // sqrt(r^2 - u^2)) for |u| below r (the integral of the chord 2 sqrt(r^2 - y^2)).
        let r = 2.0;
        assert!((area_below(5.0, r) - std::f64::consts::PI * 4.0).abs() < 1e-14);
        assert!((area_below(0.0, r) - std::f64::consts::PI * 2.0).abs() < 1e-14);
        assert_eq!(area_below(-3.0, r), 0.0);
        let strip = area_below(1.0, r) - area_below(-1.0, r);
        let exact = 2.0 * (r * r * (0.5f64).asin() + 1.0 * (r * r - 1.0f64).sqrt());
        assert!((strip - exact).abs() < 1e-13, "{strip} {exact}");
    }

    #[test]
    fn the_frictions_interval_covers_the_true_ratio_of_noisy_series() {
        // Independent noise on tau and P about 0.3 x 1e5 and 1e5: over 400 series of
        // 400 samples in 10 blocks, the 95% interval of the block ratios covers the true
        // ratio 0.3 in 92-98% of them (binomial spread of 95% over 400 is +-2.2%).
        let mut seed = 7u64;
        let mut normal = || {
            // Box-Muller from a small LCG: enough for a coverage test.
            let mut u = || {
                seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                ((seed >> 11) as f64 + 0.5) / (1u64 << 53) as f64
            };
            (-2.0 * u().ln()).sqrt() * (2.0 * std::f64::consts::PI * u()).cos()
        };
        let mut covered = 0;
        for _ in 0..400 {
            let tau: Vec<f64> = (0..400).map(|_| 3e4 + 3e3 * normal()).collect();
            let p: Vec<f64> = (0..400).map(|_| 1e5 + 5e3 * normal()).collect();
            let half = ratio_interval(&tau, &p, 10).unwrap();
            let est = tau.iter().sum::<f64>() / p.iter().sum::<f64>();
            covered += ((est - 0.3).abs() <= half) as usize;
        }
        assert!((368..=392).contains(&covered), "covered {covered} of 400");
        assert!(ratio_interval(&[1.0; 8], &[-1.0; 8], 2).is_none());
    }
}
