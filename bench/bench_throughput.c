/* Throughput of the solver's stages on a 3D grid of about a million cells,
 * against a STREAM-like triad bandwidth measured in the same process, at 2
 * and 1 OpenMP threads.
 *
 *   bench_throughput OUTDIR [nx ny nz] [repeats]
 *   bench_throughput --profile [nx ny nz [steps]]   (only march, for a profiler)
 *
 * The case is bench/shear3d.ini (Bagnold layer, walls below, free surface
 * above, periodic x and y, mu(I) mc) started from the Bagnold profile with 3D
 * perturbations and marched two steps before anything is timed, so every
 * field holds a realistic, non-trivial state.  Each stage is then called
 * `repeats` times (default 9) and the median time is kept; a whole step is the
 * median of the per-step wall times of a short march (observer timestamps).
 *
 * Bytes per cell (written next to each stage in stages.csv) count every field
 * array a kernel sweeps once, 8 bytes per interior cell: neighbours reached by
 * the stencil are assumed to come from cache, ghost layers are ignored, and a
 * written array counts once (the write-allocate read that a normal store
 * also causes is given separately).  The triad a[i] = b[i] + s c[i] is counted
 * the same way: 24 bytes per element, 32 with the write-allocate read. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include "diagnostics/profile.h"
#include "scenes/scene.h"
#include "bench.h"
#include "grid/boundary.h"
#include "kernels/kernels.h"
#include "march/march.h"
#include "solvers/poisson.h"
#include "solvers/viscous.h"

#define CASE_INI "bench/shear3d.ini"
#define PI 3.14159265358979323846
#define TRIAD_N (1L << 25) /* 3 x 256 MiB, far beyond any cache */
#define WARM_STEPS 2
#define TIMED_STEPS 4

static int reps = 9;
static volatile double sink;
/* seconds after which a stage stops repeating (at least 3 repeats) */
static double item_budget = 4.0;
/* seconds from the start after which no further timed step is taken (at least one) */
static double steps_deadline = 330.0;

/* ---- triad ------------------------------------------------------------------ */

static double triad_bandwidth(double *a, const double *b, const double *c, long n, int reps_t,
                              double *best)
{
    double *t = calloc((size_t)reps_t, sizeof *t);
    const double s = 1.000001;
    for (int r = 0; r < reps_t; r++) {
        double t0 = bench_now();
#pragma omp parallel for schedule(static)
        for (long i = 0; i < n; i++)
            a[i] = b[i] + s * c[i];
        t[r] = bench_now() - t0;
    }
    double med = bench_median(t, reps_t);
    *best = 24.0 * (double)n / bench_min(t, reps_t) / 1e9;
    free(t);
    return 24.0 * (double)n / med / 1e9; /* GB/s, 24 bytes per element */
}

/* ---- the benchmark state ---------------------------------------------------- */

struct bench3d {
    struct muflow_case cs;
    struct march_state st;
    double *x[3], *y[3];          /* scratch vectors */
    struct viscous_problem pb;
    double setup_seconds;
};

static double bagnold_u(const struct muflow_case *cs, double z)
{
    struct muflow_case b = *cs;
    b.scene = scene_find("bagnold");
    return scene_exact_at(&b, z);
}

/* The Bagnold profile plus two discretely divergence-free perturbations:
 * psi = A sin(kx x) sin(ky y) sin(pi z / H) (u' = d psi/dy, v' = -d psi/dx) and
 * phi = B sin(kx x) cos(ky y) sin(pi z / H) (u'' = -d phi/dz, w'' = d phi/dx),
 * each a difference of its stream function between edges, so the discrete
 * divergence of the perturbation vanishes and w vanishes at the base and the
 * surface. */
static double psi_xy(const double L[3], double x, double y, double z)
{
    return sin(2.0 * PI * x / L[0]) * sin(2.0 * PI * y / L[1]) * sin(PI * z / L[2]);
}

