#!/usr/bin/python3
"""Field maps of a granular cylinder run (Chauchat & Medale 2014, sec. 4.2, figs. 13, 14
and 16): the velocity magnitude, the regularised pressure and the
viscosity (log colours) around the body, from the run's last field file.

usage: cylinder_maps.py RUNDIR [--out FILE.png] [--window 4]

A half box (a slip face through the body's centre, cases/cylinder.ini) is
mirrored about that face into the whole box.  The cells whose centre lies
inside the body are left blank (their values are the solid's, not the
flow's).  --window W shows W body diameters either side of the centre
(0: the whole box)."""
import argparse
import glob
import os

import h5py
import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import LogNorm  # noqa: E402


def text(attrs, key):
    v = attrs[key]
    return v.decode() if isinstance(v, bytes) else str(v)


def axis(f, d):
    """The cell centres and faces of direction d of an open field file: its
    stretched faces (x_faces, ...) where the grid has them, else the
    uniform ones of n and h."""
    name = "xyz"[d] + "_faces"
    if name in f:
        faces = np.array(f[name][:])
    else:
        faces = np.arange(f.attrs["n"][d] + 1) * f.attrs["h"][d]
    return 0.5 * (faces[:-1] + faces[1:]), faces


def last_fields(rundir):
    """The run's last field file (fields_*.h5) and its body, the one circle
    of obstacle.shapes: (path, (xc, zc, r)); exits naming the folder when
    there is no field file or the body is not one circle."""
    files = sorted(glob.glob(os.path.join(rundir, "fields_*.h5")))
    if not files:
        raise SystemExit(f"{rundir}: no field file (fields_*.h5)")
    with h5py.File(files[-1], "r") as f:
        shape = text(f.attrs, "obstacle.shapes").split()
    if not shape or shape[0] != "circle":
        raise SystemExit(f"{rundir}: obstacle.shapes is not one circle")
    return files[-1], tuple(float(x) for x in shape[1:4])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("rundir")
    ap.add_argument("--out", default=None)
    ap.add_argument("--window", type=float, default=4.0)
    a = ap.parse_args()
    path, (xc, zc, r) = last_fields(a.rundir)
    with h5py.File(path, "r") as f:
        at = f.attrs
        n = at["n"]
        mirrored = text(at, "boundary.xlo") == "slip" and xc == 0.0
        speed = np.linalg.norm(f["velocity"][:, 0, :, :], axis=-1)
        fields = [("|u|", speed, None),
                  ("regularised pressure", f["pressure_regularised"][:, 0, :], None),
                  ("viscosity", f["viscosity"][:, 0, :], "log")]
        title = (f"p_ext {text(at, 'physics.confining_pressure')}, g "
                 f"{text(at, 'physics.gravity')}, {n[0]} x {n[2]} cells, lambda "
                 f"{text(at, 'rheology.lambda')}")
        x, xf = axis(f, 0)
        z, _ = axis(f, 2)
    if mirrored:
        x = np.concatenate([-x[::-1], x])
    X, Z = np.meshgrid(x, z)
    inside = (X - xc) ** 2 + (Z - zc) ** 2 < r * r
    fig, axes = plt.subplots(1, 3, figsize=(13, 6.2))
    for ax, (name, v, scale) in zip(axes, fields):
        if mirrored:
            v = np.concatenate([v[:, ::-1], v], axis=1)
        v = np.ma.masked_where(inside, v)
        norm = None
        if scale == "log":
            pos = v[v > 0]
            norm = LogNorm(vmin=max(pos.min(), pos.max() * 1e-12), vmax=pos.max())
        im = ax.pcolormesh(X, Z, v, shading="nearest", norm=norm, cmap="viridis")
        ax.add_patch(plt.Circle((xc, zc), r, color="0.6"))
        if a.window > 0:
            lo, hi = (-xf[-1], xf[-1]) if mirrored else (xf[0], xf[-1])
            ax.set_xlim(max(lo, xc - a.window), min(hi, xc + a.window))
            ax.set_ylim(zc - 1.5 * a.window, zc + 1.5 * a.window)
        ax.set_aspect("equal")
        ax.set_title(name)
        ax.set_xlabel("x / D")
        fig.colorbar(im, ax=ax, shrink=0.8)
    axes[0].set_ylabel("z / D (flow downwards)")
    fig.suptitle(title)
    fig.tight_layout()
    out = a.out or os.path.join(a.rundir, "cylinder_maps.png")
    fig.savefig(out, dpi=100)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
