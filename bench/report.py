#!/usr/bin/python3
"""Turns the CSV tables of bench_scenes and bench_throughput into
bench/out/report.md and its PNG plots, and prints the report.

    /usr/bin/python3 bench/report.py OUTDIR

Needs Debian's python3-matplotlib (and with it numpy): `make bench` installs it.
"""
import csv
import math
import os
import platform
import subprocess
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

OUT = sys.argv[1] if len(sys.argv) > 1 else "bench/out"
REGS = ["simple", "bercovier", "papanastasiou", "mc"]
# stages that are stencil sweeps over the grid (the bandwidth target applies to them)
STENCIL = ["viscosity", "strain", "viscosity_cells", "viscosity_edges", "viscous_apply",
           "advection", "correction", "stress_divergence", "stress_magnitude"]
TARGET_FRACTION = 0.5
TARGET_SPEEDUP = 1.6
TARGET_CHUTE_SECONDS = 1.0
BUSY_CORES = 0.2  # other processes above this: the section's timings are suspect


def read(name):
    path = os.path.join(OUT, name)
    if not os.path.exists(path):
        return None
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def meta(name):
    rows = read(name) or []
    return {r["key"]: r["value"] for r in rows}


def fnum(x, fmt="{:.3g}"):
    try:
        x = float(x)
    except (TypeError, ValueError):
        return str(x)
    if math.isnan(x):
        return "–"
    return fmt.format(x)


def sci(x):
    return fnum(x, "{:.2e}")


def table(head, rows):
    lines = ["| " + " | ".join(head) + " |", "|" + "|".join("---" for _ in head) + "|"]
    for r in rows:
        lines.append("| " + " | ".join(str(c) for c in r) + " |")
    return "\n".join(lines)


def order(e1, e2, ratio=2.0):
    e1, e2 = float(e1), float(e2)
    if e1 <= 0 or e2 <= 0:
        return float("nan")
    return math.log(e1 / e2) / math.log(ratio)


def fit_order(h, e):
    h, e = np.asarray(h, float), np.asarray(e, float)
    ok = (h > 0) & (e > 0)
    if ok.sum() < 2:
        return float("nan"), float("nan")
    p = np.polyfit(np.log(h[ok]), np.log(e[ok]), 1)
    return p[0], p[1]


def sh(cmd):
    try:
        return subprocess.run(cmd, capture_output=True, text=True, timeout=10).stdout.strip()
    except Exception:  # noqa: BLE001
        return ""


def capacity_note(values, what):
    """values: parallel capacities (2 = both cores there) measured around a section."""
    caps = []
    for v in values:
        try:
            caps.append(float(v))
        except (TypeError, ValueError):
            pass
    if not caps:
        return ""
    low = min(caps)
    text = (f" Parallel capacity around {what}: "
            + ", ".join(f"{c:.2f}" for c in caps)
            + " (a compute-bound loop's speed-up on all threads; 2 = both cores there).")
    if low < 1.8:
        text += (" **Below 1.8: the processors were not all available to this process "
                 "for part of the time (another process, or the host); the multi-thread "
                 "timings and speed-ups of this section understate the code.**")
    return text


def busy_note(value, what):
    try:
        v = float(value)
    except (TypeError, ValueError):
        return ""
    if v > BUSY_CORES:
        return (f"\n\n**Other processes used {v:.2f} cores on average during {what}:** the "
                "timings of this section are inflated (a 2-thread OpenMP barrier waits for a "
                "preempted thread); rerun `make bench` on a quiet machine.")
    return f"\n\nOther processes used {v:.2f} cores on average during {what}."


md = []
figs = []
headline = []  # (what, value, target verdict) rows of the summary at the top


def save_figure(fig, name, alt):
    """Lays out, writes and closes fig; returns its markdown image line."""
    fig.tight_layout()
    fig.savefig(fig_path(name), dpi=110)
    plt.close(fig)
    return f"![{alt}]({name})"


def fig_path(name):
    figs.append(name)
    return os.path.join(OUT, name)



# ---------------------------------------------------------------------------
# The three stages the bandwidth target is missed by, against the triad of the
# same run, with the instruction profile of bench/analysis.md (callgrind).
BOUND_STAGES = [
    ("viscosity", ["kernel_viscosity_cells", "kernel_viscosity_edges"],
     "cells + edges (strain and ghost fills not counted: a lower bound)"),
    ("stress_divergence", ["kernel_stress_divergence"], "the kernel alone"),
    ("viscous_apply", ["kernel_stress_divergence"],
     "the stress divergence (+ a lincomb, a few instructions)"),
]


def callgrind_counts():
    """{kernel: (calls, before, after)} instructions per cell and call from the
    table of bench/analysis.md ("Instructions per cell and call")."""
    out = {}
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "analysis.md")
    if not os.path.exists(path):
        return out
    import re
    pat = re.compile(r"^\|\s*`(kernel_\w+)`[^|]*\|\s*(\d+)\s*\|\s*([\d.,]+)\s*\|\s*([\d.,]+)\s*\|")
    with open(path) as f:
        for line in f:
            m = pat.match(line)
            if m and m.group(1) not in out:
                out[m.group(1)] = (int(m.group(2)), float(m.group(3).replace(",", "")),
                                   float(m.group(4).replace(",", "")))
    return out


def cpu_ghz():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("cpu MHz"):
                    return float(line.split(":", 1)[1]) / 1e3
    except (OSError, ValueError):
        pass
    return float("nan")


def bound_table(st, bw, tmax, cells):
    """Markdown: for the viscosity, stress-divergence and viscous-apply stages,
    the fraction of this run's triad and, below 50 %, the instruction profile."""
    cg = callgrind_counts()
    ghz = cpu_ghz()
    triad_sp = bw[tmax] / bw[1] if 1 in bw and tmax in bw and tmax > 1 else float("nan")
    rows = []
    for name, kernels, what in BOUND_STAGES:
        a = st.get((tmax, name))
        if a is None:
            continue
        t = float(a["median_s"])
        rd, wr, wa = float(a["reads"]), float(a["writes"]), float(a["wa"])
        if not t > 0:
            continue
        f24 = 8 * (rd + wr) * cells / t / 1e9 / bw[tmax]
        f32 = 8 * (rd + wr + wa) * cells / t / 1e9 / (bw[tmax] * 32 / 24)
        ns = t * 1e9 / cells
        b1 = st.get((1, name))
        sp = float(b1["median_s"]) / t if b1 is not None and float(b1["median_s"]) > 0 else float("nan")
        row = [name, f"{100*f32:.0f} % ({100*f24:.0f} %)", fnum(ns, "{:.2f}"),
               fnum(sp, "{:.2f}")]
        if f32 >= TARGET_FRACTION:
            row += ["–", "–", "at or above 50 %: bandwidth, not instructions"]
        elif not all(k in cg for k in kernels):
            row += ["not in bench/analysis.md", "–", "–"]
        else:
            ipc = sum(cg[k][2] for k in kernels)
            per_core = ipc / ns / tmax  # instructions per ns and core
            parts = " + ".join(f"`{k}` {cg[k][2]:g}" for k in kernels)
            row += [f"{ipc:.0f} ({parts}; {what})",
                    f"{per_core:.2f}" + (f" (IPC {per_core/ghz:.2f} at {ghz:.2f} GHz)"
                                         if ghz == ghz else ""),
                    (f"its instructions ({ipc:.0f} a cell, under {100*f32:.0f} % of the "
                     "bandwidth drawn); it scales " + fnum(sp, "{:.2f}") + f"x on {tmax} threads "
                     "against the triad's " + fnum(triad_sp, "{:.2f}") + "x"
                     + (": beyond the memory's scaling, so not the memory"
                        if sp == sp and triad_sp == triad_sp and sp > triad_sp else
                        ": not beyond the memory's scaling (a busy machine, see the "
                        "parallel capacity below, or memory stalls as well)"))]
        rows.append(row)
    if not rows:
        return ""
    return ("\n### 3b. The stages below the bandwidth target: what binds them\n\n"
            "The stage table above already gives each stage's bandwidth against the triad "
            f"measured in the same run (the mean of the {tmax}-thread triad medians before "
            "and after the stages). For the viscosity, the stress divergence and the viscous "
            "operator's apply: the fraction of that triad (write-allocate counted; without "
            "it in brackets), and where it is below 50 % the instructions each cell costs "
            "(callgrind's inclusive counts per cell and call of bench/analysis.md, "
            "\"Instructions per cell and call\", measured at 32 x 32 x 16 on 1 thread, not "
            "by this run) and the rate they are executed at here (instructions per cell "
            f"over this run's ns per cell, per core of the {tmax}): a stage that runs "
            "instructions at 1-3 per cycle while drawing well under half the bandwidth is "
            "bound by its instruction count, not by the memory.\n\n"
            + table(["stage", "fraction of the triad", "ns / cell", f"speed-up {tmax} vs 1",
                     "instructions / cell (callgrind)", "instructions / ns / core",
                     "bound by"], rows) + "\n")

