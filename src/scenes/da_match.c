/* The depth-averaged model matched to a case's mu(I) (scenes/da_match.h). */
#include <math.h>
#include "scenes/da_match.h"

struct da_params da_params_matched(const struct muflow_case *cs)
{
    const struct rheology *r = &cs->rheo;
    struct da_params p = da_params_default();
    p.g = cs->gravity;
    p.law = DA_POULIQUEN;
    p.mu1 = r->mu_s;
    p.mu2 = r->mu_s + r->delta_mu;
    p.beta = 1.0;
    p.L = r->grain_diameter / (0.4 * r->i0 * sqrt(r->phi));
    return p;
}
