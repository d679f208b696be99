#!/usr/bin/python3
"""The granular cylinder's continuation in the forcing (Chauchat &
Medale 2014, sec. 4.2, fig. 12): steady solves of cases/cylinder.ini along F for several confining
pressures.

usage: cylinder_granular.py MUFLOW OUTDIR [--pressures 5,10,20]
                            [--forcing 1.0,1.05,1.1,1.2,1.3,1.4]
                            [--grid 40x120] [--start RUNDIR] [--min-step 0.0125]
                            [--plot] [--csv RUN/cylinder.csv,...]

F = rho phi g L_x / p_ext (L_x = 20 D, the paper's whole box; the case holds
half of it) sets the gravity: physics.gravity = F p_ext / (rho phi L_x),
which scene cylinder computes from cylinder.forcing (its own continuation,
cylinder.forcing_end, does one pressure in one run; this driver adds the
scaled starts across pressures and keeps each solve's folder).
The first pressure's first F starts from rest with the case's continuation
in lambda (1e-2 down to 1e-6), or from --start RUNDIR (a steady state of
the case at another F or pressure); every later F of that pressure starts
from the one before (solver.initial_state, the same grid: an exact copy)
at lambda 1e-6.  A solve without a steady state is retried at the midpoint
of the last step in F, down to steps of --min-step: the series ends at
the first F that fails within --min-step of a steady one: the limit of
the continuation, or only the march's failure before it
(docs/validation/cylinder.md, "Known limits").  Every other pressure starts each F from
the first pressure's state at that F scaled to it (velocity times
sqrt(p / p_first), pressure times p / p_first: mu(I) has no stress or rate
scale of its own, so at a fixed F the steady state scales so but for the
regularisation's lambda), and from its own previous F if that fails.

Per solve (OUTDIR/cylinder_granular.csv): p_ext, F, g, status, steps, wall
seconds, Q (the flow rate per unit span of the whole box), U (the mean
velocity over the box, Q / L_x: the summary's mean_velocity), Fr = U /
sqrt(g D), Fr_eff = U / sqrt(g (D + d)), the whole cylinder's drag F_D
along the flow by the control volume and by the surface integral, F_D /
p_ext, C_D = F_D / (rho phi U^2 / 2), and C_D / p_ext.  --plot draws the
two panels of fig. 12 (F_D / p_ext against Fr, C_D against Fr_eff) (cylinder_granular.png) and, by cylinder_maps.py, the
velocity, regularised pressure and viscosity around the body at the first
pressure's largest steady F (cylinder_granular_maps.png: figs. 13, 14, 16)."""
import argparse
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from summary_ini import summary  # noqa: E402

CASE = "cases/cylinder.ini"
LX_WHOLE = 20.0  # the paper's box across, in D
RHO_PHI = 1.0    # physics.density of the case
D, d = 1.0, 0.1


def gravity(p, F):
    """physics.gravity for the forcing F = rho phi g L_x / p_ext."""
    return F * p / (RHO_PHI * LX_WHOLE)


def reuse(out, p, F, nx, nz):
    """The summary of an earlier steady solve of this p, F and grid in out,
    or (None, None)."""
    path = os.path.join(out, "summary.ini")
    if not os.path.exists(path):
        return None, None
    s = summary(path)
    case = summary(path, "physics")
    dom = summary(path, "domain")
    g = gravity(p, F)
    if (s.get("status") == "steady" and "mean_velocity" in s
            and float(case["confining_pressure"]) == p
            and abs(float(case["gravity"]) / g - 1.0) < 1e-12
            and int(dom["nx"]) == nx and int(dom["nz"]) == nz):
        print(f"{out}: reused", flush=True)
        return s, g
    return None, None


def secant_state(a, b, w, path):
    """b's checkpoint moved w of the way from a to b further on: the secant
    predictor of the next F's state."""
    import h5py
    import shutil
    shutil.copyfile(os.path.join(b, "checkpoint.h5"), path)
    with h5py.File(os.path.join(a, "checkpoint.h5"), "r") as fa, h5py.File(path, "r+") as f:
        for name in ("velocity_x", "velocity_y", "velocity_z", "p_dyn"):
            f[name][...] = (1.0 + w) * f[name][...] - w * fa[name][...]
    return path