# ---------------------------------------------------------------------------
sm = meta("scenes_meta.csv")
tm = meta("throughput_meta.csv")
cpu = ""
try:
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
except OSError:
    pass
gcc = sh(["gcc", "--version"]).splitlines()
md.append("# muflow benchmarks\n")
md.append(
    f"Generated by `make bench` on {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}: "
    f"{os.cpu_count()} cores ({cpu or platform.processor()}), {gcc[0] if gcc else 'gcc'}, "
    f"`-O3 -fopenmp`, OMP_NUM_THREADS={sm.get('threads', tm.get('threads', '?'))}. "
    "Times are medians over repeated runs in one process "
    f"({sm.get('repeats', '?')} for the timing tables, {sm.get('repeats_studies', '?')} "
    "for the convergence and lambda studies); a run is `run_case` from the case to the "
    "steady state, its setup (grid, FFTW plans, hydrostatic split) included; *march* is "
    "the time loop alone. Comparisons are ratios of timings taken in the same run.\n")

# ---------------------------------------------------------------------------
bag = read("bagnold.csv")
if bag:
    md.append("## 1. bagnold against the Newton FEM of Chauchat & Medale (2014), Table 1\n")
    md.append(
        "Layer H = 14 on a plane tilted 0.406 rad, mu(I) with the mc regularisation, "
        "lambda 1e-8, from rest to a relative residual of 1e-10 (`cases/bagnold.ini` with "
        "`domain.nz` overridden). *steps*: pseudo-time steps; *order*: observed order of "
        "err_rms (and err_max) between successive h. FEM columns: Newton iterations and CPU "
        "seconds of Table 1 (10000: no convergence); their CPU seconds were measured on the "
        "authors' 2014 machine, so *FEM / muflow* compares implementations and hardware "
        "together, an indication rather than a like-for-like ratio.\n")
    rows = []
    for i, r in enumerate(bag):
        if r["status"] == "skipped":
            rows.append([f"H/{r['nz']}", r["cells"], "skipped (time budget)"] + ["–"] * 8
                        + [r["fem_iterations"], r["fem_cpu_seconds"], "–"])
            continue
        o_rms = o_max = "–"
        if i > 0:
            o_rms = fnum(order(bag[i - 1]["err_rms"], r["err_rms"]), "{:.2f}")
            o_max = fnum(order(bag[i - 1]["err_max"], r["err_max"]), "{:.2f}")
        fem_it = int(r["fem_iterations"])
        fem = f"{fem_it} (no conv.)" if fem_it >= 10000 else str(fem_it)
        ratio = float(r["fem_cpu_seconds"]) / float(r["wall_median"])
        rows.append([
            f"H/{r['nz']}", r["cells"], r["steps"] + ("" if r["status"] == "steady" else f" ({r['status']})"),
            fnum(float(r["wall_median"]) * 1e3, "{:.1f}") + f" ({fnum(float(r['wall_min'])*1e3, '{:.1f}')}–{fnum(float(r['wall_max'])*1e3, '{:.1f}')}, {r['runs']} runs)",
            fnum(float(r["march_median"]) * 1e3, "{:.1f}"),
            sci(r["err_rms"]), sci(r["err_max"]), sci(r["err_rms_paper"]), o_rms, o_max,
            fem, r["fem_cpu_seconds"], fnum(ratio, "{:,.3g}")])
    for r in bag:
        if r["nz"] == "40":
            headline.append([
                "bagnold H/40 (mc, lambda 1e-8), from rest",
                f"{r['steps']} steps, {float(r['wall_median'])*1e3:.1f} ms, err_rms {sci(r['err_rms'])}; "
                f"FEM: {r['fem_iterations']} Newton iterations, {r['fem_cpu_seconds']} s "
                f"(FEM / muflow {fnum(float(r['fem_cpu_seconds'])/float(r['wall_median']), '{:,.3g}')})", ""])
    md.append(table(["h", "cells", "steps", "wall ms (min–max, runs)", "march ms", "err_rms",
                     "err_max", "err_rms_paper", "order rms", "order max", "FEM iterations",
                     "FEM CPU s", "FEM / muflow"], rows))
    hs = [14.0 / int(r["nz"]) for r in bag]
    p_rms, _ = fit_order(hs[1:], [float(r["err_rms"]) for r in bag[1:]])
    p_max, _ = fit_order(hs[1:], [float(r["err_max"]) for r in bag[1:]])
    md.append(f"\nFitted order H/10..H/160: err_rms {p_rms:.2f}, err_max {p_max:.2f}. "
              "Every resolution converges in the same number of steps: with the consistent "
              "tangent the pseudo-time march becomes Newton's method as dt grows."
              + busy_note(sm.get("foreign_cores_bagnold"), "the bagnold runs") + "\n")

    # profile plot
    prof = read("bagnold_profile.csv")
    exact = read("bagnold_exact.csv")
    if prof and exact:
        fig, ax = plt.subplots(1, 2, figsize=(10, 4.5))
        ze = [float(r["z"]) for r in exact]
        ue = [float(r["u_exact"]) for r in exact]
        ax[0].plot(ue, ze, "k-", lw=1.2, label="analytic (Bagnold)")
        marks = {"5": "s", "10": "^", "40": "o"}
        for nz in sorted({r["nz"] for r in prof}, key=int):
            pr = [r for r in prof if r["nz"] == nz]
            z = [float(r["z"]) for r in pr]
            u = [float(r["u"]) for r in pr]
            ax[0].plot(u, z, marks.get(nz, "o"), ms=4, mfc="none", label=f"muflow H/{nz}")
            err = [abs(float(r["u"]) - float(r["u_exact"])) for r in pr]
            ax[1].semilogx(err, z, marks.get(nz, "o") + "-", ms=3, lw=0.8, label=f"H/{nz}")
        ax[0].set_xlabel("u")
        ax[0].set_ylabel("z")
        ax[0].set_title("bagnold velocity profile, mc, lambda 1e-8")
        ax[0].legend(fontsize=8)
        ax[1].set_xlabel("|u - u_exact|")
        ax[1].set_ylabel("z")
        ax[1].set_title("pointwise error")
        ax[1].legend(fontsize=8)
        md.append(save_figure(fig, "bagnold_profile.png", "bagnold profile") + "\n")

