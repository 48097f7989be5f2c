# YADE 2023.02a script exported by grainlab 0.1.0 from scene `space-shear-ensemble-yade-seed-2`. Generated: do not edit;
# regenerate with `grainlab export yade SCENE --out DIR`.
# Run in this directory: yade -n -x yade.py (reads grains.data, writes series.txt).
# Recorded between the contact law and the integrator: positions x(n), force F(x(n)), velocities v(n-1/2).
# Differs: walls.top.control.pressure = 100000: YADE's leapfrog takes the initial velocities as v(-1/2), grainlab's velocity Verlet as v(0): bodies under a force at t = 0 (the loaded wall, touching grains) start O(a dt^2) apart, which a flow forgets
import math, sys
E = [6.30000000000000000e10]
NU = [2.00000000000000011e-1]
RHO = [2.50000000000000000e3]
MU = [5.00000000000000000e-1]
BETA = 1.96681475880436663e-1  # sqrt(5/6) |ln e| / sqrt(ln^2 e + pi^2)
DT = 5.78717239854016999e-8
STEPS = 345592
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
# Periodic in x and z; YADE cells are periodic in every direction, so y is made 10x the packing.
X0 = 0.00000000000000000e0
L = 5.00000000000000010e-3
H = 9.64461312669049331e-2
Z0 = 0.00000000000000000e0
LZ = 5.00000000000000010e-3
FREE = 200
BOTTOM = (200, 225)
TOP = (225, 250)
LOAD = 2.50000000000000000e0  # N on the top wall, towards the grains (0: the wall is held)
SAMPLE = 1727  # steps per row of walls.txt (forces averaged over each step)
O.periodic = True
O.cell.setBox(L, H, LZ)
bodies = grains()
for b in bodies:
    b.state.pos = b.state.pos + Vector3(-X0, 0.5 * H, -Z0)  # into the cell [0, L) x [0, H) x [0, LZ)
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
out.write('step bottom_fx_n bottom_fy_n bottom_fz_n top_fx_n top_fy_n top_fz_n gap_m\n')
acc = [0.0] * 6
def record():
    fb = Vector3(0, 0, 0)
    for i in bottom:
        fb += O.forces.f(i, sync=True)
    ft = Vector3(0, 0, 0)
    for i in top:
        ft += O.forces.f(i, sync=True)
    for k, v in enumerate((fb[0], fb[1], fb[2], ft[0], ft[1], ft[2])):
        acc[k] += v
    if O.iter % SAMPLE == 0:
        gap = O.bodies[top[0]].state.pos[1] - O.bodies[bottom[0]].state.pos[1]
        out.write('%d %s %.17g\n' % (O.iter, ' '.join('%.17g' % (a / SAMPLE) for a in acc), gap))
        for k in range(6):
            acc[k] = 0.0
import time
t0 = time.time()
O.run(STEPS, True)
print('grainlab-loop-seconds %.6f' % (time.time() - t0))
out.close()
sys.exit(0)
