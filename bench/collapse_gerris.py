#!/usr/bin/python3
"""The column collapse beside Gerris, on one machine in one sitting.

usage: collapse_gerris.py MUFLOW OUTDIR [--levels 7 8] [--caps 10 1e4]
                          [--muflow-sets SET ...] [--gerris-dts 0.01 0.02]
                          [--repeats 2]

a = 0.5 to t = 4 at LEVEL (2^LEVEL cells across Gerris's 5 H0 box: 7, 8, 9
are 25.6, 51.2, 102.4 cells per H0), for each upper clip of the granular
viscosity ETAMAX (Gerris's example of the paper: 10; the Basilisk port and
muflow's published set-up, `make bench-collapse`: 1e4), with each code's
time-step settings: Gerris's cap `dtmax` (the example's 0.01; its CFL,
0.8, cuts it) and muflow's SETs, each a space-separated list of case
overrides (the defaults: the set-up's cap solver.dt = 0.01; 0.04; the
caps 0.03 and 0.04 with the advective CFL number 1 and the VOF's limit of
the step off, collapse.vof_cfl = 0, its transport sub-stepping instead).  Each
repeat runs Gerris 1.3.2 (bench/gerris/collapse.gfs; serial, as it runs)
at each of its caps and muflow (cases/collapse.ini with the clip and van
Leer's advection on the grid of the same cell size, square cells, the
caller's OMP_NUM_THREADS, 2 in `make bench-collapse-gerris`) with each of
its SETs, one after the other, the order reversed every other repeat.  Recorded per run: wall and CPU seconds
of the process (wait4), peak resident memory, steps, the 1-minute load
average before it, the front x_f(t) at t = 1..4 against the reference,
the height on the axis h(0, 4) (the Basilisk port's output,
cases/data/lagree2011_collapse.csv) and the grains' volume drift.  Writes
OUTDIR/collapse_gerris.md (medians, and per run the ratio of the wall time
of Gerris at its first cap, the example's, in the same repeat over the
run's) and collapse_gerris_runs.csv.

Gerris's front is the largest interface position where T > 0.1 (its
example's own diagnostic), muflow's the largest x of the T = 1/2 contour;
both codes compile nothing of the case but Gerris (it builds the viscosity
function with the C compiler at start, inside its wall time: about 0.5 s)."""
import argparse
import os
import shutil
import statistics
import subprocess
import sys

from collapse_series import at, reference, series
from summary_ini import loadavg, summary, timed_run

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..")
CASE = os.path.join(ROOT, "cases", "collapse.ini")
GFS = os.path.join(HERE, "gerris", "collapse.gfs")
TIMES = [1, 2, 3, 4]
GERRIS = "gerris2D"


def gerris_norm_log(path):
    """Times and infinity norms of an OutputScalarNorm file."""
    ts, vs = [], []
    with open(path) as f:
        for line in f:
            w = line.split()
            if "time:" in w and "infty:" in w:
                ts.append(float(w[w.index("time:") + 1]))
                vs.append(float(w[w.index("infty:") + 1]))
    return ts, vs


def run_gerris(d, level, cap, dtmax):
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    shutil.copy(GFS, d)
    load = loadavg()
    with open(os.path.join(d, "gerris.log"), "w") as log:
        code, wall, cpu, mb = timed_run(
            [GERRIS, "-DLEVEL=%d" % level, "-DETAMAX=%s" % cap, "-DDTMAX=%s" % dtmax,
             "collapse.gfs"],
            cwd=d, stdout=log, stderr=subprocess.STDOUT)
    if code != 0:
        sys.exit("gerris failed in %s (exit %d): see gerris.log" % (d, code))
    steps = 0
    with open(os.path.join(d, "time.log")) as f:
        for line in f:
            if line.startswith("step:"):
                steps = int(line.split()[1])
    ts, xf = gerris_norm_log(os.path.join(d, "front.log"))
    th, h0 = gerris_norm_log(os.path.join(d, "axis.log"))
    vol = []
    with open(os.path.join(d, "volume.log")) as f:
        for line in f:
            w = line.split()
            if "sum:" in w:
                vol.append(float(w[w.index("sum:") + 1]))
    return {"code": "gerris", "wall": wall, "cpu": cpu, "mb": mb, "load": load,
            "steps": steps, "ts": ts, "xf": xf, "h4": at(th, h0, 4.0),
            "volume_drift": abs(vol[-1] - vol[0]) / vol[0]}


