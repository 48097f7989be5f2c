//! The YADE 2023.02 script of a scene.
//!
//! Model: `Ip2_FrictMat_FrictMat_MindlinPhys(betan = betas = sqrt(5/6) |beta(e)|)` and
//! `Law2_ScGeom_MindlinPhys_Mindlin` (incremental tangential force, Fn clamped at 0 as
//! YADE always does), spheres with `blockedDOFs = 'zXY'` (the sphere-in-plane model),
//! `NewtonIntegrator(damping = 0)`, flat walls as `wall` bodies with
//! `Ig2_Wall_Sphere_ScGeom(hertzian = True)` (R* = r, m* = m). The restitution is never
//! passed as `en`, which YADE maps through a different damping fit (reference-notes.md).

use std::fmt::Write as _;

use super::{Exported, f};
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
    if ex.info.analysis == Analysis::Shear {
        return refuse("the shear cell is not exported to YADE yet (periodic cell with rough-wall clumps)");
    }
    let e = ex.built.engine.as_ref();
    let info = &ex.info;
    let beta = (5.0f64 / 6.0).sqrt() * pairs[0].beta.abs();
    let frictionless = model.tangential == TangentialSpec::Frictionless;
    let mut s = String::new();
    let w = &mut s;
    let _ = writeln!(w, "# YADE 2023.02a script exported by grainlab {} from scene `{}`. Generated: do not edit;", env!("CARGO_PKG_VERSION"), scene.name);
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
    let _ = writeln!(w, "{}", COMMON);
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
ids = []
with open('grains.data') as fh:
    lines = [l.split() for l in fh.read().splitlines()]
atoms = lines.index(['Atoms']) + 2
vels = lines.index(['Velocities']) + 2
n = int(lines[2][0])
for k in range(n):
    i, t, d, rho, x, y, z = lines[atoms + k]
    b = sphere((float(x), float(y), float(z)), 0.5 * float(d), material=mats[int(t) - 1])
    b.state.blockedDOFs = 'zXY'
    _, vx, vy, vz, wx, wy, wz = lines[vels + k]
    b.state.vel = Vector3(float(vx), float(vy), 0.0)
    b.state.angVel = Vector3(0.0, 0.0, float(wz))
    ids.append(O.bodies.append(b))
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
    InteractionLoop(
        [Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom(hertzian=True)],
        [Ip2_FrictMat_FrictMat_MindlinPhys(betan=BETA, betas=BETA)],
        [Law2_ScGeom_MindlinPhys_Mindlin()],
    ),
    PyRunner(iterPeriod=1, command='record()'),
    NewtonIntegrator(damping=0.0),
]
O.dt = DT"#;

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
O.run(STEPS, True)
out.close()
sys.exit(0)"#;
