/* The tilt that gives a target flow rate: a bracketing root finder (GSL's
 * Brent solver) around full steady solves; once a solve's flow rate is within
 * 10% of the target the next continues from its solution (march_reforce).  It solves ln(Q*(tilt) / target) = 0: the flow
 * rate grows roughly exponentially with the tilt, so the logarithm is close
 * to linear and the interpolation steps of Brent's method land well. */
#ifndef MUFLOW_TILT_SEARCH_H
#define MUFLOW_TILT_SEARCH_H

#include "march/march.h"

struct tilt_search_result {
    int searched;          /* a search took place (set by its caller) */
    int converged;         /* |Q* / target - 1| <= tolerance at the final solve */
    double tilt;           /* of the final solve (the state st holds) */
    double flow_rate;      /* Q* of the final solve */
    int solves;            /* steady solves, the two bracket ends included */
    long steps;            /* pseudo-time steps over all solves */
    char message[256];     /* why the search ended */
};

/* Called after every steady solve (for progress lines). */
typedef void (*tilt_search_report)(void *ctx, int solve, double tilt, double flow_rate,
                                   const struct march_state *st);

struct tilt_search_spec {
    double target;         /* Q* wanted */
    double tilt_min, tilt_max; /* bracket: Q*(tilt_min) < target < Q*(tilt_max) */
    double tolerance;      /* relative, on Q* */
    int max_solves;
    double (*flow_rate)(const struct march_state *st); /* Q* of a state */
};

/* Runs the search on st, whose case *cs is (st->cs == cs) and whose tilt it
 * sets before each solve.  obs / obs_ctx observe every step of every solve
 * (march_run); a non-zero return stops the search.  Returns 0 when the search
 * ran (converged or not: see res), -1 when a solve failed or the target is not
 * bracketed (res->message says which). */
int tilt_search_run(struct march_state *st, struct muflow_case *cs,
                    const struct tilt_search_spec *spec, march_observer obs, void *obs_ctx,
                    tilt_search_report report, void *report_ctx, struct tilt_search_result *res);

#endif
