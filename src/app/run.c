/* One case from start to output (run.h). */
#include <errno.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <string.h>
#include "app/interrupt.h"
#include "app/run.h"
#include "diagnostics/profile.h"
#include "physics/obstacle.h"
#include "physics/obstacle_forces.h"
#include "physics/forces_file.h"
#include "io/checkpoint.h"
#include "march/step.h"
#include "io/initial_state.h"
#include "io/field_series.h"
#include "scenes/scene.h"
#include "solvers/pressure.h"
#include "solvers/viscous.h"
#include "platform/comm.h"

struct observer_ctx {
    const struct muflow_case *cs;
    const struct run_options *opt;
    struct history hist;
    struct forces_file forces; /* forces.csv (a body in a flow) */
    struct field_series series;
    double last_print;
    double last_scene_write; /* wall time of the last write_running refresh */
    long resume_step;      /* restart: the checkpoint's step, whose outputs exist; else -1 */
    long last_row;         /* the step of the last history row (-1: none) */
    long unconverged;      /* pressure solves that failed, as last reported */
    long linear_unconverged; /* implicit solves stopped at their cap, as last reported */
    long fallbacks;        /* implicit steps' failed factorisations, as last reported */
    long coupled_fallbacks; /* coupled steps' failed GMRES solves, as last reported */
    int signal;            /* the signal that stopped the run */
    int failed;            /* an output failed during the run (cause in err) */
    int checkpoint_failed;
    int not_restartable;   /* the scene's run cannot continue from its checkpoint */
    int root;              /* this process writes the outputs (rank 0 of a decomposed run) */
    char err[1024];
};

static void print_progress(const struct march_state *st, const struct scene_errors *e)
{
    printf("  step %6ld  t %-11.5g dt %-10.3g residual %.3e  div %.1e  cg %3d", st->step,
           st->time, st->dt, st->residual, st->divergence, st->linear_iterations);
    if (e->valid) /* err_midline for a scene compared with a reference curve */
        printf("  %s %.3e", scene_error_name(case_scene(st->cs)), e->err_rms);
    printf("  [%.2f s]\n", st->wall_seconds);
    fflush(stdout);
}

/* The outputs due at this step: history row, field file, checkpoint.  Returns
 * non-zero when one failed (the run then stops).  On ranks the field file
 * and the checkpoint are every rank's (collective, one status), the rest
 * rank 0's, after them (no rank leaves a collective write unreached). */
static int step_outputs(struct observer_ctx *ctx, const struct march_state *st,
                        const struct scene_errors *e)
{
    const struct muflow_case *cs = ctx->cs;
    /* the march observes a step again when it ends on the state it had
     * already observed (a breakdown of the viscous solve restores it): one
     * row per step */
    if (ctx->root && st->step != ctx->last_row)
        history_row(&ctx->hist, st, e);
    ctx->last_row = st->step;
    int field_due = field_series_due(&ctx->series, cs, st) &&
                    !field_series_has(&ctx->series, st->step);
    if (field_due &&
        field_series_write(&ctx->series, cs->output_dir, st, ctx->err, sizeof ctx->err) != 0)
        return ctx->failed = 1;
    if (cs->checkpoint_every > 0 && st->step > 0 && st->step % cs->checkpoint_every == 0 &&
        st->status == STATUS_RUNNING) {
        if (ctx->root) {
            history_flush(&ctx->hist); /* a restart after a crash continues these rows */
            forces_file_flush(&ctx->forces);
        }
        if (checkpoint_write(cs->output_dir, st, &ctx->series, ctx->err, sizeof ctx->err) != 0)
            return ctx->failed = ctx->checkpoint_failed = 1;
    }
    const struct scene *sc = case_scene(cs);
    if (ctx->root && sc->write_running && sc->write && st->status == STATUS_RUNNING &&
        (field_due || st->wall_seconds - ctx->last_scene_write >= cs->progress_interval)) {
        if (sc->write(cs->output_dir, st, ctx->err, sizeof ctx->err) != 0)
            return ctx->failed = 1;
        ctx->last_scene_write = st->wall_seconds;
    }
    return 0;
}

/* Whether a run's count of some failure rose from 0 to count (its first
 * occurrence, the one to tell: later ones are only counted); *reported
 * follows count.  A restart starts *reported at the checkpoint's count,
 * whose first was told before. */
static int first_rise(long count, long *reported)
{
    int first = count > *reported && *reported == 0;
    if (count > *reported)
        *reported = count;
    return first;
}

/* A pressure solve that did not converge is taken as it is (the step goes
 * on), but never silently: one line when the count first rises, the count
 * in summary.ini. */
