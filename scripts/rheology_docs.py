"""Write docs/rheology.md, its figures and CSVs (run through scripts/rheology-docs).

The mu(I) study: the built-in shear cell (`grainlab scenes shear`, 1000 grains) run over
wall speeds and confining stresses, each run's profiles.csv cut into bulk layers (local
inertial number, friction |sigma_yx|/P and solid fraction), mu(I) and phi(I) fitted with
scipy, and two or three of the points run again in LIGGGHTS 3.8 for the global tau/sigma.

    scripts/rheology-docs [--quick] [--reuse] [--no-liggghts] [--keep DIR]

--quick        a small smoke version (short runs, few points, one tiny LIGGGHTS run) written to a
               scratch folder (the page and CSVs in docs/ are left alone unless --out)
--reuse        rebuild the page and figures from the CSVs already in docs/rheology/
--no-liggghts  skip the LIGGGHTS points (keep the LIGGGHTS rows already in liggghts.csv)
--keep DIR     keep every run's output folder under DIR (default: a temporary folder)
Runs are serial (one grainlab or LIGGGHTS process at a time).
"""
import argparse, csv, datetime, json, math, os, shutil, subprocess, sys, tempfile, time

import numpy as np
from scipy.optimize import curve_fit

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GRAINLAB = os.path.join(ROOT, "target", "release", "grainlab")

ap = argparse.ArgumentParser()
ap.add_argument("--quick", action="store_true")
ap.add_argument("--reuse", action="store_true")
ap.add_argument("--no-liggghts", action="store_true")
ap.add_argument("--keep", default="")
ap.add_argument("--out", default="", help="docs folder to write into (default: docs/, or a scratch folder with --quick)")
args = ap.parse_args()

DOCS = args.out or (tempfile.mkdtemp(prefix="rheology-quick-") if args.quick else os.path.join(ROOT, "docs"))
OUT = os.path.join(DOCS, "rheology")
os.makedirs(OUT, exist_ok=True)
WORK = args.keep or tempfile.mkdtemp(prefix="rheology-runs-")
os.makedirs(WORK, exist_ok=True)

RHO = 2500.0          # glass, kg/m^3 (the built-in scene's material)
EXCLUDE = 3           # layers left out next to each wall
DISK_T = 0.001        # disk thickness, m (= the mean grain diameter)
PHI_FIT_MAX_I = 0.3   # phi(I) = phi_max - a I is fitted for I below this

# The runs: (series, shape, confining stress P Pa, wall speed V m/s (each wall +-V),
# total gap strain 2 V T / H0 with H0 = 0.025 m, seeds). Durations follow from the strain.
H0 = 0.025
if args.quick:
    POINTS = [("sphere", "sphere", 1e5, 1.5, 1.5, [1]), ("sphere", "sphere", 1e4, 1.5, 1.5, [1]),
              ("sphere", "sphere", 1e3, 2.5, 1.5, [1]), ("disk", "disk", 1e3, 2.5, 1.5, [1])]
    LIGGGHTS_POINTS = [(1e3, 2.5, 0.5)]
else:
    POINTS = [
        ("sphere", "sphere", 1e6, 0.3, 6.0, [1]),
        ("sphere", "sphere", 1e5, 0.1, 6.0, [1]),
        ("sphere", "sphere", 1e5, 0.25, 8.0, [1]),
        ("sphere", "sphere", 1e5, 0.6, 8.0, [1, 2, 3, 4]),
        ("sphere", "sphere", 1e5, 1.5, 8.0, [1]),
        ("sphere", "sphere", 1e4, 0.5, 8.0, [1, 2, 3, 4]),
        ("sphere", "sphere", 1e4, 1.5, 8.0, [1]),
        ("sphere", "sphere", 1e4, 4.0, 8.0, [1]),
        ("sphere", "sphere", 1e3, 0.3, 8.0, [1]),
        ("sphere", "sphere", 1e3, 1.0, 8.0, [1]),
        ("sphere", "sphere", 1e3, 2.5, 8.0, [1, 2, 3, 4]),
        ("sphere", "sphere", 1e3, 5.0, 8.0, [1]),
        ("disk", "disk", 1e5, 0.25, 8.0, [1]),
        ("disk", "disk", 1e5, 0.6, 8.0, [1]),
        ("disk", "disk", 1e5, 1.5, 8.0, [1]),
        ("disk", "disk", 1e4, 1.5, 8.0, [1]),
        ("disk", "disk", 1e3, 1.0, 8.0, [1]),
        ("disk", "disk", 1e3, 2.5, 8.0, [1]),
        ("disk", "disk", 1e3, 5.0, 8.0, [1]),
    ]
    # LIGGGHTS: shorter, moderate-I points (LIGGGHTS is ~5x slower than grainlab).
    LIGGGHTS_POINTS = [(1e3, 2.5, 6.0), (1e4, 1.5, 6.0), (1e5, 1.5, 6.0)]


def duration(V, strain):
    return strain * H0 / (2.0 * V)


def scene(shape, P, V, T, seed, lever_arm="radius", samples=400, contacts=True):
    s = json.loads(subprocess.run([GRAINLAB, "scenes", "shear"], check=True, capture_output=True, text=True).stdout)
    s["name"] = f"rheology-{shape}-P{P:g}-V{V:g}-s{seed}"
    s["description"] = f"mu(I) study: the built-in shear cell, {shape} grains, walls at +-{V:g} m/s under {P:g} Pa, packing seed {seed}"
    s["walls"]["bottom"]["velocity_x"] = -V
    s["walls"]["top"]["velocity_x"] = V
    s["walls"]["top"]["control"] = {"pressure": P}
    s["grains"]["pack"]["seed"] = seed
    s["duration"] = T
    # dt = t_c / 50 at the larger of 0.5 m/s (the built-in's) and the wall speed
    s["time_step"]["rule"]["steps_per_contact"]["impact_speed"] = max(0.5, V)
    s["model"]["lever_arm"] = lever_arm
    s["output"] = {"samples": samples, "frames": 0, "energy": False, "contacts": contacts}
    if shape == "disk":
        s["grain_shape"] = {"disk": {"thickness": DISK_T}}
    return s


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def write_csv(path, rows, fields):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(r)


def run_grainlab(sc, tag):
    d = os.path.join(WORK, tag)
    os.makedirs(d, exist_ok=True)
    path = os.path.join(d, "scene.json")
    json.dump(sc, open(path, "w"), indent=1)
    out = os.path.join(d, "out")
    t0 = time.time()
    subprocess.run([GRAINLAB, "run", path, "--out", out, "--quiet", "--overwrite"], check=True, capture_output=True, text=True)
    return out, time.time() - t0


def f(r, k):
    return float(r[k])


