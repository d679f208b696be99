#!/usr/bin/python3
"""The 3D steady bagnold run (cases/bagnold3d.ini, 128 x 128 x 64 cells from
rest plus a divergence-free 3D perturbation) on the threads the environment
gives (make bench-3d: 2), beside the 1D run of the same nz: wall time of the
whole process, steps, peak resident memory (the child's rusage), err_rms of
both, and the 1-minute load average before and after (the machine may be
shared: other processes inflate the wall time).  Writes OUT/bagnold3d.md
(a markdown table) and prints it.

usage: bagnold3d_bench.py MUFLOW OUTDIR [section.key=value ...]
"""
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from summary_ini import loadavg, summary, timed_run  # noqa: E402


def run(muflow, case, outdir, overrides):
    """Runs one case; returns its [result] section, wall seconds, peak RSS
    (MB) and CPU seconds (user + system, all threads)."""
    cmd = [muflow, case, "output.dir=" + outdir, "output.quiet=on"] + overrides
    code, wall, cpu, rss = timed_run(cmd, stdout=subprocess.DEVNULL)
    if code != 0:
        sys.exit("%s failed (exit %d)" % (" ".join(cmd), code))
    return summary(os.path.join(outdir, "summary.ini")), wall, rss, cpu


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    muflow, out = sys.argv[1], sys.argv[2]
    overrides = sys.argv[3:]
    here = os.path.dirname(os.path.abspath(__file__))
    cases = os.path.join(here, "..", "cases")
    os.makedirs(out, exist_ok=True)
    threads = os.environ.get("OMP_NUM_THREADS", "all")
    load0 = loadavg()
    r3, wall3, rss3, cpu3 = run(muflow, os.path.join(cases, "bagnold3d.ini"),
                          os.path.join(out, "bagnold3d"), overrides)
    load1 = loadavg()
    nz = [o.split("=", 1)[1] for o in overrides if o.startswith("domain.nz=")]
    r1, wall1, _, cpu1 = run(muflow, os.path.join(cases, "bagnold.ini"), os.path.join(out, "bagnold1d"),
                       ["domain.nz=" + (nz[0] if nz else "64")])
    domain = summary(os.path.join(out, "bagnold3d", "summary.ini"), "domain")
    dims = [int(domain[k]) for k in ("nx", "ny", "nz")]
    n3 = "%d x %d x %d = %d" % (dims[0], dims[1], dims[2], dims[0] * dims[1] * dims[2])
    rows = [
        "| run | cells | threads | status | steps | wall s | CPU s | peak RSS MB | err_rms "
        "| load before / after |",
        "|---|---|---|---|---|---|---|---|---|---|",
        "| bagnold3d (3D, from rest + perturbation) | %s | %s | %s | %s | %.1f | %.1f | %.0f | %s "
        "| %.2f / %.2f |"
        % (n3, threads, r3["status"], r3["steps"], wall3, cpu3, rss3, r3["err_rms"], load0,
           load1),
        "| bagnold 1D, same nz | 2 x 1 x %s | %s | %s | %s | %.2f | %.2f | | %s | |"
        % (nz[0] if nz else "64", threads, r1["status"], r1["steps"], wall1, cpu1,
           r1["err_rms"]),
    ]
    diff = abs(float(r3["err_rms"]) - float(r1["err_rms"]))
    text = "\n".join(rows) + "\n\n|err_rms(3D) - err_rms(1D)| = %.3e\n" % diff
    with open(os.path.join(out, "bagnold3d.md"), "w") as f:
        f.write(text)
    print(text)


if __name__ == "__main__":
    main()
