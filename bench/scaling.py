"""How the implicit step's cost grows with the grid: CPU time per step and
per cell, peak memory and Krylov iterations per step at 1x, 4x and 16x the
cells, for the default solver (`auto`) and a factorised one beside it.

usage: scaling.py MUFLOW OUTDIR [--steps N] [--only collapse,cavity,...]

Each run is a fixed number of steps from the case's start (solver.max_steps:
a steady case stops `unsteady` after them, a transient one `stopped`; a
scene that solves several stages, the cylinder's continuation, its first
stage's steps), on one
thread (OMP_NUM_THREADS=1: CPU time is then the work, whatever else the
machine runs), fields off.  The two solvers of a grid run back to back and
the load is written beside each.  A case the memory check refuses is a row
saying so.  Writes OUTDIR/scaling.md and scaling.csv."""
import csv
import os
import statistics
import subprocess
import sys

from summary_ini import loadavg, summary, timed_run

# scene: (case file, [(label, overrides)], the other solver's overrides: the
# Cholesky beside a matrix-free default, the matrix-free one beside a
# factorised default (the cavity's Cholesky, the cylinder's coupled LU))
COLLAPSE = [(f"{n} per H0", [f"domain.nx={5 * n}", f"domain.nz={3 * n // 2}",
                             f"domain.ly={1.0 / n}"]) for n in (32, 64, 128)]
CAVITY = [(f"{n}^2, Bn {bn}", [f"domain.nx={n}", f"domain.nz={n}", f"domain.ly={1.0 / n}",
                              f"rheology.yield_stress={bn / 2 ** 0.5!r}"])
          for bn in (10, 1000) for n in (64, 128, 256)]
CYLINDER = [(f"D/{k}", [f"domain.nx={10 * k}", f"domain.nz={30 * k}"]) for k in (8, 16, 32)]
BAGNOLD2 = [(f"{n} x {2 * n}", [f"domain.nx={n}", f"domain.nz={2 * n}",
                                f"domain.ly={9e-4 / n!r}"]) for n in (50, 100, 200)]
SCENES = {
    "collapse": ("cases/collapse.ini", COLLAPSE, ["solver.preconditioner=cholesky"]),
    "cavity": ("cases/bingham_cavity.ini", CAVITY, ["solver.preconditioner=multigrid"]),
    "cylinder": ("cases/cylinder.ini", CYLINDER, ["solver.preconditioner=multigrid"]),
    "bagnold2": ("cases/bagnold2.ini", BAGNOLD2, ["solver.preconditioner=cholesky"]),
}


def run(muflow, outdir, tag, case, overrides, steps):
    d = os.path.join(outdir, "scaling_runs", tag)
    args = [muflow, case, f"output.dir={d}", "output.quiet=on", "output.fields=off",
            f"solver.max_steps={steps}"] + overrides
    print(" ".join(args), flush=True)
    # a grid whose estimate passes MUFLOW_MEMORY_BOUND (bytes, default 8e9) is
    # refused at load, a row saying so, rather than a shared machine swapping
    env = dict(os.environ, OMP_NUM_THREADS="1", OMP_WAIT_POLICY="passive",
               MUFLOW_AVAILABLE_MEMORY=os.environ.get("MUFLOW_MEMORY_BOUND", "8000000000"))
    load0 = loadavg()
    code, wall, cpu, mb = timed_run(args, stdout=subprocess.DEVNULL,
                                    stderr=subprocess.PIPE, env=env)
    load1 = loadavg()
    path = os.path.join(d, "summary.ini")
    if not os.path.exists(path):
        print(f"  exit {code}: no summary", flush=True)
        return dict(tag=tag, status=f"refused (exit {code})", steps=0, cpu=cpu, mb=mb,
                    load=max(load0, load1), iters=float("nan"), matrices="")
    s = summary(path)
    iters = []
    with open(os.path.join(d, "history.csv")) as f:
        for row in csv.DictReader(f):
            if int(row["step"]) > 0:
                iters.append(int(row["linear_iterations"]))
    r = dict(tag=tag, status=s.get("status", "?"), steps=int(s.get("steps", 0)), cpu=cpu,
             mb=mb, load=max(load0, load1),
             iters=statistics.mean(iters) if iters else float("nan"),
             matrices=s.get("grid_matrices", ""))
    print(f"  {r['status']}, {r['steps']} steps, {cpu:.1f} s CPU, {mb:.0f} MB, "
          f"{r['iters']:.1f} iterations a step, load {r['load']:.1f}", flush=True)
    return r


def cells(overrides):
    n = 1
    for o in overrides:
        k, v = o.split("=")
        if k in ("domain.nx", "domain.nz"):
            n *= int(v)
    return n


def main():
    muflow, outdir = sys.argv[1], sys.argv[2]
    steps = int(sys.argv[sys.argv.index("--steps") + 1]) if "--steps" in sys.argv else 30
    only = sys.argv[sys.argv.index("--only") + 1].split(",") if "--only" in sys.argv \
        else list(SCENES)
    os.makedirs(outdir, exist_ok=True)
    rows = []
    for scene in only:
        case, grids, other = SCENES[scene]
        for label, over in grids:
            n = cells(over)
            for solver, extra in (("auto", []), (other[0].split("=")[1], other)):
                tag = f"{scene}_{label}_{solver}".replace(" ", "").replace("/", "").replace(
                    "^", "").replace(",", "_")
                r = run(muflow, outdir, tag, case, over + extra, steps)
                per = r["cpu"] / max(r["steps"], 1) / n * 1e6
                rows.append(dict(scene=scene, grid=label, cells=n, solver=solver, **r,
                                 us_cell_step=per))
    with open(os.path.join(outdir, "scaling.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    lines = [f"Cost of a step against the grid, {steps} steps from each case's start, "
             "1 thread (CPU s), peak resident memory, mean Krylov iterations a step, "
             "grid_matrices; the load is the 1-minute average's larger end.", "",
             "| scene | grid | cells | solver | status, steps | CPU s | us per cell-step | "
             "peak MB | iterations a step | grid_matrices | load |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['grid']} | {r['cells']:,} | {r['solver']} | "
                     f"{r['status']}, {r['steps']} | {r['cpu']:.1f} | {r['us_cell_step']:.2f} | "
                     f"{r['mb']:.0f} | {r['iters']:.1f} | {r['matrices']} | {r['load']:.1f} |")
    with open(os.path.join(outdir, "scaling.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