static void warn_pressure(struct observer_ctx *ctx, const struct march_state *st)
{
    if (first_rise(st->pressure_unconverged, &ctx->unconverged))
        fprintf(stderr,
                "muflow: warning: step %ld: %s; the projection took that iterate "
                "(summary.ini: pressure_unconverged)\n",
                st->step, pressure_message(st->pressure_solver));
}

/* An implicit solve that stopped at its iteration cap is taken as it is
 * (the step goes on with the iterate), but never silently: the same. */
static void warn_linear(struct observer_ctx *ctx, const struct march_state *st)
{
    if (first_rise(st->linear_unconverged, &ctx->linear_unconverged))
        fprintf(stderr,
                "muflow: warning: step %ld: the implicit viscous solve stopped at "
                "solver.max_linear_iterations = %d with a relative residual of %.1e; the step "
                "took that iterate (summary.ini: linear_unconverged)\n",
                st->step, st->cs->max_linear_iterations, st->linear_residual);
}

/* A sparse factorisation or AMG setup that failed leaves the step to the
 * line blocks, which converge slowly or not at all in 2D, and an AMG whose
 * GMRES failed leaves the run to the LU: never silently (one line with the
 * cause when the count first rises, the count in summary.ini). */
static void warn_preconditioner(struct observer_ctx *ctx, const struct march_state *st)
{
    const char *cause;
    long coupled = stage_coupled_fallbacks(st->coupled, &cause);
    if (first_rise(coupled, &ctx->coupled_fallbacks))
        fprintf(stderr,
                "muflow: warning: step %ld: %s; the coupled step fell back to the sparse LU "
                "(summary.ini: preconditioner_fallbacks)\n",
                st->step, cause);
    if (!st->viscous)
        return;
    struct viscous_precond_info info;
    viscous_precond_info(st->viscous, &info);
    if (first_rise(info.fallbacks, &ctx->fallbacks))
        fprintf(stderr,
                "muflow: warning: step %ld: %s; the implicit step fell back to the %s "
                "(summary.ini: preconditioner_fallbacks)\n",
                st->step, info.cause, info.kind == VISCOUS_LU ? "sparse LU" : "line blocks");
}

/* This rank's observation: 1 when an output failed (the cause in ctx->err). */
static int observe_here(struct observer_ctx *ctx, const struct march_state *st)
{
    if (ctx->opt->hook)
        ctx->opt->hook(ctx->opt->hook_ctx, st);
    if (!ctx->opt->write_output)
        return 0;
    struct scene_errors e;
    memset(&e, 0, sizeof e);
    e.err_rms = NAN;
    if (case_scene(ctx->cs)->profile_axis >= 0)
        scene_errors_of(st, &e); /* over every rank */
    if (ctx->root) {
        warn_pressure(ctx, st);
        warn_linear(ctx, st);
        warn_preconditioner(ctx, st);
    }
    forces_file_row(&ctx->forces, st); /* before a checkpoint; once per step; every rank's */
    /* the first observation of a restart is the checkpoint's step, whose
     * outputs the run that wrote the checkpoint has written */
    int resumed = st->step == ctx->resume_step;
    ctx->resume_step = -1;
    if (!resumed && step_outputs(ctx, st, &e) != 0)
        return 1;
    if (ctx->root && !ctx->cs->quiet) {
        int due = st->step == 0 || resumed || st->status != STATUS_RUNNING ||
                  st->wall_seconds - ctx->last_print >= ctx->cs->progress_interval;
        if (due) {
            print_progress(st, &e);
            ctx->last_print = st->wall_seconds;
        }
    }
    return 0;
}

/* Stops the run when an output failed or SIGINT / SIGTERM came; a
 * decomposed run's ranks agree on both (a maximum over the ranks) and stop
 * at the same step, whichever rank met it. */
static int observe(void *vctx, const struct march_state *st)
{
    struct observer_ctx *ctx = vctx;
    double stop[2] = {observe_here(ctx, st), 0.0};
    if (!stop[0] && ctx->opt->write_output && st->status == STATUS_RUNNING)
        stop[1] = interrupt_signal();
    if (st->ranks) {
        comm_max(stop, 2); /* the ranks of the march are every rank */
        if (stop[0] != 0.0 && !ctx->failed) {
            ctx->failed = 1;
            snprintf(ctx->err, sizeof ctx->err, "an output failed on another rank");
        }
    }
    if (stop[0] == 0.0 && stop[1] != 0.0)
        ctx->signal = (int)stop[1];
    return stop[0] != 0.0 || stop[1] != 0.0;
}

