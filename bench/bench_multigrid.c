/* Geometric multigrid (src/solvers/multigrid.c): convergence per cycle and time.
 *
 *   bench_multigrid OUTDIR [sections]     sections: any of variants scaling big
 *                                         (default: all three)
 *
 * The problem: the unit square / cube with a heavy blob, a = 1e-4 in a ball
 * of radius 0.3 around (0.45, 0.55, 0.5) (density ratio 1e4, interface on no
 * coarse grid line), 1 outside, faces across the interface at the harmonic
 * mean of their cells; Neumann walls in x, periodic y, Dirichlet z (the
 * hydrostatic pressure set-up); a random right-hand side (every frequency
 * present, the hardest case for a rate).
 *
 *  variants  the design choices on 256^2 and 64^3: prolongation (flux,
 *            linear, constant), coarse coefficients (coincident, harmonic),
 *            sweeps and V / W cycles, stationary cycles and PCG
 *  scaling   default options, 32^2 .. 1024^2 and 32^3 .. 128^3: mean
 *            reduction per cycle, time per cycle, time to 1e-10
 *  big       256^3 to relative residual 1e-10 (blob 1e4, and a = 1) beside
 *            the FFT solve of the same grid (a = 1): wall times, cycles,
 *            memory
 *
 * Writes OUTDIR/multigrid.md (markdown tables) and prints it. */
#include <math.h>
#include <stdarg.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include "bench.h"
#include "grid/grid.h"
#include "solvers/multigrid.h"
#include "solvers/poisson.h"

static const enum poisson_bc bcs[3][2] = {{POISSON_NEUMANN, POISSON_NEUMANN},
                                          {POISSON_PERIODIC, POISSON_PERIODIC},
                                          {POISSON_DIRICHLET, POISSON_DIRICHLET}};

struct problem {
    struct grid g;
    double *a[3], *rhs, *phi;
};

static double rand_pm1(unsigned long long *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / 4503599627370496.0 - 1.0;
}

static void *must(void *p)
{
    if (!p) {
        fprintf(stderr, "bench_multigrid: out of memory\n");
        exit(1);
    }
    return p;
}

/* ratio: the blob's coefficient is 1/ratio (ratio 1: a = 1 everywhere) */
static void problem_init(struct problem *pb, const int n[3], double ratio)
{
    const double len[3] = {1.0, 1.0, 1.0};
    if (grid_init(&pb->g, n, len) != 0)
        exit(2);
    const struct grid *g = &pb->g;
    double *cell = must(field_alloc(g));
    for (int d = 0; d < 3; d++)
        pb->a[d] = must(field_alloc(g));
    pb->rhs = must(field_alloc(g));
    pb->phi = must(field_alloc(g));
#pragma omp parallel for collapse(2) schedule(static)
    for (int i = -1; i <= n[0]; i++)
        for (int j = -1; j <= n[1]; j++)
            for (int l = -1; l <= n[2]; l++) {
                double x = (i + 0.5) * g->h[0] - 0.45, y = (j + 0.5) * g->h[1] - 0.55,
                       z = (l + 0.5) * g->h[2] - 0.5;
                double r2 = x * x + z * z + (n[1] > 1 ? y * y : 0.0);
                cell[grid_idx(g, i, j, l)] = r2 < 0.09 ? 1.0 / ratio : 1.0;
            }
    for (int d = 0; d < 3; d++) {
        const ptrdiff_t sd = g->stride[d];
        double *a = pb->a[d];
#pragma omp parallel for collapse(2) schedule(static)
        for (int i = 0; i <= n[0]; i++)
            for (int j = 0; j <= n[1]; j++)
                for (int l = 0; l <= n[2]; l++) {
                    ptrdiff_t m = grid_idx(g, i, j, l);
                    double c1 = cell[m], c0 = cell[m - sd];
                    a[m] = 2.0 * c0 * c1 / (c0 + c1);
                }
    }
    field_free(cell);
    unsigned long long seed = 12345;
    for (int i = 0; i < n[0]; i++)
        for (int j = 0; j < n[1]; j++)
            for (int l = 0; l < n[2]; l++)
                pb->rhs[grid_idx(g, i, j, l)] = rand_pm1(&seed);
}

static void problem_free(struct problem *pb)
{
    for (int d = 0; d < 3; d++)
        field_free(pb->a[d]);
    field_free(pb->rhs);
    field_free(pb->phi);
}

struct result {
    int cycles, converged;
    double rate, setup, solve, per_cycle;
    size_t bytes;
    int levels;
    int coarse[3];
};