def digest_run(out, series, shape, P, V, strain, seed, wall):
    """One run's bulk layers and its run-level values."""
    summ = json.load(open(os.path.join(out, "summary.json")))
    prof = read_csv(os.path.join(out, "profiles.csv"))
    n = len(prof)
    bulk = prof[EXCLUDE:n - EXCLUDE]
    sh = summ["shear"]
    # the mean grain diameter the profiles used: I = gamma_dot d / sqrt(P / rho)
    r0 = next(r for r in bulk if r["inertial_number"] and abs(f(r, "shear_rate_1_s")) > 0)
    d = f(r0, "inertial_number") * math.sqrt(f(r0, "pressure_pa") / RHO) / abs(f(r0, "shear_rate_1_s"))
    layers = []
    for r in bulk:
        P_l = -(f(r, "sigma_xx_pa") + f(r, "sigma_yy_pa")) / 2
        dP = 0.5 * math.hypot(f(r, "sigma_xx_pa_ci95"), f(r, "sigma_yy_pa_ci95"))
        tau = abs(f(r, "sigma_yx_pa"))
        mu = tau / P_l
        dmu = mu * math.hypot(f(r, "sigma_yx_pa_ci95") / tau, dP / P_l) if tau > 0 else float("nan")
        layers.append(dict(series=series, shape=shape, P_set_pa=P, V_m_s=V, seed=seed, layer=int(r["layer"]), y_over_gap=f(r, "y_over_gap"),
                           shear_rate_1_s=f(r, "shear_rate_1_s"), pressure_pa=P_l, pressure_ci95=dP, inertial_number=f(r, "inertial_number") if r["inertial_number"] else float("nan"),
                           friction=mu, friction_ci95=dmu, solid_fraction=f(r, "solid_fraction"), solid_fraction_ci95=f(r, "solid_fraction_ci95"),
                           velocity_x_m_s=f(r, "velocity_x_m_s")))
    # run level: bulk shear rate from the velocity difference across the bulk layers
    lo, hi = bulk[0], bulk[-1]
    rate = (f(hi, "velocity_x_m_s") - f(lo, "velocity_x_m_s")) / (f(hi, "y_m") - f(lo, "y_m"))
    Pb = float(np.mean([l["pressure_pa"] for l in layers]))
    taub = float(np.mean([abs(f(r, "sigma_yx_pa")) for r in bulk]))
    gap = (f(prof[-1], "y_m") - f(prof[0], "y_m")) * n / (n - 1)
    rows = summ["shear"]
    return layers, dict(series=series, shape=shape, P_set_pa=P, V_m_s=V, seed=seed, strain_set=strain, duration_s=summ["simulated_time_s"], steps=summ["steps"],
                        dt_s=summ["time_step"]["dt_s"], wall_s=wall, layers=n, gap_m=gap, diameter_m=d,
                        window_strain=2 * V * (summ["simulated_time_s"] - sh["averaged_from_s"]) / gap,
                        tau_over_sigma=sh["stress_ratio"]["mean"], tau_over_sigma_ci95=sh["stress_ratio"]["ci95"],
                        sigma_wall_pa=sh["normal_stress_pa"]["mean"], packing_fraction=sh["packing_fraction"],
                        I_wall=(2 * V / gap) * d / math.sqrt(sh["normal_stress_pa"]["mean"] / RHO),
                        bulk_shear_rate_1_s=rate, bulk_pressure_pa=Pb, I_bulk=abs(rate) * d / math.sqrt(Pb / RHO), mu_bulk=taub / Pb,
                        phi_bulk=float(np.mean([l["solid_fraction"] for l in layers])),
                        bulk_velocity_span=(f(hi, "velocity_x_m_s") - f(lo, "velocity_x_m_s")) / (2 * V))


LAYER_FIELDS = ["series", "shape", "P_set_pa", "V_m_s", "seed", "layer", "y_over_gap", "shear_rate_1_s", "pressure_pa", "pressure_ci95", "inertial_number",
                "friction", "friction_ci95", "solid_fraction", "solid_fraction_ci95", "velocity_x_m_s"]
RUN_FIELDS = ["series", "shape", "P_set_pa", "V_m_s", "seed", "strain_set", "duration_s", "steps", "dt_s", "wall_s", "layers", "gap_m", "diameter_m", "window_strain",
              "tau_over_sigma", "tau_over_sigma_ci95", "sigma_wall_pa", "packing_fraction", "I_wall", "bulk_shear_rate_1_s", "bulk_pressure_pa", "I_bulk", "mu_bulk",
              "phi_bulk", "bulk_velocity_span"]
LIG_FIELDS = ["P_set_pa", "V_m_s", "seed", "duration_s", "steps", "code", "tau_over_sigma", "tau_over_sigma_ci95", "sigma_pa", "wall_s", "I_wall"]


def run_liggghts(P, V, strain):
    """The same scene (LIGGGHTS' lever arm on both sides) in grainlab and LIGGGHTS."""
    T = duration(V, strain)
    sc = scene("sphere", P, V, T, 1, lever_arm="radius_minus_half_overlap", samples=400, contacts=False)
    tag = f"liggghts-P{P:g}-V{V:g}"
    out, wall_g = run_grainlab(sc, tag + "-grainlab")
    summ = json.load(open(os.path.join(out, "summary.json")))
    d = os.path.join(WORK, tag)
    case = os.path.join(d, "case")
    os.makedirs(d, exist_ok=True)
    path = os.path.join(d, "scene.json")
    json.dump(sc, open(path, "w"), indent=1)
    subprocess.run([GRAINLAB, "export", "liggghts", path, "--out", case, "--overwrite"], check=True, capture_output=True, text=True)
    json.dump({"name": tag, "description": sc["description"], "codes": ["liggghts"], "quick": False, "curve": False}, open(os.path.join(case, "case.json"), "w"))
    rund = os.path.join(d, "run")
    os.makedirs(rund, exist_ok=True)
    for fn in ("in.liggghts", "grains.data"):
        shutil.copy(os.path.join(case, fn), rund)
    t0 = time.time()
    p = subprocess.run(["liggghts", "-in", "in.liggghts"], cwd=rund, capture_output=True, text=True, env=dict(os.environ, OMP_NUM_THREADS="1"))
    wall_l = time.time() - t0
    if p.returncode != 0:
        raise RuntimeError("LIGGGHTS failed:\n" + "\n".join((p.stdout + p.stderr).splitlines()[-15:]))
    subprocess.run([GRAINLAB, "digest", case, "liggghts", rund], check=True, capture_output=True, text=True)
    lig = json.load(open(os.path.join(case, "expected", "liggghts", "shear.json")))
    sh = summ["shear"]
    gap = None
    rows = []
    for code, s, w in [("grainlab", sh, wall_g), ("liggghts", lig, wall_l)]:
        rows.append(dict(P_set_pa=P, V_m_s=V, seed=1, duration_s=summ["simulated_time_s"], steps=summ["steps"], code=code,
                         tau_over_sigma=s["stress_ratio"]["mean"], tau_over_sigma_ci95=s["stress_ratio"]["ci95"], sigma_pa=s["normal_stress_pa"]["mean"], wall_s=w))
    return rows


