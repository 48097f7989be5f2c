#!/usr/bin/python3
"""Evaluate a frozen state (src/workbench/frozen.rs) in LIGGGHTS 3.8 without moving.

    liggghts.py STATE_DIR OUT_DIR

STATE_DIR holds scene.txt, grains.txt, history.txt. LIGGGHTS has no input command that
sets a pair's tangential history, but restores it from a restart file, so:
  stage 1: read_data, run 0, write_restart: every touching pair is in the restart, with
           zero history; the wall histories go in with `set ... property/atom history_<fix>`
  patch:   each pair's history xi = -Ft/kt (Ft the engine's elastic tangential force) is
           written into both atoms' contact-history records (patch_restart.py)
  stage 2: read_restart, the same pair and walls, and one `run 0` (a second run after
           read_restart loses the restored histories, LIGGGHTS 3.8) with
           `compute pair/gran/local`, `contact/atom`, `stress/atom pair` and the walls'
           `store_force`.
`run 0` computes the forces from the loaded positions, velocities and histories without
updating the histories. Writes OUT_DIR/contacts.txt (the engine's table) and
OUT_DIR/summary.txt (per grain: contact count, stress/atom pair; their sums).
"""
import math
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
import patch_restart  # noqa: E402

LIG = os.environ.get("LIGGGHTS", "liggghts")