/* Creates the solver, sets the coefficients, solves from phi = 0 to rtol. */
static struct result run(struct problem *pb, const struct multigrid_options *opt, int pcg,
                         double rtol, int max_cycles)
{
    struct result res;
    memset(&res, 0, sizeof(res));
    char err[256];
    struct multigrid *mg = NULL;
    double t0 = bench_now();
    if (multigrid_create(&mg, &pb->g, bcs, opt, err, sizeof(err)) != 0 ||
        multigrid_set_coefficients(mg, pb->a, err, sizeof(err)) != 0) {
        fprintf(stderr, "bench_multigrid: %s\n", err);
        exit(1);
    }
    res.setup = bench_now() - t0;
    memset(pb->phi, 0, pb->g.size * sizeof(double));
    struct multigrid_stats st;
    t0 = bench_now();
    if (pcg)
        multigrid_pcg(mg, pb->rhs, pb->phi, rtol, max_cycles, &st);
    else
        multigrid_solve(mg, pb->rhs, pb->phi, rtol, max_cycles, &st);
    res.solve = bench_now() - t0;
    res.cycles = st.cycles;
    res.converged = st.converged;
    res.rate = st.rate;
    res.per_cycle = st.cycles ? res.solve / st.cycles : 0.0;
    res.bytes = multigrid_bytes(mg);
    res.levels = multigrid_levels(mg);
    multigrid_level_size(mg, res.levels - 1, res.coarse);
    multigrid_destroy(mg);
    return res;
}

static FILE *md;

