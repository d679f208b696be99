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

double march_sum(const struct march_state *st, double v) { return decomp_sum(st->bc.dc, v); }

double march_max(const struct march_state *st, double v) { return decomp_max(st->bc.dc, v); }

void march_sum_array(const struct march_state *st, double *v, int n)
{
    decomp_sum_array(st->bc.dc, v, n);
}

void march_max_array(const struct march_state *st, double *v, int n)
{
    decomp_max_array(st->bc.dc, v, n);
}

const struct grid *march_global_grid(const struct march_state *st)
{
    return st->ranks ? &st->ranks->global : &st->g;
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

double march_component_mean(const struct march_state *st, int a, const double *f)
{
    double mean = kernel_component_mean(&st->g, &st->act[a], a, f);
    if (st->ranks) { /* the ranks' means weighted by their nodes */
        const struct box *b = &st->act[a];
        double w[2] = {(double)(b->hi[0] - b->lo[0]) * (b->hi[1] - b->lo[1]) * (b->hi[2] - b->lo[2])};
        w[1] = mean * w[0];
        march_sum_array(st, w, 2);
        mean = w[0] > 0.0 ? w[1] / w[0] : 0.0;
    }
    return mean;
}

double march_mean_acceleration(const struct march_state *st)
{
    /* mean residual per unit mass of the component the body force drives */
    int a = march_driven_component(st);
    return march_component_mean(st, a, st->field.residual[a]) / st->cs->density;
}
