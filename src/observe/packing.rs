//! Inside the packing, from the contacts of one step ([`View::contacts`]): the stress
//! tensor of the free grains (contact and kinetic parts), the coordination number with
//! and without rattlers, the fraction of sliding contacts, and the fabric tensor.
//!
//! **Stress** (tension positive, as LAMMPS' `stress/atom` and YADE's `getStress`): the
//! mean over the free grains' region of the grains' stresses,
//! sigma_ab = (1/V) [sum over grains p, contacts c of p: (x_c - x_p)_a f_c,b minus
//! sum over grains p: m_p v'_a v'_b], with v' a grain's velocity less the free grains'
//! mean (the kinetic part). A grain-grain contact adds -l_a f_b (l from j to i, f on i),
//! whatever its contact point; a contact with a wall (flat, or a grain glued to a rough
//! wall) adds (x_c - x_i)_a f_b. The volume V = L_x t H, with t the scene's depth (the
//! walls' stress convention, [`crate::observe::stress`]) and H the distance between the
//! walls' contact points (each wall's mean contact height, weighted by the normal force
//! it carries): the surfaces the walls' stresses act on. So in steady shear, on time
//! average, sigma_yy = -sigma (the walls' normal stress) and sigma_yx = tau: momentum
//! balance, which `tests/packing.rs` asserts.
//!
//! **Coordination** Z: contacts per free grain (a contact with a wall counts for its
//! grain). Rattlers: free grains with fewer than 2 contacts, removed one round after
//! another (removing one lowers its partners' counts) until none is left; Z without them
//! counts the rest. **Fabric**: F = mean of n n over the contacts of free grains (trace 1),
//! its anisotropy a = 2 (lambda_max - lambda_min) and the major axis' angle from x.

use serde::{Deserialize, Serialize};

use crate::engine::world::View;
use crate::physics::contact::{ContactRecord, Partner};
use crate::observe::stats::{Blocking, Estimate, estimate};
use crate::physics::dim::Vec2;

/// What the contacts of one step say of the packing inside.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct PackingRow {
    pub time_s: f64,
    /// Contacts touching at least one free grain.
    pub contacts: usize,
    pub coordination: f64,
    pub coordination_without_rattlers: f64,
    pub rattlers: usize,
    pub sliding_fraction: Option<f64>,
    /// The stress tensor of the free grains, Pa (tension positive): sigma_ab from
    /// positions along a and forces along b; the contact part and the kinetic part.
    pub sigma_xx_pa: f64,
    pub sigma_xy_pa: f64,
    pub sigma_yx_pa: f64,
    pub sigma_yy_pa: f64,
    pub kinetic_xx_pa: f64,
    pub kinetic_xy_pa: f64,
    pub kinetic_yy_pa: f64,
    /// Height H between the walls' contact surfaces, m (the volume is L_x t H).
    pub height_m: f64,
    pub fabric_xx: f64,
    pub fabric_xy: f64,
    pub fabric_yy: f64,
    pub fabric_anisotropy: f64,
    /// Angle of the fabric's major axis from x, degrees, in (-90, 90].
    pub fabric_angle_deg: f64,
}

/// Which wall a contact's partner belongs to: a flat wall by number, a glued grain by
/// the nearer wall.
fn wall_of(c: &ContactRecord, v: &View) -> Option<usize> {
    let n_free = v.particles.n_free as u32;
    match c.partner {
        Partner::Wall(k) => Some(k as usize),
        Partner::Grain(j) if j >= n_free => {
            let y = v.particles.x[j as usize].y;
            v.walls.iter().enumerate().min_by(|a, b| (a.1.y - y).abs().total_cmp(&(b.1.y - y).abs())).map(|(k, _)| k)
        }
        Partner::Grain(_) => None,
    }
}