MAX_STEPS = 3000  # per solve: F = 1.2 at D/4 was still at 1e-3 after 1000


def solve(muflow, out, p, F, nx, nz, start):
    """One steady solve; start: a run directory (its checkpoint) or an
    .h5 state, None for rest with the case's continuation in lambda."""
    g = gravity(p, F)
    args = [muflow, CASE, f"domain.nx={nx}", f"domain.nz={nz}",
            f"physics.confining_pressure={p}", f"cylinder.forcing={F!r}",
            f"output.dir={out}", "solver.progress_interval=50",
            f"solver.max_steps={MAX_STEPS}"]
    if start:
        state = start if start.endswith(".h5") else os.path.join(start, "checkpoint.h5")
        args += [f"solver.initial_state={state}",
                 "solver.continuation=1"]
    print(" ".join(args), flush=True)
    r = subprocess.run(args)
    if r.returncode not in (0, 1, 3):  # steady; diverged or unsteady: a result too
        sys.exit(f"muflow failed (exit {r.returncode})")
    s = summary(os.path.join(out, "summary.ini"))
    return s, g


def scaled_state(src, k, path):
    """src's checkpoint with the velocity times sqrt(k) and the pressure
    times k, written to path: the steady state at pressure k p_ext for the
    same F if the regularisation did not set a rate of its own."""
    import h5py
    import shutil
    shutil.copyfile(os.path.join(src, "checkpoint.h5"), path)
    with h5py.File(path, "r+") as f:
        for name in ("velocity_x", "velocity_y", "velocity_z"):
            f[name][...] = f[name][...] * math.sqrt(k)
        f["p_dyn"][...] = f["p_dyn"][...] * k
    return path


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("muflow")
    ap.add_argument("outdir")
    ap.add_argument("--pressures", default="5,10,20")
    ap.add_argument("--forcing", default="1.0,1.05,1.1,1.2,1.3,1.4")
    ap.add_argument("--grid", default="40x120")
    ap.add_argument("--plot", action="store_true")
    ap.add_argument("--start", default=None)
    ap.add_argument("--min-step", type=float, default=0.0125, dest="min_step")
    ap.add_argument("--reuse", action="store_true",
                    help="keep the steady solves already in OUTDIR (same p, F, grid)")
    ap.add_argument("--png", default=None,
                    help="the plot's file name in outdir (default cylinder_granular.png)")
    ap.add_argument("--title", default=None, help="the plot's title (with --csv)")
    ap.add_argument("--no-solve", action="store_true", dest="no_solve",
                    help="solve nothing: the CSV and plots of the steady solves in OUTDIR")
    ap.add_argument("--csv", default=None,
                    help="solve nothing: plot the rows of scene cylinder's cylinder.csv files "
                         "(comma-separated paths, one per pressure) into OUTDIR")
    a = ap.parse_args()
    if a.csv:
        plot_csv(a)
        return
    nx, nz = (int(x) for x in a.grid.split("x"))
    pressures = [float(x) for x in a.pressures.split(",")]
    forcing = [float(x) for x in a.forcing.split(",")]
    rows = []
    base = pressures[0]
    steady_base = {}  # F -> run directory of the first pressure's steady state
    for p in pressures:
        prev, prev_F = a.start, None
        older = None  # (run directory, F) of the steady solve before prev
        queue = list(forcing)
        while queue:
            F = queue.pop(0)
            out = os.path.join(a.outdir, "cylinder_granular_runs", f"p{p:g}_F{F:g}")
            s, g = reuse(out, p, F, nx, nz) if a.reuse or a.no_solve else (None, None)
            if s is None and a.no_solve:
                continue  # tables and plots of what is stored only
            if s is None:
                os.makedirs(out, exist_ok=True)
                start = prev
                if p != base and F in steady_base:
                    # the first pressure's state at this F, scaled to p (exact
                    # without the regularisation: u ~ sqrt(p), stresses ~ p)
                    start = scaled_state(steady_base[F], p / base, os.path.join(out, "start.h5"))
                elif older and prev_F is not None:
                    # the secant through the last two steady states, at most
                    # one of their steps ahead
                    w = min(1.0, (F - prev_F) / (prev_F - older[1]))
                    start = secant_state(older[0], prev, w, os.path.join(out, "start.h5"))
                s, g = solve(a.muflow, out, p, F, nx, nz, start)
                if s.get("status") != "steady" and start is not None and start != prev:
                    s, g = solve(a.muflow, out, p, F, nx, nz, prev)  # from this pressure's last
                if s.get("status") != "steady" and prev is None and start is not None:
                    s, g = solve(a.muflow, out, p, F, nx, nz, None)  # from rest
            row = {"p_ext": p, "F": F, "g": g, "status": s.get("status"),
                   "steps": int(s.get("steps", 0)), "wall_s": float(s.get("wall_seconds", 0))}
            if s.get("status") == "steady":
                U = float(s["mean_velocity"])
                FD = float(s["drag_force_control_volume"])  # along the flow, -z
                FDs = float(s["drag_force"])
                row.update(Q=U * LX_WHOLE, U=U, Fr=U / math.sqrt(g * D), Fr_eff=U / math.sqrt(g * (D + d)),
                           F_D=FD, F_D_surface=FDs, F_D_over_p=FD / p,
                           C_D=FD / (0.5 * RHO_PHI * U * U) if U > 0 else float("nan"))
                row["C_D_over_p"] = row["C_D"] / p
            rows.append(row)
            print(row, flush=True)
            if s.get("status") == "steady":
                older = (prev, prev_F) if prev_F is not None else None
                prev, prev_F = out, F
                if p == base:
                    steady_base[F] = out
            elif prev_F is not None and F - prev_F > a.min_step * (1 + 1e-9):
                # too long a step or the limit: halve the step before calling it
                queue = [round(0.5 * (prev_F + F), 6), F] + queue
            else:
                # the limit of the continuation: no steady state at this F
                # within min_step of the last steady one
                break
    keys = ["p_ext", "F", "g", "status", "steps", "wall_s", "Q", "U", "Fr", "Fr_eff", "F_D",
            "F_D_surface", "F_D_over_p", "C_D", "C_D_over_p"]
    with open(os.path.join(a.outdir, "cylinder_granular.csv"), "w") as f:
        f.write(",".join(keys) + "\n")
        for r in rows:
            f.write(",".join(f"{r[k]:.6g}" if isinstance(r.get(k), float) else str(r.get(k, ""))
                             for k in keys) + "\n")
    if a.plot:
        plot(a, rows, pressures, nx, nz)
        if steady_base:  # figs. 13, 14, 16: the first pressure's fastest steady flow
            last = steady_base[max(steady_base)]
            subprocess.run([sys.executable, os.path.join(os.path.dirname(__file__),
                                                         "cylinder_maps.py"), last, "--out",
                            os.path.join(a.outdir, "cylinder_granular_maps.png")], check=True)


