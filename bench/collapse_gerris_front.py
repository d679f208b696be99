#!/usr/bin/python3
"""The column collapse's front beside Gerris's on the same grids.

usage: collapse_gerris_front.py MUFLOW OUTDIR [--aspect 1.42] [--levels 6 7 8]
                                [--end 6] [--eta-max 10]

Both codes with the same model: the aspect ratio a = H0/R0 of Lagree,
Staron & Popinet (2011) (H0 = 1; R0 and d as collapse_deposits.py and
docs/validation/collapse.md give them), the granular viscosity clipped to
[d sqrt(g d), ETA_MAX] (Gerris's example: 10) and mixed with the light
phase's by the harmonic mean (collapse.mixture = harmonic, Gerris's rule),
van Leer's advection for muflow, each code's own step (Gerris's example's
cap 0.01, cases/collapse.ini's), to t = END.  Gerris 1.3.2 runs
bench/gerris/collapse.gfs with R0, d and the end time put in; muflow
cases/collapse.ini on the grid of the same cell size (2^LEVEL cells
across Gerris's 5 H0 box: 6, 7, 8, 9 are 12.8, 25.6, 51.2, 102.4 cells per
H0).  Writes OUTDIR/collapse_gerris_front.md: per grid the largest
|x_f(muflow) - x_f(Gerris)| over t in [0, END] (both series linear between
their steps, compared every 0.01), when it happens, and the fronts at t =
1, 2, ..., END; then each code's every grid against Gerris's finest.
Gerris's front is the largest interface position where T > 0.1 (its
example's diagnostic) and, beside it, where T > 0.5; muflow's the largest x
of the T = 1/2 contour.  --reuse keeps the runs already in OUTDIR."""
import argparse
import math
import os
import re
import shutil
import subprocess
import sys

from collapse_gerris import GERRIS, GFS, gerris_norm_log
from collapse_series import at, series
from summary_ini import timed_run

HERE = os.path.dirname(os.path.abspath(__file__))
CASE = os.path.join(HERE, "..", "cases", "collapse.ini")
# aspect ratio -> (R0, d), H0 = 1: the paper's Table (collapse_deposits.py)
ASPECTS = {0.5: (2.0, 1.0 / 30.0), 1.42: (1.0 / 1.42, 1.0 / 65.0),
           6.26: (1.0 / 6.26, 1.0 / 65.0)}
EVERY = 0.01


def gerris_case(text, r0, d, end):
    """collapse.gfs with R0, d and the end time put in (each must be found
    once: the file's own definitions)."""
    for pattern, value in ((r"Define R0 \S+", "Define R0 %.17g" % r0),
                           (r"Define D \S+", "Define D %.17g" % d),
                           (r"end = \S+", "end = %g" % end)):
        text, n = re.subn(pattern, value, text)
        if n != 1:
            sys.exit("collapse_gerris_front.py: %r not once in %s" % (pattern, GFS))
    return text


def gerris_fronts(d):
    """Gerris's fronts where T > 0.1 and where T > 0.5, each (times, x)."""
    return (gerris_norm_log(os.path.join(d, "front.log")),
            gerris_norm_log(os.path.join(d, "front_half.log")))


def run_gerris(d, level, r0, dg, end, eta_max, reuse):
    if reuse and os.path.exists(os.path.join(d, "front_half.log")):
        return gerris_fronts(d), float("nan")
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    with open(GFS) as f:
        text = gerris_case(f.read(), r0, dg, end)
    with open(os.path.join(d, "collapse.gfs"), "w") as f:
        f.write(text)
    with open(os.path.join(d, "gerris.log"), "w") as log:
        code, wall, _, _ = timed_run(
            [GERRIS, "-DLEVEL=%d" % level, "-DETAMAX=%s" % eta_max, "-DDTMAX=0.01",
             "collapse.gfs"], cwd=d, stdout=log, stderr=subprocess.STDOUT)
    if code != 0:
        sys.exit("gerris failed in %s (exit %d): see gerris.log" % (d, code))
    return gerris_fronts(d), wall


