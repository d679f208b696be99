"""The Bingham cavity against Vola, Boscardin & Latche (2003): the vertical
mid-line u(z) against their fig. 3 at the run's Bingham number, psi_max
against Bn with their fig. 2a curve and the augmented-Lagrangian values of
the reference file, and the run's stream function."""
import math
import os

import numpy as np

from . import figure
from .run import reference_curve

DATA = "vola2003_cavity.csv"


def bn_vola(run):
    """Bn in Vola's convention: sqrt(2) tau_0 L / (mu_p U) (cases/bingham_cavity.ini)."""
    return math.sqrt(2.0) * run.num("rheology.yield_stress") * run.num("domain.lx") / (
        run.num("rheology.plastic_viscosity") * abs(run.num("boundary.lid_velocity")))


def stream_function(run):
    """(x faces, z faces, psi at the corners), u = d psi/dz, psi = 0 on the
    base, from the last field file's x-face velocities (mean over y)."""
    import h5py
    with h5py.File(run.fields[-1][1], "r") as f:
        u = np.asarray(f["u"][...], dtype=float).mean(axis=1)  # (nz, nx + 1)
        n, length = [int(v) for v in f.attrs["n"]], [float(v) for v in f.attrs["len"]]
    hz = length[2] / n[2]
    psi = np.vstack([np.zeros(u.shape[1]), np.cumsum(u * hz, axis=0)])
    return np.linspace(0, length[0], u.shape[1]), np.linspace(0, length[2], n[2] + 1), psi


def plot(run, out, units):
    bn = bn_vola(run)
    ref = run.reference(DATA)
    fig = figure.new(15.0, 5.0)
    ax_mid, ax_psi, ax_map = fig.subplots(1, 3, gridspec_kw={"width_ratios": [1, 1.1, 1]})

    t = run.table("profile.csv")
    if t is not None:
        ax_mid.plot(t["u"], t["z"], "o-", ms=3, label="muflow, %d cells" % t.rows)
    if ref:
        z, u = reference_curve(ref, "midline", bn)
        if z.size:
            ax_mid.plot(u, z, "k.", ms=4, label="Vola et al. 2003, fig. 3")
        else:
            print("%s has no mid-line at Bn = %g" % (ref, bn))
    ax_mid.set_xlabel(units.label("u", "velocity") + " on x = L/2")
    ax_mid.set_ylabel(units.label("z", "length"))
    ax_mid.set_title("mid-line, Bn (Vola) = %.4g" % bn, fontsize=10)
    ax_mid.legend(fontsize=8)

    if ref:
        b, p = reference_curve(ref, "psi_max")
        ax_psi.loglog(b[b > 0], p[b > 0], "k-", lw=1, label="Vola et al. 2003, fig. 2a")
        b, p = reference_curve(ref, "psi_max_al")
        ax_psi.loglog(b[b > 0], p[b > 0], "s", mfc="none", color="0.3",
                      label="augmented Lagrangian, 128 x 128")
    psi = run.num("psi_max")
    if math.isfinite(psi) and bn > 0:
        ax_psi.loglog([bn], [psi], "o", color="C0", ms=8, label="muflow: %.4g" % psi)
    ax_psi.set_xlabel("Bn (Vola's convention)")
    ax_psi.set_ylabel(r"$\psi_{max}$ / (U L)")
    ax_psi.set_title("largest |stream function| against Bn", fontsize=10)
    ax_psi.legend(fontsize=8)
    for a in (ax_mid, ax_psi):
        a.grid(alpha=0.3)

    if run.fields:
        x, z, s = stream_function(run)
        cs = ax_map.contourf(x, z, s, levels=20, cmap="viridis")
        if np.ptp(s) > 0:
            ax_map.contour(x, z, s, levels=np.linspace(s.min(), s.max(), 12)[1:-1], colors="w",
                           linewidths=0.6, linestyles="solid")
        fig.colorbar(cs, ax=ax_map, label=r"$\psi$ / (U L)", shrink=0.9)
        ax_map.set_aspect("equal")
        ax_map.set_xlabel(units.label("x", "length"))
        ax_map.set_ylabel(units.label("z", "length"))
        ax_map.set_title("stream function (lid at the top moving along +x)", fontsize=10)
    else:
        ax_map.set_axis_off()
    fig.suptitle("%s against Vola, Boscardin & Latche (2003)\n%s" % (
        run.name, figure.headline_text(run, ("err_midline", "psi_max"))), fontsize=10)
    return figure.save(fig, out, "compare.png", "against Vola et al. 2003, %s" % (
        os.path.basename(ref) if ref else "no reference file"))
