//! The part of an export both decks need: the scene built (so that both start from
//! exactly grainlab's grains), the refusals both share, the particle file `grains.data`
//! and the box that holds the grains for the whole run. Written once for the plane and
//! space (`D`): a 2D scene is built in the plane ([`Plane`]), a 3D one in space
//! ([`crate::physics::dim::Space`]), and the files read each grain's components through
//! [`Dim`] (a plane grain's z is 0 and its spin is about z).

use std::fmt::Write as _;

use crate::engine::build::{Building, Built};
use crate::error::Error;
use crate::physics::dim::{Dim, GrainShape, Plane};
use crate::physics::walls::{Control, Surface};
use crate::scene::{Analysis, ControlSpec, Grains, Scene, TangentialSpec};
use crate::workbench::export::common::{Code, ExportInfo, ExportStage, escaped, impact_columns_in, wall_columns_in};
use crate::workbench::export::fields;

/// The part of a scene both exporters need, with the checks both share.
pub(crate) struct Exported<D: Dim = Plane> {
    pub built: Built<D>,
    pub info: ExportInfo,
    /// A timing deck: no recording.
    pub bench: bool,
}

/// The scene built in `D` (the plane for a 2D scene, space for a 3D one: the build
/// refuses the other) and what both decks share.
pub(crate) fn prepare<D: Building>(scene: &Scene, code: Code, limits: &crate::scene::limits::Limits) -> Result<Exported<D>, Error>
where
    D::Vector<f64>: serde::Serialize + serde::de::DeserializeOwned,
    D::Spin<f64>: serde::Serialize + serde::de::DeserializeOwned,
{
    if let GrainShape::Disk { thickness } = scene.grain_shape {
        return Err(fields::refuse(code, "grain_shape.disk.thickness", thickness, ""));
    }
    // Every component (two in the plane, two or three in space).
    if scene.gravity.iter().any(|&g| g != 0.0) {
        return Err(fields::refuse(code, "gravity", listed(scene.gravity.as_slice()), ""));
    }
    if scene.model.damping.tsuji().is_some() && code != Code::Lammps {
        return Err(fields::refuse(code, "model.damping", format!("\"{}\"", scene.model.damping.name()), ""));
    }
    if let Some((k, m)) = scene.adhesive_material()
        && (code != Code::Lammps || !scene.model.normal.is_hertz())
    {
        return Err(fields::refuse(code, &format!("materials[{k}].work_of_adhesion"), m.work_of_adhesion, if code == Code::Lammps { "model.normal = hooke" } else { "" }));
    }
    // Rolling resistance: LIGGGHTS has CDT and EPSD2, LAMMPS SDS, YADE none.
    let rolling = scene.model.rolling;
    let has = match rolling {
        crate::scene::RollingSpec::None => true,
        crate::scene::RollingSpec::Cdt | crate::scene::RollingSpec::Epsd2 => code == Code::Liggghts,
        crate::scene::RollingSpec::Sds { .. } => code == Code::Lammps,
    };
    if !has {
        // The law's name alone: its parameters change nothing about the refusal.
        let name = match rolling {
            crate::scene::RollingSpec::Cdt => "\"cdt\"",
            crate::scene::RollingSpec::Epsd2 => "\"epsd2\"",
            _ => "\"sds\"",
        };
        return Err(fields::refuse(code, "model.rolling", name, ""));
    }
    if let Some(c) = scene.model.general_damping {
        return Err(fields::refuse(code, "model.general_damping", c, ""));
    }
    if !scene.model.rotation
        && scene.model.tangential != TangentialSpec::Frictionless
        && let Grains::List(list) = &scene.grains
        && let Some((k, g)) = list.iter().enumerate().find(|(_, g)| g.omega.norm() != 0.0)
    {
        return Err(fields::refuse(code, &format!("grains.list[{k}].omega"), g.omega, "model.rotation = false"));
    }
    let built = crate::study::accuracy::build_in::<D>(scene, 1, limits)?;
    let phases = crate::study::protocol::phases(scene, built.time_step.dt_s, built.length, built.depth)?;
    let (steps, sample_every) = (phases.last().map_or(0, |p| p.last()), phases[0].sample_every);
    let e = built.engine.as_ref();
    if let Some(w) = e.walls().iter().find(|w| w.is_flat() && w.v[1] != 0.0) {
        return Err(fields::refuse(code, &format!("walls.{}.velocity_y", w.name), w.v[1], &format!("walls.{}.surface = flat", w.name)));
    }
    // A wall moving along z (3D): a scene gives none (walls slide in x), so this guards the
    // decks, which write a wall's x velocity alone, against a build that one day does.
    if D::D == 3
        && let Some(w) = e.walls().iter().find(|w| w.v[2] != 0.0)
    {
        return Err(Error::Export(format!("export to {}: walls.{} = a z velocity of {} m/s cannot be expressed: the decks move walls along x (flat: `shear x`, a wall body's x velocity; rough: the lattice's velocities) and write no wall z velocity", code.name(), w.name, w.v[2])));
    }
    if let Some((k, g)) = scene.stages.iter().enumerate().find_map(|(k, st)| st.gravity.filter(|g| g.norm() != 0.0).map(|g| (k, g))) {
        return Err(fields::refuse(code, &format!("stages[{k}].gravity"), listed(g.as_slice()), ""));
    }
    if !scene.stages.is_empty()
        && let Some(w) = e.walls().iter().find(|w| w.is_flat())
    {
        return Err(fields::refuse(code, "stages[0].duration", format!("{} s", scene.stages[0].duration), &format!("walls.{}.surface = flat", w.name)));
    }
    let n_free = e.particles().n_free;
    let walls = e.walls();
    if let Some(w) = walls.iter().find(|w| w.is_flat() && w.control != Control::Fixed) {
        return Err(fields::refuse(code, &format!("walls.{}.control.pressure", w.name), pressure(scene, w.name), &format!("walls.{}.surface = flat", w.name)));
    }
    let columns = match scene.analysis {
        // The build refused an impact without two grains, or a grain and a flat wall.
        Analysis::Impact => impact_columns_in(n_free == 2, scene.dimension),
        Analysis::Shear => {
            if let Some(w) = walls.iter().find(|w| w.is_flat()) {
                return Err(fields::refuse(code, &format!("walls.{}.surface", w.name), "flat", "analysis = shear"));
            }
            wall_columns_in(scene.dimension)
        }
        // The deck records nothing, as a timing deck.
        Analysis::None => Vec::new(),
    };
    let p = e.particles();
    let impact = scene.analysis == Analysis::Impact;
    let info = ExportInfo {
        radii_m: if impact { p.r[..n_free].to_vec() } else { Vec::new() },
        masses_kg: if impact { p.m[..n_free].to_vec() } else { Vec::new() },
        flat_wall: if impact && n_free == 1 { walls.iter().find(|w| w.is_flat()).map(|w| [w.y, w.side, w.v[0]]) } else { None },
        scene: scene.name.clone(),
        dimension: scene.dimension,
        analysis: scene.analysis,
        time_step_s: built.time_step.dt_s,
        steps,
        sample_every,
        free_grains: n_free,
        length_m: built.length,
        depth_m: built.depth,
        columns,
        stages: phases.iter().filter(|p| !p.name.is_empty()).map(|p| ExportStage { name: p.name.clone(), first_step: p.first, steps: p.steps, sample_every: p.sample_every, average: p.average }).collect(),
        statistics: scene.statistics,
    };
    Ok(Exported { built, info, bench: false })
}

