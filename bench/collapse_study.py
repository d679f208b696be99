#!/usr/bin/python3
"""Column collapse study: a = 0.5 to t = 4 at three resolutions.

usage: collapse_study.py MUFLOW OUTDIR [N ...] [section.key=value ...] [--tag NAME]

Runs cases/collapse.ini through the muflow command (the caller's
OMP_NUM_THREADS, 2 in `make bench-collapse`) at N cells per H0 (default 16,
32, 64; square cells, the case's 5 x 1.5 domain), to t = 4 without the rest
criterion, and writes OUTDIR/collapse_table.md (x_f(t) and h(0,t) against
the Basilisk reference at t = 0..4, the grid convergence of x_f(4), wall
time, steps, cell-steps per second), collapse_runs.csv and the plot
collapse_front.png; with --tag NAME, collapse_table_NAME.md and so on, and
the overrides (section.key=value) go to every run."""
import math
import os
import subprocess
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from collapse_series import at, reference, series
from summary_ini import summary

HERE = os.path.dirname(os.path.abspath(__file__))
CASE = os.path.join(HERE, "..", "cases", "collapse.ini")
TIMES = [0, 1, 2, 3, 4]


def run(muflow, outdir, n, overrides, tag):
    d = os.path.join(outdir, "collapse%s_n%d" % ("_" + tag if tag else "", n))
    nx, nz = 5 * n, (3 * n) // 2
    cmd = [muflow, CASE, "domain.nx=%d" % nx, "domain.nz=%d" % nz,
           "domain.ly=%.17g" % (1.0 / n), "collapse.rest_energy=0", "output.fields=off",
           "output.quiet=on", "output.dir=" + d] + overrides
    print(" ".join(cmd), flush=True)
    subprocess.run(cmd, check=True)
    s = summary(os.path.join(d, "summary.ini"))
    ts, xf, h0 = series(os.path.join(d, "collapse.csv"))
    return {"n": n, "cells": nx * nz, "steps": int(s["steps"]),
            "wall": float(s["wall_seconds"]), "mass_error": float(s["mass_error"]),
            "tracer_min": float(s["tracer_min"]), "tracer_over": float(s["tracer_max_minus_1"]),
            "status": s["status"], "ts": ts, "xf": xf, "h0": h0}


def main():
    muflow, outdir = sys.argv[1], sys.argv[2]
    args = sys.argv[3:]
    tag = ""
    if "--tag" in args:
        i = args.index("--tag")
        tag = args[i + 1]
        del args[i:i + 2]
    overrides = [a for a in args if "=" in a]
    ns = [int(a) for a in args if "=" not in a] or [16, 32, 64]
    suffix = "_" + tag if tag else ""
    os.makedirs(outdir, exist_ok=True)
    ref = reference()
    runs = [run(muflow, outdir, n, overrides, tag) for n in ns]
    lines = ["# Column collapse, a = 0.5, to t = 4 (units H0, sqrt(H0/g))", "",
             "cases/collapse.ini at N cells per H0%s; reference: Basilisk (Lagree et al. 2011 "
             "set-up), cases/data/lagree2011_collapse.csv." % (
                 (", overrides " + " ".join(overrides)) if overrides else ""), "",
             "## Front x_f(t)", "",
             "| t | reference | " + " | ".join("N = %d" % r["n"] for r in runs) + " |",
             "|---|---|" + "---|" * len(runs)]
    for t in TIMES:
        vals = [at(r["ts"], r["xf"], t) for r in runs]
        lines.append("| %g | %.3f | " % (t, ref["x_front"][t]) +
                     " | ".join("%.3f (%+.3f)" % (v, v - ref["x_front"][t]) for v in vals) + " |")
    lines += ["", "## Height on the axis h(0, t)", "",
              "| t | reference | " + " | ".join("N = %d" % r["n"] for r in runs) + " |",
              "|---|---|" + "---|" * len(runs)]
    for t in TIMES:
        vals = [at(r["ts"], r["h0"], t) for r in runs]
        lines.append("| %g | %.4f | " % (t, ref["h_axis"][t]) +
                     " | ".join("%.4f (%+.4f)" % (v, v - ref["h_axis"][t]) for v in vals) + " |")
    x4 = [at(r["ts"], r["xf"], 4.0) for r in runs]
    lines += ["", "## Grid convergence of x_f(4)", ""]
    lines.append("x_f(4): " + ", ".join("%.4f (N = %d)" % (x, r["n"]) for x, r in zip(x4, runs)))
    if len(runs) >= 3:
        d1, d2 = x4[1] - x4[0], x4[2] - x4[1]
        lines.append("")
        lines.append("differences %+.4f, %+.4f" % (d1, d2))
        if d1 * d2 > 0 and abs(d2) < abs(d1):
            p = math.log(abs(d1 / d2)) / math.log(ns[1] / ns[0])
            rich = x4[2] + d2 / ((ns[2] / ns[1]) ** p - 1.0)
            lines.append("; observed order %.2f, Richardson extrapolation %.4f "
                         "(reference %.3f)" % (p, rich, ref["x_front"][4]))
        else:
            lines.append("; not monotone or not contracting: no observed order")
    lines += ["", "## Cost (to t = 4)", "",
              "| N | grid | steps | wall s | cell-steps/s | mass error | T min | T max - 1 |",
              "|---|---|---|---|---|---|---|---|"]
    for r in runs:
        lines.append("| %d | %d x %d | %d | %.2f | %.3g | %.1e | %.1e | %.1e |" % (
            r["n"], 5 * r["n"], (3 * r["n"]) // 2, r["steps"], r["wall"],
            r["cells"] * r["steps"] / r["wall"], r["mass_error"], r["tracer_min"],
            r["tracer_over"]))
    lines.append("")
    lines.append("Threads: OMP_NUM_THREADS = %s." % os.environ.get("OMP_NUM_THREADS", "unset"))
    with open(os.path.join(outdir, "collapse_table%s.md" % suffix), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(outdir, "collapse_runs%s.csv" % suffix), "w") as f:
        f.write("n,t,x_front,h_axis\n")
        for r in runs:
            for t in TIMES:
                f.write("%d,%g,%.6f,%.6f\n" % (r["n"], t, at(r["ts"], r["xf"], t),
                                               at(r["ts"], r["h0"], t)))
    plt.figure(figsize=(6, 4))
    for r in runs:
        plt.plot(r["ts"], r["xf"], label="muflow N = %d" % r["n"])
    plt.plot(TIMES, [ref["x_front"][t] for t in TIMES], "ko", label="Basilisk reference")
    plt.xlabel("t / sqrt(H0/g)")
    plt.ylabel("x_f / H0")
    plt.legend()
    plt.tight_layout()
    plt.savefig(os.path.join(outdir, "collapse_front%s.png" % suffix), dpi=120)
    print("\n".join(lines))


if __name__ == "__main__":
    main()