static double phi_xz(const double L[3], double x, double y, double z)
{
    return sin(2.0 * PI * x / L[0]) * cos(2.0 * PI * y / L[1]) * sin(PI * z / L[2]);
}

static void initial_field(struct bench3d *b)
{
    struct march_state *st = &b->st;
    const struct grid *g = &st->g;
    const double *L = g->len, *h = g->h, H = g->len[2];
    double us = bagnold_u(&b->cs, H);
    double A = 0.1 * us * L[0] / (2.0 * PI), B = 0.05 * us * L[0] / (2.0 * PI);
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                double xf = i * h[0], yf = j * h[1], zf = k * h[2];
                double yc = yf + 0.5 * h[1], zc = zf + 0.5 * h[2];
                /* u on x-face (xf, yc, zc); psi on z-edges (xf, yf), phi on y-edges (xf, zf) */
                st->field.velocity[0][p] =
                    bagnold_u(&b->cs, zc) +
                    A * (psi_xy(L, xf, yf + h[1], zc) - psi_xy(L, xf, yf, zc)) / h[1] -
                    B * (phi_xz(L, xf, yc, zf + h[2]) - phi_xz(L, xf, yc, zf)) / h[2];
                /* v on y-face (xc, yf, zc) */
                st->field.velocity[1][p] =
                    -A * (psi_xy(L, xf + h[0], yf, zc) - psi_xy(L, xf, yf, zc)) / h[0];
                /* w on z-face (xc, yc, zf) */
                st->field.velocity[2][p] =
                    B * (phi_xz(L, xf + h[0], yc, zf) - phi_xz(L, xf, yc, zf)) / h[0];
            }
    bc_fill_velocity(g, &st->bc, st->field.velocity);
}

static void problem_of(struct bench3d *b)
{
    struct march_state *st = &b->st;
    memset(&b->pb, 0, sizeof b->pb);
    b->pb.mass = b->cs.density / st->dt;
    b->pb.augmentation = st->aug; /* as the march builds it (line blocks: symmetric tangent) */
    for (int a = 0; a < 3; a++) {
        b->pb.A_cell[a] = st->field.tangent_cells[a];
        b->pb.A_edge[a] = st->field.tangent_edges[a];
    }
}

static void bench_create(struct bench3d *b, int n[3])
{
    char o[3][64];
    snprintf(o[0], sizeof o[0], "domain.nx=%d", n[0]);
    snprintf(o[1], sizeof o[1], "domain.ny=%d", n[1]);
    snprintf(o[2], sizeof o[2], "domain.nz=%d", n[2]);
    char *ov[] = {o[0], o[1], o[2]};
    bench_load(&b->cs, CASE_INI, 3, ov);
    /* keep h = 0.21875 in every direction whatever the cell counts */
    b->cs.len[0] = b->cs.len[2] / b->cs.n[2] * b->cs.n[0];
    b->cs.len[1] = b->cs.len[2] / b->cs.n[2] * b->cs.n[1];
    char err[512];
    double t0 = bench_now();
    if (scene_march_create(&b->st, &b->cs, NULL, err, sizeof err) != 0) {
        fprintf(stderr, "bench: %s\n", err);
        exit(1);
    }
    b->setup_seconds = bench_now() - t0;
    for (int c = 0; c < 3; c++) {
        b->x[c] = field_alloc(&b->st.g);
        b->y[c] = field_alloc(&b->st.g);
        if (!b->x[c] || !b->y[c]) {
            fprintf(stderr, "bench: out of memory\n");
            exit(1);
        }
    }
    initial_field(b);
    b->cs.max_steps = WARM_STEPS;
    march_run(&b->st, NULL, NULL);
    if (b->st.status != STATUS_STOPPED) {
        fprintf(stderr, "bench: warm-up march ended %s: %s\n", run_status_name(b->st.status),
                b->st.message);
        exit(1);
    }
    problem_of(b);
    for (int c = 0; c < 3; c++)
        memcpy(b->x[c], b->st.field.velocity[c], b->st.g.size * sizeof(double));
}

