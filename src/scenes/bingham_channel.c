/* Scene "bingham_channel": plane Poiseuille flow of a Bingham fluid between
 * walls at z = 0 and H, driven by the body force G along x (Chauchat &
 * Medale 2010, sec. 3.1.1; cases/bingham_channel.ini).
 *
 * Exact solution: |tau| = G |Y| with Y = z - H/2, plug where G |Y| < tau_0,
 * i.e. |Y| < y0 = tau_0 / G, and outside it
 * u = (G / (2 mu_p)) (H/2 - |Y|) (H/2 + |Y| - 2 y0).  Headline: the plug. */
#include <math.h>
#include "scenes/scene.h"
#include "scene_common.h"

static double channel_u(const struct muflow_case *cs, double z)
{
    const struct rheology *r = &cs->rheo;
    double G = cs->density * cs->gravity * sin(cs->tilt);
    double a = 0.5 * cs->len[2], Y = fabs(z - a);
    double y0 = r->yield_stress / fabs(G);
    if (y0 >= a)
        return 0.0;
    if (Y < y0)
        Y = y0;
    return copysign(1.0, G) * (fabs(G) / (2.0 * r->plastic_viscosity)) * (a - Y) * (a + Y - 2.0 * y0);
}

POINTWISE_PROFILE(exact_profile, channel_u)

const struct scene scene_bingham_channel = {
    .name = "bingham_channel",
    .title = "Bingham plane Poiseuille flow (plug-flow profile)",
    /* the periodic x and y split over ranks: the law is pointwise, the profile
     * and its plug summed over them (profile.c) */
    .decomposed = scene_decomposed_always,
    .profile_axis = 2,
    .profile_component = 0,
    .exact_profile = exact_profile,
    .headline_name = "u_plug",
};
