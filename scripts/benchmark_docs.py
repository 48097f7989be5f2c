"""Plots and the results table of docs/benchmarks.md from the rows tests/chung_ooi.rs wrote
(one CSV per test in the folder given): grainlab's values as points, the closed forms as
lines, for the sphere in the plane and for disks."""
import csv, os, sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "docs", "benchmarks")
rows_dir = sys.argv[1]
os.makedirs(OUT, exist_ok=True)


def rows(test):
    return list(csv.DictReader(open(os.path.join(rows_dir, f"{test}.csv"))))


SHAPES = [("sphere_in_plane", "sphere in the plane", "o"), ("disk", "disk", "s")]
FORMS = [("total_displacement", "C0"), ("incremental_force", "C3"), ("total_force_cap", "C2"), ("total_force_cap_spring_kept", "C4"), ("mindlin_deresiewicz", "C1")]


def series(rs, shape, form, quantity):
    pts = sorted((float(r["x"]), float(r["grainlab"]), float(r["closed_form"]) if r["closed_form"] else None) for r in rs if r["shape"] == shape and r["form"] == form and r["quantity"] == quantity)
    return pts


# Test 3: realised against input restitution.
fig, ax = plt.subplots(figsize=(8.5, 4))
t3 = rows("test_3")
for (shape, label, marker) in SHAPES:
    for mat, color in [("Al2O3", "C0"), ("cast_iron", "C1")]:
        p = series(t3, shape, mat, "restitution_normal")
        ax.plot([x for x, _, _ in p], [y for _, y, _ in p], marker, mfc="none", color=color, label=f"{mat.replace('_', ' ')}, {label}")
ax.plot([0, 1], [0, 1], "k-", lw=0.8, label="input e (closed form)")
# Under the clamp (test_3_clamped): the clamped damping returns e; beta(e) returns more,
# on its own closed form.
t3c = rows("test_3_clamped")
for (shape, label, marker) in SHAPES:
    for mat, color in [("Al2O3", "C0"), ("cast_iron", "C1")]:
        p = series(t3c, shape, mat, "restitution_normal")
        ax.plot([x for x, _, _ in p], [y for _, y, _ in p], "^" if shape == "disk" else "v", mfc="none", color=color, ms=5, label=f"{mat.replace('_', ' ')}, {label}, clamp + clamped_restitution")
        p = series(t3c, shape, mat + "_beta_e", "restitution_normal")
        ax.plot([x for x, _, _ in p], [y for _, y, _ in p], "x", color=color, ms=5, label=f"{mat.replace('_', ' ')}, {label}, clamp + beta(e)")
c = sorted((x, cf) for x, _, cf in series(t3c, "sphere_in_plane", "Al2O3_beta_e", "restitution_normal"))
ax.plot([x for x, _ in c], [y for _, y in c], "k--", lw=0.8, label="beta(e) under the clamp (closed form)")
ax.set_xlabel("input e")
ax.set_ylabel("realised e")
ax.set_title("Test 3: restitution on a rigid plane (t_c/1000)")
ax.legend(fontsize=6, loc="center left", bbox_to_anchor=(1.02, 0.5))
fig.tight_layout()
fig.savefig(os.path.join(OUT, "test_3.png"), dpi=110)

def reference(case, code):
    """A committed reference run's impact summary (reference/cases/chung-ooi), or None."""
    path = os.path.join(ROOT, "reference", "cases", "chung-ooi", case, "expected", code, "impact.csv")
    return next(csv.DictReader(open(path)), None) if os.path.exists(path) else None


CODES = [("liggghts", "history", "LIGGGHTS 3.8.0 (history; no clamp, arm r - dn/2)", "C0"), ("yade", "incremental", "YADE 2023.02a (Mindlin; clamp, its kinematics)", "C3")]

# Test 4: tangential restitution and rebound spin against angle.
fig, axes = plt.subplots(1, 2, figsize=(10, 4))
t4 = rows("test_4")
for ax, q, ylabel in [(axes[0], "tangential_restitution", "tangential restitution e_t"), (axes[1], "spin_r_over_v", "rebound spin w r / v")]:
    for (shape, label, marker) in SHAPES:
        for form, color in FORMS:
            p = series(t4, shape, form, q)
            ax.plot([x for x, _, _ in p], [y for _, y, _ in p], marker, mfc="none", color=color, ms=5, label=f"{form.replace('_', ' ')}, {label}")
            c = [(x, cf) for x, _, cf in p if cf is not None]
            if form == "total_displacement":
                ax.plot([x for x, _ in c], [y for _, y in c], "-", color="k" if shape == "disk" else "0.5", lw=0.8, label=f"gross sliding (closed form), {label}")
    for code, tag, label, color in CODES:
        pts = [(a, reference(f"test4-{tag}-a{a}", code)) for a in range(5, 90, 10)]
        key = {"tangential_restitution": lambda r: float(r["restitution_tangential"]), "spin_r_over_v": lambda r: float(r["rebound_spin_rad_s"]) * 2.5e-3 / 3.9}[q]
        pts = [(a, key(r)) for a, r in pts if r]
        ax.plot([a for a, _ in pts], [y for _, y in pts], "+", color=color, ms=9, label=f"{label}, sphere in the plane")
    ax.set_xlabel("impact angle from the normal, degrees")
    ax.set_ylabel(ylabel)
