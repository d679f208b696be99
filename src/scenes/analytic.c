/* Analytic profiles: Bagnold flow down an incline and the vertical chute. */
#include <math.h>
#include "scenes/analytic.h"

const char *scene_name(enum scene s)
{
    switch (s) {
    case SCENE_NONE: return "none";
    case SCENE_BAGNOLD: return "bagnold";
    case SCENE_CHUTE: return "chute";
    case SCENE_BINGHAM_CHANNEL: return "bingham_channel";
    case SCENE_BINGHAM_CAVITY: return "bingham_cavity";
    case SCENE_HEAP: return "heap";
    }
    return "?";
}

const char *scene_headline_name(enum scene s)
{
    return s == SCENE_BAGNOLD ? "u_surface" : s == SCENE_CHUTE ? "u_plug"
         : s == SCENE_BINGHAM_CHANNEL ? "u_plug" : s == SCENE_BINGHAM_CAVITY ? "psi_max" : NULL;
}

const char *scene_error_name(enum scene s)
{
    return s == SCENE_BINGHAM_CAVITY ? "err_midline" : "err_rms";
}

int scene_profile_axes(enum scene s, int *axis, int *component)
{
    switch (s) {
    case SCENE_BAGNOLD: *axis = 2; *component = 0; return 0;
    case SCENE_CHUTE: *axis = 1; *component = 2; return 0;
    case SCENE_BINGHAM_CHANNEL:
    case SCENE_BINGHAM_CAVITY: *axis = 2; *component = 0; return 0;
    case SCENE_HEAP: /* a cross-section: heap.h */
    case SCENE_NONE: break;
    }
    return -1;
}

/* sqrt(p / rho_s) / d per unit sqrt(p): the shear rate at I = 1 is
 * sqrt(p) * this. */
static double shear_per_sqrt_p(const struct rheology *r)
{
    return 1.0 / (r->grain_diameter * sqrt(r->grain_density));
}

/* Bagnold (eqs. 18-19, 30-32): mu(I) = tan(alpha) everywhere, I = I_a fixed,
 * p = rho g cos(alpha) (H - z), du/dz = I_a sqrt(p / rho_s) / d. */
static double bagnold(const struct muflow_case *cs, double z)
{
    const struct rheology *r = &cs->rheo;
    double ta = tan(cs->tilt);
    if (ta <= r->mu_s)
        return 0.0;
    if (ta >= r->mu_s + r->delta_mu)
        return NAN;
    double ia = r->i0 * (ta - r->mu_s) / (r->mu_s + r->delta_mu - ta);
    double H = cs->len[2];
    double k = cs->density * cs->gravity * cos(cs->tilt);
    double depth = H - z;
    return (2.0 / 3.0) * ia * shear_per_sqrt_p(r) * sqrt(k) * (H * sqrt(H) - depth * sqrt(depth));
}

/* Chute (eqs. 17, 20-27): shear stress k |y| from the centre line (k = rho g),
 * pressure p constant, plug where k |y| < mu_s p.  With A = (mu_s + dmu) p,
 * I = I0 (k Y - mu_s p) / (A - k Y) integrates in closed form. */
static double chute(const struct muflow_case *cs, double y)
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

/* Bingham plane Poiseuille flow between walls at z = 0 and H, driven by the
 * body force G along x: |tau| = G |Y| with Y = z - H/2, plug where G |Y| <
 * tau_0, i.e. |Y| < y0 = tau_0 / G, and outside it
 * u = (G / (2 mu_p)) (H/2 - |Y|) (H/2 + |Y| - 2 y0). */
static double bingham_channel(const struct muflow_case *cs, double z)
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

double analytic_velocity(const struct muflow_case *cs, double x)
{
    switch (cs->scene) {
    case SCENE_BAGNOLD: return bagnold(cs, x);
    case SCENE_CHUTE: return chute(cs, x);
    case SCENE_BINGHAM_CHANNEL: return bingham_channel(cs, x);
    case SCENE_BINGHAM_CAVITY:
    case SCENE_HEAP:
    case SCENE_NONE: break;
    }
    return NAN;
}

double analytic_headline(const struct muflow_case *cs)
{
    switch (cs->scene) {
    case SCENE_BAGNOLD: return bagnold(cs, cs->len[2]);
    case SCENE_CHUTE: return chute(cs, 0.5 * cs->len[1]);
    case SCENE_BINGHAM_CHANNEL: return bingham_channel(cs, 0.5 * cs->len[2]);
    case SCENE_BINGHAM_CAVITY:
    case SCENE_HEAP:
    case SCENE_NONE: break;
    }
    return NAN;
}

double cavity_reference_bn(const struct muflow_case *cs)
{
    /* Bn = tau_0 L / (mu_p U) with L = lx, U the lid speed */
    double bn = cs->rheo.yield_stress * cs->len[0] /
                (cs->rheo.plastic_viscosity * fabs(cs->bc.lid_velocity));
    return sqrt(2.0) * bn;
}
