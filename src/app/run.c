/* One case from start to output (run.h). */
#include <errno.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <string.h>
#include "scenes/analytic.h"
#include "io/checkpoint.h"
#include "io/field_series.h"
#include "scenes/heap.h"
#include "app/interrupt.h"
#include "diagnostics/profile.h"
#include "app/run.h"
#include "scenes/tilt_search.h"

struct observer_ctx {
    const struct muflow_case *cs;
    const struct run_options *opt;
    struct history hist;
    struct field_series series;
    double last_print;
    long resume_step;      /* restart: the checkpoint's step, whose outputs exist; else -1 */
    int signal;            /* the signal that stopped the run */
    int failed;            /* an output failed during the run (cause in err) */
    int checkpoint_failed;
    int no_checkpoint;     /* a tilt search: its final state is not restartable */
    double search_start;   /* omp_get_wtime() at the start of a tilt search */
    char err[1024];
};

static void print_progress(const struct march_state *st, const struct scene_errors *e)
{
    printf("  step %6ld  t %-11.5g dt %-10.3g residual %.3e  div %.1e  cg %3d", st->step,
           st->time, st->dt, st->residual, st->divergence, st->linear_iterations);
    if (e->valid)
        printf("  err_rms %.3e", e->err_rms);
    printf("  [%.2f s]\n", st->wall_seconds);
    fflush(stdout);
}

/* The outputs due at this step: history row, field file, checkpoint.  Returns
 * non-zero when one failed (the run then stops). */
static int step_outputs(struct observer_ctx *ctx, const struct march_state *st,
                        const struct scene_errors *e)
{
    const struct muflow_case *cs = ctx->cs;
    history_row(&ctx->hist, st, e);
    if (field_series_due(&ctx->series, cs, st) && !field_series_has(&ctx->series, st->step) &&
        field_series_write(&ctx->series, cs->output_dir, st, ctx->err, sizeof ctx->err) != 0)
        return ctx->failed = 1;
    if (cs->checkpoint_every > 0 && st->step > 0 && st->step % cs->checkpoint_every == 0 &&
        st->status == STATUS_RUNNING) {
        history_flush(&ctx->hist); /* a restart after a crash continues these rows */
        if (checkpoint_write(cs->output_dir, st, &ctx->series, ctx->err, sizeof ctx->err) != 0)
            return ctx->failed = ctx->checkpoint_failed = 1;
    }
    return 0;
}

static int observe(void *vctx, const struct march_state *st)
{
    struct observer_ctx *ctx = vctx;
    if (ctx->opt->hook)
        ctx->opt->hook(ctx->opt->hook_ctx, st);
    if (!ctx->opt->write_output)
        return 0;
    struct scene_errors e;
    memset(&e, 0, sizeof e);
    e.err_rms = NAN;
    if (ctx->cs->scene != SCENE_NONE)
        scene_errors_of(st, &e);
    /* the first observation of a restart is the checkpoint's step, whose
     * outputs the run that wrote the checkpoint has written */
    int resumed = st->step == ctx->resume_step;
    ctx->resume_step = -1;
    if (!resumed && step_outputs(ctx, st, &e) != 0)
        return 1;
    if (!ctx->cs->quiet) {
        int due = st->step == 0 || resumed || st->status != STATUS_RUNNING ||
                  st->wall_seconds - ctx->last_print >= ctx->cs->progress_interval;
        if (due) {
            print_progress(st, &e);
            ctx->last_print = st->wall_seconds;
        }
    }
    int sig = interrupt_signal();
    if (sig && st->status == STATUS_RUNNING) {
        ctx->signal = sig;
        return 1;
    }
    return 0;
}

void run_result_from(const struct march_state *st, struct run_result *res)
{
    res->status = st->status;
    res->steps = st->step;
    res->time = st->time;
    res->wall_seconds = st->wall_seconds;
    res->residual = st->residual;
    res->divergence = st->divergence;
    snprintf(res->message, sizeof res->message, "%s", st->message);
}

int run_exit_code(enum run_status s)
{
    switch (s) {
    case STATUS_STEADY:
    case STATUS_FINISHED: return 0;
    case STATUS_DIVERGED: return 1;
    default: return 3;
    }
}

