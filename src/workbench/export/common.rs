//! What every deck and its readers share: the reference codes, what an exported deck
//! measures ([`ExportInfo`]) and the columns of its raw output, the escaping of the scene
//! name, and floats written to read back the same.

use std::fmt::Write as _;

use serde::Serialize;

use crate::scene::Analysis;

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
    /// `impact` (writes series.txt) or `shear` (writes walls.txt).
    pub analysis: Analysis,
    pub time_step_s: f64,
    pub steps: u64,
    /// Steps per row of walls.txt.
    pub sample_every: u64,
    pub free_grains: usize,
    /// Length of the periodic cell, m, and depth for stresses, m (shear scenes).
    pub length_m: f64,
    pub depth_m: f64,
    /// Radii, m, and masses, kg, of the free grains (impact scenes).
    pub radii_m: Vec<f64>,
    pub masses_kg: Vec<f64>,
    /// The flat wall an impact scene's grain hits: y (m), side (+1 bottom, -1 top),
    /// x velocity (m/s).
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

/// Columns of walls.txt.
pub fn wall_columns() -> Vec<String> {
    ["step", "bottom_fx_n", "bottom_fy_n", "top_fx_n", "top_fy_n", "gap_m"].map(String::from).to_vec()
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
