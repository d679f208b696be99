/* Scene "ngf_chute": the nonlocal fluidity (rheology.law = ngf, physics/ngf.h)
 * in a vertical chute between rough walls at z = 0 and z = H, gravity along
 * the flow (x, physics.tilt = pi/2), periodic along x and y, the pressure the
 * confining pressure P across the channel (cases/ngf_chute.ini; one of the
 * geometries of Liu & Henann 2018, "Size-dependence of the flow threshold
 * in dense granular materials", for this model).
 *
 * The shear stress is rho g |s|, s = z - H/2, so mu = rho g |s| / P: shear
 * bands along the walls where mu > mu_s, and a plug |s| < s_y = mu_s P /
 * (rho g) (the local law's, which does not move relative to itself) that
 * the fluidity of the bands makes creep.  There the fluidity is small, b I
 * negligible against mu_s - mu, and its equation linear:
 *   A^2 d^2 g'' = (mu_s - rho g |s| / P) g,  g'(0) = 0 (symmetry),
 * an Airy equation in zeta = c (s_y - s), c = (rho g / (P A^2 d^2))^(1/3):
 *   g ∝ Bi'(zeta_0) Ai(zeta) - Ai'(zeta_0) Bi(zeta),  zeta_0 = c s_y.
 * Its width: the creep length, the distance from the centre at which g has
 * grown by e (the e-folding of the creeping plug; a uniform stress ratio mu
 * would give xi acosh(e), xi = A d / sqrt(mu_s - mu), the cooperativity
 * length of Kamrin & Koval).  The velocity has no closed form (NaN); the
 * headline is the centre velocity. */
#include <gsl/gsl_sf_airy.h>
#include <math.h>
#include <stdio.h>
#include "march/march.h"
#include "io/output.h"
#include "scenes/scene.h"
#include "scene_common.h"

/* |cos(tilt)| below this: gravity has no component across the channel and
 * the pressure is the confining pressure (cos(pi/2) in double is 6.1e-17) */
#define NGF_CHUTE_COS_MAX 1e-12

static int check(const struct muflow_case *c, char *msg, size_t msglen)
{
    if (c->rheo.law != LAW_NGF) {
        snprintf(msg, msglen, "case.scene = ngf_chute needs rheology.law = ngf");
        return 1;
    }
    if (c->bc.face[2][0] != BC_WALL || c->bc.face[2][1] != BC_WALL) {
        snprintf(msg, msglen, "case.scene = ngf_chute needs boundary.zlo = wall and boundary.zhi "
                              "= wall (the rough walls of the chute, g = 0 on them)");
        return 1;
    }
    if (!(fabs(cos(c->tilt)) < NGF_CHUTE_COS_MAX && sin(c->tilt) > 0.0)) {
        snprintf(msg, msglen, "case.scene = ngf_chute needs physics.tilt = 1.5707963267948966 "
                              "(pi/2: gravity along the flow, none across the channel); got %s",
                 num_text(c->tilt).s);
        return 1;
    }
    if (!(c->confining_pressure > 0.0)) {
        snprintf(msg, msglen, "case.scene = ngf_chute needs physics.confining_pressure > 0 (the "
                              "pressure across the channel)");
        return 1;
    }
    return 0;
}

/* The linear plug's shape: g(zeta) / g(zeta_0), zeta_0 at the centre. */
static double plug_ratio(double zeta, double zeta0)
{
    double bp = gsl_sf_airy_Bi_deriv(zeta0, GSL_PREC_DOUBLE);
    double ap = gsl_sf_airy_Ai_deriv(zeta0, GSL_PREC_DOUBLE);
    double g = bp * gsl_sf_airy_Ai(zeta, GSL_PREC_DOUBLE) - ap * gsl_sf_airy_Bi(zeta, GSL_PREC_DOUBLE);
    double g0 = bp * gsl_sf_airy_Ai(zeta0, GSL_PREC_DOUBLE) -
                ap * gsl_sf_airy_Bi(zeta0, GSL_PREC_DOUBLE);
    return g / g0;
}

