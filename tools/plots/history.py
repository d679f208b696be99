"""history.png: how the run went.

A steady run (solver.mode = steady): the residual and the error column of
history.csv against the step, the tolerance drawn.  A transient run has no
residual to converge: the time step against time with the steps the march
rejected, the kinetic energy where the run records one (a kinetic_energy
column of history.csv or of the scene's time series, e.g. collapse.csv), the
forces on a body (forces.csv: C_D and C_L, or the drag and lift forces
without the coefficients), and any other column a scene adds to
history.csv."""
import numpy as np

from . import figure

ERROR_COLUMNS = ("err_rms", "err_midline", "diff_plane")
SCENE_SERIES = ("collapse.csv",)  # scene time series with t and kinetic_energy columns
# forces.csv's series: the coefficients where it has them, else the forces
FORCES = (("drag_coefficient", "lift_coefficient"), ("drag_force", "lift_force"))
# history.csv's columns of every run (its error column is a series where finite)
STANDARD = {"step", "time", "wall_seconds", "dt", "residual", "residual_beyond_roundoff",
            "divergence", "linear_iterations", "rejected_steps"}
MAX_SERIES = 4


def plot(run, out, units):
    h = run.table("history.csv")
    if h is None or "step" not in h:
        print("no history.csv (or an empty one): no history plot")
        return None
    return _transient(run, out, units, h) if run.transient else _steady(run, out, h)


def _steady(run, out, h):
    fig = figure.new(6.5, 4.2)
    ax = fig.add_subplot()
    step = h["step"]
    drawn = []
    for name, style in (("residual", "-"),) + tuple((c, "--") for c in ERROR_COLUMNS):
        if name not in h:
            continue
        y = h[name]
        ok = np.isfinite(y) & (y > 0)
        if ok.any():
            ax.semilogy(step[ok], y[ok], style, label=_label(name))
            drawn.append(name)
    tol = run.num("solver.tolerance")
    if drawn and np.isfinite(tol) and tol > 0:
        ax.axhline(tol, color="0.5", lw=0.8, ls=":", label="solver.tolerance %g" % tol)
    if not drawn:
        print("history.csv has no positive residual or error: history plot empty")
    ax.set_xlabel("step (pseudo-time)")
    ax.set_title("%s: convergence to the steady state (%s)" % (
        run.name, run.result.get("status", "unfinished")), fontsize=10)
    ax.grid(alpha=0.3)
    if drawn:
        ax.legend(fontsize=8)
    return figure.save(fig, out, "history.png", "%s against the step" % ", ".join(drawn))


def _label(name):
    return {"residual": "residual: max |momentum residual| / force scale",
            "err_rms": "err_rms: RMS error against the exact profile",
            "err_midline": "err_midline: RMS difference from the reference mid-line",
            "diff_plane": "diff_plane: RMS difference from the plane channel"}.get(name, name)


def _series(run, h):
    """[(name, t, values)]: the kinetic energy and any other time series of
    the run beyond history.csv's standard columns (a scene's own columns of
    history.csv, the kinetic energy of collapse.csv, the forces of
    forces.csv), at most MAX_SERIES."""
    out = [(c, h["time"], h[c]) for c in h.header
           if c not in STANDARD and np.isfinite(h[c]).any()]
    if not any(name == "kinetic_energy" for name, _, _ in out):
        for table in SCENE_SERIES:
            s = run.table(table)
            if s is not None and "t" in s and "kinetic_energy" in s:
                out.insert(0, ("kinetic_energy", s["t"], s["kinetic_energy"]))
                break
    f = run.table("forces.csv")
    for names in FORCES if f is not None and "time" in f else ():
        if all(n in f for n in names):
            out += [(n, f["time"], f[n]) for n in names]
            break
    return out[:MAX_SERIES]


def _transient(run, out, units, h):
    t = h["time"]
    series = _series(run, h)
    fig = figure.new(7.0, 2.4 + 2.3 * (1 + len(series)))
    axes = fig.subplots(1 + len(series), 1, sharex=True, squeeze=False)[:, 0]
    ok = h["dt"] > 0
    axes[0].semilogy(t[ok], h["dt"][ok], "-", label="dt")
    if "rejected_steps" in h and np.nanmax(h["rejected_steps"]) > 0:
        bad = np.flatnonzero(np.diff(h["rejected_steps"], prepend=0) > 0)
        axes[0].semilogy(t[bad], h["dt"][bad], "rx", label="after a rejected step")
    axes[0].set_ylabel(units.label("dt", "time"))
    axes[0].legend(fontsize=8)
    for ax, (name, st, v) in zip(axes[1:], series):
        pos = v > 0
        if name == "kinetic_energy" and pos.any():
            ax.semilogy(st[pos], v[pos], "-")
            peak = run.num("kinetic_energy_peak")
            rest = run.num("collapse.rest_energy")
            if np.isfinite(peak) and np.isfinite(rest) and rest > 0:
                ax.axhline(rest * peak, color="0.5", ls=":", lw=0.8,
                           label="rest: %g of the peak" % rest)
                ax.legend(fontsize=8)
        else:
            ax.plot(st, v, "-")
        ax.set_ylabel(name.replace("_", " "))
    if not series:
        print("%s records no kinetic energy: history shows the time step alone" % run.name)
    for ax in axes:
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel(units.label("t", "time"))
    axes[0].set_title("%s: transient, %d steps to t = %.4g (%s)" % (
        run.name, len(t) - 1, t[-1], run.result.get("status", "unfinished")), fontsize=10)
    return figure.save(fig, out, "history.png", "dt%s against t" % "".join(
        ", " + name.replace("_", " ") for name, _, _ in series))
