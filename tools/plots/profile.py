"""The profile scenes' comparison: profile.csv's velocity against its exact
profile (u_exact, or another *_exact / *_reference column), and the
difference, with the scene's marks (the two-phase interface, the bed, the
Bingham plug).  A scene this tool does not know gets the same plot of its
profile.csv's first value column against the exact column the file holds,
named by its column."""
import math

import numpy as np

from . import figure
from .units import FIELD_KIND

# scene -> (what the exact profile is, the [result] keys of the headline)
REFERENCE = {
    "bagnold": ("Bagnold's profile (Chauchat & Medale 2014, eqs. 30-32)",
                ("err_rms", "u_surface")),
    "bagnold2": ("the exact two-phase profile (Barker & Rauter 2018, eqs. 6-11)",
                 ("err_rms", "u_top", "u_interface")),
    "chute": ("the chute's exact profile (Chauchat & Medale 2014, eq. 27)",
              ("err_rms", "u_plug")),
    "couette": ("u = U z/H + G z (H - z) / (2 mu)", ("err_rms", "u_mid")),
    "bingham_channel": ("the Bingham plug-flow profile", ("err_rms", "u_plug")),
    "bedload": ("the mixed-fluid model's exact profile (Ouriemi, Aussillous & Guazzelli 2009)",
                ("err_rms", "u_max", "mobile_layer", "flow_rate")),
}


def exact_column(t):
    """The profile's reference column: the velocity column's _exact or
    _reference partner, else any column so named."""
    vel = t.header[1]
    for suffix in ("_exact", "_reference", "_plane"):
        if vel + suffix in t:
            return vel + suffix
    for h in t.header:
        if h.endswith(("_exact", "_reference")):
            return h
    return None


def marks(run):
    """[(coordinate, label, line style)] of lines that explain the profile."""
    out = []
    if run.scene == "bagnold2":
        out.append((run.num("bagnold2.interface_height"), "interface (grains below, air above)",
                    "--"))
    elif run.scene == "bedload":
        hp = run.num("bedload.bed_height")
        out.append((hp, "bed surface h$_p$", "--"))
        ml = run.num("mobile_layer")
        if math.isfinite(ml):
            out.append((hp - ml, "mobile layer's base", ":"))
    elif run.scene == "bingham_channel":
        g = run.num("physics.gravity") * run.num("physics.density") * \
            math.sin(run.num("physics.tilt"))
        y0 = run.num("rheology.yield_stress") / g if g > 0 else math.nan
        half = run.num("domain.lz") / 2
        if 0 < y0 < half:
            out += [(half - y0, "plug edges (exact)", "--"), (half + y0, None, "--")]
    elif run.scene == "chute":
        y0 = run.num("rheology.mu_s") * run.num("physics.confining_pressure")
        half = run.num("domain.ly") / 2
        if 0 < y0 < half:
            out += [(half - y0, "plug edges (exact)", "--"), (half + y0, None, "--")]
    return [m for m in out if math.isfinite(m[0])]


def plot(run, out, units, name="compare.png"):
    t = run.table("profile.csv")
    if t is None or len(t.header) < 2:
        print("no profile.csv (or an empty one): no profile comparison")
        return None
    coord, vel = t.header[0], t.header[1]
    z, u = t[coord], t[vel]
    exact = exact_column(t)
    known = run.scene in REFERENCE
    ref_name, keys = REFERENCE[run.scene] if known else (
        "profile.csv's %s" % exact if exact else "the exact profile", ("err_rms",))
    fig = figure.new(9.5, 5.2)
    ax, ex = fig.subplots(1, 2, sharey=True, gridspec_kw={"width_ratios": [3, 2]})
    if exact is not None and np.isfinite(t[exact]).any():
        ok = np.isfinite(t[exact])
        ax.plot(t[exact][ok], z[ok], "-", color="C1", lw=1.5, label=ref_name)
        ex.plot(u[ok] - t[exact][ok], z[ok], "o-", ms=3, color="C0")
        ex.axvline(0.0, color="0.5", lw=0.8)
    else:
        print("profile.csv has no exact profile: muflow's alone")
        ex.text(0.5, 0.5, "no exact profile", ha="center", transform=ex.transAxes)
    ax.plot(u, z, "o", ms=4, color="C0", label="muflow, %d cells" % len(z))
    for zm, label, style in marks(run):
        for a in (ax, ex):
            a.axhline(zm, color="0.35", ls=style, lw=0.9, label=label if a is ax else None)
    kind = "velocity" if known else FIELD_KIND.get(vel, "none")
    ax.set_xlabel(units.label(vel, kind))
    ax.set_ylabel(units.label(coord, "length"))
    ex.set_xlabel(units.label("%s - %s" % (vel, exact or "exact"), kind))
    ax.legend(fontsize=8, loc="best")
    ex.ticklabel_format(axis="x", style="sci", scilimits=(-2, 3))
    top = run.num("domain.l" + coord) if coord in "xyz" else float("nan")
    for a in (ax, ex):
        a.grid(alpha=0.3)
        if math.isfinite(top):
            a.set_ylim(0.0, top)
    if known:
        what = "velocity profile against %s" % ref_name
    else:
        what = "profile.csv's %s %s" % (vel, "against " + exact if exact else "alone")
    fig.suptitle("%s: %s\n%s" % (run.name, what, figure.headline_text(run, keys)), fontsize=10)
    return figure.save(fig, out, name, "against " + ref_name if exact is not None else
                       "no exact profile: muflow alone")
