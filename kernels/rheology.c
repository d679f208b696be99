/* Viscosity laws of muflow (see include/kernels/rheology.h for the formulas).
 * The per-point evaluation lives in kernels/rheology_inline.h, inlined in the
 * viscosity kernels; the public functions here call the same code.
 *
 * Pure functions: no I/O, no globals, no allocation, since rheology_eval is
 * called once per cell inside an OpenMP loop.  The one exception,
 * rheology_curve_setup, runs once when a case is loaded (it allocates GSL's
 * root finder) and fills the derived values the evaluation then reads.  The
 * evaluation uses sqrt/hypot/exp/expm1 (and log for the Barker & Gray curve's
 * low branch), no pow.  The derivatives are exact analytic ones, because the
 * Newton/Picard tangents and the unit tests compare against them.
 *
 * Every law is written as  eta = Y f(|D|) + rest,  where Y is the yield
 * stress (mu_s p or tau_0) and f one of the regularised 1/|D| kernels:
 *   simple         f = 1 / (D + lam)
 *   bercovier      f = 1 / sqrt(D^2 + lam^2)
 *   papanastasiou  f = (1 - exp(-D/lam)) / D = h(D/lam) / lam,
 *                  h(x) = -expm1(-x) / x
 * All are finite at D = 0 as long as lam > 0 (a regularised law with
 * lam = 0 is the unregularised one and is singular at rest by design). */
#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include "kernels/rheology.h"
#include "rheology_inline.h"
#include "platform/num_text.h" /* numbers in messages as case files write them */

double rheology_pressure(const struct rheology *r, double p, double *dpreg_dp)
{
    return rheo_pressure(r, p, dpreg_dp);
}

void rheology_eval(const struct rheology *r, double shear, double p_reg, struct rheology_point *out)
{
    rheo_eval(r, r->law, r->reg, r->curve, shear, p_reg, out);
}

void rheology_yield_kernel(enum regularisation reg, double shear, double lambda, double *f,
                           double *df)
{
    rheo_yield_kernel(reg, fabs(shear), lambda, f, df);
}

/* mu and m1 = I mu'(I) of the curve mu_s + dmu r + mu_inf I r, r = I/(I0+I)
 * (the jop curve for mu_inf = 0), at finite I > 0. */
static void high_branch(const struct rheology *r, double mu_inf, double I, double *mu,
                        double *m1)
{
    double rr = I / (r->i0 + I), one_m_r = r->i0 / (r->i0 + I);
    *mu = r->mu_s + r->delta_mu * rr + mu_inf * I * rr;
    *m1 = r->delta_mu * rr * one_m_r + mu_inf * I * rr * (2.0 - rr);
}

/* The low branch of Barker & Gray at 0 < I <= I_1^N: mu and m1. */
static void low_branch(const struct rheology *r, double I, double *mu, double *m1)
{
    *mu = sqrt(r->alpha / (log(r->a_minus) - log(I)));
    *m1 = *mu * *mu * *mu / (2.0 * r->alpha);
}

double rheology_mu_of_i(const struct rheology *r, double inertial_number)
{
    double I = inertial_number;
    if (r->curve == CURVE_BARKER_GRAY) {
        double mu, m1;
        if (!(I > 0.0))
            return 0.0; /* no static yield: mu(0) = 0 */
        if (isinf(I))
            return r->mu_inf > 0.0 ? INFINITY : r->mu_s + r->delta_mu;
        if (I <= r->i1n)
            low_branch(r, I, &mu, &m1);
        else
            high_branch(r, r->mu_inf, I, &mu, &m1);
        return mu;
    }
    if (!(I > 0.0))
        return r->mu_s;
    if (isinf(I)) /* I / (i0 + I) would be inf/inf */
        return r->mu_s + r->delta_mu;
    /* = mu_s + dmu / (i0/I + 1), without dividing by I */
    return r->mu_s + r->delta_mu * I / (r->i0 + I);
}

