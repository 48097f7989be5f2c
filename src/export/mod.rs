//! Exporting a scene to the reference codes: an equivalent LIGGGHTS 3.8 input deck and
//! YADE 2023.02 script, never hand-kept twins.
//!
//! The scene is built first, so both decks start from exactly the grains grainlab starts
//! from (a packing is generated once, here). Files written to the output directory:
//! - `grains.data`: the shared particle file, in the LAMMPS data format because that is
//!   the one LIGGGHTS reads (`atom-ID type diameter density x y z`, then velocities and
//!   spins); the YADE script parses the same file;
//! - `in.liggghts` or `yade.py`: the deck;
//! - `export.json`: what the deck measures and how to read its output ([`ExportInfo`]).
//!
//! Both decks write the same raw output in the working directory: `series.txt` (impact
//! scenes: the state of grains 1 and 2 at every step) or `walls.txt` (wall scenes: wall
//! forces averaged over each sample interval). `scripts/regen-reference` turns that into
//! the reference CSV schema.
//!
//! The exporter is exact or refuses by name: [`fields`] holds, for every scene field and
//! each code, whether it is written (and where), refused (`export to CODE: PATH = VALUE
//! cannot be expressed: WHY`), expressed approximately (a `# Differs: PATH = VALUE: ...`
//! line at the top of the deck) or not part of the physics a deck computes;
//! tests/export_fields.rs walks the scene's schema and holds the exporter to that table.
//! The scene name, the one string a deck carries, is escaped for each target
//! ([`escaped`]).

pub mod fields;
pub mod liggghts;
pub mod yade;

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use crate::build::Built;
use crate::dim::GrainShape;
use crate::error::Error;
use crate::scene::{Analysis, ControlSpec, Grains, Scene, TangentialSpec};
use crate::walls::{Control, Surface};

/// The reference codes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Code {
    Liggghts,
    Yade,
}

