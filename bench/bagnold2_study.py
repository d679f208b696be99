#!/usr/bin/python3
"""The granular layer under air (bagnold2) against its exact solution.

usage: bagnold2_study.py MUFLOW OUTDIR [section.key=value ...]

Runs cases/bagnold2.ini through the muflow command (the caller's
OMP_NUM_THREADS, 2 in `make bench`), steady from rest with the interface
held flat, on 25 x 50, 50 x 100 and 100 x 200 cells, for each mixture law
(weighted, harmonic); the interface at 0, 0.1, 0.3, 0.5, 0.7 and 0.9 of a
cell above a face on 45 x 90 at 22 and 28 degrees; then the transient from rest to t = 10 s on
50 x 100 (steps of 1e-2 s), the paper's run, and from rest to the steady
mode's criterion (solver.steady_tolerance).  Writes OUTDIR/bagnold2_runs.csv, bagnold2_table.md
(errors in the grains and in the air, observed orders, mass error, steps,
wall time; the transient's time to the steady state) and
bagnold2_profile.png (u(z) and u - u_exact on 50 x 100)."""
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
CASE = os.path.join(HERE, "..", "cases", "bagnold2.ini")
GRIDS = [(25, 50), (50, 100), (100, 200)]
VARIANTS = [("series", "weighted"), ("series", "harmonic")]
# the interface inside a cell: 45 x 90 cells (1e-5 m), h0 = (40 + s) 1e-5 m
POSITIONS = [0.0, 0.1, 0.3, 0.5, 0.7, 0.9]
TILTS = [22.0, 28.0]
TRANSIENT_DT = 1e-2
TRANSIENT_END = 10.0
# the transient is at its steady state from the first step after which its
# err_rms stays within this share of the top velocity of its final value
STEADY_BAND = 1e-5
# the transient from rest to a steady state: steps and criterion
STEADY_DT = 2e-3
STEADY_TOL = 1e-6


def run(muflow, outdir, name, args):
    d = os.path.join(outdir, name)
    cmd = [muflow, CASE, "output.fields=off", "output.quiet=on", "output.dir=" + d] + args
    print(" ".join(cmd), flush=True)
    # exit 3: no steady state (the table says so); anything else stops the study
    rc = subprocess.run(cmd).returncode
    if rc not in (0, 3):
        raise SystemExit("%s: exit %d" % (" ".join(cmd), rc))
    return d, summary(os.path.join(d, "summary.ini"))


def positions(muflow, outdir, overrides):
    """The table of the errors with the interface at s of a cell above a face."""
    md = ["The interface s of a cell above face 40 of 45 x 90 (h0 = (40 + s) 1e-5 m): "
          "err_rms in m/s, the air's also as a share of u_top.", "",
          "| tilt | mixture | s | grains err_rms | air err_rms | air / u_top | steps |",
          "|---|---|---|---|---|---|---|"]
    for tilt in TILTS:
        for law in ("weighted", "harmonic"):
            for s in POSITIONS:
                name = "bagnold2_at_%g_%s_%g" % (tilt, law, s)
                _, r = run(muflow, outdir, name, [
                    "domain.nx=45", "domain.nz=90", "physics.tilt=%.17g" % math.radians(tilt),
                    "bagnold2.interface_height=%.17g" % ((40.0 + s) * 1e-5),
                    "bagnold2.mixture=" + law] + overrides)
                air = float(r["err_rms_air"])
                md.append("| %g | %s | %g | %.3e | %.3e | %.4f%% | %s |" % (
                    tilt, law, s, float(r["err_rms_grains"]), air,
                    100.0 * air / float(r["u_top_exact"]), r["steps"]))
    return md + [""]


def profile(d):
    with open(os.path.join(d, "profile.csv")) as f:
        rows = list(csv.DictReader(f))
    return ([float(r["z"]) for r in rows], [float(r["u"]) for r in rows],
            [float(r["u_exact"]) for r in rows])


def order(e1, e2):
    return "%.2f" % (math.log(e1 / e2) / math.log(2.0)) if e1 > 0 and e2 > 0 else "–"


