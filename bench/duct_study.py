#!/usr/bin/python3
"""Duct study (Chauchat & Medale 2010, sec. 4, figs. 10-15): mesh study, plots.

usage: duct_study.py MUFLOW OUTDIR [--meshes 20x40,40x80,80x160] [--reuse]
                     [--model mixed|two_fluid] [--case cases/duct_circular.ini]
                     [--set SECTION.KEY=VALUE ...]

A mesh may carry its own overrides after a colon ("80x160:solver.newton_below=1",
several joined by ':'); "solver.initial_state=previous" starts it from the
previous mesh's solution (grid sequencing).  --case cases/duct_circular.ini runs the circular duct (sec. 4.2, figs.
13-15) instead of the square one; its files are named duct_circular_*
(duct_circular_runs/, duct_circular_table.md, ...) where the square duct's
are duct_*.  --set passes an override to every run (repeatable).

Runs cases/duct_square.ini through the muflow command (the caller's
OMP_NUM_THREADS) on each mesh of the half cross-section (ny x nz; the
paper's are 20 x 40 and 40 x 80), into OUTDIR/duct_runs/NYxNZ (--reuse: a
mesh whose summary.ini says steady is not run again).  Writes
OUTDIR/duct_table.md (per mesh: steps, wall seconds, flow rate of the full
duct, mean velocity against the plane channel's, u_max, the mid-plane's
u_max and mobile layer, and the difference of the mid-plane profile
(midplane.csv, u on the symmetry plane) from the next finer mesh's
interpolated to the coarse heights, RMS and max), and the plots
duct_midplane.png (the mid-plane profiles of every mesh with the plane
channel's exact profile: the paper's fig. 11) and duct_map.png (u over the
whole cross-section of the finest mesh, mirrored about the symmetry plane,
with the bed's top: the paper's fig. 10).  --model two_fluid runs the
two-fluid model (duct.model) into duct_runs_two_fluid/ and writes
duct_table_two_fluid.md, duct_midplane_two_fluid.png and
duct_map_two_fluid.png, and duct_phases_two_fluid.png (u^f and u^p on
the mid-plane column: the paper's fig. 12)."""
import argparse
import glob
import os
import subprocess
import sys

import h5py
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from summary_ini import summary  # noqa: E402

def tag_of(case):
    """The files' prefix: duct for the square duct, else the case's name."""
    name = os.path.splitext(os.path.basename(case))[0]
    return "duct" if name == "duct_square" else name


def run(muflow, outdir, ny, nz, reuse, model, case, extra):
    sfx = "" if model == "mixed" else "_" + model
    d = os.path.join(outdir, tag_of(case) + "_runs" + sfx, f"{ny}x{nz}")
    sp = os.path.join(d, "summary.ini")
    if not (reuse and os.path.exists(sp) and summary(sp).get("status") == "steady"):
        args = [muflow, case, f"domain.ny={ny}", f"domain.nz={nz}", f"output.dir={d}",
                "solver.progress_interval=60", f"duct.model={model}"] + extra
        print(" ".join(args), flush=True)
        p = subprocess.run(args, stdout=subprocess.PIPE, text=True)
        name = os.path.splitext(os.path.basename(case))[0]
        for line in p.stdout.splitlines():
            if line.startswith(name + ":"):
                print("  " + line, flush=True)
        if p.returncode != 0:
            sys.exit(f"duct study: the run at {ny} x {nz} failed ({p.returncode})")
    s = summary(sp)
    if s.get("status") != "steady":
        sys.exit(f"duct study: {ny} x {nz} is {s.get('status')}: {s.get('message')}")
    mid = np.genfromtxt(os.path.join(d, "midplane.csv"), delimiter=",", names=True)
    fields = sorted(glob.glob(os.path.join(d, "fields_*.h5")))[-1]
    with h5py.File(fields) as h:
        u = h["u"][:, :, 0]                      # (z, y) at the u-faces' centres
        up = h["up"][:, :, 0] if "up" in h else None
    return dict(ny=ny, nz=nz, dir=d, summary=s, mid=mid, u=u, up=up)


