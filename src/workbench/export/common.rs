//! What every deck and its readers share: the reference codes, what an exported deck
//! measures ([`ExportInfo`]) and the columns of its raw output, the escaping of the scene
//! name, and floats written to read back the same.

use std::fmt::Write as _;

use serde::Serialize;

use crate::scene::{Analysis, Dimension};

/// The reference codes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, clap::ValueEnum, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Code {
    Liggghts,
    Yade,
    Lammps,
}

impl Code {
    pub fn name(self) -> &'static str {
        match self {
            Code::Liggghts => "liggghts",
            Code::Yade => "yade",
            Code::Lammps => "lammps",
        }
    }
    /// The deck's file name.
    pub fn deck(self) -> &'static str {
        match self {
            Code::Liggghts => "in.liggghts",
            Code::Yade => "yade.py",
            Code::Lammps => "in.lammps",
        }
    }
}

/// What an exported deck measures, for the scripts that read its output.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct ExportInfo {
    pub scene: String,
    /// The scene's dimension: 2 (spheres in the plane, the default, left out of the file
    /// so that a 2D export.json keeps its bytes) or 3 (spheres in space: 3-component
    /// columns, [`impact_columns_in`] and [`wall_columns_in`]).
    #[serde(default, skip_serializing_if = "Dimension::is_two")]
    pub dimension: Dimension,
    /// `impact` (writes series.txt) or `shear` (writes walls.txt).
    pub analysis: Analysis,
    pub time_step_s: f64,
    pub steps: u64,
    /// Steps per row of walls.txt.
    pub sample_every: u64,
    pub free_grains: usize,
    /// Length of the periodic cell (x), m, and depth for stresses, m (shear scenes): in 3D
    /// the cell's z length the engine divides the wall forces by (`Built::depth`).
    pub length_m: f64,
    pub depth_m: f64,
    /// Radii, m, and masses, kg, of the free grains (impact scenes).
    pub radii_m: Vec<f64>,
    pub masses_kg: Vec<f64>,
    /// The flat wall an impact scene's grain hits: y (m), side (+1 bottom, -1 top),
    /// x velocity (m/s). In 3D too: a wall's z velocity is always 0 (a scene gives walls
    /// an x velocity only; the export refuses any other, by name).
    pub flat_wall: Option<[f64; 3]>,
    /// Columns of the raw output file.
    pub columns: Vec<String>,
    /// A protocol's stages (none without): each its name, first step (the steps before
    /// it), steps, and whether the summary averages it. The deck's rows carry the run's
    /// step, so each row falls in one stage.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stages: Vec<ExportStage>,
    /// How the digest averages the rows (the scene's `statistics`, as grainlab's summary).
    #[serde(default)]
    pub statistics: crate::scene::StatisticsSpec,
}

/// One stage of an exported protocol ([`ExportInfo::stages`]).
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct ExportStage {
    pub name: String,
    pub first_step: u64,
    pub steps: u64,
    /// grainlab's rows: one every this many of the stage's steps, and at its last (the
    /// decks record every step of a protocol; the digest averages them into these rows).
    pub sample_every: u64,
    pub average: bool,
}

impl ExportStage {
    /// Whether a row at `time_s` (its step times `dt`, s, as the rows' times are) falls
    /// in this stage: after its first step's start, up to its last step.
    pub fn holds(&self, time_s: f64, dt: f64) -> bool {
        time_s > self.first_step as f64 * dt && time_s <= (self.first_step + self.steps) as f64 * dt
    }
}

/// Columns of series.txt for an impact scene with `two` grains (else one grain on a wall).
pub fn impact_columns(two: bool) -> Vec<String> {
    let mut c = vec!["step".to_string()];
    for k in 0..if two { 2 } else { 1 } {
        for q in ["x_m", "y_m", "vx_m_s", "vy_m_s", "omega_rad_s", "fx_n", "fy_n"] {
            c.push(format!("{q}{k}"));
        }
    }
    c
}

/// Columns of series.txt for an impact scene with `two` grains (else one grain on a wall)
/// in `dimension`: in 2D [`impact_columns`]; in 3D, after `step`, per grain k: `x_m{k}
/// y_m{k} z_m{k}` (m), `vx_m_s{k} vy_m_s{k} vz_m_s{k}` (m/s), `omegax_rad_s{k}
/// omegay_rad_s{k} omegaz_rad_s{k}` (rad/s), `fx_n{k} fy_n{k} fz_n{k}` (N).
pub fn impact_columns_in(two: bool, dimension: Dimension) -> Vec<String> {
    if dimension.is_two() {
        return impact_columns(two);
    }
    let mut c = vec!["step".to_string()];
    for k in 0..if two { 2 } else { 1 } {
        for q in IMPACT_SPACE {
            c.push(format!("{q}{k}"));
        }
    }
    c
}

