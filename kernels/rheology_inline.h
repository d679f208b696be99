/* The viscosity laws of kernels/rheology.c as static inline functions, for
 * the kernels that evaluate them once per cell or edge (internal to kernels/;
 * the public functions of include/kernels/rheology.h call these, so the tests
 * of the public functions test exactly what the kernels compute).
 *
 * rheo_eval takes the law and the regularisation as arguments apart from the
 * struct: a kernel selects them once, outside its loops (RHEOLOGY_DISPATCH),
 * and calls a loop instantiated with them as constants, so the switch on the
 * law and the regularisation is resolved at compile time and the whole
 * evaluation is inlined in the loop (bench/analysis.md, section 4). */
#ifndef MUFLOW_RHEOLOGY_INLINE_H
#define MUFLOW_RHEOLOGY_INLINE_H

#include <float.h>
#include <math.h>
#include "kernels/rheology.h"

/* hypot(x, y) where sqrt(x^2 + y^2) can neither overflow nor lose digits to
 * the subnormal range: there the two agree within an ulp and the square root
 * is one instruction, where glibc's hypot costs about 50.  Elsewhere (and for
 * NaN) hypot itself. */
static inline double rheo_hypot(double x, double y)
{
    double s = x * x + y * y;
    if (s > 1e-290 && s < 1e290)
        return sqrt(s);
    return hypot(x, y);
}

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
static inline void rheo_yield_kernel(enum regularisation reg, double D, double lam, double *f,
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
        double s = rheo_hypot(D, lam);
        double inv = 1.0 / s;
        *f = inv;
        *df = -(D * inv) * inv * inv;
        return;
    }
    }
}