def case_value(d, section, key):
    """A case key as the run used it (summary.ini repeats every key)."""
    cur = None
    with open(os.path.join(d, "summary.ini")) as f:
        for line in f:
            line = line.split(";")[0].strip()
            if line.startswith("["):
                cur = line.strip("[]")
            elif cur == section and "=" in line:
                k, v = line.split("=", 1)
                if k.strip() == key:
                    return float(v)
    sys.exit(f"duct study: {section}.{key} not in {d}/summary.ini")


def difference(coarse, fine):
    """u on the symmetry plane: the fine profile interpolated (linearly) to
    the coarse heights, minus the coarse one; RMS and max |.|."""
    zf, uf = fine["mid"]["z"], fine["mid"]["u_symmetry"]
    zc, uc = coarse["mid"]["z"], coarse["mid"]["u_symmetry"]
    d = np.interp(zc, zf, uf) - uc
    return float(np.sqrt(np.mean(d * d))), float(np.max(np.abs(d)))


def table(runs, path):
    rows = ["| mesh (y x z) | steps (rejected) | wall s | flow rate (m^3/s, full duct) | "
            "mean velocity / plane | u_max (m/s) | u_max mid-plane | mobile layer mid-plane (m) | "
            "mid-plane diff. to next mesh, RMS / max (m/s) |",
            "|---|---|---|---|---|---|---|---|---|"]
    for i, r in enumerate(runs):
        s = r["summary"]
        diff = ""
        if i + 1 < len(runs):
            rms, mx = difference(r, runs[i + 1])
            diff = f"{rms:.3e} / {mx:.3e}"
        rows.append(
            f"| {r['ny']} x {r['nz']} | {s['steps']} ({s['rejected_steps']}) | "
            f"{float(s['wall_seconds']):.1f} | {float(s['flow_rate']):.6e} | "
            f"{float(s['velocity_ratio']):.5f} | {float(s['u_max']):.6f} | "
            f"{float(s['u_max_midplane']):.6f} | {float(s['mobile_layer_midplane']):.6f} | "
            f"{diff} |")
    s = runs[0]["summary"]
    rows.append("")
    rows.append(f"plane channel (exact, same pressure gradient): flow rate over the duct's "
                f"width {float(s['flow_rate_plane']):.6e} m^3/s, mean velocity "
                f"{float(s['mean_velocity_plane']):.6f} m/s, u_max "
                f"{float(s['u_max_plane']):.6f} m/s, mobile layer "
                f"{float(s['mobile_layer_plane']):.6f} m")
    text = "\n".join(rows) + "\n"
    with open(path, "w") as f:
        f.write(text)
    print(text)


