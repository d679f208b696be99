/* Viscosity laws of muflow (see include/kernels/rheology.h for the formulas).
 *
 * Pure functions: no I/O, no globals, no allocation, since rheology_eval is
 * called once per cell inside an OpenMP loop.  Only sqrt/hypot/exp/expm1 are
 * used (no pow).  The derivatives are exact analytic ones, because the
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
#include <math.h>
#include <stddef.h>
#include "kernels/rheology.h"

/* Below this x = D/lam, h(x) is summed as 1 - x/2 + x^2/6: the next term,
 * x^3/24, is < 1e-16 relative, and it avoids 0/0 at x = 0. */
#define PAPA_H_SERIES_X 1e-5
/* Below this x, h'(x) is summed as a series: the closed form
 * ((1+x) e^-x - 1) / x^2 loses about 2 eps / x relative to cancellation,
 * i.e. < 5e-15 above 0.1.  Ten terms make the series exact to ~5e-18 there. */
#define PAPA_DH_SERIES_X 0.1
/* Above this x, x e^-x < 1e-400 underflows anyway; skipping it avoids
 * inf * 0 when x itself overflows. */
#define PAPA_EXP_NEGLIGIBLE_X 800.0

/* Regularised kernel f(D) and f'(D) for one regularisation. */
static inline void yield_kernel(enum regularisation reg, double D, double lam, double *f,
                                double *df)
{
    switch (reg) {
    case REG_SIMPLE: {
        double inv = 1.0 / (D + lam);
        *f = inv;
        *df = -inv * inv;
        return;
    }
    case REG_PAPANASTASIOU: {
        double x = D / lam;
        if (x < PAPA_DH_SERIES_X) {
            /* h'(x) = sum_{k>=0} (-1)^(k+1) (k+1) x^k / (k+2)!  (Horner) */
            double dh = -1.0 / 2.0
                + x * (1.0 / 3.0
                + x * (-1.0 / 8.0
                + x * (1.0 / 30.0
                + x * (-1.0 / 144.0
                + x * (1.0 / 840.0
                + x * (-1.0 / 5760.0
                + x * (1.0 / 45360.0
                + x * (-1.0 / 403200.0
                + x * (1.0 / 3991680.0)))))))));
            double h = x < PAPA_H_SERIES_X ? 1.0 - x * (0.5 - x / 6.0) : -expm1(-x) / x;
            *f = h / lam;
            *df = dh / lam / lam;
        } else {
            /* f = (1 - e^-x) / D,  f' = -[1 - (1+x) e^-x] / D^2; written
             * with D rather than x so a huge D / lam cannot overflow. */
            double one_m_e = -expm1(-x);
            double q = one_m_e - (x < PAPA_EXP_NEGLIGIBLE_X ? x * exp(-x) : 0.0);
            *f = one_m_e / D;
            *df = -(q / D) / D;
        }
        return;
    }
    case REG_BERCOVIER:
    case REG_MC: /* the yield term of "mc" is Bercovier's (mc differs only for mu(I)) */
    default: {
        double s = hypot(D, lam); /* no overflow/underflow of D^2 */
        double inv = 1.0 / s;
        *f = inv;
        *df = -(D * inv) * inv * inv;
        return;
    }
    }
}

double rheology_pressure(const struct rheology *r, double p, double *dpreg_dp)
{
    if (!r->pressure_regularisation) {
        if (dpreg_dp)
            *dpreg_dp = p > 0.0 ? 1.0 : 0.0;
        return p > 0.0 ? p : 0.0;
    }
    double lam = r->lambda;
    double h = hypot(p, lam);
    if (p >= 0.0) {
        if (dpreg_dp)
            *dpreg_dp = h > 0.0 ? 0.5 * (1.0 + p / h) : 0.5; /* h = 0 only if p = lam = 0 */
        return 0.5 * (p + h);
    }
    /* p < 0: p + h cancels; multiply by (h - p)/(h - p), h - p = h + |p| > 0. */
    double hmp = h - p;
    if (dpreg_dp)
        *dpreg_dp = lam * lam / (2.0 * h * hmp);
    return lam * lam / (2.0 * hmp);
}

void rheology_eval(const struct rheology *r, double shear, double p_reg, struct rheology_point *out)
{
    double D = fabs(shear);
    double lam = r->lambda;
    double f, df;

    switch (r->law) {
    case LAW_NEWTONIAN:
        out->eta = r->viscosity;
        out->deta_dshear = 0.0;
        out->deta_dp = 0.0;
        return;

    case LAW_BINGHAM: {
        double tau0 = r->yield_stress;
        yield_kernel(r->reg, D, lam, &f, &df);
        out->eta = tau0 * f + r->plastic_viscosity;
        out->deta_dshear = tau0 * df;
        out->deta_dp = 0.0;
        return;
    }

    case LAW_MUI:
    default:
        break;
    }

    double p = p_reg > 0.0 ? p_reg : 0.0;
    double mu_s = r->mu_s, dmu = r->delta_mu;
    /* D0 = i0 sqrt(p / rho_s) / d.  dD0/dp = D0 / (2p) is infinite at p = 0,
     * so it only ever appears as p dD0/dp = D0 / 2, which is finite. */
    double D0 = r->i0 * sqrt(p / r->grain_density) / r->grain_diameter;

    if (r->reg == REG_MC) {
        /* eta = g(D, D0) p / s,  g = mu_s + dmu D / (D0 + D),  s = hypot(D, lam) */
        double s = hypot(D, lam);
        double inv_s = 1.0 / s;
        double sum = D0 + D;
        /* D0 + D = 0 means D = 0 and p = 0 (or i0 = 0): the rate-dependent
         * part D / (D0 + D) is then taken as its value at rest, 0. */
        double ratio = sum > 0.0 ? D / sum : 0.0;     /* D / (D0 + D) */
        double dratio = sum > 0.0 ? D0 / sum / sum : 0.0; /* d ratio / dD */
        double g = mu_s + dmu * ratio;
        double p_s = p * inv_s;
        out->eta = g * p_s;
        out->deta_dshear = p_s * (dmu * dratio - g * (D * inv_s) * inv_s);
        /* d ratio / dp = -D/(D0+D)^2 dD0/dp, times p: -ratio D0 / (2 (D0+D)) */
        double p_dratio_dp = sum > 0.0 ? -0.5 * ratio * (D0 / sum) : 0.0;
        out->deta_dp = g * inv_s + dmu * p_dratio_dp * inv_s;
        return;
    }

    /* eta = mu_s p f(D) + dmu p / (D0 + D + lam) */
    yield_kernel(r->reg, D, lam, &f, &df);
    double den = D0 + D + lam;
    double inv_den = 1.0 / den;
    double rate = dmu * p * inv_den;
    out->eta = mu_s * p * f + rate;
    out->deta_dshear = mu_s * p * df - rate * inv_den;
    /* d/dp [p / den] = 1/den - p dD0/dp / den^2 = (den - D0/2) / den^2 */
    out->deta_dp = mu_s * f + dmu * (den - 0.5 * D0) * inv_den * inv_den;
}

double rheology_mu_of_i(const struct rheology *r, double inertial_number)
{
    double I = inertial_number;
    if (!(I > 0.0))
        return r->mu_s;
    if (isinf(I)) /* I / (i0 + I) would be inf/inf */
        return r->mu_s + r->delta_mu;
    /* = mu_s + dmu / (i0/I + 1), without dividing by I */
    return r->mu_s + r->delta_mu * I / (r->i0 + I);
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
