#!/usr/bin/python3
"""Schaefer & Turek (1996) 2D-1 grid study: steady flow past a cylinder, Re 20.

usage: cylinder_study.py MUFLOW OUTDIR [--grids 10,20,40] [--reuse]
                         [--from-previous] [--plot]

Runs cases/cylinder_benchmark.ini through the muflow command (the caller's
OMP_NUM_THREADS) with D / h = each of --grids cells across the cylinder
(h = 0.1 / N: 22 N x 4.1 N cells) into OUTDIR/cylinder_runs/DN (--reuse: a
grid whose summary.ini says steady is not run again), with the settings the
study measured fastest: the transient march to the steady state
(solver.steady_tolerance 1e-6; the forces then agree with 1e-8 to 9 digits
on D/10), dt 0.02 capped by solver.cfl = 2 (explicit advection with the
implicit viscous step is stable below about 2 nu / u^2 = 0.01-0.02 whatever
the grid), the probed Cholesky factorisation reused for every step (the
operator of a Newtonian fluid at a fixed dt does not change).
--from-previous starts each grid after the first from the previous grid's
steady state (solver.initial_state, interpolated): D/60 from D/40 took
t = 24 instead of the t = 36 of D/40 from rest.

Writes OUTDIR/cylinder_table.md: per grid the cells, steps, wall seconds,
C_D from the surface integral (the discrete surface's fluxes), from the
control volume and from the reconstructed traction, C_L, the
pressure difference, their errors against the reference (C_D 5.5795, C_L
0.0106, Delta p 0.1175), the observed order of each error between
successive grids, and the order of convergence from the three finest
grids' differences (Richardson: log2 of the ratio of successive
differences); --plot also cylinder_surface.png (p and the wall shear stress
against the angle on every grid)."""
import argparse
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from summary_ini import summary  # noqa: E402

CASE = "cases/cylinder_benchmark.ini"
REF = {"drag_coefficient": 5.5795, "drag_coefficient_control_volume": 5.5795,
       "drag_coefficient_reconstructed": 5.5795,
       "lift_coefficient": 0.0106, "pressure_drop": 0.1175}
NAMES = {"drag_coefficient": "C_D surface", "drag_coefficient_control_volume": "C_D control volume",
         "drag_coefficient_reconstructed": "C_D reconstructed",
         "lift_coefficient": "C_L", "pressure_drop": "Delta p"}


def run(muflow, outdir, n, reuse, start=None):
    d = os.path.join(outdir, "cylinder_runs", f"D{n}")
    sp = os.path.join(d, "summary.ini")
    if not (reuse and os.path.exists(sp) and summary(sp).get("status") == "steady"):
        args = [muflow, CASE, f"domain.nx={22 * n}", f"domain.nz={41 * n // 10}",
                f"output.dir={d}", "solver.steady_tolerance=1e-6", "solver.cfl=2",
                "solver.dt=0.02", "solver.preconditioner=cholesky",
                "solver.preconditioner_reuse=1000000", "solver.progress_interval=60"]
        if start:
            args.append(f"solver.initial_state={os.path.join(start, 'checkpoint.h5')}")
        print(" ".join(args), flush=True)
        p = subprocess.run(args)
        if p.returncode != 0:
            sys.exit(f"muflow failed on D/{n} (exit {p.returncode})")
    return summary(sp), d


def order(e1, e2, r):
    """The order of errors e1 -> e2 on grids refined by the ratio r."""
    return math.log(abs(e1) / abs(e2)) / math.log(r) if e1 and e2 and e1 * e2 > 0 else float("nan")


def order3(v, n):
    """The order p of v = v* + C h^p through three grids n (cells per D):
    (v0 - v1) / (v1 - v2) = (h0^p - h1^p) / (h1^p - h2^p), by bisection."""
    d1, d2 = v[0] - v[1], v[1] - v[2]
    if not d1 or not d2 or d1 * d2 < 0:
        return float("nan")
    h = [1.0 / x for x in n]

    def g(p):
        return (h[0] ** p - h[1] ** p) / (h[1] ** p - h[2] ** p) - d1 / d2
    lo, hi = 0.05, 8.0
    if g(lo) * g(hi) > 0:
        return float("nan")
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if g(lo) * g(mid) <= 0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("muflow")
    ap.add_argument("outdir")
    ap.add_argument("--grids", default="10,20,40")
    ap.add_argument("--reuse", action="store_true")
    ap.add_argument("--plot", action="store_true")
    ap.add_argument("--from-previous", action="store_true")
    a = ap.parse_args()
    grids = [int(x) for x in a.grids.split(",")]
    if any(41 * n % 10 for n in grids):
        sys.exit("each grid's D / h must make 4.1 D / h cells across the channel whole")
    rows, dirs = [], []
    for n in grids:
        s, d = run(a.muflow, a.outdir, n, a.reuse,
                   dirs[-1] if a.from_previous and dirs else None)
        rows.append(s)
        dirs.append(d)
    out = ["| D/h | cells | steps | wall s | " + " | ".join(
        f"{NAMES[k]} | error" for k in REF) + " |",
        "|---|---|---|---|" + "---|---|" * len(REF)]
    for n, s in zip(grids, rows):
        cells = 22 * n * (41 * n // 10)
        cols = []
        for k, r in REF.items():
            if k not in s:  # a summary from before the key
                cols.append("- | -")
                continue
            v = float(s[k])
            cols.append(f"{v:.5g} | {100 * (v - r) / r:+.2f} %")
        out.append(f"| {n} | {22 * n} x {41 * n // 10} = {cells} | {s['steps']} | "
                   f"{float(s['wall_seconds']):.0f} | " + " | ".join(cols) + " |")
    out.append("")
    out.append("Observed order of the error against the reference between successive grids, "
               "and (three grids) from the differences of the values:")
    out.append("")
    out.append("| quantity | " + " | ".join(f"{grids[i]}->{grids[i + 1]}"
                                            for i in range(len(grids) - 1)) + " | differences |")
    out.append("|---|" + "---|" * len(grids))
    for k, r in REF.items():
        if any(k not in s for s in rows):
            continue
        v = [float(s[k]) for s in rows]
        e = [x - r for x in v]
        o = [order(e[i], e[i + 1], grids[i + 1] / grids[i]) for i in range(len(e) - 1)]
        rich = order3(v[-3:], grids[-3:]) if len(v) >= 3 else float("nan")
        out.append(f"| {NAMES[k]} | " + " | ".join(f"{x:.2f}" for x in o) + f" | {rich:.2f} |")
    table = "\n".join(out) + "\n"
    with open(os.path.join(a.outdir, "cylinder_table.md"), "w") as f:
        f.write(table)
    print(table)
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        import numpy as np
        fig, ax = plt.subplots(2, 1, figsize=(7, 7), sharex=True)
        for n, d in zip(grids, dirs):
            c = np.genfromtxt(os.path.join(d, "obstacle_surface.csv"), delimiter=",", names=True)
            ax[0].plot(c["angle_deg"], c["pressure"], label=f"D/{n}")
            ax[1].plot(c["angle_deg"], c["tangential_stress"], label=f"D/{n}")
        ax[0].set_ylabel("p on the surface")
        ax[1].set_ylabel("wall shear stress")
        ax[1].set_xlabel("angle from the downstream axis (degrees)")
        ax[0].legend()
        fig.savefig(os.path.join(a.outdir, "cylinder_surface.png"), dpi=120)


if __name__ == "__main__":
    main()
