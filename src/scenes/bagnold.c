/* Scene "bagnold": steady flow of a granular layer of height H down a rough
 * plane tilted by alpha (Chauchat & Medale 2014,
 * "A three-dimensional numerical model for dense granular flows based on the
 * mu(I) rheology", sec. 3.2, app. B; cases/bagnold.ini).
 * Periodic along the flow, no slip at the base, flat stress-free surface.
 *
 * Exact solution (eqs. 18-19, 30-32): mu(I) = tan(alpha) everywhere, so
 * I = I_a is fixed, p = rho g cos(alpha) (H - z) and du/dz = I_a sqrt(p /
 * rho_s) / d; steady flow exists for mu_s < tan(alpha) < mu_s + dmu only
 * (jop curve).  With rheology.curve = barker_gray the same holds with I_a
 * from that curve, which has no static yield: every tilt flows.  With
 * rheology.law = ngf (physics/ngf.h) there is no closed form (the profile
 * is NaN): a layer thinner than the stopping height stops
 * (docs/validation/ngf.md).
 *
 * bagnold.perturbation starts the run from rest plus a divergence-free 3D
 * velocity (scenes/perturbation.h): the steady state must still be the
 * uniform profile, reached through a flow that varies in x, y and z. */
#include <math.h>
#include <stdio.h>
#include "diagnostics/profile.h"
#include "march/march.h"
#include "scenes/perturbation.h"
#include "scenes/scene.h"
#include "scene_common.h"

struct bagnold_params {
    double perturbation;       /* of the initial velocity, relative to u(H) */
};

#define T struct bagnold_params
static const struct key bagnold_keys[] = {
    KEY_DBL(T, "bagnold", "perturbation", perturbation,
            KEY_HELP("largest velocity of a divergence-free 3D perturbation of the state at rest "
                     "(the curl of a pseudo-random vector potential times sin^2(pi z / H)), "
                     "relative to the exact surface velocity; 0: none",
                     NULL,
                     "Largest face velocity of a divergence-free 3D perturbation of the initial "
                     "state at rest, relative to the exact surface velocity u(H): the discrete "
                     "curl of a vector potential on the edges (a pseudo-random deviate per edge, "
                     "the same on any number of threads, times sin^2(pi z / H)), so div u = 0 "
                     "cell by cell to round-off and w = 0 on the base and the surface. Needs "
                     "periodic x and y and a tilt that flows; `0`: none (rest)"),
            KEY_RANGE(0.0, 1.0, 1, 1)),
};
#undef T

static void defaults(void *block)
{
    struct bagnold_params *b = block;
    b->perturbation = 0.0;
}

SCENE_PARAMS(bagnold_block, "bagnold",
             "The granular layer down an incline (`cases/bagnold.ini`, `cases/bagnold3d.ini`).",
             struct bagnold_params, bagnold_keys, defaults)

static double bagnold_u(const struct muflow_case *cs, double z)
{
    const struct rheology *r = &cs->rheo;
    if (r->law == LAW_NGF)
        return NAN; /* the nonlocal fluidity's profile has no closed form */
    /* a negative tilt is the mirror image: |tan| sets I, the sign the flow */
    double ta = fabs(tan(cs->tilt));
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
    return copysign(1.0, cs->tilt) * (2.0 / 3.0) * ia * shear_per_sqrt_p(r) * sqrt(k) *
           (H * sqrt(H) - depth * sqrt(depth));
}

POINTWISE_PROFILE(exact_profile, bagnold_u)

/* The perturbation's potential wraps along x and y, and its scale is the
 * exact surface velocity: periodic x and y and a tilt that flows. */
static int check(const struct muflow_case *c, char *msg, size_t msglen)
{
    if (!(params(c)->perturbation > 0.0))
        return 0;
    if (c->bc.face[0][0] != BC_PERIODIC || c->bc.face[1][0] != BC_PERIODIC) {
        snprintf(msg, msglen, "bagnold.perturbation > 0 needs boundary.xlo, boundary.xhi, "
                              "boundary.ylo and boundary.yhi = periodic (the perturbation wraps "
                              "along x and y)");
        return 1;
    }
    double top = bagnold_u(c, c->len[2]);
    if (!(isfinite(top) && top != 0.0)) {
        snprintf(msg, msglen,
                 "bagnold.perturbation > 0 is relative to the exact surface velocity, which "
                 "physics.tilt = %s (tan %.6g) does not have with this rheology.curve (jop: "
                 "tan between rheology.mu_s and rheology.mu_s + rheology.delta_mu)",
                 num_text(c->tilt).s, tan(c->tilt));
        return 1;
    }
    return 0;
}

/* Rest plus the perturbation, which vanishes on the base and the surface
 * nodes (w = 0 there, as both conditions require). */
static int setup(struct march_state *st, char *err, size_t errlen)
{
    (void)err;
    (void)errlen;
    const struct muflow_case *cs = st->cs;
    double p = params(cs)->perturbation;
    if (p > 0.0)
        perturbation_add(st, PERTURB_3D, cs->len[2], p * bagnold_u(cs, cs->len[2]));
    return 0;
}

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
    .keys = &bagnold_block,
    .check = check,
    .setup = setup,
    /* periodic x and y split over ranks; the perturbation drawn by the global
     * index (perturbation.c), the nonlocal fluidity on the unsplit z lines */
    .decomposed = scene_decomposed_always,
    .profile_axis = 2,
    .profile_component = 0,
    .exact_profile = exact_profile,
    .headline_name = "u_surface",
    .errors = errors,
};