void run_result_from(const struct march_state *st, struct run_result *res)
{
    scene_result_names(case_scene(st->cs), &res->names);
    res->status = st->status;
    res->steps = st->step;
    res->rejected_steps = st->rejected;
    res->pressure_iterations = st->pressure_iterations;
    res->pressure_unconverged = st->pressure_unconverged;
    res->linear_unconverged = st->linear_unconverged;
    res->grid_matrices = st->grid_matrices;
    res->pressure_matrices =
        st->hydrostatic_matrices +
        (st->pressure_solver ? pressure_direct_factorisations(st->pressure_solver) : 0);
    if (st->viscous) {
        struct viscous_precond_info info;
        viscous_precond_info(st->viscous, &info);
        res->preconditioner_fallbacks = info.fallbacks;
    }
    res->preconditioner_fallbacks += stage_coupled_fallbacks(st->coupled, NULL);
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
                         const char *restart_from)
{
    const struct grid *g = march_global_grid(st);
    char ranks[80] = "";
    if (st->ranks) /* the memory is rank 0's */
        snprintf(ranks, sizeof ranks, "ranks %d (%d x %d x %d), ", st->ranks->cart.size,
                 st->ranks->cart.dims[0], st->ranks->cart.dims[1], st->ranks->cart.dims[2]);
    /* the solver auto took: the coupled step's LU unless GMRES is named */
    char solver[80];
    if (cs->coupled)
        snprintf(solver, sizeof solver, "coupled %s%s",
                 st->precond == VISCOUS_AMG || st->precond == VISCOUS_MG ? "GMRES + " : "LU",
                 st->precond == VISCOUS_AMG || st->precond == VISCOUS_MG
                     ? viscous_precond_name(st->precond) : "");
    else
        snprintf(solver, sizeof solver, "implicit %s%s", viscous_precond_name(st->precond),
                 cs->preconditioner == PRECOND_AUTO ? " (auto)" : "");
    printf("muflow %s: %s, %d x %d x %d cells, %s mode, %s / %s, lambda %g, %s, %s%d thread%s, "
           "memory ~%.0f MB\n",
           cs->name, case_scene(cs)->name, g->n[0], g->n[1], g->n[2],
           cs->mode == MODE_STEADY ? "steady" : "transient", rheology_law_name(cs->rheo.law),
           regularisation_name(cs->rheo.reg), cs->rheo.lambda, solver, ranks, omp_get_max_threads(),
           omp_get_max_threads() == 1 ? "" : "s", st->memory_estimate / 1e6);
    /* the curve's derived values, which no key shows (jop: nothing to add) */
    if (cs->rheo.law == LAW_MUI && cs->rheo.curve != CURVE_JOP)
        printf("muflow %s: mu(I) curve %s: alpha %g, mu_inf %g, I_1^N = %.8g, A_minus = %.8g\n",
               cs->name, rheology_curve_name(cs->rheo.curve), cs->rheo.alpha, cs->rheo.mu_inf,
               cs->rheo.i1n, cs->rheo.a_minus);
    if (restart_from)
        printf("muflow %s: continuing from %s at step %ld, t = %.6g\n", cs->name, restart_from,
               st->step, st->time);
    fflush(stdout);
}

/* Warnings go to stderr whatever output.quiet says (quiet silences progress,
 * not problems; a restart inherits the checkpoint's quiet, which must not
 * hide this one). */
static void warn_threads(const char *restart_from, const int writer[2], int ranks)
{
    if (restart_from && writer[0] != omp_get_max_threads())
        fprintf(stderr,
                "muflow: warning: the checkpoint was written with %d threads, this run has %d: "
                "the continuation is not bit for bit the uninterrupted run (reductions sum per "
                "thread)\n",
                writer[0], omp_get_max_threads());
    if (restart_from && writer[1] != ranks)
        fprintf(stderr,
                "muflow: warning: the checkpoint was written on %d MPI rank%s, this run has %d: "
                "the continuation is not bit for bit the uninterrupted run (sums over ranks "
                "in another order)\n",
                writer[1], writer[1] == 1 ? "" : "s", ranks);
}

/* The output folder, history.csv and forces.csv of a run.  Returns 0, or
 * -1 with the cause in err (nothing left open). */
