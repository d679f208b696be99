#!/usr/bin/python3
"""Pictures of a column collapse run: snapshots and an animation.

    /usr/bin/python3 tools/collapse_movie.py OUTDIR [--out DIR] [--fps N]

OUTDIR is a collapse run's output.dir with field files (output.fields = on,
output.fields_interval sets their times).  Draws, into DIR (default
OUTDIR/pictures), for every fields_*.h5 (its time from fields.xdmf):

  snapshot_NNNNNN.png  the grains' fraction T (top) and the velocity
                       magnitude |u| (bottom) over x-z, the T = 1/2
                       contour on both
  collapse.gif         the snapshots in order (Pillow, through matplotlib)
  collapse.mp4         the same, when Debian's ffmpeg is installed

Needs numpy, matplotlib and h5py (Debian: python3-matplotlib python3-h5py,
`make deps`).  Exit status 0, or 1 when OUTDIR has no field files.
"""
import argparse
import glob
import os
import re
import shutil
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import animation  # noqa: E402
import numpy as np  # noqa: E402


def times(outdir):
    """File name -> time, from fields.xdmf (its Time values, in order)."""
    path = os.path.join(outdir, "fields.xdmf")
    out = {}
    if not os.path.exists(path):
        return out
    text = open(path).read()
    for block in re.findall(r"<Grid Name=\"[^\"]*\"[^>]*>(.*?)</Grid>", text, re.S):
        t = re.search(r"<Time Value=\"([^\"]+)\"", block)
        f = re.search(r"(fields_\d+\.h5)", block)
        if t and f:
            out[f.group(1)] = float(t.group(1))
    return out


def extent(outdir):
    """lx, lz from summary.ini's [domain] (cells are uniform)."""
    lx = lz = None
    section = None
    with open(os.path.join(outdir, "summary.ini")) as f:
        for line in f:
            line = line.split(";")[0].strip()
            if line.startswith("["):
                section = line.strip("[]")
            elif section == "domain" and "=" in line:
                k, v = [s.strip() for s in line.split("=", 1)]
                if k == "lx":
                    lx = float(v)
                elif k == "lz":
                    lz = float(v)
    return lx, lz


def frame(fig, axes, path, t, lx, lz, umax):
    with h5py.File(path, "r") as f:
        T = f["tracer"][:, 0, :]
        vel = f["velocity"][:, 0, :, :]
    speed = np.sqrt((vel ** 2).sum(axis=-1))
    ext = [0, lx, 0, lz]
    for ax in axes:
        ax.clear()
    axes[0].imshow(T, origin="lower", extent=ext, vmin=0, vmax=1, cmap="YlOrBr",
                   aspect="equal", interpolation="nearest")
    axes[1].imshow(speed, origin="lower", extent=ext, vmin=0, vmax=umax, cmap="viridis",
                   aspect="equal", interpolation="nearest")
    nz, nx = T.shape
    x = (np.arange(nx) + 0.5) * lx / nx
    z = (np.arange(nz) + 0.5) * lz / nz
    for ax in axes:
        ax.contour(x, z, T, levels=[0.5], colors="k", linewidths=0.8)
        ax.set_ylabel("z / H0")
    axes[0].set_title("grains' fraction T, t = %.2f" % t)
    axes[1].set_title("|u| (0 to %.2f)" % umax)
    axes[1].set_xlabel("x / H0")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("outdir")
    ap.add_argument("--out", default=None)
    ap.add_argument("--fps", type=int, default=4)
    a = ap.parse_args()
    files = sorted(glob.glob(os.path.join(a.outdir, "fields_*.h5")))
    if not files:
        print("collapse_movie: no fields_*.h5 in %s" % a.outdir, file=sys.stderr)
        return 1
    out = a.out or os.path.join(a.outdir, "pictures")
    os.makedirs(out, exist_ok=True)
    tm = times(a.outdir)
    lx, lz = extent(a.outdir)
    umax = 0.0
    for path in files:
        with h5py.File(path, "r") as f:
            v = f["velocity"][:, 0, :, :]
        umax = max(umax, float(np.sqrt((v ** 2).sum(axis=-1)).max()))
    umax = umax or 1.0
    fig, axes = plt.subplots(2, 1, figsize=(8, 2 * 0.9 * 8 * lz / lx + 1.2), sharex=True)
    for path in files:
        name = os.path.basename(path)
        frame(fig, axes, path, tm.get(name, float("nan")), lx, lz, umax)
        fig.tight_layout()
        png = os.path.join(out, name.replace("fields_", "snapshot_").replace(".h5", ".png"))
        fig.savefig(png, dpi=100)
        print(png)

    def draw(m):
        frame(fig, axes, files[m], tm.get(os.path.basename(files[m]), float("nan")), lx, lz,
              umax)
        return axes

    anim = animation.FuncAnimation(fig, draw, frames=len(files))
    gif = os.path.join(out, "collapse.gif")
    anim.save(gif, writer=animation.PillowWriter(fps=a.fps), dpi=80)
    print(gif)
    if shutil.which("ffmpeg"):
        mp4 = os.path.join(out, "collapse.mp4")
        anim.save(mp4, writer=animation.FFMpegWriter(fps=a.fps), dpi=100)
        print(mp4)
    return 0


if __name__ == "__main__":
    sys.exit(main())
