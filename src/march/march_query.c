/* What the march's loop, its stages and its modules ask of its state
 * (march.h): the scales residuals are measured against, whether a step
 * takes the tangent, the driven component, a module's state. */
#include <math.h>
#include "march/march.h"
#include "march/step.h"

double march_picard_reference(const struct march_state *st)
{
    double r0 = st->stage_residual0 > 0.0 ? st->stage_residual0 : st->residual0;
    return fmax(r0, st->peak_residual);
}

int implicit_uses_tangent(const struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    return cs->newton && cs->mode == MODE_STEADY &&
           (cs->newton_below >= 1.0 || st->picard_stalled ||
            st->residual <= cs->newton_below * march_picard_reference(st));
}

void *march_module_state(const struct march_state *st, const struct module *m)
{
    for (int i = 0; i < st->nmodules; i++)
        if (st->modules[i] == m)
            return st->module_state[i];
    return NULL;
}

double march_force_scale(const struct march_state *st)
{
    return st->force_ref > 0.0 ? st->force_ref : 1.0;
}

double march_min_spacing(const struct grid *g)
{
    double h = grid_min_width(g, 0);
    for (int d = 1; d < 3; d++) {
        double w = grid_min_width(g, d);
        if (g->n[d] > 1 && w < h)
            h = w;
    }
    return h;
}

int march_driven_component(const struct march_state *st)
{
    double f[3];
    body_force_vector(st->cs, f);
    int a = fabs(f[0]) >= fabs(f[2]) ? 0 : 2;
    if (!bc_through_flow(&st->bc, a))
        a = a == 0 ? 2 : 0;
    return a;
}

double march_mean_acceleration(const struct march_state *st)
{
    /* mean residual per unit mass of the component the body force drives */
    int a = march_driven_component(st);
    return kernel_component_mean(&st->g, &st->act[a], a, st->field.residual[a]) / st->cs->density;
}
