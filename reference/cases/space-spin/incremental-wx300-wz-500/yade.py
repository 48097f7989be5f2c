# YADE 2023.02a script exported by grainlab 0.1.0 from scene `space-spin-incremental-wx300-wz-500`. Generated: do not edit;
# regenerate with `grainlab export yade SCENE --out DIR`.
# Run in this directory: yade -n -x yade.py (reads grains.data, writes series.txt).
# Recorded between the contact law and the integrator: positions x(n), force F(x(n)), velocities v(n-1/2).
# Differs: walls.bottom.surface = flat: YADE's hertzian wall has a large finite radius, so R* and the ratcheting factor differ from a plane's by O(r / R_wall) (2e-9 relative on the oblique impacts)
# Differs: walls.top.surface = flat: YADE's hertzian wall has a large finite radius, so R* and the ratcheting factor differ from a plane's by O(r / R_wall) (2e-9 relative on the oblique impacts)
import math, sys
E = [6.30000000000000000e10]
NU = [2.00000000000000011e-1]
RHO = [2.50000000000000000e3]
MU = [5.00000000000000000e-1]
BETA = 3.05980177796130147e-2  # sqrt(5/6) |ln e| / sqrt(ln^2 e + pi^2)
DT = 3.14730528547887614e-8
STEPS = 621
RECORD = True  # False in a timing deck
mats = [O.materials.append(FrictMat(young=E[k], poisson=NU[k], density=RHO[k], frictionAngle=math.atan(MU[k]))) for k in range(len(E))]
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
        _, vx, vy, vz, wx, wy, wz = lines[vels + k]
        b.state.vel = Vector3(float(vx), float(vy), float(vz))
        b.state.angVel = Vector3(float(wx), float(wy), float(wz))
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
O.dt = DT
ids = [O.bodies.append(b) for b in grains()]
b = O.bodies.append(wall(0.00000000000000000e0, axis=1, sense=1, material=mats[0]))
O.bodies[b].state.vel = Vector3(0.00000000000000000e0, 0, 0)
b = O.bodies.append(wall(1.00000000000000000e0, axis=1, sense=-1, material=mats[0]))
O.bodies[b].state.vel = Vector3(0.00000000000000000e0, 0, 0)
out = open('series.txt', 'w')
cols = ['step']
for k in range(len(ids)):
    cols += ['%s%d' % (q, k) for q in ('x_m', 'y_m', 'z_m', 'vx_m_s', 'vy_m_s', 'vz_m_s', 'omegax_rad_s', 'omegay_rad_s', 'omegaz_rad_s', 'fx_n', 'fy_n', 'fz_n')]
out.write(' '.join(cols) + '\n')
def record():
    row = ['%d' % O.iter]
    for i in ids:
        st = O.bodies[i].state
        fo = O.forces.f(i, sync=True)
        row += ['%.17g' % v for v in (st.pos[0], st.pos[1], st.pos[2], st.vel[0], st.vel[1], st.vel[2], st.angVel[0], st.angVel[1], st.angVel[2], fo[0], fo[1], fo[2])]
    out.write(' '.join(row) + '\n')
import time
t0 = time.time()
O.run(STEPS, True)
print('grainlab-loop-seconds %.6f' % (time.time() - t0))
out.close()
sys.exit(0)
