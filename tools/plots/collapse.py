"""The column collapse against Lagree, Staron & Popinet (2011): the front
x_f(t) and the height on the axis h(0, t) of collapse.csv against the
published Basilisk run (cases/data/lagree2011_collapse.csv, the case's
case.reference), and the surface profiles of surface.csv beside the final
deposit of Staron's contact dynamics (cases/data/staron_cd_deposits.csv),
both at the run's aspect ratio a = H0 / R0."""
import os

import numpy as np

from . import figure
from .run import reference_curve

FRONT = "lagree2011_collapse.csv"
DEPOSITS = "staron_cd_deposits.csv"


def plot(run, out, units):
    s = run.table("collapse.csv")
    if s is None:
        print("no collapse.csv: no collapse comparison")
        return None
    a = run.num("collapse.height") / run.num("collapse.half_width")
    ref = run.reference(FRONT)
    fig = figure.new(13.0, 7.5)
    grid = fig.add_gridspec(2, 2, height_ratios=[1, 1.1])
    ax_x, ax_h = fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[0, 1])
    ax_s = fig.add_subplot(grid[1, :])
    drawn = 0
    for ax, col, symbol in ((ax_x, "x_front", "x$_f$"), (ax_h, "h_axis", "h(0, t)")):
        ax.plot(s["t"], s[col], "-", label="muflow")
        rt, rv = reference_curve(ref, col, a) if ref else ([], [])
        if len(rt):
            ax.plot(rt, rv, "ko", ms=6, mfc="none", label="Lagree et al. 2011 (Basilisk)")
            drawn += 1
        ax.set_xlabel(units.label("t", "time"))
        ax.set_ylabel(units.label(symbol, "length"))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    ax_x.set_title("front position", fontsize=10)
    ax_h.set_title("height on the axis", fontsize=10)

    _surfaces(run, ax_s, units, a)
    fig.suptitle("%s, a = H$_0$/R$_0$ = %.3g: against Lagree, Staron & Popinet (2011)\n%s" % (
        run.name, a, figure.headline_text(run, ("x_front", "x_front_err_max", "h_axis",
                                                "h_axis_err_max", "mass_error"))), fontsize=10)
    return figure.save(fig, out, "compare.png", "against Lagree et al. 2011, %s" % (
        os.path.basename(ref)) if drawn else "no reference x_f(t) at a = %.4g: muflow alone" % a)


def _surfaces(run, ax, units, a):
    t = run.table("surface.csv")
    if t is not None:
        fin = t["final"] == 1
        end = np.nanmax(t["t"][fin]) if fin.any() else np.nan
        times = [tm for tm in sorted(set(t["t"][~fin])) if not np.isclose(tm, end)]
        colours = matplotlib_colours(len(times))
        for c, tm in zip(colours, times):
            m = (t["t"] == tm) & (t["final"] == 0)
            ax.plot(t["x"][m], t["h"][m], "-", color=c, lw=1.2, label="t = %g" % tm)
        if fin.any():
            ax.plot(t["x"][fin], t["h"][fin], "k-", lw=2, label="muflow, end (t = %.3g)" % end)
    dep = run.shipped(DEPOSITS)
    if dep:
        x, h = reference_curve(dep, "deposit", a)
        if x.size:
            x = np.abs(x)  # both sides of the centred column, folded onto x >= 0
            ax.plot(x, h, ".", color="0.5", ms=3, label="final deposit, contact dynamics")
    ax.set_xlim(0, run.num("domain.lx"))
    ax.set_ylim(0, None)
    ax.set_aspect("equal")
    ax.set_xlabel(units.label("x", "length") + " (the axis at 0)")
    ax.set_ylabel(units.label("h", "length"))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, ncol=2, loc="upper right")
    ax.set_title("surface h(x)", fontsize=10)


def matplotlib_colours(n):
    import matplotlib
    cmap = matplotlib.colormaps["viridis"]
    return [cmap(v) for v in np.linspace(0.0, 0.85, max(n, 1))]
