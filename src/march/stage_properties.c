/* Stage 1, properties: strain rates, the total and the regularised pressure,
 * the viscosity of every stress where it lives and its tangent (step.h). */
#include "march/step.h"

void stage_properties(struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    const struct grid *g = &st->g;
    bc_fill_velocity(g, &st->bc, st->field.velocity);
    kernel_strain(g, st->field.velocity, st->field.strain_normal2, st->field.strain_shear2);
    bc_fill_scalar(g, &st->bc, st->field.strain_normal2);
    for (size_t p = 0; p < g->size; p++)
        st->field.pressure[p] =
            cs->confining_pressure + st->pressure_gauge + st->field.p_hyd[p] + st->field.p_dyn[p];
    bc_fill_scalar_linear(g, &st->bc, st->field.pressure);
    kernel_viscosity_cells(g, &st->rheo, st->field.velocity, st->field.strain_normal2,
                           st->field.strain_shear2, st->field.pressure, st->field.viscosity,
                           cs->newton ? st->field.tangent_cells : NULL, st->field.shear2,
                           st->field.pressure_regularised, st->b_c);
    /* periodic directions this grid holds whole (not split over ranks: there
     * face n is the next rank's face 0, evaluated from the exchanged ghosts) */
    int wraps = 0;
    for (int d = 0; d < 3; d++)
        if (st->bc.face[d][0] == BC_PERIODIC && !bc_split(&st->bc, d))
            wraps |= 1 << d;
    kernel_viscosity_edges(g, &st->rheo, st->field.strain_normal2, st->field.strain_shear2,
                           st->field.pressure, st->field.viscosity_edges,
                           cs->newton ? st->field.tangent_edges : NULL,
                           st->full_tangent ? st->b_e : NULL, wraps);
    bc_fill_scalar(g, &st->bc, st->field.viscosity);
    if (cs->newton)
        for (int a = 0; a < 3; a++)
            bc_fill_scalar(g, &st->bc, st->field.tangent_cells[a]);
}