/* The closed form's creep length: the s in (0, s_y) where the ratio is e,
 * by bisection (the ratio grows monotonically from 1 at the centre; NaN when
 * it does not reach e inside the plug). */
static double creep_length_exact(const struct muflow_case *cs)
{
    const struct rheology *r = &cs->rheo;
    double P = cs->confining_pressure, k = cs->density * cs->gravity;
    double ad = r->nonlocal_a * r->grain_diameter;
    double c = cbrt(k / (P * ad * ad)), sy = r->mu_s * P / k, zeta0 = c * sy;
    double lo = 0.0, hi = sy;
    if (!(plug_ratio(0.0, zeta0) > exp(1.0)))
        return NAN;
    for (int it = 0; it < 200 && hi - lo > 1e-14 * sy; it++) {
        double mid = 0.5 * (lo + hi);
        if (plug_ratio(c * (sy - mid), zeta0) > exp(1.0))
            hi = mid;
        else
            lo = mid;
    }
    return 0.5 * (lo + hi);
}

/* The measured creep length on one half of the column (dir -1: towards
 * z = 0, +1: towards z = H): ln g at the cell centres, its centre value from
 * the centre cell (nz odd) or the even fit L(s) = L0 + c s^2 through the two
 * cells nearest the centre (nz even: L0 = (9 L(h/2) - L(3h/2)) / 8), then
 * the first crossing of L0 + 1, linear in s between cells. */
static double creep_length_half(const struct grid *g, double H, const double *f, int dir)
{
    const int nz = g->n[2];
    const double mid = 0.5 * H;
    int first = nz % 2 ? nz / 2 : (dir < 0 ? nz / 2 - 1 : nz / 2);
    double L0;
    if (nz % 2)
        L0 = log(f[grid_idx(g, 0, 0, first)]);
    else
        L0 = (9.0 * log(f[grid_idx(g, 0, 0, first)]) -
              log(f[grid_idx(g, 0, 0, first + dir)])) / 8.0;
    double s_prev = 0.0, d_prev = 0.0;
    for (int k = first; k >= 0 && k < nz; k += dir) {
        double v = f[grid_idx(g, 0, 0, k)];
        if (!(v > 0.0))
            return NAN;
        double s = fabs(grid_xc(g, 2, k) - mid), d = log(v) - L0;
        if (d >= 1.0)
            return s_prev + (1.0 - d_prev) * (s - s_prev) / (d - d_prev);
        s_prev = s;
        d_prev = d;
    }
    return NAN;
}

static void results(const struct march_state *st, const struct scene_drive *d,
                    struct run_result *res)
{
    (void)d;
    const struct muflow_case *cs = st->cs;
    int idx = fields_find(&st->fields, "fluidity");
    double measured = NAN;
    if (idx >= 0) {
        const double *f = st->fields.e[idx].v[0];
        measured = 0.5 * (creep_length_half(&st->g, cs->len[2], f, -1) +
                          creep_length_half(&st->g, cs->len[2], f, 1));
    }
    double exact = creep_length_exact(cs);
    double sy = cs->rheo.mu_s * cs->confining_pressure / (cs->density * cs->gravity);
    run_result_add(res, "plug_half_width_local", "%.10g", sy);
    run_result_add_compared(res, "creep_length", measured, exact);
    snprintf(res->scene_line, sizeof res->scene_line,
             "creep length %.6g (the Airy closed form's %.6g, %+.2f%%)", measured, exact,
             100.0 * (measured / exact - 1.0));
}

const struct scene scene_ngf_chute = {
    .name = "ngf_chute",
    .title = "nonlocal fluidity in a vertical chute: the creeping plug's width against its "
             "closed form",
    .check = check,
    .profile_axis = 2,
    .profile_component = 0,
    /* periodic x and y split over ranks: the fluidity on the unsplit z
     * lines; the results read column 0, every column alike */
    .decomposed = scene_decomposed_always,
    .exact_profile = scene_no_exact_profile,
    .headline_name = "u_centre",
    .results = results,
};