impl Code {
    pub fn name(self) -> &'static str {
        match self {
            Code::Liggghts => "liggghts",
            Code::Yade => "yade",
        }
    }
    /// The deck's file name.
    pub fn deck(self) -> &'static str {
        match self {
            Code::Liggghts => "in.liggghts",
            Code::Yade => "yade.py",
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

/// The part of a scene both exporters need, with the checks both share.
pub(crate) struct Exported {
    pub built: Built,
    pub info: ExportInfo,
    /// A timing deck: no recording.
    pub bench: bool,
}

pub(crate) fn prepare(scene: &Scene, code: Code, limits: &crate::limits::Limits) -> Result<Exported, Error> {
    if let GrainShape::Disk { thickness } = scene.grain_shape {
        return Err(fields::refuse(code, "grain_shape.disk.thickness", thickness, ""));
    }
    if let [gx, gy] = scene.gravity
        && (gx != 0.0 || gy != 0.0)
    {
        return Err(fields::refuse(code, "gravity", format!("[{gx}, {gy}]"), ""));
    }
    if let Some(c) = scene.model.general_damping {
        return Err(fields::refuse(code, "model.general_damping", c, ""));
    }
    if !scene.model.rotation
        && scene.model.tangential != TangentialSpec::Frictionless
        && let Grains::List(list) = &scene.grains
        && let Some((k, g)) = list.iter().enumerate().find(|(_, g)| g.omega != 0.0)
    {
        return Err(fields::refuse(code, &format!("grains.list[{k}].omega"), g.omega, "model.rotation = false"));
    }
    let built = crate::build::build_limited(scene, 1, limits)?;
    let (steps, sample_every) = crate::run::schedule(scene.duration, built.time_step.dt_s, scene.output.samples);
    let e = built.engine.as_ref();
    let n_free = e.particles().n_free;
    let walls = e.walls();
    if let Some(w) = walls.iter().find(|w| w.is_flat() && w.control != Control::Fixed) {
        return Err(fields::refuse(code, &format!("walls.{}.control.pressure", w.name), pressure(scene, w.name), &format!("walls.{}.surface = flat", w.name)));
    }
    let columns = match scene.analysis {
        // The build refused an impact without two grains, or a grain and a flat wall.
        Analysis::Impact => impact_columns(n_free == 2),
        Analysis::Shear => {
            if let Some(w) = walls.iter().find(|w| w.is_flat()) {
                return Err(fields::refuse(code, &format!("walls.{}.surface", w.name), "flat", "analysis = shear"));
            }
            wall_columns()
        }
        // The deck records nothing, as a timing deck.
        Analysis::None => Vec::new(),
    };
    let p = e.particles();
    let impact = scene.analysis == Analysis::Impact;
    let info = ExportInfo {
        radii_m: if impact { p.r[..n_free].to_vec() } else { Vec::new() },
        masses_kg: if impact { p.m[..n_free].to_vec() } else { Vec::new() },
        flat_wall: if impact && n_free == 1 { walls.iter().find(|w| w.is_flat()).map(|w| [w.y, w.side, w.v.x]) } else { None },
        scene: scene.name.clone(),
        analysis: scene.analysis,
        time_step_s: built.time_step.dt_s,
        steps,
        sample_every,
        free_grains: n_free,
        length_m: built.length,
        depth_m: built.depth,
        columns,
    };
    Ok(Exported { built, info, bench: false })
}

/// The pressure a scene puts on wall `name` (`walls.NAME.control.pressure`), Pa; 0 if held.
pub(crate) fn pressure(scene: &Scene, name: &str) -> f64 {
    let w = scene.walls.as_ref().expect("a wall exists");
    match if name == "bottom" { &w.bottom.control } else { &w.top.control } {
        ControlSpec::Pressure(p) => *p,
        ControlSpec::Fixed => 0.0,
    }
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

/// The shared particle file, LAMMPS data format for `atom_style granular`.
pub(crate) fn grains_data(scene: &Scene, built: &Built, bounds: [[f64; 2]; 3]) -> String {
    let p = built.engine.particles();
    let mut s = String::new();
    // The title line: LIGGGHTS' read_data skips the first line whole, and the YADE script
    // counts lines from it, so it must stay one line.
    let _ = writeln!(s, "grainlab grains of scene `{}`: id type diameter(m) density(kg/m^3) x y z (m); velocities: id vx vy vz (m/s) wx wy wz (rad/s)", escaped(&scene.name, &[]));
    let _ = writeln!(s, "\n{} atoms\n{} atom types\n", p.len(), scene.materials.len());
    for (k, ax) in ["x", "y", "z"].iter().enumerate() {
        let _ = writeln!(s, "{:.17e} {:.17e} {ax}lo {ax}hi", bounds[k][0], bounds[k][1]);
    }
    let _ = writeln!(s, "\nAtoms\n");
    for i in 0..p.len() {
        let m = p.material[i] as usize;
        let _ = writeln!(s, "{} {} {:.17e} {:.17e} {:.17e} {:.17e} 0", i + 1, m + 1, 2.0 * p.r[i], scene.materials[m].density, p.x[i].x, p.x[i].y);
    }
    let _ = writeln!(s, "\nVelocities\n");
    for i in 0..p.len() {
        let _ = writeln!(s, "{} {:.17e} {:.17e} 0 0 0 {:.17e}", i + 1, p.v[i].x, p.v[i].y, p.omega[i]);
    }
    s
}

/// Box bounds that hold every grain for the whole run: the periodic cell in x, and a
/// margin of the distance a grain can travel at the largest initial speed.
pub(crate) fn bounds(built: &Built, duration: f64) -> [[f64; 3]; 2] {
    let e = built.engine.as_ref();
    let p = e.particles();
    let rmax = p.r.iter().cloned().fold(0.0, f64::max);
    let vmax = p.v.iter().map(|v| v.norm()).fold(0.0, f64::max);
    let travel = vmax * duration + 4.0 * rmax;
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for x in &p.x {
        lo[0] = lo[0].min(x.x);
        lo[1] = lo[1].min(x.y);
        hi[0] = hi[0].max(x.x);
        hi[1] = hi[1].max(x.y);
    }
    for w in e.walls() {
        if w.is_flat() {
            lo[1] = lo[1].min(w.y);
            hi[1] = hi[1].max(w.y);
        }
    }
    let gap = hi[1] - lo[1];
    let b = e.boundary();
    let (x0, x1) = if b.is_periodic() { (b.x_min, b.x_min + b.period) } else { (lo[0] - travel, hi[0] + travel) };
    // A loaded wall may move: leave half the gap above.
    let loaded = e.walls().iter().any(|w| matches!(w.control, Control::Load { .. }) && matches!(w.surface, Surface::Rough { .. }));
    let top_margin = if loaded { 0.5 * gap } else { 0.0 };
    [[x0, lo[1] - travel, -2.0 * rmax], [x1, hi[1] + travel + top_margin, 2.0 * rmax]]
}

/// Write the deck for `code`, the shared particle file and export.json into `dir`.
pub fn export(scene: &Scene, code: Code, dir: &Path) -> Result<Vec<std::path::PathBuf>, Error> {
    export_with(scene, code, dir, false)
}

/// As [`export`]; with `bench`, the deck records nothing (no per-step output, which would
/// cost the reference code time that grainlab's own timing does not include) and prints
/// its loop time: LIGGGHTS' `Loop time of ...`, YADE's `grainlab-loop-seconds ...`.
pub fn export_with(scene: &Scene, code: Code, dir: &Path, bench: bool) -> Result<Vec<std::path::PathBuf>, Error> {
    let files = export_files(scene, code, bench, &crate::limits::Limits::machine())?;
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir.display(), e))?;
    let mut written = Vec::new();
    for (name, text) in files {
        let path = dir.join(name);
        crate::output::folder::write_atomic(&path, text.as_bytes())?;
        written.push(path);
    }
    Ok(written)
}

/// What [`export_with`] writes, as (file name, text), without writing it.
pub fn export_files(scene: &Scene, code: Code, bench: bool, limits: &crate::limits::Limits) -> Result<Vec<(&'static str, String)>, Error> {
    let mut ex = prepare(scene, code, limits)?;
    ex.bench = bench;
    let b = bounds(&ex.built, scene.duration);
    let deck = match code {
        Code::Liggghts => liggghts::deck(scene, &ex)?,
        Code::Yade => yade::deck(scene, &ex)?,
    };
    let data = grains_data(scene, &ex.built, [[b[0][0], b[1][0]], [b[0][1], b[1][1]], [b[0][2], b[1][2]]]);
    Ok(vec![(code.deck(), deck), ("grains.data", data), ("export.json", serde_json::to_string_pretty(&ex.info).expect("serialisable") + "\n")])
}


/// Format a float so that it reads back to the same f64.
pub(crate) fn f(v: f64) -> String {
    format!("{v:.17e}")
}