static void print_header(const struct muflow_case *cs, const struct march_state *st,
                         const char *restart_from, int threads_then)
{
    printf("muflow %s: %s, %d x %d x %d cells, %s mode, %s / %s, lambda %g, %d threads\n",
           cs->name, scene_name(cs->scene), st->g.n[0], st->g.n[1], st->g.n[2],
           cs->mode == MODE_STEADY ? "steady" : "transient", rheology_law_name(cs->rheo.law),
           regularisation_name(cs->rheo.reg), cs->rheo.lambda, omp_get_max_threads());
    if (restart_from)
        printf("muflow %s: continuing from %s at step %ld, t = %.6g\n", cs->name, restart_from,
               st->step, st->time);
    fflush(stdout);
    if (restart_from && threads_then != omp_get_max_threads())
        fprintf(stderr,
                "muflow: warning: the checkpoint was written with %d threads, this run has %d: "
                "the continuation is not bit for bit the uninterrupted run (reductions sum per "
                "thread)\n",
                threads_then, omp_get_max_threads());
}

/* Sets up st (and, for a restart, its state) and the output folder. */
static int start(struct march_state *st, struct observer_ctx *ctx, const struct muflow_case *cs,
                 const struct run_options *opt, char *err, size_t errlen)
{
    int threads_then = omp_get_max_threads();
    if (opt->restart_from && checkpoint_import_wisdom(opt->restart_from, err, errlen) != 0)
        return RUN_ERR_SETUP;
    if (march_create(st, cs, err, errlen) != 0)
        return RUN_ERR_SETUP;
    if (opt->restart_from) {
        if (checkpoint_read_state(opt->restart_from, st, &ctx->series, &threads_then, err,
                                  errlen) != 0)
            goto fail;
        ctx->resume_step = st->step;
    }
    if (!opt->write_output)
        return RUN_OK;
    if (output_make_dir(cs->output_dir, err, errlen) != 0)
        goto fail;
    if ((opt->restart_from ? history_resume(&ctx->hist, cs->output_dir, st->step, err, errlen)
                           : history_open(&ctx->hist, cs->output_dir, err, errlen)) != 0)
        goto fail;
    if (interrupt_install() != 0) {
        snprintf(err, errlen, "cannot install the SIGINT/SIGTERM handler: %s", strerror(errno));
        history_close(&ctx->hist, err, 0);
        goto fail;
    }
    if (!cs->quiet)
        print_header(cs, st, opt->restart_from, threads_then);
    return RUN_OK;
fail:
    march_destroy(st);
    return RUN_ERR_SETUP;
}

/* Keeps the first error of the final outputs. */
static void note(int *rc, char *err, size_t errlen, const char *cause)
{
    if (*rc == RUN_OK)
        snprintf(err, errlen, "%s", cause);
    *rc = RUN_ERR_OUTPUT;
}

/* The outputs of the final state: field file, checkpoint (when stopped),
 * history, profile, summary; each attempted even when an earlier one failed. */
static int finish_outputs(struct observer_ctx *ctx, const struct march_state *st,
                          const struct profile *pr, const struct heap_profile *hp,
                          struct run_result *res, char *err, size_t errlen)
{
    const struct muflow_case *cs = ctx->cs;
    int rc = RUN_OK;
    char cause[1024];
    if (ctx->failed)
        note(&rc, err, errlen, ctx->err);
    /* the field file first, so the checkpoint's list of field files (and the
     * restarted run's fields.xdmf) includes it */
    if (cs->fields && !field_series_has(&ctx->series, st->step) &&
        field_series_write(&ctx->series, cs->output_dir, st, cause, sizeof cause) != 0)
        note(&rc, err, errlen, cause);
    if (st->status == STATUS_STOPPED && !ctx->checkpoint_failed && !ctx->no_checkpoint) {
        if (checkpoint_write(cs->output_dir, st, &ctx->series, cause, sizeof cause) != 0)
            note(&rc, err, errlen, cause);
        else
            res->checkpointed = 1;
    }
    if (history_close(&ctx->hist, cause, sizeof cause) != 0)
        note(&rc, err, errlen, cause);
    if (pr && output_profile(cs->output_dir, pr, cause, sizeof cause) != 0)
        note(&rc, err, errlen, cause);
    if (hp && output_heap(cs->output_dir, hp, cause, sizeof cause) != 0)
        note(&rc, err, errlen, cause);
    if (output_summary(cs->output_dir, cs, res, cause, sizeof cause) != 0)
        note(&rc, err, errlen, cause);
    return rc;
}

static void report_solve(void *vctx, int solve, double tilt, double flow_rate,
                         const struct march_state *st)
{
    struct observer_ctx *ctx = vctx;
    if (!ctx->opt->write_output || ctx->cs->quiet)
        return;
    double target = ctx->cs->heap.flow_rate;
    printf("heap: solve %2d  tilt %.8f  Q* %-10.6g (target %g, %+.3f%%)  %s after %ld steps  "
           "[%.1f s]\n",
           solve, tilt, flow_rate, target, 100.0 * (flow_rate / target - 1.0),
           run_status_name(st->status), st->step, omp_get_wtime() - ctx->search_start);
    fflush(stdout);
}

