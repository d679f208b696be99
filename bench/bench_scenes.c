/* Profile scenes against their analytic solutions and the published Newton
 * FEM (Chauchat & Medale 2014): convergence in h, cost to a steady state,
 * error against wall time during the march, the regularisations and lambda.
 *
 *   bench_scenes OUTDIR [repeats]
 *
 * Writes CSV tables into OUTDIR (bench/report.py turns them into the report).
 * Every timing is the median of `repeats` runs in this process (default 7;
 * the convergence and lambda studies use min(repeats, 3)); a run is what
 * run_case(cs, 0, ...) does in memory (see run_limited) and its wall time
 * includes the setup (grid, FFTW plans, hydrostatic split); "march" is the
 * time loop alone (st.wall_seconds). */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "scenes/scene.h"
#include "bench.h"
#include "march/march.h"
#include "io/output.h"
#include "diagnostics/profile.h"
#include "app/run.h"

#define BAGNOLD_INI "cases/bagnold.ini"
#define CHUTE_INI "cases/chute.ini"
#define CAVITY_INI "cases/bingham_cavity.ini"
#define HEAP_INI "cases/heap.ini"

static const char *regs[] = {"simple", "bercovier", "papanastasiou", "mc"};
#define NREGS 4

/* A set of timed runs of one case: the result of the first run (the march is
 * deterministic at a fixed thread count) and the median times. */
struct timed {
    struct run_result res;
    int runs;       /* repeats actually made (fewer when over the time budget) */
    double wall_med, wall_min, wall_max, march_med;
    int consistent; /* every repeat took the same number of steps */
};

/* Time budget: an item stops repeating once it has taken item_budget seconds
 * (after its first run); after the soft deadline every item runs once, and
 * after the hard deadline the remaining items are skipped (their rows say
 * "skipped"), so that a machine loaded by other processes cannot stretch the
 * benchmark without bound.  On a quiet machine no item comes near any of them. */
static double item_budget = 5.0, deadline = 1e300, hard_deadline = 1e300;

static int over_hard_deadline(void) { return bench_now() > hard_deadline; }

/* A run is what run_case(cs, 0, ...) does in memory -- march_create, march_run,
 * the profile and its errors -- with one addition: an observer that stops the
 * march after run_limit seconds (status "stopped"), so that a single run
 * slowed down by a loaded machine cannot hold up the benchmark. */
static double run_limit = 20.0;

struct limit_ctx {
    double t0;
};

static int limit_observer(void *ctx, const struct march_state *st)
{
    (void)st;
    return bench_now() - ((struct limit_ctx *)ctx)->t0 > run_limit;
}

static void run_limited(const struct muflow_case *cs, struct run_result *res)
{
    memset(res, 0, sizeof *res);
    struct march_state st;
    char err[512];
    struct limit_ctx l = {bench_now()};
    if (scene_march_create(&st, cs, NULL, err, sizeof err) != 0) {
        fprintf(stderr, "bench: run failed: %s\n", err);
        exit(1);
    }
    march_run(&st, limit_observer, &l);
    run_result_from(&st, res);
    struct profile pr;
    if (scene_profile(&pr, &st) == 0) {
        scene_profile_errors(&pr, &st, &res->errors);
        profile_free(&pr);
    }
    march_destroy(&st);
}

static void timed_runs(const struct muflow_case *cs, int reps, struct timed *t)
{
    double *wall = calloc((size_t)reps, sizeof *wall), *march = calloc((size_t)reps, sizeof *march);
    if (!wall || !march) {
        fprintf(stderr, "bench: out of memory\n");
        exit(1);
    }
    t->consistent = 1;
    double start = bench_now();
    int r;
    for (r = 0; r < reps; r++) {
        if (r > 0 && (bench_now() - start > item_budget || bench_now() > deadline))
            break;
        struct run_result res;
        double t0 = bench_now();
        run_limited(cs, &res);
        wall[r] = bench_now() - t0;
        march[r] = res.wall_seconds;
        if (r == 0)
            t->res = res;
        else if (res.steps != t->res.steps)
            t->consistent = 0;
        if (res.status == STATUS_STOPPED) { /* over run_limit: no point repeating */
            t->res = res;
            r++;
            break;
        }
    }
    t->runs = r;
    t->wall_med = bench_median(wall, r);
    t->wall_min = bench_min(wall, r);
    t->wall_max = bench_max(wall, r);
    t->march_med = bench_median(march, r);
    free(wall);
    free(march);
}

