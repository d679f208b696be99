/* The step's stages in order (step.h): the one place that says what a step
 * does, and where the physics modules come in. */
#include "march/step.h"

void step_evaluate(struct march_state *st)
{
    stage_properties(st);
    for (int m = 0; m < st->nmodules; m++)
        if (st->modules[m]->properties)
            st->modules[m]->properties(st, st->module_state[m]);
    stage_residual(st);
}

int step_advance(struct march_state *st, double dt)
{
    if (stage_implicit(st, dt) != 0)
        return -1;
    if (st->cs->coupled)
        stage_coupled_update(st);
    else
        stage_projection(st, dt);
    for (int m = 0; m < st->nmodules; m++)
        if (st->modules[m]->transport &&
            st->modules[m]->transport(st, st->module_state[m], dt) != 0)
            return -1;
    for (int m = 0; m < st->nmodules; m++)
        if (st->modules[m]->end_step)
            st->modules[m]->end_step(st, st->module_state[m], dt);
    return 0;
}