def plot_midplane(runs, path, hp):
    fig, (ax, az) = plt.subplots(1, 2, figsize=(10, 5))
    for r in runs:
        m = r["mid"]
        for a in (ax, az):
            a.plot(m["u_symmetry"], m["z"], ".-", ms=3, lw=1, label=f"{r['ny']} x {r['nz']}")
    m = runs[-1]["mid"]
    # the plane exact profile at the finest mesh's points (u_plane column)
    for a in (ax, az):
        a.plot(m["u_plane"], m["z"], "k--", lw=1, label="plane channel (exact)")
        a.axhline(hp, color="0.6", lw=0.8)
        a.set_xlabel("u on the symmetry plane (m/s)")
        a.set_ylabel("z (m)")
    ax.set_title("mid-plane profiles (y = W/2)")
    ax.legend(loc="upper left", fontsize=8)
    top = hp + 0.002
    lo = hp - 0.016
    az.set_ylim(lo, top)
    sel = (m["z"] > lo) & (m["z"] < top)
    az.set_xlim(-1e-4, 1.2 * max(float(np.max(m["u_symmetry"][sel])), 1e-6))
    az.set_title("zoom: the mobile layer")
    az.locator_params(axis="x", nbins=5)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_map(r, path, hp, D, title):
    u = r["u"]                                    # (nz, ny), y from the side wall
    nz, ny = u.shape
    full = np.concatenate([u, u[:, ::-1]], axis=1)
    # a body's held nodes (the circular duct's wall) are exactly 0: not drawn
    full = np.where(full == 0.0, np.nan, full)
    fig, ax = plt.subplots(figsize=(6, 5.2))
    im = ax.imshow(full, origin="lower", extent=[0, D, 0, D], cmap="viridis", aspect="equal")
    cs = ax.contour(np.linspace(D / (4 * ny), D - D / (4 * ny), 2 * ny),
                    np.linspace(D / (2 * nz), D - D / (2 * nz), nz), full,
                    levels=np.linspace(0.005, 0.045, 9), colors="w", linewidths=0.5)
    ax.clabel(cs, fontsize=6, fmt="%.3f")
    # the top of the fixed bed: where u reaches 1e-3 of its largest value
    ax.contour(np.linspace(D / (4 * ny), D - D / (4 * ny), 2 * ny),
               np.linspace(D / (2 * nz), D - D / (2 * nz), nz), full,
               levels=[1e-3 * float(np.max(full))], colors="orange", linewidths=1.0,
               linestyles="--")
    ax.axhline(hp, color="r", lw=1.5)
    ax.axvline(D / 2, color="w", lw=0.5, ls=":")
    ax.set_xlabel("y (m)")
    ax.set_ylabel("z (m)")
    ax.set_title(f"u (m/s), {title}, {ny} x {nz} per half (mirrored)\n"
                 "red: bed top h_p; dashed: u = 1e-3 u_max (fixed bed below)", fontsize=9)
    fig.colorbar(im, ax=ax, shrink=0.85)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_phases(r, path, hp, phi):
    """Two-fluid: the fluid and particle velocities on the last column (the
    paper's fig. 12, with its offset of 1e-3 on u^p to show it)."""
    um, up = r["u"][:, -1], r["up"][:, -1]
    nz = len(um)
    z = (np.arange(nz) + 0.5) * (r["mid"]["z"][1] - r["mid"]["z"][0])
    bed = z < hp
    uf = np.where(bed, (um - phi * up) / (1.0 - phi), um)
    fig, ax = plt.subplots(figsize=(5, 5))
    ax.plot(uf, z, "b-", lw=1.2, label="fluid u^f")
    ax.plot(np.where(bed, up, np.nan) + 1e-3, z, "r-", lw=1.2, label="particles u^p + 1e-3")
    ax.axhline(hp, color="0.6", lw=0.8)
    ax.set_xlabel("u (m/s), last column (y = W/2 - dy/2)")
    ax.set_ylabel("z (m)")
    ax.set_title(f"two-fluid model, {r['ny']} x {r['nz']}")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("muflow")
    ap.add_argument("outdir")
    ap.add_argument("--meshes", default="20x40,40x80,80x160")
    ap.add_argument("--reuse", action="store_true")
    ap.add_argument("--model", default="mixed", choices=["mixed", "two_fluid"])
    ap.add_argument("--case", default="cases/duct_square.ini")
    ap.add_argument("--set", action="append", default=[], dest="extra")
    a = ap.parse_args()
    sfx = "" if a.model == "mixed" else "_" + a.model
    tag = tag_of(a.case)
    os.makedirs(a.outdir, exist_ok=True)
    runs = []
    for m in a.meshes.split(","):
        size, *own = m.split(":")
        ny, nz = (int(v) for v in size.split("x"))
        own = [f"solver.initial_state={runs[-1]['dir']}"
               if o == "solver.initial_state=previous" else o for o in own]
        runs.append(run(a.muflow, a.outdir, ny, nz, a.reuse, a.model, a.case, a.extra + own))
    hp = case_value(runs[0]["dir"], "duct", "bed_height")
    D = case_value(runs[0]["dir"], "domain", "lz")
    title = "square duct" if tag == "duct" else "circular duct" if "circular" in tag else tag
    table(runs, os.path.join(a.outdir, f"{tag}_table{sfx}.md"))
    plot_midplane(runs, os.path.join(a.outdir, f"{tag}_midplane{sfx}.png"), hp)
    plot_map(runs[-1], os.path.join(a.outdir, f"{tag}_map{sfx}.png"), hp, D, title)
    if a.model == "two_fluid":
        plot_phases(runs[-1], os.path.join(a.outdir, f"{tag}_phases_two_fluid.png"), hp,
                    case_value(runs[0]["dir"], "duct", "phi"))
    print(f"wrote {a.outdir}/{tag}_table{sfx}.md, {tag}_midplane{sfx}.png, {tag}_map{sfx}.png")


if __name__ == "__main__":
    main()
