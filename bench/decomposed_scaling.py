"""Projected weak and strong scaling of the decomposed pressure multigrid
to 1,024 ranks (docs/numerics/decomposition.md), from bench_decomposed's
measurements (`make bench-decomposed`: OUTDIR/decomposed.txt).

usage: decomposed_scaling.py OUTDIR

Measured here: the compute time per cell and PCG iteration on one rank of
one thread (the 128^3 run's CPU seconds: the work, on shared cores too),
the serial cycle of a gathered level of 4,096 cells (the 16^3 run's CPU
seconds an iteration), the peak RSS and the solver's bytes per local cell.  Modelled: the
traffic of one PCG iteration of the busiest rank (an interior block), the
formulas of multigrid_traffic_model, checked here against every measured
rank line first; its cost on a network of latency ALPHA and bandwidth BETA
(Hockney's model), the gathered level's allgather and its serial cycles
(every rank runs them: they do not shrink with the ranks), and the three
sums over the ranks per iteration.  Writes OUTDIR/decomposed_scaling.md and
OUTDIR/decomposed_scaling.png."""
import math
import os
import sys

ALPHA = 1.5e-6  # s per message: EDR InfiniBand MPI latency between nodes
BETA = 10e9     # bytes/s: EDR's 12.5 GB/s line rate at 80 % for MPI payload
GATHER_CELLS = 4096  # MG_GATHER_CELLS: gathered below this
PRE, POST, GAMMA = 2, 2, 2  # the cycle's defaults (multigrid_default_options)
BASILISK = {2: 1.0, 4: 0.96, 8: 0.89, 16: 0.79}  # 3D Poisson, 512^3 cells


def read_lines(path):
    runs = []
    with open(path) as f:
        for line in f:
            if line.startswith("traffic "):
                runs.append({k: float(v) for k, v in
                             (w.split("=") for w in line.split()[1:])})
    return runs


def dims_create(p):
    """MPI_Dims_create for a power of two: factors of 2 to the smallest."""
    d = [1, 1, 1]
    while p > 1:
        i = d.index(min(d))
        d[i] *= 2
        p //= 2
    return sorted(d, reverse=True)


