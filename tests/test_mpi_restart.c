/* Checkpoints of decomposed runs and restarts on another rank count (the
 * `mpi` group's, test_mpi.c; run alone and under mpirun on 2 and 4 ranks
 * by `make test`): bagnold stopped on this run's P ranks continues on one
 * process, and stopped on one process continues on P ranks.  Every check
 * reduces its result over the ranks first (no rank waits in a collective
 * for one that failed). */
#define _POSIX_C_SOURCE 200809L /* mkdir, raise */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "app/run.h"
#include "io/checkpoint.h"
#include "platform/comm.h"
#include "test_main.h"
#include "test_mpi.h"
#include "test_util.h"

/* bagnold on 4 x 2 x 40 cells (test_mpi.c's): 15 steps to steady */
static char *bagnold_ov[] = {"domain.nx=4", "domain.lx=1.4", "domain.ny=2", "domain.ly=0.7",
                             "output.quiet=on", NULL, NULL, NULL};
#define BAGNOLD_OV 5

/* With output.dir=dir and the overrides extra (up to 2, NULL-ended). */
static void load_bagnold(struct muflow_case *cs, const char *dir, char *const extra[])
{
    static char out[400]; /* read by the case loader only */
    snprintf(out, sizeof out, "output.dir=%s", dir);
    int n = BAGNOLD_OV;
    bagnold_ov[n++] = out;
    for (int e = 0; e < 2 && extra[e]; e++)
        bagnold_ov[n++] = extra[e];
    test_load_case(cs, "../cases/bagnold.ini", n, bagnold_ov);
}

/* A run continued from the checkpoint at path (its case, max_steps back
 * to the case file's), alone or on this run's ranks, without outputs. */
static int continue_from(const char *path, int one_process, struct run_result *r, char *err,
                         size_t errlen)
{
    static struct muflow_case cs;
    char *ov[] = {"solver.max_steps=5000"};
    if (checkpoint_load_case(path, 1, ov, &cs, err, errlen) != 0)
        return -1;
    const struct run_options opt = {.restart_from = path, .one_process = one_process};
    return run_case_opts(&cs, &opt, r, err, errlen) == RUN_OK ? 0 : -1;
}

/* The [result] values of two runs: the largest |a - b| / |a| of the errors
 * and the headline, and whether these, the final residual and the time are
 * the same doubles.  A steady run's residual (8.8e-14 here, tolerance
 * 1e-10) is round-off, 0.75% apart between 1 and 2 ranks, and its pseudo
 * time (the sum of steps the residual sets) 3e-8 apart: compared bit for
 * bit only. */
static double result_difference(const struct run_result *a, const struct run_result *b,
                                int *identical)
{
    const double x[6] = {a->errors.err_rms, a->errors.err_max, a->errors.err_rms_paper,
                         a->errors.headline, a->residual, a->time},
                 y[6] = {b->errors.err_rms, b->errors.err_max, b->errors.err_rms_paper,
                         b->errors.headline, b->residual, b->time};
    double rel = 0.0;
    *identical = memcmp(x, y, sizeof x) == 0;
    for (int v = 0; v < 4; v++)
        rel = fmax(rel, fabs(y[v] - x[v]) / fabs(x[v]));
    return rel;
}

/* A continued run ends as the uninterrupted one: status, steps, and the
 * [result] values bit for bit (identical: the same rank count throughout)
 * or the errors and headline within 1e-8 relative (the sums over ranks in
 * MPI's order: test_mpi.c's bound for a run on ranks against one process). */
static double ends_alike(const char *what, const struct run_result *uninterrupted,
                         const struct run_result *continued, int identical)
{
    int same;
    const double rel = result_difference(uninterrupted, continued, &same);
    const int bad = continued->status != uninterrupted->status ||
                    continued->steps != uninterrupted->steps || !(rel <= 1e-8) ||
                    (identical && !same);
    if (comm_rank() == 0)
        printf("    %s: %s after %ld steps (uninterrupted %ld), [result] %s (errors, "
               "headline %.1e relative)\n",
               what, run_status_name(continued->status), continued->steps,
               uninterrupted->steps, same ? "bit for bit" : "differs", rel);
    return bad;
}

struct stop_hook {
    const char *dir;
    int renamed, raised;
};

