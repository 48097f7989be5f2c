//! The YADE 2023.02 script of a scene.
//!
//! Model: `Ip2_FrictMat_FrictMat_MindlinPhys(betan = betas = sqrt(5/6) |beta(e)|)` and
//! `Law2_ScGeom_MindlinPhys_Mindlin` (incremental tangential force, Fn clamped at 0 as
//! YADE always does), spheres with `blockedDOFs = 'zXY'` (the sphere-in-plane model),
//! `NewtonIntegrator(damping = 0)`, flat walls as `wall` bodies with
//! `Ig2_Wall_Sphere_ScGeom(hertzian = True)` (R* = r, m* = m). The restitution is never
//! passed as `en`, which YADE maps through a different damping fit (reference-notes.md).
//!
//! The scene name enters comments only, escaped ([`super::escaped`]). What the script
//! cannot express is refused and what it expresses approximately is noted, both as
//! [`super::fields`] says.

use std::fmt::Write as _;

use super::fields::{differs_line, note, refuse};
use super::liggghts::name_of;
use super::common::{Code, escaped, f};
use super::prepare::{Exported, pressure};
use crate::error::Error;
use crate::physics::contact::LeverArm;
use crate::physics::material::PairMaterial;
use crate::physics::walls::{Control, Surface};
use crate::scene::{Analysis, Scene, TangentialSpec};

