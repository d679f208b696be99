#!/usr/bin/python3
"""Bed load beside the Newton FEM's Table 2 (Chauchat & Medale 2010).

usage: bedload_study.py MUFLOW OUTDIR [section.key=value ...]

Runs cases/bedload.ini (set A, bercovier) through the
muflow command (the caller's OMP_NUM_THREADS, 2 in `make bench`) with the
mixed-fluid model at lambda 1e-6 and 1e-7 and the two-fluid model at
lambda 1e-6, on the FEM's grids along the depth (12 x 1 x 80 and
24 x 1 x 160 elements: nz = 80 and 160 cells; the flow is uniform along x
and y, so muflow's 2 x 1 x nz holds the same profile), each REPEATS times
(median wall time), and writes OUTDIR/bedload_table.md and
bedload_runs.csv: steps and wall time beside the FEM's iterations and CPU
seconds, the error against Ouriemi et al.'s exact solution, the mobile
layer."""
import csv
import os
import statistics
import subprocess
import sys

from summary_ini import summary

HERE = os.path.dirname(os.path.abspath(__file__))
CASE = os.path.join(HERE, "..", "cases", "bedload.ini")
REPEATS = 5
# Chauchat & Medale (2010), Table 2: (model, lambda, FEM grid) -> (iterations, CPU s on 8 processes)
FEM = {("mixed", 1e-6, 80): (269, 438.0), ("mixed", 1e-6, 160): (54, 473.0),
       ("mixed", 1e-7, 80): (253, 453.0), ("mixed", 1e-7, 160): (75, 589.0),
       ("two_fluid", 1e-6, 80): (1943, 5682.0), ("two_fluid", 1e-6, 160): (206, 5476.0)}


def run(muflow, outdir, model, lam, nz, overrides):
    d = os.path.join(outdir, "bedload_%s_l%g_nz%d" % (model, lam, nz))
    cmd = [muflow, CASE, "bedload.model=" + model, "rheology.lambda=%g" % lam,
           "domain.nz=%d" % nz, "output.fields=off", "output.quiet=on",
           "output.dir=" + d] + overrides
    walls = []
    for _ in range(REPEATS):
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        s = summary(os.path.join(d, "summary.ini"))
        walls.append(float(s["wall_seconds"]))
    print(" ".join(cmd), flush=True)
    return {"model": model, "lambda": lam, "nz": nz, "status": s["status"],
            "steps": int(s["steps"]), "wall_median": statistics.median(walls),
            "wall_max": max(walls), "err_rms": float(s["err_rms"]),
            "err_rms_particles": float(s.get("err_rms_particles", "nan")),
            "mobile_layer": float(s["mobile_layer"]),
            "mobile_layer_exact": float(s["mobile_layer_exact"])}


def main():
    muflow, outdir = sys.argv[1], sys.argv[2]
    overrides = sys.argv[3:]
    os.makedirs(outdir, exist_ok=True)
    rows = [run(muflow, outdir, m, lam, nz, overrides) for (m, lam, nz) in FEM]
    with open(os.path.join(outdir, "bedload_runs.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    md = ["The plane bed-load flow (`cases/bedload.ini`, set A, bercovier), "
          "steady from rest to a relative residual of 1e-10, beside the Newton FEM of "
          "Chauchat & Medale (2010), Table 2 (its grids 12 x 1 x 80 and 24 x 1 x 160 quadratic "
          "elements; "
          "muflow 2 x 1 x nz cells, the same profile, since the flow is uniform along x and "
          "y).  muflow: wall seconds of the march, median of %d runs on 2 threads; the FEM: "
          "CPU seconds on 8 processes, its iterations.  err_rms: the mixture (mixed) or "
          "mixture velocity (two-fluid) against the exact solution, m/s; the FEM gives its "
          "errors only in its figure 9, with another norm, so equal error is not checked "
          "here." % REPEATS, ""]
    md.append("| model | lambda | FEM grid | FEM iterations | FEM CPU s | muflow nz | status | "
              "steps | wall s (max) | FEM s / muflow s | err_rms | err_rms particles | "
              "mobile layer (exact) |")
    md.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        it, cpu = FEM[(r["model"], r["lambda"], r["nz"])]
        grid = "12 x 1 x 80" if r["nz"] == 80 else "24 x 1 x 160"
        md.append("| %s | %g | %s | %d | %g | %d | %s | %d | %.4f (%.4f) | %.0f | %.3e | %s | "
                  "%.6f (%.6f) |" % (
                      r["model"], r["lambda"], grid, it, cpu, r["nz"], r["status"], r["steps"],
                      r["wall_median"], r["wall_max"], cpu / max(r["wall_median"], 1e-6),
                      r["err_rms"],
                      "%.3e" % r["err_rms_particles"] if r["model"] == "two_fluid" else "–",
                      r["mobile_layer"], r["mobile_layer_exact"]))
    with open(os.path.join(outdir, "bedload_table.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    print("\n".join(md))


if __name__ == "__main__":
    main()