/// Numbers as a scene writes a vector: `[a, b]` or `[a, b, c]`.
fn listed(v: &[f64]) -> String {
    format!("[{}]", v.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(", "))
}

/// The pressure a scene puts on wall `name` (`walls.NAME.control.pressure`), Pa; 0 if held.
pub(crate) fn pressure(scene: &Scene, name: &str) -> f64 {
    let w = scene.walls.as_ref().expect("a wall exists");
    match if name == "bottom" { &w.bottom.control } else { &w.top.control } {
        ControlSpec::Pressure(p) => *p,
        ControlSpec::Fixed => 0.0,
    }
}

/// The shared particle file, LAMMPS data format for `atom_style granular`: in the plane
/// every z and the spins' x and y components are 0; in space each grain's own.
pub(crate) fn grains_data<D: Dim>(scene: &Scene, built: &Built<D>, bounds: [[f64; 2]; 3]) -> String {
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
        let _ = write!(s, "{} {} {:.17e} {:.17e} {:.17e} {:.17e} ", i + 1, m + 1, 2.0 * p.r[i], scene.materials[m].density, p.x[i][0], p.x[i][1]);
        let _ = if D::D == 3 { writeln!(s, "{:.17e}", p.x[i][2]) } else { writeln!(s, "0") };
    }
    let _ = writeln!(s, "\nVelocities\n");
    for i in 0..p.len() {
        let _ = write!(s, "{} {:.17e} {:.17e} ", i + 1, p.v[i][0], p.v[i][1]);
        let _ = match D::spin_components(&p.omega[i]) {
            &[w] => writeln!(s, "0 0 0 {w:.17e}"),
            w => writeln!(s, "{:.17e} {:.17e} {:.17e} {:.17e}", p.v[i][2], w[0], w[1], w[2]),
        };
    }
    s
}

/// Box bounds that hold every grain for the whole run: the periodic cell in x (and in z,
/// 3D), and a margin of the distance a grain can travel at the largest initial speed.
/// In the plane z spans +-2 r_max about the grains' plane z = 0.
pub(crate) fn bounds<D: Dim>(built: &Built<D>, duration: f64) -> [[f64; 3]; 2] {
    let e = built.engine.as_ref();
    let p = e.particles();
    let rmax = p.r.iter().cloned().fold(0.0, f64::max);
    let vmax = p.v.iter().map(|&v| D::norm(v)).fold(0.0, f64::max);
    let travel = vmax * duration + 4.0 * rmax;
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for x in &p.x {
        for k in 0..D::D {
            lo[k] = lo[k].min(x[k]);
            hi[k] = hi[k].max(x[k]);
        }
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
    let (z0, z1) = if D::D == 2 {
        (-2.0 * rmax, 2.0 * rmax)
    } else if b.is_periodic_z() {
        (b.z_min, b.z_min + b.z_period)
    } else {
        (lo[2] - travel, hi[2] + travel)
    };
    [[x0, lo[1] - travel, z0], [x1, hi[1] + travel + top_margin, z1]]
}

