#!/usr/bin/python3
"""The algebraic multigrid against the probed LU on whole steady solves.

usage: heap_amg.py MUFLOW OUTDIR [--repeats N] [--quick] [--skip-side] [--side-only]
                   [--scaling-only]

Runs `muflow` processes (OMP_NUM_THREADS as the caller sets it, 2 in `make
bench-amg`), each timed from start to exit (wall), with its CPU time and
peak resident memory from wait4's rusage and the 1-minute load average
before and after:

1. side by side: the heap at the fixed tilt 0.4061 (heap.flow_rate = 0) on
   140 x 200 with solver.preconditioner = lu, = amg, = amg with
   solver.preconditioner_reuse = 2 (a hierarchy serves up to two further
   steps), and = gmg (the matrix-free geometric multigrid), alternating run by run, N repeats each (default 2); medians and
   the LU / AMG ratios (the LU's own reuse is no faster: a kept
   factorisation needs 10-30 GMRES iterations and is rebuilt every other
   step, 27.5 s against 22.9 s at 70 x 100);
2. the heap on 280 x 400 with the AMG to its steady state (the LU would take
   about 3 GB: not run);
3. Krylov iterations per Newton step: the heap from 35 x 50 to 280 x 400,
   whole solves with the inexact Newton forcing term (the default) and the
   first 10 steps at the fixed linear tolerance 1e-8
   (solver.inexact_newton = off); the Bingham cavity (cases/bingham_cavity.ini)
   from 32 x 32 to 256 x 256, its first 8 steps with the AMG, with its
   grad-div augmentation (the case's) and without;
4. the geometric multigrid's scaling: the heap from 35 x 50 to 280 x 400
   with solver.preconditioner = gmg, whole solves (iterations per Newton
   step and their growth per doubling), and 280 x 400 with gmg and with the
   LU, one run each (time and memory);
5. the cavity's coupled step by GMRES (solver.coupled = on,
   solver.augmentation = 0, solver.preconditioner = amg), whole steady
   solves from 32 x 32 to 256 x 256 with solver.newton_below = 1e-3 on
   every grid (the same march everywhere; the case's 1e-2 switches to the
   tangent earlier and at 256 x 256 cuts dt to 2e-6), iterations per step.

Writes OUTDIR/amg_runs.csv (one row a run) and OUTDIR/amg_table.md, and
prints the tables.  --quick: one repeat, no 280 x 400, grids to 140 x 200
and 128 x 128 (a smoke test of the script); --skip-side: parts 2 to 5 only
(the iteration table's 140 x 200 whole solve is then run once with amg);
--side-only: part 1 alone; --scaling-only: parts 4 and 5 alone."""
import csv
import os
import statistics
import subprocess
import sys

from summary_ini import loadavg, summary, timed_run

TILT = 0.4061
HEAP_GRIDS = [(35, 50), (70, 100), (140, 200), (280, 400)]
CAVITY_GRIDS = [32, 64, 128, 256]


def run(muflow, outdir, tag, case, overrides):
    """One muflow process: wall, CPU, peak memory, load, summary, history."""
    d = os.path.join(outdir, "amg_runs", tag)
    args = [muflow, case, f"output.dir={d}", "output.quiet=on", "output.fields=off"] + overrides
    print(" ".join(args), flush=True)
    load0 = loadavg()
    code, wall, cpu, mb = timed_run(args, stdout=subprocess.DEVNULL)
    load1 = loadavg()
    s = summary(os.path.join(d, "summary.ini"))
    iters = []
    with open(os.path.join(d, "history.csv")) as f:
        for row in csv.DictReader(f):
            if int(row["step"]) > 0:
                iters.append(int(row["linear_iterations"]))
    r = dict(tag=tag, wall=wall, cpu=cpu, mb=mb,
             load0=load0, load1=load1, status=s.get("status", f"exit {code}"),
             steps=int(s.get("steps", 0)), rejected=int(s.get("rejected_steps", 0)),
             flow_rate=s.get("flow_rate", ""), u_surface=s.get("u_surface_mid", ""),
             psi_max=s.get("psi_max", ""),
             iters_mean=statistics.mean(iters) if iters else float("nan"),
             iters_max=max(iters) if iters else 0)
    print(f"  {r['status']}, {r['steps']} steps, {wall:.1f} s wall, {r['cpu']:.1f} s CPU, "
          f"{r['mb']:.0f} MB, load {load0:.2f} -> {load1:.2f}", flush=True)
    return r