static void out(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static void out(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vprintf(fmt, ap);
    va_end(ap);
    va_start(ap, fmt);
    vfprintf(md, fmt, ap);
    va_end(ap);
    fflush(stdout);
}

static const char *prolong_name[] = {"flux", "linear", "constant"};
static const char *average_name[] = {"harmonic", "coincident"};

static void section_variants(void)
{
    static const int sizes[][3] = {{256, 1, 256}, {64, 64, 64}};
    /* prolongation, coarse coefficients, sweeps, gamma */
    static const int var[][4] = {{0, 1, 1, 1}, {0, 1, 2, 1}, {0, 1, 1, 2}, {0, 1, 2, 2},
                                 {0, 0, 2, 1}, {0, 0, 2, 2}, {1, 1, 2, 1}, {1, 1, 2, 2},
                                 {2, 1, 2, 1}, {2, 1, 2, 2}};
    out("## Design variants (blob, coefficient ratio 1e4, rtol 1e-10)\n\n");
    out("Mean reduction of the residual per cycle (stationary cycles, at most 60) and per "
        "PCG iteration (at most 60); `-` = not converged in 60 (the rate is then that of the "
        "60 cycles; above 1: diverging).  Coarse coefficients: `coincident` = arithmetic mean "
        "of the fine faces the coarse face covers, `harmonic` = series resistance of three "
        "fine faces along the normal, arithmetic across.\n\n");
    out("| grid | prolongation | coarse coefficients | cycle | cycles: rate | cycles | "
        "PCG: rate | iterations | PCG s |\n|---|---|---|---|---|---|---|---|---|\n");
    for (size_t s = 0; s < sizeof(sizes) / sizeof(sizes[0]); s++) {
        struct problem pb;
        problem_init(&pb, sizes[s], 1e4);
        for (size_t k = 0; k < sizeof(var) / sizeof(var[0]); k++) {
            struct multigrid_options o;
            multigrid_default_options(&o);
            o.prolong = (enum multigrid_prolong)var[k][0];
            o.average = (enum multigrid_average)var[k][1];
            o.pre = o.post = var[k][2];
            o.gamma = var[k][3];
            struct result v = run(&pb, &o, 0, 1e-10, 60);
            struct result c = run(&pb, &o, 1, 1e-10, 60);
            out("| %dx%dx%d | %s | %s | %c(%d,%d) | %.3f | %s%d | %.3f | %s%d | %.3f |\n",
                sizes[s][0], sizes[s][1], sizes[s][2], prolong_name[var[k][0]],
                average_name[var[k][1]], var[k][3] == 2 ? 'W' : 'V', var[k][2], var[k][2],
                v.rate, v.converged ? "" : "- ", v.cycles, c.rate, c.converged ? "" : "- ",
                c.cycles, c.solve);
        }
        problem_free(&pb);
    }
    out("\n");
}

static void section_scaling(void)
{
    static const int sizes[][3] = {{32, 1, 32},   {64, 1, 64},    {128, 1, 128}, {256, 1, 256},
                                   {512, 1, 512}, {1024, 1, 1024}, {32, 32, 32},  {64, 64, 64},
                                   {128, 128, 128}};
    out("## Scaling (default options: W(2,2), flux prolongation; blob, coefficient ratio 1e4, "
        "rtol 1e-10, %d threads)\n\n",
        omp_get_max_threads());
    out("| grid | levels (coarsest) | W-cycles: rate | cycles | s / cycle | PCG: rate | "
        "iterations | s / iteration | PCG total s | set-up s |\n"
        "|---|---|---|---|---|---|---|---|---|---|\n");
    for (size_t s = 0; s < sizeof(sizes) / sizeof(sizes[0]); s++) {
        struct problem pb;
        problem_init(&pb, sizes[s], 1e4);
        struct result v = run(&pb, NULL, 0, 1e-10, 100);
        struct result c = run(&pb, NULL, 1, 1e-10, 100);
        out("| %dx%dx%d | %d (%dx%dx%d) | %.3f | %s%d | %.2e | %.3f | %s%d | %.2e | %.3f | %.3f |\n",
            sizes[s][0], sizes[s][1], sizes[s][2], c.levels, c.coarse[0], c.coarse[1],
            c.coarse[2], v.rate, v.converged ? "" : "- ", v.cycles, v.per_cycle, c.rate,
            c.converged ? "" : "- ", c.cycles, c.per_cycle, c.solve, c.setup);
        problem_free(&pb);
    }
    out("\n");
}

static double rss_gib(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_maxrss / (1024.0 * 1024.0); /* kB -> GiB */
}

static void section_big(void)
{
    const int n[3] = {256, 256, 256};
    out("## 256^3 (%d threads): multigrid to relative residual 1e-10 beside the FFT solve\n\n",
        omp_get_max_threads());
    out("| solver | coefficients | set-up s | solve s | cycles | rate | solver memory GiB |\n"
        "|---|---|---|---|---|---|---|\n");
    struct problem pb;
    problem_init(&pb, n, 1e4);
    double field_gib = (double)pb.g.size * 8.0 / (1024.0 * 1024.0 * 1024.0);
    struct result c = run(&pb, NULL, 1, 1e-10, 100);
    out("| multigrid PCG | blob 1e4 | %.2f | %.2f | %d | %.3f | %.2f |\n", c.setup, c.solve,
        c.cycles, c.rate, (double)c.bytes / (1024.0 * 1024.0 * 1024.0));
    struct result v = run(&pb, NULL, 0, 1e-10, 100);
    out("| multigrid W-cycles | blob 1e4 | %.2f | %.2f | %d | %.3f | %.2f |\n", v.setup, v.solve,
        v.cycles, v.rate, (double)v.bytes / (1024.0 * 1024.0 * 1024.0));
    problem_free(&pb);
    problem_init(&pb, n, 1.0);
    struct result u = run(&pb, NULL, 1, 1e-10, 100);
    out("| multigrid PCG | a = 1 | %.2f | %.2f | %d | %.3f | %.2f |\n", u.setup, u.solve, u.cycles,
        u.rate, (double)u.bytes / (1024.0 * 1024.0 * 1024.0));
    struct result w = run(&pb, NULL, 0, 1e-10, 100);
    out("| multigrid W-cycles | a = 1 | %.2f | %.2f | %d | %.3f | %.2f |\n", w.setup, w.solve,
        w.cycles, w.rate, (double)w.bytes / (1024.0 * 1024.0 * 1024.0));
    struct poisson_fft *ps = NULL;
    char err[256];
    double t0 = bench_now();
    if (poisson_fft_create(&ps, &pb.g, bcs, err, sizeof(err)) != 0) {
        fprintf(stderr, "bench_multigrid: %s\n", err);
        exit(1);
    }
    double fsetup = bench_now() - t0;
    double ft[3];
    for (int r = 0; r < 3; r++) {
        t0 = bench_now();
        poisson_fft_solve(ps, pb.rhs, pb.phi);
        ft[r] = bench_now() - t0;
    }
    poisson_fft_destroy(ps);
    out("| FFT (poisson_fft) | a = 1 only | %.2f | %.2f | direct | - | %.2f |\n", fsetup,
        bench_median(ft, 3), field_gib);
    problem_free(&pb);
    out("\nSolver memory: what the solver allocates (levels, work arrays, coarsest factor); "
        "one field of this grid is %.2f GiB; the caller's coefficient, rhs and phi fields (5 "
        "fields) come on top.  Peak resident size of the whole benchmark: %.2f GiB.  Set-up "
        "of the FFT is FFTW_MEASURE planning.\n\n",
        field_gib, rss_gib());
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_multigrid OUTDIR [variants] [scaling] [big]\n");
        return 2;
    }
    int want[3] = {argc < 3, argc < 3, argc < 3};
    for (int a = 2; a < argc; a++) {
        want[0] |= strcmp(argv[a], "variants") == 0;
        want[1] |= strcmp(argv[a], "scaling") == 0;
        want[2] |= strcmp(argv[a], "big") == 0;
    }
    bench_mkdir(argv[1]);
    md = bench_open(argv[1], "multigrid.md");
    struct bench_cpu cpu;
    bench_cpu_start(&cpu);
    double t0 = bench_now();
    out("# Multigrid\n\nProblem: unit square / cube, a = 1e-4 in a ball of radius 0.3 (ratio "
        "1e4, interface on no coarse grid line), Neumann x, periodic y, Dirichlet z, random "
        "right-hand side; relative residual = ||rhs - L phi||_2 / ||rhs||_2.\n\n");
    if (want[0])
        section_variants();
    if (want[1])
        section_scaling();
    if (want[2])
        section_big();
    out("Benchmark wall time %.0f s; other processes used %.2f cores on average meanwhile "
        "(timings are inflated when this is above ~0.2).\n",
        bench_now() - t0, bench_cpu_foreign(&cpu));
    fclose(md);
    return 0;
}