/* Regularised pressure (rheology_pressure). */
static inline double rheo_pressure(const struct rheology *r, double p, double *dpreg_dp)
{
    if (!r->pressure_regularisation) {
        if (dpreg_dp)
            *dpreg_dp = p > 0.0 ? 1.0 : 0.0;
        return p > 0.0 ? p : 0.0;
    }
    double lam = r->lambda;
    double h = rheo_hypot(p, lam);
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

/* The Barker & Gray curve in eta = mu(I) p f(D) (rheology.h), with the
 * yield kernel f, f' = df of the regularisation already evaluated at D > 0.
 * Everything is written with m1 = I mu'(I) and dI/dD = I/D, dI/dp = -I/(2p):
 *   d eta / dD = p (m1 f / D + mu f'),   d eta / dp = f (mu - m1 / 2).
 * Low branch: mu = sqrt(alpha / ln(A_minus / I)), m1 = mu^3 / (2 alpha).
 * High branch with r = I / (I0 + I) = D / (D0 + D):
 *   mu = mu_s + dmu r + mu_inf I r,   m1 = dmu r (1 - r) + mu_inf I r (2 - r).
 * I itself is only compared with I_1^N: I overflows (p -> 0, |D| large) where
 * the terms do not, so they are grouped as I p = D q, q = d sqrt(rho_s p),
 * r (1 - r) / D = (1 - r) / (D0 + D), f I = (f D) d sqrt(rho_s) / sqrt(p),
 * with f D <= 1 and f' D bounded for every kernel. */
static inline void rheo_eval_barker_gray(const struct rheology *r, double D, double p, double f,
                                         double df, struct rheology_point *out)
{
    double sqrt_rho = sqrt(r->grain_density), d = r->grain_diameter;
    double sp = sqrt(p);
    /* I = D d sqrt(rho_s / p), inf at p = 0 (and where it overflows) */
    double I = p > 0.0 ? D * d * sqrt_rho / sp : INFINITY;
    if (I <= r->i1n) {
        /* ln(A/I) as a difference: A / I overflows for subnormal I; I = 0
         * (underflow) gives ln = inf and mu = 0, the curve's value at rest */
        double L = log(r->a_minus) - log(I);
        double mu = sqrt(r->alpha / L);
        double m1 = mu * mu * mu / (2.0 * r->alpha);
        double mp = mu * p;
        out->eta = mp * f;
        /* m1 f p / D ~ 1 / (D ln^(3/2)) is unbounded as D -> 0 (mu' is
         * infinite at I = 0).  The symmetric tangent uses it times
         * gamma^2 / |D| <= |D|, which tends to 0 with mu; the full tangent's
         * eta' / (2 |D|) is unbounded at rest, as for the simple form.  It
         * overflows only for subnormal D, where the largest finite number
         * stands for it. */
        out->deta_dshear = fmin(m1 * p * f / D, DBL_MAX) + mp * df;
        out->deta_dp = f * (mu - 0.5 * m1);
        return;
    }
    double dmu = r->delta_mu, minf = r->mu_inf;
    double D0 = r->i0 * sp / (d * sqrt_rho); /* the D at which I = I0 */
    double sum = D0 + D;                     /* > 0: D > 0 on this branch */
    double rr = D / sum, one_m_r = D0 / sum;
    double q = d * sqrt_rho * sp;            /* I p / D, 0 at p = 0 */
    double fD = f * D, dfD = df * D;
    double jop = r->mu_s + dmu * rr;         /* mu without the mu_inf term */
    out->eta = f * p * jop + minf * rr * fD * q;
    out->deta_dshear = f * dmu * p * (one_m_r / sum) + minf * rr * (2.0 - rr) * f * q +
                       df * p * jop + minf * rr * dfD * q;
    /* mu - m1/2 = mu_s + dmu r (1 + r)/2 + mu_inf I r^2/2: the last term
     * grows like 1/sqrt(p) as p -> 0 and is infinite at p = 0 (which only
     * pressure_regularisation = off reaches), where DBL_MAX stands for it */
    double dp = f * (r->mu_s + 0.5 * dmu * rr * (1.0 + rr));
    if (minf > 0.0)
        dp += fmin(0.5 * minf * rr * rr * fD * (d * sqrt_rho / sp), DBL_MAX);
    out->deta_dp = fmin(dp, DBL_MAX);
}

/* rheology_eval with the law, regularisation and curve given apart
 * (constants in an instantiated loop); they must be those of r, or what they
 * stand for (RHEOLOGY_DISPATCH). */
static inline void rheo_eval(const struct rheology *r, enum rheology_law law,
                             enum regularisation reg, enum rheology_curve curve, double shear,
                             double p_reg, struct rheology_point *out)
{
    double D = fabs(shear);
    double lam = r->lambda;
    double f, df;

    switch (law) {
    case LAW_NEWTONIAN:
        out->eta = r->viscosity;
        out->deta_dshear = 0.0;
        out->deta_dp = 0.0;
        return;

    case LAW_BINGHAM: {
        double tau0 = r->yield_stress;
        rheo_yield_kernel(reg, D, lam, &f, &df);
        out->eta = tau0 * f + r->plastic_viscosity;
        out->deta_dshear = tau0 * df;
        out->deta_dp = 0.0;
        return;
    }

    case LAW_NGF: {
        /* the local limit of the nonlocal fluidity (A = 0): g = |D| / mu,
         * mu = mu_s + b I, so eta = p / g = mu_s p f(|D|) + b d sqrt(rho_s p).
         * physics/ngf.c replaces it by p / g of the nonlocal g; this is what
         * a kernel without the fluidity field evaluates */
        double p = p_reg > 0.0 ? p_reg : 0.0;
        double rate = r->nonlocal_b * r->grain_diameter * sqrt(r->grain_density);
        rheo_yield_kernel(reg, D, lam, &f, &df);
        out->eta = r->mu_s * p * f + rate * sqrt(p);
        out->deta_dshear = r->mu_s * p * df;
        out->deta_dp = r->mu_s * f + (p > 0.0 ? fmin(0.5 * rate / sqrt(p), DBL_MAX) : DBL_MAX);
        return;
    }

    case LAW_MUI:
    default:
        break;
    }

    double p = p_reg > 0.0 ? p_reg : 0.0;
    if (curve == CURVE_BARKER_GRAY) {
        if (!(D > 0.0)) {
            /* at rest I = 0 and mu(0) = 0: eta = 0 with a zero pressure slope;
             * d eta / dD has no finite limit (see rheo_eval_barker_gray), and
             * the kernels, like every law at D = 0, use eta alone there */
            out->eta = 0.0;
            out->deta_dshear = 0.0;
            out->deta_dp = 0.0;
            return;
        }
        rheo_yield_kernel(reg, D, lam, &f, &df);
        rheo_eval_barker_gray(r, D, p, f, df, out);
        return;
    }
    double mu_s = r->mu_s, dmu = r->delta_mu;
    /* D0 = i0 sqrt(p / rho_s) / d.  dD0/dp = D0 / (2p) is infinite at p = 0,
     * so it only ever appears as p dD0/dp = D0 / 2, which is finite. */
    double D0 = r->i0 * sqrt(p / r->grain_density) / r->grain_diameter;

    if (reg == REG_MC) {
        /* eta = g(D, D0) p / s,  g = mu_s + dmu D / (D0 + D),  s = hypot(D, lam) */
        double s = rheo_hypot(D, lam);
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
    rheo_yield_kernel(reg, D, lam, &f, &df);
    double den = D0 + D + lam;
    double inv_den = 1.0 / den;
    double rate = dmu * p * inv_den;
    out->eta = mu_s * p * f + rate;
    out->deta_dshear = mu_s * p * df - rate * inv_den;
    /* d/dp [p / den] = 1/den - p dD0/dp / den^2 = (den - D0/2) / den^2 */
    out->deta_dp = mu_s * f + dmu * (den - 0.5 * D0) * inv_den * inv_den;
}

/* Runs CALL(law, reg, curve) with the law, regularisation and curve of r as
 * constants: one instantiation per distinct code path of rheo_eval
 * (Newtonian ignores the regularisation; mc is Bercovier's yield term for
 * Bingham, and an unknown regularisation is Bercovier's as in
 * rheo_yield_kernel; the curve matters for mu(I) only, and for Barker & Gray
 * mc is again Bercovier's kernel). */
#define RHEOLOGY_DISPATCH(r, CALL)                                                  \
    do {                                                                            \
        switch ((r)->law) {                                                         \
        case LAW_NEWTONIAN:                                                         \
            CALL(LAW_NEWTONIAN, REG_SIMPLE, CURVE_JOP);                             \
            break;                                                                  \
        case LAW_BINGHAM:                                                           \
            switch ((r)->reg) {                                                     \
            case REG_SIMPLE: CALL(LAW_BINGHAM, REG_SIMPLE, CURVE_JOP); break;       \
            case REG_PAPANASTASIOU:                                                 \
                CALL(LAW_BINGHAM, REG_PAPANASTASIOU, CURVE_JOP);                    \
                break;                                                              \
            default: CALL(LAW_BINGHAM, REG_BERCOVIER, CURVE_JOP); break;            \
            }                                                                       \
            break;                                                                  \
        case LAW_NGF:                                                               \
            switch ((r)->reg) {                                                     \
            case REG_SIMPLE: CALL(LAW_NGF, REG_SIMPLE, CURVE_JOP); break;           \
            case REG_PAPANASTASIOU: CALL(LAW_NGF, REG_PAPANASTASIOU, CURVE_JOP); break;\
            default: CALL(LAW_NGF, REG_BERCOVIER, CURVE_JOP); break;                \
            }                                                                       \
            break;                                                                  \
        case LAW_MUI:                                                               \
        default:                                                                    \
            if ((r)->curve == CURVE_BARKER_GRAY) {                                  \
                switch ((r)->reg) {                                                 \
                case REG_SIMPLE: CALL(LAW_MUI, REG_SIMPLE, CURVE_BARKER_GRAY); break;\
                case REG_PAPANASTASIOU:                                             \
                    CALL(LAW_MUI, REG_PAPANASTASIOU, CURVE_BARKER_GRAY);            \
                    break;                                                          \
                default: CALL(LAW_MUI, REG_BERCOVIER, CURVE_BARKER_GRAY); break;    \
                }                                                                   \
                break;                                                              \
            }                                                                       \
            switch ((r)->reg) {                                                     \
            case REG_SIMPLE: CALL(LAW_MUI, REG_SIMPLE, CURVE_JOP); break;           \
            case REG_PAPANASTASIOU: CALL(LAW_MUI, REG_PAPANASTASIOU, CURVE_JOP); break;\
            case REG_MC: CALL(LAW_MUI, REG_MC, CURVE_JOP); break;                   \
            default: CALL(LAW_MUI, REG_BERCOVIER, CURVE_JOP); break;                \
            }                                                                       \
            break;                                                                  \
        }                                                                           \
    } while (0)

#endif
