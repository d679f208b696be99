#!/usr/bin/python3
"""The shock from a wall: three grids against the jump conditions of the
depth-averaged equations (with u2 = 0 and with the measured creep u2) and
against those equations' own solution, and that solution's grid
convergence.

usage: wall_shock_study.py MUFLOW OUTDIR [NX ...] [section.key=value ...]

Runs cases/wall_shock.ini through the muflow command (the caller's
OMP_NUM_THREADS, 2 in `make bench-wall-shock`) with NX cells along the box
(default 40 80 160; nz = 3 nx / 4, the case's cell shape), then the
coarsest grid with wall_shock.da_cells = 5, 10, 40, 80 (20: the case's; the
depth-averaged solution's convergence), and writes OUTDIR/wall_shock_table.md
(docs/validation/wall_shock.md's table, the 2D speed's Richardson estimate
and the depth-averaged solution's convergence) and wall_shock_runs.csv."""
import math
import os
import subprocess
import sys

from summary_ini import summary

HERE = os.path.dirname(os.path.abspath(__file__))
CASE = os.path.join(HERE, "..", "cases", "wall_shock.ini")
DEPTH_CELLS = 30 / 40  # nz / nx of the grid study: 5, 10, 20 cells per h1 at 40, 80, 160
BOX_DEPTHS = 6  # domain.lz / wall_shock.depth
KEYS = ["depth_ratio", "depth_ratio_exact", "depth_ratio_error", "shock_speed",
        "shock_speed_exact", "shock_speed_error", "depth_ratio_u2_exact", "depth_ratio_u2_error",
        "shock_speed_u2_exact", "shock_speed_u2_error", "shock_speed_mass_error",
        "shock_speed_depth_averaged", "shock_speed_depth_averaged_error",
        "depth_ratio_depth_averaged", "depth_ratio_depth_averaged_error", "u2_over_u1",
        "u2_over_u1_depth_averaged", "speed_depth_averaged_jump_u2_error",
        "ratio_depth_averaged_jump_u2_error", "froude", "steps", "wall_seconds"]


def run(muflow, outdir, nx, tag, overrides):
    d = os.path.join(outdir, "wall_shock_%s" % tag)
    cmd = [muflow, CASE, "domain.nx=%d" % nx, "domain.nz=%d" % round(DEPTH_CELLS * nx),
           "output.fields=off", "output.quiet=on", "output.dir=" + d] + overrides
    print(" ".join(cmd), flush=True)
    subprocess.run(cmd, check=True)
    s = summary(os.path.join(d, "summary.ini"))
    r = {k: float(s.get(k, "nan")) for k in KEYS}
    r.update({"nx": nx, "nz": round(DEPTH_CELLS * nx)})
    return r


def richardson(a, b, c):
    """Order and limit of three values on grids refined by 2 each."""
    ratio = (b - a) / (c - b)
    if ratio <= 1.0:
        return float("nan"), float("nan")
    return math.log2(ratio), c + (c - b) / (ratio - 1.0)


def table(runs, da_runs, path):
    pc = lambda r, k: 100 * r[k]
    with open(path, "w") as f:
        f.write("| grid (cells / h1) | h2/h1 (u2 = 0), error | speed m/s (u2 = 0), error | creep: "
                "h2/h1, speed, errors | vs depth-averaged: speed, h2/h1 | u2/u1 |\n")
        f.write("|---|---|---|---|---|---|\n")
        for r in runs:
            f.write("| %d x %d (%d) | %.3f (%.3f), %+.2f %% | %.4f (%.4f), %+.1f %% | %.3f, %.4f: "
                    "%+.1f, %+.1f %% | %+.1f, %+.1f %% | %.3f |\n" % (
                        r["nx"], r["nz"], round(r["nz"] / BOX_DEPTHS), r["depth_ratio"],
                        r["depth_ratio_exact"], pc(r, "depth_ratio_error"), r["shock_speed"],
                        r["shock_speed_exact"], pc(r, "shock_speed_error"),
                        r["depth_ratio_u2_exact"], r["shock_speed_u2_exact"],
                        pc(r, "depth_ratio_u2_error"), pc(r, "shock_speed_u2_error"),
                        pc(r, "shock_speed_depth_averaged_error"),
                        pc(r, "depth_ratio_depth_averaged_error"), r["u2_over_u1"]))
        if len(runs) == 3:
            for k, ref in (("shock_speed", "shock_speed_u2_exact"),
                           ("depth_ratio", "depth_ratio_u2_exact")):
                p, lim = richardson(*[r[k] for r in runs])
                f.write("\n%s: order %.2f, Richardson's limit %.5g, %+.1f %% of the finest grid's "
                        "jumps with u2, %+.1f %% of the depth-averaged solution\n" % (
                            k, p, lim, 100 * (lim / runs[-1][ref] - 1),
                            100 * (lim / runs[-1][k + "_depth_averaged"] - 1)))
        f.write("\n| depth-averaged cells / h1 | speed m/s | h2/h1 | u2/u1 | against its jumps "
                "with u2: speed, ratio |\n|---|---|---|---|---|\n")
        for n, r in da_runs:
            f.write("| %d | %.5f | %.4f | %.3f | %+.2f, %+.2f %% |\n" % (
                n, r["shock_speed_depth_averaged"], r["depth_ratio_depth_averaged"],
                r["u2_over_u1_depth_averaged"], pc(r, "speed_depth_averaged_jump_u2_error"),
                pc(r, "ratio_depth_averaged_jump_u2_error")))


def main():
    muflow, outdir = sys.argv[1], sys.argv[2]
    args = sys.argv[3:]
    overrides = [a for a in args if "=" in a]
    nxs = [int(a) for a in args if "=" not in a] or [40, 80, 160]
    os.makedirs(outdir, exist_ok=True)
    runs = [run(muflow, outdir, nx, "nx%d" % nx, overrides) for nx in nxs]
    # the case's da_cells = 20 is the coarsest grid's run
    da_runs = [(n, runs[0] if n == 20 else
                run(muflow, outdir, nxs[0], "da%d" % n, overrides + ["wall_shock.da_cells=%d" % n]))
               for n in (5, 10, 20, 40, 80)]
    table(runs, da_runs, os.path.join(outdir, "wall_shock_table.md"))
    with open(os.path.join(outdir, "wall_shock_runs.csv"), "w") as f:
        f.write("nx,nz," + ",".join(KEYS) + "\n")
        for r in runs:
            f.write("%d,%d,%s\n" % (r["nx"], r["nz"], ",".join(repr(r[k]) for k in KEYS)))
    with open(os.path.join(outdir, "wall_shock_table.md")) as f:
        print(f.read())


if __name__ == "__main__":
    main()