/// The row of the contacts in `v` (recorded at this step): `None` without two walls, or
/// without contacts on both (no height to divide by).
pub fn packing_row(v: &View, length: f64, depth: f64) -> Option<PackingRow> {
    let p = v.particles;
    let n_free = p.n_free;
    if v.walls.len() != 2 || n_free == 0 {
        return None;
    }
    let contacts: Vec<&ContactRecord> = v.contacts.iter().filter(|c| (c.i as usize) < n_free).collect();
    // Each wall's contact height, weighted by the normal force it carries.
    let mut height = [(0.0f64, 0.0f64); 2];
    let mut sum = [[0.0f64; 2]; 2];
    let mut counts = vec![0u32; n_free];
    let mut links: Vec<(usize, Option<usize>)> = Vec::with_capacity(contacts.len());
    let (mut sliding, mut fabric) = (0usize, [[0.0f64; 2]; 2]);
    for c in &contacts {
        let i = c.i as usize;
        let f = c.force();
        let arm = match wall_of(c, v) {
            Some(k) => {
                let w = c.normal_force.abs();
                height[k.min(1)].0 += w * c.point.y;
                height[k.min(1)].1 += w;
                links.push((i, None));
                c.point - p.x[i]
            }
            None => {
                links.push((i, match c.partner { Partner::Grain(j) => Some(j as usize), Partner::Wall(_) => None }));
                -c.branch
            }
        };
        for a in 0..2 {
            for b in 0..2 {
                sum[a][b] += arm[a] * f[b];
                fabric[a][b] += c.normal[a] * c.normal[b];
            }
        }
        sliding += c.sliding as usize;
    }
    if height.iter().any(|h| !(h.1 > 0.0)) {
        return None;
    }
    let h = (height[1].0 / height[1].1 - height[0].0 / height[0].1).abs();
    let volume = length * depth * h;
    if !(volume > 0.0) {
        return None;
    }
    // Kinetic part: velocities less the free grains' mean.
    let mass: f64 = p.m[..n_free].iter().sum();
    let mean = (0..n_free).fold(Vec2::zeros(), |s, i| s + p.v[i] * p.m[i]) / mass;
    let mut kin = [[0.0f64; 2]; 2];
    for i in 0..n_free {
        let u = p.v[i] - mean;
        for a in 0..2 {
            for b in 0..2 {
                kin[a][b] -= p.m[i] * u[a] * u[b];
            }
        }
    }
    // Coordination, and rattlers removed round by round.
    for &(i, j) in &links {
        counts[i] += 1;
        if let Some(j) = j.filter(|&j| j < n_free) {
            counts[j] += 1;
        }
    }
    let z = counts.iter().map(|&c| c as f64).sum::<f64>() / n_free as f64;
    let mut rattler = vec![false; n_free];
    loop {
        let newly: Vec<bool> = (0..n_free).map(|i| !rattler[i] && counts[i] < 2).collect();
        if !newly.contains(&true) {
            break;
        }
        for &(i, j) in &links {
            if let Some(j) = j.filter(|&j| j < n_free) {
                if newly[i] && !rattler[j] {
                    counts[j] = counts[j].saturating_sub(1);
                }
                if newly[j] && !rattler[i] {
                    counts[i] = counts[i].saturating_sub(1);
                }
            }
        }
        for i in 0..n_free {
            rattler[i] |= newly[i];
        }
    }
    let rattlers = rattler.iter().filter(|&&r| r).count();
    let kept = n_free - rattlers;
    let z_kept = if kept > 0 { (0..n_free).filter(|&i| !rattler[i]).map(|i| counts[i] as f64).sum::<f64>() / kept as f64 } else { 0.0 };
    let nc = contacts.len().max(1) as f64;
    let (fxx, fxy, fyy) = (fabric[0][0] / nc, fabric[0][1] / nc, fabric[1][1] / nc);
    let half_diff = (0.25 * (fxx - fyy).powi(2) + fxy * fxy).sqrt();
    Some(PackingRow {
        time_s: v.time,
        contacts: contacts.len(),
        coordination: z,
        coordination_without_rattlers: z_kept,
        rattlers,
        sliding_fraction: (!contacts.is_empty()).then(|| sliding as f64 / contacts.len() as f64),
        sigma_xx_pa: (sum[0][0] + kin[0][0]) / volume,
        sigma_xy_pa: (sum[0][1] + kin[0][1]) / volume,
        sigma_yx_pa: (sum[1][0] + kin[1][0]) / volume,
        sigma_yy_pa: (sum[1][1] + kin[1][1]) / volume,
        kinetic_xx_pa: kin[0][0] / volume,
        kinetic_xy_pa: kin[0][1] / volume,
        kinetic_yy_pa: kin[1][1] / volume,
        height_m: h,
        fabric_xx: fxx,
        fabric_xy: fxy,
        fabric_yy: fyy,
        fabric_anisotropy: 4.0 * half_diff,
        fabric_angle_deg: 0.5 * (2.0 * fxy).atan2(fxx - fyy).to_degrees(),
    })
}