/* Keeps the checkpoint of step 4 as step4.h5 (rank 0, at step 5: every
 * rank has finished writing it) and stops the run at step 6 by SIGTERM to
 * the last rank alone: the ranks must agree to stop at that step. */
/* Every rank's verdict: the first error said, the folder removed once all
 * are done, the test failed on every rank if any rank failed. */
static void ranks_verdict(double bad, const char *err, const char *dir)
{
    if (bad != 0.0 && err[0])
        print_error("%s\n", err);
    comm_sum(&bad, 1);
    comm_barrier();
    if (comm_rank() == 0)
        test_tmp_remove(dir);
    assert_true(bad == 0.0);
}

static void stop_hook(void *ctx, const struct march_state *st)
{
    struct stop_hook *h = ctx;
    if (st->step == 5 && comm_rank() == 0 && !h->renamed) {
        char a[400], b[400];
        snprintf(a, sizeof a, "%s/%s", h->dir, CHECKPOINT_NAME);
        snprintf(b, sizeof b, "%s/step4.h5", h->dir);
        h->renamed = rename(a, b) == 0;
    }
    if (st->step == 6 && comm_rank() == comm_size() - 1 && !h->raised) {
        h->raised = 1;
        raise(SIGTERM);
    }
}

/* On P ranks (this run's): bagnold checkpointed every 4 steps and stopped
 * by SIGTERM on one rank at step 6; continued from step 6 on one process
 * and from step 4 on the P ranks.  Then stopped by max_steps = 6 on one
 * process, continued on the P ranks.  Each ends as the uninterrupted run
 * of the rank count it continued on; from P ranks on P ranks bit for bit. */
void test_bagnold_checkpoint_ranks(void **state)
{
    (void)state;
    char dir[256], a_dir[300], b_dir[300], path[400], err[1024] = "";
    test_ranks_dir(dir, sizeof dir, "restart");
    snprintf(a_dir, sizeof a_dir, "%s/a", dir);
    snprintf(b_dir, sizeof b_dir, "%s/b", dir);
    static struct muflow_case cs;
    struct run_result one, all, r;
    double bad = 0.0;
    load_bagnold(&cs, a_dir, (char *[]){"output.checkpoint_every=4", "output.fields_every=3", NULL});
    const struct run_options alone = {.one_process = 1}, split = {0};
    bad += run_case_opts(&cs, &alone, &one, err, sizeof err) != RUN_OK;
    bad += run_case_opts(&cs, &split, &all, err, sizeof err) != RUN_OK;
    /* A: on the ranks, stopped at step 6 */
    struct stop_hook h = {a_dir, 0, 0};
    const struct run_options stopped = {.write_output = 1, .hook = stop_hook, .hook_ctx = &h};
    bad += run_case_opts(&cs, &stopped, &r, err, sizeof err) != RUN_OK;
    bad += r.status != STATUS_STOPPED || r.signal != SIGTERM || r.steps != 6 || !r.checkpointed;
    /* its field files every 3 steps (the ranks' blocks) and their index */
    if (comm_rank() == 0) {
        snprintf(path, sizeof path, "%s/fields_000003.h5", a_dir);
        char *xdmf = test_read_in(a_dir, "fields.xdmf");
        bad += !test_file_exists(path) || !strstr(xdmf, "fields_000006.h5");
        free(xdmf);
    }
    if (comm_rank() == 0)
        printf("    on %d ranks: %s at step %ld by %s to rank %d, checkpoint %s\n", comm_size(),
               run_status_name(r.status), r.steps, r.signal == SIGTERM ? "SIGTERM" : "?",
               comm_size() - 1, r.checkpointed ? "written" : "NOT written");
    comm_sum(&bad, 1);
    if (bad == 0.0) {
        snprintf(path, sizeof path, "%s/%s", a_dir, CHECKPOINT_NAME);
        bad += continue_from(path, 1, &r, err, sizeof err) != 0 ||
               ends_alike("step 6 continued on 1 process", &one, &r, comm_size() == 1);
        snprintf(path, sizeof path, "%s/step4.h5", a_dir);
        bad += continue_from(path, 0, &r, err, sizeof err) != 0 ||
               ends_alike("step 4 continued on the same ranks", &all, &r, 1);
    }
    /* B: one process stopped by max_steps, its checkpoint continued on the ranks */
    load_bagnold(&cs, b_dir, (char *[]){"solver.max_steps=6", NULL});
    const struct run_options alone_out = {.one_process = 1, .write_output = 1};
    if (comm_rank() == 0)
        bad += run_case_opts(&cs, &alone_out, &r, err, sizeof err) != RUN_OK ||
               r.status != STATUS_UNSTEADY || r.steps != 6 || !r.checkpointed;
    comm_sum(&bad, 1);
    if (bad == 0.0) {
        snprintf(path, sizeof path, "%s/%s", b_dir, CHECKPOINT_NAME);
        static struct muflow_case cb;
        char *ov[] = {"solver.max_steps=5000"};
        const struct run_options on_ranks = {.write_output = 1, .restart_from = path};
        bad += checkpoint_load_case(path, 1, ov, &cb, err, sizeof err) != 0 ||
               run_case_opts(&cb, &on_ranks, &r, err, sizeof err) != RUN_OK || !r.checkpointed;
        bad += ends_alike("1 process's step 6 continued on the ranks", &all, &r,
                          comm_size() == 1);
    }
    ranks_verdict(bad, err, dir);
}