def run_muflow(muflow, d, level, cap, overrides):
    cells = 2 ** level                     # across Gerris's 5 H0
    n_per_h0 = cells / 5.0
    nx, nz = cells, (cells * 5) // 16      # the case's 5 x 1.5625 box
    shutil.rmtree(d, ignore_errors=True)
    cmd = [muflow, CASE, "domain.nx=%d" % nx, "domain.nz=%d" % nz,
           "domain.ly=%.17g" % (1.0 / n_per_h0), "domain.lz=1.5625",
           "collapse.viscosity_clip=on", "collapse.eta_max=%s" % cap,
           "physics.advection_scheme=vanleer", "collapse.rest_energy=0",
           "output.fields=off", "output.quiet=on", "output.dir=" + d] + overrides.split()
    load = loadavg()
    code, wall, cpu, mb = timed_run(cmd)
    if code != 0:
        sys.exit("muflow failed (exit %d): %s" % (code, " ".join(cmd)))
    s = summary(os.path.join(d, "summary.ini"))
    ts, xf, h0 = series(os.path.join(d, "collapse.csv"))
    return {"code": "muflow", "wall": wall, "cpu": cpu, "mb": mb, "load": load,
            "steps": int(s["steps"]), "ts": ts, "xf": xf, "h4": at(ts, h0, 4.0),
            "volume_drift": abs(float(s["mass_error"]))}


def options():
    p = argparse.ArgumentParser(description="The column collapse beside Gerris (see the "
                                "module's docstring).")
    p.add_argument("muflow")
    p.add_argument("outdir")
    p.add_argument("--levels", type=int, nargs="+", default=[7, 8])
    p.add_argument("--caps", nargs="+", default=["10", "1e4"])
    p.add_argument("--muflow-sets", nargs="+",
                   default=["solver.dt=0.01", "solver.dt=0.04",
                            "solver.dt=0.03 solver.cfl=1 collapse.vof_cfl=0",
                            "solver.dt=0.04 solver.cfl=1 collapse.vof_cfl=0"],
                   help="muflow's time-step settings, each a space-separated list of "
                        "case overrides")
    p.add_argument("--gerris-dts", nargs="+", default=["0.01", "0.02"],
                   help="Gerris's step caps (dtmax); the first is the ratios' reference")
    p.add_argument("--repeats", type=int, default=2)
    return p.parse_args()


