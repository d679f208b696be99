#!/usr/bin/python3
"""The stopping height of the nonlocal granular fluidity (rheology.law = ngf)
down a rough incline, against the closed form, and the flow rule above it.

usage: ngf_hstop.py MUFLOW OUTDIR [section.key=value ...]

Runs cases/ngf_incline.ini through the muflow command (the caller's
OMP_NUM_THREADS).  For five angles and N = 10, 20, 40 cells across the
layer (about N cells per stopping height, since the layer is within a few
per cent of it), bisects in the layer's height H between 0.5 and 1.5 times
the closed form

    H_stop = (pi / 2) A d / sqrt(tan(theta) - mu_s)

(the height at which g = 0 loses its stability: A^2 d^2 g'' + (tan(theta) -
mu_s) g = 0 with g(0) = 0, g'(H) = 0 has the solution sin(pi z / (2 H)) there;
Kamrin & Henann 2015), each run from rest (flows(): how a run is judged).
Then, on N = 40, the depth-averaged velocity of layers of 1.25 .. 6 H_stop
against Pouliquen's flow rule u / sqrt(g H) = beta H / h_stop, beta fitted
(and Forterre & Pouliquen's beta H / h_stop - gamma), beside the local law's
(A = 0) Bagnold value.  Writes OUTDIR/ngf_hstop.csv, ngf_hstop.md (the
table) and ngf_flow_rule.csv.  4 minutes on one thread of the busy 2-core
machine (load 7 to 10)."""
import csv
import math
import os
import subprocess
import sys

from summary_ini import summary

HERE = os.path.dirname(os.path.abspath(__file__))
CASE = os.path.join(HERE, "..", "cases", "ngf_incline.ini")
ANGLES_DEG = [22.0, 23.0, 24.0, 25.0, 26.0]
CELLS = [10, 20, 40]
MU_S, A, B, D, PHI = 0.3819, 0.48, 0.9377, 1.0, 0.6
BISECTIONS = 12            # bracket 1 H_stop wide: 2.4e-4 H_stop at the end
FLOW_U = 1e-4
PICARD_DT = 1e6
PICARD_STEPS = 1000
MAX_STEPS = 20000
RULE_RATIOS = [1.25, 1.5, 2.0, 3.0, 4.0, 6.0]


def closed_form(theta):
    return 0.5 * math.pi * A * D / math.sqrt(math.tan(theta) - MU_S)


def run(muflow, outdir, name, args):
    d = os.path.join(outdir, name)
    cmd = [muflow, CASE, "output.fields=off", "output.quiet=on", "output.dir=" + d,
           "solver.max_steps=%d" % MAX_STEPS] + args
    rc = subprocess.run(cmd, stdout=subprocess.DEVNULL).returncode
    if rc not in (0, 3):
        raise SystemExit("%s: exit %d" % (" ".join(cmd), rc))
    return d


def surface_velocity(muflow, outdir, theta, n, H, steps, extra):
    d = run(muflow, outdir, "bisect", ["physics.tilt=%.17g" % theta, "domain.lz=%.17g" % H,
                                        "domain.nz=%d" % n, "solver.mode=transient",
                                        "solver.dt=%g" % PICARD_DT, "solver.end_time=1e300",
                                        "solver.max_steps=%d" % steps] + extra)
    return float(summary(os.path.join(d, "summary.ini"))["u_surface"])


def flows(muflow, outdir, theta, n, H, extra):
    """From rest, each step of PICARD_DT is one Picard iteration, and while
    the flow is at lambda's scale the iteration is linear: u_k = a (r^k - 1)
    / (r - 1) + (the other modes: a bounded sum), r the growth factor of the
    least stable mode, above 1 where the layer flows.  u_2M / u_M = r^M + 1
    then tells r > 1 (above 2) from r < 1; a layer far above its stopping
    height has reached its flowing state (u above FLOW_U sqrt(g H))."""
    u1 = surface_velocity(muflow, outdir, theta, n, H, PICARD_STEPS, extra)
    u2 = surface_velocity(muflow, outdir, theta, n, H, 2 * PICARD_STEPS, extra)
    return u2 > FLOW_U * math.sqrt(H) or u2 > 2.0 * u1


def bisect(muflow, outdir, theta, n, extra):
    hs = closed_form(theta)
    lo, hi = 0.5 * hs, 1.5 * hs
    if flows(muflow, outdir, theta, n, lo, extra) or not flows(muflow, outdir, theta, n, hi, extra):
        raise SystemExit("theta %.4g, N %d: the bracket [0.5, 1.5] H_stop does not straddle "
                         "the stopping height" % (theta, n))
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        if flows(muflow, outdir, theta, n, mid, extra):
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def depth_averaged(d):
    with open(os.path.join(d, "profile.csv")) as f:
        u = [float(r["u"]) for r in csv.DictReader(f)]
    return sum(u) / len(u)