double rheology_i_of_mu(const struct rheology *r, double mu)
{
    double mu_2 = r->mu_s + r->delta_mu;
    if (r->curve != CURVE_BARKER_GRAY || r->mu_inf == 0.0) {
        double rest = r->curve == CURVE_BARKER_GRAY ? 0.0 : r->mu_s;
        if (!(mu > rest))
            return 0.0;
        if (mu >= mu_2)
            return NAN;
        if (r->curve != CURVE_BARKER_GRAY || mu > rheology_mu_of_i(r, r->i1n))
            return r->i0 * (mu - r->mu_s) / (mu_2 - mu);
        return r->a_minus * exp(-r->alpha / (mu * mu));
    }
    if (!(mu > 0.0))
        return 0.0;
    if (mu <= rheology_mu_of_i(r, r->i1n)) /* low branch: ln(A/I) = alpha / mu^2 */
        return r->a_minus * exp(-r->alpha / (mu * mu));
    /* mu_inf I^2 + b I + c = 0 with b = mu_2 - mu, c = (mu_s - mu) I0 < 0 (mu
     * is above mu(I_1^N) > mu_s): the positive root, in the form that does
     * not cancel for either sign of b */
    double a = r->mu_inf, b = mu_2 - mu, c = (r->mu_s - mu) * r->i0;
    double sq = sqrt(b * b - 4.0 * a * c);
    return b >= 0.0 ? 2.0 * c / (-b - sq) : (sq - b) / (2.0 * a);
}

double rheology_well_posedness(const struct rheology *r, enum rheology_curve curve, double I)
{
    double mu, m1;
    if (curve == CURVE_BARKER_GRAY && I <= r->i1n)
        low_branch(r, I, &mu, &m1);
    else
        high_branch(r, curve == CURVE_BARKER_GRAY ? r->mu_inf : 0.0, I, &mu, &m1);
    double nu = m1 / mu;
    double b = 1.0 - 0.5 * nu;
    return 4.0 * nu * nu - 4.0 * nu + mu * mu * b * b;
}

static double jop_well_posedness(double I, void *params)
{
    return rheology_well_posedness(params, CURVE_JOP, I);
}

/* Log-spaced samples of C over the bracket when its ends do not straddle a
 * root: the well-posed band may lie inside it, and the first negative
 * sample then brackets the lower root. */
#define I1N_SCAN_POINTS 400

