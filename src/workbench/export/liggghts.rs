//! The LIGGGHTS 3.8 input deck of a scene, and the LAMMPS deck, which reads the same
//! input language: the LAMMPS deck is this one with its own contact model and flat walls
//! ([`super::lammps`]), `atom_style sphere`, `comm_modify vel yes` and the spin read
//! through a compute.
//!
//! Model: `pair_style gran model hertz tangential history`, with `limitForce on` when
//! the scene clamps Fn >= 0; flat walls are primitive `wall/gran` planes (R* = r,
//! m* = m), rough walls are rows of atoms moved as rigid rows (`setforce` + `nve`, the
//! top row pushed by `aveforce` for a constant load, its total mass that of the row).
//! The traps of reference-notes.md are handled here: `hard_particles yes`, `atom_modify
//! map array`, `communicate single vel yes`, `newton off`, `neigh_modify delay 0`,
//! per-type material matrices that include wall types, `aveforce` per atom.
//!
//! A 3D scene's deck is the same deck in space: `boundary X f Z` (`p` along each periodic
//! axis, x and z), the grains' three components of position, velocity and spin in
//! grains.data, flat walls the same `yplane` primitives (infinite in x and z), rough walls
//! the lattices of atoms the build glued over L_x by L_z, moved as one (`setforce`, nve,
//! `aveforce`), and the records with the z components (series.txt: 12 columns per grain;
//! walls.txt: each wall's z force). No `enforce2d` and no 2D dimension in either case:
//! the plane's grains are spheres at z = 0 that nothing moves out of the plane.
//!
//! The scene name enters comments only, escaped (`comment`). What the deck cannot
//! express is refused and what it expresses approximately is noted, both as
//! [`super::fields`] says.

use std::fmt::Write as _;

use super::fields::{differs_line, refuse};
use super::common::{Code, escaped, f};
use super::prepare::Exported;
use crate::error::Error;
use crate::physics::contact::LeverArm;
use crate::physics::material::{BetaRule, PairMaterial};
use crate::physics::restitution::restitution_of_beta;
use crate::engine::world::WallMotion;
use crate::physics::dim::Dim;
use crate::physics::walls::{Control, Surface};
use crate::scene::{Analysis, NormalLaw, Scene, TangentialSpec};