static int open_outputs(const struct march_state *st, struct observer_ctx *ctx,
                        const struct muflow_case *cs, const struct run_options *opt, char *err,
                        size_t errlen)
{
    if (output_make_dir(cs->output_dir, err, errlen) != 0)
        return -1;
    /* a fresh run starts from a folder without an earlier run's files,
     * whichever scene wrote them; a continued run keeps them (its series
     * and history go on from them) */
    const char *names[SCENE_OUTPUT_FILES_MAX];
    if (!opt->restart_from &&
        scene_output_files(names, SCENE_OUTPUT_FILES_MAX, opt->modules) < 0) {
        snprintf(err, errlen, "more than %d names of output files", SCENE_OUTPUT_FILES_MAX - 1);
        return -1;
    }
    if (!opt->restart_from && output_remove_run_files(cs->output_dir, names, err, errlen) < 0)
        return -1;
    const char *ename = scene_error_name(case_scene(cs));
    if ((opt->restart_from
             ? history_resume(&ctx->hist, cs->output_dir, ename, st->step, err, errlen)
             : history_open(&ctx->hist, cs->output_dir, ename, err, errlen)) != 0)
        return -1;
    if (forces_file_open(&ctx->forces, st, cs->output_dir, opt->restart_from ? st->step : -1,
                         err, errlen) != 0) {
        history_close(&ctx->hist, err, 0);
        return -1;
    }
    return 0;
}

/* Sets up st (and, for a restart, its state) and the output folder. */
static int start(struct march_state *st, struct observer_ctx *ctx, const struct muflow_case *cs,
                 const struct run_options *opt, char *err, size_t errlen)
{
    int writer[2] = {omp_get_max_threads(), 1}; /* a restart's checkpoint: threads, ranks */
    if (opt->restart_from && checkpoint_import_wisdom(opt->restart_from, err, errlen) != 0)
        return RUN_ERR_SETUP;
    struct march_setup su;
    scene_march_setup(cs, opt->modules, &su);
    su.decompose = !opt->one_process;
    for (int d = 0; d < 3; d++)
        su.dims[d] = opt->dims[d];
    if (march_create(st, cs, &su, err, errlen) != 0)
        return RUN_ERR_SETUP;
    const int ranks = st->ranks ? st->ranks->cart.size : 1;
    writer[1] = ranks;
    int bad = 0;
    if (opt->restart_from) {
        bad = checkpoint_read_state(opt->restart_from, st, &ctx->series, writer, err,
                                    errlen) != 0;
        ctx->resume_step = st->step;
    } else if (cs->initial_state[0]) {
        bad = initial_state_load(cs->initial_state, st, err, errlen) != 0;
    }
    if (st->ranks && march_max(st, bad) != 0.0 && !bad) { /* every rank reads its block */
        snprintf(err, errlen, "another rank could not read its part of %s",
                 opt->restart_from ? opt->restart_from : cs->initial_state);
        bad = 1;
    }
    if (bad)
        goto fail;
    if (!opt->write_output)
        return RUN_OK;
    /* a decomposed run's files are rank 0's (its field files and checkpoints
     * every rank's, after rank 0 made the folder: the agreement below waits
     * for it) */
    bad = ctx->root && open_outputs(st, ctx, cs, opt, err, errlen) != 0;
    if (!ctx->root)
        forces_file_follow(&ctx->forces, st);
    if (st->ranks && march_max(st, bad) != 0.0 && !bad) {
        snprintf(err, errlen, "rank 0 could not open the outputs");
        goto fail;
    }
    if (bad)
        goto fail;
    if (interrupt_install() != 0) {
        snprintf(err, errlen, "cannot install the SIGINT/SIGTERM handler: %s", strerror(errno));
        if (ctx->root) {
            history_close(&ctx->hist, err, 0);
            forces_file_close(&ctx->forces, err, 0);
        }
        goto fail;
    }
    if (!cs->quiet && ctx->root)
        print_header(cs, st, opt->restart_from);
    if (ctx->root)
        warn_threads(opt->restart_from, writer, ranks);
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

/* Rank 0's outputs of the final state (a run of one process: its own):
 * history, forces, profile, the scene's files, summary. */
static void root_outputs(struct observer_ctx *ctx, const struct march_state *st,
                         const struct profile *pr, struct run_result *res, int *rc, char *err,
                         size_t errlen)
{
    const struct muflow_case *cs = ctx->cs;
    char cause[1024];
    res->restartable = !ctx->not_restartable;
    if (history_close(&ctx->hist, cause, sizeof cause) != 0)
        note(rc, err, errlen, cause);
    if (forces_file_close(&ctx->forces, cause, sizeof cause) != 0)
        note(rc, err, errlen, cause);
    if (pr && profile_write(cs->output_dir, pr, cause, sizeof cause) != 0)
        note(rc, err, errlen, cause);
    const struct scene *sc = case_scene(cs);
    if (sc->write && sc->write(cs->output_dir, st, cause, sizeof cause) != 0)
        note(rc, err, errlen, cause);
    if (output_summary(cs->output_dir, cs, res, cause, sizeof cause) != 0)
        note(rc, err, errlen, cause);
}

/* The outputs of the final state: field file, checkpoint (every rank's on
 * ranks), then rank 0's; each attempted even when an earlier one failed.
 * On ranks every rank returns the same status (rank 0's err the cause). */
static int finish_outputs(struct observer_ctx *ctx, const struct march_state *st,
                          const struct profile *pr, struct run_result *res, char *err,
                          size_t errlen)
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
    /* every run ends with a checkpoint of its final state: one that missed its
     * goal (max_steps in either mode, a signal, no steady state, the last
     * sane state of a divergence) continues from it with other keys, and one
     * that reached it can go on with a tighter tolerance or a later end time;
     * `muflow --restart out/bagnold` after `make run` is then a command that
     * works (also after a steady run stopped at max_steps).  A
     * scene's run that cannot continue from it (a search, a continuation)
     * still leaves its final state there: a new run starts from it with
     * solver.initial_state */
    if (!ctx->checkpoint_failed) { /* agreed on ranks, as the write's status */
        if (checkpoint_write(cs->output_dir, st, &ctx->series, cause, sizeof cause) != 0)
            note(&rc, err, errlen, cause);
        else
            res->checkpointed = 1;
    }
    /* the forces' row of the final state (if no observation wrote it) and
     * the body's surface: every rank's blocks, rank 0's files */
    forces_file_row(&ctx->forces, st);
    if (case_obstacle_active(cs) && obstacle_write(cs->output_dir, st, cause, sizeof cause) != 0)
        note(&rc, err, errlen, cause);
    if (ctx->root)
        root_outputs(ctx, st, pr, res, &rc, err, errlen);
    if (st->ranks && march_max(st, rc != RUN_OK) != 0.0 && rc == RUN_OK)
        note(&rc, err, errlen, "an output failed on rank 0");
    return rc;
}