# ---------------------------------------------------------------------------
ch = read("chute_h.csv")
ct = read("chute_time.csv")
cl = read("chute_lambda.csv")
et = read("error_time.csv")
etm = read("error_time_meta.csv")
if ch or ct or cl or et:
    md.append("## 2. chute: the paper's studies redone\n")
    md.append(
        "Vertical chute between rough plates, b = 28, p = 28 (`cases/chute.ini`), from rest "
        "to a relative residual of 1e-10 (less its round-off, see "
        "docs/numerics/steady-criterion.md), "
        "`domain.ny` = b/h.\n")
if ch:
    md.append("### 2a. Error against h, lambda 1e-4\n")
    nys = sorted({int(r["ny"]) for r in ch})
    rows = []
    for ny in nys:
        row = [f"b/{ny}"]
        for reg in REGS:
            r = next((x for x in ch if x["regularisation"] == reg and int(x["ny"]) == ny), None)
            row.append("–" if r is None else "skipped" if r["status"] == "skipped" else
                       f"{sci(r['err_rms'])} / {sci(r['err_rms_paper'])} ({r['steps']}, "
                       f"{fnum(float(r['wall_median'])*1e3, '{:.0f}')} ms)"
                       + ("" if r["status"] == "steady" else f" {r['status']}"))
        rows.append(row)
    orders = ["fitted order"]
    for reg in REGS:
        rr = [x for x in ch if x["regularisation"] == reg and x["status"] != "skipped"]
        p, _ = fit_order([28.0 / int(x["ny"]) for x in rr], [float(x["err_rms"]) for x in rr])
        succ = [order(rr[i - 1]["err_rms"], rr[i]["err_rms"]) for i in range(1, len(rr))]
        orders.append(f"{p:.2f} (successive: {', '.join(f'{o:.2f}' for o in succ)})")
    rows.append(orders)
    md.append("Each cell: err_rms / err_rms_paper (steps, median wall ms).\n")
    md.append(table(["h"] + REGS, rows))
    md.append("\nThe regularisation error (lambda = 1e-4) and the plug edge's position "
              "within a cell limit the order at fine h, most of all for `simple`, whose "
              "yield term differs from the others at O(lambda / |D|).\n")

    fig, ax = plt.subplots(1, 2, figsize=(10, 4.2))
    bag_ok = [r for r in (bag or []) if r["status"] != "skipped"]
    if bag_ok:
        h = np.array([14.0 / int(r["nz"]) for r in bag_ok])
        for key, mk in (("err_rms", "o"), ("err_max", "s")):
            e = np.array([float(r[key]) for r in bag_ok])
            p, c = fit_order(h[1:], e[1:])
            ax[0].loglog(h, e, mk, mfc="none", label=f"{key}")
            ax[0].loglog(h[1:], np.exp(c) * h[1:] ** p, "--", lw=0.8,
                         label=f"fit H/10..H/160: order {p:.2f}")
        ax[0].set_xlabel("h")
        ax[0].set_ylabel("error")
        ax[0].set_title("bagnold, mc, lambda 1e-8")
        ax[0].legend(fontsize=8)
    for reg, mk in zip(REGS, "os^v"):
        rr = [x for x in ch if x["regularisation"] == reg and x["status"] != "skipped"]
        h = np.array([28.0 / int(x["ny"]) for x in rr])
        e = np.array([float(x["err_rms"]) for x in rr])
        p, c = fit_order(h, e)
        line, = ax[1].loglog(h, e, mk + "-", mfc="none", lw=0.8, label=f"{reg} (order {p:.2f})")
        ax[1].loglog(h, np.exp(c) * h ** p, "--", color=line.get_color(), lw=0.6)
    ax[1].set_xlabel("h")
    ax[1].set_ylabel("err_rms")
    ax[1].set_title("chute, lambda 1e-4")
    ax[1].legend(fontsize=8)
    md.append(save_figure(fig, "error_h.png", "error against h") + "\n")

if et:
    md.append("### 2b. Error against wall time during the march\n")
    md.append(
        "err_rms of the profile after every step against the march's wall time (the "
        "per-step median over repeats), for the chute at b/160 with each regularisation "
        "and for bagnold at H/40 and H/160. The observer that computes the error "
        "(`scene_errors_of`) is timed and its time subtracted; setup (`march_create`) is "
        "not included and is given below.\n")
    rows = []
    for m in etm or []:
        tr = [x for x in et if x["scene"] == m["scene"] and x["regularisation"] == m["regularisation"]
              and x["n"] == m["n"]]
        if not tr:
            continue
        last = tr[-1]
        rows.append([m["scene"], m["regularisation"],
                     ("H/" if m["scene"] == "bagnold" else "b/") + m["n"], str(len(tr) - 1),
                     fnum(float(last["wall"]) * 1e3, "{:.1f}"),
                     fnum(float(m["setup_median"]) * 1e3, "{:.1f}"), sci(last["err_rms"]),
                     fnum(100 * float(m["observer_fraction"]), "{:.1f}") + " %"])
    md.append(table(["scene", "regularisation", "h", "steps", "march ms", "setup ms",
                     "final err_rms", "observer share (subtracted)"], rows))
    fig, ax = plt.subplots(1, 2, figsize=(10, 4.2))
    for n in sorted({x["n"] for x in et if x["scene"] == "bagnold"}, key=int):
        tr = [x for x in et if x["scene"] == "bagnold" and x["n"] == n]
        ax[0].loglog([float(x["wall"]) for x in tr], [float(x["err_rms"]) for x in tr], "o-",
                     ms=3, lw=0.8, label=f"mc H/{n}")
    ax[0].set_xlabel("wall time of the march (s)")
    ax[0].set_ylabel("err_rms")
    ax[0].set_title("bagnold, lambda 1e-8")
    ax[0].legend(fontsize=8)
    for reg, ls in zip(REGS, ["-", "--", "-.", ":"]):
        tr = [x for x in et if x["scene"] == "chute" and x["regularisation"] == reg]
        if tr:
            ax[1].loglog([float(x["wall"]) for x in tr], [float(x["err_rms"]) for x in tr],
                         "." + ls, ms=3, lw=1.0, label=f"{reg} b/{tr[0]['n']}")
    ax[1].set_xlabel("wall time of the march (s)")
    ax[1].set_ylabel("err_rms")
    ax[1].set_title("chute, lambda 1e-4")
    ax[1].legend(fontsize=8)
    md.append("\n" + save_figure(fig, "error_time.png", "error against wall time")
              + busy_note(sm.get("foreign_cores_error_time"), "these traces") + "\n")

