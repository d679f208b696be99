/* Small pieces shared by the scene files (internal to src/scenes/). */
#ifndef MUFLOW_SCENES_COMMON_H
#define MUFLOW_SCENES_COMMON_H

#include <math.h>
#include "config/case.h"

/* sqrt(p / rho_s) / d per unit sqrt(p): the shear rate at I = 1 is
 * sqrt(p) * this. */
static inline double shear_per_sqrt_p(const struct rheology *r)
{
    return 1.0 / (r->grain_diameter * sqrt(r->grain_density));
}

/* u[i] = f(cs, x[i]) for a pointwise exact profile. */
#define POINTWISE_PROFILE(name, f)                                                       \
    static void name(const struct muflow_case *cs, int n, const double *x, double *u)   \
    {                                                                                    \
        for (int i = 0; i < n; i++)                                                      \
            u[i] = f(cs, x[i]);                                                          \
    }

#endif