# ---------------------------------------------------------------- the runs
started = time.time()
if not args.reuse:
    subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=ROOT, check=True)
    layers, runs = [], []
    for series, shape, P, V, strain, seeds in POINTS:
        for seed in seeds:
            T = duration(V, strain)
            out, wall = run_grainlab(scene(shape, P, V, T, seed), f"{shape}-P{P:g}-V{V:g}-s{seed}")
            ls, r = digest_run(out, series, shape, P, V, strain, seed, wall)
            layers += ls
            runs.append(r)
            print(f"{shape:6s} P={P:8.0f} V={V:5.2f} seed {seed}: T={T:.4f} s, {wall:6.1f} s wall, I_bulk={r['I_bulk']:.4f}, mu_bulk={r['mu_bulk']:.3f}, "
                  f"tau/sigma={r['tau_over_sigma']:.3f}, window strain {r['window_strain']:.1f}", flush=True)
            write_csv(os.path.join(OUT, "layers.csv"), layers, LAYER_FIELDS)
            write_csv(os.path.join(OUT, "runs.csv"), runs, RUN_FIELDS)
    lig_rows = read_csv(os.path.join(OUT, "liggghts.csv")) if args.no_liggghts and os.path.exists(os.path.join(OUT, "liggghts.csv")) else []
    if not args.no_liggghts:
        for P, V, strain in LIGGGHTS_POINTS:
            rows = run_liggghts(P, V, strain)
            lig_rows += rows
            print(f"LIGGGHTS point P={P:g} V={V:g}: " + ", ".join(f"{r['code']} {r['tau_over_sigma']:.3f} +- {r['tau_over_sigma_ci95']:.3f} ({r['wall_s']:.0f} s)" for r in rows), flush=True)
            write_csv(os.path.join(OUT, "liggghts.csv"), lig_rows, LIG_FIELDS)
    print(f"compute: {time.time() - started:.0f} s", flush=True)

layers = read_csv(os.path.join(OUT, "layers.csv"))
runs = read_csv(os.path.join(OUT, "runs.csv"))
lig_rows = read_csv(os.path.join(OUT, "liggghts.csv")) if os.path.exists(os.path.join(OUT, "liggghts.csv")) else []
for rows in (layers, runs, lig_rows):
    for r in rows:
        for k, v in r.items():
            try:
                r[k] = float(v)
            except (TypeError, ValueError):
                pass


# ---------------------------------------------------------------- the fits
def mu_law(I, mu_s, mu_2, I0):
    return mu_s + (mu_2 - mu_s) / (I0 / I + 1.0)


def phi_law(I, phi_max, a):
    return phi_max - a * I


def lin_law(I, mu_min, b):
    return mu_min + b * I


# A run is used only if it reached a steady simple shear: the top wall's time-averaged normal
# stress within 15% of the load, and the bulk layers' pressure uniform (sd over the layers
# below 15% of their mean; momentum balance makes sigma_yy uniform in a steady state).
STEADY_TOL = 0.15
for r in runs:
    p = [l["pressure_pa"] for l in layers if (l["shape"], l["P_set_pa"], l["V_m_s"], l["seed"]) == (r["shape"], r["P_set_pa"], r["V_m_s"], r["seed"])]
    r["wall_over_load"] = r["sigma_wall_pa"] / r["P_set_pa"]
    r["bulk_pressure_cv"] = float(np.std(p) / np.mean(p))
    r["bulk_rate_ratio"] = r["bulk_shear_rate_1_s"] * r["gap_m"] / (2 * r["V_m_s"])
    r["steady"] = abs(r["wall_over_load"] - 1) < STEADY_TOL and r["bulk_pressure_cv"] < STEADY_TOL
STEADY = {(r["shape"], r["P_set_pa"], r["V_m_s"], r["seed"]) for r in runs if r["steady"]}
for l in layers:
    l["steady"] = (l["shape"], l["P_set_pa"], l["V_m_s"], l["seed"]) in STEADY


def usable(l, steady=True):
    return (l["steady"] or not steady) and np.isfinite(l["inertial_number"]) and l["inertial_number"] > 0 and l["shear_rate_1_s"] > 0 and l["pressure_pa"] > 0 and np.isfinite(l["friction_ci95"])


def fit(points, law, p0, bounds, ycol, ecol, imax=None):
    pts = [p for p in points if imax is None or p["inertial_number"] <= imax]
    I = np.array([p["inertial_number"] for p in pts])
    y = np.array([p[ycol] for p in pts])
    # ecol None: equal weights (the phi intervals of profiles.csv are 3-5x too wide and uneven)
    s = np.ones(len(pts)) if ecol is None else np.array([max(p[ecol] / 1.96, 1e-3 * abs(p[ycol]) + 1e-6) for p in pts])
    popt, pcov = curve_fit(law, I, y, p0=p0, sigma=s, absolute_sigma=False, bounds=bounds, maxfev=20000)
    chi2 = float(np.sum(((y - law(I, *popt)) / s) ** 2) / max(len(y) - len(popt), 1))
    return popt, 1.96 * np.sqrt(np.diag(pcov)), chi2, len(y)


def bootstrap(points, law, p0, bounds, ycol, ecol, imax=None, reps=400, seed=7):
    """Percentile 95% intervals from resampling whole runs (a run's layers share its noise)."""
    keys = sorted({(p["shape"], p["P_set_pa"], p["V_m_s"], p["seed"]) for p in points})
    by = {k: [p for p in points if (p["shape"], p["P_set_pa"], p["V_m_s"], p["seed"]) == k] for k in keys}
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(reps):
        pick = rng.integers(0, len(keys), len(keys))
        pts = [p for i in pick for p in by[keys[i]]]
        try:
            out.append(fit(pts, law, p0, bounds, ycol, ecol, imax)[0])
        except (RuntimeError, ValueError):
            pass
    out = np.array(out)
    return np.percentile(out, 2.5, axis=0), np.percentile(out, 97.5, axis=0), len(out)


