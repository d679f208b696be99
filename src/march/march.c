/* The time loop (see march.h): the steps, their acceptance or rejection,
 * the stages of a continuation; the end of a run is end_check.c's. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include "march_internal.h"

#include "march/step.h"

/* A steady-mode step that multiplies the residual by more than this is
 * rejected and retried with a ten times smaller pseudo-time step: a linearised
 * step far from the solution can overshoot into spurious states. */
#define REJECT_GROWTH 2.0
/* ... and only when its root mean square grew as much too: the maximum alone
 * sits where the plug forms (or at the lid's corners) and doubles on Newton
 * steps that reduce the residual elsewhere.  Only in solves that start with
 * Picard steps (solver.newton_below < 1); solves with the tangent from the
 * start keep the plain test (docs/numerics/steady-criterion.md). */
/* Picard steps (solver.newton_below < 1) that make no 10% progress of the
 * best residual in PICARD_STALL steps hand over to the tangent before the
 * residual has fallen newton_below-fold, */
#define PICARD_STALL 10
/* but no earlier than at the geometric mean of the start and newton_below
 * (a 10-fold drop for 1e-2): a tangent from a Picard state stalled far above
 * it let the residual grow (docs/numerics/steady-criterion.md). */
/* In Picard-first solves the maximum may double with the RMS, but not grow
 * beyond this in one step. */
#define REJECT_MAX_GROWTH 10.0
#define MIN_DT_SCALE 1e-12
/* the retries' insensitivity to dt, and the round-off's share of the
 * residual, of the rule that takes a try at a steady state's round-off
 * (march_run) */
#define DT_BLIND 0.1
#define ROUNDOFF_SHARE 10.0

const char *run_status_name(enum run_status s)
{
    switch (s) {
    case STATUS_RUNNING: return "running";
    case STATUS_STEADY: return "steady";
    case STATUS_FINISHED: return "finished";
    case STATUS_UNSTEADY: return "unsteady";
    case STATUS_DIVERGED: return "diverged";
    case STATUS_STOPPED: return "stopped";
    }
    return "?";
}

int march_reforce(struct march_state *st, char *err, size_t errlen)
{
    if (hydrostatic_split(st, err, errlen) != 0)
        return -1;
    st->force_ref = 0.0; /* rho g may have changed */
    st->step = 0;
    st->time = 0.0;
    st->dt = st->cs->dt;
    st->bdf2_steps = 0; /* a new start: its first step is Euler's */
    /* residual0 is kept: it sets the pseudo-time step dt = dt0 r0 / r, and the
     * first residual of a continued solve is already small, so resetting it
     * would hold dt near dt0 and march through the physical transient
     * (docs/numerics/time-step.md) */
    st->rejected = 0;
    march_forget_progress(st);
    st->sane_velocity = 0.0; /* a new forcing: a new velocity scale */
    st->mark_time = 0.0;
    st->marks = 0;
    st->dt_scale = 1.0;
    st->forcing = st->forcing_rms = 0.0; /* the step count starts again */
    st->wall_seconds = 0.0;
    st->status = STATUS_RUNNING;
    st->message[0] = '\0';
    return 0;
}

void march_evaluate(struct march_state *st) { step_evaluate(st); }

void march_apply_tangent(struct march_state *st, double *v[3], double *out[3])
{
    struct viscous_problem pb = implicit_problem(st, 0.0);
    viscous_apply(st->viscous, &pb, v, out);
}

/* Continuation in the regularisation (solver.continuation): a stage ends
 * when its residual has fallen STAGE_DROP-fold (or it is steady), and lambda
 * is lowered LAMBDA_STEP-fold, down to the case's. */
#define STAGE_DROP 1e-3
#define LAMBDA_STEP 10.0

static void next_stages(struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    while (march_continuing(st) && isfinite(st->residual) &&
           (st->residual <= STAGE_DROP * st->stage_residual0 ||
            (st->residual_excess <= cs->tolerance && st->divergence <= cs->tolerance))) {
        st->rheo.lambda = fmax(cs->rheo.lambda, st->rheo.lambda / LAMBDA_STEP);
        step_evaluate(st);
        st->stage_residual0 = st->residual;
        /* A start already steady at the stages above (solver.initial_state
         * from a solve at a larger lambda) left residual0 at that state's
         * round-off, which would hold the pseudo-time step dt0 r0 / r at dt0
         * for good: nothing marched yet, so the scale is this stage's. */
        if (st->step == 0)
            st->residual0 = st->residual;
        march_forget_progress(st);
        st->dt_scale = 1.0;
        st->picard_stalled = 0;
    }
}

