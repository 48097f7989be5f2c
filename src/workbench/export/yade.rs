//! The YADE 2023.02 script of a scene.
//!
//! Model: `Ip2_FrictMat_FrictMat_MindlinPhys(betan = betas = sqrt(5/6) |beta(e)|)` and
//! `Law2_ScGeom_MindlinPhys_Mindlin` (incremental tangential force, Fn clamped at 0 as
//! YADE always does), spheres with `blockedDOFs = 'zXY'` (the sphere-in-plane model),
//! `NewtonIntegrator(damping = 0)`, flat walls as `wall` bodies with
//! `Ig2_Wall_Sphere_ScGeom(hertzian = True)` (R* = r, m* = m). The restitution is never
//! passed as `en`, which YADE maps through a different damping fit (reference-notes.md).
//! The linear spring: `ViscElMat(kn, ks, cn, cs)` per material and per flat wall, which
//! `Ip2_ViscElMat_ViscElMat_ViscElPhys` puts in series per contact, and
//! `Law2_ScGeom_ViscElPhys_Basic` (incremental tangential force, Fn clamped at 0, arms to
//! the contact point), the values solved from grainlab's pairs or refused by name
//! ([`spring_materials`]).
//!
//! A 3D scene's script is the same script in space: the free spheres unblocked (no
//! `blockedDOFs = 'zXY'`; without rotation `'XYZ'`), their three components of velocity
//! and spin from grains.data, flat walls the same `wall` bodies (infinite in x and z),
//! rough walls the lattices of spheres the build glued over L_x by L_z (blocked, the
//! loaded one a clump), the periodic cell periodic in z too when the scene is (else made
//! 10x the packing along z, as along y), and the records with the z components
//! (series.txt: 12 columns per grain; walls.txt: each wall's z force).
//!
//! The scene name enters comments only, escaped ([`super::escaped`]). What the script
//! cannot express is refused and what it expresses approximately is noted, both as
//! [`super::fields`] says.

use std::fmt::Write as _;

use super::fields::{differs_line, note, refuse};
use super::liggghts::name_of;
use super::common::{Code, contact_kinds, escaped, f, same_value};
use super::prepare::{Exported, pressure};
use crate::error::Error;
use crate::physics::contact::LeverArm;
use crate::physics::dim::Dim;
use crate::physics::material::PairMaterial;
use crate::physics::walls::{Control, Surface};
use crate::scene::{Analysis, Scene, TangentialSpec};