/// The deck of `code`, [`Code::Liggghts`] or [`Code::Lammps`].
pub(crate) fn deck<D: Dim>(scene: &Scene, ex: &Exported<D>, code: Code) -> Result<String, Error> {
    let lammps = code == Code::Lammps;
    let model = &scene.model;
    let e = ex.built.engine.as_ref();
    let p = e.particles();
    let info = &ex.info;
    let mats = &scene.materials;
    let mut s = String::new();
    let w = &mut s;
    let version = if lammps { "LAMMPS 20220106 (29 Sep 2021, update 2)" } else { "LIGGGHTS 3.8.0" };
    let _ = writeln!(w, "# {version} deck exported by grainlab {} from scene `{}`. Generated: do not edit;", env!("CARGO_PKG_VERSION"), comment(&scene.name));
    let _ = writeln!(w, "# regenerate with `grainlab export {} SCENE --out DIR`.", code.name());
    let writes = match info.analysis {
        Analysis::Impact => "writes series.txt",
        Analysis::Shear => "writes walls.txt",
        Analysis::None => "records nothing",
    };
    if lammps {
        let _ = writeln!(w, "# Run in this directory: lmp -in in.lammps, or on N processes mpirun -np N lmp -in in.lammps (reads grains.data, {writes}).");
    } else {
        let _ = writeln!(w, "# Run in this directory: liggghts -in in.liggghts (reads grains.data, {writes}).");
    }
    if D::D == 3 {
        let _ = writeln!(w, "# Grains: spheres in space (a 3D scene): positions, velocities and spins of three components in grains.data.");
    } else {
        let _ = writeln!(w, "# Grains: spheres at z = 0 in a 3D box (the sphere-in-plane model); nothing moves them out of the plane.");
    }
    let frictional = model.tangential != TangentialSpec::Frictionless;
    if lammps {
        // LAMMPS' arms are lever_arm lammps, and radius for one grain on flat walls; its
        // history is total_force_cap, and total_displacement for one grain on flat walls
        // without damping.
        let pairs = p.len() > 1;
        if frictional && model.lever_arm != LeverArm::Lammps && (pairs || model.lever_arm != LeverArm::Radius) {
            let _ = writeln!(w, "{}", differs_line(code, "model.lever_arm", name_of(&model.lever_arm)));
        }
        let damped = mats.iter().any(|m| m.restitution < 1.0);
        let history_alike = model.tangential == TangentialSpec::TotalDisplacement && !pairs && !damped;
        if model.tangential == TangentialSpec::IncrementalForce || (frictional && model.tangential != TangentialSpec::TotalForceCap && !history_alike) {
            let _ = writeln!(w, "{}", differs_line(code, "model.tangential", name_of(&model.tangential)));
        }
        // LAMMPS 20220106's DMT friction cap (docs/fidelity.md).
        if frictional && let Some((k, m)) = scene.adhesive_material() {
            let _ = writeln!(w, "{}", differs_line(code, &format!("materials[{k}].work_of_adhesion"), m.work_of_adhesion));
        }
    } else {
        if model.lever_arm != LeverArm::RadiusMinusHalfOverlap && frictional {
            let _ = writeln!(w, "{}", differs_line(code, "model.lever_arm", name_of(&model.lever_arm)));
        }
        if matches!(model.tangential, TangentialSpec::IncrementalForce | TangentialSpec::TotalForceCap | TangentialSpec::TotalForceCapSpringKept) {
            let _ = writeln!(w, "{}", differs_line(code, "model.tangential", name_of(&model.tangential)));
        }
    }
    if !frictional {
        let _ = writeln!(w, "{}", if lammps { "# Frictionless: friction coefficient 0, so Ft = 0." } else { "# Frictionless: tangential history with coefficientFriction 0, so Ft = 0." });
    }
    let _ = writeln!(w, "{}\natom_modify map array", if lammps { "atom_style sphere" } else { "atom_style granular" });
    let px = if e.boundary().is_periodic() { "p" } else { "f" };
    // Along z: periodic in a 3D scene with domain.periodic_z; else fixed bounds that hold
    // every grain for the run (grains.data), as along x.
    let pz = if e.boundary().is_periodic_z() { "p" } else { "f" };
    let comm = if lammps { "comm_modify vel yes" } else { "communicate single vel yes" };
    let _ = writeln!(w, "boundary {px} f {pz}\nnewton off\n{comm}\nunits si");
    let _ = writeln!(w, "read_data grains.data");
    let skin = scene.neighbor.skin * 2.0 * p.r[..p.n_free].iter().cloned().fold(f64::INFINITY, f64::min);
    let _ = writeln!(w, "neighbor {} bin\nneigh_modify delay 0", f(skin));
    // LAMMPS: the contacts each pair of types and each flat wall can make, for its
    // pair_coeff lines and wall fixes; LIGGGHTS: the model words its pair style and
    // wall/gran fixes share.
    let (kinds, law) = if lammps {
        let kinds = super::lammps::kinds(scene, ex);
        super::lammps::pair_style(w, scene, &kinds)?;
        (Some(kinds), String::new())
    } else {
        let _ = writeln!(w, "hard_particles yes");
        (None, materials(w, scene, ex)?)
    };
    let _ = writeln!(w, "timestep {}", f(info.time_step_s));
    let _ = writeln!(w, "group free id <> 1 {}", p.n_free);
    let _ = writeln!(w, "run 0");
    let mut wall_vars: Vec<WallVars> = Vec::new();
    for (index, wall) in e.walls().iter().enumerate() {
        let name = wall.name;
        match &wall.surface {
            Surface::Flat => {
                let shear = if wall.v[0] != 0.0 { format!(" shear x {}", f(wall.v[0])) } else { String::new() };
                if let Some(kinds) = &kinds {
                    // The bottom wall holds the grains above it (LO), the top one below (HI).
                    let plane = if wall.side > 0.0 { format!("yplane {} NULL{shear}", f(wall.y)) } else { format!("yplane NULL {}{shear}", f(wall.y)) };
                    super::lammps::flat_wall(w, scene, ex, kinds, index, &plane)?;
                } else {
                    let _ = writeln!(w, "fix w_{name} free wall/gran {law} primitive type {} yplane {}{shear}", wall.material + 1 /* its material's atom type */, f(wall.y));
                }
            }
            Surface::Rough { grains } => {
                let (a, b) = (grains.start + 1, grains.end);
                let _ = writeln!(w, "group {name} id <> {a} {b}");
                match wall.control {
                    Control::Fixed => {
                        let _ = writeln!(w, "fix f_{name} {name} setforce 0.0 0.0 0.0");
                    }
                    Control::Load { force } => {
                        let _ = writeln!(w, "fix f_{name} {name} setforce 0.0 NULL 0.0");
                        load_row(w, code, wall, grains, p, force)?;
                    }
                }
                // The grains' force on the row: what `setforce` found before it set the
                // row's (defined before `aveforce`, it sees the contacts' sum alone), a fix
                // every control keeps, so one recording serves a protocol's stages.
                wall_vars.push((name, (1..=D::D).map(|k| format!("f_f_{name}[{k}]")).collect(), a));
                let _ = writeln!(w, "fix i_{name} {name} nve");
            }
        }
    }
    let rotation = model.rotation && frictional;
    let _ = writeln!(w, "fix integrate free {}", if rotation { "nve/sphere" } else { "nve" });
    let _ = writeln!(w, "variable s equal step");
    let record = if ex.bench { Analysis::None } else { info.analysis };
    if !scene.stages.is_empty() {
        // A protocol: one block per stage, the wall fixes changed between them.
        let mut header = String::new();
        stages(w, &mut header, scene, ex, code, record, &wall_vars)?;
        // Its Differs lines go with the others, before the first command.
        let at = s.find("atom_style").expect("the deck's first command");
        s.insert_str(at, &header);
        return Ok(s);
    }
    match record {
        Analysis::Impact if D::D == 3 => {
            // Three components of each (common::impact_columns_in). LAMMPS has no per-atom
            // spin in variables: a compute per component reads it.
            if lammps {
                for a in ["x", "y", "z"] {
                    let _ = writeln!(w, "compute spin{a} all property/atom omega{a}");
                }
            }
            let spin = |a: &'static str| if lammps { format!("c_spin{a}") } else { format!("omega{a}") };
            let mut cols = vec!["${s}".to_string()];
            for k in 1..=p.n_free {
                let qs = [("x", "x".into()), ("y", "y".into()), ("z", "z".into()), ("vx", "vx".into()), ("vy", "vy".into()), ("vz", "vz".into()), ("wx", spin("x")), ("wy", spin("y")), ("wz", spin("z")), ("fx", "fx".into()), ("fy", "fy".into()), ("fz", "fz".into())];
                for (q, v) in qs {
                    let _ = writeln!(w, "variable {q}{k} equal {v}[{k}]");
                    cols.push(format!("${{{q}{k}}}"));
                }
            }
            let _ = writeln!(w, "fix rec all print 1 \"{}\" file series.txt screen no title \"{}\"", cols.join(" "), info.columns.join(" "));
        }
        Analysis::Impact => {
            // LAMMPS has no per-atom spin in variables: a compute reads it.
            if lammps {
                let _ = writeln!(w, "compute spin all property/atom omegaz");
            }
            let mut cols = vec!["${s}".to_string()];
            for k in 1..=p.n_free {
                for (q, v) in [("x", "x"), ("y", "y"), ("vx", "vx"), ("vy", "vy"), ("wz", if lammps { "c_spin" } else { "omegaz" }), ("fx", "fx"), ("fy", "fy")] {
                    let _ = writeln!(w, "variable {q}{k} equal {v}[{k}]");
                    cols.push(format!("${{{q}{k}}}"));
                }
            }
            let _ = writeln!(w, "fix rec all print 1 \"{}\" file series.txt screen no title \"{}\"", cols.join(" "), info.columns.join(" "));
        }
        Analysis::Shear => record_walls(w, info.sample_every, &wall_vars, &info.columns),
        Analysis::None => {
            let _ = writeln!(w, "{}", if ex.bench { "# timing deck: nothing recorded" } else { "# analysis none: nothing recorded" });
        }
    }
    let _ = writeln!(w, "thermo_style custom step atoms\nthermo {}", (info.steps / 10).max(1));
    let _ = writeln!(w, "run {}", info.steps);
    Ok(s)
}