def main():
    o = options()
    muflow, outdir = o.muflow, o.outdir
    if shutil.which(GERRIS) is None:
        sys.exit("collapse_gerris.py: %s not found (Debian's gerris and libgfs-dev: "
                 "make bench-collapse-gerris installs them)" % GERRIS)
    os.makedirs(outdir, exist_ok=True)
    ref = reference()["x_front"]
    rows = []
    runs = ([("gerris", dtmax) for dtmax in o.gerris_dts]
            + [("muflow", m) for m in o.muflow_sets])
    for level in o.levels:
        for cap in o.caps:
            for rep in range(o.repeats):
                base = os.path.join(outdir, "collapse_gerris_l%d_cap%s" % (level, cap))
                order = runs if rep % 2 == 0 else runs[::-1]
                got = {}
                for code, setting in order:
                    d = "%s_%s%d_%d" % (base, code, runs.index((code, setting)), rep)
                    print("level %d, clip %s, %s, %s, run %d"
                          % (level, cap, code, setting, rep + 1), flush=True)
                    got[code, setting] = (run_gerris(d, level, cap, setting) if code == "gerris"
                                          else run_muflow(muflow, d, level, cap, setting))
                first = got["gerris", o.gerris_dts[0]]["wall"]
                for code, setting in runs:
                    r = got[code, setting]
                    r.update(level=level, cap=cap, rep=rep, setting=setting,
                             ratio=first / r["wall"])
                    r["x"] = [at(r["ts"], r["xf"], t) for t in TIMES]
                    r["err"] = max(abs(x - ref[t]) for x, t in zip(r["x"], TIMES))
                    rows.append(r)
    with open(os.path.join(outdir, "collapse_gerris_runs.csv"), "w") as f:
        f.write("level,cells_per_H0,eta_max,code,step_setting,run,wall_s,cpu_s,peak_MB,load,steps,"
                + ",".join("x_f_%d" % t for t in TIMES) + ",max_err,h_axis_4,volume_drift\n")
        for r in rows:
            f.write("%d,%g,%s,%s,%s,%d,%.3f,%.3f,%.1f,%.2f,%d,%s,%.4f,%.4f,%.2e\n" % (
                r["level"], 2 ** r["level"] / 5.0, r["cap"], r["code"], r["setting"], r["rep"] + 1,
                r["wall"], r["cpu"], r["mb"], r["load"], r["steps"],
                ",".join("%.4f" % x for x in r["x"]), r["err"], r["h4"], r["volume_drift"]))
    threads = os.environ.get("OMP_NUM_THREADS", "unset")
    lines = ["# Column collapse a = 0.5 to t = 4: muflow beside Gerris 1.3.2", "",
             "One sitting, one machine; Gerris serial (as it runs), muflow on "
             "OMP_NUM_THREADS = %s; %d repeat(s) per row, the order reversed every "
             "other repeat; medians.  Steps: Gerris's dtmax (its CFL 0.8 cuts it), "
             "muflow's overrides (cases/collapse.ini: solver.dt 0.01, solver.cfl and "
             "collapse.vof_cfl 0.4).  The ratio is the wall time of Gerris at dtmax "
             "%s (its example's) over the row's, per repeat (the median, and the "
             "range).  x_f error: the largest |x_f - reference| at t = 1..4 "
             "(reference: the Basilisk port, cases/data/lagree2011_collapse.csv)."
             % (threads, o.repeats, o.gerris_dts[0]), "",
             "| cells per H0 | eta clip | code | steps set | wall s | CPU s | steps | peak MB | "
             "x_f(1..4) | x_f error | h(0, 4) | volume drift | Gerris (%s) / row | load |"
             % o.gerris_dts[0],
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for level in o.levels:
        for cap in o.caps:
            for code, setting in runs:
                rs = [r for r in rows if r["level"] == level and r["cap"] == cap
                      and r["code"] == code and r["setting"] == setting]
                ratios = [r["ratio"] for r in rs]
                ratio = ("%.2f (%.2f-%.2f)" % (statistics.median(ratios), min(ratios),
                                                max(ratios))
                         if (code, setting) != ("gerris", o.gerris_dts[0]) else "")
                lines.append("| %g | %s | %s | %s | %.2f | %.2f | %d | %.0f | %s | %.3f | %.4f | "
                             "%.1e | %s | %.1f-%.1f |" % (
                                 2 ** level / 5.0, cap, code,
                                 ("dtmax = " if code == "gerris" else "") + setting,
                                 statistics.median(r["wall"] for r in rs),
                                 statistics.median(r["cpu"] for r in rs), rs[0]["steps"],
                                 max(r["mb"] for r in rs),
                                 ", ".join("%.3f" % x for x in rs[0]["x"]), rs[0]["err"],
                                 rs[0]["h4"], rs[0]["volume_drift"], ratio,
                                 min(r["load"] for r in rs), max(r["load"] for r in rs)))
    with open(os.path.join(outdir, "collapse_gerris.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
