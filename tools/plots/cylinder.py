"""Flow past a body.

plot_drag: the granular cylinder (scene cylinder): the drag per solve of
cylinder.csv against the forcing F and C_D against the Froude number, and
the stresses around the body (obstacle_surface.csv).  No published drag is
in the project: muflow's alone.

plot_benchmark: a body in a channel (the summary's drag_coefficient): C_D,
C_L and the pressure difference of every evaluation the summary has, against
the Schaefer & Turek (1996) test 2D-1 values when the run is that set-up (the
summary's *_reference keys where it writes them, else the published values
below), and the stresses around the body."""
import math

import numpy as np

from . import figure

# Schaefer & Turek (1996), test 2D-1: reference value and the paper's bounds
SCHAEFER_TUREK = {"drag_coefficient": (5.5795, 5.57, 5.59),
                  "lift_coefficient": (0.0106, 0.0104, 0.0110),
                  "pressure_drop": (0.1175, 0.1172, 0.1176)}
SETUP_2D1 = {"domain.lx": 2.2, "domain.lz": 0.41, "rheology.viscosity": 1e-3,
             "boundary.inflow_velocity": 0.3, "physics.density": 1.0}
# the summary's evaluations of each quantity: key suffix, what it is
VARIANTS = {"drag_coefficient": (("", "surface integral"), ("_control_volume", "control volume"),
                                 ("_reconstructed", "reconstructed traction")),
            "pressure_drop": (("", "p at the front and back points"),)}
VARIANTS["lift_coefficient"] = VARIANTS["drag_coefficient"]
TITLES = {"drag_coefficient": "C$_D$", "lift_coefficient": "C$_L$",
          "pressure_drop": r"$\Delta p$ = p(front) - p(back)"}


def is_2d1(run):
    shapes, _ = figure.shapes(run)
    return (shapes == [("circle", [0.2, 0.2, 0.05])] and
            run.key("boundary.inflow_profile") == "parabolic" and
            all(abs(run.num(k) - v) <= 1e-9 * abs(v) for k, v in SETUP_2D1.items()))


def reference(run, key):
    """(value, low, high) of a benchmark quantity: the summary's key_reference
    where it has one, else the published value when the run is the 2D-1
    set-up, with the paper's bounds there (NaN elsewhere); None without."""
    published = SCHAEFER_TUREK[key] if is_2d1(run) else None
    given = run.num(key + "_reference")
    if math.isfinite(given):
        return (given,) + (published[1:] if published else (math.nan, math.nan))
    return published


def _contiguous(angle):
    """The angles (degrees) shifted by -360 past the widest gap between
    samples, so that a part of the outline (a half body on a symmetry
    plane) is drawn as one curve."""
    a = np.sort(angle)
    gaps = np.append(np.diff(a), a[0] + 360.0 - a[-1])
    g = int(np.argmax(gaps))
    if g == len(a) - 1 or gaps[g] < 4 * np.median(gaps):  # a whole outline: as it is
        return angle
    return np.where(angle > a[g], angle - 360.0, angle)


def _surface(run, ax, units):
    s = run.table("obstacle_surface.csv")
    if s is None:
        ax.set_axis_off()
        return
    angle = _contiguous(s["angle_deg"])
    order = np.argsort(angle)
    for col, label in (("pressure", "p"), ("tangential_stress", "tangential stress")):
        if col in s:
            ax.plot(angle[order], s[col][order], "-", label=label)
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.set_xlabel("angle on the outline [deg] (obstacle_surface.csv)")
    ax.set_ylabel(units.label("stress", "pressure"))
    ax.set_xlim(np.nanmin(angle), np.nanmax(angle))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("stresses around the body", fontsize=10)