def heap(muflow, outdir, tag, ny, nz, *extra):
    return run(muflow, outdir, tag, "cases/heap.ini",
               [f"domain.ny={ny}", f"domain.nz={nz}", "heap.flow_rate=0",
                f"physics.tilt={TILT}"] + list(extra))


def main():
    muflow, outdir = sys.argv[1], sys.argv[2]
    quick = "--quick" in sys.argv
    repeats = 1 if quick else 2
    if "--repeats" in sys.argv:
        repeats = int(sys.argv[sys.argv.index("--repeats") + 1])
    os.makedirs(outdir, exist_ok=True)
    runs, lines = [], []

    # 1. side by side at 140 x 200, alternating
    variants = {"lu": ["solver.preconditioner=lu"], "amg": ["solver.preconditioner=amg"],
                "amg, reuse 2": ["solver.preconditioner=amg", "solver.preconditioner_reuse=2"],
                "gmg": ["solver.preconditioner=gmg"]}
    side = {pc: [] for pc in variants}
    if "--scaling-only" in sys.argv:
        scaling(muflow, outdir, quick, side, runs, lines)
        write_tables(outdir, runs, lines)
        return
    skip_side = "--skip-side" in sys.argv
    if skip_side:
        side["amg"].append(heap(muflow, outdir, "heap140_amg", 140, 200,
                                "solver.preconditioner=amg"))
        runs.append(side["amg"][0])
    for k in range(0 if skip_side else repeats):
        for pc, extra in variants.items():
            tag = pc.replace(", ", "_").replace(" ", "")
            r = heap(muflow, outdir, f"heap140_{tag}_{k}", 140, 200, *extra)
            side[pc].append(r)
            runs.append(r)
    med = {pc: {key: statistics.median(r[key] for r in rs) for key in ("wall", "cpu", "mb")}
           for pc, rs in side.items() if rs}
    lines += ["Heap at the tilt 0.4061, 140 x 200, whole steady solve from rest "
              f"(OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS', '?')}; "
              f"OPENBLAS_CORETYPE={os.environ.get('OPENBLAS_CORETYPE', 'unset: muflow names it from the CPU')}; "
              f"{repeats} run(s) each, alternating; medians):", "",
              "| preconditioner | wall s | CPU s | peak MB | steps (rejected) | Q* | u_surface mid "
              "| iterations per step mean (max) | load before-after |",
              "|---|---|---|---|---|---|---|---|---|"]
    for pc, rs in side.items():
        if not rs:
            continue
        r0 = rs[0]
        walls = ", ".join(f"{r['wall']:.1f}" for r in rs)
        loads = "; ".join(f"{r['load0']:.2f}-{r['load1']:.2f}" for r in rs)
        lines.append(f"| {pc} | {med[pc]['wall']:.1f} ({walls}) | {med[pc]['cpu']:.1f} "
                     f"| {med[pc]['mb']:.0f} | {r0['steps']} ({r0['rejected']}) | {r0['flow_rate']} "
                     f"| {r0['u_surface']} | {r0['iters_mean']:.1f} ({r0['iters_max']}) | {loads} |")
    if "lu" in med:
        lines.append("")
        for pc in med:
            if pc != "lu":
                lines.append(f"LU / {pc}: wall {med['lu']['wall'] / med[pc]['wall']:.2f}x, "
                             f"CPU {med['lu']['cpu'] / med[pc]['cpu']:.2f}x, "
                             f"peak memory {pc} / LU {med[pc]['mb'] / med['lu']['mb']:.2f}")
    lines.append("")

    if "--side-only" in sys.argv:
        write_tables(outdir, runs, lines)
        return

    # 2. and 3. the heap's grids with the AMG: whole solves (forcing term)
    # and the first 10 steps at the fixed tolerance
    grids = HEAP_GRIDS[:3] if quick else HEAP_GRIDS
    whole, fixed = {}, {}
    for ny, nz in grids:
        if (ny, nz) == (140, 200):
            whole[(ny, nz)] = side["amg"][0]
        else:
            whole[(ny, nz)] = heap(muflow, outdir, f"heap{ny}_amg", ny, nz,
                                   "solver.preconditioner=amg")
            runs.append(whole[(ny, nz)])
        fixed[(ny, nz)] = heap(muflow, outdir, f"heap{ny}_amg_fixed10", ny, nz,
                               "solver.preconditioner=amg", "solver.inexact_newton=off",
                               "solver.max_steps=10")
        runs.append(fixed[(ny, nz)])
    if (280, 400) in whole:
        r = whole[(280, 400)]
        lines += ["Heap 280 x 400 with the AMG, whole steady solve from rest:", "",
                  f"{r['status']}, {r['steps']} steps ({r['rejected']} rejected), "
                  f"{r['wall']:.1f} s wall, {r['cpu']:.1f} s CPU, peak {r['mb']:.0f} MB, "
                  f"Q* {r['flow_rate']}, u_surface mid {r['u_surface']}, "
                  f"load {r['load0']:.2f}-{r['load1']:.2f}", ""]
    lines += ["Krylov (GMRES) iterations per Newton step, heap with the AMG:", "",
              "| grid | whole solve, forcing term: steps, mean (max) | growth | first 10 steps, "
              "tolerance 1e-8: mean (max) | growth |", "|---|---|---|---|---|"]
    prev = None
    for g in grids:
        w, f = whole[g], fixed[g]
        gw = f"{w['iters_mean'] / prev[0]:.2f}x" if prev else ""
        gf = f"{f['iters_mean'] / prev[1]:.2f}x" if prev else ""
        lines.append(f"| {g[0]} x {g[1]} | {w['steps']}, {w['iters_mean']:.1f} ({w['iters_max']}) "
                     f"| {gw} | {f['iters_mean']:.1f} ({f['iters_max']}) | {gf} |")
        prev = (w["iters_mean"], f["iters_mean"])

    # 3. the cavity: its first 8 steps (Picard: the case switches to the
    # tangent after a 100-fold fall of the residual) with and without the
    # augmentation
    lines += ["", "Bingham cavity (Vola Bn = 10), first 8 steps with the AMG: GMRES iterations "
              "per step, mean (max; 500 is the cap):", "",
              "| grid | augmentation (the case's) | growth | without augmentation | growth |",
              "|---|---|---|---|---|"]
    prev = None
    for n in CAVITY_GRIDS[:3] if quick else CAVITY_GRIDS:
        common = [f"domain.nx={n}", f"domain.nz={n}", "solver.preconditioner=amg",
                  "solver.max_steps=8"]
        if n <= 128:
            a = run(muflow, outdir, f"cavity{n}_amg_aug", "cases/bingham_cavity.ini", common)
            runs.append(a)
        else:
            a = None
        b = run(muflow, outdir, f"cavity{n}_amg_noaug", "cases/bingham_cavity.ini",
                common + ["solver.augmentation=0"])
        runs.append(b)
        ga = f"{a['iters_mean'] / prev[0]:.2f}x" if a and prev and prev[0] else ""
        gb = f"{b['iters_mean'] / prev[1]:.2f}x" if prev else ""
        astr = f"{a['iters_mean']:.1f} ({a['iters_max']})" if a else "not run"
        lines.append(f"| {n} x {n} | {astr} | {ga} | {b['iters_mean']:.1f} ({b['iters_max']}) "
                     f"| {gb} |")
        prev = (a["iters_mean"] if a else None, b["iters_mean"])

    scaling(muflow, outdir, quick, side, runs, lines)
    write_tables(outdir, runs, lines)


