#!/usr/bin/python3
"""The sheared layer at the granular cylinder's surface, grid by grid: the
shear rate |D| against the distance from the body along the ray from the
body's centre through the flow cell of largest |D|, one curve per run,
from each run's last field file (Chauchat & Medale 2014, sec. 4.2;
docs/validation/cylinder.md, the drag's grid convergence).

usage: cylinder_layer.py OUT.png RUNDIR [RUNDIR ...]

A layer one cell thick on every grid shows as a peak of |D| ~ U / h in the
first cell, doubling with each refinement, and the printed table gives the
largest |D|, where it is and h times it (about the velocity jump across
the cell)."""
import math
import sys

import h5py
import matplotlib
import numpy as np

from cylinder_maps import axis, last_fields

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def layer(rundir):
    """The layer of one run: h (the width of the cell of the largest |D|), the cells, the largest |D| outside the body
    and its angle, and |D| against the distance s along the ray through it."""
    path, (xc, zc, r) = last_fields(rundir)
    with h5py.File(path, "r") as f:
        n = f.attrs["n"]
        rate = np.array(f["shear_rate"][:, 0, :])
        x, xf = axis(f, 0)
        z, zf = axis(f, 2)
    X, Z = np.meshgrid(x, z)
    dist = np.hypot(X - xc, Z - zc) - r
    flow = np.isfinite(rate) & (dist > 0)
    k = np.argmax(np.where(flow, rate, -np.inf))
    kz, ix = np.unravel_index(k, rate.shape)
    angle = math.atan2(Z[kz, ix] - zc, X[kz, ix] - xc)
    # the cell of the largest |D|: its width (a stretched grid's local one)
    h = max(xf[ix + 1] - xf[ix], zf[kz + 1] - zf[kz])
    # the cells the ray crosses, sampled at a tenth of that cell
    s = np.arange(0.0, 1.0, 0.1 * h)
    px, pz = xc + (r + s) * math.cos(angle), zc + (r + s) * math.sin(angle)
    ii = np.clip(np.searchsorted(xf, px, side="right") - 1, 0, n[0] - 1)
    kk = np.clip(np.searchsorted(zf, pz, side="right") - 1, 0, n[2] - 1)
    prof = rate[kk, ii]
    keep = flow[kk, ii]
    return {"dir": rundir, "h": h, "n": (n[0], n[2]), "max": rate[kz, ix],
            "angle": math.degrees(angle), "s": s[keep], "rate": prof[keep]}


def plot(out, layers):
    """Prints the layers' table and draws their curves into out."""
    fig, ax = plt.subplots(figsize=(7, 4.5))
    print("| run | cells | h / D | max |D| | angle from the cross-flow axis | h max |D| |")
    print("|---|---|---|---|---|---|")
    for lay in layers:
        label = f"D/{round(1.0 / lay['h'])}"
        print(f"| {lay['dir']} | {lay['n'][0]} x {lay['n'][1]} | {lay['h']:.4g} | "
              f"{lay['max']:.3f} | {lay['angle']:.0f} deg | {lay['h'] * lay['max']:.3f} |")
        ax.step(lay["s"], lay["rate"], where="mid", label=f"{label}: max |D| {lay['max']:.2f}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("distance from the body's surface / D (along the ray through max |D|)")
    ax.set_ylabel("shear rate |D| (g / D)^(1/2)")
    ax.set_title("granular cylinder, F = 1: the layer at the body")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


def main():
    if len(sys.argv) < 3:
        raise SystemExit(__doc__)
    plot(sys.argv[1], [layer(rundir) for rundir in sys.argv[2:]])


if __name__ == "__main__":
    main()