/* ---- error against wall time during the march ---------------------------- */

struct trace {
    int n, cap;
    long *step;
    double *wall, *err;
    double observer_seconds; /* time spent in this observer so far (subtracted) */
};

static void trace_push(struct trace *t, long step, double wall, double err)
{
    if (t->n == t->cap) {
        t->cap = t->cap ? 2 * t->cap : 256;
        t->step = realloc(t->step, (size_t)t->cap * sizeof *t->step);
        t->wall = realloc(t->wall, (size_t)t->cap * sizeof *t->wall);
        t->err = realloc(t->err, (size_t)t->cap * sizeof *t->err);
        if (!t->step || !t->wall || !t->err) {
            fprintf(stderr, "bench: out of memory\n");
            exit(1);
        }
    }
    t->step[t->n] = step;
    t->wall[t->n] = wall;
    t->err[t->n] = err;
    t->n++;
}

static void trace_free(struct trace *t)
{
    free(t->step);
    free(t->wall);
    free(t->err);
    memset(t, 0, sizeof *t);
}

/* Records the march's own wall time (minus what this observer has cost so
 * far: st->wall_seconds is read before the observer runs) and err_rms. */
static int trace_observer(void *ctx, const struct march_state *st)
{
    struct trace *t = ctx;
    double t0 = bench_now();
    struct scene_errors e;
    scene_errors_of(st, &e);
    trace_push(t, st->step, st->wall_seconds - t->observer_seconds, e.err_rms);
    t->observer_seconds += bench_now() - t0;
    return st->wall_seconds > run_limit; /* a loaded machine: stop ("stopped") */
}

/* Traces one case `reps` times and writes rows label,reg,n,step,wall,err with
 * the per-step median wall time over the repeats. */
static void error_time(FILE *out, const char *scene, const char *reg, int n,
                       const struct muflow_case *cs, int reps, double *setup_med,
                       double *observer_fraction)
{
    struct trace *tr = calloc((size_t)reps, sizeof *tr);
    double *setup = calloc((size_t)reps, sizeof *setup), *obs = calloc((size_t)reps, sizeof *obs);
    if (!tr || !setup || !obs) {
        fprintf(stderr, "bench: out of memory\n");
        exit(1);
    }
    double start = bench_now();
    int r0;
    for (r0 = 0; r0 < reps; r0++) {
        if (r0 > 0 && (bench_now() - start > item_budget || bench_now() > deadline))
            break;
        int r = r0;
        struct march_state st;
        char err[512];
        double t0 = bench_now();
        if (scene_march_create(&st, cs, NULL, err, sizeof err) != 0) {
            fprintf(stderr, "bench: %s\n", err);
            exit(1);
        }
        setup[r] = bench_now() - t0;
        march_run(&st, trace_observer, &tr[r]);
        obs[r] = st.wall_seconds > 0.0 ? tr[r].observer_seconds / st.wall_seconds : 0.0;
        march_destroy(&st);
    }
    reps = r0;
    int n0 = tr[0].n;
    for (int r = 1; r < reps; r++)
        if (tr[r].n < n0)
            n0 = tr[r].n;
    double *w = calloc((size_t)reps, sizeof *w);
    for (int i = 0; i < n0; i++) {
        for (int r = 0; r < reps; r++)
            w[r] = tr[r].wall[i];
        fprintf(out, "%s,%s,%d,%ld,%.6e,%.6e\n", scene, reg, n, tr[0].step[i],
                bench_median(w, reps), tr[0].err[i]);
    }
    *setup_med = bench_median(setup, reps);
    *observer_fraction = bench_median(obs, reps);
    for (int r = 0; r < r0; r++)
        trace_free(&tr[r]);
    free(tr);
    free(w);
    free(setup);
    free(obs);
}

/* ---- the studies ------------------------------------------------------------ */

/* Chauchat & Medale (2014), Table 1: Newton FEM, mc, lambda 1e-8; 10000 means
 * no convergence. */
static const int bag_nz[] = {5, 10, 20, 40, 80, 160};
static const int fem_iter[] = {10000, 10000, 13, 9, 8, 8};
static const double fem_cpu[] = {109.56, 149.16, 2.68, 2.28, 2.63, 3.6};
#define NBAG 6

