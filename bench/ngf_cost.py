#!/usr/bin/python3
"""The cost of a steady run of the nonlocal fluidity (rheology.law = ngf)
against the local law's on the same layer.

usage: ngf_cost.py MUFLOW OUTDIR [REPEATS]

For cases/ngf_incline.ini as shipped (nz 40) and at nz 400, and for
cases/ngf_shear.ini and cases/ngf_chute.ini, runs REPEATS (5) rounds that
alternate the accelerated steady iteration (the case as shipped), the plain
Picard iteration (rheology.fluidity_anderson = 0) and, on the incline, the
local law with Newton's tangent (rheology.law = mui solver.newton = on; the
two other scenes need law = ngf), each with output.fields = off on the
caller's OMP_NUM_THREADS.  Prints and writes OUTDIR/ngf_cost.md: the steps,
the median of the march's wall time (summary.ini's wall_seconds), the load
average beside the runs, and the time ratio of ngf to the local law."""
import os
import statistics
import subprocess
import sys

from summary_ini import loadavg, summary

HERE = os.path.dirname(os.path.abspath(__file__))
CASES = os.path.join(HERE, "..", "cases")
LAYERS = [("ngf_incline", "ngf_incline.ini", ["domain.nz=40"], True),
          ("ngf_incline nz 400", "ngf_incline.ini", ["domain.nz=400"], True),
          ("ngf_shear", "ngf_shear.ini", [], False),
          ("ngf_chute", "ngf_chute.ini", [], False)]
RUNS = [("ngf", []), ("picard", ["rheology.fluidity_anderson=0"]),
        ("local", ["rheology.law=mui", "solver.newton=on"])]


def run(muflow, outdir, case, args):
    d = os.path.join(outdir, "ngf_cost")
    cmd = [muflow, os.path.join(CASES, case), "output.fields=off", "output.quiet=on",
           "output.dir=" + d] + args
    rc = subprocess.run(cmd, stdout=subprocess.DEVNULL).returncode
    if rc not in (0, 3):
        raise SystemExit("%s: exit %d" % (" ".join(cmd), rc))
    s = summary(os.path.join(d, "summary.ini"))
    return int(s["steps"]), float(s["wall_seconds"]), s["status"]


def main():
    if len(sys.argv) < 3:
        raise SystemExit(__doc__)
    muflow, outdir = sys.argv[1], sys.argv[2]
    repeats = int(sys.argv[3]) if len(sys.argv) > 3 else 5
    rows = ["| layer | ngf steps | ngf s | Picard steps | Picard s | local steps | local s "
            "| ngf / local | load |", "|---|---|---|---|---|---|---|---|---|"]
    for name, case, extra, local in LAYERS:
        times = {k: [] for k, _ in RUNS}
        steps, loads = {}, []
        for _ in range(repeats):
            for key, args in RUNS:
                if key == "local" and not local:
                    continue
                loads.append(loadavg())
                n, t, status = run(muflow, outdir, case, extra + args)
                if status != "steady":
                    raise SystemExit("%s %s: %s" % (name, key, status))
                steps[key] = n
                times[key].append(t)
        med = {k: statistics.median(v) for k, v in times.items() if v}
        ratio = "%.1f" % (med["ngf"] / med["local"]) if "local" in med else "-"
        rows.append("| %s | %d | %.4f | %d | %.4f | %s | %s | %s | %.1f-%.1f |" % (
            name, steps["ngf"], med["ngf"], steps["picard"], med["picard"],
            steps.get("local", "-"), "%.4f" % med["local"] if "local" in med else "-", ratio,
            min(loads), max(loads)))
        print(rows[-1], flush=True)
    with open(os.path.join(outdir, "ngf_cost.md"), "w") as f:
        f.write("\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
