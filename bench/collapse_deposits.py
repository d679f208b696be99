#!/usr/bin/python3
"""Column collapse deposits: a = 0.5, 1.42 and 6.26 against contact dynamics.

usage: collapse_deposits.py MUFLOW OUTDIR [N] [section.key=value ...] [--tag NAME]

Runs cases/collapse.ini (the caller's OMP_NUM_THREADS) at N cells per H0
(default 32) for the three aspect ratios of Lagree, Staron & Popinet (2011)
with the overrides docs/validation/collapse.md gives, each until the grains come to rest
(collapse.rest_energy) or t = 12, and compares the final surface h(x) with
the final contact-dynamics profile of cases/data/staron_cd_deposits.csv
(both of its sides folded onto x >= 0): OUTDIR/collapse_deposit_a*.png and
collapse_deposits.md (run-out L_f, (L_f - R0)/R0 and the height on the axis
H_f, muflow against contact dynamics); with --tag NAME the files are named
with _NAME and the overrides go to every run."""
import csv
import os
import subprocess
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from summary_ini import summary

HERE = os.path.dirname(os.path.abspath(__file__))
CASE = os.path.join(HERE, "..", "cases", "collapse.ini")
CD = os.path.join(HERE, "..", "cases", "data", "staron_cd_deposits.csv")
# aspect ratio -> (R0, d, lx): the domain reaches past the contact-dynamics run-out
CASES = {0.5: (2.0, 1.0 / 30.0, 5.0),
         1.42: (1.0 / 1.42, 1.0 / 65.0, 4.5),
         6.26: (1.0 / 6.26, 1.0 / 65.0, 3.0)}
END_TIME = 12.0



def cd_profile(a):
    rows = [r for r in open(CD) if not r.startswith("#")]
    pts = [(abs(float(r["coord"])), float(r["value"])) for r in csv.DictReader(rows)
           if abs(float(r["parameter"]) - a) < 1e-9]
    return sorted(pts)


def run(muflow, outdir, a, n, overrides, suffix):
    r0, d, lx = CASES[a]
    nx = int(round(lx * n))
    out = os.path.join(outdir, "collapse%s_a%g_n%d" % (suffix, a, n))
    cmd = [muflow, CASE, "collapse.half_width=%.17g" % r0, "rheology.grain_diameter=%.17g" % d,
           "domain.lx=%g" % lx, "domain.nx=%d" % nx, "domain.nz=%d" % (3 * n // 2),
           "domain.ly=%.17g" % (1.0 / n), "solver.end_time=%g" % END_TIME,
           "output.fields=off", "output.quiet=on", "output.dir=" + out] + overrides
    print(" ".join(cmd), flush=True)
    subprocess.run(cmd, check=True)
    s = summary(os.path.join(out, "summary.ini"))
    with open(os.path.join(out, "surface.csv")) as f:
        prof = [(float(r["x"]), float(r["h"])) for r in csv.DictReader(f) if r["final"] == "1"]
    return s, prof


def main():
    muflow, outdir = sys.argv[1], sys.argv[2]
    args = sys.argv[3:]
    tag = ""
    if "--tag" in args:
        i = args.index("--tag")
        tag = args[i + 1]
        del args[i:i + 2]
    overrides = [x for x in args if "=" in x]
    counts = [int(x) for x in args if "=" not in x]
    n = counts[0] if counts else 32
    suffix = "_" + tag if tag else ""
    os.makedirs(outdir, exist_ok=True)
    lines = ["# Column collapse deposits against contact dynamics (N = %d cells per H0%s)" % (
        n, (", " + " ".join(overrides)) if overrides else ""), "",
             "Contact dynamics: Staron's discrete-grain runs, final snapshot "
             "(cases/data/staron_cd_deposits.csv), both sides folded; run-out = mean of the two "
             "sides' extents.  muflow: x_front and h_axis of the final state.", "",
             "| a | status | t end | L_f muflow | L_f CD | (L_f-R0)/R0 muflow | (L_f-R0)/R0 CD "
             "| H_f muflow | H_f CD (max) | mass error |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for a in sorted(CASES):
        r0 = CASES[a][0]
        s, prof = run(muflow, outdir, a, n, overrides, suffix)
        cd = cd_profile(a)
        rows = [r for r in open(CD) if not r.startswith("#")]
        xs = [float(r["coord"]) for r in csv.DictReader(rows)
              if abs(float(r["parameter"]) - a) < 1e-9]
        lf_cd = 0.5 * (abs(min(xs)) + abs(max(xs)))
        hf_cd = max(h for _, h in cd)
        lf, hf = float(s["x_front"]), float(s["h_axis"])
        lines.append("| %g | %s | %.2f | %.3f | %.3f | %.2f | %.2f | %.3f | %.3f | %.1e |" % (
            a, s["status"], float(s["time"]), lf,
            lf_cd, (lf - r0) / r0, (lf_cd - r0) / r0, hf, hf_cd, float(s["mass_error"])))
        plt.figure(figsize=(7, 3))
        plt.plot([x for x, _ in cd], [h for _, h in cd], ".", ms=3, color="0.5",
                 label="contact dynamics (final)")
        plt.plot([x for x, _ in prof], [h for _, h in prof], "-", color="C0",
                 label="muflow (final, %s)" % s["status"])
        plt.plot([0, r0, r0], [1, 1, 0], "k:", lw=0.8, label="initial column")
        plt.xlabel("x / H0")
        plt.ylabel("h / H0")
        plt.title("a = %g" % a)
        plt.legend(fontsize=8)
        plt.tight_layout()
        plt.savefig(os.path.join(outdir, "collapse_deposit%s_a%g.png" % (suffix, a)), dpi=120)
        plt.close()
    with open(os.path.join(outdir, "collapse_deposits%s.md" % suffix), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