/* Makes the final checkpoint's temporary name a folder (rank 0, at step 1):
 * its write fails on every rank. */
static void block_checkpoint(void *ctx, const struct march_state *st)
{
    if (st->step == 1 && comm_rank() == 0) {
        char tmp[400];
        snprintf(tmp, sizeof tmp, "%s/%s.tmp", (const char *)ctx, CHECKPOINT_NAME);
        mkdir(tmp, 0700);
    }
}

/* A checkpoint that cannot be written fails the run on every rank (the
 * output error: exit status 4 in muflow), none reporting it written. */
void test_checkpoint_fails_on_ranks(void **state)
{
    (void)state;
    char dir[256], err[1024] = "";
    test_ranks_dir(dir, sizeof dir, "ckfail");
    static struct muflow_case cs;
    load_bagnold(&cs, dir, (char *[]){"solver.max_steps=2", NULL});
    const struct run_options opt = {.write_output = 1, .hook = block_checkpoint,
                                    .hook_ctx = dir};
    struct run_result r;
    const int rc = run_case_opts(&cs, &opt, &r, err, sizeof err);
    const int named = comm_rank() != 0 || strstr(err, "checkpoint") != NULL;
    double bad = rc != RUN_ERR_OUTPUT || r.checkpointed || !named;
    if (bad != 0.0)
        print_error("rank %d: rc %d: %s\n", comm_rank(), rc, err);
    else if (comm_rank() == 0)
        printf("    on %d ranks: every rank failed: %.120s\n", comm_size(), err);
    comm_sum(&bad, 1);
    comm_barrier();
    if (comm_rank() == 0)
        test_tmp_remove(dir);
    assert_true(bad == 0.0);
}

/* The collapse's lines of r: x_front, h_axis, the energies, mass_error,
 * tracer_min, and the final residual and time (doubles, exact). */
#define COLLAPSE_LINES 8
static void collapse_lines(const struct run_result *r, double v[COLLAPSE_LINES])
{
    static const char *const keys[COLLAPSE_LINES - 2] = {
        "x_front", "h_axis", "kinetic_energy", "kinetic_energy_peak", "mass_error", "tracer_min"};
    for (int k = 0; k < COLLAPSE_LINES - 2; k++)
        v[k] = run_result_value(r, keys[k]);
    v[COLLAPSE_LINES - 2] = r->residual;
    v[COLLAPSE_LINES - 1] = r->time;
}

/* A continued collapse ends as the uninterrupted one: status and steps,
 * its lines bit for bit (same: on the same ranks) or x_front, h_axis and
 * the energies within 1e-8 relative. */
static double collapse_ends_alike(const char *what, const struct run_result *a,
                                  const struct run_result *b, int same)
{
    double x[COLLAPSE_LINES], y[COLLAPSE_LINES], rel = 0.0;
    collapse_lines(a, x);
    collapse_lines(b, y);
    const int identical = memcmp(x, y, sizeof x) == 0;
    for (int k = 0; k < 4; k++)
        rel = fmax(rel, isnan(x[k]) || isnan(y[k]) ? INFINITY : fabs(y[k] - x[k]) / fabs(x[k]));
    if (comm_rank() == 0)
        printf("    collapse %s: %s after %ld steps (uninterrupted %ld), its lines %s (%.1e "
               "relative)\n",
               what, run_status_name(b->status), b->steps, a->steps,
               identical ? "bit for bit" : "differ", rel);
    return b->status != a->status || b->steps != a->steps || !(rel <= 1e-8) ||
           (same && !identical);
}

