#!/usr/bin/python3
"""The granular front fed by a uniform layer: three grids against the
depth-averaged travelling front (Pouliquen 1999) and Bagnold's profile.

usage: front_study.py MUFLOW OUTDIR [NZ ...] [section.key=value ...]

Runs cases/front.ini through the muflow command (the caller's
OMP_NUM_THREADS, 2 in `make bench-front`) at NZ cells over the box's height
(default 10 15 24; nx = 50 nz / 3, the case's cell shape), and writes
OUTDIR/front_table.md (front speed and its error against the uniform
layer's mean speed, h(x) rms and max error over the front's length, over
its body, over its nose by the depth and by the T = 1/2 contour, against
the depth-averaged front over the precursor (rms, body max, nose max; that
front's own nose against the closed form), the depth behind, the tip's
offset, the profile behind, the precursor's flux against its uniform
flow's, wall time, steps),
front_runs.csv and the plot front_compare.png: h(xi) in the front's frame
beside the closed form, x_half(t) and the error's history, the velocity
profile behind the front beside Bagnold's."""
import csv
import os
import subprocess
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from summary_ini import summary

HERE = os.path.dirname(os.path.abspath(__file__))
CASE = os.path.join(HERE, "..", "cases", "front.ini")
DEPTH = 1.43e-3  # front.depth, h_inf
KEYS = ["front_speed", "front_speed_exact", "front_speed_error", "uniform_speed",
        "front_speed_depth_averaged", "h_err_rms", "h_err_max", "h_columns", "h_err_rms_body",
        "h_err_max_body", "h_behind_error", "nose_offset", "profile_err_rms", "precursor_flux",
        "precursor_flux_exact", "h_err_max_nose", "h_err_rms_depth_averaged",
        "h_err_max_body_depth_averaged", "h_err_max_nose_depth_averaged",
        "depth_averaged_nose_err_max", "steps", "wall_seconds", "status"]
NOSE_SHARE = 0.25  # the nose: where the exact depth is below this share of h_inf (front.c)