/// LIGGGHTS' material fixes and pair style; returns the model words the pair style and
/// the wall/gran fixes share (`model hertz tangential history ...`).
fn materials<D: Dim>(w: &mut String, scene: &Scene, ex: &Exported<D>) -> Result<String, Error> {
    let model = &scene.model;
    let e = ex.built.engine.as_ref();
    let p = e.particles();
    let mats = &scene.materials;
    let n = mats.len();
    let list = |g: &dyn Fn(&crate::physics::material::Material) -> f64| mats.iter().map(|m| f(g(m))).collect::<Vec<_>>().join(" ");
    let _ = writeln!(w, "fix m1 all property/global youngsModulus peratomtype {}", list(&|m| m.youngs_modulus));
    let _ = writeln!(w, "fix m2 all property/global poissonsRatio peratomtype {}", list(&|m| m.poisson_ratio));
    // A `peratomtypepair` table: g of each pair of atom types (materials), row by row.
    let table = |g: &dyn Fn(usize, usize) -> f64| (0..n).flat_map(|a| (0..n).map(move |b| (a, b))).map(|(a, b)| f(g(a, b))).collect::<Vec<_>>().join(" ");
    let rule = model.beta_rule();
    // Each pair of materials mixed once, row by row.
    let pms: Vec<PairMaterial> = (0..n * n).map(|k| PairMaterial::mix_with(&mats[k / n], &mats[k % n], rule)).collect();
    let pair = |g: &dyn Fn(&PairMaterial) -> f64| table(&|a, b| g(&pms[a * n + b]));
    // The clamped damping: the restitution whose beta(e) LIGGGHTS turns back into the
    // pair's clamped beta (to rounding); none exists for |beta| >= 1 (e below exp(-2)).
    // LIGGGHTS 3.8 takes 0.05 < coefficientRestitution <= 1 only (global_properties.cpp),
    // where its law reads it: `model hertz` and `model hooke`; `model hooke/stiffness`
    // damps with the gammas written below and ran with 0.0345 (the clamped/spring-e0.2 case).
    let restitution = |pm: &PairMaterial| if rule == BetaRule::Free { Some(pm.restitution) } else { restitution_of_beta(pm.beta) };
    let reads_restitution = !matches!(model.normal, NormalLaw::HookeStiffness { .. });
    for a in 0..n {
        for b in a..n {
            let pm = &pms[a * n + b];
            match restitution(pm) {
                Some(e) if e > 0.05 => {}
                _ if !reads_restitution => {}
                _ if rule == BetaRule::Free => {
                    let k = if mats[a].restitution <= mats[b].restitution { a } else { b };
                    return Err(refuse(Code::Liggghts, &format!("materials[{k}].restitution"), mats[k].restitution, "0.05 < e: LIGGGHTS 3.8 requires 0.05 < coefficientRestitution <= 1"));
                }
                e => {
                    return Err(refuse(Code::Liggghts, "model.damping", "\"clamped_restitution\"", &format!("materials[{a}] and materials[{b}] (e = {}): the clamped beta {} needs a coefficientRestitution of {}, and LIGGGHTS 3.8 requires 0.05 < coefficientRestitution <= 1 (pairs of e above 0.214 can be written)", pm.restitution, pm.beta, e.map_or("none (|beta| >= 1)".to_string(), |e| format!("{e:e}")))));
                }
            }
        }
    }
    let _ = writeln!(w, "fix m3 all property/global coefficientRestitution peratomtypepair {n} {}", pair(&|pm| restitution(pm).unwrap_or(pm.restitution)));
    let frictionless = model.tangential == TangentialSpec::Frictionless;
    let _ = writeln!(w, "fix m4 all property/global coefficientFriction peratomtypepair {n} {}", pair(&|pm| if frictionless { 0.0 } else { pm.friction }));
    let style = match model.normal {
        NormalLaw::Hertz => "hertz",
        NormalLaw::Hooke { characteristic_velocity } => {
            let _ = writeln!(w, "fix m5 all property/global characteristicVelocity scalar {}", f(characteristic_velocity));
            "hooke"
        }
        NormalLaw::HookeStiffness { kn, kt } => {
            let rate = spring_rates(scene, p, e.walls(), kn, kt)?;
            let _ = writeln!(w, "fix m5 all property/global kn peratomtypepair {n} {}", table(&|_, _| kn));
            let _ = writeln!(w, "fix m6 all property/global kt peratomtypepair {n} {}", table(&|_, _| kt));
            let _ = writeln!(w, "# gamman, gammat: LIGGGHTS damps with m* x these (1/s); grainlab's -2 beta(e) sqrt(k m*) is m* x -2 beta sqrt(k / m*), one m* per pair of atom types.");
            let _ = writeln!(w, "fix m7 all property/global gamman peratomtypepair {n} {}", table(&|a, b| rate[a * n + b].0));
            let _ = writeln!(w, "fix m8 all property/global gammat peratomtypepair {n} {}", table(&|a, b| rate[a * n + b].1));
            "hooke/stiffness"
        }
    };
    let rolling = match model.rolling {
        crate::scene::RollingSpec::Cdt => " rolling_friction cdt",
        crate::scene::RollingSpec::Epsd2 => " rolling_friction epsd2",
        // (prepare refused SDS)
        _ => "",
    };
    if !rolling.is_empty() {
        let _ = writeln!(w, "fix m9 all property/global coefficientRollingFriction peratomtypepair {n} {}", pair(&|pm| pm.rolling_friction));
    }
    let law = format!("model {style} tangential history{rolling}{}", if model.limit_force { " limitForce on" } else { "" });
    let _ = writeln!(w, "pair_style gran {law}\npair_coeff * *");
    Ok(law)
}