def growth_rows(results, label):
    """Table rows: grid, steps (rejected), iterations a step mean (max),
    growth of the mean against the row above."""
    rows, prev = [], None
    for grid, r in results:
        g = f"{r['iters_mean'] / prev:.2f}x" if prev else ""
        rows.append(f"| {label(grid)} | {r['steps']} ({r['rejected']}) "
                    f"| {r['iters_mean']:.1f} ({r['iters_max']}) | {g} |")
        prev = r["iters_mean"]
    return rows


def scaling(muflow, outdir, quick, side, runs, lines):
    """Parts 4 and 5: the multigrid's and the coupled GMRES's iterations
    per Newton step against the grid, whole steady solves."""
    grids = HEAP_GRIDS[:3] if quick else HEAP_GRIDS
    gmg = []
    for ny, nz in grids:
        if (ny, nz) == (140, 200) and side.get("gmg"):
            r = side["gmg"][0]
        else:
            r = heap(muflow, outdir, f"heap{ny}_gmg", ny, nz, "solver.preconditioner=gmg")
            runs.append(r)
        gmg.append(((ny, nz), r))
    lines += ["", "Heap with the geometric multigrid (gmg), whole steady solves from rest: "
              "GMRES iterations per Newton step:", "",
              "| grid | steps (rejected) | its a step, mean (max) | growth |", "|---|---|---|---|"]
    lines += growth_rows(gmg, lambda g: f"{g[0]} x {g[1]}")
    if not quick:
        r_lu = heap(muflow, outdir, "heap280_lu", 280, 400, "solver.preconditioner=lu")
        runs.append(r_lu)
        r_mg = gmg[-1][1]
        lines += ["", "Heap 280 x 400, one run each:", "",
                  "| preconditioner | status | steps | wall s | peak MB | u_surface mid | load |",
                  "|---|---|---|---|---|---|---|"]
        for name, r in (("gmg", r_mg), ("lu", r_lu)):
            lines.append(f"| {name} | {r['status']} | {r['steps']} | {r['wall']:.1f} "
                         f"| {r['mb']:.0f} | {r['u_surface']} "
                         f"| {r['load0']:.2f}-{r['load1']:.2f} |")
        lines += ["", f"LU / gmg: wall {r_lu['wall'] / r_mg['wall']:.2f}x, peak memory "
                  f"gmg / LU {r_mg['mb'] / r_lu['mb']:.2f}"]

    coupled = []
    for n in CAVITY_GRIDS[:3] if quick else CAVITY_GRIDS:
        r = run(muflow, outdir, f"cavity{n}_coupled_gmres", "cases/bingham_cavity.ini",
                [f"domain.nx={n}", f"domain.nz={n}", "solver.coupled=on",
                 "solver.augmentation=0", "solver.preconditioner=amg",
                 "solver.newton_below=1e-3"])
        runs.append(r)
        coupled.append((n, r))
    lines += ["", "Bingham cavity (Vola Bn = 10), the coupled step by GMRES "
              "(solver.coupled=on, augmentation 0, amg), newton_below 1e-3 on every grid, "
              "whole steady solves: GMRES iterations per Newton step:", "",
              "| grid | steps (rejected) | its a step, mean (max) | growth |", "|---|---|---|---|"]
    lines += growth_rows(coupled, lambda n: f"{n} x {n}")
    lines.append("")
    lines.append("psi_max: " + ", ".join(f"{n}: {r['psi_max']} ({r['status']})"
                                         for n, r in coupled))


def write_tables(outdir, runs, lines):
    with open(os.path.join(outdir, "amg_runs.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(runs[0].keys()))
        w.writeheader()
        w.writerows(runs)
    with open(os.path.join(outdir, "amg_table.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
