/* Scene "bagnold": steady flow of a granular layer of height H down a rough
 * plane tilted by alpha (seeds/000 sec. 3.2, app. B; cases/bagnold.ini).
 * Periodic along the flow, no slip at the base, flat stress-free surface.
 *
 * Exact solution (eqs. 18-19, 30-32): mu(I) = tan(alpha) everywhere, so
 * I = I_a is fixed, p = rho g cos(alpha) (H - z) and du/dz = I_a sqrt(p /
 * rho_s) / d; steady flow exists for mu_s < tan(alpha) < mu_s + dmu only
 * (jop curve).  With rheology.curve = barker_gray the same holds with I_a
 * from that curve, which has no static yield: every tilt flows. */
#include <math.h>
#include "diagnostics/profile.h"
#include "scenes/scene.h"
#include "scene_common.h"

static double bagnold_u(const struct muflow_case *cs, double z)
{
    const struct rheology *r = &cs->rheo;
    double ta = tan(cs->tilt);
    double ia;
    if (r->curve == CURVE_JOP) {
        if (ta <= r->mu_s)
            return 0.0;
        if (ta >= r->mu_s + r->delta_mu)
            return NAN;
        ia = r->i0 * (ta - r->mu_s) / (r->mu_s + r->delta_mu - ta);
    } else {
        /* any curve: the I at which it reaches tan(alpha) */
        ia = rheology_i_of_mu(r, ta);
    }
    double H = cs->len[2];
    double k = cs->density * cs->gravity * cos(cs->tilt);
    double depth = H - z;
    return (2.0 / 3.0) * ia * shear_per_sqrt_p(r) * sqrt(k) * (H * sqrt(H) - depth * sqrt(depth));
}

POINTWISE_PROFILE(exact_profile, bagnold_u)

/* Surface velocity from the two top nodes.  Near a free surface p grows
 * linearly with depth and, at fixed friction, the shear rate as
 * sqrt(depth): u = U - C depth^(3/2) is the local form, so the two nodes at
 * depths h/2 and 3h/2 give U. */
static double surface_velocity(const struct profile *pr, double H)
{
    if (pr->n < 2)
        return pr->velocity[pr->n - 1];
    double d1 = H - pr->coord[pr->n - 1], d2 = H - pr->coord[pr->n - 2];
    double u1 = pr->velocity[pr->n - 1], u2 = pr->velocity[pr->n - 2];
    double c = (u1 - u2) / (d2 * sqrt(d2) - d1 * sqrt(d1));
    return u1 + c * d1 * sqrt(d1);
}

static void errors(const struct march_state *st, const struct profile *pr, struct scene_errors *e)
{
    const struct muflow_case *cs = st->cs;
    profile_errors_default(pr, bagnold_u(cs, cs->len[2]), e);
    e->headline = surface_velocity(pr, cs->len[2]);
}

const struct scene scene_bagnold = {
    .name = "bagnold",
    .title = "granular layer down a rough inclined plane (Bagnold profile)",
    .profile_axis = 2,
    .profile_component = 0,
    .exact_profile = exact_profile,
    .headline_name = "u_surface",
    .errors = errors,
};