static void bench_destroy(struct bench3d *b)
{
    for (int c = 0; c < 3; c++) {
        field_free(b->x[c]);
        field_free(b->y[c]);
    }
    march_destroy(&b->st);
}

/* ---- stages ------------------------------------------------------------------- */

typedef void (*stage_fn)(struct bench3d *b);

#define ST(b) (&(b)->st)
#define G(b) (&(b)->st.g)

static void s_strain(struct bench3d *b)
{
    kernel_strain(G(b), ST(b)->field.velocity, ST(b)->field.strain_normal2,
                  ST(b)->field.strain_shear2);
}

static void s_visc_cells(struct bench3d *b)
{
    struct march_state *st = ST(b);
    kernel_viscosity_cells(G(b), &b->cs.rheo, st->field.velocity, st->field.strain_normal2,
                           st->field.strain_shear2, st->field.pressure, st->field.viscosity,
                           st->field.tangent_cells, st->field.shear2,
                           st->field.pressure_regularised, st->b_c);
}

static void s_visc_edges(struct bench3d *b)
{
    struct march_state *st = ST(b);
    kernel_viscosity_edges(G(b), &b->cs.rheo, st->field.strain_normal2, st->field.strain_shear2,
                           st->field.pressure, st->field.viscosity_edges, st->field.tangent_edges,
                           st->full_tangent ? st->b_e : NULL, 0);
}

/* the ghost fills that go with a viscosity evaluation (march.c, evaluate_residual) */
static void s_visc_fills(struct bench3d *b)
{
    struct march_state *st = ST(b);
    bc_fill_velocity(G(b), &st->bc, st->field.velocity);
    bc_fill_scalar(G(b), &st->bc, st->field.strain_normal2);
    bc_fill_scalar_linear(G(b), &st->bc, st->field.pressure);
    bc_fill_scalar(G(b), &st->bc, st->field.viscosity);
    for (int a = 0; a < 3; a++)
        bc_fill_scalar(G(b), &st->bc, st->field.tangent_cells[a]);
}

static void s_viscosity(struct bench3d *b)
{
    struct march_state *st = ST(b);
    bc_fill_velocity(G(b), &st->bc, st->field.velocity);
    s_strain(b);
    bc_fill_scalar(G(b), &st->bc, st->field.strain_normal2);
    bc_fill_scalar_linear(G(b), &st->bc, st->field.pressure);
    s_visc_cells(b);
    s_visc_edges(b);
    bc_fill_scalar(G(b), &st->bc, st->field.viscosity);
    for (int a = 0; a < 3; a++)
        bc_fill_scalar(G(b), &st->bc, st->field.tangent_cells[a]);
}

static void s_apply(struct bench3d *b) { viscous_apply(ST(b)->viscous, &b->pb, b->x, b->y); }

static void s_stress_div(struct bench3d *b)
{
    struct march_state *st = ST(b);
    const double *eta_cell[3] = {st->field.viscosity, st->field.viscosity, st->field.viscosity};
    kernel_stress_divergence(G(b), st->act, eta_cell,
                             (const double *const *)st->field.viscosity_edges, st->field.velocity,
                             b->y);
}

static void s_stress_mag(struct bench3d *b)
{
    struct march_state *st = ST(b);
    const double *eta_cell[3] = {st->field.viscosity, st->field.viscosity, st->field.viscosity};
    kernel_stress_magnitude(G(b), st->act, eta_cell,
                            (const double *const *)st->field.viscosity_edges, st->field.velocity,
                            b->y);
}

static void s_precondition(struct bench3d *b) { viscous_precondition(ST(b)->viscous, &b->pb); }