def main(state, out):
    S, G, H = common.scene(state), common.grains(state), common.history(state)
    L, yb, yt = S["L"], S["y_bottom"], S["y_top"]
    rmax = max(g[2] for g in G.values())
    tmp = tempfile.mkdtemp(prefix="grainlab-frozen-lig-")
    with open(os.path.join(tmp, "grains.data"), "w") as f:
        f.write("frozen state (grainlab freeze)\n\n%d atoms\n1 atom types\n\n" % len(G))
        f.write("0 %.17g xlo xhi\n%.17g %.17g ylo yhi\n%.17g %.17g zlo zhi\n\nAtoms\n\n" % (L, yb - 2 * rmax, yt + 2 * rmax, -1.2 * rmax, 1.2 * rmax))
        for i, g in sorted(G.items()):
            f.write("%d 1 %.17g %.17g %.17g %.17g 0\n" % (i, 2 * g[2], S["rho"], g[0], g[1]))
        f.write("\nVelocities\n\n")
        for i, g in sorted(G.items()):
            f.write("%d %.17g %.17g 0 0 0 %.17g\n" % (i, g[3], g[4], g[5]))
    limit = " limitForce on" if S["limitForce"] else ""
    common_deck = f"""atom_modify map array
boundary p f f
newton off
communicate single vel yes
units si
{{read}}
neighbor {0.5 * rmax:.17g} bin
neigh_modify delay 0
hard_particles yes
fix m1 all property/global youngsModulus peratomtype {S['E']:.17g}
fix m2 all property/global poissonsRatio peratomtype {S['nu']:.17g}
fix m3 all property/global coefficientRestitution peratomtypepair 1 {S['e']:.17g}
fix m4 all property/global coefficientFriction peratomtypepair 1 {S['mu']:.17g}
pair_style gran model hertz tangential history{limit}
pair_coeff * *
timestep {S['dt']:.17g}
fix wb all wall/gran model hertz tangential history{limit} primitive type 1 yplane {yb:.17g} shear x {S['vx_bottom']:.17g} store_force yes
fix wt all wall/gran model hertz tangential history{limit} primitive type 1 yplane {yt:.17g} shear x {S['vx_top']:.17g} store_force yes
"""
    pairs, sets = {}, ""
    for (i, j), (fx, fy, sliding) in sorted(H.items(), key=lambda kv: (kv[0][0], str(kv[0][1]))):
        fx, fy = common.handed_over((fx, fy), sliding)
        gi = G[i]
        if isinstance(j, str):
            dn = gi[2] - abs(gi[1] - (yb if j == "bottom" else yt))
            kt = common.stiffness_t(S, gi[2], None, dn)
            sets += "set atom %d property/atom history_%s %.17g %.17g 0\n" % (i, "wb" if j == "bottom" else "wt", -fx / kt, -fy / kt)
        else:
            gj = G[j]
            dx = gj[0] - gi[0]
            dx -= L * round(dx / L)
            dn = gi[2] + gj[2] - math.hypot(dx, gj[1] - gi[1])
            kt = common.stiffness_t(S, gi[2], gj[2], dn)
            pairs[(i, j)] = (-fx / kt, -fy / kt, 0.0)
    with open(os.path.join(tmp, "in.stage1"), "w") as f:
        f.write("atom_style granular\n" + common_deck.format(read="read_data grains.data") + "run 0\n" + sets + "write_restart stage1.restart\n")
    cols = " ".join("c_pgl[%d]" % k for k in range(1, 26))
    with open(os.path.join(tmp, "in.stage2"), "w") as f:
        f.write("atom_style granular\n" + common_deck.format(read="read_restart stage2.restart") + f"""compute pgl all pair/gran/local id pos force force_normal force_tangential torque history delta
compute ca all contact/atom
compute sp all stress/atom pair
dump dl all local 1 pairs.local {cols}
dump_modify dl format "{' '.join(['%.17g'] * 25)}"
dump da all custom 1 atoms.dump id x y fx fy f_force_wb[1] f_force_wb[2] f_force_wt[1] f_force_wt[2] c_ca c_sp[1] c_sp[2] c_sp[4]
dump_modify da sort id format "%d {' '.join(['%.17g'] * 12)}"
run 0
""")

    def run(deck):
        r = subprocess.run(["stdbuf", "-o0", "-e0", LIG, "-in", deck, "-log", deck + ".log", "-echo", "screen"], cwd=tmp, capture_output=True, text=True)
        if r.returncode != 0 or "ERROR" in r.stdout:
            sys.exit("liggghts %s failed:\n%s\n%s" % (deck, r.stdout[-3000:], r.stderr[-2000:]))

    run("in.stage1")
    # The patcher finds each atom's record by its exact position and id.
    patch_restart.patch(os.path.join(tmp, "stage1.restart"), os.path.join(tmp, "stage2.restart"), [(i, g[0], g[1]) for i, g in G.items()], pairs, L)
    run("in.stage2")
    rows = []
    for line in open(os.path.join(tmp, "pairs.local")):
        w = line.split()
        if len(w) != 25:
            continue
        try:
            v = [float(t) for t in w]
        except ValueError:
            continue
        i, j, F = int(v[6]), int(v[7]), [v[9], v[10]]
        if i > j:
            i, j, F = j, i, [-F[0], -F[1]]
        gi, gj = G[i], G[j]
        dx = gj[0] - gi[0]
        dx -= L * round(dx / L)
        dy = gj[1] - gi[1]
        d = math.hypot(dx, dy)
        rows.append(split(i, j, gi, dx / d, dy / d, v[24], F))
    atoms = {}
    for line in open(os.path.join(tmp, "atoms.dump")):
        w = line.split()
        if len(w) == 13 and w[0].isdigit():
            atoms[int(w[0])] = [float(t) for t in w]
    for name, yw, col in (("bottom", yb, 5), ("top", yt, 7)):
        for i, g in sorted(G.items()):
            dn = g[2] - abs(g[1] - yw)
            if dn > 0:
                rows.append(split(i, name, g, 0.0, 1.0 if yw > g[1] else -1.0, dn, atoms[i][col:col + 2], wall=True))
    os.makedirs(out, exist_ok=True)
    common.write_contacts(os.path.join(out, "contacts.txt"), rows, "LIGGGHTS 3.8.0 run 0 on the frozen state")
    with open(os.path.join(out, "summary.txt"), "w") as f:
        f.write("# per grain: id contact/atom (grain-grain contacts) stress/atom pair xx yy xy (stress times volume, N m, LAMMPS' sign: minus the virial)\n")
        for i in sorted(atoms):
            a = atoms[i]
            f.write("%d %d %.17g %.17g %.17g\n" % (i, round(a[9]), a[10], a[11], a[12]))
    shutil.rmtree(tmp)
    print("wrote", os.path.join(out, "contacts.txt"), "and summary.txt:", len(rows), "contacts")


def split(i, j, g, nx, ny, dn, F, wall=False):
    """A contact row: the force on i split along n (from i to j) and across; the contact
    point mid-overlap on the line of centres, or on a wall's plane."""
    fn = F[0] * nx + F[1] * ny
    c = g[2] - (dn if wall else 0.5 * dn)
    return (i, j, g[0] + c * nx, g[1] + c * ny, nx, ny, dn, fn * nx, fn * ny, F[0] - fn * nx, F[1] - fn * ny)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
