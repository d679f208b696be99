#!/usr/bin/python3
"""Pictures of a column collapse run: snapshots and an animation.

    /usr/bin/python3 tools/collapse_movie.py OUTDIR [--out DIR] [--fps N]

OUTDIR is a collapse run's output.dir (case.scene = collapse) with field
files (output.fields = on, output.fields_interval sets their times).  Draws,
into DIR (default OUTDIR/pictures), for every fields_*.h5:

  snapshot_NNNNNN.png  the grains' fraction T (top) and the velocity
                       magnitude |u| (bottom) over x-z, the T = 1/2
                       contour on both
  collapse.gif         the snapshots in order (Pillow, through matplotlib)
  collapse.mp4         the same, when Debian's ffmpeg is installed

Needs numpy, matplotlib and h5py (Debian: python3-matplotlib python3-h5py,
`make deps`).  Exit status 0; 1 when OUTDIR has no field files; 2 when
OUTDIR is not a collapse run (one line saying what it is).
"""
import argparse
import os
import shutil
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import h5py  # noqa: E402
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import animation  # noqa: E402
import numpy as np  # noqa: E402

from plots.fields import edges  # noqa: E402
from plots.run import Run  # noqa: E402


def read(path):
    """(t, T, |u|, x faces, z faces) of a field file (the one y cell)."""
    with h5py.File(path, "r") as f:
        T = np.asarray(f["tracer"][:, 0, :])
        vel = np.asarray(f["velocity"][:, 0, :, :])
        speed = np.sqrt((vel ** 2).sum(axis=-1))
        return float(f.attrs["time"]), T, speed, edges(f, 0), edges(f, 2)


def frame(axes, path, umax):
    t, T, speed, ex, ez = read(path)
    for ax in axes:
        ax.clear()
    axes[0].pcolormesh(ex, ez, T, vmin=0, vmax=1, cmap="YlOrBr", shading="flat")
    axes[1].pcolormesh(ex, ez, speed, vmin=0, vmax=umax, cmap="viridis", shading="flat")
    x, z = 0.5 * (ex[:-1] + ex[1:]), 0.5 * (ez[:-1] + ez[1:])
    for ax in axes:
        if T.min() < 0.5 < T.max():
            ax.contour(x, z, T, levels=[0.5], colors="k", linewidths=0.8)
        ax.set_aspect("equal")
        ax.set_ylabel("z / H$_0$")
    axes[0].set_title("grains' fraction T, t = %.2f $\\sqrt{H_0/g}$" % t)
    axes[1].set_title("|u| / $\\sqrt{g H_0}$ (0 to %.2f)" % umax)
    axes[1].set_xlabel("x / H$_0$")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("outdir")
    ap.add_argument("--out", default=None)
    ap.add_argument("--fps", type=int, default=4)
    a = ap.parse_args()
    if not os.path.isdir(a.outdir):
        print("collapse_movie: %s is not a folder" % a.outdir, file=sys.stderr)
        return 1
    run = Run(a.outdir)
    if run.scene and run.scene != "collapse":
        print("collapse_movie: %s is not a column collapse (case.scene = %s): nothing to draw"
              % (a.outdir, run.scene), file=sys.stderr)
        return 2
    files = [p for _, p in run.fields]
    if not files:
        print("collapse_movie: no fields_*.h5 in %s (output.fields = off?)" % a.outdir,
              file=sys.stderr)
        return 1
    with h5py.File(files[0], "r") as f:
        if "tracer" not in f:
            print("collapse_movie: %s has no tracer (the grains' fraction T): not a collapse "
                  "run" % files[0], file=sys.stderr)
            return 2
        lx, lz = float(f.attrs["len"][0]), float(f.attrs["len"][2])
    out = a.out or os.path.join(a.outdir, "pictures")
    os.makedirs(out, exist_ok=True)
    umax = max(float(read(p)[2].max()) for p in files) or 1.0
    fig, axes = plt.subplots(2, 1, figsize=(8, 2 * 0.9 * 8 * lz / lx + 1.2), sharex=True)
    for path in files:
        frame(axes, path, umax)
        fig.tight_layout()
        name = os.path.basename(path)
        png = os.path.join(out, name.replace("fields_", "snapshot_").replace(".h5", ".png"))
        fig.savefig(png, dpi=100)
        print(png)

    def draw(m):
        frame(axes, files[m], umax)
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