if cl:
    md.append("### 2c. Error against lambda (mc)\n")
    lams = sorted({float(r["lambda"]) for r in cl}, reverse=True)
    nys = sorted({int(r["ny"]) for r in cl})
    rows = []
    for ny in nys:
        row = [f"b/{ny}"]
        for lam in lams:
            r = next((x for x in cl if int(x["ny"]) == ny and float(x["lambda"]) == lam), None)
            row.append("–" if r is None else "skipped" if r["status"] == "skipped" else
                       f"{sci(r['err_rms'])} ({r['steps']}, {fnum(float(r['wall_median'])*1e3, '{:.0f}')} ms)"
                       + ("" if r["status"] == "steady" else f" {r['status']}"))
        rows.append(row)
    md.append("Each cell: err_rms (steps, median wall ms).\n")
    md.append(table(["h"] + [f"lambda {lam:g}" for lam in lams], rows))
    md.append("\nThe error falls with lambda until the discretisation error of the grid "
              "dominates; below that, smaller lambda only costs steps.\n")
    fig, ax = plt.subplots(figsize=(6, 4.2))
    for ny in nys:
        rr = sorted([x for x in cl if int(x["ny"]) == ny and x["status"] != "skipped"],
                    key=lambda x: float(x["lambda"]))
        ax.loglog([float(x["lambda"]) for x in rr], [float(x["err_rms"]) for x in rr], "o-",
                  ms=3, lw=0.8, label=f"b/{ny}")
    ax.set_xlabel("lambda")
    ax.set_ylabel("err_rms")
    ax.set_title("chute, mc: error against lambda")
    ax.legend(fontsize=8)
    md.append(save_figure(fig, "chute_lambda.png", "error against lambda")
              + busy_note(sm.get("foreign_cores_chute_studies"), "the studies 2a and 2c") + "\n")

if ct:
    md.append("### 2d. Steady-state wall time per regularisation at b/160\n")
    md.append(f"Target: under {TARGET_CHUTE_SECONDS:g} s each (run_case, setup included).\n")
    threads = sorted({int(r["threads"]) for r in ct}, reverse=True)
    rows = []
    for reg in REGS:
        row = [reg]
        rr = {int(r["threads"]): r for r in ct if r["regularisation"] == reg}
        for t in threads:
            r = rr.get(t)
            if r is None or r["status"] == "skipped":
                row += ["skipped" if r is not None else "–", "–"]
                continue
            row.append(f"{fnum(float(r['wall_median'])*1e3, '{:.0f}')} "
                       f"({fnum(float(r['wall_min'])*1e3, '{:.0f}')}–{fnum(float(r['wall_max'])*1e3, '{:.0f}')}, "
                       f"{r['runs']} runs)")
            row.append(fnum(float(r["march_median"]) * 1e3, "{:.0f}"))
        r0 = rr.get(threads[0])
        row.insert(1, r0["steps"] if r0 else "–")
        row.insert(2, sci(r0["err_rms"]) if r0 else "–")
        if r0 is not None and r0["status"] == "skipped":
            r0 = None
        ok = r0 is not None and float(r0["wall_median"]) < TARGET_CHUTE_SECONDS
        row.append("–" if r0 is None else "met" if ok else "missed")
        if r0 is not None:
            headline.append([f"chute b/160 {reg}, steady from rest",
                             f"{r0['steps']} steps, {float(r0['wall_median'])*1e3:.0f} ms "
                             f"(march {float(r0['march_median'])*1e3:.0f} ms)",
                             f"< {TARGET_CHUTE_SECONDS:g} s: {'met' if ok else 'missed'}"])
        if len(threads) > 1 and rr.get(1) and r0 and rr[1]["status"] != "skipped":
            row.append(fnum(float(rr[1]["wall_median"]) / float(r0["wall_median"]), "{:.2f}"))
        rows.append(row)
    head = ["regularisation", "steps", "err_rms"]
    for t in threads:
        head += [f"wall ms, {t} thr (min–max, runs)", f"march ms, {t} thr"]
    head.append(f"< {TARGET_CHUTE_SECONDS:g} s")
    if len(threads) > 1:
        head.append(f"speed-up {threads[0]} vs 1 thr")
    md.append(table(head, rows))
    md.append("\nOn this 1 x 160 x 2 grid (640 cells) a step is dominated by fixed costs "
              "(OpenMP fork/join and barriers of some 200 parallel loops a step, serial ghost "
              "fills and FFTW's thread dispatch), not by arithmetic; the 1-thread column "
              "shows what the threads cost there."
              + busy_note(sm.get("foreign_cores_chute_times"), "these runs") + "\n")

# ---------------------------------------------------------------------------
hs = read("heap_solve.csv")
if hs:
    md.append("## Heap cross-section: one steady solve\n")
    rows = [[f"{r['ny']} x {r['nz']}", r["tilt"], r["status"], r["steps"], r["runs"],
             fnum(r["wall_median"], "{:.2f}"),
             f"{fnum(r['wall_min'], '{:.2f}')} .. {fnum(r['wall_max'], '{:.2f}')}"] for r in hs]
    md.append(table(["mesh", "tilt (rad)", "status", "steps", "runs", "wall median (s)",
                     "range (s)"], rows))
    md.append("\nOne function evaluation of the tilt search: the heap's half cross-section "
              "(`cases/heap.ini`, 70 x 100 cells, lambda 1e-5) from rest to a residual of "
              "1e-8, at the tilt the search finds for Q* = 40.2; setup included.  The whole "
              "search, the three flow rates and the mesh study are `make bench-heap` "
              "(bench/out/heap_table.md)."
              + busy_note(sm.get("foreign_cores_heap"), "these runs") + "\n")
    heap_table = os.path.join(OUT, "heap_table.md")
    if os.path.exists(heap_table):
        with open(heap_table) as f:
            md.append("Last `make bench-heap` (tilt searches):\n\n" + f.read())

# ---------------------------------------------------------------------------
for name, title, png in [
        ("bagnold2_table.md",
         "Granular layer under air (bagnold2) against Barker & Rauter (2018), eqs. (6)-(11)",
         "bagnold2_profile.png"),
        ("bedload_table.md", "Bed load beside the Newton FEM (Chauchat & Medale 2010, Table 2)", None),
        ("collapse_gerris.md", "Column collapse beside Gerris (last `make bench-collapse-gerris`)",
         None),
        ("amg_table.md", "Preconditioners of the implicit step on whole steady solves "
         "(last `make bench-amg`)", None),
        ("bagnold3d.md", "A 3D steady flow of a million cells (last `make bench-3d`)", None),
        ("scene_times.md", "The scenes beside the depth-averaged model: whole runs", None),
        ("scaling.md", "The implicit step's cost against the grid (last `make bench-scaling`)",
         None)]:
    path = os.path.join(OUT, name)
    if os.path.exists(path):
        md.append(f"## {title}\n")
        with open(path) as f:
            md.append(f.read())
        if png and os.path.exists(os.path.join(OUT, png)):
            figs.append(png)
            md.append(f"![{title}]({png})\n")