def hierarchy(n, dims):
    """Local blocks of the levels kept on the ranks (every direction halved
    while the global level above has more than GATHER_CELLS cells and the
    blocks halve in place), and the gathered level's global cells."""
    blocks = [[n[d] // dims[d] for d in range(3)]]
    glob = list(n)
    while (math.prod(glob) > GATHER_CELLS and all(b % 2 == 0 for b in blocks[-1])
           and all(g % 2 == 0 for g in glob)):
        blocks.append([b // 2 for b in blocks[-1]])
        glob = [g // 2 for g in glob]
    return blocks, math.prod(glob)


def fill(block, sides):
    """One halo fill: bytes, messages, directions exchanged."""
    b = m = k = 0
    for d in range(3):
        if sides[d]:
            e1, e2 = [e for e in range(3) if e != d]
            b += sides[d] * (block[e1] + 2) * (block[e2] + 2) * 8
            m += sides[d]
            k += 1
    return b, m, k


def iteration(n, dims, sides=None):
    """One PCG iteration of the busiest rank (a cycle and L p): halo bytes,
    messages, directions; gathers, their bytes received; gathered cells."""
    if sides is None:  # an interior block: two sides where three blocks or more
        sides = [min(2, p - 1) for p in dims]
    blocks, gathered = hierarchy(n, dims)
    last = len(blocks) - 1
    fills = 2 * (PRE + POST) + 2
    t = {"bytes": 0, "messages": 0, "dirs": 0}

    def add(block, times):
        b, m, k = fill(block, sides)
        t["bytes"] += times * b
        t["messages"] += times * m
        t["dirs"] += times * k
    visits, above = 1, 1
    for l in range(last):
        add(blocks[l], visits * fills)
        add(blocks[l + 1], visits)
        above, visits = visits, visits * GAMMA
    ranks = math.prod(dims)
    slots = math.prod(b + 2 for b in blocks[last])
    t["gathers"] = visits + (visits - above if last > 0 else 0)
    t["gather_recv"] = t["gathers"] * (ranks - 1) * slots * 8 if ranks > 1 else 0
    t["coarse_visits"] = visits
    t["gathered"] = gathered
    t["levels"] = len(blocks)
    cycle = dict(t)
    add(blocks[0], 1)  # L p
    return cycle, t


def check_model(runs):
    """The model's cycle of every measured run equals its measured cycle."""
    for r in runs:
        n = [int(r["N"])] * 3
        ranks = int(r["ranks"])
        dims = dims_create(ranks)
        cycle, _ = iteration(n, dims, [1 if p > 1 else 0 for p in dims])
        if ranks > 1 and (cycle["bytes"] != r["cycle_bytes"] or
                          cycle["messages"] != r["cycle_messages"] or
                          cycle["gather_recv"] != r["cycle_gather_recv"]):
            sys.exit("decomposed_scaling: the model misses N %d on %d ranks (rank %d): %s"
                     % (n[0], ranks, r["rank"], cycle))


def seconds(n, ranks, t_cell, t_visit):
    """One PCG iteration's time on `ranks` ranks: compute, halo, gathered
    level (allgather and its serial cycles), sums; and the traffic."""
    dims = dims_create(ranks)
    _, t = iteration(n, dims)
    cells = math.prod(n) / ranks
    logp = math.ceil(math.log2(ranks)) if ranks > 1 else 0
    parts = {
        "compute": t_cell * cells,
        "halo": t["dirs"] * ALPHA + t["bytes"] / BETA,
        "gather": (t["gathers"] * logp * ALPHA + t["gather_recv"] / BETA
                   + (t["coarse_visits"] * t_visit * t["gathered"] / GATHER_CELLS
                      if ranks > 1 else 0.0)),
        "sums": 3 * logp * ALPHA,
    }
    return parts, t, dims


def table(rows, title, base_cells_per_rank, t_cell, t_visit, weak):
    out = ["### " + title, "",
           "| ranks | blocks | levels on ranks | halo MB / it | messages / it | gather KB / it "
           "| compute ms | halo ms | gathered level ms | sums ms | efficiency |",
           "|---|---|---|---|---|---|---|---|---|---|---|"]
    eff = {}
    for p, n in rows:
        parts, t, dims = seconds(n, p, t_cell, t_visit)
        total = sum(parts.values())
        ideal = t_cell * (base_cells_per_rank if weak else math.prod(n) / p)
        eff[p] = ideal / total
        out.append("| %d | %s | %d | %.2f | %d | %.0f | %.2f | %.2f | %.2f | %.3f | %.3f |" % (
            p, "x".join(str(n[d] // dims[d]) for d in range(3)), t["levels"], t["bytes"] / 1e6,
            t["messages"], t["gather_recv"] / 1e3, 1e3 * parts["compute"], 1e3 * parts["halo"],
            1e3 * parts["gather"], 1e3 * parts["sums"], eff[p]))
    return out + [""], eff


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    outdir = sys.argv[1]
    runs = read_lines(os.path.join(outdir, "decomposed.txt"))
    check_model(runs)
    one = [r for r in runs if r["ranks"] == 1 and r["N"] == max(q["N"] for q in runs)][0]
    t_cell = one["cpu_s"] / (one["iterations"] * one["cells"])
    small = [r for r in runs if r["ranks"] == 1 and r["cells"] == GATHER_CELLS][0]
    t_visit = small["cpu_s"] / small["iterations"]
    biggest = max((r for r in runs if r["ranks"] > 1), key=lambda r: r["cells"])
    rss, solver = biggest["rss_bytes"] / biggest["cells"], biggest["solver_bytes"] / biggest["cells"]
    lines = ["# The decomposed multigrid: projected scaling", "",
             "Measured (bench_decomposed, 1 thread a rank, CPU time): %.1f ns per cell and PCG "
             "iteration (%d^3 on 1 rank), %.3f ms a gathered level's cycle (16^3); %.0f B of peak RSS and %.0f B of solver per local cell "
             "(%d^3 on %d ranks).  Network: alpha %.1f us, beta %.0f GB/s.  The model's "
             "cycle equals every measured rank's (bytes, messages, gathers)." % (
                 1e9 * t_cell, one["N"], 1e3 * t_visit, rss, solver, biggest["N"], biggest["ranks"],
                 1e6 * ALPHA, BETA / 1e9), ""]
    pows = [2 ** k for k in range(11)]
    n9 = [1024, 1024, 1024]
    strong, e_strong = table([(p, n9) for p in pows], "Strong: 1024^3 (1.07e9 cells)",
                             0, t_cell, t_visit, False)
    weak_rows = [(p, [64 * d if i == 0 else 128 * d for i, d in
                      enumerate(dims_create(p))]) for p in pows]
    weak, e_weak = table(weak_rows, "Weak: 64 x 128 x 128 cells a rank (1024^3 on 1,024)",
                         64 * 128 * 128, t_cell, t_visit, True)
    b512, e512 = table([(p, [512] * 3) for p in (2, 4, 8, 16)],
                       "Strong: 512^3 (1.34e8 cells), beside Basilisk", 0, t_cell,
                       t_visit, False)
    lines += strong + weak + b512
    lines.append("512^3 from 2 ranks: ours %s; Basilisk's measured %s" % (
        ", ".join("%d: %.2f" % (p, e512[p] / e512[2]) for p in (4, 8, 16)),
        ", ".join("%d: %.2f" % (p, BASILISK[p]) for p in (4, 8, 16))))
    with open(os.path.join(outdir, "decomposed_scaling.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.semilogx(pows, [e_strong[p] for p in pows], "o-", base=2, label="strong, 1024^3 (model)")
    ax.semilogx(pows, [e_weak[p] for p in pows], "s-", base=2, label="weak, 1M cells a rank (model)")
    ax.semilogx(list(BASILISK), [e512[p] / e512[2] for p in BASILISK], "^-", base=2,
                label="strong, 512^3 from 2 ranks (model)")
    ax.semilogx(list(BASILISK), list(BASILISK.values()), "kx--", base=2,
                label="Basilisk, 512^3 from 2 ranks (measured)")
    ax.set_xlabel("ranks")
    ax.set_ylabel("parallel efficiency")
    ax.set_ylim(0, 1.05)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "decomposed_scaling.png"), dpi=120)


if __name__ == "__main__":
    main()