/// The quantities of one grain in a 3D series.txt row, in order ([`impact_columns_in`]).
pub(crate) const IMPACT_SPACE: [&str; 12] = ["x_m", "y_m", "z_m", "vx_m_s", "vy_m_s", "vz_m_s", "omegax_rad_s", "omegay_rad_s", "omegaz_rad_s", "fx_n", "fy_n", "fz_n"];

/// Columns of walls.txt.
pub fn wall_columns() -> Vec<String> {
    ["step", "bottom_fx_n", "bottom_fy_n", "top_fx_n", "top_fy_n", "gap_m"].map(String::from).to_vec()
}

/// Columns of walls.txt in `dimension`: in 2D [`wall_columns`]; in 3D the walls' z forces
/// too: `step bottom_fx_n bottom_fy_n bottom_fz_n top_fx_n top_fy_n top_fz_n gap_m`
/// (forces in N on the wall from the grains, averaged over the row's interval; the gap, m,
/// between the two walls' glued lattices at the row's step).
pub fn wall_columns_in(dimension: Dimension) -> Vec<String> {
    if dimension.is_two() {
        return wall_columns();
    }
    ["step", "bottom_fx_n", "bottom_fy_n", "bottom_fz_n", "top_fx_n", "top_fy_n", "top_fz_n", "gap_m"].map(String::from).to_vec()
}

/// `s` as printable ASCII on one line: `\`, quotes, control and non-ASCII characters as
/// Rust escapes (`\n`, `\u{e9}`), and each of `also` as `\u{..}`. This is how the
/// scene name enters the decks' comments and the title line of grains.data: no line
/// break can start a command (LIGGGHTS) or a statement (Python), and nothing outside
/// printable ASCII reaches a reader that assumes an encoding.
pub fn escaped(s: &str, also: &[char]) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        if also.contains(&c) {
            let _ = write!(out, "\\u{{{:x}}}", c as u32);
        } else {
            out.extend(c.escape_default());
        }
    }
    out
}

/// Format a float so that it reads back to the same f64.
pub(crate) fn f(v: f64) -> String {
    format!("{v:.17e}")
}

/// Two per-contact values the decks take as one (within 1e-12 relative; 0 only equals 0).
pub(crate) fn same_value(x: f64, m: f64) -> bool {
    (x - m).abs() <= 1e-12 * m.abs()
}

/// What a deck needs of the contacts each pair of materials can make: the distinct values
/// (to 1e-12) of `key(a, b, m*, R*)` over the contacts between grains of materials a and
/// b, indexed `[a * n + b]` (both orders), and of `key(wall material, a, m, r)` over each
/// flat wall's contacts with the free grains of material a, `[wall][a]` (R* = r, m* = m).
/// Contacts: free grains with free grains (a material's grain with another of its own
/// only if it has two), free grains with glued ones. The decks need only the first value
/// and whether there is a second, so each list stops at two distinct values. Each
/// material's grains are read as their first three distinct (m, r) free and two glued: a
/// material's grains are of one density, so distinct grains differ in mass, and the keys
/// the decks use (the reduced mass; the derived spring's kn, which grows with R* and m*)
/// grow with a partner's mass, so three of them already give two values with any grain
/// (two with a grain of their own). The work is linear in the grains (a million-grain
/// packing of all-different radii is read in one pass).
pub(crate) struct ContactKinds {
    pub pairs: Vec<Vec<f64>>,
    pub walls: Vec<Vec<Vec<f64>>>,
}