static void bagnold_table(const char *dir, int reps)
{
    FILE *f = bench_open(dir, "bagnold.csv");
    fprintf(f, "nz,cells,status,steps,consistent,runs,wall_median,wall_min,wall_max,march_median,"
               "err_rms,err_max,err_rms_paper,u_surface,u_surface_exact,fem_iterations,"
               "fem_cpu_seconds\n");
    for (int m = 0; m < NBAG; m++) {
        char o1[64];
        snprintf(o1, sizeof o1, "domain.nz=%d", bag_nz[m]);
        char *ov[] = {o1};
        struct muflow_case cs;
        bench_load(&cs, BAGNOLD_INI, 1, ov);
        if (over_hard_deadline()) {
            fprintf(f, "%d,%d,skipped,0,0,0,nan,nan,nan,nan,nan,nan,nan,nan,nan,%d,%.2f\n",
                    bag_nz[m], cs.n[0] * cs.n[1] * cs.n[2], fem_iter[m], fem_cpu[m]);
            continue;
        }
        struct timed t;
        timed_runs(&cs, reps, &t);
        long cells = (long)cs.n[0] * cs.n[1] * cs.n[2];
        fprintf(f, "%d,%ld,%s,%ld,%d,%d,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.8f,%.8f,%d,%.2f\n",
                bag_nz[m], cells, run_status_name(t.res.status), t.res.steps, t.consistent,
                t.runs, t.wall_med, t.wall_min, t.wall_max, t.march_med, t.res.errors.err_rms,
                t.res.errors.err_max, t.res.errors.err_rms_paper, t.res.errors.headline,
                t.res.errors.headline_exact, fem_iter[m], fem_cpu[m]);
        fprintf(stderr, "  bagnold H/%-3d %s %ld steps  %.4f s  err_rms %.3e\n", bag_nz[m],
                run_status_name(t.res.status), t.res.steps, t.wall_med, t.res.errors.err_rms);
    }
    fclose(f);
}

static void bagnold_profiles(const char *dir)
{
    static const int nz[] = {5, 10, 40};
    FILE *f = bench_open(dir, "bagnold_profile.csv");
    fprintf(f, "nz,z,u,u_exact\n");
    struct muflow_case cs;
    for (size_t m = 0; m < sizeof nz / sizeof nz[0]; m++) {
        char o1[64];
        snprintf(o1, sizeof o1, "domain.nz=%d", nz[m]);
        char *ov[] = {o1};
        bench_load(&cs, BAGNOLD_INI, 1, ov);
        struct march_state st;
        char err[512];
        if (scene_march_create(&st, &cs, NULL, err, sizeof err) != 0) {
            fprintf(stderr, "bench: %s\n", err);
            exit(1);
        }
        march_run(&st, NULL, NULL);
        struct profile pr;
        if (scene_profile(&pr, &st) != 0) {
            fprintf(stderr, "bench: no profile for bagnold\n");
            exit(1);
        }
        for (int l = 0; l < pr.n; l++)
            fprintf(f, "%d,%.8e,%.8e,%.8e\n", nz[m], pr.coord[l], pr.velocity[l], pr.exact[l]);
        profile_free(&pr);
        march_destroy(&st);
    }
    fclose(f);
    f = bench_open(dir, "bagnold_exact.csv");
    fprintf(f, "z,u_exact\n");
    for (int i = 0; i <= 280; i++) {
        double z = cs.len[2] * i / 280.0;
        fprintf(f, "%.8e,%.8e\n", z, scene_exact_at(&cs, z));
    }
    fclose(f);
}

static void chute_case(struct muflow_case *cs, const char *reg, int ny, double lambda)
{
    char o1[64], o2[64], o3[64];
    snprintf(o1, sizeof o1, "domain.ny=%d", ny);
    snprintf(o2, sizeof o2, "rheology.regularisation=%s", reg);
    snprintf(o3, sizeof o3, "rheology.lambda=%.17g", lambda);
    char *ov[] = {o1, o2, o3};
    bench_load(cs, CHUTE_INI, 3, ov);
}

static void chute_skipped(FILE *f, const char *reg, int ny, double lambda)
{
    fprintf(f, "%s,%d,%g,skipped,0,0,0,nan,nan,nan,nan,nan,nan,nan,nan,nan\n", reg, ny, lambda);
}

