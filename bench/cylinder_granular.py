#!/usr/bin/python3
"""The granular cylinder's continuation in the forcing (seeds/000 sec. 4.2,
fig. 12): steady solves of cases/cylinder.ini along F for several confining
pressures.

usage: cylinder_granular.py MUFLOW OUTDIR [--pressures 5,10,20]
                            [--forcing 1.0,1.05,1.1,1.2,1.3,1.4]
                            [--grid 40x120] [--start RUNDIR] [--plot]

F = rho phi g L_x / p_ext (L_x = 20 D, the seed's whole box; the case holds
half of it) sets the gravity: physics.gravity = F p_ext / (rho phi L_x).
The first pressure's first F starts from rest with the case's continuation
in lambda (1e-2 down to 1e-6); every later solve starts from the state
before it (solver.initial_state, the same grid: an exact copy) at lambda
1e-6: the next F from the previous one, a new pressure's first F from the
previous pressure's first (a start from rest with the continuation if that
fails).  --start RUNDIR: the first solve starts from that run's state
instead of rest (a steady state of the case at another F or pressure).
A pressure's series stops at the first F without a steady state:
the limit of the continuation.

Per solve (OUTDIR/cylinder_granular.csv): p_ext, F, g, status, steps, wall
seconds, U (the mean velocity over the box, Q / (L_x L_y)), Fr = U /
sqrt(g D), Fr_eff = U / sqrt(g (D + d)), the whole cylinder's drag F_D
along the flow by the control volume and by the surface integral, F_D /
p_ext, C_D = F_D / (rho phi U^2 / 2), and C_D / p_ext.  --plot draws the
two panels of fig. 12 (cylinder_granular.png)."""
import argparse
import glob
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from summary_ini import summary  # noqa: E402

CASE = "cases/cylinder.ini"
LX_WHOLE = 20.0  # the seed's box across, in D
RHO_PHI = 1.0    # physics.density of the case
D, d = 1.0, 0.1


def solve(muflow, out, p, F, nx, nz, start):
    g = F * p / (RHO_PHI * LX_WHOLE)
    args = [muflow, CASE, f"domain.nx={nx}", f"domain.nz={nz}",
            f"physics.confining_pressure={p}", f"physics.gravity={g!r}",
            f"output.dir={out}", "solver.progress_interval=50"]
    if start:
        args += [f"solver.initial_state={os.path.join(start, 'checkpoint.h5')}",
                 "solver.continuation=1"]
    print(" ".join(args), flush=True)
    r = subprocess.run(args)
    if r.returncode not in (0, 1, 3):  # steady; diverged or unsteady: a result too
        sys.exit(f"muflow failed (exit {r.returncode})")
    s = summary(os.path.join(out, "summary.ini"))
    return s, g


def mean_velocity(out):
    import h5py
    import numpy as np
    last = sorted(glob.glob(os.path.join(out, "fields_*.h5")))[-1]
    with h5py.File(last, "r") as f:
        return abs(float(np.mean(f["w"][:])))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("muflow")
    ap.add_argument("outdir")
    ap.add_argument("--pressures", default="5,10,20")
    ap.add_argument("--forcing", default="1.0,1.05,1.1,1.2,1.3,1.4")
    ap.add_argument("--grid", default="40x120")
    ap.add_argument("--plot", action="store_true")
    ap.add_argument("--start", default=None)
    a = ap.parse_args()
    nx, nz = (int(x) for x in a.grid.split("x"))
    pressures = [float(x) for x in a.pressures.split(",")]
    forcing = [float(x) for x in a.forcing.split(",")]
    rows = []
    first_state = a.start
    for p in pressures:
        prev = first_state
        for i, F in enumerate(forcing):
            out = os.path.join(a.outdir, "cylinder_granular_runs", f"p{p:g}_F{F:g}")
            s, g = solve(a.muflow, out, p, F, nx, nz, prev)
            if s.get("status") != "steady" and i == 0 and prev:
                s, g = solve(a.muflow, out, p, F, nx, nz, None)
            row = {"p_ext": p, "F": F, "g": g, "status": s.get("status"),
                   "steps": int(s.get("steps", 0)), "wall_s": float(s.get("wall_seconds", 0))}
            if s.get("status") == "steady":
                U = mean_velocity(out)
                FD = -float(s["lift_force_control_volume"])
                FDs = -float(s["lift_force"])
                row.update(U=U, Fr=U / math.sqrt(g * D), Fr_eff=U / math.sqrt(g * (D + d)),
                           F_D=FD, F_D_surface=FDs, F_D_over_p=FD / p,
                           C_D=FD / (0.5 * RHO_PHI * U * U) if U > 0 else float("nan"))
                row["C_D_over_p"] = row["C_D"] / p
            rows.append(row)
            print(row, flush=True)
            if s.get("status") != "steady":
                break  # the limit: no steady state at this F
            prev = out
            if i == 0:
                first_state = out
    keys = ["p_ext", "F", "g", "status", "steps", "wall_s", "U", "Fr", "Fr_eff", "F_D",
            "F_D_surface", "F_D_over_p", "C_D", "C_D_over_p"]
    with open(os.path.join(a.outdir, "cylinder_granular.csv"), "w") as f:
        f.write(",".join(keys) + "\n")
        for r in rows:
            f.write(",".join(f"{r[k]:.6g}" if isinstance(r.get(k), float) else str(r.get(k, ""))
                             for k in keys) + "\n")
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(1, 2, figsize=(11, 4.5))
        for p in pressures:
            r = [x for x in rows if x["p_ext"] == p and x["status"] == "steady"]
            ax[0].plot([x["Fr"] for x in r], [x["F_D_over_p"] for x in r], "o-",
                       label=f"p_ext = {p:g}")
            ax[1].loglog([x["Fr_eff"] for x in r], [x["C_D_over_p"] for x in r], "o-",
                         label=f"p_ext = {p:g}")
        ax[0].set_xlabel("Fr = U / sqrt(g D)")
        ax[0].set_ylabel("F_D / p_ext")
        ax[1].set_xlabel("U / sqrt(g (D + d))")
        ax[1].set_ylabel("C_D / p_ext")
        for x in ax:
            x.legend()
            x.grid(True, which="both", alpha=0.3)
        fig.suptitle(f"granular cylinder, half box {nx} x {nz} (D/{nx // 10}), lambda 1e-6")
        fig.tight_layout()
        fig.savefig(os.path.join(a.outdir, "cylinder_granular.png"), dpi=110)


if __name__ == "__main__":
    main()