pub(crate) fn contact_kinds<D: crate::physics::dim::Dim>(n: usize, p: &crate::physics::particles::Particles<D>, walls: &[crate::physics::walls::Wall<D>], key: impl Fn(usize, usize, f64, f64) -> f64) -> ContactKinds {
    let same = same_value;
    let add = |list: &mut Vec<f64>, k: f64| {
        if list.len() < 2 && !list.iter().any(|&v| same(k, v)) {
            list.push(k);
        }
    };
    // Each material's distinct (m, r) of free grains, with how many, and of glued grains.
    let mut free: Vec<Vec<((f64, f64), usize)>> = vec![Vec::new(); n];
    let mut glued: Vec<Vec<((f64, f64), usize)>> = vec![Vec::new(); n];
    for k in 0..p.len() {
        let (m, r, mat) = (p.m[k], p.r[k], p.material[k] as usize);
        let (list, cap) = if k < p.n_free { (&mut free[mat], 3) } else { (&mut glued[mat], 2) };
        match list.iter().position(|((x, y), _)| same(*x, m) && same(*y, r)) {
            Some(j) => list[j].1 += 1,
            None if list.len() < cap => list.push(((m, r), 1)),
            None => {}
        }
    }
    let reduced = crate::physics::material::reduced;
    let mut pairs = vec![Vec::new(); n * n];
    // A contact of materials a and b at (m*, R*), listed for both orders.
    let meet = |pairs: &mut Vec<Vec<f64>>, a: usize, b: usize, m: f64, r: f64| {
        let k = key(a, b, m, r);
        add(&mut pairs[a * n + b], k);
        add(&mut pairs[b * n + a], k);
    };
    for a in 0..n {
        for (ka, &((ma, ra), ca)) in free[a].iter().enumerate() {
            for (b, fb) in free.iter().enumerate().skip(a) {
                for (kb, &((mb, rb), _)) in fb.iter().enumerate() {
                    if b > a || kb > ka || (kb == ka && ca > 1) {
                        meet(&mut pairs, a, b, reduced(ma, mb), reduced(ra, rb));
                    }
                }
            }
            for (b, g) in glued.iter().enumerate() {
                for &((mb, rb), _) in g {
                    meet(&mut pairs, a, b, reduced(ma, mb), reduced(ra, rb));
                }
            }
        }
    }
    let walls = walls
        .iter()
        .map(|w| {
            let mut per = vec![Vec::new(); n];
            if w.is_flat() {
                for (a, fa) in free.iter().enumerate() {
                    for &((m, r), _) in fa {
                        add(&mut per[a], key(w.material, a, m, r));
                    }
                }
            }
            per
        })
        .collect();
    ContactKinds { pairs, walls }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Grains of radii `r` (m) and density 2500 kg/m^3, the first `n_free` free.
    fn grains(r: &[f64], n_free: usize) -> crate::physics::particles::Particles {
        let mut p = crate::physics::particles::Particles::default();
        for &r in r {
            let m = 4.0 / 3.0 * std::f64::consts::PI * r * r * r * 2500.0;
            p.push(crate::physics::dim::Vec2::zeros(), crate::physics::dim::Vec2::zeros(), 0.0, r, m, 0.4 * m * r * r, 0);
        }
        p.n_free = n_free;
        p
    }

    #[test]
    fn contact_kinds_tell_one_from_several_in_one_pass() {
        // 100 000 free grains of all-different radii and two glued ones: every list holds
        // the first two kinds found, read in one pass (listing every kind, as the first
        // version did, never finished on the 5000-grain cell).
        let n = 100_000;
        let r: Vec<f64> = (0..n + 2).map(|k| 1e-3 * (1.0 + k as f64 / n as f64)).collect();
        let m_star = |_: usize, _: usize, m: f64, _: f64| m;
        let kinds = contact_kinds::<crate::physics::dim::Plane>(1, &grains(&r, n), &[], m_star);
        assert_eq!(kinds.pairs[0].len(), 2);
        // Two equal grains: one kind; a grain of each of two sizes: one kind (they meet
        // only each other); three sizes: two.
        assert_eq!(contact_kinds(1, &grains(&[1e-3, 1e-3], 2), &[], m_star).pairs[0].len(), 1);
        assert_eq!(contact_kinds(1, &grains(&[1e-3, 2e-3], 2), &[], m_star).pairs[0].len(), 1);
        assert_eq!(contact_kinds(1, &grains(&[1e-3, 2e-3, 3e-3], 3), &[], m_star).pairs[0].len(), 2);
        // A free grain and a glued one of another size: one kind.
        assert_eq!(contact_kinds(1, &grains(&[1e-3, 2e-3], 1), &[], m_star).pairs[0].len(), 1);
        // Kinds that differ but share the key count once: every pair of the 100 000 grains
        // under a key that ignores them.
        assert_eq!(contact_kinds(1, &grains(&r, n), &[], |_, _, _, _| 0.0).pairs[0].len(), 1);
    }
}
