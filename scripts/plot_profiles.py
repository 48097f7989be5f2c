"""Plot a run's profiles.csv (scripts/plot-profiles)."""
import argparse
import csv
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def load(path):
    rows = list(csv.DictReader(open(path)))
    num = lambda v: float(v) if v != "" else np.nan
    return {k: np.array([num(r[k]) for r in rows]) for k in rows[0]}


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("dir", help="a run's output folder with profiles.csv")
    ap.add_argument("--png", help="default: DIR/profiles.png")
    a = ap.parse_args()
    d = load(Path(a.dir) / "profiles.csv")
    y = d["y_over_gap"]
    panels = [
        ("mean x velocity (m/s)", [("velocity_x_m_s", None)]),
        ("solid fraction", [("solid_fraction", None)]),
        ("granular temperature (m$^2$/s$^2$)", [("granular_temperature_m2_s2", None)]),
        ("stress (kPa, tension positive)", [("sigma_xx_pa", "$\\sigma_{xx}$"), ("sigma_yy_pa", "$\\sigma_{yy}$"), ("sigma_yx_pa", "$\\sigma_{yx}$")]),
        ("inertial number I and friction", [("inertial_number", "I"), ("friction", "$|\\sigma_{yx}|/P$")]),
    ]
    fig, axes = plt.subplots(1, len(panels), figsize=(3.1 * len(panels), 4.2), sharey=True)
    for ax, (title, series) in zip(axes, panels):
        for key, label in series:
            scale = 1e-3 if key.startswith("sigma") else 1.0
            ci = d.get(key + "_ci95")
            ax.errorbar(d[key] * scale, y, xerr=None if ci is None else ci * scale, fmt="o-", ms=3, lw=1, capsize=2, label=label)
        if key == "inertial_number" or key == "friction":
            ax.set_xscale("log")
        ax.set_xlabel(title, fontsize=9)
        if any(lbl for _, lbl in series):
            ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("height over the gap (0: bottom wall, 1: top wall)")
    fig.tight_layout()
    out = a.png or str(Path(a.dir) / "profiles.png")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