SHAPES = [s for s in ("sphere", "disk") if any(l["shape"] == s for l in layers)]
fits = {}
for shape in SHAPES:
    pts = [l for l in layers if l["shape"] == shape and usable(l)]
    mu_p0, mu_b = [0.25, 0.6, 0.3], ([0.0, 0.0, 1e-4], [1.0, 3.0, 20.0])
    r = dict(n_runs=len({(p["P_set_pa"], p["V_m_s"], p["seed"]) for p in pts}), I_min=min(p["inertial_number"] for p in pts), I_max=max(p["inertial_number"] for p in pts))
    try:
        r["mu"] = fit(pts, mu_law, mu_p0, mu_b, "friction", "friction_ci95")
        r["mu_boot"] = bootstrap(pts, mu_law, mu_p0, mu_b, "friction", "friction_ci95", reps=60 if args.quick else 400)
    except (RuntimeError, ValueError) as e:
        print(f"mu(I) fit failed for {shape}: {e}")
    try:
        r["lin"] = fit(pts, lin_law, [0.25, 1.0], ([0, -10], [1, 10]), "friction", "friction_ci95", imax=0.2)
        r["lin_boot"] = bootstrap(pts, lin_law, [0.25, 1.0], ([0, -10], [1, 10]), "friction", "friction_ci95", imax=0.2, reps=60 if args.quick else 400)
    except (RuntimeError, ValueError) as e:
        print(f"linear mu fit failed for {shape}: {e}")
    try:
        r["phi"] = fit(pts, phi_law, [0.82, 0.3], ([0.5, -5], [1.0, 5]), "solid_fraction", None, imax=PHI_FIT_MAX_I)
        r["phi_boot"] = bootstrap(pts, phi_law, [0.82, 0.3], ([0.5, -5], [1.0, 5]), "solid_fraction", None, imax=PHI_FIT_MAX_I, reps=60 if args.quick else 400)
    except (RuntimeError, ValueError) as e:
        print(f"phi fit failed for {shape}: {e}")
    fits[shape] = r
    if "mu" in r:
        print(f"{shape}: mu_s={r['mu'][0][0]:.3f}+-{r['mu'][1][0]:.3f} mu_2={r['mu'][0][1]:.3f}+-{r['mu'][1][1]:.3f} I0={r['mu'][0][2]:.3f}+-{r['mu'][1][2]:.3f} (chi2/dof {r['mu'][2]:.2f}, {r['mu'][3]} layers)")
    if "phi" in r:
        print(f"{shape}: phi_max={r['phi'][0][0]:.4f}+-{r['phi'][1][0]:.4f} a={r['phi'][0][1]:.3f}+-{r['phi'][1][1]:.3f}")

# ---------------------------------------------------------------- figures
PCOL = {1e6: "C4", 1e5: "C0", 1e4: "C2", 1e3: "C3"}
MARK = {"sphere": "o", "disk": "s"}
FITCOL = {"sphere": "k", "disk": "C1"}


def plabel(P):
    return f"{P / 1e3:g} kPa"


def figure(ycol, ecol, law_key, law, ylabel, fname, ylim=None):
    fig, axes = plt.subplots(1, len(SHAPES), figsize=(6.2 * len(SHAPES), 4.6), squeeze=False, sharey=True)
    for ax, shape in zip(axes[0], SHAPES):
        pts = [l for l in layers if l["shape"] == shape and usable(l)]
        for P in sorted({p["P_set_pa"] for p in pts}, reverse=True):
            q = [p for p in pts if p["P_set_pa"] == P]
            ax.errorbar([p["inertial_number"] for p in q], [p[ycol] for p in q], yerr=[p[ecol] for p in q], fmt=MARK[shape], ms=3, lw=0.6, alpha=0.55,
                        color=PCOL.get(P, "C5"), label=f"bulk layers, P = {plabel(P)}")
        bad = [l for l in layers if l["shape"] == shape and not l["steady"] and usable(l, steady=False)]
        if bad:
            ax.plot([p["inertial_number"] for p in bad], [p[ycol] for p in bad], MARK[shape], ms=3, color="0.6", alpha=0.6, label="not steady (left out of the fit)")
        rr = [r for r in runs if r["shape"] == shape and r["steady"]]
        key = {"friction": "mu_bulk", "solid_fraction": "phi_bulk"}[ycol]
        ax.plot([r["I_bulk"] for r in rr], [r[key] for r in rr], MARK[shape], mfc="none", mec="k", ms=9, mew=1.2, label="run: bulk-layer average")
        if ycol == "friction":
            ax.plot([r["I_wall"] for r in rr], [r["tau_over_sigma"] for r in rr], "x", color="0.35", ms=7, label="run: wall tau/sigma vs I_wall (2V/H)")
        f = fits.get(shape, {})
        if law_key in f:
            popt = f[law_key][0]
            hi = PHI_FIT_MAX_I if law_key == "phi" else max(f["I_max"], 0.5)
            I = np.logspace(np.log10(max(f["I_min"], 1e-4)), np.log10(hi), 200)
            ax.plot(I, law(I, *popt), "-", color=FITCOL[shape], lw=2, label="fit: " + (f"mu_s={popt[0]:.3f}, mu_2={popt[1]:.3f}, I0={popt[2]:.3f}" if law_key == "mu" else f"phi_max={popt[0]:.3f}, a={popt[1]:.3f}"))
        ax.set_xscale("log")
        ax.set_xlabel("inertial number I (local)")
        ax.set_title({"sphere": "sphere-in-plane grains (default)", "disk": "disk grains (t = 1 mm)"}[shape])
        ax.grid(alpha=0.3, which="both", lw=0.4)
        ax.legend(fontsize=7, loc="best")
        if ylim:
            ax.set_ylim(*ylim)
    axes[0][0].set_ylabel(ylabel)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, fname), dpi=110)
    plt.close(fig)


figure("friction", "friction_ci95", "mu", mu_law, "mu = |sigma_yx| / P", "mu_I.png", ylim=(0, 0.8))
figure("solid_fraction", "solid_fraction_ci95", "phi", phi_law, "solid fraction phi", "phi_I.png", ylim=(0.6, 0.87))

# velocity profiles: where the shear goes
fig, axes = plt.subplots(1, len(SHAPES), figsize=(6.2 * len(SHAPES), 4.2), squeeze=False, sharey=True)
allprof = {}
for ax, shape in zip(axes[0], SHAPES):
    for r in [r for r in runs if r["shape"] == shape and r["seed"] == 1]:
        q = sorted([l for l in layers if l["shape"] == shape and l["P_set_pa"] == r["P_set_pa"] and l["V_m_s"] == r["V_m_s"] and l["seed"] == 1], key=lambda l: l["layer"])
        ax.plot([l["velocity_x_m_s"] / r["V_m_s"] for l in q], [l["y_over_gap"] for l in q], ".-", lw=0.8, color=PCOL.get(r["P_set_pa"], "C5"),
                alpha=0.4 + 0.6 * (math.log10(r["V_m_s"]) + 1) / 2, label=f"{plabel(r['P_set_pa'])}, V={r['V_m_s']:g}")
    ax.plot([-1, 1], [0, 1], "k:", lw=0.8, label="uniform shear")
    ax.set_xlabel("v_x / V (bulk layers)")
    ax.set_title(shape)
    ax.legend(fontsize=6, ncol=2)