def run_muflow(muflow, d, level, r0, dg, end, eta_max, reuse, advection):
    csv = os.path.join(d, "collapse.csv")
    if reuse and os.path.exists(os.path.join(d, "summary.ini")):
        ts, xf, _ = series(csv)
        return ts, xf, float("nan")
    cells = 2 ** level                     # across Gerris's 5 H0
    cmd = [muflow, CASE, "domain.nx=%d" % cells, "domain.nz=%d" % (cells * 5 // 16),
           "domain.ly=%.17g" % (5.0 / cells), "domain.lz=1.5625",
           "collapse.half_width=%.17g" % r0, "rheology.grain_diameter=%.17g" % dg,
           "collapse.mixture=harmonic", "collapse.viscosity_clip=on",
           "collapse.eta_max=%s" % eta_max, "physics.advection_scheme=" + advection,
           "collapse.rest_energy=0", "solver.end_time=%g" % end,
           "output.fields=off", "output.quiet=on", "output.dir=" + d]
    print(" ".join(cmd), flush=True)
    code, wall, _, _ = timed_run(cmd)
    if code != 0:
        sys.exit("muflow failed (exit %d): %s" % (code, " ".join(cmd)))
    ts, xf, _ = series(csv)
    return ts, xf, wall


def apart(a, b, end):
    """The largest |a - b| of two front series over t in [0, end], every EVERY,
    and when."""
    worst, when = 0.0, 0.0
    for m in range(int(round(end / EVERY)) + 1):
        t = m * EVERY
        e = abs(at(a[0], a[1], t) - at(b[0], b[1], t))
        if math.isnan(e):
            sys.exit("collapse_gerris_front.py: a front missing at t = %g" % t)
        if e > worst:
            worst, when = e, t
    return worst, when


def main():
    p = argparse.ArgumentParser(description="The collapse's front beside Gerris's (see the "
                                "module's docstring).")
    p.add_argument("muflow")
    p.add_argument("outdir")
    p.add_argument("--aspect", type=float, default=1.42, choices=sorted(ASPECTS))
    p.add_argument("--levels", type=int, nargs="+", default=[6, 7, 8])
    p.add_argument("--end", type=float, default=6.0)
    p.add_argument("--eta-max", default="10")
    p.add_argument("--reuse", action="store_true")
    p.add_argument("--advection", default="vanleer", choices=["vanleer", "centred", "upwind"],
                   help="muflow's advection scheme (the runs' directories are named by it "
                   "unless vanleer)")
    o = p.parse_args()
    if shutil.which(GERRIS) is None:
        sys.exit("collapse_gerris_front.py: %s not found (Debian's gerris and libgfs-dev)"
                 % GERRIS)
    os.makedirs(o.outdir, exist_ok=True)
    r0, dg = ASPECTS[o.aspect]
    whole = [int(t) for t in range(1, int(o.end) + 1)]
    lines = ["# Column collapse a = %g to t = %g beside Gerris 1.3.2" % (o.aspect, o.end), "",
             "The harmonic mixture, the clip [d sqrt(g d), %s], muflow's advection %s, each "
             "code's own step; max |x_f(muflow) - x_f(Gerris)| over t in [0, %g] every %g." % (
                 o.eta_max, o.advection, o.end, EVERY), "",
             "| cells per H0 | max apart | at t | " + " | ".join(
                 "x_f(%d) muflow, Gerris" % t for t in whole) + " | wall s muflow, Gerris |",
             "|---|---|---|" + "---|" * len(whole) + "---|"]
    runs = {}
    for level in o.levels:
        base = os.path.join(o.outdir, "collapse_front_a%g_l%d" % (o.aspect, level))
        print("level %d: Gerris" % level, flush=True)
        (g, gh), wg = run_gerris(base + "_gerris", level, r0, dg, o.end, o.eta_max, o.reuse)
        print("level %d: muflow" % level, flush=True)
        mdir = base + "_muflow" + ("" if o.advection == "vanleer" else "_" + o.advection)
        tm, xm, wm = run_muflow(o.muflow, mdir, level, r0, dg, o.end, o.eta_max, o.reuse,
                                o.advection)
        runs[level] = ((tm, xm), g, gh)
        worst, when = apart((tm, xm), g, o.end)
        lines.append("| %g | %.3f | %.2f | %s | %.1f, %.1f |" % (
            2 ** level / 5.0, worst, when,
            " | ".join("%.3f, %.3f" % (at(tm, xm, t), at(g[0], g[1], t)) for t in whole),
            wm, wg))
        print(lines[-1], flush=True)
    finest = max(o.levels)
    _, gf, ghf = runs[finest]
    lines += ["", "Against Gerris's finest grid (%g cells per H0): max |x_f - x_f(Gerris, "
              "finest)| over t in [0, %g] (at t)." % (2 ** finest / 5.0, o.end), "",
              "| cells per H0 | muflow (T = 1/2) vs Gerris T > 0.1 | muflow vs Gerris T > 0.5 "
              "| Gerris T > 0.1 vs its finest | Gerris T > 0.5 vs its finest "
              "| Gerris T > 0.5 vs T > 0.1, same grid |", "|---|---|---|---|---|---|"]
    for level in o.levels:
        m, g, gh = runs[level]
        cols = [apart(m, gf, o.end), apart(m, ghf, o.end), apart(g, gf, o.end),
                apart(gh, ghf, o.end), apart(gh, g, o.end)]
        lines.append("| %g | %s |" % (2 ** level / 5.0, " | ".join(
            "%.3f (%.2f)" % c for c in cols)))
        print(lines[-1], flush=True)
    with open(os.path.join(o.outdir, "collapse_gerris_front.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