/// The wall series' recording: the wall forces averaged over every `k` steps and the gap
/// at the row's step (as grainlab's rows: forces averaged over the interval, the gap where
/// the walls are at its end), printed to walls.txt under a title line of `columns`. `k = 1`
/// prints every step's forces as they are (a protocol's raw series, averaged by the digest).
/// Each wall's x and y forces, and in 3D its z force (common::wall_columns_in).
fn record_walls(w: &mut String, k: u64, wall_vars: &[WallVars], columns: &[String]) {
    let (bot, top) = (&wall_vars[0], &wall_vars[1]);
    let _ = writeln!(w, "variable gap equal y[{}]-y[{}]", top.2, bot.2);
    let forces: Vec<&String> = bot.1.iter().chain(&top.1).collect();
    if k > 1 {
        let _ = writeln!(w, "fix avg all ave/time 1 {k} {k} {}", forces.iter().map(|s| s.as_str()).collect::<Vec<_>>().join(" "));
    }
    let mut cols = vec!["${s}".to_string()];
    for (j, force) in forces.iter().enumerate() {
        let value = if k > 1 { format!("f_avg[{}]", j + 1) } else { force.to_string() };
        let _ = writeln!(w, "variable a{} equal {value}", j + 1);
        cols.push(format!("${{a{}}}", j + 1));
    }
    cols.push("${gap}".into());
    let _ = writeln!(w, "fix rec all print {k} \"{}\" file walls.txt screen no title \"{}\"", cols.join(" "), columns.join(" "));
}

