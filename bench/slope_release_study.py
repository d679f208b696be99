#!/usr/bin/python3
"""The column released on a bent incline: three grids beside the
depth-averaged model.

usage: slope_release_study.py MUFLOW OUTDIR [N ...] [section.key=value ...] [--reuse]

Runs cases/slope_release.ini through the muflow command (the caller's
OMP_NUM_THREADS, 2 in `make bench-slope-release`) at N cells per column
height (default 8, 12, 16; square cells, the case's 0.15 x 0.06 m box) to
rest, and writes OUTDIR/slope_release_table.md (run-out: the s behind
which 99 % of the grains lie, and the T = 1/2 contour's tip; tail, time to
rest, volume error, never-yielded area, wall time and steps per grid, the
depth-averaged model's beside), slope_release_front.png (front and tail
along the bed against t, each grid and the depth-averaged model) and
slope_release_deposit.png (the deposits on the bed, the finest grid's and
the model's).  --reuse: a grid whose run folder already holds a summary.ini
is read, not run again."""
import csv
import math
import os
import subprocess
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from summary_ini import summary

HERE = os.path.dirname(os.path.abspath(__file__))
CASE = os.path.join(HERE, "..", "cases", "slope_release.ini")
H0 = 0.01  # the column's height, m


def columns(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def run(muflow, outdir, n, overrides, reuse):
    d = os.path.join(outdir, "slope_release_n%d" % n)
    cmd = [muflow, CASE, "domain.nx=%d" % (15 * n), "domain.nz=%d" % (6 * n),
           "domain.ly=%.17g" % (H0 / n), "output.quiet=on", "output.dir=" + d] + overrides
    if not (reuse and os.path.exists(os.path.join(d, "summary.ini"))):
        print(" ".join(cmd), flush=True)
        subprocess.run(cmd, check=True)
    s = summary(os.path.join(d, "summary.ini"))
    r = {"n": n, "dir": d, "steps": int(s["steps"]), "wall": float(s["wall_seconds"])}
    for k in ("run_out", "run_out_99", "da_run_out_99", "tail", "time_to_rest", "volume_error", "never_yielded_area",
              "da_run_out", "da_tail", "da_time_to_rest", "da_volume_error"):
        r[k] = float(s[k])
    r["rec"] = columns(os.path.join(d, "slope_release.csv"))
    return r


def table(runs, path):
    lines = ["| cells per H0 | run-out 99 % (m) | tip (m) | tail (m) | at rest (s) | "
             "volume error | never yielded (m^2) | steps | wall (s) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in runs:
        lines.append("| %d | %.5f | %.5f | %.5f | %.3f | %.1e | %.2e | %d | %.0f |" % (
            r["n"], r["run_out_99"], r["run_out"], r["tail"], r["time_to_rest"],
            r["volume_error"], r["never_yielded_area"], r["steps"], r["wall"]))
    a = runs[-1]
    lines.append("| depth-averaged | %.5f | %.5f | %.5f | %.3f | %.1e | | | |" % (
        a["da_run_out_99"], a["da_run_out"], a["da_tail"], a["da_time_to_rest"],
        a["da_volume_error"]))
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


def plot_front(runs, path):
    fig, ax = plt.subplots(figsize=(7, 4))
    for r in runs:
        c = r["rec"]
        line, = ax.plot(c["t"], c["s_front"], label="%d cells per H0" % r["n"])
        ax.plot(c["t"], c["s_tail"], color=line.get_color(), ls="--")
    c = runs[-1]["rec"]
    ax.plot(c["t"], c["s_front_99"], color=line.get_color(), ls=":",
            label="99 %% of the volume behind, %d cells per H0" % runs[-1]["n"])
    da = columns(os.path.join(runs[-1]["dir"], "depth_averaged.csv"))
    ax.plot(da["t"], da["s_front"], "k", label="depth-averaged")
    ax.plot(da["t"], da["s_tail"], "k--")
    ax.plot(da["t"], da["s_front_99"], "k:")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("front (solid), tail (dashed): s along the bed (m)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print("wrote", path)


def plot_deposit(runs, path):
    fig, ax = plt.subplots(figsize=(8, 3.2))
    r = runs[-1]
    dep = columns(os.path.join(r["dir"], "deposit.csv"))
    da = columns(os.path.join(r["dir"], "depth_averaged_deposit.csv"))
    ax.plot(da["x_bed"], da["z_bed"], "k", lw=1, label="bed")
    top = [z + h for z, h in zip(dep["z_bed"], dep["depth"])]
    ax.fill_between(dep["x"], dep["z_bed"], top, color="tan",
                    label="grains, %d cells per H0" % r["n"])
    ax.plot([x + h * nx for x, h, nx in zip(da["x_bed"], da["h"], da["nx"])],
            [z + h * nz for z, h, nz in zip(da["z_bed"], da["h"], da["nz"])],
            "b", lw=1, label="depth-averaged")
    ax.set_aspect("equal")
    ax.set_xlim(0, max(dep["x"]))
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print("wrote", path)


def main():
    muflow, outdir = sys.argv[1], sys.argv[2]
    args = sys.argv[3:]
    reuse = "--reuse" in args
    args = [a for a in args if a != "--reuse"]
    overrides = [a for a in args if "=" in a]
    ns = [int(a) for a in args if "=" not in a] or [8, 12, 16]
    os.makedirs(outdir, exist_ok=True)
    runs = [run(muflow, outdir, n, overrides, reuse) for n in ns]
    table(runs, os.path.join(outdir, "slope_release_table.md"))
    plot_front(runs, os.path.join(outdir, "slope_release_front.png"))
    plot_deposit(runs, os.path.join(outdir, "slope_release_deposit.png"))
    if any(not math.isfinite(r["time_to_rest"]) for r in runs):
        print("a grid did not come to rest by solver.end_time")


if __name__ == "__main__":
    main()