static void s_advection(struct bench3d *b)
{
    kernel_advection(G(b), ST(b)->act, ST(b)->field.velocity, ST(b)->field.advection);
}

static void s_poisson(struct bench3d *b)
{
    pressure_solve(ST(b)->pressure_solver, ST(b)->field.divergence, ST(b)->field.phi, 0.0);
}

static void s_divergence(struct bench3d *b)
{
    kernel_divergence(G(b), ST(b)->field.velocity, ST(b)->field.divergence);
}

static void s_gradient(struct bench3d *b)
{
    kernel_gradient_update(G(b), ST(b)->act, ST(b)->field.phi, 1e-30, b->y);
}

static void s_correction(struct bench3d *b)
{
    s_divergence(b);
    s_gradient(b);
}

static void s_dot(struct bench3d *b)
{
    sink = kernel_dot(G(b), ST(b)->act, b->x, ST(b)->field.velocity);
}
static void s_axpy(struct bench3d *b)
{
    kernel_axpy(G(b), ST(b)->act, 1e-30, ST(b)->field.velocity, b->y);
}
static void s_lincomb(struct bench3d *b)
{
    kernel_lincomb(G(b), ST(b)->act, 1.0, ST(b)->field.velocity, 1e-30, b->y);
}
static void s_max_abs(struct bench3d *b)
{
    sink = kernel_max_abs(G(b), ST(b)->act, ST(b)->field.velocity);
}
static void s_residual_excess(struct bench3d *b)
{
    struct march_state *st = ST(b);
    sink = kernel_residual_excess(G(b), st->act, st->field.residual, b->y, st->field.force, 1e-15);
}
static void s_fill_vel(struct bench3d *b)
{
    bc_fill_velocity(G(b), &ST(b)->bc, ST(b)->field.velocity);
}
static void s_fill_scalar(struct bench3d *b) { bc_fill_scalar(G(b), &ST(b)->bc, ST(b)->field.phi); }

/* One CG iteration: the difference of solves capped at 6 and 1 iterations
 * (rtol 0: the cap is always reached), over 5. */
static int solve_its;
static void s_solve(struct bench3d *b)
{
    struct viscous_stats vs;
    viscous_solve(ST(b)->viscous, &b->pb, ST(b)->field.residual, b->y, 0.0, solve_its, &vs);
}

/* ---- whole steps -------------------------------------------------------------- */

struct steplog {
    int n;
    double wall[2];
    int its[2];
};

static int step_observer(void *ctx, const struct march_state *st)
{
    struct steplog *l = ctx;
    if (l->n < 2) {
        l->wall[l->n] = st->wall_seconds;
        l->its[l->n] = st->linear_iterations;
        l->n++;
    }
    return 0;
}

/* One march step: the time between the observer calls before and after it. */
static double one_step(struct bench3d *b, int *its)
{
    struct steplog log = {0};
    b->cs.max_steps = b->st.step + 1;
    march_run(&b->st, step_observer, &log);
    if (log.n < 2 || b->st.status != STATUS_STOPPED) {
        fprintf(stderr, "bench: the march ended %s: %s\n", run_status_name(b->st.status),
                b->st.message);
        exit(1);
    }
    *its = log.its[1];
    return log.wall[1] - log.wall[0];
}

/* ---- stages -------------------------------------------------------------------- */

struct stage {
    const char *name;
    stage_fn fn;
    double reads, writes, wa;   /* arrays swept per cell; wa: write-allocate reads */
    const char *note;
};