/// Each grain's stress times its volume from the contacts in `v` (recorded at this
/// step), N m, tension positive, `[xx, xy, yx, yy]` with positions along the first
/// index and forces along the second: the sum over the grain's contacts of
/// (x_c - x_p)_a f_b, with x_c the contact point and f the force on the grain (the
/// contact part of the grain's Cauchy stress times its volume, as YADE's
/// `bodyStressTensors`; LIGGGHTS' `stress/atom` splits a pair's r_ij f_ij half and half,
/// which sums to the same over the grains). Glued grains get theirs too; a flat wall
/// none. Divide by a grain's volume for its mean stress; summed over the free grains,
/// the contact part of [`PackingRow`]'s stress times its volume.
pub fn grain_stress_volumes(v: &View) -> Vec<[f64; 4]> {
    let p = v.particles;
    let mut s = vec![[0.0f64; 4]; p.len()];
    let mut add = |k: usize, arm: Vec2, f: Vec2| {
        s[k][0] += arm.x * f.x;
        s[k][1] += arm.x * f.y;
        s[k][2] += arm.y * f.x;
        s[k][3] += arm.y * f.y;
    };
    for c in v.contacts {
        let i = c.i as usize;
        let f = c.force();
        let arm = c.point - p.x[i];
        add(i, arm, f);
        if let Partner::Grain(j) = c.partner {
            // The partner's image next to grain i: x_i - branch.
            add(j as usize, arm + c.branch, -f);
        }
    }
    s
}

/// Each grain's number of contacts in `v` (a wall contact counts for its grain).
pub fn grain_contacts(v: &View) -> Vec<u32> {
    let mut n = vec![0u32; v.particles.len()];
    for c in v.contacts {
        n[c.i as usize] += 1;
        if let Partner::Grain(j) = c.partner {
            n[j as usize] += 1;
        }
    }
    n
}

/// The time averages of the packing rows of an averaging window, each with a 95%
/// interval from block averages (as the wall stresses'; `summary.json`'s
/// `shear.packing`).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct PackingSummary {
    pub rows: usize,
    pub sigma_xx_pa: Estimate,
    pub sigma_xy_pa: Estimate,
    pub sigma_yx_pa: Estimate,
    pub sigma_yy_pa: Estimate,
    pub coordination: Estimate,
    pub coordination_without_rattlers: Estimate,
    pub rattlers: Estimate,
    pub sliding_fraction: Option<Estimate>,
    pub fabric_xx: Estimate,
    pub fabric_xy: Estimate,
    pub fabric_yy: Estimate,
    pub fabric_anisotropy: Estimate,
}

/// The summary of `rows` (evenly spaced in time), blocks as `blocking` says; none with
/// fewer than 4 rows.
pub fn packing_summary(rows: &[PackingRow], blocking: Blocking) -> Option<PackingSummary> {
    if rows.len() < 4 {
        return None;
    }
    let interval = (rows[rows.len() - 1].time_s - rows[0].time_s) / (rows.len() - 1) as f64;
    let est = |f: fn(&PackingRow) -> f64| estimate(&rows.iter().map(f).collect::<Vec<_>>(), blocking, interval);
    let sliding: Vec<f64> = rows.iter().filter_map(|r| r.sliding_fraction).collect();
    Some(PackingSummary {
        rows: rows.len(),
        sigma_xx_pa: est(|r| r.sigma_xx_pa),
        sigma_xy_pa: est(|r| r.sigma_xy_pa),
        sigma_yx_pa: est(|r| r.sigma_yx_pa),
        sigma_yy_pa: est(|r| r.sigma_yy_pa),
        coordination: est(|r| r.coordination),
        coordination_without_rattlers: est(|r| r.coordination_without_rattlers),
        rattlers: est(|r| r.rattlers as f64),
        sliding_fraction: (sliding.len() >= 4).then(|| estimate(&sliding, blocking, interval)),
        fabric_xx: est(|r| r.fabric_xx),
        fabric_xy: est(|r| r.fabric_xy),
        fabric_yy: est(|r| r.fabric_yy),
        fabric_anisotropy: est(|r| r.fabric_anisotropy),
    })
}