static void chute_row(FILE *f, const char *reg, int ny, double lambda, const struct timed *t)
{
    fprintf(f, "%s,%d,%g,%s,%ld,%d,%d,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.8f,%.8f\n", reg, ny,
            lambda, run_status_name(t->res.status), t->res.steps, t->consistent, t->runs,
            t->wall_med,
            t->wall_min, t->wall_max, t->march_med, t->res.errors.err_rms, t->res.errors.err_max,
            t->res.errors.err_rms_paper, t->res.errors.headline, t->res.errors.headline_exact);
}

#define CHUTE_HEADER                                                                           \
    "regularisation,ny,lambda,status,steps,consistent,runs,wall_median,wall_min,wall_max,"         \
    "march_median,err_rms,err_max,err_rms_paper,u_plug,u_plug_exact\n"

static void chute_h(const char *dir, int reps)
{
    static const int ny[] = {10, 20, 40, 80, 160, 320};
    FILE *f = bench_open(dir, "chute_h.csv");
    fprintf(f, CHUTE_HEADER);
    for (int r = 0; r < NREGS; r++)
        for (size_t m = 0; m < sizeof ny / sizeof ny[0]; m++) {
            struct muflow_case cs;
            chute_case(&cs, regs[r], ny[m], 1e-4);
            if (over_hard_deadline()) {
                chute_skipped(f, regs[r], ny[m], 1e-4);
                continue;
            }
            struct timed t;
            timed_runs(&cs, reps, &t);
            chute_row(f, regs[r], ny[m], 1e-4, &t);
            fprintf(stderr, "  chute %-13s b/%-3d %s %3ld steps  %.4f s  err_rms %.3e\n", regs[r],
                    ny[m], run_status_name(t.res.status), t.res.steps, t.wall_med,
                    t.res.errors.err_rms);
        }
    fclose(f);
}

static void chute_lambda(const char *dir, int reps)
{
    static const int ny[] = {20, 40, 80, 160, 320};
    static const double lam[] = {1e-4, 1e-5, 1e-6, 1e-7, 1e-8};
    FILE *f = bench_open(dir, "chute_lambda.csv");
    fprintf(f, CHUTE_HEADER);
    for (size_t m = 0; m < sizeof ny / sizeof ny[0]; m++)
        for (size_t l = 0; l < sizeof lam / sizeof lam[0]; l++) {
            struct muflow_case cs;
            chute_case(&cs, "mc", ny[m], lam[l]);
            if (over_hard_deadline()) {
                chute_skipped(f, "mc", ny[m], lam[l]);
                continue;
            }
            struct timed t;
            timed_runs(&cs, reps, &t);
            chute_row(f, "mc", ny[m], lam[l], &t);
            fprintf(stderr, "  chute mc b/%-3d lambda %-5g %s %3ld steps  %.4f s  err_rms %.3e\n",
                    ny[m], lam[l], run_status_name(t.res.status), t.res.steps, t.wall_med,
                    t.res.errors.err_rms);
        }
    fclose(f);
}

/* Steady-state time per regularisation at b/160, at the process's thread
 * count and at 1 thread (on a thin grid the threads' synchronisation can cost
 * more than it saves). */
static void chute_times(const char *dir, int reps)
{
    FILE *f = bench_open(dir, "chute_time.csv");
    fprintf(f, "threads," CHUTE_HEADER);
    int maxt = omp_get_max_threads();
    int threads[2] = {maxt, 1};
    for (int m = 0; m < (maxt > 1 ? 2 : 1); m++) {
        omp_set_num_threads(threads[m]);
        for (int r = 0; r < NREGS; r++) {
            struct muflow_case cs;
            chute_case(&cs, regs[r], 160, 1e-4);
            fprintf(f, "%d,", threads[m]);
            if (over_hard_deadline()) {
                chute_skipped(f, regs[r], 160, 1e-4);
                continue;
            }
            struct timed t;
            timed_runs(&cs, reps, &t);
            chute_row(f, regs[r], 160, 1e-4, &t);
            fprintf(stderr, "  chute %-13s b/160 steady in %.4f s (march %.4f s), %d thread%s\n",
                    regs[r], t.wall_med, t.march_med, threads[m], threads[m] > 1 ? "s" : "");
        }
    }
    omp_set_num_threads(maxt);
    fclose(f);
}

