"""The ducts (square and circular, Chauchat & Medale 2010 sec. 4): the
velocity on the mid-plane (midplane.csv: the last column of cells and the
symmetry plane itself) against the plane channel's exact profile at the same
pressure gradient, and the half cross-section with the bed and, for the
circular duct, the wall's outline."""
import numpy as np

from . import figure
from .fields import cell_values, edges


def plot(run, out, units):
    t = run.table("midplane.csv") or run.table("profile.csv")
    if t is None:
        print("no midplane.csv or profile.csv: no duct comparison")
        return None
    ly, lz = run.num("domain.ly"), run.num("domain.lz")
    w, h = figure.map_size(ly, lz, area=22.0)
    fig = figure.new(5.5 + w + 1.8, max(h + 1.6, 5.0))
    ax, ax_map = fig.subplots(1, 2, gridspec_kw={"width_ratios": [5.5, w + 1.2]})
    z = t["z"]
    for col, style, label in (("u_plane", "-", "plane channel, exact (same -dp/dx)"),
                              ("u_column", "o", "muflow, last cell column"),
                              ("u_symmetry", "x", "muflow, on the symmetry plane"),
                              ("u", "o", "muflow, mid-plane")):
        if col in t:
            ax.plot(t[col], z, style, ms=4, label=label)
    hp = run.num("duct.bed_height")
    for a in (ax, ax_map):
        a.axhline(hp, color="0.4", ls="--", lw=0.8, label="bed surface h$_p$" if a is ax else None)
    ax.set_xlabel(units.label("u", "velocity"))
    ax.set_ylabel(units.label("z", "length"))
    ax.set_ylim(0, lz)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("mid-plane profile against the plane channel", fontsize=10)

    if run.fields:
        import h5py
        with h5py.File(run.fields[-1][1], "r") as f:
            u = cell_values(f, "u").mean(axis=2)  # (nz, ny): uniform along x
            ey, ez = edges(f, 1), edges(f, 2)
        cy, cz = 0.5 * (ey[:-1] + ey[1:]), 0.5 * (ez[:-1] + ez[1:])
        solid = figure.solid_mask(run, 1, 2, cy, cz)
        if solid is not None:
            u = np.ma.masked_array(u, mask=solid)
        ax_map.set_facecolor("0.8")
        mesh = ax_map.pcolormesh(ey, ez, u, shading="flat", cmap="viridis")
        fig.colorbar(mesh, ax=ax_map, label=units.label("u", "velocity"), shrink=0.8)
        figure.draw_body(ax_map, run, 1, 2)
    ax_map.set_aspect("equal")
    ax_map.set_xlim(0, ly)
    ax_map.set_ylim(0, lz)
    ax_map.set_xlabel(units.label("y", "length") + " (symmetry plane at %g)" % ly)
    ax_map.set_ylabel(units.label("z", "length"))
    ax_map.set_title("velocity along the duct, half cross-section", fontsize=10)
    fig.suptitle("%s: the duct against the plane channel of the same pressure gradient\n%s" % (
        run.name, figure.headline_text(run, ("diff_plane", "u_max", "velocity_ratio",
                                             "flow_rate"))), fontsize=10)
    return figure.save(fig, out, "compare.png", "against the plane channel's exact profile")