axes[0][0].set_ylabel("y / gap")
fig.tight_layout()
fig.savefig(os.path.join(OUT, "velocity_profiles.png"), dpi=110)
plt.close(fig)

# ---------------------------------------------------------------- ensemble check
from scipy.stats import t as student_t

ens = []
for key in sorted({(r["shape"], r["P_set_pa"], r["V_m_s"]) for r in runs}):
    rr = [r for r in runs if (r["shape"], r["P_set_pa"], r["V_m_s"]) == key]
    if len(rr) < 3:
        continue
    n = len(rr)
    ts = np.array([r["tau_over_sigma"] for r in rr])
    cis = np.array([r["tau_over_sigma_ci95"] for r in rr])
    mub = np.array([r["mu_bulk"] for r in rr])
    ib = np.array([r["I_bulk"] for r in rr])
    phib = np.array([r["phi_bulk"] for r in rr])
    # layer level: per layer index, the spread over seeds against the layers' own intervals
    ratios, pratios = [], []
    for k in sorted({l["layer"] for l in layers if (l["shape"], l["P_set_pa"], l["V_m_s"]) == key}):
        q = [l for l in layers if (l["shape"], l["P_set_pa"], l["V_m_s"]) == key and l["layer"] == k]
        if len(q) == n:
            ratios.append(np.std([l["friction"] for l in q], ddof=1) / np.mean([l["friction_ci95"] / 1.96 for l in q]))
            pratios.append(np.std([l["solid_fraction"] for l in q], ddof=1) / np.mean([l["solid_fraction_ci95"] / 1.96 for l in q]))
    tq = student_t.ppf(0.975, n - 1)
    ens.append(dict(shape=key[0], P=key[1], V=key[2], n=n, ts_mean=ts.mean(), ts_ci=tq * ts.std(ddof=1) / math.sqrt(n), ts_sd=ts.std(ddof=1), ts_block_ci=cis.mean(),
                    mu_mean=mub.mean(), mu_ci=tq * mub.std(ddof=1) / math.sqrt(n), mu_sd=mub.std(ddof=1), I_mean=ib.mean(), I_sd=ib.std(ddof=1),
                    phi_mean=phib.mean(), phi_sd=phib.std(ddof=1), layer_ratio=float(np.median(ratios)) if ratios else float("nan"),
                    phi_ratio=float(np.median(pratios)) if pratios else float("nan")))

# ---------------------------------------------------------------- the page
def pm(v, e, nd=3):
    return f"{v:.{nd}f} ± {e:.{nd}f}"


def rng_(lo, hi, nd=3):
    return f"[{lo:.{nd}f}, {hi:.{nd}f}]"


total_wall = sum(r["wall_s"] for r in runs) + sum(r["wall_s"] for r in lig_rows)
md = []
A = md.append
A("# mu(I) rheology of the shear cell")
A("")
A("Generated by `scripts/rheology-docs` (scripts/rheology_docs.py) from real runs of grainlab" + (" (quick smoke version: short runs, not the study)" if args.quick else "") + "; "
  f"the numbers behind every figure and table are in `docs/rheology/*.csv`, and `scripts/rheology-docs --reuse` rebuilds this page from them. Generated {datetime.date.today().isoformat()}.")
A("")
A("## What was run")
A("")
A("Every run is the built-in shear cell (`grainlab scenes shear`: 1000 polydisperse glass beads, radii uniform in 0.4-0.6 mm, "
  "E = 63 GPa, nu = 0.2, rho = 2500 kg/m^3, e = 0.5, contact friction 0.5; a periodic cell 40 mm long between two rough walls of glued 0.5 mm grains, "
  "the bottom wall held at y = 0, the top wall under a constant load; Hertz-Mindlin with LIGGGHTS' total-displacement tangential history) with only these fields changed:")
A("")
A("- `walls.bottom.velocity_x = -V`, `walls.top.velocity_x = +V` and `walls.top.control = {\"pressure\": P}`: the wall speed V and the confining stress P of each point;")
A(f"- `duration = S H0 / (2 V)` with H0 = {H0 * 1e3:g} mm (the built-in gap at 100 kPa) and a total gap strain S = 8 (6 for the two slowest points); "
  "`statistics.average_from = 0.5` (the built-in: the second half of the run is averaged, so about S/2 of strain is averaged after S/2 of strain to reach the steady state);")
A("- `time_step.rule.steps_per_contact.impact_speed = max(0.5 m/s, V)` (dt = t_c/50 of the smallest grains at that speed: " + f"{min(r['dt_s'] for r in runs):.2g}-{max(r['dt_s'] for r in runs):.2g} s" + "; the disks, heavier, get the longer steps);")
A("- `output = {samples: 400, frames: 0, energy: false, contacts: true}` (contacts on: profiles.csv and the packing stress are recorded at every sample);")
A(f"- disks: `grain_shape = {{\"disk\": {{\"thickness\": {DISK_T}}}}}` (m = pi r^2 t rho, I = m r^2 / 2; stresses are per t) instead of the default sphere-in-plane grains (m = 4/3 pi r^3 rho, I = 2/5 m r^2, stresses per mean diameter);")
A("- `grains.pack.seed`: 1, and 1-4 at three points (the ensemble check below).")
A("")
A("No stiffness scaling and no change of the grain count: every run is the 1000-grain cell with glass stiffness. "
  f"Runs were serial, one process at a time on one core; the whole study took {total_wall / 60:.1f} minutes of run time "
  f"({sum(r['wall_s'] for r in runs) / 60:.1f} min grainlab, {sum(r['wall_s'] for r in lig_rows if r['code'] == 'liggghts') / 60:.1f} min LIGGGHTS).")
