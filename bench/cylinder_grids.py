#!/usr/bin/python3
"""Grid convergence of the granular cylinder's drag at one forcing
(cases/cylinder.ini, F = 1, p_ext = 10; docs/validation/cylinder.md).

usage: cylinder_grids.py MUFLOW OUTDIR [--grids 4,8,16] [--lambda 1e-2]
                         [--band W [--far 4]] [section.key=value ...]

The first grid (D/h cells across a diameter) starts from rest, each finer
one from the state before it interpolated (solver.initial_state) with
Picard steps until the residual has fallen a hundredfold
(solver.newton_below = 1e-2): from rest the finer grids are not steady in
any sane time.  lambda (default 1e-2, the case's continuation off) is the
same on every grid.  Extra overrides go to every run (for instance
rheology.curve=barker_gray).  With --band W the grids are stretched
(domain.x_band, z_band): D/h cells in the band within W diameters of the
cylinder's centre (x from the symmetry plane to W), growing by
domain.growth outside it to the far grid D/FAR (default D/4; a grid as
fine as the far one is the uniform grid), the first from rest, the others
as above.  Writes OUTDIR/cylinder_grids.md: per grid
(cylinder_bands.md with --band) its cells, steps, wall and CPU seconds, peak memory, the machine's load, U, F_D by
the control volume and by the surface integral, the successive
differences of F_D and the observed order where three grids give one, and
the sheared layer at the body (max |D| and h max |D|, bench/cylinder_layer.py),
with OUTDIR/cylinder_grids_layer.png."""
import argparse
import math
import os
import subprocess

from cylinder_layer import layer, plot
from summary_ini import loadavg, summary, timed_run

HERE = os.path.dirname(os.path.abspath(__file__))
CASE = os.path.join(HERE, "..", "cases", "cylinder.ini")


def main():
    ap = argparse.ArgumentParser(usage=__doc__)
    ap.add_argument("muflow")
    ap.add_argument("outdir")
    ap.add_argument("overrides", nargs="*")
    ap.add_argument("--grids", default="4,8,16")
    ap.add_argument("--lambda", dest="lam", default="1e-2")
    ap.add_argument("--band", type=float, default=0.0)
    ap.add_argument("--far", type=int, default=4)
    a = ap.parse_args()
    grids = [int(g) for g in a.grids.split(",")]
    muflow, outdir, extra, lam = a.muflow, a.outdir, a.overrides, a.lam
    band, far = a.band, a.far
    os.makedirs(outdir, exist_ok=True)
    rows, previous = [], None
    for n in grids:
        if band > 0 and n != far:
            d = os.path.join(outdir, f"cylinder_band_d{n}")
            grid = [f"domain.nx={10 * far}", f"domain.nz={30 * far}",
                    f"domain.x_band=0 {band} {1.0 / n!r}",
                    f"domain.z_band={15 - band} {15 + band} {1.0 / n!r}"]
        else:
            d = os.path.join(outdir, f"cylinder_grid_d{n}")
            grid = [f"domain.nx={10 * n}", f"domain.nz={30 * n}"]
        run = [muflow, CASE] + grid + [f"rheology.lambda={lam}", "solver.continuation=1",
                                       f"output.dir={d}"] + extra
        if previous:
            run += ["solver.newton_below=1e-2",
                    f"solver.initial_state={os.path.join(previous, 'checkpoint.h5')}"]
        print(" ".join(run), flush=True)
        load = loadavg()
        code, wall, cpu, mb = timed_run(run, stdout=subprocess.DEVNULL)
        res = summary(os.path.join(d, "summary.ini"))
        if code != 0 or res.get("status") != "steady":
            print(f"D/{n}: {res.get('status')}: {res.get('message')}", flush=True)
            break
        rows.append({"n": n, "steps": int(res["steps"]), "wall": wall, "cpu": cpu, "mb": mb,
                     "load": load, "U": float(res["mean_velocity"]), "cv": float(res["drag"]),
                     "surface": float(res["drag_surface"]), "layer": layer(d)})
        previous = d
    lines = [f"Granular cylinder, F = 1, p_ext = 10, lambda {lam}"
             + (f", stretched: D/h within {band} D of the centre, D/{far} far"
                if band > 0 else "")
             + (f", {' '.join(extra)}" if extra else "")
             + f"; OMP_NUM_THREADS = {os.environ.get('OMP_NUM_THREADS', '(unset)')}", "",
             "| grid | cells | steps | wall s | CPU s | peak MB | load | U | F_D control volume "
             "| F_D surface | step of F_D | max |D| at the body | h max |D| |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for i, r in enumerate(rows):
        step = f"{r['cv'] - rows[i - 1]['cv']:+.3f}" if i else ""
        cells = f"{r['layer']['n'][0]} x {r['layer']['n'][1]}"
        lines.append(f"| D/{r['n']} | {cells} | {r['steps']} | "
                     f"{r['wall']:.1f} | {r['cpu']:.1f} | {r['mb']:.0f} | {r['load']:.2f} | "
                     f"{r['U']:.4f} | {r['cv']:.3f} | {r['surface']:.3f} | {step} | "
                     f"{r['layer']['max']:.3f} | {r['layer']['h'] * r['layer']['max']:.3f} |")
    lines.append("")
    for i in range(2, len(rows)):
        a, b, c = (rows[j]["cv"] for j in (i - 2, i - 1, i))
        q = (b - a) / (c - b) if c != b else float("inf")
        order = f"{math.log2(q):.2f}" if q > 0 else "none (the steps change sign)"
        lines.append(f"Observed order from D/{rows[i - 2]['n']}, D/{rows[i - 1]['n']}, "
                     f"D/{rows[i]['n']}: {order} (ratio of the steps {q:.3f}).")
    text = "\n".join(lines) + "\n"
    name = "cylinder_bands.md" if band > 0 else "cylinder_grids.md"
    with open(os.path.join(outdir, name), "w") as f:
        f.write(text)
    print(text)
    if rows:
        plot(os.path.join(outdir, name.replace(".md", "_layer.png")), [r["layer"] for r in rows])


if __name__ == "__main__":
    main()
