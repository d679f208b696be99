/* The march's pressure solvers (step.h): the projection's and the
 * hydrostatic split's, made alike. */
#include "march/step.h"

/* A pressure solver on the march's grid (over its ranks when decomposed),
 * with the case's choice of the whole-grid factorisation. */
int march_pressure_create(const struct march_state *st, struct pressure_solver **ps,
                          const enum poisson_bc bc[3][2], char *err, size_t errlen)
{
    if ((st->ranks ? pressure_create_decomposed(ps, &st->g, &st->ranks->global, &st->ranks->dc,
                                                bc, err, errlen)
                   : pressure_create(ps, &st->g, bc, err, errlen)) != 0)
        return -1;
    pressure_allow_direct(*ps, st->cs->pressure_factorisation);
    return 0;
}
