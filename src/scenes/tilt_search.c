/* Tilt search by Brent's method around steady solves (tilt_search.h). */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>
#include "config/keys.h"
#include "scenes/tilt_search.h"

struct search_ctx {
    struct march_state *st;
    struct muflow_case *cs;
    const struct tilt_search_spec *spec;
    march_observer obs;
    void *obs_ctx;
    tilt_search_report report;
    void *report_ctx;
    struct tilt_search_result *res;
    int failed;            /* a solve did not end steady (message set) */
    double last_f;         /* ln(Q / target) of the last solve */
    double end_rate[2];    /* Q* at the bracket ends, for the message */
};

/* One steady solve at tilt, from rest or continued (below); returns
 * ln(Q* / target), or NaN (GSL then stops) when the solve failed. */
static double misfit(double tilt, void *vctx)
{
    struct search_ctx *x = vctx;
    struct tilt_search_result *res = x->res;
    struct march_state *st = x->st;
    x->cs->tilt = tilt;
    /* Continuing from the last solution pays only near the target: from a
     * faster flow the Newton iterates must stop part of the flowing layer and
     * overshoot across the yield surface, from a much slower one the
     * pseudo-time march oscillates and takes more steps than from rest
     * (docs/numerics/time-step.md).  Farther away the solve starts from rest,
     * as a fresh run would. */
    int from_last = res->solves > 0 && fabs(x->last_f) < 0.1;
    if (!from_last) {
        for (int c = 0; c < 3; c++)
            memset(st->field.velocity[c], 0, st->g.size * sizeof(double));
        memset(st->field.p_dyn, 0, st->g.size * sizeof(double));
    }
    char err[256];
    if (march_reforce(st, err, sizeof err) != 0) {
        snprintf(res->message, sizeof res->message, "tilt %.8g: %.200s", tilt, err);
        x->failed = 1;
        return NAN;
    }
    if (!from_last)
        st->residual0 = 0.0; /* the pseudo-time scale of a fresh start */
    enum run_status s = march_run(x->st, x->obs, x->obs_ctx);
    res->solves++;
    res->steps += x->st->step;
    res->tilt = tilt;
    res->flow_rate = x->spec->flow_rate(x->st);
    if (x->report)
        x->report(x->report_ctx, res->solves, tilt, res->flow_rate, x->st);
    if (s != STATUS_STEADY) {
        snprintf(res->message, sizeof res->message, "the solve at tilt %.8g ended %s: %.200s",
                 tilt, run_status_name(s), x->st->message);
        x->failed = 1;
        return NAN;
    }
    if (!(res->flow_rate > 0.0)) {
        snprintf(res->message, sizeof res->message,
                 "the solve at tilt %.8g has flow rate %.6g: no flow to compare", tilt,
                 res->flow_rate);
        x->failed = 1;
        return NAN;
    }
    if (res->solves <= 2)
        x->end_rate[res->solves - 1] = res->flow_rate;
    x->last_f = log(res->flow_rate / x->spec->target);
    return x->last_f;
}

static int close_enough(const struct search_ctx *x)
{
    return fabs(x->res->flow_rate / x->spec->target - 1.0) <= x->spec->tolerance;
}

int tilt_search_run(struct march_state *st, struct muflow_case *cs,
                    const struct tilt_search_spec *spec, march_observer obs, void *obs_ctx,
                    tilt_search_report report, void *report_ctx, struct tilt_search_result *res)
{
    memset(res, 0, sizeof *res);
    struct search_ctx x = {.st = st, .cs = cs, .spec = spec, .obs = obs, .obs_ctx = obs_ctx,
                           .report = report, .report_ctx = report_ctx, .res = res};
    gsl_function fn = {.function = misfit, .params = &x};
    gsl_root_fsolver *solver = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    if (!solver) {
        snprintf(res->message, sizeof res->message, "out of memory for the root finder");
        return -1;
    }
    /* errors come back as codes: the default handler would abort */
    gsl_error_handler_t *previous = gsl_set_error_handler_off();
    int rc = -1;
    /* gsl_root_fsolver_set solves at both ends of the bracket, lower first */
    int status = gsl_root_fsolver_set(solver, &fn, spec->tilt_min, spec->tilt_max);
    if (x.failed)
        goto done;
    if (status != GSL_SUCCESS) {
        snprintf(res->message, sizeof res->message,
                 "heap.flow_rate = %s is not between Q*(heap.tilt_min = %s) = %.6g and "
                 "Q*(heap.tilt_max = %s) = %.6g: widen the bracket",
                 num_text(spec->target).s, num_text(spec->tilt_min).s, x.end_rate[0],
                 num_text(spec->tilt_max).s, x.end_rate[1]);
        goto done;
    }
    rc = 0;
    while (!close_enough(&x)) {
        if (res->solves >= spec->max_solves) {
            snprintf(res->message, sizeof res->message,
                     "no tilt within tolerance %.1e after heap.max_solves = %d solves: "
                     "Q* %.8g against %.8g",
                     spec->tolerance, spec->max_solves, res->flow_rate, spec->target);
            break;
        }
        status = gsl_root_fsolver_iterate(solver);
        if (x.failed) {
            rc = -1;
            break;
        }
        if (status != GSL_SUCCESS) {
            snprintf(res->message, sizeof res->message, "root finder: %s",
                     gsl_strerror(status));
            break;
        }
        double lo = gsl_root_fsolver_x_lower(solver), hi = gsl_root_fsolver_x_upper(solver);
        if (!close_enough(&x) && hi - lo <= 1e-12 * fabs(hi)) {
            snprintf(res->message, sizeof res->message,
                     "the bracket closed at tilt %.12g with Q* %.8g against %.8g: the steady "
                     "solves are not accurate enough for heap.flow_rate_tolerance",
                     lo, res->flow_rate, spec->target);
            break;
        }
    }
    if (close_enough(&x)) {
        res->converged = 1;
        snprintf(res->message, sizeof res->message,
                 "tilt %.8g gives Q* %.8g (target %.8g, within %.1e) after %d steady solves",
                 res->tilt, res->flow_rate, spec->target, spec->tolerance, res->solves);
    }
done:
    gsl_set_error_handler(previous);
    gsl_root_fsolver_free(solver);
    return rc;
}
