/* FFTW_ESTIMATE against FFTW_MEASURE for the pressure transforms: the cost of
 * planning one forward + backward pair in a fresh planner (wisdom forgotten)
 * and the cost of one solve's two transforms with the plans each gives, per
 * grid and thread count; then how many solves the measured plans need to win
 * back their planning (the crossover).
 *
 *   bench_fftplan [OUTDIR [reps]]     writes OUTDIR/fftplan.csv, prints the table
 *
 * The transform kinds are those of the shipped scenes: R2HC along x and y
 * (periodic), REDFT11 along z (no-slip base, free surface: Neumann / Dirichlet
 * for the pressure).  Timings are minima over `reps` repeats, taken back to
 * back, so a busy machine inflates both columns alike; read the ratios. */
#include <fftw3.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include "bench.h"

struct shape {
    const char *name;
    int n[3];
};

static const struct shape shapes[] = {
    {"bagnold 2x1x40", {2, 1, 40}},      {"chute 1x80x2", {1, 80, 2}},
    {"heap-like 70x1x100", {70, 1, 100}}, {"16^3", {16, 16, 16}},
    {"32x32x16", {32, 32, 16}},           {"32^3", {32, 32, 32}},
    {"64x64x32", {64, 64, 32}},           {"64^3", {64, 64, 64}},
    {"128x128x64", {128, 128, 64}},
};

struct result {
    double plan, exec;
};

static struct result measure(const int n[3], unsigned flags, int threads, int reps)
{
    size_t cells = (size_t)n[0] * (size_t)n[1] * (size_t)n[2];
    double *buf = fftw_malloc(cells * sizeof(double));
    fftw_forget_wisdom();
    fftw_plan_with_nthreads(threads);
    double t0 = bench_now();
    fftw_plan f = fftw_plan_r2r_3d(n[0], n[1], n[2], buf, buf, FFTW_R2HC, FFTW_R2HC,
                                   FFTW_REDFT11, flags);
    fftw_plan b = fftw_plan_r2r_3d(n[0], n[1], n[2], buf, buf, FFTW_HC2R, FFTW_HC2R,
                                   FFTW_REDFT11, flags);
    struct result r = {bench_now() - t0, 1e30};
    for (size_t i = 0; i < cells; i++)
        buf[i] = (double)(i % 17) - 8.0;
    for (int k = 0; k < reps; k++) {
        double t1 = bench_now();
        fftw_execute(f);
        fftw_execute(b);
        double t = bench_now() - t1;
        if (t < r.exec)
            r.exec = t;
        for (size_t i = 0; i < cells; i++) /* keep the values bounded */
            buf[i] *= 1e-3;
    }
    fftw_destroy_plan(f);
    fftw_destroy_plan(b);
    fftw_free(buf);
    return r;
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "bench/out";
    int reps = argc > 2 ? atoi(argv[2]) : 20;
    if (reps < 1)
        reps = 1;
    bench_mkdir(dir);
    FILE *f = bench_open(dir, "fftplan.csv");
    if (!fftw_init_threads())
        return 1;
    fprintf(f, "grid,cells,threads,plan_estimate_s,plan_measure_s,solve_estimate_s,"
               "solve_measure_s,crossover_solves\n");
    printf("%-20s %9s %3s %11s %11s %11s %11s %10s\n", "grid", "cells", "thr", "plan EST",
           "plan MEAS", "solve EST", "solve MEAS", "crossover");
    for (size_t s = 0; s < sizeof shapes / sizeof shapes[0]; s++) {
        const int *n = shapes[s].n;
        double cells = (double)n[0] * n[1] * n[2];
        for (int threads = 1; threads <= 2; threads++) {
            /* interleaved, twice: a change of the machine's load hits both */
            struct result e = measure(n, FFTW_ESTIMATE, threads, reps);
            struct result m = measure(n, FFTW_MEASURE, threads, reps);
            struct result e2 = measure(n, FFTW_ESTIMATE, threads, reps);
            struct result m2 = measure(n, FFTW_MEASURE, threads, reps);
            if (e2.plan < e.plan) e.plan = e2.plan;
            if (e2.exec < e.exec) e.exec = e2.exec;
            if (m2.plan < m.plan) m.plan = m2.plan;
            if (m2.exec < m.exec) m.exec = m2.exec;
            double gain = e.exec - m.exec;
            double cross = gain > 0.0 ? (m.plan - e.plan) / gain : -1.0; /* -1: never */
            fprintf(f, "%s,%.0f,%d,%.6e,%.6e,%.6e,%.6e,%.6g\n", shapes[s].name, cells, threads,
                    e.plan, m.plan, e.exec, m.exec, cross);
            printf("%-20s %9.0f %3d %11.3e %11.3e %11.3e %11.3e %10.3g\n", shapes[s].name, cells,
                   threads, e.plan, m.plan, e.exec, m.exec, cross);
            fflush(stdout);
        }
    }
    fclose(f);
    fftw_cleanup_threads();
    return 0;
}