A("")
A("| grains | P (kPa) | V (m/s) | seeds | duration (s) | steps | wall time (s) | gap (mm) | strain averaged | wall tau/sigma | I_bulk | mu_bulk | phi_bulk | bulk shear rate / (2V/H) | wall sigma / P | steady |")
A("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for key in sorted({(r["shape"], r["P_set_pa"], r["V_m_s"]) for r in runs}, key=lambda k: (k[0] != "sphere", -k[1], k[2])):
    rr = [r for r in runs if (r["shape"], r["P_set_pa"], r["V_m_s"]) == key]
    r = rr[0]
    A(f"| {key[0]} | {key[1] / 1e3:g} | {key[2]:g} | {','.join(str(int(x['seed'])) for x in rr)} | {r['duration_s']:.4f} | {int(r['steps']):,} | {sum(x['wall_s'] for x in rr):.0f} | "
      f"{r['gap_m'] * 1e3:.1f} | {r['window_strain']:.1f} | {pm(r['tau_over_sigma'], r['tau_over_sigma_ci95'])} | {r['I_bulk']:.4f} | {r['mu_bulk']:.3f} | {r['phi_bulk']:.3f} | {r['bulk_rate_ratio']:.2f} | {r['wall_over_load']:.2f} | {'yes' if all(x['steady'] for x in rr) else 'no'} |")
A("")
A("(Seed-1 values, wall times summed over the seeds; `runs.csv` has every run. \"bulk shear rate / (2V/H)\": the bulk layers' mean shear rate over the nominal 2V/H; "
  "below 1, part of the imposed speed slips or shears in the layers next to the walls. \"wall sigma / P\": the top wall's time-averaged normal stress over the load; "
  "\"steady\": see the caveats.)")
A("")
A("## How I, mu and phi are measured")
A("")
A("Each run's `profiles.csv` (src/observe/profiles.rs) cuts the gap into layers of about one mean diameter (" + f"{int(min(r['layers'] for r in runs))}-{int(max(r['layers'] for r in runs))}" + " layers here) and averages over the averaging window, "
  "with 95% intervals from block averages. The points of mu(I) and phi(I) are the **bulk layers**: every layer except the "
  f"{EXCLUDE} next to each wall (the rough walls' layers slip and are disordered: their solid fraction drops and their stresses are not those of the bulk). Per bulk layer:")
A("")
A("- I = gamma_dot d / sqrt(P / rho): gamma_dot the centred difference of the layer mean velocities, d = 1.0 mm the free grains' mean diameter, rho = 2500 kg/m^3 (the grain material density, for both shapes);")
A("- mu = |sigma_yx| / P with P = -(sigma_xx + sigma_yy) / 2 from the layer's stress (contacts plus kinetic part); its interval is propagated from the intervals of sigma_yx, sigma_xx and sigma_yy (treated as independent, which overstates it somewhat, since sigma_xx and sigma_yy fluctuate together);")
A("- phi: the layer's area fraction (disks cut exactly by the layer lines), with its block interval.")
A("")
A("The local layer values are the primary data because the shear is not uniform (figure below): at high I (1 kPa, V >= 2.5 m/s) the profile is S-shaped, with most of the shear next to the walls, while at low I it is close to linear (the bulk shear rate is 0.7-1 of 2V/H). "
  "For each run the figures also show a run-level point, the **bulk average**: mu_bulk = mean |sigma_yx| / mean P over the bulk layers, I_bulk from the velocity difference across the bulk layers, "
  "and the **wall value**: the time-averaged wall shear stress over the wall normal stress (summary.json `shear.stress_ratio`, the quantity LIGGGHTS is compared on) against I_wall = (2V/H) d / sqrt(sigma_wall / rho), which ignores wall slip and overestimates the bulk I.")
A("")
A("![velocity profiles](rheology/velocity_profiles.png)")
A("")
A("## mu(I) and phi(I)")
A("")
A("![mu(I)](rheology/mu_I.png)")
A("")
A("![phi(I)](rheology/phi_I.png)")
A("")
A("Fits (scipy `curve_fit`, all bulk layers of the steady runs of a grain shape): mu(I) = mu_s + (mu_2 - mu_s) / (I0/I + 1) over the whole range, weighted by each layer's interval; "
  f"phi(I) = phi_max - a I for I <= {PHI_FIT_MAX_I}, with equal weights (the layers' phi intervals are 3-5 times too wide and uneven, see below; chi^2/dof of this fit is then in units of phi^2 and not a test); and for comparison with da Cruz et al. the linear form mu = mu_min + b I for I <= 0.2. "
  "Two 95% intervals per constant: from the fit's covariance (scaled by the reduced chi^2), and a bootstrap that resamples whole runs (400 resamples; the layers of one run share its noise "
  "and neighbouring layers share velocities, so this is the more honest one).")
A("")
A("| grains | runs | I range of the layers | constant | value ± 95% (covariance) | 95% bootstrap over runs | chi^2/dof |")
A("|---|---|---|---|---|---|---|")
for shape in SHAPES:
    f = fits[shape]
    for law, names in [("mu", ["mu_s", "mu_2", "I0"]), ("lin", ["mu_min (I<=0.2)", "b (I<=0.2)"]), ("phi", ["phi_max", "a"])]:
        if law not in f:
            continue
        popt, ci, chi2, npts = f[law]
        lo, hi, nb = f[law + "_boot"]
        for i, nm in enumerate(names):
            A(f"| {shape} | {f['n_runs']} | {f['I_min']:.1e} - {f['I_max']:.2f} | {nm} | {pm(popt[i], ci[i], 4 if law == 'phi' else 3)} | {rng_(lo[i], hi[i], 4 if law == 'phi' else 3)} | {'- (equal weights)' if law == 'phi' else f'{chi2:.2f}'} |")
A("")
A("## Error bars against the run-to-run spread")
A("")
if ens:
    A("Three points were run with packing seeds 1-4. The wall tau/sigma of each run has a 95% interval from block averages (summary.json); if that interval is honest, "
      "a single run's half-width should be about 1.96 times the standard deviation over seeds. For the layers, the same check is the standard deviation over seeds of one layer's mu "
      "against its propagated interval / 1.96 (median over the bulk layers; 1 = the interval is right, below 1 = it is too wide).")
    A("")
    A("| grains | P (kPa) | V (m/s) | runs | wall tau/sigma: mean ± 95% (seeds) | mean block half-width of one run | 1.96 x sd over seeds | mu_bulk: mean ± 95% (seeds) | I_bulk mean (sd) | phi_bulk mean (sd) | layer mu: sd over seeds / (interval/1.96) | layer phi: the same |")
    A("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for e in ens:
        A(f"| {e['shape']} | {e['P'] / 1e3:g} | {e['V']:g} | {e['n']} | {pm(e['ts_mean'], e['ts_ci'])} | {e['ts_block_ci']:.3f} | {1.96 * e['ts_sd']:.3f} | {pm(e['mu_mean'], e['mu_ci'])} | "
          f"{e['I_mean']:.4f} ({e['I_sd']:.4f}) | {e['phi_mean']:.3f} ({e['phi_sd']:.3f}) | {e['layer_ratio']:.2f} | {e['phi_ratio']:.2f} |")
    A("")
    ENS_TEXT_MARK = len(md)
else:
    A("(No point with several seeds in this run.)")
    A("")
A("## Literature: 2D frictional disks")
A("")
A("What could be confirmed with the sources available while writing this page (a search over stored public pages; the papers themselves were not available):")
A("")
A("- GDR MiDi (2004, Eur. Phys. J. E 14, 341), da Cruz et al. (2005, Phys. Rev. E 72, 021309) and Pouliquen et al. (2006) found that in steady flows the solid fraction depends on the inertial number alone, "
  "decreasing as I grows (stated in the introduction of *Constitutive relations for compressible granular flow in the inertial regime*, J. Fluid Mech., on cambridge.org); "
  "the form mu(I) = mu_s + (mu_2 - mu_s)/(I0/I + 1) is that of Jop, Forterre & Pouliquen (2006) (Wikipedia, *mu(I) rheology*).")
A("- Shojaaee, Roux, Chevoir & Wolf (2012, Phys. Rev. E 86, 011301; abstract on duepublico.uni-duisburg-essen.de): in the same geometry (2D disks between walls moving at ±V under controlled normal stress, contact dynamics) "
  "smooth frictional walls can localise the shear in the boundary layer, unlike rough walls made of strands of particles; with smooth walls they find a homogeneous strain rate except near the walls at high V, "
  "then a rigid middle block, then shear confined to one wall as V decreases. (The walls here are rough; the layers next to them still slip, see the profiles.)")
A("")
A("Numbers, **not confirmed** here (recalled from da Cruz et al. 2005, their plane shear of dense 2D disks with contact friction 0.4 and restitution 0.1, walls of glued grains, I from about 1e-3 to 0.3; "
  "check against the paper before quoting): mu(I) ≈ mu_min + b I with mu_min ≈ 0.26 and b ≈ 1.1, and phi ≈ phi_max - a I with phi_max ≈ 0.81 and a ≈ 0.3. "
  "For 3D glass beads (not comparable: spheres, inclined-plane flows) Jop et al. (2006) give mu_s = tan 20.9° ≈ 0.38, mu_2 = tan 32.76° ≈ 0.64 and I0 = 0.279 (also from memory, not confirmed here).")
A("")
lit = []
for shape in SHAPES:
    f = fits[shape]
    if "lin" in f and "phi" in f:
        lit.append(f"{shape}: mu_min = {f['lin'][0][0]:.3f}, b = {f['lin'][0][1]:.2f}, phi_max = {f['phi'][0][0]:.3f}, a = {f['phi'][0][1]:.2f}")
if lit:
    A("The same linear forms fitted here (I <= 0.2 for mu, I <= 0.3 for phi): " + "; ".join(lit) + ". "
      "Differences to expect even where the numbers agree or not: contact friction 0.5 here against 0.4, restitution 0.5 against 0.1, Hertz contacts of glass stiffness against "
      "rigid or linear contacts, and 20% polydispersity.")
    A("")
A("**Which I.** The sphere-in-plane grains' I uses the material density rho = 2500 kg/m^3, but the stresses are per mean diameter of depth, so the mass per unit of that slab is 2/3 rho "
  "(a sphere of radius r against a disk of thickness 2r). A disk-equivalent inertial number, the one 2D papers use (areal mass density over line pressure), is sqrt(2/3) = 0.82 times the one here: "
  "I0 and the I axis of the sphere-in-plane data shrink by that factor (mu_s, mu_2 and phi_max do not change; a and b grow by 1/0.82). For the disk grains (t = 1 mm = the mean diameter) the two definitions agree.")
A("")
A("## LIGGGHTS at three points")
A("")
if lig_rows:
    A("Three of the moderate-I sphere-in-plane points were run again in LIGGGHTS 3.8.0 (`/usr/bin/liggghts`, Debian package) with a shorter total strain of 6 (LIGGGHTS is about 4-5 times slower): "
      "`grainlab export liggghts scene.json` writes the deck (spheres at z = 0 in a 3D box, the same packing file, the same dt, Hertz with `tangential history`), "
      "LIGGGHTS runs it, and `grainlab digest` measures its walls output with the engine's own estimator (the same averaging window and block intervals). "
      "Both sides use LIGGGHTS' lever arm (`model.lever_arm = radius_minus_half_overlap`, as the workbench's shear case does; grainlab's default `radius` would be a `# Differs` line in the deck), "
      "and grainlab ran the identical scene (so the grainlab column is not the main sweep's run). The quantity compared is the wall tau/sigma over the second half of the run.")
    A("")
    A("| P (kPa) | V (m/s) | duration (s) | steps | grainlab tau/sigma | LIGGGHTS tau/sigma | difference / combined 95% | grainlab sigma (kPa) | LIGGGHTS sigma (kPa) | wall time grainlab / LIGGGHTS (s) |")
    A("|---|---|---|---|---|---|---|---|---|---|")
    for key in sorted({(r["P_set_pa"], r["V_m_s"]) for r in lig_rows}, key=lambda k: -k[0]):
        g = next(r for r in lig_rows if (r["P_set_pa"], r["V_m_s"]) == key and r["code"] == "grainlab")
        l = next((r for r in lig_rows if (r["P_set_pa"], r["V_m_s"]) == key and r["code"] == "liggghts"), None)
        if l is None:
            continue
        comb = math.hypot(g["tau_over_sigma_ci95"], l["tau_over_sigma_ci95"])
        A(f"| {key[0] / 1e3:g} | {key[1]:g} | {g['duration_s']:.4f} | {int(g['steps']):,} | {pm(g['tau_over_sigma'], g['tau_over_sigma_ci95'])} | {pm(l['tau_over_sigma'], l['tau_over_sigma_ci95'])} | "
          f"{(l['tau_over_sigma'] - g['tau_over_sigma']) / comb:+.2f} | {g['sigma_pa'] / 1e3:.2f} | {l['sigma_pa'] / 1e3:.2f} | {g['wall_s']:.0f} / {l['wall_s']:.0f} |")
    A("")
    LIG_TEXT_MARK = len(md)
else:
    A("(Not run in this version: `--no-liggghts` or `--quick` without LIGGGHTS rows.)")
    A("")
A("## Regenerate")
A("")
A("```")
A(f"scripts/rheology-docs             # every run (serial, about {total_wall / 60:.0f} minutes on one core of the machine that wrote this page), fits, figures, this page")
A("scripts/rheology-docs --reuse     # the fits, figures and page from docs/rheology/*.csv, no runs")
A("scripts/rheology-docs --quick     # a smoke version (short runs, 4 points, one tiny LIGGGHTS run) into a scratch folder")
A("scripts/rheology-docs --no-liggghts --keep DIR   # skip LIGGGHTS; keep every run's output folder (profiles.csv, summary.json) under DIR")
A("```")
A("")
A("Files: `docs/rheology/layers.csv` (every bulk layer of every run: I, mu with its interval, phi, P, shear rate), `runs.csv` (one row per run: duration, steps, wall time, gap, "
  "averaged strain, wall tau/sigma, bulk averages), `liggghts.csv` (the LIGGGHTS points and grainlab on the same scenes), `mu_I.png`, `phi_I.png`, `velocity_profiles.png`.")
A("")
CAVEAT_MARK = len(md)
def run_of(shape, P, V, seed=1):
    return next((r for r in runs if (r["shape"], r["P_set_pa"], r["V_m_s"], r["seed"]) == (shape, P, V, seed)), None)


CAVEATS = []
bad = [r for r in runs if not r["steady"]]
if bad:
    CAVEATS.append("**Not steady, left out.** " + "; ".join(f"{r['shape']} at {plabel(r['P_set_pa'])}, V = {r['V_m_s']:g} m/s: the top wall carries {r['wall_over_load']:.2f} of the load on average "
                   f"and the bulk pressure varies by {100 * r['bulk_pressure_cv']:.0f}% across the gap" for r in bad)
                   + ". At 1 kPa and 5 m/s the cell keeps dilating and the loaded wall (the mass of its glued grains) is thrown about; these runs are drawn grey and are in the CSVs, but no constant is fitted to them.")
for shape in SHAPES:
    f = fits[shape]
    if "mu_boot" in f:
        lo, hi, _ = f["mu_boot"]
        ptsh = [l for l in layers if l["shape"] == shape and usable(l)]
        n01 = sum(1 for l in ptsh if l["inertial_number"] > 0.1)
        n02 = sum(1 for l in ptsh if l["inertial_number"] > 0.2)
        st = [r for r in runs if r["shape"] == shape and r["steady"]]
        CAVEATS.append(f"**mu_2 and I0 are not resolved ({shape}).** The bulk layers reach I ≈ {f['I_max']:.2f} at most; {n01} of {len(ptsh)} layers lie above I = 0.1 and {n02} above 0.2; the bootstrap over runs puts mu_2 in "
                       f"[{lo[1]:.2f}, {hi[1]:.2f}] and I0 in [{lo[2]:.2f}, {hi[2]:.2f}] (the bounds of the fit are mu_2 <= 3, I0 <= 20). "
                       "The data fix mu_s and the initial slope (mu_2 - mu_s)/I0, which is why mu_min + b I fits as well. "
                       "Higher wall speeds do not raise the bulk I: at 1 kPa most of the imposed 2V goes into slip and a dilute gas in the three layers next to each rough wall "
                       "(the bulk shear rate falls to " + f"{min(r['bulk_rate_ratio'] for r in runs if r['steady'] and r['shape'] == shape):.2f}" + " of 2V/H in the steady runs, against " + f"{max(r['bulk_rate_ratio'] for r in runs if r['shape'] == shape):.2f}" + " at best), and the wall tau/sigma (crosses) rises to " + f"{max(r['tau_over_sigma'] for r in st):.2f} while the bulk-average mu stays at or below {max(r['mu_bulk'] for r in st):.2f}. "
                       "Resolving I > 0.2 would need a homogeneous drive (Lees-Edwards boundaries, which grainlab does not have) or a different wall.")
if "phi" in fits.get("sphere", {}):
    CAVEATS.append("**phi(I) is not linear over the whole range.** The bulk solid fraction stays at about " + f"{fits['sphere']['phi'][0][0]:.3f}" + " up to I of a few 1e-2 and falls faster beyond "
                   "(figure); the straight line is a compromise over I <= " + f"{PHI_FIT_MAX_I}" + ", so a depends on the range fitted and on where the points lie (the disks, with fewer low-pressure points, get a larger a). "
                   "The dilute layers next to the walls (phi down to 0.2-0.6 at high speed) are not part of it.")
lowp = [r for r in runs if r["I_bulk"] < 2e-3]
if lowp:
    CAVEATS.append(f"**The quasi-static end.** The lowest bulk I is {min(r['I_bulk'] for r in runs):.1e} (P = 1 MPa at 0.3 m/s and 100 kPa at 0.1 m/s, 3 units of strain averaged); "
                   "mu_s is the fit's extrapolation to I -> 0, not a measured yield stress. Creep below yield and non-local effects were not studied.")
pairs = [(("sphere", 1e6, 0.3), ("sphere", 1e5, 0.1)), (("sphere", 1e5, 1.5), ("sphere", 1e4, 0.5))]
txt = []
for a, b in pairs:
    ra, rb = run_of(*a), run_of(*b)
    if ra and rb:
        txt.append(f"I_bulk = {ra['I_bulk']:.4f} at {plabel(a[1])} against {rb['I_bulk']:.4f} at {plabel(b[1])}: mu_bulk {ra['mu_bulk']:.3f} against {rb['mu_bulk']:.3f}, phi_bulk {ra['phi_bulk']:.3f} against {rb['phi_bulk']:.3f}")
if txt:
    CAVEATS.append("**Stiffness.** The grains have glass stiffness at every load (no scaling): the mean overlap is about 3e-3 of a radius at 1 MPa and far less at 1 kPa. "
                   "Points at the same I and different P agree within their noise (" + "; ".join(txt) + "), so no softness effect is visible, but it was not studied beyond that.")
if ens:
    CAVEATS.append("**The layers' intervals are too wide**, by a factor of about " + f"{1 / max(e['layer_ratio'] for e in ens):.1f}-{1 / min(e['layer_ratio'] for e in ens):.1f} for mu and "
                   f"{1 / max(e['phi_ratio'] for e in ens):.0f}-{1 / min(e['phi_ratio'] for e in ens):.0f} for phi (the seed check above): mu's interval treats sigma_xx and sigma_yy as independent, and profiles.csv's "
                   "block intervals probably use few blocks where a layer's autocorrelation is long (a Student t with few degrees of freedom; profiles.csv does not report the block count, so this is not verified). "
                   "So chi^2/dof is below 1 for mu and the weights are only relative; the bootstrap over runs does not depend on them. The wall tau/sigma's block interval is "
                   f"{min(e['ts_block_ci'] / (1.96 * e['ts_sd']) for e in ens):.1f}-{max(e['ts_block_ci'] / (1.96 * e['ts_sd']) for e in ens):.1f} of 1.96 sd over seeds, i.e. about right (4 seeds only).")
CAVEATS.append("**One cell, mostly one seed.** All points use the 1000-grain cell (gap about 25 diameters, periodic length 40 mm) and packing seed 1 except the three ensemble points; "
               "no larger cell was run, and the averaging windows hold 3-4 units of gap strain after 3-4 units of start-up (the start-up transient was not checked run by run beyond the steadiness test).")
CAVEATS.append("**Literature numbers are unconfirmed**: see the section above; the comparison is with recalled values, and the contact parameters differ anyway.")
if lig_rows:
    CAVEATS.append("**LIGGGHTS** was compared on the wall tau/sigma only (it has no layer profiles here), at three moderate-I points with the LIGGGHTS lever arm on both sides; the main sweep uses grainlab's default lever arm (`radius`).")
A("## Caveats: what is not resolved")
A("")
for c in CAVEATS:
    A("- " + c)
A("")
with open(os.path.join(DOCS, "rheology.md"), "w") as fh:
    fh.write("\n".join(md))
print(f"wrote {os.path.join(DOCS, 'rheology.md')} and {OUT}")