/* The collapse (two_phase's record, rank 0's, holds no face density: a
 * run on ranks rebuilds it from T) at 32 x 12, stopped by max_steps = 30
 * on this run's ranks, continued on the same ranks: as the uninterrupted
 * run on them bit for bit; continued on one process: as one process's. */
void test_collapse_checkpoint_ranks(void **state)
{
    (void)state;
    char dir[256], out[400], path[400], err[1024] = "";
    test_ranks_dir(dir, sizeof dir, "collapse");
    snprintf(out, sizeof out, "output.dir=%s", dir);
    char *ov[] = {"domain.lx=4", "domain.nx=32",    "domain.nz=12",        "solver.end_time=0.6",
                  out,           "output.quiet=on", "solver.max_steps=30"};
    static struct muflow_case cs, stop;
    test_load_case(&cs, "../cases/collapse.ini", 6, ov);
    test_load_case(&stop, "../cases/collapse.ini", 7, ov);
    struct run_result one, all, r;
    const struct run_options alone = {.one_process = 1}, split = {0}, written = {.write_output = 1};
    double bad = run_case_opts(&cs, &alone, &one, err, sizeof err) != RUN_OK;
    bad += run_case_opts(&cs, &split, &all, err, sizeof err) != RUN_OK;
    bad += run_case_opts(&stop, &written, &r, err, sizeof err) != RUN_OK;
    bad += r.steps != 30 || !r.checkpointed;
    comm_sum(&bad, 1);
    if (bad == 0.0) {
        snprintf(path, sizeof path, "%s/%s", dir, CHECKPOINT_NAME);
        bad += continue_from(path, 0, &r, err, sizeof err) != 0 ||
               collapse_ends_alike("continued on the same ranks", &all, &r, 1);
        bad += continue_from(path, 1, &r, err, sizeof err) != 0 ||
               collapse_ends_alike("continued on 1 process", &one, &r, comm_size() == 1);
    }
    ranks_verdict(bad, err, dir);
}

/* solver.initial_state on ranks: the collapse at 16 x 6 to t = 0.3, written
 * on this run's ranks, starts the collapse at 32 x 12 (every rank reads the
 * whole source and interpolates to the positions of its block) to t = 0.5,
 * split along x, z and both against one process: status, steps within 1,
 * measures within 1e-8, mass_error within 1e-13 (check_scene_lines) */
void test_initial_state_on_ranks(void **state)
{
    (void)state;
    char dir[256], out[400], from[400], err[1024] = "";
    test_ranks_dir(dir, sizeof dir, "initial");
    snprintf(out, sizeof out, "output.dir=%s", dir);
    char *coarse[] = {"domain.lx=4", "domain.nx=16", "domain.nz=6", "solver.end_time=0.3", out,
                      "output.quiet=on", "output.fields=off"};
    static struct muflow_case cs;
    test_load_case(&cs, "../cases/collapse.ini", 7, coarse);
    struct run_result r;
    const struct run_options written = {.write_output = 1};
    double bad = run_case_opts(&cs, &written, &r, err, sizeof err) != RUN_OK || !r.checkpointed;
    comm_sum(&bad, 1);
    if (bad == 0.0) {
        snprintf(from, sizeof from, "solver.initial_state=%s", dir);
        char *fine[] = {"domain.lx=4", "domain.nx=32", "domain.nz=12", "solver.end_time=0.5", from};
        static const char *const keys[] = {"x_front", "h_axis", "kinetic_energy",
                                           "kinetic_energy_peak", NULL};
        const struct scene_lines s = {.file = "../cases/collapse.ini", .n = 5, .ov = fine,
                                      .keys = keys, .want = STATUS_FINISHED};
        const int p = comm_size();
        const int splits[3][3] = {{p, 1, 1}, {1, 1, p}, {0, 1, 0}}; /* x, z, both */
        check_scene_splits(&s, 3, splits);
    }
    ranks_verdict(bad, err, dir);
}