/* A tangent step of a Picard-first steady solve (solver.newton_below < 1)
 * that raised both the maximum and the root mean square of the residual is
 * shortened: the state moves back along the step, halving it up to
 * LINE_SEARCH_HALVINGS times, until the root mean square has fallen by the
 * Armijo fraction of the step taken.  The pseudo-time step's cut (a
 * rejection) needs a new factorisation per try and leaves the tangent steps
 * crawling far from the solution; a shorter step along the same direction
 * costs one residual evaluation.  When no length descends, the full
 * step is taken again and judged as before (the tangent direction of the
 * split step is no descent direction there, and a lagged-viscosity step in
 * its place stalled: docs/numerics/steady-criterion.md). */
#define LINE_SEARCH_HALVINGS 5
#define ARMIJO_FRACTION 1e-4

static int line_search(struct march_state *st, double dt, double rms0)
{
    double alpha = 1.0;
    for (int k = 0; k < LINE_SEARCH_HALVINGS; k++) {
        fields_blend(&st->fields, 0.5);
        alpha *= 0.5;
        step_evaluate(st);
        if (st->residual_rms <= (1.0 - ARMIJO_FRACTION * alpha) * rms0)
            return 0;
    }
    march_restore_good(st);
    if (step_advance(st, dt) != 0)
        return -1;
    step_evaluate(st);
    return 0;
}

/* Whether a module asks for the line search (module.h: line_search). */
static int module_searches(const struct march_state *st)
{
    for (int m = 0; m < st->nmodules; m++)
        if (st->modules[m]->line_search &&
            st->modules[m]->line_search(st, st->module_state[m]))
            return 1;
    return 0;
}

/* The steps that take the line search and the rejection on the maximum and
 * the root mean square together: those of a Picard-first solve, and those of
 * a continuation stage above the case's lambda (solver.continuation), whose
 * state only has to be close enough to start the next stage: in the stages
 * the plain rejection crawled, the first tangent steps after each tenfold
 * lowering cut to small pseudo-time steps.  The final stage, and solves
 * without continuation, keep the plain rejection: with the search a
 * continuation in the forcing stalled where the plain march's crawl reaches
 * the steady state.  But a module may ask for the search (module.h:
 * line_search; a held mean velocity, whose plug's speed the border fixes):
 * there the plain rejection crawled on the maximum at the sliding layers
 * while the root mean square fell (docs/numerics/steady-criterion.md). */
static int searched_steps(const struct march_state *st)
{
    return st->cs->newton_below < 1.0 || march_continuing(st) || module_searches(st);
}

/* st->step_halo and step_collectives: the tallies' growth since halo0, coll0. */
static void record_step_traffic(struct march_state *st, const struct decomp_traffic *halo0,
                                const struct comm_traffic *coll0)
{
    struct decomp_traffic h;
    struct comm_traffic c;
    decomp_traffic_read(&h);
    decomp_collectives_read(&c);
    st->step_halo = (struct decomp_traffic){
        h.exchanges - halo0->exchanges, h.messages - halo0->messages, h.bytes - halo0->bytes,
        h.gathers - halo0->gathers, h.gather_sent - halo0->gather_sent,
        h.gather_received - halo0->gather_received};
    st->step_collectives = (struct comm_traffic){
        c.reductions - coll0->reductions, c.reduced_values - coll0->reduced_values,
        c.alltoalls - coll0->alltoalls, c.alltoall_messages - coll0->alltoall_messages,
        c.alltoall_bytes - coll0->alltoall_bytes, c.fft_executions - coll0->fft_executions};
}

