//! The YADE 2023.02 script of a scene.
//!
//! Model: `Ip2_FrictMat_FrictMat_MindlinPhys(betan = betas = sqrt(5/6) |beta(e)|)` and
//! `Law2_ScGeom_MindlinPhys_Mindlin` (incremental tangential force, Fn clamped at 0 as
//! YADE always does), spheres with `blockedDOFs = 'zXY'` (the sphere-in-plane model),
//! `NewtonIntegrator(damping = 0)`, flat walls as `wall` bodies with
//! `Ig2_Wall_Sphere_ScGeom(hertzian = True)` (R* = r, m* = m). The restitution is never
//! passed as `en`, which YADE maps through a different damping fit (reference-notes.md).

use std::fmt::Write as _;

use super::{Exported, escaped, f};
use crate::error::Error;
use crate::material::PairMaterial;
use crate::scene::{Analysis, Scene, TangentialSpec};
use crate::walls::Surface;

pub(crate) fn deck(scene: &Scene, ex: &Exported) -> Result<String, Error> {
    let refuse = |what: &str| Err(Error::Other(format!("export to yade: {what}")));
    let model = &scene.model;
    let mats = &scene.materials;
    let pairs: Vec<PairMaterial> = mats.iter().flat_map(|a| mats.iter().map(move |b| PairMaterial::mix(a, b))).collect();
    if pairs.iter().any(|p| p.beta != pairs[0].beta) {
        return refuse("YADE's Ip2 takes one betan for all pairs: give every material the same restitution");
    }
    let e = ex.built.engine.as_ref();
    let info = &ex.info;
    let beta = (5.0f64 / 6.0).sqrt() * pairs[0].beta.abs();
    let frictionless = model.tangential == TangentialSpec::Frictionless;
    let mut s = String::new();
    let w = &mut s;
    let _ = writeln!(w, "# YADE 2023.02a script exported by grainlab {} from scene `{}`. Generated: do not edit;", env!("CARGO_PKG_VERSION"), escaped(&scene.name, &[]));
    let _ = writeln!(w, "# regenerate with `grainlab export yade SCENE --out DIR`.");
    let _ = writeln!(w, "# Run in this directory: yade -n -x yade.py (reads grains.data, writes series.txt).");
    let _ = writeln!(w, "# Recorded between the contact law and the integrator: positions x(n), force F(x(n)), velocities v(n-1/2).");
    if model.tangential == TangentialSpec::TotalDisplacement {
        let _ = writeln!(w, "# Differs: the scene's tangential model is total displacement (LIGGGHTS); YADE's is incremental. Only head-on impacts agree.");
    }
    if !model.limit_force {
        let _ = writeln!(w, "# Differs: YADE always clamps Fn >= 0; the scene does not (model.limit_force = false).");
    }
    let _ = writeln!(w, "import math, sys");
    let _ = writeln!(w, "E = [{}]", mats.iter().map(|m| f(m.youngs_modulus)).collect::<Vec<_>>().join(", "));
    let _ = writeln!(w, "NU = [{}]", mats.iter().map(|m| f(m.poisson_ratio)).collect::<Vec<_>>().join(", "));
    let _ = writeln!(w, "RHO = [{}]", mats.iter().map(|m| f(m.density)).collect::<Vec<_>>().join(", "));
    let _ = writeln!(w, "MU = [{}]", mats.iter().map(|m| f(if frictionless { 0.0 } else { m.friction })).collect::<Vec<_>>().join(", "));
    let _ = writeln!(w, "BETA = {}  # sqrt(5/6) |ln e| / sqrt(ln^2 e + pi^2)", f(beta));
    let _ = writeln!(w, "DT = {}\nSTEPS = {}", f(info.time_step_s), info.steps);
    let _ = writeln!(w, "RECORD = {}  # False in a timing deck", if ex.bench { "False" } else { "True" });
    let _ = writeln!(w, "{}", COMMON);
    if info.analysis == Analysis::Shear {
        let b = e.boundary();
        if !b.is_periodic() {
            return refuse("the shear export needs a periodic x");
        }
        let walls = e.walls();
        let range = |k: usize| match &walls[k].surface {
            Surface::Rough { grains } => Ok((grains.start, grains.end)),
            Surface::Flat => Err(Error::Other("export to yade: the shear export needs rough walls".into())),
        };
        let ((b0, b1), (t0, t1)) = (range(0)?, range(1)?);
        let p = e.particles();
        let ys = p.x.iter().map(|x| x.y);
        let (lo, hi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, c), y| (a.min(y), c.max(y)));
        let load = match walls[1].control {
            crate::walls::Control::Load { force } => force,
            crate::walls::Control::Fixed => 0.0,
        };
        let _ = writeln!(w, "# Periodic in x; YADE cells are periodic in every direction, so y and z are made 10x the packing.");
        let _ = writeln!(w, "X0 = {}\nL = {}\nH = {}", f(b.x_min), f(b.period), f(10.0 * (hi - lo)));
        let _ = writeln!(w, "FREE = {}\nBOTTOM = ({b0}, {b1})\nTOP = ({t0}, {t1})", p.n_free);
        let _ = writeln!(w, "LOAD = {}  # N on the top wall, towards the grains (0: the wall is held)", f(load));
        let _ = writeln!(w, "SAMPLE = {}  # steps per row of walls.txt (forces averaged over each step)", info.sample_every);
        let _ = writeln!(w, "{}", SHEAR);
        return Ok(s);
    }
    let _ = writeln!(w, "{}", IMPACT_SETUP);
    for wall in e.walls() {
        if let Surface::Flat = wall.surface {
            let ws = scene.walls.as_ref().expect("walls");
            let m = if wall.name == "bottom" { ws.bottom.material } else { ws.top.material };
            let _ = writeln!(w, "b = O.bodies.append(wall({}, axis=1, sense={}, material=mats[{m}]))", f(wall.y), if wall.side > 0.0 { 1 } else { -1 });
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

const IMPACT_SETUP: &str = r#"ids = [O.bodies.append(b) for b in grains()]"#;

const SHEAR: &str = r#"O.periodic = True
O.cell.setBox(L, H, H)
bodies = grains()
for b in bodies:
    b.state.pos = b.state.pos + Vector3(-X0, 0.5 * H, 0)  # into the cell [0, L) x [0, H)
ids = [O.bodies.append(b) for b in bodies[:FREE]]
bottom = [O.bodies.append(b) for b in bodies[BOTTOM[0]:BOTTOM[1]]]
for i in bottom:
    O.bodies[i].state.blockedDOFs = 'xyzXYZ'  # a rigid row at its initial velocity
top_clump, top = O.bodies.appendClumped(bodies[TOP[0]:TOP[1]])
c = O.bodies[top_clump].state
c.vel = O.bodies[top[0]].state.vel
c.angVel = Vector3(0, 0, 0)
c.blockedDOFs = 'xzXYZ' if LOAD > 0 else 'xyzXYZ'
if LOAD > 0:
    O.forces.setPermF(top_clump, Vector3(0, -LOAD, 0))
out = open('walls.txt', 'w')
out.write('step bottom_fx_n bottom_fy_n top_fx_n top_fy_n gap_m\n')
acc = [0.0] * 5
def record():
    fb = Vector3(0, 0, 0)
    for i in bottom:
        fb += O.forces.f(i, sync=True)
    ft = Vector3(0, 0, 0)
    for i in top:
        ft += O.forces.f(i, sync=True)
    gap = O.bodies[top[0]].state.pos[1] - O.bodies[bottom[0]].state.pos[1]
    for k, v in enumerate((fb[0], fb[1], ft[0], ft[1], gap)):
        acc[k] += v
    if O.iter % SAMPLE == 0:
        out.write('%d %s\n' % (O.iter, ' '.join('%.17g' % (a / SAMPLE) for a in acc)))
        for k in range(5):
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