pub(crate) fn deck<D: Dim>(scene: &Scene, ex: &Exported<D>) -> Result<String, Error> {
    let space = D::D == 3;
    let model = &scene.model;
    let mats = &scene.materials;
    // The linear spring: ViscElMat and its law; Hertz: FrictMat and Mindlin's law, with
    // one betan for every pair.
    let spring = if model.normal.is_hertz() { None } else { Some(spring_materials(scene, ex)?) };
    if spring.is_none()
        && let Some(k) = mats.iter().position(|m| m.restitution != mats[0].restitution)
    {
        return Err(refuse(Code::Yade, &format!("materials[{k}].restitution"), mats[k].restitution, &format!("materials[0].restitution = {}", mats[0].restitution)));
    }
    // The clamped damping's beta is YADE's own case: it always clamps.
    let rule = model.beta_rule();
    let pairs: Vec<PairMaterial> = mats.iter().flat_map(|a| mats.iter().map(move |b| PairMaterial::mix_with(a, b, rule))).collect();
    let e = ex.built.engine.as_ref();
    let info = &ex.info;
    let p = e.particles();
    let beta = (5.0f64 / 6.0).sqrt() * pairs[0].beta.abs();
    let frictionless = model.tangential == TangentialSpec::Frictionless;
    let walls = e.walls();
    let loaded = walls.iter().find(|w| w.control != Control::Fixed);
    // Two scripts: the periodic shear cell between rough rows, and the open one (free
    // grains, flat walls, held rough rows).
    let periodic = e.boundary().is_periodic();
    if let Some([a, b]) = scene.domain.periodic_x {
        let rough_rows = walls.len() == 2 && walls.iter().all(|w| !w.is_flat());
        if info.analysis == Analysis::Impact || !rough_rows {
            let why = if info.analysis == Analysis::Impact { "analysis = impact" } else { "without two rough walls" };
            return Err(refuse(Code::Yade, "domain.periodic_x", format!("[{a}, {b}]"), why));
        }
    } else if let Some(w) = loaded {
        return Err(refuse(Code::Yade, &format!("walls.{}.control.pressure", w.name), pressure(scene, w.name), "no domain.periodic_x"));
    }
    // A periodic z (3D) has the periodic shear cell's script only.
    if let (Some([a, b]), false) = (scene.domain.periodic_z, periodic) {
        return Err(refuse(Code::Yade, "domain.periodic_z", format!("[{a}, {b}]"), "no domain.periodic_x"));
    }
    let mut s = String::new();
    let w = &mut s;
    let _ = writeln!(w, "# YADE 2023.02a script exported by grainlab {} from scene `{}`. Generated: do not edit;", env!("CARGO_PKG_VERSION"), escaped(&scene.name, &[]));
    let _ = writeln!(w, "# regenerate with `grainlab export yade SCENE --out DIR`.");
    let _ = writeln!(w, "# Run in this directory: yade -n -x yade.py (reads grains.data, writes series.txt).");
    let _ = writeln!(w, "# Recorded between the contact law and the integrator: positions x(n), force F(x(n)), velocities v(n-1/2).");
    if matches!(model.tangential, TangentialSpec::TotalDisplacement | TangentialSpec::TotalForceCap | TangentialSpec::TotalForceCapSpringKept) {
        let _ = writeln!(w, "{}", differs_line(Code::Yade, "model.tangential", name_of(&model.tangential)));
    }
    if !model.limit_force {
        let _ = writeln!(w, "{}", differs_line(Code::Yade, "model.limit_force", false));
    }
    if model.lever_arm != lever_arm(&model.normal) && !frictionless {
        let _ = writeln!(w, "{}", differs_line(Code::Yade, "model.lever_arm", name_of(&model.lever_arm)));
    }
    for wall in walls.iter().filter(|w| w.is_flat()) {
        let _ = writeln!(w, "{}", differs_line(Code::Yade, &format!("walls.{}.surface", wall.name), "flat"));
    }
    // Leapfrog reads the initial velocities as v(-1/2): what is under a force at t = 0
    // starts apart from velocity Verlet's run.
    if let Some(wall) = loaded {
        let _ = writeln!(w, "{}", differs_line(Code::Yade, &format!("walls.{}.control.pressure", wall.name), pressure(scene, wall.name)));
    } else if (0..p.n_free).any(|i| (0..D::D).any(|k| p.f[i][k] != 0.0)) {
        let _ = writeln!(w, "# Differs: grains under a force at t = 0: {}", note(Code::Yade, "walls.top.control.pressure"));
    }
    let _ = writeln!(w, "import math, sys");
    let list = |v: &mut dyn Iterator<Item = f64>| v.map(f).collect::<Vec<_>>().join(", ");
    if spring.is_none() {
        let _ = writeln!(w, "E = [{}]", list(&mut mats.iter().map(|m| m.youngs_modulus)));
        let _ = writeln!(w, "NU = [{}]", list(&mut mats.iter().map(|m| m.poisson_ratio)));
    }
    let _ = writeln!(w, "RHO = [{}]", list(&mut mats.iter().map(|m| m.density)));
    let _ = writeln!(w, "MU = [{}]", list(&mut mats.iter().map(|m| if frictionless { 0.0 } else { m.friction })));
    if let Some(sm) = &spring {
        let _ = writeln!(w, "# The linear spring: each material's (and flat wall's) kn, ks (N/m), cn, cs (kg/s), which YADE puts in series per");
        let _ = writeln!(w, "# contact (k1 k2 / (k1 + k2); 0: the other's), solved by grainlab from its pairs' kn, kt, 2 |beta| sqrt(m* k).");
        for (name, k) in [("KN", 0), ("KS", 1), ("CN", 2), ("CS", 3)] {
            let _ = writeln!(w, "{name} = [{}]", list(&mut sm.grains.iter().map(|g| g[k])));
        }
        for (name, k) in [("WALL_KN", 0), ("WALL_KS", 1), ("WALL_CN", 2), ("WALL_CS", 3)] {
            let _ = writeln!(w, "{name} = [{}]", list(&mut sm.walls.iter().map(|g| g[k])));
        }
        let _ = writeln!(w, "WALL_MAT = [{}]  # each wall's material (its friction)", walls.iter().map(|wl| wl.material.to_string()).collect::<Vec<_>>().join(", "));
    } else {
        let how = if rule == crate::physics::material::BetaRule::Free { "sqrt(5/6) |ln e| / sqrt(ln^2 e + pi^2)" } else { "sqrt(5/6) |beta| of the beta that returns e under the clamp (model.damping clamped_restitution)" };
        let _ = writeln!(w, "BETA = {}  # {how}", f(beta));
    }
    let _ = writeln!(w, "DT = {}\nSTEPS = {}", f(info.time_step_s), info.steps);
    let record = !ex.bench && info.analysis != Analysis::None;
    let _ = writeln!(w, "RECORD = {}  # False in a timing deck", if record { "True" } else { "False" });
    // In space the spheres are free and read with their three components.
    let common = if space { edited(COMMON, GRAINS_PLANE, GRAINS_SPACE) } else { COMMON.to_string() };
    if spring.is_some() {
        let common = edited(&common, MATS_HERTZ, MATS_SPRING);
        let _ = writeln!(w, "{}", edited(&common, LAW_HERTZ, LAW_SPRING));
    } else {
        let _ = writeln!(w, "{}", common);
    }
    // Without rotation (and with friction: frictionless grains never spin) the free
    // grains' spin is blocked too.
    let no_spin = if model.rotation || frictionless {
        ""
    } else if space {
        "for i in ids:\n    O.bodies[i].state.blockedDOFs = 'XYZ'  # model.rotation = false: the free grains do not spin"
    } else {
        "for i in ids:\n    O.bodies[i].state.blockedDOFs = 'zXYZ'  # model.rotation = false: the free grains do not spin"
    };
    if periodic {
        let b = e.boundary();
        let (r_min, r_max) = p.r.iter().fold((f64::INFINITY, 0.0f64), |(a, c), &r| (a.min(r), c.max(r)));
        if b.period < 4.0 * r_max + 2.0 * r_min {
            let [x0, x1] = scene.domain.periodic_x.expect("periodic");
            return Err(refuse(Code::Yade, "domain.periodic_x", format!("[{x0}, {x1}]"), &format!("a cell of {:e} m, under 4 r_max + 2 r_min = {:e} m", b.period, 4.0 * r_max + 2.0 * r_min)));
        }
        if b.is_periodic_z() && b.z_period < 4.0 * r_max + 2.0 * r_min {
            let [z0, z1] = scene.domain.periodic_z.expect("periodic in z");
            return Err(refuse(Code::Yade, "domain.periodic_z", format!("[{z0}, {z1}]"), &format!("a cell of {:e} m along z, under 4 r_max + 2 r_min = {:e} m", b.z_period, 4.0 * r_max + 2.0 * r_min)));
        }
        let range = |k: usize| match &walls[k].surface {
            Surface::Rough { grains } => Ok((grains.start, grains.end)),
            Surface::Flat => Err(Error::Export("export to yade: the shear export needs rough walls".into())),
        };
        let ((b0, b1), (t0, t1)) = (range(0)?, range(1)?);
        let ys = p.x.iter().map(|x| x[1]);
        let (lo, hi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, c), y| (a.min(y), c.max(y)));
        let load = match walls[1].control {
            Control::Load { force } => force,
            Control::Fixed => 0.0,
        };
        if space {
            // The cell along z: the scene's periodic one, or (free grains along z) 10x the
            // grains' z extent (at least H), centred on them: nothing crosses it in a run.
            let (z0, lz) = if b.is_periodic_z() {
                let _ = writeln!(w, "# Periodic in x and z; YADE cells are periodic in every direction, so y is made 10x the packing.");
                (b.z_min, b.z_period)
            } else {
                let _ = writeln!(w, "# Periodic in x; YADE cells are periodic in every direction, so y and z are made 10x the packing.");
                let (zlo, zhi) = p.x.iter().map(|x| x[2]).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, c), z| (a.min(z), c.max(z)));
                let lz = (10.0 * (zhi - zlo)).max(10.0 * (hi - lo));
                (0.5 * (zlo + zhi) - 0.5 * lz, lz)
            };
            let _ = writeln!(w, "X0 = {}\nL = {}\nH = {}\nZ0 = {}\nLZ = {}", f(b.x_min), f(b.period), f(10.0 * (hi - lo)), f(z0), f(lz));
        } else {
            let _ = writeln!(w, "# Periodic in x; YADE cells are periodic in every direction, so y and z are made 10x the packing.");
            let _ = writeln!(w, "X0 = {}\nL = {}\nH = {}", f(b.x_min), f(b.period), f(10.0 * (hi - lo)));
        }
        let _ = writeln!(w, "FREE = {}\nBOTTOM = ({b0}, {b1})\nTOP = ({t0}, {t1})", p.n_free);
        let _ = writeln!(w, "LOAD = {}  # N on the top wall, towards the grains (0: the wall is held)", f(load));
        if scene.stages.is_empty() {
            let _ = writeln!(w, "SAMPLE = {}  # steps per row of walls.txt (forces averaged over each step)", info.sample_every);
        } else {
            let _ = writeln!(w, "SAMPLE = 1  # a protocol's walls.txt: a row at every step");
        }
        let _ = writeln!(w, "{}", if space { edited(&edited(SHEAR_FREE, "O.cell.setBox(L, H, H)", "O.cell.setBox(L, H, LZ)"), "Vector3(-X0, 0.5 * H, 0)  # into the cell [0, L) x [0, H)", "Vector3(-X0, 0.5 * H, -Z0)  # into the cell [0, L) x [0, H) x [0, LZ)") } else { SHEAR_FREE.to_string() });
        if !no_spin.is_empty() {
            let _ = writeln!(w, "{no_spin}");
        }
        let _ = writeln!(w, "{}", SHEAR_WALLS);
        // A given mass of the loaded wall: the clump's, which NewtonIntegrator divides the
        // clump's force by (its spheres keep their own masses for the contact damping).
        let given = scene.walls.as_ref().and_then(|ws| ws.top.mass);
        let loaded_later = scene.stages.iter().any(|st| matches!(st.walls.top.control, Some(crate::scene::ControlSpec::Pressure(_))));
        if (load > 0.0 || loaded_later) && given.is_some() {
            let _ = writeln!(w, "c.mass = {}  # walls.top.mass, kg", f(walls[1].mass));
        }
        let run = shear_run::<D>(&info.columns);
        if scene.stages.is_empty() {
            let _ = writeln!(w, "{}", run);
        } else {
            let _ = writeln!(w, "{}", stages(scene, ex, &run)?);
        }
        return Ok(s);
    }
    if !scene.stages.is_empty() {
        return Err(refuse(Code::Yade, "stages[0].duration", format!("{} s", scene.stages[0].duration), "no domain.periodic_x"));
    }
    if walls.iter().any(|w| !w.is_flat()) {
        // Rough rows (held: a loaded one was refused above) follow the free grains in
        // grains.data; they keep their velocity.
        let _ = writeln!(w, "FREE = {}\n{}", p.n_free, IMPACT_SETUP_ROUGH);
    } else {
        let _ = writeln!(w, "{}", IMPACT_SETUP);
    }
    if !no_spin.is_empty() {
        let _ = writeln!(w, "{no_spin}");
    }
    for (j, wall) in walls.iter().enumerate() {
        if let Surface::Flat = wall.surface {
            let material = if spring.is_some() { format!("wmats[{j}]") } else { format!("mats[{}]", wall.material) };
            let _ = writeln!(w, "b = O.bodies.append(wall({}, axis=1, sense={}, material={material}))", f(wall.y), if wall.side > 0.0 { 1 } else { -1 });
            let _ = writeln!(w, "O.bodies[b].state.vel = Vector3({}, 0, 0)", f(wall.v[0]));
        }
    }
    if space {
        let cols = super::common::IMPACT_SPACE.map(|q| format!("'{q}'")).join(", ");
        let impact = edited(IMPACT, "('x_m', 'y_m', 'vx_m_s', 'vy_m_s', 'omega_rad_s', 'fx_n', 'fy_n')", &format!("({cols})"));
        let impact = edited(&impact, "(st.pos[0], st.pos[1], st.vel[0], st.vel[1], st.angVel[2], fo[0], fo[1])", "(st.pos[0], st.pos[1], st.pos[2], st.vel[0], st.vel[1], st.vel[2], st.angVel[0], st.angVel[1], st.angVel[2], fo[0], fo[1], fo[2])");
        let _ = writeln!(w, "{impact}");
        return Ok(s);
    }
    let _ = writeln!(w, "{}", IMPACT);
    Ok(s)
}

