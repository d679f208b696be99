#!/usr/bin/python3
"""Heap study: the tilt for the experiment's flow rates, a mesh study, plots.

usage: heap_study.py MUFLOW OUTDIR [--quick]

Runs cases/heap.ini through the muflow command (2 threads, the caller's
OMP_NUM_THREADS): the tilt search for Q* = 14.9, 40.2 and 90.1 at 70 x 100
(the paper's mesh), and for Q* = 40.2 at 35 x 50 and 140 x 200.  Each finer
search is bracketed by the coarser tilt +- 0.01 rad, which only saves solves:
the bracket is checked by the search itself.  Writes OUTDIR/heap_table.md,
heap_runs.csv and the plots heap_surface_velocity.png, heap_flowing_depth.png,
heap_velocity_maps.png.  --quick runs the mesh study only at 35 x 50 and
70 x 100 (for a smoke test of the script)."""
import csv
import glob
import os
import subprocess
import sys

import h5py
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from summary_ini import summary

TARGETS = [14.9, 40.2, 90.1]
MESHES = [(35, 50), (70, 100), (140, 200)]
PAPER_MESH = (70, 100)
STUDY_TARGET = 40.2



def run(muflow, outdir, ny, nz, q, bracket):
    d = os.path.join(outdir, "heap_runs", f"q{q:g}_{ny}x{nz}")
    args = [muflow, "cases/heap.ini", f"domain.ny={ny}", f"domain.nz={nz}",
            f"heap.flow_rate={q}", f"output.dir={d}", "solver.progress_interval=60"]
    if bracket:
        args += [f"heap.tilt_min={bracket[0]:.6f}", f"heap.tilt_max={bracket[1]:.6f}",
                 f"physics.tilt={0.5 * (bracket[0] + bracket[1]):.6f}"]
    print(" ".join(args), flush=True)
    p = subprocess.run(args, stdout=subprocess.PIPE, text=True)
    for line in p.stdout.splitlines():
        if line.startswith("heap:"):
            print("  " + line, flush=True)
    s = summary(os.path.join(d, "summary.ini"))
    if p.returncode != 0 or s.get("search_converged") != "true":
        sys.exit(f"heap study: the search for Q* = {q} at {ny} x {nz} failed: "
                 f"{s.get('message', p.returncode)}")
    prof = np.genfromtxt(os.path.join(d, "heap.csv"), delimiter=",", names=True)
    fields = sorted(glob.glob(os.path.join(d, "fields_*.h5")))[-1]
    with h5py.File(fields) as h:
        u = h["u"][:, :, 0]                      # (z, y) cell centres
    return dict(q=q, ny=ny, nz=nz, summary=s, profile=prof, u=u)


