/* Stage 1, properties: strain rates, the total and the regularised pressure,
 * the viscosity of every stress where it lives and its tangent (step.h). */
#include "march/step.h"

void stage_properties(struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    const struct grid *g = &st->g;
    bc_fill_velocity(g, &st->bc, st->vel);
    kernel_strain(g, st->vel, st->cn2, st->e2);
    bc_fill_scalar(g, &st->bc, st->cn2);
    for (size_t p = 0; p < g->size; p++)
        st->pressure[p] =
            cs->confining_pressure + st->pressure_gauge + st->p_hyd[p] + st->p_dyn[p];
    bc_fill_scalar_linear(g, &st->bc, st->pressure);
    kernel_viscosity_cells(g, &st->rheo, st->vel, st->cn2, st->e2, st->pressure, st->eta,
                           cs->newton ? st->tan_c : NULL, st->shear2, st->preg, st->b_c);
    /* periodic directions: this grid holds each whole (one process) */
    int wraps = 0;
    for (int d = 0; d < 3; d++)
        if (st->bc.face[d][0] == BC_PERIODIC)
            wraps |= 1 << d;
    kernel_viscosity_edges(g, &st->rheo, st->cn2, st->e2, st->pressure, st->eta_e,
                           cs->newton ? st->tan_e : NULL, st->full_tangent ? st->b_e : NULL,
                           wraps);
    bc_fill_scalar(g, &st->bc, st->eta);
    if (cs->newton)
        for (int a = 0; a < 3; a++)
            bc_fill_scalar(g, &st->bc, st->tan_c[a]);
}