/// The lever arm of YADE's law for the normal law `normal`: Mindlin's (Hertz) takes
/// ScGeom's ratcheting-corrected velocity (`yade`), ViscElPhys' (the linear spring) the
/// contact point's (`contact_point`).
pub fn lever_arm(normal: &crate::scene::NormalLaw) -> LeverArm {
    if normal.is_hertz() { LeverArm::Yade } else { LeverArm::ContactPoint }
}

/// The materials of the Hertz deck's [`COMMON`], and the linear spring's in their place.
const MATS_HERTZ: &str = "mats = [O.materials.append(FrictMat(young=E[k], poisson=NU[k], density=RHO[k], frictionAngle=math.atan(MU[k]))) for k in range(len(E))]\n";
const MATS_SPRING: &str = "mats = [O.materials.append(ViscElMat(kn=KN[k], ks=KS[k], cn=CN[k], cs=CS[k], density=RHO[k], frictionAngle=math.atan(MU[k]))) for k in range(len(RHO))]
wmats = [O.materials.append(ViscElMat(kn=WALL_KN[j], ks=WALL_KS[j], cn=WALL_CN[j], cs=WALL_CS[j], density=1.0, frictionAngle=math.atan(MU[WALL_MAT[j]]))) for j in range(len(WALL_KN))]\n";
/// The contact law of the Hertz deck's [`COMMON`], and the linear spring's in its place.
const LAW_HERTZ: &str = "        [Ip2_FrictMat_FrictMat_MindlinPhys(betan=BETA, betas=BETA)],\n        [Law2_ScGeom_MindlinPhys_Mindlin()],\n";
const LAW_SPRING: &str = "        [Ip2_ViscElMat_ViscElMat_ViscElPhys()],\n        [Law2_ScGeom_ViscElPhys_Basic()],\n";