/* Arrays per cell, counted from the kernels' sources (see the header). */
static const struct stage stages[] = {
    {"strain", s_strain, 9, 4, 4, "kernel_strain: vel x3 -> cn2; per plane vel_a, vel_b -> e2[c]"},
    {"viscosity_cells", s_visc_cells, 8, 6, 6,
     "cn2, e2 x3, p, vel x3 -> eta, tan_c x3, shear2, preg"},
    {"viscosity_edges", s_visc_edges, 15, 6, 6, "per plane: e2 x3, cn2, p -> eta_e, tan_e"},
    {"viscosity_fills", s_visc_fills, 0, 0, 0, "ghost fills: vel, cn2, p (linear), eta, tan_c x3"},
    {"viscosity", s_viscosity, 32, 16, 16, "strain + cells + edges + fills, as in the march"},
    {"viscous_apply", s_apply, 24, 6, 3,
     "stress divergence (per component A_cell, vel x3, A_edge x2 -> out) + lincomb (v, out -> out)"},
    {"precondition_setup", s_precondition, 0, 0, 0, "15 probing applies + banded Cholesky"},
    {"advection", s_advection, 9, 3, 3, "per component vel x3 -> out"},
    {"poisson", s_poisson, 9, 9, 0,
     "gather, scale, scatter + 2 FFTs of 3 passes each (one read+write per pass assumed)"},
    {"correction", s_correction, 9, 4, 1,
     "divergence (vel x3 -> div) + gradient update (p, vel -> vel, x3)"},
    {"stress_divergence", s_stress_div, 18, 3, 3, "the residual's stress term"},
    {"stress_magnitude", s_stress_mag, 18, 3, 3, "the residual's round-off scale"},
    {"dot", s_dot, 6, 0, 0, "kernel_dot"},
    {"axpy", s_axpy, 6, 3, 0, "kernel_axpy"},
    {"lincomb", s_lincomb, 6, 3, 0, "kernel_lincomb"},
    {"max_abs", s_max_abs, 3, 0, 0, "kernel_max_abs"},
    {"residual_excess", s_residual_excess, 9, 0, 0, "kernel_residual_excess"},
    {"fill_velocity", s_fill_vel, 0, 0, 0, "bc_fill_velocity"},
    {"fill_scalar", s_fill_scalar, 0, 0, 0, "bc_fill_scalar"},
};
#define NSTAGES (int)(sizeof stages / sizeof stages[0])

/* Evicts the field arrays from every cache level before a timed call, so that
 * each timing starts cold, as the bytes-moved model assumes (a field is 8.9 MB
 * at 128 x 128 x 64, and a repeated stage would otherwise find part of its
 * arrays in the last-level cache). */
#define FLUSH_N (1L << 26) /* 512 MiB */
static double *flush_buf;

static void flush_caches(void)
{
    if (!flush_buf) {
        flush_buf = malloc(FLUSH_N * sizeof *flush_buf);
        if (!flush_buf)
            return;
#pragma omp parallel for schedule(static)
        for (long i = 0; i < FLUSH_N; i++)
            flush_buf[i] = 1.0;
    }
    double s = 0.0;
#pragma omp parallel for schedule(static) reduction(+ : s)
    for (long i = 0; i < FLUSH_N; i += 8)
        s += flush_buf[i];
    sink = s;
}

/* Times f on state bs[m] at threads[m], the thread counts in turn within each
 * repeat (paired, so a drift of the machine's speed hits both alike). */
static void time_paired(stage_fn f, struct bench3d *bs[2], const int threads[2], int nt, int n,
                        double med[2], double mn[2])
{
    double *t[2] = {calloc((size_t)n, sizeof(double)), calloc((size_t)n, sizeof(double))};
    for (int m = 0; m < nt; m++) { /* warm */
        omp_set_num_threads(threads[m]);
        f(bs[m]);
    }
    double start = bench_now();
    int r;
    for (r = 0; r < n; r++) {
        if (r >= 3 && bench_now() - start > item_budget)
            break; /* a loaded machine: fewer repeats rather than no end */
        for (int m = 0; m < nt; m++) {
            omp_set_num_threads(threads[m]);
            flush_caches();
            double t0 = bench_now();
            f(bs[m]);
            t[m][r] = bench_now() - t0;
        }
    }
    for (int m = 0; m < nt; m++) {
        med[m] = bench_median(t[m], r);
        mn[m] = bench_min(t[m], r);
        free(t[m]);
    }
}