# ---------------------------------------------------------------------------
tri = read("triad.csv")
stg = read("stages.csv")
steps = read("steps.csv")
if tri and stg:
    md.append("## 3. Throughput on a 3D grid\n")
    nx, ny, nz = tm.get("nx"), tm.get("ny"), tm.get("nz")
    cells = float(stg[0]["cells"])
    tmax = max(int(r["threads"]) for r in stg)
    md.append(
        f"`bench/shear3d.ini`: {nx} x {ny} x {nz} = {int(cells):,} cells, periodic in x "
        f"and y, no-slip base, free surface on top, mu(I) mc lambda {tm.get('lambda', '?')}, "
        f"advection on, transient dt {tm.get('dt', '?')}, line preconditioner along "
        f"{'xyz'[int(tm.get('line_direction', 2))]}; started from the Bagnold profile with "
        "divergence-free 3D perturbations of all components and marched "
        f"{tm.get('warm_steps', '?')} steps before anything is timed. "
        f"Each stage is timed {tm.get('repeats', '?')} times on a state of its own per "
        "thread count (created at that count, FFTW plans included), the thread counts "
        "alternating within each repeat; medians.\n")
    md.append(
        "Before every timed call a 512 MiB buffer is read, so each timing starts with cold "
        "caches as the byte counts below assume. "
        "Bytes per cell count each field array a kernel sweeps once, 8 bytes per cell "
        "(stencil neighbours from cache, ghost layers ignored); *+WA* adds the "
        "write-allocate read of every array written by a normal store. The triad "
        "a = b + s c is counted alike (24 bytes an element, 32 with the write-allocate), "
        f"on arrays of {int(tri[0]['elements']) * 8 // 2**20} MiB each.\n")
    trows = [[r.get("phase", "before"), r["threads"], fnum(r["gbs_median"], "{:.1f}"),
              fnum(r["gbs_best"], "{:.1f}"), fnum(float(r["gbs_median"]) * 32 / 24, "{:.1f}")]
             for r in tri]
    md.append(table(["measured", "threads", "triad GB/s (24 B)", "best",
                     "with write-allocate (32 B)"], trows))
    # the reference: the mean of the medians before and after the stages
    bw = {}
    for t in {int(r["threads"]) for r in tri}:
        v = [float(r["gbs_median"]) for r in tri if int(r["threads"]) == t]
        bw[t] = sum(v) / len(v)
    md.append("\nThe stages are compared with the mean of the triad medians before and after "
              "them: " + ", ".join(f"{bw[t]:.1f} GB/s at {t} thread{'s' if t > 1 else ''}"
                                   for t in sorted(bw, reverse=True)) + ".")
    if len(bw) > 1:
        md.append(f"\nTriad speed-up {tmax} vs 1 thread: {bw[tmax] / bw[1]:.2f}: the memory "
                  "bandwidth one core can draw is most of what the machine gives, so a purely "
                  "bandwidth-bound stage cannot scale much beyond this ratio.\n")
    st = {(int(r["threads"]), r["stage"]): r for r in stg}
    order_names = []
    for r in stg:
        if r["stage"] not in order_names:
            order_names.append(r["stage"])
    rows = []
    frac_stencil = {}
    for name in order_names:
        a = st.get((tmax, name))
        b = st.get((1, name))
        if a is None:
            continue
        t = float(a["median_s"])
        rd, wr, wa = float(a["reads"]), float(a["writes"]), float(a["wa"])
        nbytes = 8 * (rd + wr)
        row = [name, fnum(t * 1e3, "{:.2f}"), fnum(t * 1e9 / cells, "{:.2f}")]
        if nbytes > 0 and t > 0:
            gbs = nbytes * cells / t / 1e9
            gbs_wa = 8 * (rd + wr + wa) * cells / t / 1e9
            f24 = gbs / bw[tmax]
            f32 = gbs_wa / (bw[tmax] * 32 / 24)
            row += [f"{nbytes:.0f} (+{8*wa:.0f})", fnum(gbs, "{:.1f}"),
                    f"{100*f24:.0f} % / {100*f32:.0f} %"]
            if name in STENCIL:
                frac_stencil[name] = (f24, f32)
                row.append("met" if f32 >= TARGET_FRACTION else "missed")
            else:
                row.append("")
        else:
            row += ["–", "–", "–", ""]
        if b is not None and float(b["median_s"]) > 0 and t > 0:
            row += [fnum(float(b["median_s"]) * 1e3, "{:.2f}"),
                    fnum(float(b["median_s"]) / t, "{:.2f}")]
        else:
            row += ["–", "–"]
        rows.append(row)
    if len(bw) > 1:
        headline.append(["triad bandwidth", f"{bw[tmax]:.1f} GB/s ({tmax} threads), "
                         f"{bw[1]:.1f} GB/s (1 thread)", ""])
    for name in STENCIL:
        if name in frac_stencil:
            f24, f32 = frac_stencil[name]
            headline.append([f"{name}: fraction of the triad bandwidth",
                             f"{100*f32:.0f} % ({100*f24:.0f} % without write-allocate)",
                             f">= {int(TARGET_FRACTION*100)} %: "
                             f"{'met' if f32 >= TARGET_FRACTION else 'missed'}"])
    md.append(f"\nStages at {tmax} threads (per call). *fraction*: bytes per second against "
              f"the {tmax}-thread triad, counted without / with the write-allocate reads on both "
              "sides. The target is judged on the second, the traffic that really crosses the "
              "memory bus: the STREAM convention (first figure) undercounts the triad by a "
              "third but an in-place update (axpy, lincomb, gradient) not at all, which is why "
              "those read above 100 % there.\n")
    md.append(table(["stage", "ms", "ns / cell", "bytes / cell (+WA)", "GB/s", "fraction",
                     f"target {int(TARGET_FRACTION*100)} %", "ms, 1 thread",
                     f"speed-up {tmax} vs 1"], rows))
    notes = {r["stage"]: r["note"] for r in stg}
    md.append("\nWhat each stage is: " + "; ".join(f"*{k}*: {v}" for k, v in notes.items()) + ".\n")
    md.append(bound_table(st, bw, tmax, cells))
    if steps:
        srows = []
        for t in sorted({int(r["threads"]) for r in steps}, reverse=True):
            ss = [r for r in steps if int(r["threads"]) == t]
            secs = [float(r["seconds"]) for r in ss]
            its = [int(r["cg_iterations"]) for r in ss]
            srows.append([str(t), ", ".join(f"{s:.3f}" for s in secs),
                          ", ".join(str(i) for i in its), fnum(float(np.median(secs)), "{:.3f}"),
                          fnum(float(np.median(secs)) * 1e9 / cells, "{:.0f}")])
        md.append("\nWhole march steps (viscosity, residual, line preconditioner setup, "
                  "preconditioned CG, projection), the thread counts alternating step by step:\n")
        md.append(table(["threads", "step seconds", "CG iterations", "median s", "ns / cell"], srows))
        ws = {t: float(np.median([float(r["seconds"]) for r in steps if int(r["threads"]) == t]))
              for t in {int(r["threads"]) for r in steps}}
        if tmax in ws and 1 in ws and tmax > 1:
            sp = ws[1] / ws[tmax]
            headline.append([f"whole step, {int(cells):,} cells, {tmax} vs 1 thread",
                             f"{ws[tmax]:.2f} s vs {ws[1]:.2f} s: speed-up {sp:.2f}",
                             f">= {TARGET_SPEEDUP}: {'met' if sp >= TARGET_SPEEDUP else 'missed'}"])
            md.append(f"\n**Whole step speed-up {tmax} vs 1 thread: {sp:.2f}** (target "
                      f"{TARGET_SPEEDUP}: {'met' if sp >= TARGET_SPEEDUP else 'missed'}).")
        # step model: where a step's time goes
        a = {name: float(st[(tmax, name)]["median_s"]) for (t, name) in st if t == tmax}
        its = float(np.median([int(r["cg_iterations"]) for r in steps if int(r["threads"]) == tmax]))
        parts = [
            ("viscosity (with its fills)", a.get("viscosity", 0)),
            ("residual: stress divergence + magnitude + excess",
             a.get("stress_divergence", 0) + a.get("stress_magnitude", 0) + a.get("residual_excess", 0)),
            ("advection", a.get("advection", 0)),
            ("line preconditioner setup", a.get("precondition_setup", 0)),
            (f"CG: {its:.0f} iterations", its * a.get("cg_iteration", 0)),
            ("Poisson", a.get("poisson", 0)),
            ("divergence + gradient x2, axpy x3, max x3, fills x3",
             2 * a.get("correction", 0) + 3 * a.get("axpy", 0) + 3 * a.get("max_abs", 0)
             + a.get("fill_velocity", 0) + 2 * a.get("fill_scalar", 0)),
        ]
        total = sum(p[1] for p in parts)
        whole = ws.get(tmax, float("nan"))
        prow = [[n, fnum(v * 1e3, "{:.1f}"), f"{100*v/whole:.0f} %"] for n, v in parts]
        prow.append(["sum of the stages", fnum(total * 1e3, "{:.1f}"), f"{100*total/whole:.0f} %"])
        prow.append(["measured step - sum: serial copies and loops of the march and the "
                     "solver (save_good, memset/memcpy, the pressure, phi and p_dyn loops), "
                     "the solve's set-up, less the cache reuse inside a step",
                     fnum((whole - total) * 1e3, "{:.1f}"), f"{100*(whole-total)/whole:.0f} %"])
        md.append(f"\n\nWhere a step's {whole*1e3:.0f} ms go at {tmax} threads (stage medians "
                  "times their calls per step in `src/march.c`; CG: the median iteration count "
                  "times one iteration):\n")
        md.append(table(["part", "ms", "share"], prow))
        md.append("\nThe stages were timed from cold caches; inside a step some of their arrays "
                  "are still cached from the stage before, so the sum can exceed the measured "
                  "step by a few per cent.")
    md.append(busy_note(tm.get("foreign_cores_stages"), "the stage timings")
              + busy_note(tm.get("foreign_cores_steps"), "the whole steps")
              + "\n\n" + capacity_note([tm.get("capacity_start"), tm.get("capacity_stages"),
                                       tm.get("capacity_steps")],
                                      "this section (start, after the stages, after the steps)")
              + "\n")

    # plot: fraction of bandwidth (actual traffic) and speed-up per stage
    names = [n for n in order_names if (tmax, n) in st and float(st[(tmax, n)]["reads"]) > 0]
    if names:
        fr = []
        for n in names:
            a_ = st[(tmax, n)]
            t = float(a_["median_s"])
            nbytes = 8 * (float(a_["reads"]) + float(a_["writes"]) + float(a_["wa"]))
            fr.append(nbytes * cells / t / 1e9 / (bw[tmax] * 32 / 24) if t > 0 else 0)
        snames = names + [n for n in ("precondition_setup", "whole_step") if (tmax, n) in st]
        spd = []
        for n in snames:
            t = float(st[(tmax, n)]["median_s"])
            b_ = st.get((1, n))
            spd.append(float(b_["median_s"]) / t if b_ and t > 0 else 0)
        fig, ax = plt.subplots(1, 2, figsize=(11, 5))
        y = np.arange(len(names))
        ax[0].barh(y, fr, color=["C0" if n in STENCIL else "C7" for n in names])
        ax[0].axvline(TARGET_FRACTION, color="C3", ls="--", lw=1, label="target 50 %")
        ax[0].set_yticks(y, names, fontsize=8)
        ax[0].invert_yaxis()
        ax[0].set_xlabel(f"fraction of the {tmax}-thread triad bandwidth (write-allocate counted)")
        ax[0].legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.12))
        y2 = np.arange(len(snames))
        ax[1].barh(y2, spd, color=["C1" if n == "whole_step" else "C2" for n in snames])
        ax[1].axvline(TARGET_SPEEDUP, color="C3", ls="--", lw=1, label="whole-step target 1.6")
        if len(bw) > 1:
            ax[1].axvline(bw[tmax] / bw[1], color="k", ls=":", lw=1, label="triad speed-up")
        ax[1].set_yticks(y2, snames, fontsize=8)
        ax[1].invert_yaxis()
        ax[1].set_xlabel(f"speed-up {tmax} vs 1 thread")
        ax[1].legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2)
        fig.suptitle(f"stages on {nx} x {ny} x {nz} cells (blue: stencil stages)")
        md.append(save_figure(fig, "throughput.png", "throughput") + "\n")

