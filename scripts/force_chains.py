"""Force chains of the shear cell, drawn from a run's last frame (scripts/force-chains)."""
import argparse
import json
import subprocess
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import vtk
from matplotlib.collections import LineCollection, PatchCollection
from matplotlib.patches import Circle
from vtk.util.numpy_support import vtk_to_numpy

GRAINLAB = "target/release/grainlab"


def read_vtp(path):
    r = vtk.vtkXMLPolyDataReader()
    r.SetFileName(str(path))
    r.Update()
    return r.GetOutput()


def arrays(data):
    return {data.GetArrayName(i): vtk_to_numpy(data.GetArray(i)) for i in range(data.GetNumberOfArrays())}


def last_dataset(pvd):
    import xml.etree.ElementTree as ET
    sets = ET.parse(pvd).getroot().iter("DataSet")
    last = list(sets)[-1]
    return float(last.get("timestep")), last.get("file")


def run(out):
    scene = json.loads(subprocess.check_output([GRAINLAB, "scenes", "shear"]))
    scene["output"]["contacts"] = True
    path = Path(out) / "shear-contacts.json"
    path.write_text(json.dumps(scene))
    subprocess.check_call([GRAINLAB, "run", str(path), "--out", str(Path(out) / "run")])
    return Path(out) / "run"


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--from", dest="src", help="a run folder with contacts (output.contacts)")
    ap.add_argument("--png", default="docs/force-chains.png")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(a.src) if a.src else run(tmp)
        t, cfile = last_dataset(folder / "contacts.pvd")
        gfile = cfile.replace("contacts_", "grains_")
        g = read_vtp(folder / gfile)
        c = read_vtp(folder / cfile)
        gp, gd = vtk_to_numpy(g.GetPoints().GetData()), arrays(g.GetPointData())
        cp, cd = vtk_to_numpy(c.GetPoints().GetData()), arrays(c.GetCellData())
        scene = json.loads((folder / "scene.resolved.json").read_text())
    # A check of the files as read: each free grain's force is the sum of its contacts'.
    n = len(gd["radius_m"])
    f = np.zeros((n, 3))
    np.add.at(f, cd["grain"], cd["force_n"])
    grain_partner = cd["partner"] >= 0
    np.add.at(f, cd["partner"][grain_partner], -cd["force_n"][grain_partner])
    free = gd["wall_grain"] == 0
    scale = np.abs(gd["force_n"][free]).max()
    err = np.abs(f[free] - gd["force_n"][free]).max() / scale
    assert err < 1e-9, f"contact forces do not sum to the grains' forces: {err:e}"

    x0, x1 = scene["domain"]["periodic_x"]
    fn = cd["normal_force_n"]
    mean = fn[fn > 0].mean()
    fig, ax = plt.subplots(figsize=(9, 6.4))
    ax.add_collection(PatchCollection([Circle((x, y), r) for (x, y, _), r in zip(gp, gd["radius_m"])], facecolor=np.where(free, "0.88", "0.65"), edgecolor="0.75", linewidth=0.3))
    segs = cp[:, :2].reshape(-1, 2, 2)
    order = np.argsort(fn)
    lines = LineCollection(segs[order], linewidths=0.3 + 1.3 * np.clip(fn[order] / mean, 0, 4), cmap="inferno_r", capstyle="round")
    lines.set_array(fn[order] / mean)
    lines.set_clim(0, 3)
    ax.add_collection(lines)
    ax.set_xlim(x0, x1)
    ax.set_ylim(gp[:, 1].min() - 1e-3, gp[:, 1].max() + 1e-3)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    cb = fig.colorbar(lines, ax=ax, shrink=0.6, label="normal force / mean normal force")
    sliding = cd["sliding"].mean()
    ax.set_title(f"shear cell at t = {t * 1e3:.1f} ms: {len(fn)} contacts, mean |Fn| = {mean:.3g} N, {100 * sliding:.1f}% sliding\n(walls at +-0.5 m/s under 100 kPa; line width and colour by normal force)", fontsize=9)
    fig.tight_layout()
    fig.savefig(a.png, dpi=130)
    print(f"wrote {a.png} from {folder / cfile} (forces checked: contacts sum to grain forces within {err:.1e})")


if __name__ == "__main__":
    main()