int rheology_curve_setup(struct rheology *r, char *msg, size_t msglen)
{
    r->i1n = 0.0;
    r->a_minus = 0.0;
    if (r->curve != CURVE_BARKER_GRAY)
        return 0;
    if (!(r->alpha > 0.0 && r->alpha < 2.0)) {
        snprintf(msg, msglen,
                 "rheology.curve = barker_gray: rheology.alpha = %s must be in (0, 2): the "
                 "low-I branch has nu = mu^2 / (2 alpha) and is well posed near I = 0 only for "
                 "alpha < 2",
                 num_text(r->alpha).s);
        return 1;
    }
    double mu_2 = r->mu_s + r->delta_mu;
    double tz = tan(0.5 * (atan(r->mu_s) + atan(mu_2)));
    double lo = RHEOLOGY_I1N_LOW, hi = r->i0 * (tz - r->mu_s) / (mu_2 - tz);
    /* delta_mu = 0 gives 0/0 here: a constant mu is ill posed everywhere */
    int found = 0;
    if (hi > lo && jop_well_posedness(lo, r) > 0.0) {
        if (jop_well_posedness(hi, r) < 0.0) {
            found = 1;
        } else {
            double step = pow(hi / lo, 1.0 / I1N_SCAN_POINTS), a = lo;
            for (int k = 1; k <= I1N_SCAN_POINTS && !found; k++) {
                double b = k == I1N_SCAN_POINTS ? hi : lo * pow(step, k);
                if (jop_well_posedness(b, r) < 0.0) {
                    lo = a;
                    hi = b;
                    found = 1;
                }
                a = b;
            }
        }
    }
    if (!found && !(hi > lo)) {
        snprintf(msg, msglen,
                 "rheology.curve = barker_gray: the mu(I) curve of rheology.mu_s = %s, "
                 "rheology.delta_mu = %s, rheology.i0 = %s has no well-posed I_1^N: the "
                 "bracket [%.3g, I(mu = tan((atan mu_s + atan mu_2) / 2))] is empty%s",
                 num_text(r->mu_s).s, num_text(r->delta_mu).s, num_text(r->i0).s,
                 RHEOLOGY_I1N_LOW,
                 r->delta_mu > 0.0 ? ""
                                   : " (delta_mu = 0: a constant mu is ill posed everywhere)");
        return 1;
    }
    if (!found) {
        snprintf(msg, msglen,
                 "rheology.curve = barker_gray: the mu(I) curve of rheology.mu_s = %s, "
                 "rheology.delta_mu = %s, rheology.i0 = %s has C(I) >= 0 (ill posed) "
                 "throughout [%.3g, %.6g], so there is no well-posed I_1^N to regularise from",
                 num_text(r->mu_s).s, num_text(r->delta_mu).s, num_text(r->i0).s,
                 RHEOLOGY_I1N_LOW, hi);
        return 1;
    }

    gsl_root_fsolver *solver = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    if (!solver) {
        snprintf(msg, msglen, "rheology.curve = barker_gray: out of memory for the root finder");
        return 1;
    }
    /* errors come back as codes: the default handler would abort */
    gsl_error_handler_t *previous = gsl_set_error_handler_off();
    gsl_function fn = {.function = jop_well_posedness, .params = r};
    int status = gsl_root_fsolver_set(solver, &fn, lo, hi);
    /* to a few ulps of I_1^N: the root is simple, and each iteration costs
     * one evaluation of C */
    for (int it = 0; it < 200 && status == GSL_SUCCESS; it++) {
        status = gsl_root_fsolver_iterate(solver);
        if (status != GSL_SUCCESS)
            break;
        double a = gsl_root_fsolver_x_lower(solver), b = gsl_root_fsolver_x_upper(solver);
        if (gsl_root_test_interval(a, b, 0.0, 4.0 * 2.220446049250313e-16) == GSL_SUCCESS)
            break;
    }
    double root = gsl_root_fsolver_root(solver);
    gsl_set_error_handler(previous);
    gsl_root_fsolver_free(solver);
    if (status != GSL_SUCCESS) {
        snprintf(msg, msglen, "rheology.curve = barker_gray: I_1^N root finder: %s",
                 gsl_strerror(status));
        return 1;
    }
    /* A_minus from the regularised high branch at I_1^N (so mu is continuous
     * there): I_1^N exp(alpha (I0 + I)^2 / (mu_s I0 + mu_2 I + mu_inf I^2)^2) */
    double mu, m1;
    high_branch(r, r->mu_inf, root, &mu, &m1);
    r->i1n = root;
    r->a_minus = root * exp(r->alpha / (mu * mu));
    if (!isfinite(r->a_minus)) {
        snprintf(msg, msglen,
                 "rheology.curve = barker_gray: A_minus = I_1^N exp(alpha / mu(I_1^N)^2) "
                 "overflows for rheology.alpha = %s and mu(I_1^N = %.6g) = %.6g",
                 num_text(r->alpha).s, root, mu);
        return 1;
    }
    return 0;
}

double rheology_inertial_number(const struct rheology *r, double shear, double p)
{
    if (!(p > 0.0))
        return 0.0;
    return fabs(shear) * r->grain_diameter * sqrt(r->grain_density / p);
}

const char *rheology_law_name(enum rheology_law law)
{
    switch (law) {
    case LAW_MUI: return "mui";
    case LAW_BINGHAM: return "bingham";
    case LAW_NEWTONIAN: return "newtonian";
    case LAW_NGF: return "ngf";
    }
    return "unknown";
}

const char *rheology_curve_name(enum rheology_curve curve)
{
    switch (curve) {
    case CURVE_JOP: return "jop";
    case CURVE_BARKER_GRAY: return "barker_gray";
    }
    return "unknown";
}

const char *regularisation_name(enum regularisation reg)
{
    switch (reg) {
    case REG_SIMPLE: return "simple";
    case REG_BERCOVIER: return "bercovier";
    case REG_PAPANASTASIOU: return "papanastasiou";
    case REG_MC: return "mc";
    }
    return "unknown";
}