# the analysis behind the missed targets (written from profiles, see its header)
ana = os.path.join(os.path.dirname(os.path.abspath(__file__)), "analysis.md")
if os.path.exists(ana):
    with open(ana) as f:
        md.append(f.read())

# ---------------------------------------------------------------------------
# Bingham cavity: Vola Bn = 1000 from rest (bench_scenes), and psi_max and the
# mid-line against Vola et al. (2003) at 64 x 64 and 128 x 128 (bench_cavity,
# `make bench-cavity` and `make bench-cavity-128`, when their tables exist)
cvt = read("cavity_time.csv")
studies = {n: read(f"cavity_table_n{n}.csv") for n in (64, 128)}
if cvt or any(studies.values()):
    md.append("## 5. Bingham lid-driven cavity\n")
if cvt:
    md.append("Vola et al.'s Bn = 1000 (`yield_stress` = 1000 / sqrt 2), Papanastasiou "
              "lambda 1e-4, steady from rest to residual 1e-8 (run_case, setup included):\n")
    rows = []
    for r in cvt:
        if r["status"] == "skipped":
            rows.append([f"{r['n']} x {r['n']}", "skipped", "–", "–", "–", "–"])
            continue
        rows.append([f"{r['n']} x {r['n']}", r["status"], r["steps"],
                     f"{fnum(r['wall_median'])} ({fnum(r['wall_min'])}–{fnum(r['wall_max'])}, "
                     f"{r['runs']} runs)", fnum(r["march_median"]), fnum(r["psi_max"], "{:.4g}")])
        headline.append([f"cavity {r['n']} x {r['n']}, Vola Bn = 1000, steady from rest",
                         f"{r['status']} in {r['steps']} steps, {fnum(r['wall_median'])} s", "steady"])
    md.append(table(["grid", "status", "steps", "wall s (min–max, runs)", "march s", "psi_max"],
                    rows))
    md.append("\nAt Bn = 1000 the yielded layer under the lid spans a few cells at these "
              "resolutions: psi_max is far from converged in h (the augmented-Lagrangian "
              "reference gives 0.0110 at 128 x 128)."
              + busy_note(sm.get("foreign_cores_cavity"), "these runs") + "\n")
if any(studies.values()):
    ref = {}
    refpath = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "cases", "data",
                           "vola2003_cavity.csv")
    if os.path.exists(refpath):
        with open(refpath) as f:
            for r in csv.DictReader(line for line in f if not line.startswith("#")):
                if r["dataset"] == "psi_max_al":
                    ref[float(r["bn_vola"])] = float(r["value"])
    bns = sorted({float(r["bn_vola"]) for rows_ in studies.values() if rows_ for r in rows_})
    md.append("psi_max and the RMS difference of the mid-line u from Vola's fig. 3 "
              "(err_midline) against the grid; "
              "Vola fig. 2a is their psi_max curve at this Bn, AL the augmented-Lagrangian "
              "(unregularised) reference at 128 x 128 from the same data file:\n")
    rows = []
    for bn in bns:
        row = [fnum(bn, "{:g}")]
        vola = None
        for n in (64, 128):
            r = next((r for r in studies[n] or [] if float(r["bn_vola"]) == bn), None)
            if r is None:
                row += ["–", "–", "–"]
                continue
            vola = r["psi_max_vola"]
            row += [f"{fnum(r['psi_max'], '{:.5f}')}", fnum(r["err_midline"], "{:.4f}"),
                    f"{r['status']}, {r['steps']}"
                    + (f" ({r['rejected']} rejected)" if r.get("rejected") else "")]
        row += [fnum(vola, "{:.4f}"), fnum(ref.get(bn), "{:.4f}")]
        rows.append(row)
    md.append(table(["Bn (Vola)", "psi_max 64", "err_midline 64", "64: status, steps",
                     "psi_max 128", "err_midline 128", "128: status, steps", "Vola fig. 2a",
                     "AL 128"], rows))
    md.append("")