def columns(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def run(muflow, outdir, nz, overrides):
    d = os.path.join(outdir, "front_nz%d" % nz)
    nx = (50 * nz) // 3
    cmd = [muflow, CASE, "domain.nx=%d" % nx, "domain.nz=%d" % nz,
           "domain.ly=%.17g" % (2.145e-3 / nz), "output.fields=off", "output.quiet=on",
           "output.dir=" + d] + overrides
    print(" ".join(cmd), flush=True)
    subprocess.run(cmd, check=True)
    s = summary(os.path.join(d, "summary.ini"))
    r = {k: s.get(k, "nan") for k in KEYS}
    r.update({"nz": nz, "nx": nx, "shape": columns(os.path.join(d, "shape.csv")),
              "record": columns(os.path.join(d, "front.csv")),
              "behind": columns(os.path.join(d, "behind.csv"))})
    return r


def nose_errors(shape, depth):
    """The largest |h - h_exact| and |h_contour - h_exact| over the nose (the
    exact depth below NOSE_SHARE h_inf, behind the exact tip), in h_inf: the
    integrated depth and the T = 1/2 contour, to tell the VOF's smearing
    from the shape."""
    rows = [i for i, xi in enumerate(shape["xi"])
            if xi <= 0 and shape["h_exact"][i] < NOSE_SHARE * depth]
    err = lambda k: max(abs(shape[k][i] - shape["h_exact"][i]) for i in rows) / depth
    return err("h"), err("h_contour")


def table(runs, path):
    with open(path, "w") as f:
        f.write("| grid | front speed (m/s) | error | h rms / max | body rms / max | nose max: "
                "h / contour | model: rms / body / nose | depth behind | tip (h_inf) | "
                "profile rms | precursor flux / exact | steps | wall (s) |\n")
        f.write("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
        for r in runs:
            pc = lambda k: 100 * float(r[k])
            nose_h, nose_c = nose_errors(r["shape"], DEPTH)
            f.write("| %d x %d | %.5f | %+.2f %% | %.2f / %.2f %% | %.2f / %.2f %% | %.1f / %.1f %% "
                    "| %.2f / %.1f / %.1f %% | %+.2f %% | %+.2f | %.2f %% | %.2f | %s | %.0f |\n" % (
                        r["nx"], r["nz"], float(r["front_speed"]), pc("front_speed_error"),
                        pc("h_err_rms"), pc("h_err_max"), pc("h_err_rms_body"),
                        pc("h_err_max_body"), 100 * nose_h, 100 * nose_c,
                        pc("h_err_rms_depth_averaged"), pc("h_err_max_body_depth_averaged"),
                        pc("h_err_max_nose_depth_averaged"), pc("h_behind_error"),
                        float(r["nose_offset"]), pc("profile_err_rms"),
                        float(r["precursor_flux"]) / float(r["precursor_flux_exact"]),
                        r["steps"], float(r["wall_seconds"])))
        r = runs[0]
        f.write("\nfront speed by mass conservation %.6f m/s; the uniform layer's mean %.6f m/s; "
                "the depth-averaged front's u_f %.6f m/s; the depth-averaged front over the "
                "precursor against the closed form over the nose %.2f %% of h_inf\n"
                % (float(r["front_speed_exact"]), float(r["uniform_speed"]),
                   float(r["front_speed_depth_averaged"]),
                   100 * float(r["depth_averaged_nose_err_max"])))


def plot(runs, path, depth):
    fig, ax = plt.subplots(1, 3, figsize=(14, 4))
    for r in runs:
        s = r["shape"]
        xi = [x / depth for x in s["xi"]]
        ax[0].plot(xi, [h / depth for h in s["h"]], label="%d x %d" % (r["nx"], r["nz"]))
        rec = r["record"]
        ax[1].plot(rec["t"], [100 * e for e in rec["h_err_rms"]],
                   label="%d x %d" % (r["nx"], r["nz"]))
        b = r["behind"]
        ax[2].plot(b["u"], [z / depth for z in b["z"]], "o-", ms=3,
                   label="%d x %d" % (r["nx"], r["nz"]))
    s = runs[-1]["shape"]
    ax[0].plot([x / depth for x in s["xi"]], [h / depth for h in s["h_exact"]], "k--",
               label="Pouliquen (1999)")
    ax[0].plot([x / depth for x in s["xi"]], [h / depth for h in s["h_depth_averaged"]], "k:",
               label="depth-averaged, over the precursor")
    ax[0].set_xlim(-60, 5)
    ax[0].set_xlabel("(x - x_tip) / h_inf, exact tip")
    ax[0].set_ylabel("h / h_inf")
    ax[0].legend()
    ax[1].set_xlabel("t (s)")
    ax[1].set_ylabel("h rms error over the front (% of h_inf)")
    ax[1].legend()
    b = runs[-1]["behind"]
    ax[2].plot(b["u_exact"], [z / depth for z in b["z"]], "k--", label="Bagnold + air")
    ax[2].set_xlabel("u behind the front (m/s)")
    ax[2].set_ylabel("z / h_inf")
    ax[2].legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    muflow, outdir = sys.argv[1], sys.argv[2]
    args = sys.argv[3:]
    overrides = [a for a in args if "=" in a]
    nzs = [int(a) for a in args if "=" not in a] or [10, 15, 24]
    os.makedirs(outdir, exist_ok=True)
    runs = [run(muflow, outdir, nz, overrides) for nz in nzs]
    table(runs, os.path.join(outdir, "front_table.md"))
    with open(os.path.join(outdir, "front_runs.csv"), "w") as f:
        f.write("nx,nz," + ",".join(KEYS) + "\n")
        for r in runs:
            f.write("%d,%d,%s\n" % (r["nx"], r["nz"], ",".join(str(r[k]) for k in KEYS)))
    plot(runs, os.path.join(outdir, "front_compare.png"), DEPTH)
    with open(os.path.join(outdir, "front_table.md")) as f:
        print(f.read())


if __name__ == "__main__":
    main()
