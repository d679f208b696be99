#!/usr/bin/python3
"""The ill-posedness of mu(I) as a measured growth rate (bagnold2).

usage: illposed_study.py MUFLOW OUTDIR [NAME ...]

Runs cases/bagnold2.ini in time from the exact steady solution plus a
divergence-free perturbation of 1e-3 of the top velocity
(bagnold2.start = exact, bagnold2.perturbation = 1e-3) for the cases of
Barker & Rauter (2018), sec. 3.1-3.2 and writes OUTDIR/illposed_table.md (growth rate of
the velocity and pressure amplitudes over the scene's window, per case,
grid and time step), illposed_runs.csv and illposed_growth.png (ln A(t)).
A run whose summary.ini exists in its folder is not run again; NAME ...
selects runs by name (all without).  The caller's OMP_NUM_THREADS (2 in
`make bench-illposed`)."""
import csv
import math
import os
import subprocess
import sys
import time

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from summary_ini import summary

HERE = os.path.dirname(os.path.abspath(__file__))
CASE = os.path.join(HERE, "..", "cases", "bagnold2.ini")

DEG = math.pi / 180.0
TABLE1_32 = ["physics.tilt=%.17g" % (32 * DEG)]
TABLE2 = ["physics.tilt=%.17g" % (28.5 * DEG), "rheology.mu_s=0.342",
          "rheology.delta_mu=0.215", "rheology.i0=0.069", "rheology.grain_diameter=1.43e-4"]
BG = ["rheology.curve=barker_gray", "rheology.alpha=1.9", "rheology.mu_inf=0.05"]

# name, label, overrides, nx, nz, dt, end time
RUNS = [
    ("t1j32_25_dt2e-4", "Table 1, 32 deg, jop", TABLE1_32, 25, 50, 2e-4, 0.04),
    ("t1j32_25_dt1e-4", "Table 1, 32 deg, jop", TABLE1_32, 25, 50, 1e-4, 0.04),
    ("t1j32_25_dt5e-5", "Table 1, 32 deg, jop", TABLE1_32, 25, 50, 5e-5, 0.04),
    ("t1j32_25", "Table 1, 32 deg, jop", TABLE1_32, 25, 50, 2.5e-5, 0.04),
    ("t1j32_25_dt1.25e-5", "Table 1, 32 deg, jop", TABLE1_32, 25, 50, 1.25e-5, 0.04),
    ("t1j32_25_lambda1e-8", "Table 1, 32 deg, jop, lambda 1e-8", TABLE1_32 +
     ["rheology.lambda=1e-8"], 25, 50, 2.5e-5, 0.04),
    ("t1j32_50_dt1e-4", "Table 1, 32 deg, jop", TABLE1_32, 50, 100, 1e-4, 0.04),
    ("t1j32_50_dt5e-5", "Table 1, 32 deg, jop", TABLE1_32, 50, 100, 5e-5, 0.04),
    ("t1j32_50", "Table 1, 32 deg, jop", TABLE1_32, 50, 100, 2.5e-5, 0.04),
    ("t2j_25", "Table 2, 28.5 deg, jop", TABLE2, 25, 50, 2.5e-5, 0.04),
    ("t2bg_25", "Table 2, 28.5 deg, barker_gray", TABLE2 + BG, 25, 50, 2.5e-5, 0.04),
    ("t2j_50", "Table 2, 28.5 deg, jop", TABLE2, 50, 100, 2.5e-5, 0.04),
    ("t2bg_50", "Table 2, 28.5 deg, barker_gray", TABLE2 + BG, 50, 100, 2.5e-5, 0.04),
    ("t2j_100_dt5e-5", "Table 2, 28.5 deg, jop", TABLE2, 100, 200, 5e-5, 0.025),
    ("t2bg_100_dt5e-5", "Table 2, 28.5 deg, barker_gray", TABLE2 + BG, 100, 200, 5e-5, 0.025),
    ("t1j32_100_dt5e-5", "Table 1, 32 deg, jop", TABLE1_32, 100, 200, 5e-5, 0.025),
    ("t1j32_100", "Table 1, 32 deg, jop", TABLE1_32, 100, 200, 2.5e-5, 0.015),
]


def run(muflow, outdir, r):
    name, label, ov, nx, nz, dt, end = r
    d = os.path.join(outdir, name)
    s = os.path.join(d, "summary.ini")
    if not os.path.exists(s):
        cmd = [muflow, CASE, "solver.mode=transient", "bagnold2.start=exact",
               "bagnold2.perturbation=1e-3", "output.fields=off", "output.quiet=on",
               "domain.nx=%d" % nx, "domain.nz=%d" % nz, "solver.dt=%g" % dt,
               "solver.end_time=%g" % end, "solver.max_steps=1000000",
               "output.dir=" + d] + ov
        t = time.time()
        subprocess.run(cmd, check=True)
        print("%s: %.1f s" % (name, time.time() - t), flush=True)
    res = summary(s)
    with open(os.path.join(d, "growth.csv")) as f:
        rows = list(csv.DictReader(f))
    return res, rows


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    muflow, outdir = sys.argv[1], sys.argv[2]
    wanted = set(sys.argv[3:])
    os.makedirs(outdir, exist_ok=True)
    out = []
    for r in RUNS:
        if wanted and r[0] not in wanted:
            continue
        res, rows = run(muflow, outdir, r)
        out.append((r, res, rows))
    lines = ["| case | grid | dt (s) | window (s) | growth_rate (1/s) | of the pressure (1/s) | "
             "r^2 | A(0) / u_top | A(end) / u_top | steps | wall (s) |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    with open(os.path.join(outdir, "illposed_runs.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["name", "case", "nx", "nz", "dt", "window_start", "window_end",
                    "growth_rate", "growth_rate_pressure", "r2", "u_top", "amplitude_start",
                    "amplitude_end", "steps", "wall_seconds"])
        for r, res, rows in out:
            name, label, ov, nx, nz, dt, end = r
            win = res["growth_window"].split()
            top = float(res["u_top_exact"])
            w.writerow([name, label, nx, nz, "%g" % dt, win[0], win[1], res["growth_rate"],
                        res["growth_rate_pressure"], res["growth_fit_r2"], res["u_top_exact"],
                        res["amplitude_start"], res["amplitude_end"], res["steps"],
                        res["wall_seconds"]])
            lines.append("| %s | %d x %d | %g | %.4g-%.4g | %.1f | %.1f | %.4f | %.2e | %.2e | %s | %.0f |" % (
                label, nx, nz, dt, float(win[0]), float(win[1]), float(res["growth_rate"]),
                float(res["growth_rate_pressure"]), float(res["growth_fit_r2"]),
                float(res["amplitude_start"]) / top, float(res["amplitude_end"]) / top,
                res["steps"], float(res["wall_seconds"])))
    with open(os.path.join(outdir, "illposed_table.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    fig, ax = plt.subplots(figsize=(8, 5))
    colours = plt.get_cmap("tab20")
    for m, (r, res, rows) in enumerate(out):
        top = float(res["u_top_exact"])
        ax.semilogy([float(x["t"]) for x in rows],
                    [float(x["amplitude_velocity"]) / top for x in rows],
                    label="%s, %d x %d, dt %g" % (r[1], r[3], r[4], r[5]),
                    color=colours(m % 20), linestyle="-" if "jop" in r[1] else "--")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("A(t) / u_top (velocity)")
    ax.legend(fontsize=6)
    fig.savefig(os.path.join(outdir, "illposed_growth.png"), dpi=120)


if __name__ == "__main__":
    main()