/* The Bingham cavity at Vola et al.'s Bn = 1000 (yield_stress 1000 / sqrt 2,
 * see cases/bingham_cavity.ini), steady from rest, at 32 x 32 and 64 x 64;
 * its runs are seconds long, so they get their own repeat budget and limit. */
static void cavity_times(const char *dir, int reps)
{
    FILE *f = bench_open(dir, "cavity_time.csv");
    fprintf(f, "n,bn_vola,status,steps,consistent,runs,wall_median,wall_min,wall_max,"
               "march_median,residual,psi_max\n");
    static const int ns[] = {32, 64};
    const double bn_vola = 1000.0;
    double keep_budget = item_budget, keep_limit = run_limit;
    item_budget = 60.0;
    run_limit = 120.0;
    for (size_t m = 0; m < sizeof ns / sizeof ns[0]; m++) {
        if (over_hard_deadline()) {
            fprintf(f, "%d,%g,skipped,0,0,0,nan,nan,nan,nan,nan,nan\n", ns[m], bn_vola);
            continue;
        }
        char o1[64], o2[64], o3[64];
        snprintf(o1, sizeof o1, "domain.nx=%d", ns[m]);
        snprintf(o2, sizeof o2, "domain.nz=%d", ns[m]);
        snprintf(o3, sizeof o3, "rheology.yield_stress=%.17g", bn_vola / sqrt(2.0));
        char *ov[] = {o1, o2, o3, "output.quiet=on"};
        struct muflow_case cs;
        bench_load(&cs, CAVITY_INI, 4, ov);
        struct timed t;
        timed_runs(&cs, reps, &t);
        fprintf(f, "%d,%g,%s,%ld,%d,%d,%.6e,%.6e,%.6e,%.6e,%.6e,%.8g\n", ns[m], bn_vola,
                run_status_name(t.res.status), t.res.steps, t.consistent, t.runs, t.wall_med,
                t.wall_min, t.wall_max, t.march_med, t.res.residual, t.res.errors.headline);
        fprintf(stderr, "  cavity %dx%d Bn(Vola) %g: %s in %ld steps, %.2f s (median of %d)\n",
                ns[m], ns[m], bn_vola, run_status_name(t.res.status), t.res.steps, t.wall_med,
                t.runs);
    }
    item_budget = keep_budget;
    run_limit = keep_limit;
    fclose(f);
}

static void error_time_all(const char *dir, int reps)
{
    FILE *f = bench_open(dir, "error_time.csv");
    fprintf(f, "scene,regularisation,n,step,wall,err_rms\n");
    FILE *g = bench_open(dir, "error_time_meta.csv");
    fprintf(g, "scene,regularisation,n,setup_median,observer_fraction\n");
    static const int bag[] = {40, 160};
    for (size_t m = 0; m < sizeof bag / sizeof bag[0]; m++) {
        char o1[64];
        snprintf(o1, sizeof o1, "domain.nz=%d", bag[m]);
        char *ov[] = {o1};
        struct muflow_case cs;
        bench_load(&cs, BAGNOLD_INI, 1, ov);
        if (over_hard_deadline())
            continue;
        double setup, frac;
        error_time(f, "bagnold", "mc", bag[m], &cs, reps, &setup, &frac);
        fprintf(g, "bagnold,mc,%d,%.6e,%.4f\n", bag[m], setup, frac);
    }
    for (int r = 0; r < NREGS; r++) {
        struct muflow_case cs;
        chute_case(&cs, regs[r], 160, 1e-4);
        if (over_hard_deadline())
            continue;
        double setup, frac;
        error_time(f, "chute", regs[r], 160, &cs, reps, &setup, &frac);
        fprintf(g, "chute,%s,160,%.6e,%.4f\n", regs[r], setup, frac);
    }
    fclose(f);
    fclose(g);
}

/* One steady solve of the heap cross-section at the paper's mesh (70 x 100),
 * from rest, at the tilt the search finds for Q* = 40.2 there (the heap study,
 * make bench-heap): the cost of one function evaluation of the tilt search. */
