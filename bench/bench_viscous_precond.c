/* bench_viscous_precond -- the preconditioners of the implicit viscous step
 * compared on the 2D scenes: the probed sparse LU (UMFPACK) against algebraic
 * multigrid (BoomerAMG) inside GMRES, step by step.
 *
 * usage: bench_viscous_precond heap|cavity N1 N2 STEPS [SECTION.KEY=VALUE...]
 *   heap:   cases/heap.ini at the fixed tilt 0.4061 (heap.flow_rate = 0) on
 *           N1 x N2 cells (y x z);  cavity: cases/bingham_cavity.ini, N1 x N2 (x x z)
 *   STEPS:  solver.max_steps (the march stops there or when steady)
 * environment:
 *   MUFLOW_PRECOND = lu (default) | amg | line
 *   MUFLOW_AMG     = BoomerAMG / Krylov settings (viscous_amg_parse), e.g.
 *                    "coarsen=pmis,theta=0.25,relax=hgs,systems=0,krylov=bicgstab"
 * One process per configuration: the peak resident memory (getrusage) is the
 * configuration's own.  Prints a line per step (P: Picard operator, N: full
 * Newton tangent; iterations; setup and solve seconds) and a RESULT line with
 * the means over the Newton steps (times: CPU seconds of the process, which
 * other processes on a shared machine do not inflate; run at 1 thread) after the first (the first LU step also
 * does the symbolic analysis) and over the Picard steps. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include "bench.h"
#include "march/march.h"
#include "scenes/heap.h"
#include "scenes/scene.h"

struct tally {
    int n;
    double iters, setup, solve, wall;
};

struct obs {
    double t_last;
    int tangent_next;          /* the operator of the step about to run */
    struct tally newton, picard, newton_first;
    int max_iters;
    int fallbacks;             /* steps whose preconditioner fell back to line blocks */
};

/* CPU seconds of the process: at one thread the work, whatever else runs. */
static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int uses_tangent(const struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    return cs->newton && (cs->newton_below >= 1.0 ||
                          st->residual <= cs->newton_below * st->residual0);
}

static int observe(void *vctx, const struct march_state *st)
{
    struct obs *o = vctx;
    double now = cpu_now();
    if (st->step > 0 && o->t_last > 0.0) {
        struct viscous_precond_info in;
        viscous_precond_info(st->viscous, &in);
        int it = st->linear_iterations;
        struct tally *t = !o->tangent_next ? &o->picard
                          : o->newton_first.n == 0 ? &o->newton_first : &o->newton;
        t->n++;
        t->iters += it;
        t->setup += in.setup_seconds + in.probe_seconds;
        t->solve += in.solve_seconds;
        t->wall += now - o->t_last;
        if (it > o->max_iters)
            o->max_iters = it;
        o->fallbacks += in.kind == VISCOUS_LINE;
        printf("step %4ld %c iters %4d  setup %7.3f s (probe %6.3f)  solve %7.3f s  step %7.3f s cpu"
               "  residual %.3e  dt %.3g%s\n",
               st->step, o->tangent_next ? 'N' : 'P', it, in.setup_seconds + in.probe_seconds,
               in.probe_seconds, in.solve_seconds, now - o->t_last, st->residual, st->dt,
               in.kind == VISCOUS_LINE ? "  (fallback: line blocks)" : "");
        fflush(stdout);
    }
    o->tangent_next = uses_tangent(st);
    o->t_last = cpu_now();
    return 0;
}

static double mean(double x, int n) { return n > 0 ? x / n : NAN; }