def across_channel(path, curves, ylabel, title):
    """A plot of quantities against y across the half channel."""
    fig, ax = plt.subplots(figsize=(6, 4))
    for y, v, style in curves:
        ax.plot(y, v, **style)
    ax.set_xlabel("y / d (side wall at 0, mid-plane at 70)")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main():
    muflow, outdir = sys.argv[1], sys.argv[2]
    quick = "--quick" in sys.argv
    os.makedirs(outdir, exist_ok=True)
    runs = []
    # the mesh study for Q* = 40.2, coarse to fine, each bracketed by the last
    bracket = None
    for ny, nz in MESHES[:2] if quick else MESHES:
        r = run(muflow, outdir, ny, nz, STUDY_TARGET, bracket)
        runs.append(r)
        t = float(r["summary"]["tilt"])
        bracket = (t - 0.01, t + 0.01)
    paper = {STUDY_TARGET: next(r for r in runs if (r["ny"], r["nz"]) == PAPER_MESH)}
    for q in TARGETS:
        if q not in paper:
            paper[q] = run(muflow, outdir, *PAPER_MESH, q, None)
            runs.append(paper[q])

    with open(os.path.join(outdir, "heap_runs.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["q_target", "ny", "nz", "tilt", "flow_rate", "solves", "steps_total",
                    "wall_seconds", "u_surface_mid", "depth_mid"])
        for r in runs:
            s = r["summary"]
            w.writerow([r["q"], r["ny"], r["nz"], s["tilt"], s["flow_rate"], s["solves"],
                        s["steps_total"], s["wall_seconds"], s["u_surface_mid"],
                        s["depth_mid"]])

    lines = ["| Q* target | mesh | tilt (rad) | tilt (deg) | Q* | solves | steps | wall (s) "
             "| u_surface mid-plane | flowing depth mid-plane |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in runs:
        s = r["summary"]
        t = float(s["tilt"])
        lines.append(f"| {r['q']:g} | {r['ny']} x {r['nz']} | {t:.5f} | {np.degrees(t):.3f} "
                     f"| {float(s['flow_rate']):.4f} | {s['solves']} | {s['steps_total']} "
                     f"| {float(s['wall_seconds']):.1f} | {float(s['u_surface_mid']):.4f} "
                     f"| {float(s['depth_mid']):.3f} |")
    study = [r for r in runs if r["q"] == STUDY_TARGET]
    if len(study) >= 2:
        a, b = study[-2]["summary"], study[-1]["summary"]
        for key in ("u_surface_mid", "depth_mid", "tilt"):
            x, y = float(a[key]), float(b[key])
            lines.append("")
            lines.append(f"{key}: {x:.6g} at {study[-2]['ny']} x {study[-2]['nz']}, {y:.6g} at "
                         f"{study[-1]['ny']} x {study[-1]['nz']}: change {100 * (y - x) / y:+.2f}%")
    with open(os.path.join(outdir, "heap_table.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))

    colours = {14.9: "C0", 40.2: "C1", 90.1: "C2"}
    surface, depth = [], []
    for q in TARGETS:
        p = paper[q]["profile"]
        t = float(paper[q]["summary"]["tilt"])
        # the wall (y = 0) holds u = 0: the no-slip condition
        surface.append((np.r_[0.0, p["y"]], np.r_[0.0, p["u_surface"]],
                        dict(color=colours[q], label=f"Q* = {q:g} (tilt {np.degrees(t):.2f} deg)")))
        depth.append((p["y"], p["flowing_depth"], dict(color=colours[q], label=f"Q* = {q:g}")))
    for r in study:
        if (r["ny"], r["nz"]) != PAPER_MESH:
            p = r["profile"]
            depth.append((p["y"], p["flowing_depth"],
                          dict(color=colours[STUDY_TARGET], lw=0.8,
                               ls=":" if r["ny"] < PAPER_MESH[0] else "--",
                               label=f"Q* = {STUDY_TARGET:g}, {r['ny']} x {r['nz']}")))
    across_channel(os.path.join(outdir, "heap_surface_velocity.png"), surface,
                   "free-surface velocity / sqrt(g d)",
                   "Heap: surface velocity across the channel (70 x 100)")
    across_channel(os.path.join(outdir, "heap_flowing_depth.png"), depth,
                   "flowing depth / d (u = 1% of the surface u)", "Heap: depth of the flowing layer")

    fig, axes = plt.subplots(1, 3, figsize=(12, 3.8), sharey=True)
    for ax, q in zip(axes, TARGETS):
        u = paper[q]["u"]
        nz, ny = u.shape
        im = ax.imshow(u, origin="lower", extent=[0, 70, 0, 50], aspect="equal", cmap="viridis")
        ax.contour(np.linspace(0.5, 69.5, ny), np.linspace(0.25, 49.75, nz), u,
                   levels=[0.01 * u.max()], colors="w", linewidths=0.8)
        ax.set_title(f"Q* = {q:g}: u / sqrt(g d)")
        ax.set_xlabel("y / d")
        fig.colorbar(im, ax=ax, shrink=0.8)
    axes[0].set_ylabel("z / d")
    fig.suptitle("Heap cross-section: flow velocity (white: 1% of the largest)")
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "heap_velocity_maps.png"), dpi=120)


if __name__ == "__main__":
    main()