/* The heap scene with heap.flow_rate: the tilt by root finding over steady
 * solves.  A search that fails or misses the tolerance ends "stopped" (or
 * with the failed solve's status) and says why. */
static void search_tilt(struct march_state *st, struct muflow_case *work,
                        struct observer_ctx *ctx, struct tilt_search_result *sr)
{
    struct tilt_search_spec spec = {
        .target = work->heap.flow_rate, .tilt_min = work->heap.tilt_min,
        .tilt_max = work->heap.tilt_max, .tolerance = work->heap.flow_rate_tolerance,
        .max_solves = work->heap.max_solves, .flow_rate = heap_flow_rate};
    ctx->no_checkpoint = 1;
    ctx->search_start = omp_get_wtime();
    tilt_search_run(st, work, &spec, observe, ctx, report_solve, ctx, sr);
    st->wall_seconds = omp_get_wtime() - ctx->search_start; /* the whole search */
    if (!sr->converged && st->status == STATUS_STEADY)
        st->status = STATUS_STOPPED;
    if (st->status != STATUS_STOPPED || !ctx->signal)
        snprintf(st->message, sizeof st->message, "%s", sr->message);
}

static void heap_result_from(const struct march_state *st, const struct heap_profile *hp,
                             const struct tilt_search_result *sr, struct heap_result *h)
{
    h->valid = 1;
    h->tilt = st->cs->tilt;
    h->flow_rate = heap_flow_rate(st);
    h->searched = sr != NULL;
    h->converged = sr ? sr->converged : 0;
    h->solves = sr ? sr->solves : 1;
    h->steps = sr ? sr->steps : st->step;
    h->u_surface_mid = hp ? hp->u_surface_mid : NAN;
    h->depth_mid = hp ? hp->depth_mid : NAN;
}

int run_case_opts(const struct muflow_case *cs, const struct run_options *opt,
                  struct run_result *res, char *err, size_t errlen)
{
    memset(res, 0, sizeof *res);
    /* the working copy the march reads: a tilt search changes its tilt, and
     * the summary then records the tilt found */
    struct muflow_case work = *cs;
    int searching = work.scene == SCENE_HEAP && work.heap.flow_rate > 0.0;
    if (searching && opt->restart_from) {
        snprintf(err, errlen, "a tilt search (heap.flow_rate > 0) cannot continue from a "
                              "checkpoint: run it again, starting from physics.tilt");
        return RUN_ERR_SETUP;
    }
    struct march_state st;
    struct observer_ctx ctx = {.cs = &work, .opt = opt, .resume_step = -1};
    field_series_init(&ctx.series);
    int rc = start(&st, &ctx, &work, opt, err, errlen);
    if (rc != RUN_OK) {
        field_series_free(&ctx.series);
        return rc;
    }
    struct tilt_search_result sr;
    if (searching)
        search_tilt(&st, &work, &ctx, &sr);
    else
        march_run(&st, observe, &ctx);
    if (st.status == STATUS_STOPPED && ctx.signal) {
        res->signal = ctx.signal;
        snprintf(st.message, sizeof st.message, "interrupted by %s at step %ld",
                 interrupt_name(ctx.signal), st.step);
    } else if (st.status == STATUS_STOPPED && ctx.failed) {
        snprintf(st.message, sizeof st.message, "output failed at step %ld: %.180s", st.step,
                 ctx.err);
    }
    run_result_from(&st, res);
    struct profile pr;
    int have_profile = profile_extract(&pr, &st) == 0;
    if (have_profile)
        profile_errors(&pr, &work, &res->errors);
    struct heap_profile hp;
    int have_heap = work.scene == SCENE_HEAP &&
                    heap_profile_extract(&hp, &st, work.heap.depth_fraction) == 0;
    if (work.scene == SCENE_HEAP)
        heap_result_from(&st, have_heap ? &hp : NULL, searching ? &sr : NULL, &res->heap);
    if (opt->write_output) {
        rc = finish_outputs(&ctx, &st, have_profile ? &pr : NULL, have_heap ? &hp : NULL, res,
                            err, errlen);
        interrupt_restore(); /* only now: a signal during the final writes is ignored */
    }
    if (have_profile)
        profile_free(&pr);
    if (have_heap)
        heap_profile_free(&hp);
    field_series_free(&ctx.series);
    march_destroy(&st);
    return rc;
}

int run_case(const struct muflow_case *cs, int write_output, struct run_result *res, char *err,
             size_t errlen)
{
    struct run_options opt = {.write_output = write_output};
    return run_case_opts(cs, &opt, res, err, errlen);
}
