//! Exporting a scene to the reference codes: an equivalent LIGGGHTS 3.8 input deck, YADE
//! 2023.02 script and LAMMPS 20220106 input deck, never hand-kept twins.
//!
//! The scene is built first, so both decks start from exactly the grains grainlab starts
//! from (a packing is generated once, here). Files written to the output directory:
//! - `grains.data`: the shared particle file, in the LAMMPS data format because that is
//!   the one LIGGGHTS reads (`atom-ID type diameter density x y z`, then velocities and
//!   spins); the YADE script parses the same file;
//! - `in.liggghts`, `yade.py` or `in.lammps`: the deck;
//! - `export.json`: what the deck measures and how to read its output ([`ExportInfo`]).
//!
//! Every deck writes the same raw output in the working directory: `series.txt` (impact
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

pub mod common;
pub mod fields;
pub mod lammps;
pub mod liggghts;
pub mod prepare;
pub mod yade;

use std::path::Path;

pub use common::{Code, ExportInfo, escaped, impact_columns, impact_columns_in, wall_columns, wall_columns_in};

use crate::engine::build::Building;
use crate::error::Error;
use crate::physics::dim::{Plane, Space};
use crate::scene::{Dimension, Scene};
use prepare::{bounds, grains_data, prepare};

/// Write the deck for `code`, the shared particle file and export.json into `dir`.
pub fn export(scene: &Scene, code: Code, dir: &Path) -> Result<Vec<std::path::PathBuf>, Error> {
    export_with(scene, code, dir, false)
}

/// As [`export`]; with `bench`, the deck records nothing (no per-step output, which would
/// cost the reference code time that grainlab's own timing does not include) and prints
/// its loop time: LIGGGHTS' `Loop time of ...`, YADE's `grainlab-loop-seconds ...`.
pub fn export_with(scene: &Scene, code: Code, dir: &Path, bench: bool) -> Result<Vec<std::path::PathBuf>, Error> {
    let files = export_files(scene, code, bench, &crate::scene::limits::Limits::machine())?;
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir.display(), e))?;
    let mut written = Vec::new();
    for (name, text) in files {
        let path = dir.join(name);
        crate::output::folder::write_atomic(&path, text.as_bytes())?;
        written.push(path);
    }
    Ok(written)
}

/// What [`export_with`] writes, as (file name, text), without writing it: a 2D scene's
/// decks (spheres in the plane z = 0) or a 3D scene's (spheres in space).
pub fn export_files(scene: &Scene, code: Code, bench: bool, limits: &crate::scene::limits::Limits) -> Result<Vec<(&'static str, String)>, Error> {
    match scene.dimension {
        Dimension::Two => files_in::<Plane>(scene, code, bench, limits),
        Dimension::Three => files_in::<Space>(scene, code, bench, limits),
    }
}

/// [`export_files`] of a scene built in `D`.
fn files_in<D: Building>(scene: &Scene, code: Code, bench: bool, limits: &crate::scene::limits::Limits) -> Result<Vec<(&'static str, String)>, Error>
where
    D::Vector<f64>: serde::Serialize + serde::de::DeserializeOwned,
    D::Spin<f64>: serde::Serialize + serde::de::DeserializeOwned,
{
    let mut ex = prepare::<D>(scene, code, limits)?;
    if scene.model.tangential == crate::scene::TangentialSpec::MindlinDeresiewicz {
        return Err(fields::refuse(code, "model.tangential", "\"mindlin_deresiewicz\"", ""));
    }
    ex.bench = bench;
    let b = bounds(&ex.built, scene.duration);
    let deck = match code {
        Code::Liggghts | Code::Lammps => liggghts::deck(scene, &ex, code)?,
        Code::Yade => yade::deck(scene, &ex)?,
    };
    let data = grains_data(scene, &ex.built, [[b[0][0], b[1][0]], [b[0][1], b[1][1]], [b[0][2], b[1][2]]]);
    Ok(vec![(code.deck(), deck), ("grains.data", data), ("export.json", serde_json::to_string_pretty(&ex.info).expect("serialisable") + "\n")])
}