int run_case_opts(const struct muflow_case *cs, const struct run_options *opt,
                  struct run_result *res, char *err, size_t errlen)
{
    memset(res, 0, sizeof *res);
    /* the working copy the march reads: a driver may change it (the heap's
     * tilt search), and the summary then records what it found */
    struct muflow_case work = *cs;
    const struct scene *sc = case_scene(&work);
    scene_result_names(sc, &res->names);
    const char *why = sc->not_restartable ? sc->not_restartable(&work) : NULL;
    if (why && opt->restart_from) {
        snprintf(err, errlen, "%s", why);
        return RUN_ERR_SETUP;
    }
    struct march_state st;
    struct observer_ctx ctx = {.cs = &work, .opt = opt, .resume_step = -1, .last_row = -1, .not_restartable = !!why,
                              .root = opt->one_process || comm_rank() == 0};
    field_series_init(&ctx.series);
    int rc = start(&st, &ctx, &work, opt, err, errlen);
    if (rc != RUN_OK) {
        field_series_free(&ctx.series);
        return rc;
    }
    ctx.unconverged = st.pressure_unconverged; /* a restart's were reported before */
    ctx.linear_unconverged = st.linear_unconverged;
    struct scene_drive drive = {.st = &st, .cs = &work, .observe = observe, .observe_ctx = &ctx,
                                .verbose = opt->write_output && !work.quiet && ctx.root,
                                .restarted = opt->restart_from != NULL,
                                .dir = opt->write_output && ctx.root ? work.output_dir : NULL};
    if (sc->drive)
        sc->drive(&drive);
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
    int have_profile = scene_profile(&pr, &st) == 0;
    if (have_profile)
        scene_profile_errors(&pr, &st, &res->errors);
    if (sc->results)
        sc->results(&st, &drive, res);
    /* a run that cannot continue from its checkpoint says so when
     * interrupted, and what to do instead, never "resume with" */
    if (why && !res->stop_note[0])
        snprintf(res->stop_note, sizeof res->stop_note, "at step %ld: %s", st.step, why);
    if (case_obstacle_active(&work))
        obstacle_results(&st, &res->values);
    if (opt->write_output) {
        rc = finish_outputs(&ctx, &st, have_profile ? &pr : NULL, res, err, errlen);
        interrupt_restore(); /* only now: a signal during the final writes is ignored */
    }
    if (have_profile)
        profile_free(&pr);
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