def plot_csv(a):
    """The two panels of fig. 12 from scene cylinder's cylinder.csv files."""
    import csv
    nx, nz = (int(x) for x in a.grid.split("x"))
    rows = []
    for path in a.csv.split(","):
        with open(path) as f:
            for r in csv.DictReader(f):
                row = {k: (v if k == "status" else float(v) if v else float("nan"))
                       for k, v in r.items()}
                rows.append(row)
    pressures = sorted({r["p_ext"] for r in rows})
    os.makedirs(a.outdir, exist_ok=True)
    plot(a, rows, pressures, nx, nz, note=a.title or "")
    collapse_table(a, rows, pressures)


def collapse_table(a, rows, pressures):
    """collapse.md: how far each pressure's F_D / p_ext and F lie from
    p_ext = 10's (or the first pressure's) at the same Fr, the reference
    interpolated linearly in log Fr between its steady solves, over the Fr
    both cover."""
    import math
    ref_p = 10.0 if 10.0 in pressures else pressures[0]

    def steady(p):
        r = [x for x in rows if x["p_ext"] == p and x["status"] == "steady" and x["Fr"] > 0]
        r.sort(key=lambda x: x["Fr"])
        return r

    ref = steady(ref_p)

    def at(fr, key):
        lf = math.log(fr)
        for lo, hi in zip(ref, ref[1:]):
            a0, a1 = math.log(lo["Fr"]), math.log(hi["Fr"])
            if a0 <= lf <= a1 and a1 > a0:
                w = (lf - a0) / (a1 - a0)
                return (1 - w) * lo[key] + w * hi[key]
        return float("nan")

    lines = ["| p_ext | steady solves | Fr up to | last F_D / p_ext | last F | "
             "F_D / p_ext from p_ext = %g's: Fr <= 2, <= 10, <= 100 | F from p_ext = %g's |"
             % (ref_p, ref_p),
             "|---|---|---|---|---|---|---|"]
    for p in pressures:
        r = steady(p)
        if not r:
            continue
        dev = {2: 0.0, 10: 0.0, 100: 0.0}
        devF = 0.0
        for x in (r if p != ref_p else []):
            q, f = at(x["Fr"], "F_D_over_p"), at(x["Fr"], "F")
            if not math.isfinite(q):
                continue
            d = abs(x["F_D_over_p"] / q - 1.0)
            for lim in dev:
                if x["Fr"] <= lim:
                    dev[lim] = max(dev[lim], d)
            devF = max(devF, abs(x["F"] / f - 1.0))
        cells = ("reference" if p == ref_p else
                 ", ".join("%.2f %%" % (100 * dev[k]) for k in sorted(dev)))
        lines.append("| %g | %d | %.3g | %.4f | %.5f | %s | %s |" % (
            p, len(r), r[-1]["Fr"], r[-1]["F_D_over_p"], r[-1]["F"], cells,
            "reference" if p == ref_p else "%.2f %%" % (100 * devF)))
    text = "\n".join(lines) + "\n"
    with open(os.path.join(a.outdir, "collapse.md"), "w") as f:
        f.write(text)
    print(text, end="")


