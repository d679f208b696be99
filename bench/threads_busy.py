#!/usr/bin/env python3
"""Every case file at its default threads against one thread and two passive
threads, on an idle machine and beside two other busy processes.

    /usr/bin/python3 bench/threads_busy.py build/muflow OUT [--repeats N] [--cases a,b]

For each case file of cases/ (with the bounds below on the long ones), the
three settings run alternately, N times each, first with nothing else
running, then with two processes that spin on the two cores (a user's busy
laptop), each block once the load average shows it.  Writes OUT/threads_busy.md: the median wall seconds of each
setting, the ratio of the default to the better of the other two (the
default should be within 1.2 of it when busy), and the load average beside
each block; OUT/threads_busy.csv has every run.
"""
import argparse
import csv
import os
import statistics
import subprocess
import sys
import tempfile
import time

# Overrides that bound the long runs (the whole run of every other case).
BOUNDS = {
    "bagnold3d": ["solver.max_steps=3"],
    "collapse": ["solver.end_time=0.5"],
    "cylinder": ["solver.max_steps=20"],
    "cylinder_benchmark": ["solver.end_time=1"],
}

SETTINGS = [
    ("default", {}),
    ("one thread", {"OMP_NUM_THREADS": "1"}),
    ("two passive", {"OMP_NUM_THREADS": "2", "OMP_WAIT_POLICY": "passive"}),
]


def spin():
    """A process that keeps one core busy until killed."""
    return subprocess.Popen([sys.executable, "-c", "while True: pass"])


def settle(busy, limit=120.0):
    """Waits (up to limit s) until the 1-minute load average says what the
    block is: at least the cores less half a core beside the spinners (a
    machine that has been busy for a while, which muflow reads at start to
    choose its threads' waiting), below half a core when idle."""
    cores = os.cpu_count() or 1
    t0 = time.monotonic()
    while time.monotonic() - t0 < limit:
        load = os.getloadavg()[0]
        if (busy and load >= cores - 0.5) or (not busy and load < 0.5):
            return
        time.sleep(2.0)


def run(muflow, case, extra, env_extra, outdir):
    env = dict(os.environ)
    env.pop("OMP_WAIT_POLICY", None)
    env.pop("GOMP_SPINCOUNT", None)
    env.pop("OMP_NUM_THREADS", None)  # the default: OpenMP's count, the cores
    env.update(env_extra)
    cmd = [muflow, case, "output.quiet=on", "output.fields=off", "output.dir=" + outdir] + extra
    t0 = time.monotonic()
    rc = subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode
    return time.monotonic() - t0, rc


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("muflow")
    ap.add_argument("out")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--cases", default="")
    a = ap.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    names = sorted(f[:-4] for f in os.listdir(os.path.join(root, "cases")) if f.endswith(".ini"))
    if a.cases:
        names = [n for n in names if n in a.cases.split(",")]
    os.makedirs(a.out, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for busy in (False, True):
            spinners = [spin(), spin()] if busy else []
            settle(busy)
            try:
                for name in names:
                    case = os.path.join(root, "cases", name + ".ini")
                    extra = BOUNDS.get(name, [])
                    load0 = os.getloadavg()[0]
                    times = {s: [] for s, _ in SETTINGS}
                    # short runs repeat until each setting has about 3 s of runs
                    first, _ = run(a.muflow, case, extra, {}, os.path.join(tmp, name))
                    repeats = max(a.repeats, min(15, int(3.0 / max(first, 1e-3)) + 1))
                    for r in range(repeats):
                        order = SETTINGS if r % 2 == 0 else SETTINGS[::-1]
                        for label, env in order:
                            t, rc = run(a.muflow, case, extra, env, os.path.join(tmp, name))
                            times[label].append(t)
                            rows.append({"busy": int(busy), "case": name, "setting": label,
                                         "repeat": r, "seconds": f"{t:.3f}", "exit": rc})
                    med = {s: statistics.median(v) for s, v in times.items()}
                    best = min(med["one thread"], med["two passive"])
                    line = (busy, name, med["default"], med["one thread"], med["two passive"],
                            med["default"] / best, load0, os.getloadavg()[0])
                    print("%-5s %-20s default %7.3f  one %7.3f  passive %7.3f  ratio %.2f  load %.1f-%.1f"
                          % ((("busy" if busy else "idle"),) + line[1:]), flush=True)
                    rows.append({"busy": int(busy), "case": name, "setting": "summary",
                                 "repeat": "", "seconds": "%.3f %.3f %.3f %.2f %.1f %.1f" % line[2:],
                                 "exit": ""})
            finally:
                for p in spinners:
                    p.kill()
                    p.wait()
    with open(os.path.join(a.out, "threads_busy.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["busy", "case", "setting", "repeat", "seconds", "exit"])
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(a.out, "threads_busy.md"), "w") as f:
        f.write("Median wall seconds of at least %d alternating runs per setting (up to 15 "
                "for runs under a second; default: no thread setting (OpenMP's count, the cores), so muflow's own choice; the load is the 1-minute "
                "average before and after; bounds: %s).\n\n" % (a.repeats, "; ".join(
                    "%s %s" % (k, " ".join(v)) for k, v in BOUNDS.items())))
        for busy in (0, 1):
            f.write("\n%s\n\n" % ("Beside two busy processes" if busy else "Idle machine"))
            f.write("| case | default | one thread | two passive | default / better | load |\n")
            f.write("|---|---|---|---|---|---|\n")
            for r in rows:
                if r["setting"] == "summary" and r["busy"] == busy:
                    d, o, p, ratio, l0, l1 = r["seconds"].split()
                    f.write("| %s | %s | %s | %s | %s | %s-%s |\n" % (r["case"], d, o, p, ratio, l0, l1))
    print("wrote", os.path.join(a.out, "threads_busy.md"))


if __name__ == "__main__":
    main()