/// A wall's recorded quantities: its name, the fix outputs of its force's components (x,
/// y, and z in 3D), and its first atom's id.
type WallVars = (&'static str, Vec<String>, usize);

/// A protocol's stages, each a `run` block, and one recording for all of them: every
/// step's wall forces and gap (walls.txt holds every step; the digest averages it into
/// grainlab's rows of each stage). A rough row's velocity is set with `velocity ... set`
/// (a held row keeps it under `setforce` and nve). A stage whose start changes only
/// velocities runs with `pre no`: LIGGGHTS skips the run's setup, which would recompute
/// the forces at the step-end velocities (with the new wall velocities) and rebuild the
/// neighbour list, so its first half kick uses the last step's forces, as grainlab's does.
/// A change of a wall's control replaces its `setforce`/`aveforce` fixes, which needs the
/// setup: that stage's first step then differs, and the deck says so (a `# Differs:` line
/// at its top, `header`). What a flat wall would need (its motion and history live in its
/// wall/gran fix) and gravity are refused by name.
fn stages<D: Dim>(w: &mut String, header: &mut String, scene: &Scene, ex: &Exported<D>, code: Code, record: Analysis, wall_vars: &[WallVars]) -> Result<(), Error> {
    let e = ex.built.engine.as_ref();
    let p = e.particles();
    let info = &ex.info;
    let phases = crate::study::protocol::phases(scene, info.time_step_s, info.length_m, info.depth_m)?;
    let mut control: Vec<Control> = e.walls().iter().map(|wall| wall.control).collect();
    if record == Analysis::Shear {
        record_walls(w, 1, wall_vars, &info.columns);
    }
    // (A stage's gravity and a protocol beside a flat wall were refused in `prepare`.)
    for (k, ph) in phases.iter().enumerate() {
        let _ = writeln!(w, "# stage {}: {} ({} steps from step {})", k + 1, comment(&ph.name), ph.steps, ph.first);
        let mut setup = k == 0;
        for (i, wall) in e.walls().iter().enumerate() {
            let change = &ph.change.walls[i];
            if *change == WallMotion::default() {
                continue;
            }
            let name = wall.name;
            let Surface::Rough { grains } = &wall.surface else { unreachable!("prepare refuses a protocol beside a flat wall") };
            let before = control[i];
            match (before, change.control) {
                (_, None) | (Control::Fixed, Some(Control::Fixed)) => {}
                (_, Some(Control::Load { force })) => {
                    if before == Control::Fixed {
                        let _ = writeln!(w, "unfix f_{name}\nfix f_{name} {name} setforce 0.0 NULL 0.0");
                    } else {
                        let _ = writeln!(w, "unfix l_{name}");
                    }
                    load_row(w, code, wall, grains, p, force)?;
                }
                (Control::Load { .. }, Some(Control::Fixed)) => {
                    let _ = writeln!(w, "unfix l_{name}\nunfix f_{name}\nfix f_{name} {name} setforce 0.0 0.0 0.0");
                }
            }
            if k > 0 && change.control.is_some_and(|c| c != before || matches!(c, Control::Load { .. })) {
                setup = true;
                let value = match change.control {
                    Some(Control::Load { force }) => format!("a load of {} N", f(force)),
                    _ => "\"fixed\"".into(),
                };
                let _ = writeln!(header, "{}", differs_line(code, &format!("stages[{k}].walls.{name}.control"), value));
            }
            control[i] = change.control.unwrap_or(control[i]);
            // The y velocity as resolved for the stage (0 for a wall changed to fixed).
            let (vx, vy) = (change.velocity_x, change.velocity_y);
            if vx.is_some() || vy.is_some() {
                let v = |x: Option<f64>| x.map_or("NULL".to_string(), f);
                let _ = writeln!(w, "velocity {name} set {} {} NULL units box", v(vx), v(vy));
            }
        }
        let _ = writeln!(w, "thermo_style custom step atoms\nthermo {}", (ph.steps / 10).max(1));
        let _ = writeln!(w, "run {}{}", ph.steps, if setup { "" } else { " pre no post no" });
    }
    Ok(())
}

/// The load `force` (N) on a rough `wall`'s row of `grains`: `aveforce` adds its share to
/// each atom. The row moves as its atoms, so its mass must be theirs (equal atoms, so
/// aveforce's equal forces keep it rigid): another is refused by name.
fn load_row<D: Dim>(w: &mut String, code: Code, wall: &crate::physics::walls::Wall<D>, grains: &std::ops::Range<usize>, p: &crate::physics::particles::Particles<D>, force: f64) -> Result<(), Error> {
    let name = wall.name;
    let atoms: f64 = grains.clone().map(|k| p.m[k]).sum();
    if (wall.mass - atoms).abs() > 1e-12 * atoms {
        return Err(refuse(code, &format!("walls.{name}.mass"), wall.mass, &format!("the row's {} atoms weigh {atoms:e} kg", grains.len())));
    }
    let _ = writeln!(w, "# the load {} N on the row, per atom (aveforce adds its value to each atom)", f(force));
    let _ = writeln!(w, "fix l_{name} {name} aveforce NULL {} NULL", f(wall.side * force / grains.len() as f64));
    Ok(())
}

/// The scene name in a deck comment: [`escaped`], and `&` escaped too. LIGGGHTS reads a
/// line ending in `&` (spaces aside) as continued by the next one before it strips the
/// `#` comment (LIGGGHTS-PUBLIC src/input.cpp, `Input::file`), so a comment ending in `&`
/// would swallow the next command. `$` and quotes need nothing: the comment is stripped
/// before variables are substituted, and a `#` outside quotes starts it.
pub(crate) fn comment(s: &str) -> String {
    escaped(s, &['&'])
}

/// The scene's JSON spelling of an enum value (`radius_minus_half_overlap`).
pub(crate) fn name_of<T: serde::Serialize>(v: &T) -> String {
    match serde_json::to_value(v) {
        Ok(serde_json::Value::String(s)) => s,
        other => format!("{other:?}"),
    }
}


/// `model hooke/stiffness` damps a contact with `m* gamma_n` for one `gamma_n` per pair of
/// atom types (1/s); grainlab's `-2 beta(e) sqrt(kn m*)` is that with
/// `gamma_n = -2 beta sqrt(kn / m*)`, which one number per pair of types expresses only
/// when every contact the pair can make has one reduced mass m*. The (gamma_n, gamma_t)
/// of each pair of types (materials), row by row; a pair that meets at two reduced masses
/// is refused naming `model.normal.hooke_stiffness.kn` (and kt).
fn spring_rates<D: Dim>(scene: &Scene, p: &crate::physics::particles::Particles<D>, walls: &[crate::physics::walls::Wall<D>], kn: f64, kt: f64) -> Result<Vec<(f64, f64)>, Error> {
    let n = scene.materials.len();
    // The reduced masses each pair of types meets at: grain pairs, and grains on flat
    // walls (m* = m), whose wall/gran fixes share the pair style's table.
    let kinds = super::common::contact_kinds(n, p, walls, |_, _, m_star, _| m_star);
    let same = super::common::same_value;
    let mut stars: Vec<Vec<f64>> = vec![Vec::new(); n * n];
    let mut add = |a: usize, b: usize, m: f64| {
        for (x, y) in [(a, b), (b, a)] {
            if !stars[x * n + y].iter().any(|&s| same(s, m)) {
                stars[x * n + y].push(m);
            }
        }
    };
    for a in 0..n {
        for b in 0..n {
            for &m in &kinds.pairs[a * n + b] {
                add(a, b, m);
            }
        }
    }
    for (wall, per) in walls.iter().zip(&kinds.walls) {
        for (a, list) in per.iter().enumerate() {
            for &m in list {
                add(a, wall.material, m);
            }
        }
    }
    let mut out = vec![(0.0, 0.0); n * n];
    for a in 0..n {
        for b in 0..n {
            let m = &stars[a * n + b];
            if m.len() > 1 {
                return Err(refuse(
                    Code::Liggghts,
                    "model.normal.hooke_stiffness.kn",
                    kn,
                    &format!("with model.normal.hooke_stiffness.kt = {kt}: materials[{a}] meet materials[{b}] at reduced masses {:e} kg and {:e} kg (grains of two sizes, or a grain and a flat wall)", m[0], m[1]),
                ));
            }
            if let Some(&m) = m.first() {
                let beta = PairMaterial::mix_with(&scene.materials[a], &scene.materials[b], scene.model.beta_rule()).beta;
                out[a * n + b] = (-2.0 * beta * (kn / m).sqrt(), -2.0 * beta * (kt / m).sqrt());
            }
        }
    }
    Ok(out)
}
