/* One case from start to output (run.h). */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <string.h>
#include "analytic.h"
#include "profile.h"
#include "run.h"

struct observer_ctx {
    const struct muflow_case *cs;
    int write_output;
    struct history hist;
    double last_print;
    int printed_header;
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

static int observe(void *vctx, const struct march_state *st)
{
    struct observer_ctx *ctx = vctx;
    struct scene_errors e;
    memset(&e, 0, sizeof e);
    e.err_rms = NAN;
    if (ctx->cs->scene != SCENE_NONE)
        scene_errors_of(st, &e);
    if (ctx->write_output) {
        history_row(&ctx->hist, st, &e);
        if (!ctx->cs->quiet) {
            int due = st->step == 0 || st->status != STATUS_RUNNING ||
                      st->wall_seconds - ctx->last_print >= ctx->cs->progress_interval;
            if (due) {
                print_progress(st, &e);
                ctx->last_print = st->wall_seconds;
            }
        }
    }
    return 0;
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

int run_case(const struct muflow_case *cs, int write_output, struct run_result *res, char *err,
             size_t errlen)
{
    memset(res, 0, sizeof *res);
    struct march_state st;
    if (march_create(&st, cs, err, errlen) != 0)
        return -1;
    struct observer_ctx ctx = {.cs = cs, .write_output = write_output};
    if (write_output) {
        if (output_make_dir(cs->output_dir, err, errlen) != 0 ||
            history_open(&ctx.hist, cs->output_dir, err, errlen) != 0) {
            march_destroy(&st);
            return -1;
        }
        if (!cs->quiet) {
            printf("muflow %s: %s, %d x %d x %d cells, %s mode, %s / %s, lambda %g, %d threads\n",
                   cs->name, scene_name(cs->scene), st.g.n[0], st.g.n[1], st.g.n[2],
                   cs->mode == MODE_STEADY ? "steady" : "transient",
                   rheology_law_name(cs->rheo.law), regularisation_name(cs->rheo.reg),
                   cs->rheo.lambda, omp_get_max_threads());
            fflush(stdout);
        }
    }
    march_run(&st, observe, &ctx);
    res->status = st.status;
    res->steps = st.step;
    res->time = st.time;
    res->wall_seconds = st.wall_seconds;
    res->residual = st.residual;
    res->divergence = st.divergence;
    snprintf(res->message, sizeof res->message, "%s", st.message);
    struct profile pr;
    int have_profile = profile_extract(&pr, &st) == 0;
    if (have_profile)
        profile_errors(&pr, cs, &res->errors);
    int rc = 0;
    if (write_output) {
        rc |= history_close(&ctx.hist, err, errlen);
        if (have_profile && rc == 0)
            rc |= output_profile(cs->output_dir, &pr, err, errlen);
        if (rc == 0)
            rc |= output_summary(cs->output_dir, cs, res, err, errlen);
    }
    if (have_profile)
        profile_free(&pr);
    march_destroy(&st);
    return rc ? -1 : 0;
}
