"""Reading a frozen state (src/workbench/frozen.rs writes it) for the reference scripts."""
import math
import os

# A contact that slid at the frozen step is handed over this much beyond its Coulomb
# cap: the codes' test is strict (|Ft| > mu Fn), and a force exactly at the cap, as the
# engine leaves it, may fall either side. The capped force does not depend on it. 1e-9
# is enough for LIGGGHTS; YADE's cap differs from the engine's by up to ~1e-6 of a
# small contact's force (its normal damping's kinematics), and with 1e-9 (1e-7) it kept
# 13 (1) of the 56 sliding contacts of frozen/yade sticking, with 1e-5 none.
BEYOND_CAP = 1 + 1e-5


def lines(d, name):
    """The words of each line of DIR/name that holds any, comments ('#' on) left out."""
    with open(os.path.join(d, name)) as f:
        for line in f:
            w = line.split("#")[0].split()
            if w:
                yield w


def scene(d):
    return {w[0]: float(w[1]) for w in lines(d, "scene.txt")}


def grains(d):
    """id -> (x, y, r, vx, vy, omega)."""
    return {int(w[0]): tuple(float(v) for v in w[1:7]) for w in lines(d, "grains.txt")}


def history(d):
    """(i, j) -> (ft_x, ft_y, sliding): j an int, or 'bottom' / 'top'."""
    return {(int(w[0]), w[1] if w[1] in ("bottom", "top") else int(w[1])): (float(w[2]), float(w[3]), w[4] == "1") for w in lines(d, "history.txt")}


def handed_over(ft, sliding):
    s = BEYOND_CAP if sliding else 1.0
    return (ft[0] * s, ft[1] * s)


def stiffness_t(S, ri, rj, dn):
    """Hertz-Mindlin kt = 8 G* sqrt(R* dn) of one material (rj None: a wall, R* = ri)."""
    E, nu = S["E"], S["nu"]
    g_star = 1.0 / (2 * 2 * (2 - nu) * (1 + nu) / E)
    r_star = ri if rj is None else ri * rj / (ri + rj)
    return 8 * g_star * math.sqrt(r_star * dn)


def write_contacts(path, rows, note):
    """rows: (i, j, cx, cy, nx, ny, dn, Fnx, Fny, Ftx, Fty), pairs first by i then j, then walls;
    the contact point mid-overlap between grains, on the plane for a wall."""
    rows = sorted(rows, key=lambda r: (isinstance(r[1], str), r[0], r[1] if isinstance(r[1], int) else (0 if r[1] == "bottom" else 1)))
    with open(path, "w") as f:
        f.write("# i j cx cy nx ny dn Fnx Fny Ftx Fty (n from i to j or towards the wall; forces on i) " + note + "\n")
        for r in rows:
            f.write("%d %s" % (r[0], r[1]) + "".join(" %.17g" % v for v in r[2:]) + "\n")
