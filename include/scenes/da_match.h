/* The depth-averaged model (diagnostics/depth_averaged.h) matched to a
 * case's mu(I): the reference of the scenes on a slope (slope_release,
 * wall_shock). */
#ifndef MUFLOW_SCENES_DA_MATCH_H
#define MUFLOW_SCENES_DA_MATCH_H

#include "config/case.h"
#include "diagnostics/depth_averaged.h"

/* Pouliquen's law matched to the case's mu(I) through Bagnold's profile:
 * mu1 = mu_s, mu2 = mu_s + delta_mu, beta / L = (2/5) I0 sqrt(phi) / d,
 * whose steady uniform flow is the jop curve's (Gray & Edwards 2014; Barker
 * & Gray's above I_1^N); the case's gravity; chi 1, no viscous term. */
struct da_params da_params_matched(const struct muflow_case *cs);

#endif
