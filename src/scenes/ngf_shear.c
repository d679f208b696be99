/* Scene "ngf_shear": the nonlocal fluidity (rheology.law = ngf, physics/ngf.h)
 * in planar shear under gravity: a layer on a rough wall at z = 0 sheared by
 * a rough lid at z = H moving at U, gravity across the layer (physics.tilt =
 * 0), periodic along x and y (cases/ngf_shear.ini; one of the geometries of
 * Liu & Henann 2018, "Size-dependence of the flow threshold in dense
 * granular materials", for this model).
 *
 * The shear stress tau is uniform and the pressure grows with depth, so mu
 * = tau / p falls with depth: a shear band under the lid where mu > mu_s,
 * below it a layer the local law holds at rest, which the band's fluidity
 * makes creep.  There the fluidity is small, b I negligible against mu_s -
 * mu, and its equation linear with the base's g = 0:
 *   A^2 d^2 g'' = (mu_s - tau / p(z)) g,  g(0) = 0,  p(z) = p_top + rho g (H - z)
 * (Whittaker's equation in p; its solution through g(0) = 0 is the one
 * integrated here, to round-off).  The measure of the band's reach: the
 * fluidity's decay length 1 / (ln g)' at z = H / 4, with tau the measured
 * stress, against two references: that linear equation (the discretisation's
 * error), and the published width of a creeping zone, the cooperativity
 * length xi = A d / sqrt(mu_s - mu) of Kamrin & Koval 2012 ("Nonlocal
 * constitutive relation for steady granular flow") and Henann & Kamrin 2013
 * ("A predictive, size-dependent continuum model for dense granular flows"),
 * at the mu of H / 4.  xi is exact where mu is uniform; here mu grows towards
 * the band, and the decay length is shorter by the WKB term xi' / 2 (2.5%).
 * The velocity's decay length 1 / (ln u)' there is reported beside xi: the
 * shear rate mu g falls faster than g, and u integrates down to the base.
 * The velocity has no closed form (NaN); the headline is the mid-height
 * velocity. */
#include <math.h>
#include <stdio.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#include "march/march.h"
#include "io/output.h"
#include "scenes/scene.h"
#include "scene_common.h"

/* the reference integration's relative and absolute error per step (GSL's
 * Runge-Kutta-Fehlberg 8(9) of Prince-Dormand: far below the grids' error on
 * the scale A d / sqrt(mu_s) = 0.78 d) */
#define NGF_SHEAR_ODE_TOL 1e-12

static int check(const struct muflow_case *c, char *msg, size_t msglen)
{
    if (c->rheo.law != LAW_NGF) {
        snprintf(msg, msglen, "case.scene = ngf_shear needs rheology.law = ngf");
        return 1;
    }
    if (c->bc.face[2][0] != BC_WALL || c->bc.face[2][1] != BC_LID || c->bc.lid_direction != 0) {
        snprintf(msg, msglen, "case.scene = ngf_shear needs boundary.zlo = wall, boundary.zhi = "
                              "lid and boundary.lid_direction = x (the rough base and the "
                              "moving rough lid, g = 0 on both)");
        return 1;
    }
    if (c->tilt != 0.0) {
        snprintf(msg, msglen, "case.scene = ngf_shear needs physics.tilt = 0 (gravity across the "
                              "layer, none along the flow); got %s",
                 num_text(c->tilt).s);
        return 1;
    }
    /* the pressure's constant is the layer's mean: p = confining + rho g (H/2 - z) */
    if (!(c->confining_pressure > 0.5 * c->density * c->gravity * c->len[2])) {
        snprintf(msg, msglen, "case.scene = ngf_shear needs physics.confining_pressure > rho g H "
                              "/ 2 = %s (the mid-height pressure: the lid's must be positive)",
                 num_text(0.5 * c->density * c->gravity * c->len[2]).s);
        return 1;
    }
    return 0;
}

struct creep_line {
    double a2, mu_s, tau, p0, k; /* p(z) = p0 - k z */
};

/* (g, g')' of the linear equation at z */
static int creep_ode(double z, const double y[], double dydz[], void *params)
{
    const struct creep_line *c = params;
    dydz[0] = y[1];
    dydz[1] = (c->mu_s - c->tau / (c->p0 - c->k * z)) / c->a2 * y[0];
    return GSL_SUCCESS;
}

/* The decay length 1 / (ln g)' at z of the linear equation's solution with
 * g(0) = 0: from the base (g, g') = (0, 1), the direction in which it grows,
 * so the integration is stable; NaN if GSL's driver fails. */