/// How [`COMMON`]'s `grains()` reads a sphere in the plane (z motion and the spins about
/// x and y blocked, the spin about z), and in space in its place (free, all components).
const GRAINS_PLANE: &str = "        b.state.blockedDOFs = 'zXY'
        _, vx, vy, vz, wx, wy, wz = lines[vels + k]
        b.state.vel = Vector3(float(vx), float(vy), 0.0)
        b.state.angVel = Vector3(0.0, 0.0, float(wz))
";
const GRAINS_SPACE: &str = "        _, vx, vy, vz, wx, wy, wz = lines[vels + k]
        b.state.vel = Vector3(float(vx), float(vy), float(vz))
        b.state.angVel = Vector3(float(wx), float(wy), float(wz))
";

const COMMON: &str = r#"mats = [O.materials.append(FrictMat(young=E[k], poisson=NU[k], density=RHO[k], frictionAngle=math.atan(MU[k]))) for k in range(len(E))]
def grains():
    """The spheres of grains.data, in order, not yet added to the scene."""
    with open('grains.data') as fh:
        lines = [l.split() for l in fh.read().splitlines()]
    atoms = lines.index(['Atoms']) + 2
    vels = lines.index(['Velocities']) + 2
    out = []
    for k in range(int(lines[2][0])):
        i, t, d, rho, x, y, z = lines[atoms + k]
        b = sphere((float(x), float(y), float(z)), 0.5 * float(d), material=mats[int(t) - 1])
        b.state.blockedDOFs = 'zXY'
        _, vx, vy, vz, wx, wy, wz = lines[vels + k]
        b.state.vel = Vector3(float(vx), float(vy), 0.0)
        b.state.angVel = Vector3(0.0, 0.0, float(wz))
        out.append(b)
    return out
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
    InteractionLoop(
        [Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom(hertzian=True)],
        [Ip2_FrictMat_FrictMat_MindlinPhys(betan=BETA, betas=BETA)],
        [Law2_ScGeom_MindlinPhys_Mindlin()],
    ),
] + ([PyRunner(iterPeriod=1, command='record()')] if RECORD else []) + [
    NewtonIntegrator(damping=0.0),
]
O.dt = DT"#;