axes[0].legend(fontsize=6)
fig.suptitle("Test 4: Al2O3 on a rigid plane at 3.9 m/s, e = 0.98, mu = 0.092 (clamp on)")
fig.tight_layout()
fig.savefig(os.path.join(OUT, "test_4.png"), dpi=110)

# Test 6: rebound tangential velocity and spin against the initial spin.
fig, axes = plt.subplots(1, 2, figsize=(10, 4))
t6 = rows("test_6")
for ax, q, ylabel in [(axes[0], "vt_over_vn", "rebound tangential velocity / vn"), (axes[1], "spin_r_over_vn", "rebound spin w r / vn")]:
    for (shape, label, marker) in SHAPES:
        for form, color in FORMS:
            p = series(t6, shape, form, q)
            ax.plot([x for x, _, _ in p], [y for _, y, _ in p], marker, mfc="none", color=color, ms=6, label=f"{form.replace('_', ' ')}, {label}")
            if form == "total_displacement":
                ax.plot([x for x, _, _ in p], [c for _, _, c in p], "x", color="k", ms=8, label=f"gross sliding (closed form), {label}")
    for code, tag, label, color in CODES:
        pts = [(w, reference(f"test6-{tag}-w{w}", code)) for w in (-10, -4, 3, 5, 10)]
        key = {"vt_over_vn": lambda r: float(r["rebound_tangential_velocity_m_s"]) / 0.2, "spin_r_over_vn": lambda r: float(r["rebound_spin_rad_s"]) * 0.1 / 0.2}[q]
        pts = [(w, key(r)) for w, r in pts if r]
        ax.plot([w for w, _ in pts], [y for _, y in pts], "+", color=color, ms=9, label=f"{label}, sphere in the plane")
    ax.set_xlabel("initial spin w0 r / vn")
    ax.set_ylabel(ylabel)
axes[0].legend(fontsize=6)
fig.suptitle("Test 6: Al on a rigid plane, vn = 0.2 m/s, e = 0.5, mu = 0.4 (clamp on)")
fig.tight_layout()
fig.savefig(os.path.join(OUT, "test_6.png"), dpi=110)

# Against the paper's curves (tests/data/chung_ooi_paper, Kratos' digitisation): test 6's
# beta against x, test 5's spin against tan(angle) / mu (the paper's theory for steel and
# its finite-element reference), every formulation.
fig, axes = plt.subplots(1, 3, figsize=(16, 4.2))
tp = rows("paper")
PANELS = [
    (axes[0], "test6_beta", " (clamped damping)", "Chung & Ooi (2011), test 6 (Kratos' digitisation)", "x = 3.5 mu (1 + e) vn / |v_c0|", "beta = -v_c' / v_c0", "Test 6: Al sphere on a plane, e = 0.5, mu = 0.4 (shaded: sliding)"),
    (axes[1], "test5_spin", "", "Chung & Ooi (2011), steel, theory (Kratos' digitisation)", "tan(incident angle) / mu", "rebound spin r w' / (mu vn)", "Test 5: steel sphere on a plane, e = 1, mu = 0.3"),
    (axes[2], "test5_fem_spin", "", "Chung & Ooi (2011), finite elements (Kratos' digitisation)", "tan(incident angle) / mu", "rebound spin r w' / (mu vn)", "Test 5 against the finite-element reference"),
]
for ax, q, note, paper_label, xlabel, ylabel, title in PANELS:
    for form, color in FORMS:
        p = series(tp, "sphere_in_plane", form, q)
        ax.plot([x for x, _, _ in p], [y for _, y, _ in p], "o-", mfc="none", color=color, ms=5, lw=0.6, label=f"grainlab {form.replace('_', ' ')}{note}")
    p = series(tp, "sphere_in_plane", "total_displacement", q)
    ax.plot([x for x, _, _ in p], [c for _, _, c in p], "k-", lw=1.2, label=paper_label)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=9)
axes[0].plot([0.15, 1.0], [-0.85, 0.0], "k:", lw=0.8, label="gross sliding, beta = x - 1")
axes[0].axvspan(0.1, 1.0, color="0.93", lw=0)
axes[0].set_xscale("log")
for ax in axes:
    ax.legend(fontsize=6)
fig.tight_layout()
fig.savefig(os.path.join(OUT, "paper.png"), dpi=110)

# Tests 1 and 2: a table.
table = ["| test | material | shape | quantity | grainlab | closed form | difference |", "|---|---|---|---|---:|---:|---:|"]
names = {"test_1": {1.0: "glass", 2.0: "limestone"}, "test_2": {1.0: "Al", 2.0: "Mg"}}
for test in ("test_1", "test_2"):
    for r in rows(test):
        g, c = float(r["grainlab"]), float(r["closed_form"])
        table.append(f"| {test[-1]} | {names[test][float(r['x'])]} | {r['shape'].replace('_', ' ')} | {r['quantity']} | {g:.6g} | {c:.6g} | {abs(g - c) / abs(c):.1e} |")
md_path = os.path.join(ROOT, "docs", "benchmarks.md")
md = open(md_path).read()
start, end = "<!-- results: scripts/benchmark-docs -->", "<!-- /results -->"
i, j = md.index(start) + len(start), md.index(end)
md = md[:i] + "\n" + "\n".join(table) + "\n" + md[j:]
open(md_path, "w").write(md)
print("wrote docs/benchmarks.md and docs/benchmarks/test_3.png, test_4.png, test_6.png, paper.png")