static double decay_length_reference(struct creep_line *c, double z_end, double d)
{
    gsl_odeiv2_system sys = {creep_ode, NULL, 2, c};
    gsl_odeiv2_driver *drv = gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, 1e-3 * d,
                                                           NGF_SHEAR_ODE_TOL, NGF_SHEAR_ODE_TOL);
    if (!drv)
        return NAN;
    double z = 0.0, y[2] = {0.0, 1.0};
    int status = gsl_odeiv2_driver_apply(drv, &z, z_end, y);
    gsl_odeiv2_driver_free(drv);
    return status == GSL_SUCCESS ? y[0] / y[1] : NAN;
}

/* The shear stress tau = eta du/dz on the x-z edge at three quarters of the
 * height (uniform in a steady layer; there eta and du/dz are of order one). */
static double shear_stress(const struct march_state *st)
{
    const struct grid *g = &st->g;
    ptrdiff_t e = grid_idx(g, 0, 0, 3 * g->n[2] / 4);
    return st->field.viscosity_edges[1][e] * sqrt(st->field.strain_shear2[1][e]);
}

static void results(const struct march_state *st, const struct scene_drive *d,
                    struct run_result *res)
{
    (void)d;
    const struct muflow_case *cs = st->cs;
    const struct grid *g = &st->g;
    const struct rheology *r = &cs->rheo;
    const int nz = g->n[2];
    double tau = shear_stress(st), zs = 0.25 * cs->len[2];
    double measured = NAN, exact = NAN, xi = NAN, velocity = NAN;
    int idx = fields_find(&st->fields, "fluidity");
    int k = nz / 4; /* the cells k - 1 and k straddle the face at H / 4 (nz a multiple of 4) */
    if (idx >= 0 && nz % 4 == 0 && k >= 1) {
        const double *f = st->fields.e[idx].v[0], *u = st->field.velocity[0];
        ptrdiff_t c0 = grid_idx(g, 0, 0, k - 1), c1 = grid_idx(g, 0, 0, k);
        double dz = grid_xc(g, 2, k) - grid_xc(g, 2, k - 1);
        if (f[c0] > 0.0 && f[c1] > 0.0)
            measured = dz / log(f[c1] / f[c0]);
        if (u[c0] > 0.0 && u[c1] > 0.0)
            velocity = dz / log(u[c1] / u[c0]);
        double kp = cs->density * cs->gravity;
        /* the cells' pressure is hydrostatic: p at z = 0 from the lowest cell */
        double pc = st->field.pressure_regularised[grid_idx(g, 0, 0, 0)];
        struct creep_line c = {r->nonlocal_a * r->nonlocal_a * r->grain_diameter *
                                   r->grain_diameter,
                               r->mu_s, tau, pc + kp * grid_xc(g, 2, 0), kp};
        double mu = tau / (c.p0 - kp * zs);
        if (mu < r->mu_s) {
            exact = decay_length_reference(&c, zs, r->grain_diameter);
            xi = r->nonlocal_a * r->grain_diameter / sqrt(r->mu_s - mu);
        }
    }
    run_result_add(res, "shear_stress", "%.10g", tau);
    run_result_add_compared(res, "decay_length", measured, exact);
    run_result_add_compared(res, "decay_length_xi", measured, xi);
    run_result_add_compared(res, "velocity_decay_length", velocity, xi);
    snprintf(res->scene_line, sizeof res->scene_line,
             "decay length at H/4 %.6g (its linear equation's %.6g, %+.2f%%; the cooperativity "
             "length xi %.6g, %+.2f%%; the velocity's %.6g, %+.2f%%)",
             measured, exact, 100.0 * (measured / exact - 1.0), xi, 100.0 * (measured / xi - 1.0),
             velocity, 100.0 * (velocity / xi - 1.0));
}

const struct scene scene_ngf_shear = {
    .name = "ngf_shear",
    .title = "nonlocal fluidity in planar shear under gravity: the creeping layer's decay "
             "length against its linear equation and the cooperativity length",
    .check = check,
    .profile_axis = 2,
    .profile_component = 0,
    /* periodic x and y split over ranks: the fluidity on the unsplit z
     * lines; the results read column 0, every column alike */
    .decomposed = scene_decomposed_always,
    .exact_profile = scene_no_exact_profile,
    .headline_name = "u_mid",
    .results = results,
};