def plot(a, rows, pressures, nx, nz, note=", lambda 1e-6"):
    """cylinder_granular.png: F_D / p_ext against Fr, C_D against Fr_eff,
    and the forcing F against Fr (the approach to the limit of steady flow
    that a continuation in U, cylinder.velocity_end, follows)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.5))
    for p in pressures:
        r = [x for x in rows if x["p_ext"] == p and x["status"] == "steady"]
        r.sort(key=lambda x: x["Fr"])
        ax[0].plot([x["Fr"] for x in r], [x["F_D_over_p"] for x in r], "o-",
                   label=f"p_ext = {p:g}")
        # C_D itself: at a fixed F, F_D ~ p_ext and U^2 ~ p_ext, so C_D (not
        # C_D / p_ext) is what collapses here
        ax[1].loglog([x["Fr_eff"] for x in r], [x["C_D"] for x in r], "o-",
                     label=f"p_ext = {p:g}")
        ax[2].semilogx([x["Fr"] for x in r], [x["F"] for x in r], "o-",
                       label=f"p_ext = {p:g}")
    ax[0].set_xlabel("Fr = U / sqrt(g D)")
    ax[0].set_ylabel("F_D / p_ext")
    ax[1].set_xlabel("U / sqrt(g (D + d))")
    ax[1].set_ylabel("C_D = F_D / (rho phi U^2 / 2)")
    ax[2].set_xlabel("Fr = U / sqrt(g D)")
    ax[2].set_ylabel("F = rho phi g L_x / p_ext")
    for x in ax:
        x.legend()
        x.grid(True, which="both", alpha=0.3)
    fig.suptitle(f"granular cylinder, half box {nx} x {nz} (D/{nx // 10}){note}")
    fig.tight_layout()
    fig.savefig(os.path.join(a.outdir, getattr(a, "png", None) or "cylinder_granular.png"),
                dpi=110)


if __name__ == "__main__":
    main()