/// A protocol's run: a row at every step (walls.txt holds every step; the digest averages
/// it into grainlab's rows of each stage, `export.json` stages), and the stages' changes
/// (the rows' velocities, the top clump's control: blocked in y and held, or free in y
/// under a permanent load). The first stage's are made before the run; each later one's in
/// the recording PyRunner of the iteration at the stage's first step, after the forces of
/// that state are recorded and before NewtonIntegrator moves the bodies: as in grainlab,
/// where the last step of a stage ends with its forces and the next stage's first half
/// kick and drift see the new velocities. (Changed before an `O.run` instead, the walls'
/// new velocities would enter the contact forces of the stage's first state, one step
/// early.) The run goes one iteration past the protocol: its PyRunner records the forces
/// of the last step's state.
fn stages<D: Dim>(scene: &Scene, ex: &Exported<D>, shear_run: &str) -> Result<String, Error> {
    let info = &ex.info;
    let phases = crate::study::protocol::phases(scene, info.time_step_s, info.length_m, info.depth_m)?;
    let mut rows = Vec::new();
    // (A stage's gravity was refused in `prepare`.)
    for ph in &phases {
        let py = |x: Option<f64>| x.map_or("None".to_string(), f);
        let [b, t] = &ph.change.walls;
        let load = match t.control {
            Some(Control::Load { force }) => f(force),
            Some(Control::Fixed) => "0.0".into(),
            None => "None".into(),
        };
        rows.push(format!("    ({:?}, {}, {}, {}, {}, {}, {}, {load}),", ph.name, ph.first, ph.steps, py(b.velocity_x), py(b.velocity_y), py(t.velocity_x), py(t.velocity_y)));
    }
    let total = phases.last().map_or(0, |p| p.last());
    // The plain run's script, its record() ending with the stage changes and its O.run
    // replaced by the stages' (each piece found once: a template edited out of step with
    // this fails every protocol export's test, not silently).
    // The two walls' accumulated force components ([`shear_run`]).
    let reset = format!("        for k in range({}):\n            acc[k] = 0.0\n", 2 * D::D);
    let run = edited(shear_run, &reset, &format!("{reset}    while NEXT[0] < len(STAGES) and STAGES[NEXT[0]][1] == O.iter:\n        begin(STAGES[NEXT[0]])\n"));
    let run = edited(
        &run,
        "O.run(STEPS, True)\n",
        &format!(
            "# name, first step, steps, bottom vx, vy, top vx, vy (None: unchanged), top load (N; 0 held, None unchanged)\nSTAGES = [\n{}\n]\n{STAGE_BEGIN}\nbegin(STAGES[0])\nO.run({} + 1, True)\n",
            rows.join("\n"),
            total
        ),
    );
    Ok(format!("NEXT = [0]  # the next stage to begin\n{run}"))
}

/// `text` with its one occurrence of `from` replaced by `to`.
fn edited(text: &str, from: &str, to: &str) -> String {
    assert_eq!(text.matches(from).count(), 1, "the script template holds `{from}` once");
    text.replacen(from, to, 1)
}

const STAGE_BEGIN: &str = r#"def begin(stage):
    global LOAD
    name, first, steps, bvx, bvy, tvx, tvy, load = stage
    NEXT[0] += 1
    for i in bottom:
        v = O.bodies[i].state.vel
        O.bodies[i].state.vel = Vector3(v[0] if bvx is None else bvx, v[1] if bvy is None else bvy, 0)
    if load is not None:
        LOAD = load
        c.blockedDOFs = 'xzXYZ' if LOAD > 0 else 'xyzXYZ'
        O.forces.setPermF(top_clump, Vector3(0, -LOAD, 0))
    c.vel = Vector3(c.vel[0] if tvx is None else tvx, c.vel[1] if tvy is None else tvy, 0)"#;

