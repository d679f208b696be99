"""Whole-run times of the shipped scenes compared with the depth-averaged
model (front, slope_release, wall_shock) at their default grids.

usage: scene_times.py MUFLOW OUTDIR [--repeats N]

Each case N times (default 3), the cases alternating, on the thread count
of the environment; wall and CPU seconds and the peak memory from the
process's own rusage, the 1-minute load before and after each run.  Writes
OUTDIR/scene_times.md (medians, spreads, loads)."""
import os
import statistics
import subprocess
import sys

from summary_ini import loadavg, summary, timed_run

CASES = ["front", "slope_release", "wall_shock"]


def main():
    muflow, outdir = sys.argv[1], sys.argv[2]
    repeats = int(sys.argv[sys.argv.index("--repeats") + 1]) if "--repeats" in sys.argv else 3
    os.makedirs(outdir, exist_ok=True)
    runs = {c: [] for c in CASES}
    for k in range(repeats):
        for c in CASES:
            d = os.path.join(outdir, "scene_times", c)
            load0 = loadavg()
            code, wall, cpu, mb = timed_run([muflow, f"cases/{c}.ini", f"output.dir={d}",
                                             "output.quiet=on"], stdout=subprocess.DEVNULL)
            s = summary(os.path.join(d, "summary.ini"))
            runs[c].append(dict(wall=wall, cpu=cpu, mb=mb, load=max(load0, loadavg()),
                                status=s.get("status", f"exit {code}"), steps=s.get("steps", "")))
            print(f"{c}: {runs[c][-1]}", flush=True)
    lines = [f"Default grids, {repeats} runs each alternating, OMP_NUM_THREADS="
             f"{os.environ.get('OMP_NUM_THREADS', 'unset')}: medians (min-max)", "",
             "| case | status, steps | wall s | CPU s | peak MB | load |", "|---|---|---|---|---|---|"]
    for c in CASES:
        rs = runs[c]
        w = [r["wall"] for r in rs]
        lines.append(f"| {c} | {rs[-1]['status']}, {rs[-1]['steps']} | "
                     f"{statistics.median(w):.1f} ({min(w):.1f}-{max(w):.1f}) | "
                     f"{statistics.median(r['cpu'] for r in rs):.1f} | "
                     f"{statistics.median(r['mb'] for r in rs):.0f} | "
                     f"{min(r['load'] for r in rs):.1f}-{max(r['load'] for r in rs):.1f} |")
    with open(os.path.join(outdir, "scene_times.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