def plot_benchmark(run, out, units):
    if "drag_coefficient" not in run.result:
        print("no drag_coefficient in summary.ini: no body comparison")
        return None
    fig = figure.new(13.0, 7.5)
    axes = fig.subplots(2, 2).ravel()
    refs = 0
    for ax, key in zip(axes, SCHAEFER_TUREK):
        vals = [(label, run.num(key + suffix)) for suffix, label in VARIANTS[key]
                if math.isfinite(run.num(key + suffix))]
        ax.set_title(TITLES[key], fontsize=10)
        if not vals:
            ax.text(0.5, 0.5, "no %s in summary.ini" % key, ha="center", transform=ax.transAxes)
            continue
        ref = reference(run, key)
        if ref is not None:
            refs += 1
            value, lo, hi = ref
            if math.isfinite(lo) and math.isfinite(hi):
                ax.axhspan(lo, hi, color="0.6", alpha=0.3,
                           label="benchmark bounds %g-%g" % (lo, hi))
            ax.axhline(value, color="k", lw=1.2, label="reference %g" % value)
        for m, (label, v) in enumerate(vals):
            err = " (%+.2f %%)" % (100 * (v / ref[0] - 1)) if ref else ""
            ax.plot([m], [v], "o", ms=8, color=("C0", "C2", "C3")[m],
                    label="muflow, %s: %.5g%s" % (label, v, err))
        ax.set_xticks(range(len(vals)), [v[0] for v in vals], fontsize=8)
        ax.set_xlim(-0.5, len(vals) - 0.5)
        ax.grid(alpha=0.3, axis="y")
        ax.legend(fontsize=8)
    _surface(run, axes[-1], units)
    against = "against Schaefer & Turek (1996), test 2D-1" if refs else \
        "no reference: not the Schaefer & Turek 2D-1 set-up"
    fig.suptitle("%s: forces on the body, %s\n%s, t = %s" % (
        run.name, against, run.result.get("status", "unfinished"),
        run.result.get("time", "?")), fontsize=10)
    return figure.save(fig, out, "compare.png", against)


def plot_drag(run, out, units):
    t = run.table("cylinder.csv")
    if t is None:
        print("no cylinder.csv: no drag comparison")
        return None
    fig = figure.new(14.0, 4.8)
    ax_f, ax_c, ax_s = fig.subplots(1, 3)
    steady = np.array([s == "steady" for s in t.text["status"]])
    ax_f.plot(t["F"][steady], t["F_D_over_p"][steady], "o-", label="control volume (steady)")
    if (~steady).any():
        ax_f.plot(t["F"][~steady], t["F_D_over_p"][~steady], "rx", label="not steady")
    if "F_D_surface" in t:
        ax_f.plot(t["F"][steady], t["F_D_surface"][steady] / t["p_ext"][steady], "s",
                  mfc="none", label="surface integral (steady)")
    ax_f.set_xlabel(r"forcing F = $\rho \phi g L_x / p_{ext}$")
    ax_f.set_ylabel(r"drag F$_D$ / (p$_{ext}$ D), the whole cylinder")
    ax_f.grid(alpha=0.3)
    ax_f.legend(fontsize=8)
    ax_f.set_title("drag against the forcing", fontsize=10)
    ok = steady & (t["Fr"] > 0) & (t["C_D"] > 0)
    if ok.any():
        ax_c.loglog(t["Fr"][ok], t["C_D"][ok], "o-")
    ax_c.set_xlabel(r"Fr = U / $\sqrt{g D}$")
    ax_c.set_ylabel(r"C$_D$ = F$_D$ / ($\rho \phi$ U$^2$ D / 2)")
    ax_c.grid(alpha=0.3, which="both")
    ax_c.set_title("drag coefficient against the Froude number", fontsize=10)
    _surface(run, ax_s, units)
    fig.suptitle("%s: drag on the cylinder, p_ext = %s (no published drag in the project: "
                 "muflow alone)\n%s" % (
                     run.name, run.key("physics.confining_pressure", "?"),
                     figure.headline_text(run, ("forcing", "drag", "drag_surface", "froude"))),
                 fontsize=10)
    return figure.save(fig, out, "compare.png", "no published drag: muflow alone")
