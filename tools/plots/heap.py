"""The heap between side walls (Jop, Forterre & Pouliquen 2005): the surface
velocity across the channel (heap.csv) and the flowing layer on the
cross-section, its depth the velocity falling to heap.depth_fraction of the
column's surface velocity.  Experimental profiles are drawn when the case's
reference file (case.reference) has datasets u_surface and flowing_depth
at the run's flow rate Q*; the shipped case has none."""
import math
import os

from . import figure
from .run import reference_curve


def experiment(run):
    """{dataset: (y, value)} of the case's reference file at Q*, or {}."""
    path = run.key("case.reference", "")
    if not path or not os.path.exists(path):
        return {}
    q = run.num("flow_rate_target")
    q = q if math.isfinite(q) else run.num("heap.flow_rate")
    out = {}
    for name in ("u_surface", "flowing_depth"):
        y, v = reference_curve(path, name, q)
        if y.size:
            out[name] = (y, v)
    return out


def plot(run, out, units):
    t = run.table("heap.csv")
    if t is None:
        print("no heap.csv: no heap comparison")
        return None
    exp = experiment(run)
    ly, lz = run.num("domain.ly"), run.num("domain.lz")
    w, h = figure.map_size(ly, lz, area=24.0)
    fig = figure.new(5.5 + w + 1.6, max(h + 1.8, 6.0))
    grid = fig.add_gridspec(2, 2, width_ratios=[5.5, w + 1.0])
    ax_u, ax_d = fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[1, 0])
    ax_map = fig.add_subplot(grid[:, 1])
    y = t["y"]
    for ax, col, what, kind in ((ax_u, "u_surface", "surface velocity", "velocity"),
                                (ax_d, "flowing_depth", "flowing depth", "length")):
        ax.plot(y, t[col], "o-", ms=3, label="muflow")
        if col in exp:
            ax.plot(*exp[col], "ks", mfc="none", label="experiment")
        ax.set_ylabel(units.label(what, kind))
        ax.set_xlim(0, ly)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    ax_u.set_title("across the channel (side wall at y = 0, mid-plane at %g)" % ly, fontsize=10)
    ax_d.set_xlabel(units.label("y", "length"))

    if run.fields:
        import h5py
        from .fields import cell_values, edges
        with h5py.File(run.fields[-1][1], "r") as f:
            u = cell_values(f, "u").mean(axis=2)  # (nz, ny): uniform along x
            ey, ez = edges(f, 1), edges(f, 2)
        mesh = ax_map.pcolormesh(ey, ez, u, shading="flat", cmap="viridis")
        fig.colorbar(mesh, ax=ax_map, label=units.label("u", "velocity"), shrink=0.8)
    frac = run.num("heap.depth_fraction")
    ax_map.plot(y, lz - t["flowing_depth"], "w-", lw=1.5,
                label="flowing layer's base (u = %g u$_{surface}$)" % frac)
    if "flowing_depth" in exp:
        ye, d = exp["flowing_depth"]
        ax_map.plot(ye, lz - d, "rs", mfc="none", label="experiment")
    ax_map.set_aspect("equal")
    ax_map.set_xlim(0, ly)
    ax_map.set_ylim(0, lz)
    ax_map.set_xlabel(units.label("y", "length"))
    ax_map.set_ylabel(units.label("z", "length"))
    ax_map.legend(fontsize=8, loc="lower right")
    ax_map.set_title("velocity along the channel, half cross-section", fontsize=10)
    note = "" if exp else "\n(no experimental profiles in case.reference: muflow alone)"
    tilt = run.num("tilt")
    tilt = tilt if math.isfinite(tilt) else run.num("physics.tilt")
    fig.suptitle("%s: flow rate Q* = %.5g at the tilt %.5f rad (%.3f deg)\n%s%s" % (
        run.name, run.num("flow_rate"), tilt, math.degrees(tilt),
        figure.headline_text(run, ("flow_rate_target", "u_surface_mid", "depth_mid")), note),
        fontsize=10)
    return figure.save(fig, out, "compare.png", "against the experiment of case.reference"
                       if exp else "no experimental profiles: muflow alone")