def main():
    if len(sys.argv) < 3:
        raise SystemExit(__doc__)
    muflow, outdir, extra = sys.argv[1], sys.argv[2], sys.argv[3:]
    os.makedirs(outdir, exist_ok=True)
    rows = []
    for deg in ANGLES_DEG:
        theta = math.radians(deg)
        hs = closed_form(theta)
        for n in CELLS:
            h = bisect(muflow, outdir, theta, n, extra)
            rows.append({"theta_deg": deg, "cells": n, "h_stop_closed": hs, "h_stop": h,
                         "rel_error": h / hs - 1.0})
            print("theta %g N %d: h_stop %.5f closed form %.5f (%+.2f%%)" %
                  (deg, n, h, hs, 100 * (h / hs - 1)), flush=True)
    with open(os.path.join(outdir, "ngf_hstop.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    rule = []
    for deg in ANGLES_DEG:
        theta = math.radians(deg)
        hs = closed_form(theta)
        for ratio in RULE_RATIOS:
            H = ratio * hs
            # Picard iterations (transient steps of PICARD_DT) to the steady
            # flow: the steady mode's stall check ends the slow growth from
            # rest of the thinner layers
            d = run(muflow, outdir, "rule", ["physics.tilt=%.17g" % theta, "domain.lz=%.17g" % H,
                                             "domain.nz=40", "solver.mode=transient",
                                             "solver.dt=%g" % PICARD_DT, "solver.end_time=1e300",
                                             "solver.steady_tolerance=1e-10"] + extra)
            res = summary(os.path.join(d, "summary.ini"))
            fr = depth_averaged(d) / math.sqrt(H)
            # the local limit (A = 0): Bagnold's profile of mu = mu_s + b I,
            # depth-averaged u / sqrt(g H) = (2/5) I sqrt(phi cos) H / d
            local = 0.4 * (math.tan(theta) - MU_S) / B * math.sqrt(PHI * math.cos(theta)) * H / D
            rule.append({"theta_deg": deg, "H_over_h_stop": ratio, "status": res["status"],
                         "froude": fr, "froude_local": local})
            print("theta %g H/h_stop %g: %s, u/sqrt(g H) %.5f (local law %.5f)" %
                  (deg, ratio, res["status"], fr, local), flush=True)
    with open(os.path.join(outdir, "ngf_flow_rule.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rule[0]))
        w.writeheader()
        w.writerows(rule)
    # Pouliquen's Fr = beta H / h_stop by least squares through 0, and
    # Forterre & Pouliquen's Fr = beta H / h_stop - gamma
    pts = [(r["H_over_h_stop"], r["froude"]) for r in rule if r["status"] == "steady"]
    beta = sum(x * y for x, y in pts) / sum(x * x for x, _ in pts)
    spread = max(abs(y / (beta * x) - 1.0) for x, y in pts)
    n = len(pts)
    mx, my = sum(x for x, _ in pts) / n, sum(y for _, y in pts) / n
    beta2 = sum((x - mx) * (y - my) for x, y in pts) / sum((x - mx) ** 2 for x, _ in pts)
    gamma = beta2 * mx - my
    spread2 = max(abs(y - (beta2 * x - gamma)) for x, y in pts)
    with open(os.path.join(outdir, "ngf_hstop.md"), "w") as f:
        f.write("| theta | H_stop closed form | N = 10 | N = 20 | N = 40 |\n|---|---|---|---|---|\n")
        for deg in ANGLES_DEG:
            rs = [r for r in rows if r["theta_deg"] == deg]
            f.write("| %g deg | %.4f | %s |\n" % (deg, rs[0]["h_stop_closed"], " | ".join(
                "%.4f (%+.2f%%)" % (r["h_stop"], 100 * r["rel_error"]) for r in rs)))
        f.write("\nflow rule on N = 40, %d steady layers: Fr = beta H / h_stop with beta = %.4f "
                "(least squares through 0), largest deviation %.1f%%; Fr = beta H / h_stop - "
                "gamma with beta = %.4f, gamma = %.4f, largest deviation %.4f in Fr\n" %
                (n, beta, 100 * spread, beta2, gamma, spread2))
    print("beta %.4f, largest deviation %.1f%%; affine beta %.4f gamma %.4f, largest deviation "
          "%.4f" % (beta, 100 * spread, beta2, gamma, spread2))


if __name__ == "__main__":
    main()
