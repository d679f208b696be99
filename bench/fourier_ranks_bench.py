#!/usr/bin/python3
"""The plane Fourier line blocks over MPI ranks (solver.preconditioner =
fourier, docs/numerics/decomposition.md): cases/bagnold3d.ini (128 x 128 x
64 cells) for a fixed number of steps on 2 ranks x 1 thread against 1 rank
x 2 threads, alternated, REPEATS runs each: the march's wall time (the
summary's wall_seconds) and the process's, each rank's peak resident
memory and its bytes per local cell, the 1-minute load before and after
each run (the machine may be shared).  speed(2 x 1) / speed(1 x 2) is the
ratio of the medians, the last line printed.  Writes OUT/fourier_ranks.md
and prints it.

usage: fourier_ranks_bench.py MUFLOW OUTDIR REPEATS STEPS [mpirun ...]
       (the mpirun command and its options, default: mpirun --oversubscribe)
"""
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from summary_ini import loadavg, summary, timed_run  # noqa: E402

RANK_WRAPPER = "--rank"


def rank_main(argv):
    """Under mpirun: runs muflow, writes this rank's peak RSS (MB), CPU
    seconds and exit code into RSSDIR/rank<r>; exits 0, so that mpirun does
    not end the other ranks before theirs are written (a run stopped at
    solver.max_steps exits 3: unsteady)."""
    rssdir, cmd = argv[0], argv[1:]
    code, _, cpu, rss = timed_run(cmd, stdout=subprocess.DEVNULL)
    rank = os.environ.get("OMPI_COMM_WORLD_RANK", os.environ.get("PMI_RANK", "0"))
    with open(os.path.join(rssdir, "rank" + rank), "w") as f:
        f.write("%.1f %.2f %d\n" % (rss, cpu, code))
    sys.exit(0)


def one(muflow, case, outdir, steps, mpirun, ranks):
    """One run; (march s, process s, [peak RSS MB a rank], load before, after, result,
    CPU s of all ranks and threads)."""
    os.makedirs(outdir, exist_ok=True)
    for name in os.listdir(outdir):
        if name.startswith("rank"):
            os.remove(os.path.join(outdir, name))
    args = [muflow, case, "output.dir=" + outdir, "output.quiet=on",
            "solver.max_steps=%d" % steps]
    env = dict(os.environ, OMP_WAIT_POLICY="passive")
    if ranks > 1:
        env["OMP_NUM_THREADS"] = "1"
        cmd = mpirun + ["-np", str(ranks), sys.executable, os.path.abspath(__file__),
                        RANK_WRAPPER, outdir] + args
    else:
        env["OMP_NUM_THREADS"] = "2"
        cmd = args
    load0 = loadavg()
    code, wall, cpu, rss = timed_run(cmd, stdout=subprocess.DEVNULL, env=env)
    if ranks > 1 and code != 0:
        sys.exit("%s: exit %d" % (" ".join(cmd), code))
    load1 = loadavg()
    res = summary(os.path.join(outdir, "summary.ini"))
    # max_steps reached: status unsteady, exit code 1 by design (app/run.h)
    if res.get("steps") != str(steps):
        sys.exit("%s: %s steps, not %d (exit %d)" % (" ".join(cmd), res.get("steps"), steps,
                                                      code))
    if ranks > 1:
        per = [open(os.path.join(outdir, "rank%d" % r)).read().split() for r in range(ranks)]
        rss, cpu = [float(p[0]) for p in per], sum(float(p[1]) for p in per)
    else:
        rss = [rss]
    return float(res["wall_seconds"]), wall, rss, load0, load1, res, cpu


def main():
    if len(sys.argv) > 1 and sys.argv[1] == RANK_WRAPPER:
        rank_main(sys.argv[2:])
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    muflow, out, repeats, steps = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
    mpirun = sys.argv[5:] or ["mpirun", "--oversubscribe"]
    case = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "cases",
                        "bagnold3d.ini")
    cells = 128 * 128 * 64
    runs = {2: [], 1: []}
    for _ in range(repeats):
        for ranks in (2, 1):
            runs[ranks].append(one(muflow, case, os.path.join(out, "fourier_ranks%d" % ranks),
                                   steps, mpirun, ranks))
    rows = ["| ranks x threads | march s (median; runs) | process s (median) | CPU s, all "
            "(median) | peak RSS MB a rank | B a local cell | load before / after |",
            "|---|---|---|---|---|---|---|"]
    med = {}
    for ranks in (2, 1):
        r = runs[ranks]
        med[ranks] = (statistics.median(x[0] for x in r), statistics.median(x[1] for x in r),
                      statistics.median(x[6] for x in r))
        rss = max(max(x[2]) for x in r)
        rows.append("| %d x %d | %.2f (%s) | %.2f | %.2f | %.0f | %.0f | %s |" % (
            ranks, 2 // ranks, med[ranks][0], ", ".join("%.2f" % x[0] for x in r), med[ranks][1],
            med[ranks][2], rss, rss * 1048576.0 / (cells / ranks),
            ", ".join("%.1f / %.1f" % (x[3], x[4]) for x in r)))
    a, b = runs[2][0][5], runs[1][0][5]
    text = "\n".join([
        "bagnold3d 128 x 128 x 64, solver.preconditioner = fourier, %d steps, %d runs each "
        "(alternated)" % (steps, repeats), "",
        *rows, "",
        "speed(2 x 1) / speed(1 x 2): march %.3f, process %.3f; CPU(1 x 2) / CPU(2 x 1) %.3f"
        % (med[1][0] / med[2][0], med[1][1] / med[2][1], med[1][2] / med[2][2]),
        "residual after %d steps: %s (2 ranks), %s (1 rank)" % (steps, a.get("residual"),
                                                              b.get("residual")), ""])
    # the line to quote, last
    text += ("ratio: bagnold3d 128 x 128 x 64, 2 ranks x 1 thread at %.3f of 1 x 2's speed "
             "(march, medians of %d alternated runs, load %.1f-%.1f)\n"
             % (med[1][0] / med[2][0], repeats, min(min(x[3], x[4]) for k in runs for x in runs[k]),
                max(max(x[3], x[4]) for k in runs for x in runs[k])))
    with open(os.path.join(out, "fourier_ranks.md"), "w") as f:
        f.write(text)
    print(text)


if __name__ == "__main__":
    main()
