#!/usr/bin/python3
"""Plots of the Bingham cavity study written by bench_cavity:
yielded regions, mid-line profiles against Vola et al. (2003), psi_max
against the Bingham number.  usage: plot_cavity.py OUTDIR"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

out = sys.argv[1]
REF = "cases/data/vola2003_cavity.csv"


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


ref = rows(REF)
table = rows(f"{out}/cavity_table.csv")


def fields(bn):
    r = rows(f"{out}/cavity_fields_bn{bn:g}.csv")
    x = np.array([float(v["x"]) for v in r])
    z = np.array([float(v["z"]) for v in r])
    n = int(round(math.sqrt(len(r))))
    grid = lambda key: np.array([float(v[key]) for v in r]).reshape(n, n)
    return x.reshape(n, n), z.reshape(n, n), grid("u"), grid("w"), grid("yielded")


# yielded regions (|tau| >= tau_0) for Bn = 2, 5, 20 (muflow's convention)
wanted = [2.0, 5.0, 20.0]
have = [b for b in wanted if any(float(t["bn"]) == b for t in table)]
if have:
    fig, axes = plt.subplots(1, len(have), figsize=(4.2 * len(have), 4.2))
    for ax, bn in zip(np.atleast_1d(axes), have):
        x, z, u, w, y = fields(bn)
        ax.contourf(x, z, y, levels=[-0.5, 0.5, 1.5], colors=["0.55", "white"])
        ax.streamplot(x[0], z[:, 0], u, w, color="tab:blue", density=1.1, linewidth=0.7)
        ax.set_title(f"Bn = {bn:g}: unyielded (grey)")
        ax.set_aspect("equal")
        ax.set_xlim(0, 1)
        ax.set_ylim(0, 1)
        ax.set_xlabel("x")
        ax.set_ylabel("z")
    fig.tight_layout()
    fig.savefig(f"{out}/cavity_yield.png", dpi=110)

# mid-line profiles against Vola et al. fig. 3
fig, ax = plt.subplots(figsize=(5.5, 5))
for i, bv in enumerate([0, 1, 10, 100, 1000]):
    pts = [(float(r["coord"]), float(r["value"])) for r in ref
           if r["dataset"] == "midline" and abs(float(r["bn_vola"]) - bv) < 1e-9]
    ours = [t for t in table if abs(float(t["bn_vola"]) - bv) < 1e-6 * max(1, bv)]
    col = f"C{i}"
    if pts:
        ax.plot([p[1] for p in pts], [p[0] for p in pts], "o", ms=3, color=col, mfc="none",
                label=f"Vola et al. Bn={bv}")
    if ours:
        m = rows(f"{out}/cavity_midline_bn{float(ours[0]['bn']):g}.csv")
        ax.plot([float(v["u"]) for v in m], [float(v["z"]) for v in m], "-", color=col,
                label=f"muflow {ours[0]['n']}x{ours[0]['n']}")
ax.set_xlabel("u / U along x = 0.5")
ax.set_ylabel("z")
ax.legend(fontsize=7)
fig.tight_layout()
fig.savefig(f"{out}/cavity_midline.png", dpi=110)

# psi_max against Bn (Vola's convention)
fig, ax = plt.subplots(figsize=(5.5, 4))
v = sorted((float(r["bn_vola"]), float(r["value"])) for r in ref if r["dataset"] == "psi_max")
al = sorted((float(r["bn_vola"]), float(r["value"])) for r in ref if r["dataset"] == "psi_max_al")
ax.plot([p[0] for p in v], [p[1] for p in v], "-", color="0.4", label="Vola et al. fig. 2a")
ax.plot([max(p[0], 0.05) for p in al], [p[1] for p in al], "s", mfc="none",
        label="augmented Lagrangian, 128x128")
ours = sorted((max(float(t["bn_vola"]), 0.05), float(t["psi_max"]), t["n"]) for t in table)
ax.plot([p[0] for p in ours], [p[1] for p in ours], "o", color="C3", label="muflow")
ax.set_xscale("log")
ax.set_yscale("log")
ax.set_xlabel("Bn (Vola et al.'s convention; Bn = 0 drawn at 0.05)")
ax.set_ylabel("max |psi|")
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(f"{out}/cavity_psi.png", dpi=110)
