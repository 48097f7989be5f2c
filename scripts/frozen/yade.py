# Evaluate a frozen state (src/workbench/frozen.rs) in YADE 2023.02a without moving.
#
#     yade -n -x yade.py STATE_DIR OUT_DIR
#
# Spheres (blockedDOFs 'zXY') in a periodic cell, the flat walls as `utils.wall` bodies
# without bounds (the periodic collider never sees them; their contacts are made with
# `createInteraction`), Hertz-Mindlin with betan = betas = sqrt(5/6) |beta(e)| and no
# global damping. One step creates the interactions, their elastic tangential force
# (`phys.shearElastic`, which the law increments) is set to the engine's, then one step
# of dt = 1e-200 s evaluates the forces: dt = 0 gives NaN (the law divides the shear
# increment by dt), and 1e-200 s moves nothing in double precision while the increment
# it adds is ~1e-190 N. Writes OUT_DIR/contacts.txt (the engine's table) and
# OUT_DIR/summary.txt (avgNumInteractions, fabricTensor, per-grain force).
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0] if sys.argv[0].endswith('.py') else __file__)))
import common  # noqa: E402

STATE, OUT = sys.argv[1], sys.argv[2]
S, G, H = common.scene(STATE), common.grains(STATE), common.history(STATE)
E, NU, e, MU, RHO = S['E'], S['nu'], S['e'], S['mu'], S['rho']
L, YB, YT = S['L'], S['y_bottom'], S['y_top']
BETA = math.sqrt(5.0 / 6.0) * abs(math.log(e)) / math.sqrt(math.log(e) ** 2 + math.pi ** 2)
CELL = 20 * (YT - YB)             # the non-periodic directions made large (the cell is periodic in 3D)
Y0 = 0.5 * CELL - 0.5 * (YB + YT)  # y shifted into the cell
mat = O.materials.append(FrictMat(young=E, poisson=NU, density=RHO, frictionAngle=math.atan(MU)))
O.periodic = True
O.cell.setBox(L, CELL, CELL)
body = {}
for i, g in sorted(G.items()):
    b = sphere((g[0], g[1] + Y0, 0.5 * CELL), g[2], material=mat)
    b.state.blockedDOFs = 'zXY'
    b.state.vel = Vector3(g[3], g[4], 0.0)
    b.state.angVel = Vector3(0.0, 0.0, g[5])
    body[i] = O.bodies.append(b)
walls = {}
for name, y, v in (('bottom', YB, S['vx_bottom']), ('top', YT, S['vx_top'])):
    w = utils.wall(y + Y0, axis=1, material=mat)
    w.state.vel = Vector3(v, 0, 0)
    w.bound = None
    walls[name] = O.bodies.append(w)
grain_of = {b: i for i, b in body.items()}
wall_of = {b: n for n, b in walls.items()}
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb()]),
    InteractionLoop(
        [Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom(hertzian=True)],
        [Ip2_FrictMat_FrictMat_MindlinPhys(betan=BETA, betas=BETA)],
        [Law2_ScGeom_MindlinPhys_Mindlin()],
    ),
    NewtonIntegrator(damping=0.0),
]
O.dt = 1e-200
for name, w in walls.items():
    y = YB if name == 'bottom' else YT
    for i, g in G.items():
        if g[2] - abs(g[1] - y) > 0:
            utils.createInteraction(w, body[i])
O.step()
given = 0
for it in O.interactions:
    if not it.isReal:
        continue
    if it.id1 in wall_of:
        key, sign = (grain_of[it.id2], wall_of[it.id1]), 1.0      # id1 the wall: shearElastic acts on the sphere
    else:
        a, b = grain_of[it.id1], grain_of[it.id2]
        key, sign = ((a, b), -1.0) if (a, b) in H else ((b, a), 1.0)  # the force on id1 is -shearElastic
    if key not in H:
        sys.exit('YADE sees contact %s touching, the engine does not' % (key,))
    fx, fy = common.handed_over(H[key][:2], H[key][2])
    it.phys.shearElastic = Vector3(sign * fx, sign * fy, 0.0)
    it.phys.usElastic = Vector3(0, 0, 0)
    given += 1
if given != len(H):
    sys.exit('the engine has %d contacts, YADE %d' % (len(H), given))
O.step()
rows = []
for it in O.interactions:
    if not it.isReal:
        continue
    g, p = it.geom, it.phys
    n, Fn, Ft = g.normal, -p.normalForce, -p.shearForce     # on id1, n from id1 to id2
    if it.id1 in wall_of:
        i, j, n, Fn, Ft = grain_of[it.id2], wall_of[it.id1], -n, -Fn, -Ft
    else:
        i, j = grain_of[it.id1], grain_of[it.id2]
        if i > j:
            i, j, n, Fn, Ft = j, i, -n, -Fn, -Ft
    gi = G[i]
    dn = g.penetrationDepth
    c = gi[2] - (dn if isinstance(j, str) else 0.5 * dn)   # mid-overlap, or on a wall's plane
    rows.append((i, j, gi[0] + c * n[0], gi[1] + c * n[1], n[0], n[1], dn, Fn[0], Fn[1], Ft[0], Ft[1]))
os.makedirs(OUT, exist_ok=True)
common.write_contacts(os.path.join(OUT, 'contacts.txt'), rows, 'YADE 2023.02a, one step of 1e-200 s on the frozen state')
with open(os.path.join(OUT, 'summary.txt'), 'w') as f:
    f.write('avgNumInteractions %.17g\n' % utils.avgNumInteractions())
    ft = utils.fabricTensor()[0]
    f.write('fabricTensor xx %.17g yy %.17g xy %.17g\n' % (ft[0, 0], ft[1, 1], ft[0, 1]))
    for i in sorted(G):
        F = O.forces.f(body[i])
        f.write('grain %d F %.17g %.17g\n' % (i, F[0], F[1]))
print('wrote', os.path.join(OUT, 'contacts.txt'), 'and summary.txt:', len(rows), 'contacts')
sys.exit(0)
