//! The part of an export both decks need: the scene built (so that both start from
//! exactly grainlab's grains), the refusals both share, the particle file `grains.data`
//! and the box that holds the grains for the whole run.

use std::fmt::Write as _;

use crate::engine::build::Built;
use crate::error::Error;
use crate::physics::dim::GrainShape;
use crate::physics::walls::{Control, Surface};
use crate::scene::{Analysis, ControlSpec, Grains, Scene, TangentialSpec};
use crate::workbench::export::common::{Code, ExportInfo, ExportStage, escaped, impact_columns, wall_columns};
use crate::workbench::export::fields;

/// The part of a scene both exporters need, with the checks both share.
pub(crate) struct Exported {
    pub built: Built,
    pub info: ExportInfo,
    /// A timing deck: no recording.
    pub bench: bool,
}

pub(crate) fn prepare(scene: &Scene, code: Code, limits: &crate::scene::limits::Limits) -> Result<Exported, Error> {
    if !scene.dimension.is_two() {
        return Err(fields::refuse(code, "dimension", scene.dimension.count(), ""));
    }
    if let GrainShape::Disk { thickness } = scene.grain_shape {
        return Err(fields::refuse(code, "grain_shape.disk.thickness", thickness, ""));
    }
    if let &[gx, gy] = scene.gravity.as_slice()
        && (gx != 0.0 || gy != 0.0)
    {
        return Err(fields::refuse(code, "gravity", format!("[{gx}, {gy}]"), ""));
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
    let built = crate::study::build_limited(scene, 1, limits)?;
    let phases = crate::study::protocol::phases(scene, built.time_step.dt_s, built.length, built.depth)?;
    let (steps, sample_every) = (phases.last().map_or(0, |p| p.last()), phases[0].sample_every);
    let e = built.engine.as_ref();
    if let Some(w) = e.walls().iter().find(|w| w.is_flat() && w.v.y != 0.0) {
        return Err(fields::refuse(code, &format!("walls.{}.velocity_y", w.name), w.v.y, &format!("walls.{}.surface = flat", w.name)));
    }
    if let Some((k, g)) = scene.stages.iter().enumerate().find_map(|(k, st)| st.gravity.filter(|g| g.norm() != 0.0).map(|g| (k, g))) {
        return Err(fields::refuse(code, &format!("stages[{k}].gravity"), format!("[{}, {}]", g[0], g[1]), ""));
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
        stages: phases.iter().filter(|p| !p.name.is_empty()).map(|p| ExportStage { name: p.name.clone(), first_step: p.first, steps: p.steps, sample_every: p.sample_every, average: p.average }).collect(),
        statistics: scene.statistics,
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