const IMPACT_SETUP: &str = r#"ids = [O.bodies.append(b) for b in grains()]"#;

const IMPACT_SETUP_ROUGH: &str = r#"bodies = grains()
ids = [O.bodies.append(b) for b in bodies[:FREE]]
for b in bodies[FREE:]:
    b.state.blockedDOFs = 'xyzXYZ'  # a rough wall's row, at its initial velocity
    O.bodies.append(b)"#;

const SHEAR_FREE: &str = r#"O.periodic = True
O.cell.setBox(L, H, H)
bodies = grains()
for b in bodies:
    b.state.pos = b.state.pos + Vector3(-X0, 0.5 * H, 0)  # into the cell [0, L) x [0, H)
ids = [O.bodies.append(b) for b in bodies[:FREE]]"#;

const SHEAR_WALLS: &str = r#"bottom = [O.bodies.append(b) for b in bodies[BOTTOM[0]:BOTTOM[1]]]
for i in bottom:
    O.bodies[i].state.blockedDOFs = 'xyzXYZ'  # a rigid row at its initial velocity
top_clump, top = O.bodies.appendClumped(bodies[TOP[0]:TOP[1]])
c = O.bodies[top_clump].state
c.vel = O.bodies[top[0]].state.vel
c.angVel = Vector3(0, 0, 0)
c.blockedDOFs = 'xzXYZ' if LOAD > 0 else 'xyzXYZ'
if LOAD > 0:
    O.forces.setPermF(top_clump, Vector3(0, -LOAD, 0))"#;

/// The shear cell's run in `D`: [`SHEAR_RUN`] in the plane; in space its walls.txt has
/// the walls' z forces too, under the title line of `columns` (common::wall_columns_in).
fn shear_run<D: Dim>(columns: &[String]) -> String {
    if D::D == 2 {
        return SHEAR_RUN.to_string();
    }
    let run = edited(SHEAR_RUN, "out.write('step bottom_fx_n bottom_fy_n top_fx_n top_fy_n gap_m\\n')", &format!("out.write('{}\\n')", columns.join(" ")));
    let run = edited(&run, "acc = [0.0] * 4", "acc = [0.0] * 6");
    let run = edited(&run, "enumerate((fb[0], fb[1], ft[0], ft[1]))", "enumerate((fb[0], fb[1], fb[2], ft[0], ft[1], ft[2]))");
    edited(&run, "        for k in range(4):\n", "        for k in range(6):\n")
}

const SHEAR_RUN: &str = r#"out = open('walls.txt', 'w')
out.write('step bottom_fx_n bottom_fy_n top_fx_n top_fy_n gap_m\n')
acc = [0.0] * 4
def record():
    fb = Vector3(0, 0, 0)
    for i in bottom:
        fb += O.forces.f(i, sync=True)
    ft = Vector3(0, 0, 0)
    for i in top:
        ft += O.forces.f(i, sync=True)
    for k, v in enumerate((fb[0], fb[1], ft[0], ft[1])):
        acc[k] += v
    if O.iter % SAMPLE == 0:
        gap = O.bodies[top[0]].state.pos[1] - O.bodies[bottom[0]].state.pos[1]
        out.write('%d %s %.17g\n' % (O.iter, ' '.join('%.17g' % (a / SAMPLE) for a in acc), gap))
        for k in range(4):
            acc[k] = 0.0
import time
t0 = time.time()
O.run(STEPS, True)
print('grainlab-loop-seconds %.6f' % (time.time() - t0))
out.close()
sys.exit(0)"#;

const IMPACT: &str = r#"out = open('series.txt', 'w')
cols = ['step']
for k in range(len(ids)):
    cols += ['%s%d' % (q, k) for q in ('x_m', 'y_m', 'vx_m_s', 'vy_m_s', 'omega_rad_s', 'fx_n', 'fy_n')]
out.write(' '.join(cols) + '\n')
def record():
    row = ['%d' % O.iter]
    for i in ids:
        st = O.bodies[i].state
        fo = O.forces.f(i, sync=True)
        row += ['%.17g' % v for v in (st.pos[0], st.pos[1], st.vel[0], st.vel[1], st.angVel[2], fo[0], fo[1])]
    out.write(' '.join(row) + '\n')
import time
t0 = time.time()
O.run(STEPS, True)
print('grainlab-loop-seconds %.6f' % (time.time() - t0))
out.close()
sys.exit(0)"#;

