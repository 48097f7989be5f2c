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
//! the reference CSV schema. A 3D scene (`dimension: 3`) gets the same decks in space:
//! spheres free in z, three components of position, velocity and spin, `p` along each
//! periodic axis (x, z), and the z columns in both files ([`impact_columns_in`],
//! [`wall_columns_in`]; export.json `dimension`).
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The text of `name` among exported files.
    fn file<'a>(files: &'a [(&'static str, String)], name: &str) -> &'a str {
        &files.iter().find(|(n, _)| *n == name).expect("written").1
    }

    #[test]
    fn a_3d_scene_exports_spheres_in_space_with_z_columns() {
        // The columns the digest reads: 2D as before, 3D with the z components.
        assert_eq!(impact_columns_in(true, Dimension::Two), impact_columns(true));
        assert_eq!(wall_columns_in(Dimension::Two), wall_columns());
        let c = impact_columns_in(true, Dimension::Three);
        assert_eq!(c.len(), 1 + 2 * 12);
        assert_eq!(&c[1..13].join(" "), "x_m0 y_m0 z_m0 vx_m_s0 vy_m_s0 vz_m_s0 omegax_rad_s0 omegay_rad_s0 omegaz_rad_s0 fx_n0 fy_n0 fz_n0");
        assert_eq!(wall_columns_in(Dimension::Three).join(" "), "step bottom_fx_n bottom_fy_n bottom_fz_n top_fx_n top_fy_n top_fz_n gap_m");
        // A small 3D shear box, periodic in x and z, the top lattice loaded.
        let mut s = crate::scene::builtin::shear3d();
        s.domain.periodic_x = Some([0.0, 0.004]);
        s.domain.periodic_z = Some([0.0, 0.004]);
        if let crate::scene::Grains::Pack(p) = &mut s.grains {
            (p.count, p.x, p.z) = (40, [0.0, 0.004], Some([0.0, 0.004]));
        }
        s.output.frames = 0;
        let limits = crate::scene::limits::Limits::machine();
        for code in [Code::Liggghts, Code::Yade, Code::Lammps] {
            let files = export_files(&s, code, false, &limits).unwrap();
            let info: ExportInfo = serde_json::from_str(file(&files, "export.json")).unwrap();
            assert_eq!((info.dimension, info.length_m, info.depth_m), (Dimension::Three, 0.004, 0.004));
            assert_eq!(info.columns, wall_columns_in(Dimension::Three));
            let deck = file(&files, code.deck());
            match code {
                Code::Yade => {
                    assert!(deck.contains("O.cell.setBox(L, H, LZ)") && deck.contains("LZ = 4.0") && !deck.contains("'zXY'"), "{deck}");
                    assert!(deck.contains("enumerate((fb[0], fb[1], fb[2], ft[0], ft[1], ft[2]))"), "{deck}");
                }
                _ => assert!(deck.contains("boundary p f p") && deck.contains("f_f_top[3]") && deck.contains(&info.columns.join(" ")), "{deck}"),
            }
            // Every grain's z (the glued lattices' too) within the periodic cell.
            let data = file(&files, "grains.data");
            assert!(data.contains("0.00000000000000000e0 4.00000000000000008e-3 zlo zhi"), "{data}");
        }
        // A 2D export.json keeps its bytes: no dimension in it.
        let files = export_files(&crate::scene::builtin::builtin("collision").unwrap(), Code::Liggghts, false, &limits).unwrap();
        assert!(!file(&files, "export.json").contains("dimension"));
    }

    #[test]
    fn a_3d_pair_carries_three_components_of_position_velocity_and_spin() {
        let json = r#"{ "name": "pair3d", "dimension": 3,
          "grains": {"list": [ {"x": [0, 0, 0.0001], "v": [0.5, 0.3, 0.4], "omega": [10, -20, 5], "r": 0.001},
                               {"x": [0.0025, 0.0015, 0.002], "v": [-0.5, -0.3, -0.4], "r": 0.001} ]},
          "time_step": {"rule": {"steps_per_contact": {"steps": 50, "impact_speed": 1.0}}},
          "duration": 1e-4, "output": {"frames": 0} }"#;
        let s = Scene::from_json(json).unwrap();
        for code in [Code::Liggghts, Code::Yade, Code::Lammps] {
            let files = export_files(&s, code, false, &Default::default()).unwrap();
            let data = file(&files, "grains.data");
            assert!(data.contains("1 1 2.00000000000000004e-3 2.50000000000000000e3 0.00000000000000000e0 0.00000000000000000e0 1.00000000000000005e-4\n"), "{data}");
            assert!(data.contains("1 5.00000000000000000e-1 2.99999999999999989e-1 4.00000000000000022e-1 1.00000000000000000e1 -2.00000000000000000e1 5.00000000000000000e0\n"), "{data}");
            let deck = file(&files, code.deck());
            match code {
                Code::Yade => assert!(deck.contains("b.state.angVel = Vector3(float(wx), float(wy), float(wz))") && !deck.contains("blockedDOFs = 'zXY'"), "{deck}"),
                _ => assert!(deck.contains("boundary f f f") && !deck.contains("enforce2d") && !deck.contains("dimension"), "{deck}"),
            }
        }
        // Periodic along z without a periodic x: LIGGGHTS and LAMMPS write `p` along z,
        // YADE's open script has no periodic cell (refused by name).
        let mut s = s;
        s.domain.periodic_z = Some([-0.01, 0.01]);
        assert!(file(&export_files(&s, Code::Liggghts, false, &Default::default()).unwrap(), "in.liggghts").contains("boundary f f p"));
        let e = export_files(&s, Code::Yade, false, &Default::default()).err().unwrap().to_string();
        assert!(e.contains("export to yade: domain.periodic_z = [-0.01, 0.01] cannot be expressed"), "{e}");
        // A 3D gravity is refused by name, every component read.
        s.gravity = [0.0, 0.0, -9.81].into();
        let e = export_files(&s, Code::Liggghts, false, &Default::default()).err().unwrap().to_string();
        assert!(e.contains("export to liggghts: gravity = [0, 0, -9.81] cannot be expressed"), "{e}");
    }
}