def main():
    muflow, outdir = sys.argv[1], sys.argv[2]
    overrides = sys.argv[3:]
    os.makedirs(outdir, exist_ok=True)
    runs, dirs = [], {}
    for edges, law in VARIANTS:
        for nx, nz in GRIDS:
            name = "bagnold2_%s_%s_%dx%d" % (edges, law, nx, nz)
            d, s = run(muflow, outdir, name, ["domain.nx=%d" % nx, "domain.nz=%d" % nz,
                                               "bagnold2.interface_edges=" + edges,
                                               "bagnold2.mixture=" + law] + overrides)
            dirs[(edges, law, nz)] = d
            runs.append({"edges": edges, "mixture": law, "nx": nx, "nz": nz,
                         "status": s["status"], "steps": int(s["steps"]),
                         "wall": float(s["wall_seconds"]),
                         "err_rms_grains": float(s["err_rms_grains"]),
                         "err_max_grains": float(s["err_max_grains"]),
                         "err_rms_air": float(s["err_rms_air"]),
                         "err_max_air": float(s["err_max_air"]),
                         "u_interface": float(s["u_interface"]),
                         "u_interface_exact": float(s["u_interface_exact"]),
                         "mass_error": float(s["mass_error"])})
    top = 0.0450736  # the exact top velocity, Barker & Rauter (2018), eq. (9)
    with open(os.path.join(outdir, "bagnold2_runs.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(runs[0].keys()))
        w.writeheader()
        w.writerows(runs)

    # the transient from rest on 50 x 100
    td, ts = run(muflow, outdir, "bagnold2_transient", [
        "solver.mode=transient", "solver.end_time=%g" % TRANSIENT_END,
        "solver.dt=%g" % TRANSIENT_DT, "solver.preconditioner_reuse=20"] + overrides)
    with open(os.path.join(td, "history.csv")) as f:
        hist = list(csv.DictReader(f))
    final = float(hist[-1]["err_rms"])
    reached = None
    for r in hist:
        if reached is None and abs(float(r["err_rms"]) - final) <= STEADY_BAND * top:
            reached = r
        elif reached is not None and abs(float(r["err_rms"]) - final) > STEADY_BAND * top:
            reached = None

    md = ["Steady from rest, the interface held flat (`cases/bagnold2.ini`, Barker & Rauter "
          "2018, Table 1), errors against eqs. (6)-(11) in m/s; u_top = %.7f m/s; order: "
          "observed between a grid and the next finer one." % top, ""]
    md.append("| edges | mixture | grid | status | steps | wall s | grains err_rms (order) | "
              "air err_rms (order) | air err_rms / u_top | u_interface (exact) | mass_error |")
    md.append("|---|---|---|---|---|---|---|---|---|---|---|")
    for edges, law in VARIANTS:
        rs = [r for r in runs if r["edges"] == edges and r["mixture"] == law]
        for m, r in enumerate(rs):
            og = order(rs[m - 1]["err_rms_grains"], r["err_rms_grains"]) if m else ""
            oa = order(rs[m - 1]["err_rms_air"], r["err_rms_air"]) if m else ""
            md.append("| %s | %s | %d x %d | %s | %d | %.2f | %.3e %s | %.3e %s | %.3f%% | "
                      "%.7f (%.7f) | %.1e |" % (
                          edges, law, r["nx"], r["nz"], r["status"], r["steps"], r["wall"],
                          r["err_rms_grains"], "(%s)" % og if og else "",
                          r["err_rms_air"], "(%s)" % oa if oa else "",
                          100.0 * r["err_rms_air"] / top, r["u_interface"],
                          r["u_interface_exact"], r["mass_error"]))
    md.append("")
    md += positions(muflow, outdir, overrides)
    # from rest to the steady mode's criterion (solver.steady_tolerance)
    sd, ss = run(muflow, outdir, "bagnold2_transient_to_steady", [
        "solver.mode=transient", "solver.end_time=20", "solver.dt=%g" % STEADY_DT,
        "solver.steady_tolerance=%g" % STEADY_TOL, "solver.preconditioner_reuse=20"] + overrides)
    rmin = min(float(r["residual"]) for r in hist)
    md.append("Transient from rest on 50 x 100 (`solver.mode=transient`, steps of %g s set by "
              "the case, the lagged viscosity, T carried by the VOF transport in sub-steps, a "
              "factorisation kept up to 20 steps): "
              "%s at t = %g s after %s steps, %.1f s wall; grains err_rms %s, air err_rms %s "
              "(the steady mode's to the digits shown above), mass_error %s. "
              "At its steady state (err_rms within %g u_top of its final value from then "
              "on) from t = %s s (step %s, %s s wall); the smallest relative residual on the "
              "way %.1e." % (
                  TRANSIENT_DT, ts["status"], TRANSIENT_END, ts["steps"],
                  float(ts["wall_seconds"]), ts["err_rms_grains"], ts["err_rms_air"],
                  ts["mass_error"], STEADY_BAND,
                  reached["time"] if reached else "–", reached["step"] if reached else "–",
                  reached["wall_seconds"] if reached else "–", rmin))
    md.append("")
    md.append("Transient from rest to the steady mode's criterion on 50 x 100 "
              "(`solver.steady_tolerance=%g`, steps of %g s): %s at t = %s s after %s steps, "
              "%.1f s wall; grains err_rms %s, air err_rms %s.  The steady mode: %s steps, "
              "%.2f s wall (series, weighted, 50 x 100 above)." % (
                  STEADY_TOL, STEADY_DT, ss["status"], ss["time"], ss["steps"],
                  float(ss["wall_seconds"]), ss["err_rms_grains"], ss["err_rms_air"],
                  next(r["steps"] for r in runs if r["edges"] == "series" and
                       r["mixture"] == "weighted" and r["nz"] == 100),
                  next(r["wall"] for r in runs if r["edges"] == "series" and
                       r["mixture"] == "weighted" and r["nz"] == 100)))
    with open(os.path.join(outdir, "bagnold2_table.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    print("\n".join(md))

    fig, ax = plt.subplots(1, 2, figsize=(10, 4.5))
    for (edges, law), style in zip(VARIANTS, ["-", ":"]):
        z, u, ue = profile(dirs[(edges, law, 100)])
        ax[0].plot(u, [1e3 * v for v in z], style, label="%s, %s" % (edges, law))
        ax[1].plot([(a - b) / top for a, b in zip(u, ue)], [1e3 * v for v in z], style,
                   label="%s, %s" % (edges, law))
    z, u, ue = profile(dirs[("series", "weighted", 100)])
    ax[0].plot(ue, [1e3 * v for v in z], "k", lw=0.8, label="exact (6)-(11)")
    for a in ax:
        a.axhline(0.5, color="grey", lw=0.5)
        a.set_ylabel("z (mm)")
    ax[0].set_xlabel("u (m/s)")
    ax[1].set_xlabel("(u - u_exact) / u_top")
    ax[0].legend(fontsize=8)
    ax[0].set_title("bagnold2, 50 x 100: grains below 0.5 mm, air above")
    ax[1].set_title("error")
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "bagnold2_profile.png"), dpi=110)


if __name__ == "__main__":
    main()