/// The linear spring's per-material parameters in YADE: `ViscElMat(kn, ks, cn, cs)`, which
/// `Ip2_ViscElMat_ViscElMat_ViscElPhys` (YADE 2023.02a, with kn, ks, cn, cs given and no
/// tc, en, et) combines per contact as springs and dashpots in series, `k = k1 k2 / (k1 +
/// k2)`, a 0 standing for none (the contact takes the other body's value); the bodies'
/// masses do not enter. Each of grainlab's pair values (kn, kt, and the damping rates
/// `gn = 2 |beta| sqrt(m* kn)`, `gt = 2 |beta| sqrt(m* kt)`) must therefore be one number
/// per pair of materials, and each material's (and each flat wall's) number is solved
/// from them and checked against every pair: grains of one size per material, or
/// undamped given springs (e = 1) of any sizes, are exact; the rest is refused by name.
struct SpringMaterials {
    /// `[kn, ks, cn, cs]` of each scene material's grains (N/m, N/m, kg/s, kg/s).
    grains: Vec<[f64; 4]>,
    /// The same of each wall (used by the flat ones).
    walls: Vec<[f64; 4]>,
}

/// The quantities of [`SpringMaterials`], as a refusal names them.
const SPRING_QUANTITIES: [&str; 4] = ["normal stiffness", "tangential stiffness", "normal damping rate", "tangential damping rate"];

/// Two of YADE's per-body values in series (`Ip2_ViscElMat_ViscElMat_ViscElPhys`: a 0
/// is no element, the other's value is the contact's).
fn in_series(a: f64, b: f64) -> f64 {
    let s = if a != 0.0 { 1.0 / a } else { 0.0 } + if b != 0.0 { 1.0 / b } else { 0.0 };
    if s != 0.0 { 1.0 / s } else { 0.0 }
}

/// The value `x` whose series with `known` is `target`, if there is one.
fn series_partner(target: f64, known: f64) -> Option<f64> {
    if known == 0.0 {
        Some(target)
    } else if same_value(target, known) {
        Some(0.0)
    } else if target > 0.0 && target < known {
        Some(1.0 / (1.0 / target - 1.0 / known))
    } else {
        None
    }
}