int main(int argc, char **argv)
{
    if (argc < 5) {
        fprintf(stderr, "usage: bench_viscous_precond heap|cavity N1 N2 STEPS [S.K=V...]\n");
        return 2;
    }
    int heap = strcmp(argv[1], "heap") == 0;
    if (!heap && strcmp(argv[1], "cavity") != 0) {
        fprintf(stderr, "scene: heap or cavity\n");
        return 2;
    }
    int n1 = atoi(argv[2]), n2 = atoi(argv[3]);
    long steps = atol(argv[4]);
    char o1[64], o2[64], o3[64];
    snprintf(o1, sizeof o1, heap ? "domain.ny=%d" : "domain.nx=%d", n1);
    snprintf(o2, sizeof o2, "domain.nz=%d", n2);
    snprintf(o3, sizeof o3, "solver.max_steps=%ld", steps);
    /* the march is created with the LU (auto would take the AMG above 1e4
     * unknowns) and its solver swapped below for MUFLOW_PRECOND's */
    char *ov[32] = {o1, o2, o3, "output.quiet=on", "solver.preconditioner=lu"};
    int nov = 5;
    if (heap) {
        ov[nov++] = "heap.flow_rate=0";
        ov[nov++] = "physics.tilt=0.4061";
    }
    for (int a = 5; a < argc && nov < 32; a++)
        ov[nov++] = argv[a];
    static struct muflow_case cs;
    bench_load(&cs, heap ? "cases/heap.ini" : "cases/bingham_cavity.ini", nov, ov);

    const char *kname = getenv("MUFLOW_PRECOND");
    if (!kname || !*kname)
        kname = "lu";
    enum viscous_precond kind = strcmp(kname, "amg") == 0    ? VISCOUS_AMG
                                : strcmp(kname, "line") == 0 ? VISCOUS_LINE
                                                             : VISCOUS_LU;
    char err[512];
    struct march_state st;
    if (scene_march_create(&st, &cs, NULL, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    if (!st.full_tangent) {
        fprintf(stderr, "expected the full-tangent (LU) configuration of a 2D grid\n");
        return 1;
    }
    char desc[256] = "UMFPACK LU";
    if (kind != VISCOUS_LU) {
        /* the same march with another preconditioner: the full tangent stays */
        viscous_destroy(st.viscous);
        st.viscous = NULL;
        st.precond = kind; /* what the march's choices (the forcing term) see */
        if (viscous_create(&st.viscous, &st.g, &st.bc, st.act, cs.line_direction, kind, err,
                           sizeof err) != 0) {
            fprintf(stderr, "%s\n", err);
            return 1;
        }
        snprintf(desc, sizeof desc, "line blocks");
        if (kind == VISCOUS_AMG) {
            struct viscous_amg cfg;
            viscous_amg_defaults(&cfg);
            if (viscous_amg_parse(&cfg, getenv("MUFLOW_AMG"), err, sizeof err) != 0 ||
                viscous_set_amg(st.viscous, &cfg, err, sizeof err) != 0) {
                fprintf(stderr, "%s\n", err);
                return 1;
            }
            char a[160];
            amg_options_describe(&cfg.amg, a, sizeof a);
            snprintf(desc, sizeof desc, "AMG %s, %s%s%s", a,
                     cfg.bicgstab ? "BiCGStab" : "GMRES", cfg.picard ? ", on Picard" : "",
                     cfg.drop_augmentation ? ", no aug" : "");
        }
    }
    printf("%s %d x %d, %s, linear tolerance %g\n", heap ? "heap" : "cavity", n1, n2, desc,
           cs.linear_tolerance);
    struct obs o = {0};
    double t0 = omp_get_wtime();
    enum run_status status = march_run(&st, observe, &o);
    double wall = omp_get_wtime() - t0;
    struct viscous_precond_info in;
    viscous_precond_info(st.viscous, &in);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    double q = NAN, us = NAN;
    if (heap) {
        q = heap_flow_rate(&st);
        struct heap_profile hp;
        const struct heap_params *hpar = case_scene_params(&cs);
        if (heap_profile_extract(&hp, &st, hpar->depth_fraction) == 0) {
            us = hp.u_surface_mid;
            heap_profile_free(&hp);
        }
    }
    struct tally *N = o.newton.n ? &o.newton : &o.newton_first, *P = &o.picard;
    printf("RESULT scene=%s n=%dx%d precond=%s status=%s steps=%ld wall=%.2f "
           "newton_steps=%d newton_iters=%.1f newton_setup=%.4f newton_solve=%.4f "
           "newton_step=%.4f first_setup=%.4f picard_steps=%d picard_iters=%.1f "
           "picard_setup=%.4f picard_solve=%.4f max_iters=%d fallbacks=%d maxrss_mb=%.1f "
           "unknowns=%ld levels=%d complexity=%.2f nnz=%ld residual=%.3e flow_rate=%.8g u_surface=%.8g "
           "config=\"%s\"\n",
           argv[1], n1, n2, kname, run_status_name(status), st.step, wall,
           o.newton.n + o.newton_first.n, mean(N->iters, N->n), mean(N->setup, N->n),
           mean(N->solve, N->n), mean(N->wall, N->n), o.newton_first.setup, P->n,
           mean(P->iters, P->n), mean(P->setup, P->n), mean(P->solve, P->n), o.max_iters,
           o.fallbacks, ru.ru_maxrss / 1024.0, in.unknowns, in.levels, in.complexity, in.entries,
           st.residual, q, us, desc);
    march_destroy(&st);
    return 0;
}