static void stage_row(FILE *fs, int threads, const char *name, double med, double mn, double cells,
                      double rd, double wr, double wa, const char *note)
{
    fprintf(fs, "%d,%s,%.6e,%.6e,%.0f,%g,%g,%g,\"%s\"\n", threads, name, med, mn, cells, rd, wr,
            wa, note);
}

/* bench_throughput --profile nx ny nz steps: only marches `steps` steps of the
 * benchmark state at the current thread count after the warm-up, for a
 * sampling profiler (perf record -e cpu-clock ...). */
static int profile_mode(int argc, char **argv)
{
    int n[3] = {128, 128, 64}, steps = 3;
    if (argc >= 5)
        for (int d = 0; d < 3; d++)
            n[d] = atoi(argv[2 + d]);
    if (argc >= 6)
        steps = atoi(argv[5]);
    struct bench3d *b = calloc(1, sizeof *b);
    bench_create(b, n);
    double t0 = bench_now();
    for (int k = 0; k < steps; k++) {
        int its;
        double t = one_step(b, &its);
        fprintf(stderr, "step %ld: %.3f s, %d CG iterations\n", b->st.step, t, its);
    }
    fprintf(stderr, "profile: %d steps in %.2f s at %d threads\n", steps, bench_now() - t0,
            omp_get_max_threads());
    bench_destroy(b);
    free(b);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc >= 2 && !strcmp(argv[1], "--profile"))
        return profile_mode(argc, argv);
    if (argc < 2) {
        fprintf(stderr, "usage: %s OUTDIR [nx ny nz] [repeats]\n", argv[0]);
        return 2;
    }
    const char *dir = argv[1];
    int n[3] = {128, 128, 64};
    if (argc >= 5)
        for (int d = 0; d < 3; d++)
            n[d] = atoi(argv[2 + d]);
    if (argc >= 6)
        reps = atoi(argv[5]);
    if (reps < 1)
        reps = 1;
    bench_mkdir(dir);
    struct bench_cpu cpu_all, cpu;
    bench_wait_quiet(30.0);
    bench_cpu_start(&cpu_all);
    double t0 = bench_now();
    int maxt = omp_get_max_threads();
    int threads[2] = {maxt, 1};
    int nt = maxt > 1 ? 2 : 1;
    fprintf(stderr, "throughput: %d and 1 threads, %d repeats\n", maxt, reps);
    FILE *fm = bench_open(dir, "throughput_meta.csv");
    fprintf(fm, "key,value\nthreads,%d\nrepeats,%d\nnx,%d\nny,%d\nnz,%d\n", maxt, reps, n[0],
            n[1], n[2]);

    double cap = bench_parallel_capacity(maxt);
    fprintf(fm, "capacity_start,%.3f\n", cap);
    fprintf(stderr, "  parallel capacity: %.2f of %d cores\n", cap, maxt);

    /* triad, first touch in parallel */
    double *a = malloc(TRIAD_N * sizeof *a), *bb = malloc(TRIAD_N * sizeof *bb),
           *c = malloc(TRIAD_N * sizeof *c);
    if (!a || !bb || !c) {
        fprintf(stderr, "bench: out of memory for the triad\n");
        return 1;
    }