fn spring_materials<D: Dim>(scene: &Scene, ex: &Exported<D>) -> Result<SpringMaterials, Error> {
    use crate::physics::contact::damping::{Damping, LinearRestitution};
    let e = ex.built.engine.as_ref();
    let mats = &scene.materials;
    let n = mats.len();
    let law = scene.model.normal;
    let refused = |detail: String| refuse(Code::Yade, "model.normal", law.name(), &detail);
    let mut grains = vec![[0.0; 4]; n];
    let mut walls = vec![[0.0; 4]; e.walls().len()];
    for (q, what) in SPRING_QUANTITIES.iter().enumerate() {
        // grainlab's value of a contact of materials a and b at (m*, R*).
        let value = |a: usize, b: usize, m: f64, r: f64| {
            let pm = PairMaterial::mix_with(&mats[a], &mats[b], scene.model.beta_rule());
            let st = law.stiffness(&pm, r, m, 0.0);
            let (gn, gt) = LinearRestitution::coefficients(&pm, m.sqrt(), &st);
            [st.kn, st.kt, gn.abs(), gt.abs()][q]
        };
        let kinds = contact_kinds(n, e.particles(), e.walls(), value);
        let pair = |a: usize, b: usize| -> Result<Option<f64>, Error> {
            match kinds.pairs[a * n + b][..] {
                [] => Ok(None),
                [v] => Ok(Some(v)),
                _ => Err(refused(format!("the grains of materials[{a}] and materials[{b}] meet at more than one {what} (grains of several sizes or masses), which YADE's per-material values in series cannot give"))),
            }
        };
        // Each material from its grains' contacts with one another (two equal values in
        // series), then the others from a contact with a material already known.
        let mut known: Vec<Option<f64>> = (0..n).map(|a| pair(a, a).map(|v| v.map(|v| 2.0 * v))).collect::<Result<_, _>>()?;
        loop {
            let mut progress = false;
            for a in 0..n {
                for b in 0..n {
                    if let (Some(va), None, Some(t)) = (known[a], known[b], pair(a, b)?) {
                        known[b] = Some(series_partner(t, va).ok_or_else(|| refused(format!("no {what} of materials[{b}] in series with that of materials[{a}] gives their contacts' {t:e}")))?);
                        progress = true;
                    }
                }
            }
            if !progress {
                // A material that meets others but none known: start from it.
                match (0..n).flat_map(|a| (0..n).map(move |b| (a, b))).find(|&(a, b)| known[a].is_none() && known[b].is_none() && !kinds.pairs[a * n + b].is_empty()) {
                    Some((a, b)) => known[a] = Some(2.0 * pair(a, b)?.expect("listed")),
                    None => break,
                }
            }
        }
        for a in 0..n {
            grains[a][q] = known[a].unwrap_or(0.0);
        }
        for a in 0..n {
            for b in 0..n {
                if let Some(t) = pair(a, b)? {
                    let got = in_series(grains[a][q], grains[b][q]);
                    if !same_value(got, t) {
                        return Err(refused(format!("the grains of materials[{a}] and materials[{b}] would meet at the {what} {got:e} in YADE, {t:e} in grainlab")));
                    }
                }
            }
        }
        // Each flat wall from its contacts with the free grains of each material.
        for (j, per) in kinds.walls.iter().enumerate() {
            let mut wall: Option<f64> = None;
            for (a, list) in per.iter().enumerate() {
                let t = match list[..] {
                    [] => continue,
                    [t] => t,
                    _ => return Err(refused(format!("the free grains of materials[{a}] meet walls.{} at more than one {what} (grains of several sizes or masses)", e.walls()[j].name))),
                };
                let w = match wall {
                    Some(w) => w,
                    None => *wall.insert(series_partner(t, grains[a][q]).ok_or_else(|| refused(format!("no {what} of walls.{} in series with that of materials[{a}] gives their contacts' {t:e}", e.walls()[j].name)))?),
                };
                let got = in_series(grains[a][q], w);
                if !same_value(got, t) {
                    return Err(refused(format!("the free grains of materials[{a}] would meet walls.{} at the {what} {got:e} in YADE, {t:e} in grainlab", e.walls()[j].name)));
                }
            }
            walls[j][q] = wall.unwrap_or(0.0);
        }
    }
    Ok(SpringMaterials { grains, walls })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::NormalLaw;

    #[test]
    fn series_partners_give_the_target_back_in_series() {
        for (target, known) in [(1.0, 3.0), (2.5e5, 4e5), (0.3, 0.3), (7.0, 0.0), (0.0, 0.0)] {
            let x = series_partner(target, known).unwrap();
            let got = in_series(known, x);
            assert!((got - target).abs() <= 1e-15 * target, "{target} {known}: {x} gives {got}");
        }
        // Nothing in series is stiffer than either element (a 0 is no element).
        assert_eq!(series_partner(4.0, 3.0), None);
        assert_eq!(series_partner(0.0, 3.0), None);
    }

    fn spring(scene: &Scene) -> Result<SpringMaterials, Error> {
        let ex = super::super::prepare::prepare::<crate::physics::dim::Plane>(scene, Code::Yade, &crate::scene::limits::Limits::machine())?;
        spring_materials(scene, &ex)
    }

    #[test]
    fn the_spring_of_two_materials_and_a_wall_is_solved_exactly_and_polydisperse_damping_refused() {
        // Two grains of two materials (different moduli and restitutions) hitting each
        // other: one pair, whose four values the two materials' series gives back.
        let mut s = crate::scene::builtin::builtin("collision").unwrap();
        s.model.normal = NormalLaw::Hooke { characteristic_velocity: 1.0 };
        s.materials.push(crate::physics::material::Material { youngs_modulus: 200e9, restitution: 0.5, ..s.materials[0].clone() });
        if let crate::scene::Grains::List(l) = &mut s.grains {
            l[1].material = 1;
        }
        let sm = spring(&s).unwrap();
        let pm = PairMaterial::mix(&s.materials[0], &s.materials[1]);
        let ex = super::super::prepare::prepare::<crate::physics::dim::Plane>(&s, Code::Yade, &crate::scene::limits::Limits::machine()).unwrap();
        let p = ex.built.engine.particles();
        let (m, r) = (crate::physics::material::reduced(p.m[0], p.m[1]), crate::physics::material::reduced(p.r[0], p.r[1]));
        let kn = s.model.normal.stiffness(&pm, r, m, 0.0).kn;
        let gn = 2.0 * pm.beta.abs() * (m * kn).sqrt();
        for (q, want) in [(0, kn), (1, kn), (2, gn), (3, gn)] {
            let got = in_series(sm.grains[0][q], sm.grains[1][q]);
            assert!((got - want).abs() <= 1e-14 * want, "{}: {got} vs {want}", SPRING_QUANTITIES[q]);
        }
        // The oblique impact: a grain on flat walls, the wall's values from the grain's.
        let mut s = crate::scene::builtin::builtin("oblique").unwrap();
        s.model.normal = NormalLaw::HookeStiffness { kn: 2e5, kt: 1.5e5 };
        let sm = spring(&s).unwrap();
        assert!((in_series(sm.grains[0][1], sm.walls[0][1]) - 1.5e5).abs() <= 1e-9);
        // A damped spring in a packing of several sizes: refused by name; undamped, exact.
        let mut s = crate::scene::builtin::shear_cell(60, 0.004);
        s.model.normal = NormalLaw::HookeStiffness { kn: 2e5, kt: 1.5e5 };
        let e = spring(&s).err().expect("refused").to_string();
        assert!(e.contains("model.normal = hooke_stiffness") && e.contains("damping rate"), "{e}");
        s.materials[0].restitution = 1.0;
        let sm = spring(&s).unwrap();
        assert_eq!(sm.grains[0], [4e5, 3e5, 0.0, 0.0]);
        // The derived spring of several sizes: refused (kn differs from pair to pair).
        s.model.normal = NormalLaw::Hooke { characteristic_velocity: 1.0 };
        let e = spring(&s).err().expect("refused").to_string();
        assert!(e.contains("model.normal = hooke") && e.contains("normal stiffness"), "{e}");
    }
}
