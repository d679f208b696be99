/* Scene "chute": vertical chute flow between rough plates at y = 0 and b,
 * periodic along the flow, under a confining pressure (Chauchat &
 * Medale 2014, sec. 3.1, app. A; cases/chute.ini).
 *
 * Exact solution (eqs. 17, 20-27): shear stress k |y - b/2| (k = rho g),
 * pressure p constant, plug where k |Y| < mu_s p.  With A = (mu_s + dmu) p,
 * I = I0 (k Y - mu_s p) / (A - k Y) integrates in closed form.  Headline:
 * the plug velocity. */
#include <math.h>
#include <stdio.h>
#include "diagnostics/profile.h"
#include "scenes/scene.h"
#include "scene_common.h"

static double chute_u(const struct muflow_case *cs, double y)
{
    const struct rheology *r = &cs->rheo;
    double p = cs->confining_pressure;
    double k = cs->density * cs->gravity * cos(cs->tilt);
    double half = 0.5 * cs->len[1];
    double Y = fabs(y - half);
    double y0 = r->mu_s * p / k;
    double A = (r->mu_s + r->delta_mu) * p;
    if (y0 >= half)
        return 0.0;
    if (A - k * half <= 0.0)
        return NAN; /* the wall stress exceeds the largest friction */
    if (Y < y0)
        Y = y0;
    double bracket = (Y - half) + (r->delta_mu * p / k) * log((A - k * Y) / (A - k * half));
    return -r->i0 * sqrt(p) * shear_per_sqrt_p(r) * bracket;
}

POINTWISE_PROFILE(exact_profile, chute_u)

/* The closed form integrates the jop curve (a plug where k |Y| < mu_s p);
 * another curve would need its own profile. */
static int check(const struct muflow_case *c, char *msg, size_t msglen)
{
    if (c->rheo.law == LAW_MUI && c->rheo.curve != CURVE_JOP) {
        snprintf(msg, msglen,
                 "case.scene = chute needs rheology.curve = jop: its exact profile is that "
                 "curve's (rheology.curve = %s)",
                 rheology_curve_name(c->rheo.curve));
        return 1;
    }
    return 0;
}

const struct scene scene_chute = {
    .name = "chute",
    .check = check,
    .title = "vertical chute between rough plates under a confining pressure",
    /* the periodic x and z (the flow) split over ranks, the y lines between
     * the plates whole (the profile's and the line blocks') */
    .decomposed = scene_decomposed_always,
    .profile_axis = 1,
    .profile_component = 2,
    .exact_profile = exact_profile,
    .headline_name = "u_plug",
};