# ---------------------------------------------------------------------------
# Multigrid (bench_multigrid): its markdown tables, headings moved one level down
mgp = os.path.join(OUT, "multigrid.md")
if os.path.exists(mgp):
    with open(mgp) as f:
        lines = f.read().splitlines()
    md.append("## 6. Multigrid Poisson solver\n")
    md.append("Geometric multigrid for div(a grad phi) = f (`src/solvers/multigrid.c`, "
              "docs/numerics/multigrid.md), from `bench_multigrid`:\n")
    for line in lines:
        if line.startswith("# "):
            continue  # its own title
        md.append("#" + line if line.startswith("#") else line)
    md.append("")
# ---------------------------------------------------------------------------
# Whole processes (bench_process): `build/muflow CASE` forked, executed and
# waited for, as a user runs it
pr_runs = read("process_runs.csv")
pm = meta("process_meta.csv")
TARGET_PROCESS_MS = 30.0
TARGET_LOADED_RATIO = 2.0
if pr_runs:
    def runs_of(section, case, cond, threads):
        return [r for r in pr_runs if r["section"] == section and r["case"] == case
                and r["condition"] == cond and int(r["threads"]) == threads
                and int(r["rep"]) >= 0]

    def stats(rr):
        ok = [r for r in rr if int(r["exit"]) == 0]
        w = np.array([float(r["wall_s"]) for r in ok]) * 1e3
        cpu_ms = np.array([float(r["user_s"]) + float(r["sys_s"]) for r in ok]) * 1e3
        wall = sum(float(r["wall_s"]) for r in rr)
        fs = [float(r["foreign_cpu_s"]) for r in rr]
        sp = [float(r["spinner_cpu_s"]) for r in rr]
        d = {"n": len(ok), "fail": len(rr) - len(ok), "med": float("nan"), "q1": float("nan"),
             "q3": float("nan"), "min": float("nan"), "max": float("nan"),
             "cpu": float("nan"), "foreign": float("nan"), "spinner": float("nan"),
             "others": float("nan"), "by_rep": {int(r["rep"]): float(r["wall_s"]) for r in ok}}
        if len(w):
            d.update(med=float(np.median(w)), q1=float(np.percentile(w, 25)),
                     q3=float(np.percentile(w, 75)), min=float(w.min()), max=float(w.max()),
                     cpu=float(np.median(cpu_ms)))
        if wall > 0 and all(math.isfinite(x) for x in fs):
            d["foreign"] = max(sum(fs) / wall, 0.0)
            if all(math.isfinite(x) for x in sp):
                d["spinner"] = max(sum(sp) / wall, 0.0)
                d["others"] = max((sum(fs) - sum(sp)) / wall, 0.0)
        return d

    def ms(d):
        if not d["n"]:
            return "no successful run"
        txt = (f"**{d['med']:.1f}** (IQR {d['q1']:.1f}–{d['q3']:.1f}, "
               f"min–max {d['min']:.1f}–{d['max']:.1f}, {d['n']} runs)")
        return txt + (f", {d['fail']} failed" if d["fail"] else "")

    def pair_ratios(num, den):
        """per repeat num/den (the two ran back to back): median, q1, q3"""
        r = [num["by_rep"][k] / den["by_rep"][k] for k in num["by_rep"]
             if k in den["by_rep"] and den["by_rep"][k] > 0]
        if not r:
            return float("nan"), float("nan"), float("nan")
        return (float(np.median(r)), float(np.percentile(r, 25)), float(np.percentile(r, 75)))

    def iqr_range(num, den):
        """the ratio num/den's range from the two IQRs: q1/q3 .. q3/q1"""
        if not (num["n"] and den["n"]) or not (den["q1"] > 0 and den["q3"] > 0):
            return float("nan"), float("nan")
        return num["q1"] / den["q3"], num["q3"] / den["q1"]

    def cores(x):
        return fnum(x, "{:.2f}")

    busy = []
    md.append("## 7. Whole-process speed: `build/muflow CASE` as a user runs it\n")
    md.append(
        "`bench_process` forks and executes `" + pm.get("muflow", "build/muflow") + " CASE.ini "
        "[overrides] output.dir=OUTDIR/proc/CASE` and times the whole process: "
        "`clock_gettime(CLOCK_MONOTONIC)` from before `fork` to the return of `wait4`, "
        "whose rusage gives the child's CPU time (user + system). Every output is written, "
        "into the same folder run after run as a user's reruns do; the child's standard "
        "output goes to /dev/null. Each configuration runs once as a warm-up, then "
        f"{pm.get('repeats', '?')} times; configurations alternate run by run (their order "
        "reversed every other repeat), so a drift of the machine's load hits them alike. "
        "Times in ms: median, interquartile range (IQR), min–max. *Other processes*: the "
        "CPU the rest of the machine used during the runs (/proc/stat's busy time less the "
        "benchmark and its waited-for children, over the runs' wall time), in cores. "
        f"OMP_WAIT_POLICY in the environment: {pm.get('omp_wait_policy', '?')} (unset: "
        "muflow sets a short spin count itself, GOMP_SPINCOUNT=1000, re-executing itself only for grids that open "
        "parallel regions, src/app/main.c; none of the grids here does).\n")

    # 7a: bagnold as shipped, 2 threads, idle
    bi = stats(runs_of("load", "bagnold", "idle", 2))
    verdict = "–"
    if bi["n"]:
        verdict = "met" if bi["med"] <= TARGET_PROCESS_MS else "missed"
        if bi["foreign"] > BUSY_CORES:
            verdict += " (machine not idle)"
            busy.append("7a")
    md.append("### 7a. `build/muflow cases/bagnold.ini`, 2 threads\n")
    md.append(table(["command", "wall ms", "child CPU ms (median)", "other processes (cores)",
                     "load average (1 min) before / after", f"target <= {TARGET_PROCESS_MS:g} ms "
                     "(idle machine)"],
                    [["`muflow cases/bagnold.ini` (H/40, 2 x 1 x 40, 2 threads)", ms(bi),
                      fnum(bi["cpu"], "{:.1f}"), cores(bi["foreign"]),
                      f"{pm.get('load_loadavg_start', '?')} / {pm.get('load_loadavg_end', '?')}",
                      verdict]]))
    md.append("\nThe load average counts this benchmark's own runs (one or two runnable "
              "threads) besides the other processes.\n")
    if bi["n"]:
        headline.append(["`muflow cases/bagnold.ini`, whole process, 2 threads",
                         f"{bi['med']:.1f} ms median of {bi['n']} (IQR {bi['q1']:.1f}–"
                         f"{bi['q3']:.1f}); other processes {cores(bi['foreign'])} cores",
                         f"<= {TARGET_PROCESS_MS:g} ms idle: {verdict}"])

    # 7b: idle against one spinning process
    rows = []
    for case, label in (("bagnold", "bagnold H/40 (`cases/bagnold.ini`)"),
                        ("chute_b160", "chute b/160 (`cases/chute.ini domain.ny=160`)")):
        i = stats(runs_of("load", case, "idle", 2))
        lo = stats(runs_of("load", case, "loaded", 2))
        if not i["n"] and not lo["n"]:
            continue
        ratio = lo["med"] / i["med"] if i["n"] and lo["n"] else float("nan")
        pr_med, pr_q1, pr_q3 = pair_ratios(lo, i)
        r_lo, r_hi = iqr_range(lo, i)
        v = "–" if not math.isfinite(ratio) else ("met" if ratio <= TARGET_LOADED_RATIO else "missed")
        if math.isfinite(i["others"]) and (i["others"] > BUSY_CORES or lo["others"] > BUSY_CORES):
            v += " (other load too)"
            busy.append("7b")
        rows.append([label, ms(i), cores(i["foreign"]), ms(lo), cores(lo["spinner"]),
                     cores(lo["others"]),
                     f"**{fnum(ratio, '{:.2f}')}** ({fnum(r_lo, '{:.2f}')}–{fnum(r_hi, '{:.2f}')})",
                     f"{fnum(pr_med, '{:.2f}')} ({fnum(pr_q1, '{:.2f}')}–{fnum(pr_q3, '{:.2f}')})",
                     v])
        headline.append([f"{label.split(' (')[0]}: one spinning process / idle, whole process, "
                         "2 threads",
                         f"{fnum(ratio, '{:.2f}')} ({fnum(lo['med'], '{:.1f}')} / "
                         f"{fnum(i['med'], '{:.1f}')} ms)",
                         f"<= {TARGET_LOADED_RATIO:g}x: {v}"])
    if rows:
        md.append("### 7b. Idle against one spinning process, 2 threads\n")
        md.append(
            "*Loaded*: with one spinning process, a child of the benchmark in a busy loop "
            "(`for (;;) x++`), continued (SIGCONT) 20 ms before each loaded run and stopped "
            "(SIGSTOP) after it, so it competes for the 2 cores during the whole run. Its CPU "
            "share during the loaded runs is given apart from the other processes'. "
            "*loaded / idle*: ratio of the medians (in brackets its range from the two IQRs, "
            "q1/q3 to q3/q1); beside it the per-repeat ratios (the two ran back to back): "
            "median and IQR.\n")
        md.append(table(["case", "idle: wall ms", "idle: other processes (cores)",
                         "loaded: wall ms", "loaded: spinning process (cores)",
                         "loaded: other processes besides it (cores)", "loaded / idle",
                         "per-repeat ratio (IQR)", f"target <= {TARGET_LOADED_RATIO:g}x"], rows))
        md.append("")

    # 7c: 1 against 2 threads for every profile scene
    scenes = []
    for r in pr_runs:
        if r["section"] == "threads" and r["case"] not in scenes:
            scenes.append(r["case"])
    rows = []
    thr_summary = []
    fsum = wsum = 0.0
    for case in scenes:
        d2 = stats(runs_of("threads", case, "idle", 2))
        d1 = stats(runs_of("threads", case, "idle", 1))
        for rr in (runs_of("threads", case, "idle", 1), runs_of("threads", case, "idle", 2)):
            for r in rr:
                if math.isfinite(float(r["foreign_cpu_s"])):
                    fsum += float(r["foreign_cpu_s"])
                    wsum += float(r["wall_s"])
        ratio = d1["med"] / d2["med"] if d1["n"] and d2["n"] else float("nan")
        lo, hi = iqr_range(d1, d2)
        pr_med, pr_q1, pr_q3 = pair_ratios(d1, d2)
        if not math.isfinite(ratio):
            v = "–"
        elif ratio >= 1.0:
            v = "met"
        elif hi >= 1.0 or (math.isfinite(pr_q3) and pr_q3 >= 1.0):
            v = "within the spread"
        else:
            v = "missed"
        rows.append([case.replace("_", " "), ms(d2), ms(d1),
                     f"**{fnum(ratio, '{:.3f}')}** ({fnum(lo, '{:.2f}')}–{fnum(hi, '{:.2f}')})",
                     f"{fnum(pr_med, '{:.2f}')} ({fnum(pr_q1, '{:.2f}')}–{fnum(pr_q3, '{:.2f}')})",
                     fnum(d2["cpu"], "{:.1f}") + " / " + fnum(d1["cpu"], "{:.1f}"), v])
        thr_summary.append((case.replace("_", " "), ratio, lo, hi, v))
    if thr_summary:
        verdicts = {}
        for name, _, _, _, v in thr_summary:
            verdicts.setdefault(v, []).append(name)
        headline.append(["whole process, t1 / t2 (1 thread's median over 2 threads'; "
                         "range from their IQRs)",
                         "; ".join(f"{n} {fnum(r, '{:.3f}')} ({fnum(a, '{:.2f}')}–"
                                   f"{fnum(b, '{:.2f}')})" for n, r, a, b, _ in thr_summary),
                         ">= 1 within the spread: " + "; ".join(
                             f"{v}: {', '.join(ns)}" for v, ns in verdicts.items())])
    if rows:
        fthr = max(fsum / wsum, 0.0) if wsum > 0 else float("nan")
        md.append("### 7c. 1 thread against 2, every profile scene\n")
        md.append(
            "Each case as shipped (the chute, b/80, with each regularisation set by "
            "`rheology.regularisation=`), `OMP_NUM_THREADS` = 1 or 2 in the child's "
            "environment, the spinning process stopped. *t1 / t2*: ratio of the medians "
            "(above 1: 2 threads faster), in brackets its range from the two IQRs (q1/q3 to "
            "q3/q1); beside it the per-repeat ratios' median and IQR (each pair ran back to "
            "back). Target: t1 / t2 >= 1 (\"met\"), or 1 within either spread (\"within "
            "the spread\"); \"missed\" when both lie below 1.\n")
        md.append(table(["scene", "2 threads: wall ms", "1 thread: wall ms", "t1 / t2",
                         "per-repeat t1 / t2 (IQR)", "child CPU ms, 2 / 1 threads",
                         "target >= 1"], rows))
        md.append(f"\nOther processes during these runs: {cores(fthr)} cores; load average "
                  f"{pm.get('threads_loadavg_start', '?')} before, "
                  f"{pm.get('threads_loadavg_end', '?')} after.")
        if math.isfinite(fthr) and fthr > BUSY_CORES:
            busy.append("7c")
    if busy:
        md.append("\n**Other processes used more than "
                  f"{BUSY_CORES} cores during {', '.join(sorted(set(busy)))}:** the idle "
                  "figures there are not those of an idle machine (a 2-thread barrier waits "
                  "for a preempted thread); rerun `make bench` on a quiet machine before "
                  "judging the targets.")
    md.append(f"\nbench_process took {pm.get('seconds', '?')} s.\n")

md.append(capacity_note([sm.get("capacity_start"), sm.get("capacity_end")],
                        "the scene benchmarks (start, end)") + "\n")
md.append("\n---\nRun time: scenes "
          f"{sm.get('seconds', '?')} s, throughput {tm.get('seconds', '?')} s, whole processes "
          f"{pm.get('seconds', '?')} s. Other processes "
          f"during the whole run: {fnum(sm.get('foreign_cores_all'), '{:.2f}')} cores (scenes), "
          f"{fnum(tm.get('foreign_cores_all'), '{:.2f}')} cores (throughput).\n")

if headline:
    summary = ["## Summary\n", table(["what", "measured", "target"], headline), ""]
    md[2:2] = summary  # after the title and the introduction
text = "\n".join(md) + "\n"
with open(os.path.join(OUT, "report.md"), "w") as f:
    f.write(text)
print(text)
print(f"report: {os.path.join(OUT, 'report.md')}; plots: "
      + ", ".join(os.path.join(OUT, p) for p in figs))
