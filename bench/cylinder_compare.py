#!/usr/bin/python3
"""The granular cylinder's continuation on several grids, side by side: F_D
/ p_ext and C_D against Fr = U / sqrt(g D) from each run's cylinder.csv
(Chauchat & Medale 2014, fig. 12, one curve per run; docs/validation/cylinder.md).

usage: cylinder_compare.py OUT.png LABEL=RUNDIR [LABEL=RUNDIR ...]

Prints, for each run after the first, its F_D / p_ext at the first run's
Froude numbers (linear in log Fr, inside its own range) and the relative
difference."""
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def rows(rundir):
    """The steady solves of a run: (Fr, F_D / p_ext, C_D), by Fr."""
    with open(os.path.join(rundir, "cylinder.csv")) as f:
        out = [(float(r["Fr"]), float(r["F_D_over_p"]), float(r["C_D"]))
               for r in csv.DictReader(f) if r["status"] == "steady"]
    return sorted(out)


def at(curve, fr):
    """F_D / p_ext of curve at fr, linear in log Fr; None outside it."""
    for (f0, d0, _), (f1, d1, _) in zip(curve, curve[1:]):
        if f0 <= fr <= f1 and f1 > f0:
            t = (math.log(fr) - math.log(f0)) / (math.log(f1) - math.log(f0))
            return d0 + t * (d1 - d0)
    return None


def main():
    if len(sys.argv) < 3 or any("=" not in a for a in sys.argv[2:]):
        raise SystemExit(__doc__)
    runs = [(a.split("=", 1)[0], rows(a.split("=", 1)[1])) for a in sys.argv[2:]]
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5))
    for label, curve in runs:
        fr = [r[0] for r in curve]
        left.plot(fr, [r[1] for r in curve], "o-", ms=3, label=label)
        right.plot(fr, [r[2] for r in curve], "o-", ms=3, label=label)
    left.set_xscale("log")
    left.set_xlabel("Fr = U / sqrt(g D)")
    left.set_ylabel("F_D / p_ext")
    right.set_xscale("log")
    right.set_yscale("log")
    right.set_xlabel("Fr = U / sqrt(g D)")
    right.set_ylabel("C_D = F_D / (rho phi U^2 / 2)")
    left.legend()
    fig.suptitle("granular cylinder: the continuation on each grid")
    fig.tight_layout()
    fig.savefig(sys.argv[1], dpi=110)
    base_label, base = runs[0]
    print(f"| Fr ({base_label}) | " + " | ".join(f"{lab} F_D / p_ext" for lab, _ in runs) + " |")
    print("|---" * (len(runs) + 1) + "|")
    for fr, d, _ in base:
        cells = [f"{d:.4f}"]
        for _, curve in runs[1:]:
            v = at(curve, fr)
            cells.append("-" if v is None else f"{v:.4f} ({100 * (v / d - 1):+.1f} %)")
        print(f"| {fr:.4g} | " + " | ".join(cells) + " |")
    print(f"wrote {sys.argv[1]}")


if __name__ == "__main__":
    main()
