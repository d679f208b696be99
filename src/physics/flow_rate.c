/* The prescribed mean velocity (physics/flow_rate.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "grid/boundary.h"
#include "kernels/embedded.h"
#include "kernels/kernels.h"
#include "march/fields.h"
#include "march/module.h"
#include "march/step.h"
#include "physics/flow_rate.h"

struct flow_rate {
    double *gravity;     /* the registry's cell field: g, uniform */
    double *unit[3];     /* the body force per unit g (st->field.force at g = 1) */
    double applied;      /* the g st->field.force holds */
    double target;       /* U*; 0 while idle (the force the case's) */
    double pending;      /* this step's increment of g */
    int a;               /* the driven component */
    double sign;         /* of the force along it */
};

static struct flow_rate *state_of(const struct march_state *st)
{
    return march_module_state(st, &flow_rate_module);
}

static double held_gravity(const struct march_state *st, const struct flow_rate *s)
{
    return s->gravity[grid_idx(&st->g, 0, 0, 0)];
}

/* st->field.force (computed at the case's gravity) as the force per unit g. */
static void take_unit_force(struct march_state *st, struct flow_rate *s)
{
    double g = st->cs->gravity;
    for (int c = 0; c < 3; c++)
        for (size_t p = 0; p < st->g.size; p++)
            s->unit[c][p] = st->field.force[c][p] / g;
    s->applied = g;
}

static int create(struct march_state *st, void **state, char *err, size_t errlen)
{
    struct flow_rate *s = calloc(1, sizeof *s);
    *state = s;
    int ok = s != NULL;
    for (int c = 0; ok && c < 3; c++)
        ok = (s->unit[c] = field_alloc(&st->g)) != NULL;
    const struct field_spec spec = {"driving_gravity", FIELD_CELLS,
                                    FIELD_CHECKPOINT | FIELD_SAVED | FIELD_START_OPTIONAL};
    double *v[3] = {NULL, NULL, NULL};
    if (!ok || fields_add(&st->fields, &spec, v) < 0) {
        snprintf(err, errlen, "out of memory for the prescribed mean velocity");
        return -1;
    }
    s->gravity = v[0];
    for (size_t p = 0; p < st->g.size; p++)
        s->gravity[p] = st->cs->gravity;
    return 0;
}

const char *flow_rate_refusal(const struct muflow_case *cs)
{
    if (cs->mode != MODE_STEADY || !cs->coupled)
        return "needs solver.mode = steady and solver.coupled = on (the force is an unknown of "
               "the coupled Newton step)";
    if (cs->preconditioner == PRECOND_AMG)
        return "needs the coupled step's LU: solver.preconditioner = lu or auto";
    if (cs->tilt != 0.0)
        return "needs physics.tilt = 0 (the force along z, with no hydrostatic part)";
    for (int d = 0; d < 3; d++)
        for (int e = 0; e < 2; e++)
            if (cs->bc.face[d][e] == BC_OPEN || cs->bc.face[d][e] == BC_INFLOW ||
                (d == 2 && cs->bc.face[d][e] != BC_PERIODIC))
                return "needs boundary.zlo = zhi = periodic and no open or inflow face (the "
                       "mean velocity is then the flow rate)";
    return NULL;
}

/* The force follows the held g, which a rejected step or the line search's
 * blend may have put back (the field is saved with the state). */
static void properties(struct march_state *st, void *state)
{
    struct flow_rate *s = state;
    if (s->target <= 0.0) /* idle: the force is the case's */
        return;
    double g = held_gravity(st, s);
    if (g == s->applied)
        return;
    for (int c = 0; c < 3; c++)
        for (size_t p = 0; p < st->g.size; p++)
            st->field.force[c][p] = g * s->unit[c][p];
    s->applied = g;
}

static void end_step(struct march_state *st, void *state, double dt)
{
    (void)dt;
    struct flow_rate *s = state;
    for (size_t p = 0; p < st->g.size; p++)
        s->gravity[p] += s->pending;
    s->pending = 0.0;
}

static void destroy(void *state)
{
    struct flow_rate *s = state;
    if (!s)
        return;
    for (int c = 0; c < 3; c++)
        field_free(s->unit[c]);
    free(s);
}

/* The module's hooks of the coupled step and the loop (march/module.h),
 * over the functions below. */
static int held(const struct march_state *st, void *state)
{
    (void)state;
    return flow_rate_held(st);
}

static int border_column(struct march_state *st, void *state, double *f[3], double *gap)
{
    (void)state;
    return flow_rate_border(st, f, gap);
}

static double border_row(const struct march_state *st, void *state, double *const u[3])
{
    (void)state;
    return flow_rate_mean(st, u);
}

static void border_increment(struct march_state *st, void *state, double dg)
{
    (void)state;
    flow_rate_increment(st, dg);
}

static const struct module_border border = {border_column, border_row, border_increment};

const struct module flow_rate_module = {
    .name = "flow_rate",
    .create = create,
    .properties = properties,
    .end_step = end_step,
    .destroy = destroy,
    .line_search = held,
    .border = &border,
    .coupled_ok = 1,
};

int flow_rate_held(const struct march_state *st)
{
    const struct flow_rate *s = state_of(st);
    return s && s->target > 0.0;
}

double flow_rate_gravity(const struct march_state *st)
{
    const struct flow_rate *s = state_of(st);
    return s ? held_gravity(st, s) : NAN;
}

int flow_rate_restart(struct march_state *st, double g, double U, char *err, size_t errlen)
{
    struct flow_rate *s = state_of(st);
    if (!s)
        return 0;
    const char *why = U > 0.0 ? flow_rate_refusal(st->cs) : NULL;
    if (why || (U > 0.0 && !(st->cs->gravity > 0.0))) {
        snprintf(err, errlen, "a prescribed mean velocity %s",
                 why ? why : "needs a start with gravity > 0 (the force per unit g)");
        return -1;
    }
    take_unit_force(st, s);
    for (size_t p = 0; p < st->g.size; p++)
        s->gravity[p] = g;
    s->target = U;
    s->pending = 0.0;
    if (U > 0.0) {
        double f[3];
        body_force_vector(st->cs, f);
        s->a = march_driven_component(st);
        s->sign = f[s->a] < 0.0 ? -1.0 : 1.0;
    }
    properties(st, s);
    return 0;
}

double flow_rate_mean(const struct march_state *st, double *const u[3])
{
    const struct flow_rate *s = state_of(st);
    /* over the ranks: the border's row is the whole domain's mean */
    return s && s->target > 0.0 ? s->sign * march_component_mean(st, s->a, u[s->a]) : NAN;
}

int flow_rate_border(struct march_state *st, double *f[3], double *gap)
{
    struct flow_rate *s = state_of(st);
    if (!s || s->target <= 0.0)
        return -1;
    for (int c = 0; c < 3; c++)
        memcpy(f[c], s->unit[c], st->g.size * sizeof(double));
    if (st->embedded) /* a body's held nodes have no residual (physics/obstacle.h) */
        embedded_zero(st->embedded, f);
    *gap = s->target - flow_rate_mean(st, st->field.velocity);
    return 0;
}

void flow_rate_increment(struct march_state *st, double dg)
{
    struct flow_rate *s = state_of(st);
    if (s)
        s->pending = dg;
}