#pragma omp parallel for schedule(static)
    for (long i = 0; i < TRIAD_N; i++) {
        a[i] = 0.0;
        bb[i] = 1.0;
        c[i] = 2.0;
    }
    /* the triad before and after the stage timings: the bandwidth a virtual
     * machine gets can drift with its neighbours' load */
    FILE *ft = bench_open(dir, "triad.csv");
    fprintf(ft, "phase,threads,gbs_median,gbs_best,elements\n");
    bench_cpu_start(&cpu);
    for (int m = 0; m < nt; m++) {
        omp_set_num_threads(threads[m]);
        double best, bw = triad_bandwidth(a, bb, c, TRIAD_N, 11, &best);
        fprintf(ft, "before,%d,%.3f,%.3f,%ld\n", threads[m], bw, best, TRIAD_N);
        fprintf(stderr, "  triad %d thread%s: %.2f GB/s (best %.2f)\n", threads[m],
                threads[m] > 1 ? "s" : "", bw, best);
    }
    fprintf(fm, "foreign_cores_triad,%.3f\n", bench_cpu_foreign(&cpu));

    /* one state per thread count, each created (FFTW plans included) at its count */
    struct bench3d *bs[2] = {NULL, NULL};
    for (int m = 0; m < nt; m++) {
        omp_set_num_threads(threads[m]);
        bs[m] = calloc(1, sizeof *bs[m]);
        bench_create(bs[m], n);
        fprintf(stderr, "  state for %d thread%s: %d x %d x %d cells, setup %.2f s, dt %.3g\n",
                threads[m], threads[m] > 1 ? "s" : "", bs[m]->st.g.n[0], bs[m]->st.g.n[1],
                bs[m]->st.g.n[2], bs[m]->setup_seconds, bs[m]->st.dt);
    }
    double cells = (double)grid_cells(&bs[0]->st.g);
    fprintf(fm, "dt,%g\nlambda,%g\nwarm_steps,%d\ntimed_steps,%d\nline_direction,%d\n",
            bs[0]->st.dt, bs[0]->cs.rheo.lambda, WARM_STEPS, TIMED_STEPS,
            viscous_line_direction(bs[0]->st.viscous));

    FILE *fs = bench_open(dir, "stages.csv");
    fprintf(fs, "threads,stage,median_s,min_s,cells,reads,writes,wa,note\n");
    bench_cpu_start(&cpu);
    double med[NSTAGES][2], mn[2];
    for (int s = 0; s < NSTAGES; s++) {
        time_paired(stages[s].fn, bs, threads, nt, reps, med[s], mn);
        for (int m = 0; m < nt; m++)
            stage_row(fs, threads[m], stages[s].name, med[s][m], mn[m], cells, stages[s].reads,
                      stages[s].writes, stages[s].wa, stages[s].note);
        fprintf(stderr, "    %-20s %8.3f ms  %6.2f ns/cell   1 thread %8.3f ms\n", stages[s].name,
                1e3 * med[s][0], 1e9 * med[s][0] / cells, 1e3 * med[s][nt - 1]);
    }
    /* one CG iteration: solves capped at 6 and at 1 iteration (rtol 0, so the cap
     * is reached), the difference over 5; the preconditioner's apply is what is
     * left after the apply and the vector operations of the iteration */
    double t1[2], t6[2];
    int rs = reps < 5 ? reps : 5;
    solve_its = 1;
    time_paired(s_solve, bs, threads, nt, rs, t1, mn);
    solve_its = 6;
    time_paired(s_solve, bs, threads, nt, rs, t6, mn);
    int iapply = -1, idot = -1, iaxpy = -1, ilin = -1;
    for (int s = 0; s < NSTAGES; s++) {
        if (!strcmp(stages[s].name, "viscous_apply")) iapply = s;
        if (!strcmp(stages[s].name, "dot")) idot = s;
        if (!strcmp(stages[s].name, "axpy")) iaxpy = s;
        if (!strcmp(stages[s].name, "lincomb")) ilin = s;
    }
    for (int m = 0; m < nt; m++) {
        double it = (t6[m] - t1[m]) / 5.0;
        double pc = it - med[iapply][m] - 3.0 * med[idot][m] - 2.0 * med[iaxpy][m] - med[ilin][m];
        stage_row(fs, threads[m], "cg_iteration", it, it, cells, 24.0 + 18 + 12 + 6 + 12,
                  6.0 + 6 + 3 + 3, 3.0 + 3,
                  "(solve capped at 6 iterations - capped at 1) / 5: apply + 3 dot + 2 axpy + "
                  "lincomb + preconditioner apply");
        stage_row(fs, threads[m], "precondition_apply", pc, pc, cells, 12.0, 3.0, 3.0,
                  "cg_iteration - apply - 3 dot - 2 axpy - lincomb; per component r and 3 band "
                  "diagonals -> z");
        fprintf(stderr, "    %-20s %8.3f ms  %6.2f ns/cell  (%d thread%s)\n", "cg_iteration",
                1e3 * it, 1e9 * it / cells, threads[m], threads[m] > 1 ? "s" : "");
        fprintf(stderr, "    %-20s %8.3f ms  %6.2f ns/cell  (%d thread%s)\n", "precondition_apply",
                1e3 * pc, 1e9 * pc / cells, threads[m], threads[m] > 1 ? "s" : "");
    }
    fprintf(fm, "foreign_cores_stages,%.3f\ncapacity_stages,%.3f\n", bench_cpu_foreign(&cpu),
            bench_parallel_capacity(maxt));

    for (int m = 0; m < nt; m++) {
        omp_set_num_threads(threads[m]);
        double best, bw = triad_bandwidth(a, bb, c, TRIAD_N, 11, &best);
        fprintf(ft, "after,%d,%.3f,%.3f,%ld\n", threads[m], bw, best, TRIAD_N);
        fprintf(stderr, "  triad %d thread%s after the stages: %.2f GB/s (best %.2f)\n",
                threads[m], threads[m] > 1 ? "s" : "", bw, best);
    }
    fclose(ft);
    free(a);
    free(bb);
    free(c);

    /* whole march steps, the thread counts in turn */
    FILE *fw = bench_open(dir, "steps.csv");
    fprintf(fw, "threads,step,seconds,cg_iterations\n");
    bench_cpu_start(&cpu);
    double dts[2][TIMED_STEPS];
    int ksteps = 0;
    for (int k = 0; k < TIMED_STEPS; k++) {
        if (k > 0 && bench_now() - t0 > steps_deadline)
            break; /* a loaded machine: fewer steps rather than no end */
        ksteps++;
        for (int m = 0; m < nt; m++) {
            omp_set_num_threads(threads[m]);
            int its;
            dts[m][k] = one_step(bs[m], &its);
            fprintf(fw, "%d,%ld,%.6e,%d\n", threads[m], bs[m]->st.step, dts[m][k], its);
            fprintf(stderr, "    step %ld, %d thread%s: %.3f s, %d CG iterations\n", bs[m]->st.step,
                    threads[m], threads[m] > 1 ? "s" : "", dts[m][k], its);
        }
    }
    fprintf(fm, "foreign_cores_steps,%.3f\ncapacity_steps,%.3f\n", bench_cpu_foreign(&cpu),
            bench_parallel_capacity(maxt));
    for (int m = 0; m < nt; m++) {
        stage_row(fs, threads[m], "whole_step", bench_median(dts[m], ksteps),
                  bench_min(dts[m], ksteps), cells, 0, 0, 0,
                  "median of the march's steps (observer timestamps)");
        stage_row(fs, threads[m], "setup", bs[m]->setup_seconds, bs[m]->setup_seconds, cells, 0,
                  0, 0, "march_create: fields, FFTW plans, hydrostatic split");
        bench_destroy(bs[m]);
        free(bs[m]);
    }
    fclose(fs);
    fclose(fw);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    fprintf(fm, "seconds,%.1f\ninvoluntary_switches,%ld\nforeign_cores_all,%.3f\n",
            bench_now() - t0, ru.ru_nivcsw, bench_cpu_foreign(&cpu_all));
    fclose(fm);
    fprintf(stderr, "throughput: done in %.1f s\n", bench_now() - t0);
    return 0;
}