pub(crate) fn deck(scene: &Scene, ex: &Exported) -> Result<String, Error> {
    match scene.model.normal {
        crate::scene::NormalLaw::Hertz => {}
        crate::scene::NormalLaw::Hooke { characteristic_velocity } => return Err(refuse(Code::Yade, "model.normal.hooke.characteristic_velocity", characteristic_velocity, "")),
        crate::scene::NormalLaw::HookeStiffness { kn, kt } => return Err(refuse(Code::Yade, "model.normal.hooke_stiffness.kn", kn, &format!("with model.normal.hooke_stiffness.kt = {kt}"))),
    }
    let model = &scene.model;
    let mats = &scene.materials;
    if let Some(k) = mats.iter().position(|m| m.restitution != mats[0].restitution) {
        return Err(refuse(Code::Yade, &format!("materials[{k}].restitution"), mats[k].restitution, &format!("materials[0].restitution = {}", mats[0].restitution)));
    }
    let pairs: Vec<PairMaterial> = mats.iter().flat_map(|a| mats.iter().map(move |b| PairMaterial::mix(a, b))).collect();
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
    let mut s = String::new();
    let w = &mut s;
    let _ = writeln!(w, "# YADE 2023.02a script exported by grainlab {} from scene `{}`. Generated: do not edit;", env!("CARGO_PKG_VERSION"), escaped(&scene.name, &[]));
    let _ = writeln!(w, "# regenerate with `grainlab export yade SCENE --out DIR`.");
    let _ = writeln!(w, "# Run in this directory: yade -n -x yade.py (reads grains.data, writes series.txt).");
    let _ = writeln!(w, "# Recorded between the contact law and the integrator: positions x(n), force F(x(n)), velocities v(n-1/2).");
    if model.tangential == TangentialSpec::TotalDisplacement {
        let _ = writeln!(w, "{}", differs_line(Code::Yade, "model.tangential", name_of(&model.tangential)));
    }
    if !model.limit_force {
        let _ = writeln!(w, "{}", differs_line(Code::Yade, "model.limit_force", false));
    }
    if model.lever_arm != LeverArm::Yade && !frictionless {
        let _ = writeln!(w, "{}", differs_line(Code::Yade, "model.lever_arm", name_of(&model.lever_arm)));
    }
    for wall in walls.iter().filter(|w| w.is_flat()) {
        let _ = writeln!(w, "{}", differs_line(Code::Yade, &format!("walls.{}.surface", wall.name), "flat"));
    }
    // Leapfrog reads the initial velocities as v(-1/2): what is under a force at t = 0
    // starts apart from velocity Verlet's run.
    if let Some(wall) = loaded {
        let _ = writeln!(w, "{}", differs_line(Code::Yade, &format!("walls.{}.control.pressure", wall.name), pressure(scene, wall.name)));
    } else if (0..p.n_free).any(|i| p.f[i] != crate::physics::dim::Vec2::zeros()) {
        let _ = writeln!(w, "# Differs: grains under a force at t = 0: {}", note(Code::Yade, "walls.top.control.pressure"));
    }
    let _ = writeln!(w, "import math, sys");
    let _ = writeln!(w, "E = [{}]", mats.iter().map(|m| f(m.youngs_modulus)).collect::<Vec<_>>().join(", "));
    let _ = writeln!(w, "NU = [{}]", mats.iter().map(|m| f(m.poisson_ratio)).collect::<Vec<_>>().join(", "));
    let _ = writeln!(w, "RHO = [{}]", mats.iter().map(|m| f(m.density)).collect::<Vec<_>>().join(", "));
    let _ = writeln!(w, "MU = [{}]", mats.iter().map(|m| f(if frictionless { 0.0 } else { m.friction })).collect::<Vec<_>>().join(", "));
    let _ = writeln!(w, "BETA = {}  # sqrt(5/6) |ln e| / sqrt(ln^2 e + pi^2)", f(beta));
    let _ = writeln!(w, "DT = {}\nSTEPS = {}", f(info.time_step_s), info.steps);
    let record = !ex.bench && info.analysis != Analysis::None;
    let _ = writeln!(w, "RECORD = {}  # False in a timing deck", if record { "True" } else { "False" });
    let _ = writeln!(w, "{}", COMMON);
    // Without rotation (and with friction: frictionless grains never spin) the free
    // grains' spin is blocked too.
    let no_spin = if model.rotation || frictionless {
        ""
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
        let range = |k: usize| match &walls[k].surface {
            Surface::Rough { grains } => Ok((grains.start, grains.end)),
            Surface::Flat => Err(Error::Export("export to yade: the shear export needs rough walls".into())),
        };
        let ((b0, b1), (t0, t1)) = (range(0)?, range(1)?);
        let ys = p.x.iter().map(|x| x.y);
        let (lo, hi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, c), y| (a.min(y), c.max(y)));
        let load = match walls[1].control {
            Control::Load { force } => force,
            Control::Fixed => 0.0,
        };
        let _ = writeln!(w, "# Periodic in x; YADE cells are periodic in every direction, so y and z are made 10x the packing.");
        let _ = writeln!(w, "X0 = {}\nL = {}\nH = {}", f(b.x_min), f(b.period), f(10.0 * (hi - lo)));
        let _ = writeln!(w, "FREE = {}\nBOTTOM = ({b0}, {b1})\nTOP = ({t0}, {t1})", p.n_free);
        let _ = writeln!(w, "LOAD = {}  # N on the top wall, towards the grains (0: the wall is held)", f(load));
        if scene.stages.is_empty() {
            let _ = writeln!(w, "SAMPLE = {}  # steps per row of walls.txt (forces averaged over each step)", info.sample_every);
        } else {
            let _ = writeln!(w, "SAMPLE = 1  # a protocol's walls.txt: a row at every step");
        }
        let _ = writeln!(w, "{}", SHEAR_FREE);
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
        if scene.stages.is_empty() {
            let _ = writeln!(w, "{}", SHEAR_RUN);
        } else {
            let _ = writeln!(w, "{}", stages(scene, ex)?);
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
    for wall in walls {
        if let Surface::Flat = wall.surface {
            let _ = writeln!(w, "b = O.bodies.append(wall({}, axis=1, sense={}, material=mats[{}]))", f(wall.y), if wall.side > 0.0 { 1 } else { -1 }, wall.material);
            let _ = writeln!(w, "O.bodies[b].state.vel = Vector3({}, 0, 0)", f(wall.v.x));
        }
    }
    let _ = writeln!(w, "{}", IMPACT);
    Ok(s)
}

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
fn stages(scene: &Scene, ex: &Exported) -> Result<String, Error> {
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
    let reset = "        for k in range(4):\n            acc[k] = 0.0\n";
    let run = edited(SHEAR_RUN, reset, &format!("{reset}    while NEXT[0] < len(STAGES) and STAGES[NEXT[0]][1] == O.iter:\n        begin(STAGES[NEXT[0]])\n"));
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