enum run_status march_run(struct march_state *st, march_observer obs, void *ctx)
{
    const struct muflow_case *cs = st->cs;
    double t0 = omp_get_wtime() - st->wall_seconds; /* a restart keeps counting */
    st->status = STATUS_RUNNING;
    march_save_good(st);
    step_evaluate(st);
    if (st->step == 0 && st->residual0 == 0.0) /* march_reforce keeps it: below */
        st->residual0 = st->residual;
    if (st->stage_residual0 == 0.0)
        st->stage_residual0 = st->residual0;
    for (;;) {
        st->wall_seconds = omp_get_wtime() - t0;
        if (cs->mode == MODE_STEADY)
            next_stages(st);
        march_check_end(st);
        if (obs && obs(ctx, st) && st->status == STATUS_RUNNING) {
            st->status = STATUS_STOPPED;
            snprintf(st->message, sizeof st->message, "stopped at step %ld", st->step);
        }
        if (st->status != STATUS_RUNNING)
            break;
        march_save_good(st);
        if (st->residual < STALL_FACTOR * st->best_residual) {
            st->best_residual = st->residual;
            st->best_step = st->step;
            st->best_time = st->time;
        }
        st->recent_residual[st->step % MARCH_RECENT] = st->residual;
        st->peak_residual = fmax(st->peak_residual, st->residual);
        if (march_sane(st))
            st->sane_velocity = fmax(st->sane_velocity, st->velocity_max);
        /* Picard steps that make no 10% progress in PICARD_STALL steps: the
         * tangent takes over before the residual has fallen newton_below-fold */
        if (cs->mode == MODE_STEADY && cs->newton && cs->newton_below < 1.0 &&
            st->step - st->best_step >= PICARD_STALL && march_fell_over(st, PICARD_STALL) != 1 &&
            st->residual <= sqrt(cs->newton_below) * march_picard_reference(st))
            st->picard_stalled = 1;
        double accepted_residual = st->residual, accepted_rms = st->residual_rms, dt;
        double last_try = NAN; /* the residual the last rejected try reached */
        /* the accepted state's residual is mostly its own round-off */
        int at_roundoff = cs->mode == MODE_STEADY && !march_continuing(st) &&
                          st->residual - st->residual_excess >= st->residual / ROUNDOFF_SHARE;
        for (;;) {
            dt = march_choose_dt(st) * st->dt_scale;
            int newton_step = implicit_uses_tangent(st); /* steady mode only */
            st->step_error[0] = '\0';
            struct decomp_traffic halo0;
            struct comm_traffic coll0;
            decomp_traffic_read(&halo0);
            decomp_collectives_read(&coll0);
            int broke = step_advance(st, dt) != 0;
            if (!broke)
                step_evaluate(st);
            record_step_traffic(st, &halo0, &coll0);
            int searched = searched_steps(st);
            if (!broke && newton_step && searched &&
                isfinite(st->residual) && st->residual_rms > accepted_rms &&
                st->residual > accepted_residual)
                broke = line_search(st, dt, accepted_rms) != 0;
            int bad = broke || !isfinite(st->residual) ||
                      (cs->mode == MODE_STEADY && st->residual > REJECT_GROWTH * accepted_residual &&
                        (!searched ||
                         st->residual_rms > REJECT_GROWTH * accepted_rms ||
                         st->residual > REJECT_MAX_GROWTH * accepted_residual));
            /* At the round-off of a steady state, a growth that a tenfold
             * shorter step leaves as it was (within DT_BLIND) does not come
             * from the step's length, and shorter ones do not cure it: the
             * try is taken, and the pseudo-time step comes back in a few
             * doublings instead of some thirty from MIN_DT_SCALE.  Far from
             * the solution (the stages) the same rule let the residual grow:
             * so only at round-off (docs/numerics/steady-criterion.md). */
            int dt_blind = at_roundoff && bad && !broke && isfinite(st->residual) &&
                           isfinite(last_try) && fabs(st->residual - last_try) <= DT_BLIND * last_try;
            if (!bad || cs->mode != MODE_STEADY || st->dt_scale < MIN_DT_SCALE || dt_blind) {
                if (broke) { /* nothing usable: end with the last finite state */
                    march_restore_good(st);
                    st->status = STATUS_DIVERGED;
                    snprintf(st->message, sizeof st->message,
                             "step %ld broke down (%.150s); the last finite state is kept",
                             st->step,
                             st->step_error[0] ? st->step_error : "the implicit viscous solve");
                }
                break;
            }
            last_try = broke ? NAN : st->residual;
            march_restore_good(st);
            st->dt_scale *= 0.1;
            st->rejected++;
        }
        if (st->status == STATUS_DIVERGED) {
            st->wall_seconds = omp_get_wtime() - t0;
            if (obs)
                obs(ctx, st);
            break;
        }
        st->dt_scale = fmin(1.0, 2.0 * st->dt_scale);
        st->dt = dt;
        st->time += dt;
        st->step++;
    }
    st->wall_seconds = omp_get_wtime() - t0;
    return st->status;
}