#define HEAP_TILT_Q40 "physics.tilt=0.40610247"
static void heap_solve(const char *dir, int reps)
{
    char *ov[] = {"heap.flow_rate=0", HEAP_TILT_Q40};
    struct muflow_case cs;
    bench_load(&cs, HEAP_INI, 2, ov);
    FILE *f = bench_open(dir, "heap_solve.csv");
    fprintf(f, "ny,nz,tilt,status,steps,runs,wall_median,wall_min,wall_max\n");
    if (!over_hard_deadline()) {
        /* one solve takes 10-20 s on 2 cores: the run limit and the item's
         * repeat budget of the millisecond scenes would cut it to one run */
        double limit = run_limit, budget = item_budget;
        run_limit = 300.0;
        item_budget = 60.0;
        struct timed t;
        timed_runs(&cs, reps, &t);
        run_limit = limit;
        item_budget = budget;
        fprintf(f, "%d,%d,%.8f,%s,%ld,%d,%.6e,%.6e,%.6e\n", cs.n[1], cs.n[2], cs.tilt,
                run_status_name(t.res.status), t.res.steps, t.runs, t.wall_med, t.wall_min,
                t.wall_max);
        fprintf(stderr, "  heap 70 x 100 tilt %.5f: %s in %ld steps, %.2f s (median of %d)\n",
                cs.tilt, run_status_name(t.res.status), t.res.steps, t.wall_med, t.runs);
    }
    fclose(f);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s OUTDIR [repeats [budget_seconds]]\n", argv[0]);
        fprintf(stderr, "  budget: after it every item runs once; after 1.6 x budget the rest "
                        "is skipped (default 190 s)\n");
        return 2;
    }
    const char *dir = argv[1];
    int reps = argc > 2 ? atoi(argv[2]) : 7;
    if (reps < 1)
        reps = 1;
    int few = reps < 3 ? reps : 3;
    double budget = argc > 3 ? atof(argv[3]) : 190.0;
    bench_mkdir(dir);
    bench_wait_quiet(30.0);
    double t0 = bench_now();
    deadline = t0 + budget;
    hard_deadline = t0 + 1.6 * budget;
    fprintf(stderr, "scenes: %d threads, %d repeats\n", omp_get_max_threads(), reps);
    FILE *f = bench_open(dir, "scenes_meta.csv");
    fprintf(f, "key,value\nthreads,%d\nrepeats,%d\nrepeats_studies,%d\n", omp_get_max_threads(),
            reps, few);
    fprintf(f, "capacity_start,%.3f\n", bench_parallel_capacity(omp_get_max_threads()));
    struct bench_cpu cpu, all;
    bench_cpu_start(&all);
    bench_cpu_start(&cpu);
    bagnold_table(dir, reps);
    bagnold_profiles(dir);
    fprintf(f, "foreign_cores_bagnold,%.3f\n", bench_cpu_foreign(&cpu));
    bench_cpu_start(&cpu);
    chute_times(dir, reps);
    fprintf(f, "foreign_cores_chute_times,%.3f\n", bench_cpu_foreign(&cpu));
    bench_cpu_start(&cpu);
    cavity_times(dir, few);
    fprintf(f, "foreign_cores_cavity,%.3f\n", bench_cpu_foreign(&cpu));
    bench_cpu_start(&cpu);
    error_time_all(dir, few + 2 <= reps ? few + 2 : reps);
    fprintf(f, "foreign_cores_error_time,%.3f\n", bench_cpu_foreign(&cpu));
    bench_cpu_start(&cpu);
    chute_h(dir, few);
    chute_lambda(dir, few);
    fprintf(f, "foreign_cores_chute_studies,%.3f\n", bench_cpu_foreign(&cpu));
    bench_cpu_start(&cpu);
    heap_solve(dir, few);
    fprintf(f, "foreign_cores_heap,%.3f\n", bench_cpu_foreign(&cpu));
    fprintf(f, "capacity_end,%.3f\n", bench_parallel_capacity(omp_get_max_threads()));
    fprintf(f, "foreign_cores_all,%.3f\nseconds,%.1f\nbudget,%.0f\nover_budget,%d\n"
               "over_hard_budget,%d\n",
            bench_cpu_foreign(&all), bench_now() - t0, budget, bench_now() > deadline,
            over_hard_deadline());
    fclose(f);
    fprintf(stderr, "scenes: done in %.1f s\n", bench_now() - t0);
    return 0;
}
