/* The loop's state between steps (march_internal.h): the progress of a
 * problem, the last accepted state, the step size, the stage of a
 * continuation. */
#include <math.h>
#include "march_internal.h"

#include "march/step.h"

/* A new problem (a start, a stage of the continuation, a new forcing): its
 * progress is measured afresh. */
void march_forget_progress(struct march_state *st)
{
    st->best_residual = INFINITY;
    st->best_step = st->step;
    st->best_time = st->time;
    for (int k = 0; k < MARCH_RECENT; k++)
        st->recent_residual[k] = NAN;
    st->peak_residual = 0.0;
}

/* Whether a residual of the last `steps` steps (the current one included) is
 * 10% below the one `steps` steps ago; -1 when that one was not recorded. */
int march_fell_over(const struct march_state *st, long steps)
{
    if (st->step < steps)
        return -1;
    double start = st->recent_residual[(st->step - steps) % MARCH_RECENT];
    if (!(start > 0.0))
        return -1;
    if (st->residual < STALL_FACTOR * start)
        return 1;
    for (long k = st->step - steps + 1; k < st->step; k++)
        if (st->recent_residual[k % MARCH_RECENT] < STALL_FACTOR * start)
            return 1;
    return 0;
}

/* The last accepted state as a whole: its fields, step, time and dt. */
void march_save_good(struct march_state *st)
{
    fields_save(&st->fields);
    st->good_step = st->step;
    st->good_time = st->time;
    st->good_dt = st->dt;
}

void march_restore_good(struct march_state *st)
{
    fields_restore(&st->fields);
    st->step = st->good_step;
    st->time = st->good_time;
    st->dt = st->good_dt;
    step_evaluate(st);
}

/* The advective limit of the step (infinite without advection). */
double march_cfl_dt(const struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    if (!cs->advection)
        return INFINITY;
    double umax = march_max(st, kernel_max_abs(&st->g, st->act, st->field.velocity));
    return umax > 0.0 ? cs->cfl * march_min_spacing(march_global_grid(st)) / umax : INFINITY;
}

double march_choose_dt(const struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    double dt;
    if (cs->mode == MODE_STEADY) {
        /* switched evolution relaxation: the step grows as the residual falls */
        dt = st->residual > 0.0 ? cs->dt * st->residual0 / st->residual : cs->dt_max;
        if (dt > cs->dt_max)
            dt = cs->dt_max;
        if (dt < cs->dt)
            dt = cs->dt;
    } else {
        dt = cs->dt;
        if (st->time + dt > cs->end_time)
            dt = cs->end_time - st->time;
    }
    double lim = march_cfl_dt(st);
    /* and the modules' own limits (a tracer's transport) */
    for (int m = 0; m < st->nmodules; m++)
        if (st->modules[m]->max_dt)
            lim = fmin(lim, st->modules[m]->max_dt(st, st->module_state[m]));
    return dt > lim ? lim : dt;
}

/* A continuation in the regularisation: the stage's lambda is above the
 * case's. */
int march_continuing(const struct march_state *st)
{
    return st->rheo.lambda > st->cs->rheo.lambda;
}

/* A residual within SANE_RESIDUAL times max(1, the start's): forces at most
 * ten times the weight (or the start's) in every face. */
int march_sane(const struct march_state *st)
{
    return st->residual <= SANE_RESIDUAL * fmax(1.0, st->residual0);
}
