/* Unit tests of kernels/rheology.c: the viscosity laws against closed forms
 * written out independently here, the analytic tangents against central
 * finite differences of rheology_eval itself, and the limits D -> 0 and
 * p -> 0 where a careless implementation gives 0/0 or cancels.
 *
 * Constants are those of Chauchat & Medale (2014): mu_s = 0.383,
 * dmu = 0.26, I0 = 0.279, phi = 0.6, dimensionless d = 1, rho_s = 1/phi
 * (so D0 = I0 sqrt(phi p)), lam = 1e-4. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "test_main.h"
#include "kernels/rheology.h"

#define LAM 1e-4
#define MU_S 0.383
#define DMU 0.26
#define I0 0.279
#define PHI 0.6
#define TAU0 2.0
#define ETA_P 0.1

static const enum regularisation all_regs[] = {REG_SIMPLE, REG_BERCOVIER, REG_PAPANASTASIOU,
                                               REG_MC};
#define N_REGS (sizeof(all_regs) / sizeof(all_regs[0]))
#define COUNT(a) (sizeof(a) / sizeof((a)[0]))

static struct rheology paper(enum regularisation reg)
{
    struct rheology r = {0};
    r.law = LAW_MUI;
    r.reg = reg;
    r.lambda = LAM;
    r.pressure_regularisation = 1;
    r.mu_s = MU_S;
    r.delta_mu = DMU;
    r.i0 = I0;
    r.phi = PHI;
    r.grain_diameter = 1.0;
    r.grain_density = 1.0 / PHI;
    return r;
}

static struct rheology bingham(enum regularisation reg)
{
    struct rheology r = paper(reg);
    r.law = LAW_BINGHAM;
    r.yield_stress = TAU0;
    r.plastic_viscosity = ETA_P;
    return r;
}

/* |actual - expected| <= rtol |expected| + atol, with a readable message. */
#define assert_close(actual, expected, rtol, atol, ctx) \
    assert_close_((actual), (expected), (rtol), (atol), #actual, (ctx), __FILE__, __LINE__)

static void assert_close_(double a, double e, double rtol, double atol, const char *what,
                          const char *ctx, const char *file, int line)
{
    if (!(fabs(a - e) <= rtol * fabs(e) + atol)) {
        print_error("%s [%s]: got %.17g, expected %.17g (rel err %.3g, rtol %.3g, atol %.3g)\n",
                    what, ctx, a, e, fabs(a - e) / fabs(e), rtol, atol);
        _fail(file, line);
    }
}

static void assert_finite_point(const struct rheology_point *pt, const char *ctx)
{
    if (!isfinite(pt->eta) || !isfinite(pt->deta_dshear) || !isfinite(pt->deta_dp)) {
        print_error("non-finite result [%s]: eta %g deta_dshear %g deta_dp %g\n", ctx, pt->eta,
                    pt->deta_dshear, pt->deta_dp);
        fail();
    }
}

static struct rheology_point eval(const struct rheology *r, double D, double p)
{
    struct rheology_point pt;
    rheology_eval(r, D, p, &pt);
    return pt;
}

/* Closed forms of the paper, written naively (pow, exp, no series): valid
 * for D > 0, where they are accurate enough to serve as references. */
static double ref_eta_mui(enum regularisation reg, double D, double p)
{
    double D0 = I0 * sqrt(PHI * p);
    switch (reg) {
    case REG_SIMPLE:
        return MU_S * p / (D + LAM) + DMU * p / (D0 + D + LAM);
    case REG_BERCOVIER:
        return MU_S * p / sqrt(pow(D, 2) + pow(LAM, 2)) + DMU * p / (D0 + D + LAM);
    case REG_PAPANASTASIOU:
        return MU_S * p * (1.0 - exp(-D / LAM)) / D + DMU * p / (D0 + D + LAM);
    case REG_MC:
        return (MU_S + DMU * D / (D0 + D)) * p / sqrt(pow(D, 2) + pow(LAM, 2));
    }
    return NAN;
}

static double ref_eta_bingham(enum regularisation reg, double D)
{
    switch (reg) {
    case REG_SIMPLE:
        return TAU0 / (D + LAM) + ETA_P;
    case REG_PAPANASTASIOU:
        return TAU0 * (1.0 - exp(-D / LAM)) / D + ETA_P;
    case REG_BERCOVIER:
    case REG_MC:
        return TAU0 / sqrt(pow(D, 2) + pow(LAM, 2)) + ETA_P;
    }
    return NAN;
}

/* 1. Each regularisation of mu(I) against its closed form.  Tolerance
 * 1e-12: both sides are a dozen correctly rounded operations; the naive
 * 1 - exp(-x) of the reference loses ~eps/x <= 1e-15 for x = D/lam >= 0.1. */
static void test_mui_closed_forms(void **state)
{
    (void)state;
    const double Ds[] = {1e-5, 1e-4, 3e-4, 1e-2, 1.0, 30.0};
    const double ps[] = {1e-3, 0.1, 1.0, 20.0};
    char ctx[128];
    for (size_t k = 0; k < N_REGS; k++) {
        struct rheology r = paper(all_regs[k]);
        for (size_t i = 0; i < COUNT(Ds); i++)
            for (size_t j = 0; j < COUNT(ps); j++) {
                snprintf(ctx, sizeof ctx, "%s D=%g p=%g", regularisation_name(all_regs[k]), Ds[i],
                         ps[j]);
                struct rheology_point pt = eval(&r, Ds[i], ps[j]);
                assert_close(pt.eta, ref_eta_mui(all_regs[k], Ds[i], ps[j]), 1e-12, 0.0, ctx);
            }
    }
}

/* 1b. For D >> lam the regularised stress eta D tends to the unregularised
 * mu(I) p.  Every form differs from it by a relative amount <= lam/D
 * (simple: D/(D+lam); dmu term: (D0+D)/(D0+D+lam); bercovier/mc: lam^2/2D^2;
 * papanastasiou: exp(-D/lam)), so lam/D (+1% slack) bounds the difference. */
static void test_mui_stress_limit(void **state)
{
    (void)state;
    const double Ds[] = {1e-2, 1.0, 100.0};
    const double ps[] = {0.1, 1.0, 10.0};
    char ctx[128];
    for (size_t k = 0; k < N_REGS; k++) {
        struct rheology r = paper(all_regs[k]);
        for (size_t i = 0; i < COUNT(Ds); i++)
            for (size_t j = 0; j < COUNT(ps); j++) {
                double D = Ds[i], p = ps[j];
                double I = D / sqrt(p * PHI); /* d = 1, rho_s = 1/phi */
                double mu = MU_S + DMU / (I0 / I + 1.0);
                snprintf(ctx, sizeof ctx, "%s D=%g p=%g", regularisation_name(all_regs[k]), D, p);
                struct rheology_point pt = eval(&r, D, p);
                assert_close(pt.eta * D, mu * p, 1.01 * LAM / D, 0.0, ctx);
            }
    }
}

/* Central difference of rheology_eval in D and in p, compared with the
 * analytic tangents.  Step 1e-5 relative to the point: truncation error
 * ~(h/scale)^2 ~ 1e-10 (the scale of variation is >= D) and rounding
 * ~eps/1e-5 ~ 1e-11, so a relative tolerance of 1e-6 is very safe yet would
 * catch any wrong term.  The tolerance is relative to |derivative| plus its
 * natural scale eta/(D+lam) (resp. eta/p), since some tangents cross zero. */
static void check_tangents(const struct rheology *r, double D, double p, const char *name)
{
    char ctx[160];
    snprintf(ctx, sizeof ctx, "%s/%s D=%g p=%g", rheology_law_name(r->law), name, D, p);
    struct rheology_point pt = eval(r, D, p);
    assert_finite_point(&pt, ctx);

    double hD = 1e-5 * D;
    double fdD = (eval(r, D + hD, p).eta - eval(r, D - hD, p).eta) / (2.0 * hD);
    assert_close(pt.deta_dshear, fdD, 1e-6, 1e-6 * fabs(pt.eta) / (D + r->lambda), ctx);

    double hp = 1e-5 * p;
    double fdp = (eval(r, D, p + hp).eta - eval(r, D, p - hp).eta) / (2.0 * hp);
    assert_close(pt.deta_dp, fdp, 1e-6, 1e-6 * fabs(pt.eta) / p, ctx);
}

/* 2. Tangents of the four mu(I) regularisations, around D ~ lam (where the
 * regularisation bends the law; 0.1 lam is the papanastasiou series switch)
 * and for D >> lam. */
static void test_tangents_mui(void **state)
{
    (void)state;
    const double Ds[] = {0.1 * LAM, 0.3 * LAM, LAM, 3.0 * LAM, 0.1, 10.0};
    const double ps[] = {1e-3, 1.0, 30.0};
    for (size_t k = 0; k < N_REGS; k++) {
        struct rheology r = paper(all_regs[k]);
        for (size_t i = 0; i < COUNT(Ds); i++)
            for (size_t j = 0; j < COUNT(ps); j++)
                check_tangents(&r, Ds[i], ps[j], regularisation_name(all_regs[k]));
    }
}

/* 2b. Bingham tangents (deta_dp is exactly 0: no pressure dependence). */
static void test_tangents_bingham(void **state)
{
    (void)state;
    const double Ds[] = {0.1 * LAM, 0.3 * LAM, LAM, 3.0 * LAM, 0.1, 10.0};
    for (size_t k = 0; k < N_REGS; k++) {
        struct rheology r = bingham(all_regs[k]);
        for (size_t i = 0; i < COUNT(Ds); i++) {
            check_tangents(&r, Ds[i], 1.0, regularisation_name(all_regs[k]));
            assert_true(eval(&r, Ds[i], 1.0).deta_dp == 0.0);
        }
    }
}

/* 2c. d p_reg / dp against a central difference, including p << 0 where
 * the naive (p + sqrt(p^2+lam^2))/2 would cancel to 0 and the difference
 * quotient would be noise; same 1e-5 relative step and 1e-6 tolerance. */
static void test_tangent_pressure(void **state)
{
    (void)state;
    struct rheology r = paper(REG_BERCOVIER);
    const double ps[] = {-1e3, -1.0, -1e-4, 0.0, 1e-4, 1.0, 1e3};
    char ctx[64];
    for (size_t j = 0; j < COUNT(ps); j++) {
        double p = ps[j], d;
        snprintf(ctx, sizeof ctx, "p=%g", p);
        rheology_pressure(&r, p, &d);
        double h = 1e-5 * fmax(fabs(p), LAM);
        double fd = (rheology_pressure(&r, p + h, NULL) - rheology_pressure(&r, p - h, NULL)) /
                    (2.0 * h);
        assert_close(d, fd, 1e-6, 0.0, ctx);
        assert_true(d > 0.0 && d <= 1.0);
    }
}

/* 3. D = 0 exactly: finite, equal to the analytic limits (to rounding,
 * 1e-14), and tiny D (1e-300, the smallest subnormal) gives the same. */
static void test_limit_shear_zero(void **state)
{
    (void)state;
    const double ps[] = {1e-2, 1.0, 10.0};
    const double tiny[] = {1e-300, 4.9406564584124654e-324};
    char ctx[128];
    for (size_t k = 0; k < N_REGS; k++) {
        enum regularisation reg = all_regs[k];
        struct rheology r = paper(reg);
        for (size_t j = 0; j < COUNT(ps); j++) {
            double p = ps[j], D0 = I0 * sqrt(PHI * p);
            double eta, deta_dD, deta_dp;
            if (reg == REG_MC) {
                /* rate term D/(D0+D) vanishes at rest; its D-slope is 1/D0 */
                eta = MU_S * p / LAM;
                deta_dD = DMU * p / (D0 * LAM);
                deta_dp = MU_S / LAM;
            } else {
                double dmu_term = DMU * p / (D0 + LAM);
                eta = MU_S * p / LAM + dmu_term;
                deta_dp = MU_S / LAM + DMU * (0.5 * D0 + LAM) / ((D0 + LAM) * (D0 + LAM));
                double dyield = reg == REG_SIMPLE ? -MU_S * p / (LAM * LAM)
                                : reg == REG_BERCOVIER ? 0.0
                                : -0.5 * MU_S * p / (LAM * LAM); /* papanastasiou */
                deta_dD = dyield - dmu_term / (D0 + LAM);
            }
            snprintf(ctx, sizeof ctx, "%s D=0 p=%g", regularisation_name(reg), p);
            struct rheology_point pt = eval(&r, 0.0, p);
            assert_finite_point(&pt, ctx);
            assert_close(pt.eta, eta, 1e-14, 0.0, ctx);
            assert_close(pt.deta_dshear, deta_dD, 1e-14, 0.0, ctx);
            assert_close(pt.deta_dp, deta_dp, 1e-14, 0.0, ctx);
            for (size_t t = 0; t < COUNT(tiny); t++) {
                snprintf(ctx, sizeof ctx, "%s D=%g p=%g", regularisation_name(reg), tiny[t], p);
                struct rheology_point pt2 = eval(&r, tiny[t], p);
                assert_finite_point(&pt2, ctx);
                assert_close(pt2.eta, eta, 1e-14, 0.0, ctx);
            }
        }
    }
}

/* 3b. Pressure regularisation near and below 0. */
static void test_limit_pressure(void **state)
{
    (void)state;
    struct rheology r = paper(REG_MC);
    double d;
    /* p_reg(0) = lam/2 with slope 1/2 */
    assert_close(rheology_pressure(&r, 0.0, &d), 0.5 * LAM, 1e-15, 0.0, "p=0");
    assert_close(d, 0.5, 1e-15, 0.0, "p=0");
    /* p << 0: p_reg ~ lam^2/(4|p|) (next term relative lam^2/(4 p^2) ~ 1e-20),
     * slope ~ lam^2/(4 p^2); the naive formula would return exactly 0 here */
    double pr = rheology_pressure(&r, -1e6, &d);
    assert_true(pr > 0.0);
    assert_close(pr, LAM * LAM / 4e6, 1e-12, 0.0, "p=-1e6");
    assert_close(d, LAM * LAM / 4e12, 1e-12, 0.0, "p=-1e6");
    /* p >> 0: p_reg = p + lam^2/(4p) to rounding */
    assert_close(rheology_pressure(&r, 1e6, &d), 1e6, 1e-15, 0.0, "p=1e6");
    assert_close(d, 1.0, 1e-15, 0.0, "p=1e6");
    /* strictly increasing and positive over a sweep */
    const double sweep[] = {-1e8, -1e4, -1.0, -1e-4, -1e-8, 0.0, 1e-8, 1e-4, 1.0, 1e4, 1e8};
    double prev = 0.0;
    for (size_t i = 0; i < COUNT(sweep); i++) {
        double v = rheology_pressure(&r, sweep[i], NULL);
        assert_true(v > prev);
        prev = v;
    }
    /* without regularisation: max(p, 0) and a 0/1 slope */
    r.pressure_regularisation = 0;
    assert_true(rheology_pressure(&r, -3.0, &d) == 0.0 && d == 0.0);
    assert_true(rheology_pressure(&r, 0.0, &d) == 0.0 && d == 0.0);
    assert_true(rheology_pressure(&r, 2.5, &d) == 2.5 && d == 1.0);

    /* mc: eta -> 0 monotonically as p_reg -> 0 (eta ~ p), everything finite;
     * at p = 0 every mu(I) law gives eta = 0 exactly, at rest or not. */
    r.pressure_regularisation = 1;
    const double ps[] = {1e-2, 1e-6, 1e-10, 1e-100, 1e-300, 0.0};
    const double Ds[] = {0.0, LAM, 1.0};
    char ctx[96];
    for (size_t i = 0; i < COUNT(Ds); i++) {
        double last = INFINITY;
        for (size_t j = 0; j < COUNT(ps); j++) {
            snprintf(ctx, sizeof ctx, "mc D=%g p=%g", Ds[i], ps[j]);
            struct rheology_point pt = eval(&r, Ds[i], ps[j]);
            assert_finite_point(&pt, ctx);
            assert_true(pt.eta >= 0.0 && pt.eta < last);
            last = pt.eta;
        }
        assert_true(last == 0.0);
        for (size_t k = 0; k < N_REGS; k++) {
            struct rheology rk = paper(all_regs[k]);
            assert_true(eval(&rk, Ds[i], 0.0).eta == 0.0);
        }
    }
}

/* Long-double series of h(x) = (1 - e^-x)/x and h'(x), an independent
 * reference for the papanastasiou kernel; 40 terms converge to < 1e-19
 * for x <= 2. */
static void papa_series(double x, double *h, double *dh)
{
    long double s = 0.0L, ds = 0.0L, term = 1.0L; /* term = (-x)^n / (n+1)! */
    for (int n = 0; n < 40; n++) {
        s += term;
        if (n >= 1)
            ds += (long double)n * term / (long double)x;
        term *= -(long double)x / (long double)(n + 2);
    }
    *h = (double)s;
    *dh = (double)ds;
}

/* 3c. Papanastasiou across its series switches and at D = 1e-12 lam: the
 * yield term mu_s p h(x)/lam and its slope mu_s p h'(x)/lam^2 must match the
 * series to rounding (1e-14 for the value, 1e-13 for the slope, whose closed
 * form loses ~2 eps/x just above the x = 0.1 switch). */
static void test_papanastasiou_series(void **state)
{
    (void)state;
    struct rheology r = paper(REG_PAPANASTASIOU);
    r.delta_mu = 0.0; /* isolate the yield term */
    const double p = 1.7;
    const double xs[] = {0.0, 1e-12, 1e-6, 1e-5 * (1 - 1e-9), 1e-5 * (1 + 1e-9), 1e-3,
                         0.1 * (1 - 1e-9), 0.1 * (1 + 1e-9), 0.5, 1.0, 2.0};
    char ctx[64];
    for (size_t i = 0; i < COUNT(xs); i++) {
        double h, dh;
        if (xs[i] == 0.0) {
            h = 1.0;
            dh = -0.5;
        } else {
            papa_series(xs[i], &h, &dh);
        }
        snprintf(ctx, sizeof ctx, "x=%.17g", xs[i]);
        struct rheology_point pt = eval(&r, xs[i] * LAM, p);
        assert_close(pt.eta, MU_S * p * h / LAM, 1e-14, 0.0, ctx);
        assert_close(pt.deta_dshear, MU_S * p * dh / (LAM * LAM), 1e-13, 0.0, ctx);
    }
    /* with the rate term, at D = 1e-12 lam: eta = mu_s p (1 - x/2)/lam + dmu p/den */
    r.delta_mu = DMU;
    double x = 1e-12, D = x * LAM, D0 = I0 * sqrt(PHI * p), den = D0 + D + LAM;
    struct rheology_point pt = eval(&r, D, p);
    assert_finite_point(&pt, "papa D=1e-12 lam");
    assert_close(pt.eta, MU_S * p * (1 - 0.5 * x) / LAM + DMU * p / den, 1e-14, 0.0, "eta");
    assert_close(pt.deta_dshear,
                 -MU_S * p * (0.5 - x / 3.0) / (LAM * LAM) - DMU * p / (den * den), 1e-14, 0.0,
                 "deta_dshear");
}

/* 4. Bingham (yield term as above with tau_0, plus plastic viscosity) and
 * Newtonian values. */
static void test_bingham_newtonian(void **state)
{
    (void)state;
    const double Ds[] = {1e-5, LAM, 1.0, 100.0};
    char ctx[64];
    for (size_t k = 0; k < N_REGS; k++) {
        struct rheology r = bingham(all_regs[k]);
        for (size_t i = 0; i < COUNT(Ds); i++) {
            snprintf(ctx, sizeof ctx, "%s D=%g", regularisation_name(all_regs[k]), Ds[i]);
            /* independent of the pressure */
            assert_close(eval(&r, Ds[i], 3.0).eta, ref_eta_bingham(all_regs[k], Ds[i]), 1e-12,
                         0.0, ctx);
            assert_true(eval(&r, Ds[i], 0.0).eta == eval(&r, Ds[i], 3.0).eta);
        }
        /* at rest every form gives tau_0/lam + eta_p */
        assert_close(eval(&r, 0.0, 1.0).eta, TAU0 / LAM + ETA_P, 1e-15, 0.0, "D=0");
        /* stress -> tau_0 + eta_p D for D >> lam, relative difference <= lam/D */
        assert_close(eval(&r, 10.0, 1.0).eta * 10.0, TAU0 + ETA_P * 10.0, LAM / 10.0, 0.0,
                     "D=10");
    }

    struct rheology n = {0};
    n.law = LAW_NEWTONIAN;
    n.viscosity = 0.37;
    n.lambda = LAM;
    const double pts[][2] = {{0.0, 0.0}, {1e-300, 5.0}, {1.0, 1.0}, {1e6, 1e-3}};
    for (size_t i = 0; i < COUNT(pts); i++) {
        struct rheology_point pt = eval(&n, pts[i][0], pts[i][1]);
        assert_true(pt.eta == 0.37);
        assert_true(pt.deta_dshear == 0.0 && pt.deta_dp == 0.0);
    }
}

/* 4b. mu(I) and I, the unregularised law used by analytic solutions. */
static void test_mu_of_i(void **state)
{
    (void)state;
    struct rheology r = paper(REG_BERCOVIER);
    assert_true(rheology_mu_of_i(&r, 0.0) == MU_S);
    assert_close(rheology_mu_of_i(&r, I0), MU_S + 0.5 * DMU, 1e-15, 0.0, "I=I0");
    assert_close(rheology_mu_of_i(&r, 0.1), MU_S + DMU / (I0 / 0.1 + 1.0), 1e-15, 0.0, "I=.1");
    assert_close(rheology_mu_of_i(&r, 1e300), MU_S + DMU, 1e-15, 0.0, "I=1e300");
    assert_close(rheology_mu_of_i(&r, INFINITY), MU_S + DMU, 1e-15, 0.0, "I=inf");

    /* dimensionless: I = D / sqrt(phi p) */
    assert_close(rheology_inertial_number(&r, 2.0, 0.6), 2.0 / 0.6, 1e-15, 0.0, "I(2,.6)");
    assert_true(rheology_inertial_number(&r, 2.0, 0.0) == 0.0);
    assert_true(rheology_inertial_number(&r, 2.0, -1.0) == 0.0);
    /* at D = D0(p), I = I0 by definition of D0 */
    double p = 0.37;
    assert_close(rheology_inertial_number(&r, I0 * sqrt(PHI * p), p), I0, 1e-15, 0.0, "I(D0)");
    /* dimensional glass beads: d = 0.5 mm, rho_s = 2500, p = 100 Pa, D = 10/s */
    r.grain_diameter = 0.5e-3;
    r.grain_density = 2500.0;
    assert_close(rheology_inertial_number(&r, 10.0, 100.0), 10.0 * 0.5e-3 / sqrt(100.0 / 2500.0),
                 1e-15, 0.0, "I dimensional");
}

/* ------------------------------------------------------------------------ */
/* The Barker & Gray (2017) curve (rheology.curve = barker_gray) against
 * the published thresholds (Barker & Gray 2017, "Partial regularisation of
 * the incompressible mu(I)-rheology for granular flow"): two tables of their
 * values, written out here with the digits they were tabulated to. */

struct bg_set {
    const char *name;
    double mu_s, mu_2, i0;
    double i1n, i2n_standard, a_minus, i2n_regularised; /* tabulated, printed digits */
    double tol_i1n, tol_i2n, tol_a, tol_i2n_reg;         /* half a unit of the last digit */
};

static const struct bg_set bg_sets[] = {
    {"BG2017_glass", 0.342, 0.557, 0.069, 0.0039718, 0.28017, 15642, 16.992,
     0.5e-7, 0.5e-5, 0.5, 0.5e-3},
    {"Jop2006_brief", 0.383, 0.643, 0.279, 0.019713, 0.84578, 2794.1, 14.925,
     0.5e-6, 0.5e-5, 0.05, 0.5e-3},
};
#define BG_MU_INF 0.05
#define BG_ALPHA 1.9

static struct rheology bg_rheology(const struct bg_set *b, enum regularisation reg)
{
    struct rheology r = paper(reg);
    r.mu_s = b->mu_s;
    r.delta_mu = b->mu_2 - b->mu_s;
    r.i0 = b->i0;
    r.curve = CURVE_BARKER_GRAY;
    r.alpha = BG_ALPHA;
    r.mu_inf = BG_MU_INF;
    return r;
}

static struct rheology bg_ready(const struct bg_set *b, enum regularisation reg)
{
    struct rheology r = bg_rheology(b, reg);
    char msg[512] = "";
    if (rheology_curve_setup(&r, msg, sizeof msg) != 0) {
        print_error("rheology_curve_setup [%s]: %s\n", b->name, msg);
        fail();
    }
    return r;
}

/* The well-posedness function written out naively from Barker &
 * Gray's formulas, independent of the module: curve (mu_s I0 + mu_2 I + minf I^2) /
 * (I0 + I) (minf = 0: the standard curve) and its derivative by the quotient
 * rule. */
static double naive_c(const struct bg_set *b, double minf, double I)
{
    double num = b->mu_s * b->i0 + b->mu_2 * I + minf * I * I, den = b->i0 + I;
    double mu = num / den;
    double dmu = ((b->mu_2 + 2.0 * minf * I) * den - num) / (den * den);
    double nu = I * dmu / mu;
    return 4.0 * nu * nu - 4.0 * nu + mu * mu * pow(1.0 - nu / 2.0, 2);
}

/* Root of f(I) in [a, b] (f(a) f(b) < 0) by bisection to the last bit:
 * plain and independent of the module's Brent solver. */
static double bisect(double (*f)(const struct rheology *, const struct bg_set *, double),
                     const struct rheology *r, const struct bg_set *b, double a, double c)
{
    double fa = f(r, b, a);
    for (int it = 0; it < 2000 && c - a > 1e-16 * c; it++) {
        double m = 0.5 * (a + c), fm = f(r, b, m);
        if ((fm < 0.0) == (fa < 0.0)) {
            a = m;
            fa = fm;
        } else {
            c = m;
        }
    }
    return 0.5 * (a + c);
}

static double c_standard(const struct rheology *r, const struct bg_set *b, double I)
{
    (void)b;
    return rheology_well_posedness(r, CURVE_JOP, I);
}

static double c_regularised(const struct rheology *r, const struct bg_set *b, double I)
{
    (void)b;
    return rheology_well_posedness(r, CURVE_BARKER_GRAY, I);
}

static double c_naive_standard(const struct rheology *r, const struct bg_set *b, double I)
{
    (void)r;
    return naive_c(b, 0.0, I);
}

/* 5. I_1^N, A_minus (what the case loader stores) and I_2N (the upper
 * well-posed bound, standard and regularised curve; here only) against the
 * tabulated values to their printed digits.  I_1^N also against a bisection of
 * the naive C, to 1e-12 relative (both are roots of the same function to a
 * few ulps; C has slope ~30 there, so rounding moves the root by ~1e-15). */
static void test_bg_thresholds(void **state)
{
    (void)state;
    for (size_t s = 0; s < COUNT(bg_sets); s++) {
        const struct bg_set *b = &bg_sets[s];
        struct rheology r = bg_ready(b, REG_MC);
        double zs = 0.5 * (atan(b->mu_s) + atan(b->mu_2));
        double hi = b->i0 * (tan(zs) - b->mu_s) / (b->mu_2 - tan(zs));
        double i1n_naive = bisect(c_naive_standard, &r, b, RHEOLOGY_I1N_LOW, hi);
        double i2n = bisect(c_standard, &r, b, hi, 100.0);
        double i2n_reg = bisect(c_regularised, &r, b, hi, 1e4);
        printf("    %s: I1N %.8g (table %.8g), A_minus %.8g (%.8g), I2N %.8g (%.8g), "
               "I2N_regularised %.8g (%.8g)\n",
               b->name, r.i1n, b->i1n, r.a_minus, b->a_minus, i2n, b->i2n_standard, i2n_reg,
               b->i2n_regularised);
        assert_close(r.i1n, b->i1n, 0.0, b->tol_i1n, b->name);
        assert_close(r.a_minus, b->a_minus, 0.0, b->tol_a, b->name);
        assert_close(i2n, b->i2n_standard, 0.0, b->tol_i2n, b->name);
        assert_close(i2n_reg, b->i2n_regularised, 0.0, b->tol_i2n_reg, b->name);
        assert_close(r.i1n, i1n_naive, 1e-12, 0.0, b->name);
        /* the module's C is the naive one (to rounding) on both curves */
        const double Is[] = {1e-6, 1e-3, r.i1n, 0.05, 0.5, 5.0};
        for (size_t i = 0; i < COUNT(Is); i++) {
            assert_close(rheology_well_posedness(&r, CURVE_JOP, Is[i]), naive_c(b, 0.0, Is[i]),
                         1e-12, 1e-15, b->name);
            if (Is[i] > r.i1n)
                assert_close(rheology_well_posedness(&r, CURVE_BARKER_GRAY, Is[i]),
                             naive_c(b, BG_MU_INF, Is[i]), 1e-12, 1e-15, b->name);
        }
        /* A_minus is eq. 17 of Barker & Gray (2017) */
        double q = b->mu_s * b->i0 + b->mu_2 * r.i1n + BG_MU_INF * r.i1n * r.i1n;
        assert_close(r.a_minus,
                     r.i1n * exp(BG_ALPHA * pow(b->i0 + r.i1n, 2) / (q * q)), 1e-13, 0.0,
                     b->name);
    }
}

/* 5b. The second table (BG2017_glass, Barker & Gray 2017): the standard and the
 * regularised mu(I) to the 8 printed decimals, C of the standard curve to
 * its 6 printed significant digits. */
static void test_bg_table(void **state)
{
    (void)state;
    static const double rows[][4] = {
        {1e-08, 0.34200003, 0.26013001, 0.116964},   {1e-07, 0.34200031, 0.27150036, 0.11696},
        {1e-06, 0.34200312, 0.28450518, 0.116929},   {1e-05, 0.34203115, 0.29957774, 0.11661},
        {0.0001, 0.34231114, 0.31733131, 0.113443},  {0.001, 0.34507143, 0.33866832, 0.083245},
        {0.002, 0.34805634, 0.34598414, 0.0526059},  {0.005, 0.35652703, 0.35654392, -0.0238694},
        {0.01, 0.36921519, 0.36927848, -0.113258},   {0.05, 0.43233613, 0.43338655, -0.260952},
        {0.2, 0.50185130, 0.50928625, -0.0684127},   {0.5, 0.53092794, 0.55289631, 0.104694},
        {1, 0.54312254, 0.58989523, 0.194651},       {10, 0.55552667, 1.05210031, 0.297289},
        {100, 0.55685175, 5.55340413, 0.308938},     {5000, 0.55699703, 250.55354708, 0.310223},
    };
    struct rheology bg = bg_ready(&bg_sets[0], REG_MC);
    struct rheology jop = bg;
    jop.curve = CURVE_JOP;
    char ctx[64];
    for (size_t i = 0; i < COUNT(rows); i++) {
        double I = rows[i][0];
        snprintf(ctx, sizeof ctx, "I=%g", I);
        assert_close(rheology_mu_of_i(&jop, I), rows[i][1], 0.0, 0.5e-8, ctx);
        assert_close(rheology_mu_of_i(&bg, I), rows[i][2], 0.0, 0.5e-8, ctx);
        double c = rows[i][3];
        assert_close(rheology_well_posedness(&bg, CURVE_JOP, I), c, 0.0,
                     0.5 * pow(10.0, floor(log10(fabs(c))) - 5.0), ctx);
    }
}

/* 5c. mu(I) at I_1^N: the two branches give the same value (A_minus is
 * chosen for that: to rounding, 1e-14), but not the same slope.  Low branch
 * mu' = mu^3 / (2 alpha I); high branch mu' = (dmu I0 + mu_inf I (2 I0 + I)) /
 * (I0 + I)^2: 2.932 against 2.791 (glass, 5.0% more below), 0.8558 against
 * 0.8193 (Jop2006_brief, 4.5%), so the curve
 * is continuous but not C^1 at I_1^N.  One-sided differences of
 * rheology_mu_of_i (step 1e-7 I_1^N, error ~1e-6 relative) confirm both. */
static void test_bg_continuity(void **state)
{
    (void)state;
    for (size_t s = 0; s < COUNT(bg_sets); s++) {
        const struct bg_set *b = &bg_sets[s];
        struct rheology r = bg_ready(b, REG_MC);
        double I = r.i1n, dmu = b->mu_2 - b->mu_s;
        double mu_low = sqrt(BG_ALPHA / log(r.a_minus / I));
        double mu_high = (b->mu_s * b->i0 + b->mu_2 * I + BG_MU_INF * I * I) / (b->i0 + I);
        assert_close(mu_low, mu_high, 1e-14, 0.0, b->name);
        assert_close(rheology_mu_of_i(&r, I), mu_high, 1e-14, 0.0, b->name);
        assert_close(rheology_mu_of_i(&r, nextafter(I, 1.0)), mu_high, 1e-14, 0.0, b->name);

        double slope_low = pow(mu_low, 3) / (2.0 * BG_ALPHA * I);
        double slope_high =
            (dmu * b->i0 + BG_MU_INF * I * (2.0 * b->i0 + I)) / pow(b->i0 + I, 2);
        double h = 1e-7 * I;
        double fd_low = (rheology_mu_of_i(&r, I) - rheology_mu_of_i(&r, I - h)) / h;
        double fd_high = (rheology_mu_of_i(&r, I + h) - rheology_mu_of_i(&r, I)) / h;
        printf("    %s: mu(I1N) %.10g; slope below %.6g, above %.6g (jump %.2f%%)\n", b->name,
               mu_high, slope_low, slope_high, 100.0 * (slope_low / slope_high - 1.0));
        assert_close(fd_low, slope_low, 1e-5, 0.0, b->name);
        assert_close(fd_high, slope_high, 1e-5, 0.0, b->name);
        assert_true(fabs(slope_low / slope_high - 1.0) > 0.01); /* not C^1 */
    }
}

/* 5d. Well posed below I_1^N: on the regularised curve nu = mu^2/(2 alpha),
 * so C ~ mu^2 (1 - 2/alpha) < 0 as I -> 0 exactly when alpha < 2.  C < 0 at
 * 300 log-spaced I from 1e-300 to just below I_1^N for alpha = 1.9 and 1.5
 * (and in the band up to I2N_regularised); with alpha = 2.5 (refused by
 * the key, A_minus set here by hand) C > 0 near I = 0: ill posed again. */
static void test_bg_well_posed_below(void **state)
{
    (void)state;
    const double alphas[] = {1.9, 1.5, 1.0};
    char ctx[96];
    for (size_t s = 0; s < COUNT(bg_sets); s++)
        for (size_t a = 0; a < COUNT(alphas); a++) {
            struct rheology r = bg_rheology(&bg_sets[s], REG_MC);
            r.alpha = alphas[a];
            char msg[512];
            assert_int_equal(rheology_curve_setup(&r, msg, sizeof msg), 0);
            double lo = log(1e-300), hi = log(r.i1n * (1.0 - 1e-9));
            for (int k = 0; k <= 300; k++) {
                double I = exp(lo + (hi - lo) * k / 300.0);
                snprintf(ctx, sizeof ctx, "%s alpha=%g I=%g", bg_sets[s].name, alphas[a], I);
                double c = rheology_well_posedness(&r, CURVE_BARKER_GRAY, I);
                if (!(c < 0.0)) {
                    print_error("C = %g >= 0 [%s]\n", c, ctx);
                    fail();
                }
            }
            /* and above I_1^N up to 0.9 I2N_regularised */
            double span = log(0.9 * bg_sets[s].i2n_regularised / r.i1n);
            for (int k = 1; k <= 100; k++) {
                double I = r.i1n * exp(span * k / 100.0);
                assert_true(rheology_well_posedness(&r, CURVE_BARKER_GRAY, I) < 0.0);
            }
        }
    struct rheology r = bg_ready(&bg_sets[0], REG_MC);
    r.alpha = 2.5;
    double q = 0.342 * 0.069 + 0.557 * r.i1n + BG_MU_INF * r.i1n * r.i1n;
    r.a_minus = r.i1n * exp(r.alpha * pow(0.069 + r.i1n, 2) / (q * q));
    assert_true(rheology_well_posedness(&r, CURVE_BARKER_GRAY, 1e-30) > 0.0);
}

/* 5d'. rheology_i_of_mu inverts rheology_mu_of_i on both curves and both
 * branches (1e-12: a square root or a log away from the forward value), with
 * mu_inf = 0.05 (quadratic high branch, no upper bound) and mu_inf = 0 (the
 * jop-like high branch, bounded by mu_2). */
static void test_bg_inverse(void **state)
{
    (void)state;
    const double Is[] = {1e-200, 1e-8, 1e-3, 0.0039, 0.004, 0.02, 0.3, 3.0, 300.0};
    char ctx[96];
    for (size_t s = 0; s < COUNT(bg_sets); s++)
        for (int m = 0; m < 2; m++) {
            struct rheology r = bg_rheology(&bg_sets[s], REG_MC);
            r.mu_inf = m ? 0.0 : BG_MU_INF;
            char msg[512];
            assert_int_equal(rheology_curve_setup(&r, msg, sizeof msg), 0);
            for (size_t i = 0; i < COUNT(Is); i++) {
                snprintf(ctx, sizeof ctx, "%s mu_inf=%g I=%g", bg_sets[s].name, r.mu_inf, Is[i]);
                assert_close(rheology_i_of_mu(&r, rheology_mu_of_i(&r, Is[i])), Is[i], 1e-12,
                             0.0, ctx);
            }
            assert_true(rheology_i_of_mu(&r, 0.0) == 0.0);
            if (m)
                assert_true(isnan(rheology_i_of_mu(&r, bg_sets[s].mu_2)));
            struct rheology jop = r;
            jop.curve = CURVE_JOP;
            assert_close(rheology_i_of_mu(&jop, rheology_mu_of_i(&jop, 0.1)), 0.1, 1e-12, 0.0,
                         "jop");
            assert_true(rheology_i_of_mu(&jop, jop.mu_s) == 0.0);
        }
}

/* eta = mu_BG(I) p f(D), written out naively (I = D / sqrt(phi p)). */
static double ref_eta_bg(const struct rheology *r, double D, double p)
{
    double I = D / sqrt(PHI * p), mu;
    if (I <= r->i1n)
        mu = sqrt(r->alpha / log(r->a_minus / I));
    else
        mu = (r->mu_s * r->i0 + (r->mu_s + r->delta_mu) * I + r->mu_inf * I * I) / (r->i0 + I);
    double f = r->reg == REG_SIMPLE           ? 1.0 / (D + LAM)
               : r->reg == REG_PAPANASTASIOU ? (1.0 - exp(-D / LAM)) / D
                                              : 1.0 / sqrt(D * D + LAM * LAM);
    return mu * p * f;
}

/* 5e. The viscosity of every regularisation with the curve: against the
 * naive form (1e-12, as test 1), the tangents against central differences
 * (check_tangents, as for the Jop curve) on both branches and near I_1^N on
 * either side (0.5 and 2 I_1^N; the difference step does not cross it), at
 * rest eta = 0 with finite slopes, extreme magnitudes where I overflows,
 * and for |D| >> lam eta |D| -> mu(I) p. */
static void test_bg_viscosity(void **state)
{
    (void)state;
    const double Ds[] = {0.1 * LAM, 0.3 * LAM, LAM, 3.0 * LAM, 0.1, 10.0};
    const double ps[] = {1e-3, 1.0, 30.0};
    char ctx[128];
    for (size_t s = 0; s < COUNT(bg_sets); s++)
        for (size_t k = 0; k < N_REGS; k++) {
            struct rheology r = bg_ready(&bg_sets[s], all_regs[k]);
            snprintf(ctx, sizeof ctx, "bg %s %s", bg_sets[s].name,
                     regularisation_name(all_regs[k]));
            for (size_t i = 0; i < COUNT(Ds); i++)
                for (size_t j = 0; j < COUNT(ps); j++) {
                    assert_close(eval(&r, Ds[i], ps[j]).eta, ref_eta_bg(&r, Ds[i], ps[j]), 1e-12,
                                 0.0, ctx);
                    check_tangents(&r, Ds[i], ps[j], ctx);
                }
            const double factors[] = {0.5, 2.0};
            for (size_t i = 0; i < COUNT(factors); i++)
                for (size_t j = 0; j < COUNT(ps); j++) {
                    double D = factors[i] * r.i1n * sqrt(PHI * ps[j]);
                    assert_close(eval(&r, D, ps[j]).eta, ref_eta_bg(&r, D, ps[j]), 1e-12, 0.0,
                                 ctx);
                    check_tangents(&r, D, ps[j], ctx);
                }
            /* extreme magnitudes: I overflows a double (1e300 / sqrt(1e-30)) where
             * eta and its slopes do not; against the naive form in long double
             * (range 1e4932) and central differences */
            const double big[][2] = {{1e300, 1e-30}, {1e150, 1e-200}, {1e-3, 1e250}};
            for (size_t i = 0; i < COUNT(big); i++) {
                long double D = big[i][0], p = big[i][1], I = D / sqrtl(PHI * p);
                long double mu = (I <= r.i1n)
                                     ? sqrtl(r.alpha / logl(r.a_minus / I))
                                     : (r.mu_s * r.i0 + (r.mu_s + r.delta_mu) * I +
                                        r.mu_inf * I * I) / (r.i0 + I);
                long double f = all_regs[k] == REG_SIMPLE ? 1.0L / (D + LAM)
                                : all_regs[k] == REG_PAPANASTASIOU ? -expm1l(-D / LAM) / D
                                                                    : 1.0L / hypotl(D, LAM);
                struct rheology_point pt = eval(&r, big[i][0], big[i][1]);
                assert_finite_point(&pt, ctx);
                assert_close(pt.eta, (double)(mu * p * f), 1e-12, 0.0, ctx);
                if (I > 1e308L) {
                    /* f' ~ 1/D^2 underflows beyond D ~ 1e154 (for every law),
                     * so only the p-slope is checked; the D-slope is finite */
                    double hp = 1e-5 * big[i][1];
                    double fdp = (eval(&r, big[i][0], big[i][1] + hp).eta -
                                  eval(&r, big[i][0], big[i][1] - hp).eta) / (2.0 * hp);
                    assert_close(pt.deta_dp, fdp, 1e-6, 0.0, ctx);
                } else {
                    check_tangents(&r, big[i][0], big[i][1], ctx);
                }
            }
            struct rheology_point rest = eval(&r, 0.0, 1.0);
            assert_finite_point(&rest, ctx);
            assert_true(rest.eta == 0.0);
            /* D >> lam: the stress is mu(I) p within lam / D (as test 1b) */
            double D = 10.0, p = 2.0, I = D / sqrt(PHI * p);
            assert_close(eval(&r, D, p).eta * D, rheology_mu_of_i(&r, I) * p, 1.01 * LAM / D,
                         0.0, ctx);
        }
}

/* 5f. Bad input is refused naming the key: alpha = 2 (and 0), a jop curve
 * without a well-posed band (mu_s = 2, delta_mu = 0.1: C > 0 throughout the
 * bracket) and delta_mu = 0 (empty bracket). */
static void test_bg_refused(void **state)
{
    (void)state;
    char msg[512];
    const double bad_alpha[] = {2.0, 0.0, 2.5, -1.0};
    for (size_t i = 0; i < COUNT(bad_alpha); i++) {
        struct rheology r = bg_rheology(&bg_sets[0], REG_MC);
        r.alpha = bad_alpha[i];
        msg[0] = '\0';
        assert_int_equal(rheology_curve_setup(&r, msg, sizeof msg), 1);
        assert_non_null(strstr(msg, "rheology.alpha"));
    }
    const double bad_curves[][2] = {{2.0, 0.1}, {0.383, 0.0}};
    for (size_t i = 0; i < COUNT(bad_curves); i++) {
        struct rheology r = bg_rheology(&bg_sets[0], REG_MC);
        r.mu_s = bad_curves[i][0];
        r.delta_mu = bad_curves[i][1];
        msg[0] = '\0';
        assert_int_equal(rheology_curve_setup(&r, msg, sizeof msg), 1);
        printf("    refused: %s\n", msg);
        assert_non_null(strstr(msg, "rheology.mu_s"));
        assert_non_null(strstr(msg, "rheology.delta_mu"));
        assert_non_null(strstr(msg, "rheology.i0"));
        assert_null(strchr(msg, '\n'));
    }
    /* the jop curve needs nothing and is left as it was */
    struct rheology r = paper(REG_MC);
    assert_int_equal(rheology_curve_setup(&r, msg, sizeof msg), 0);
    assert_true(r.i1n == 0.0 && r.a_minus == 0.0);
}

/* No NaN/Inf anywhere in D >= 0, p_reg >= 0 over 400 orders of magnitude,
 * for every law, regularisation and curve, and eta >= 0. */
static void test_no_nan_sweep(void **state)
{
    (void)state;
    const double vals[] = {0.0, 4.9406564584124654e-324, 1e-300, 1e-12, LAM, 1.0, 1e6, 1e100};
    const enum rheology_law laws[] = {LAW_MUI, LAW_BINGHAM, LAW_NEWTONIAN};
    const enum rheology_curve curves[] = {CURVE_JOP, CURVE_BARKER_GRAY};
    char ctx[128];
    for (size_t l = 0; l < COUNT(laws); l++)
        for (size_t k = 0; k < N_REGS; k++)
            for (size_t c = 0; c < COUNT(curves); c++) {
                struct rheology r = curves[c] == CURVE_BARKER_GRAY
                                        ? bg_ready(&bg_sets[0], all_regs[k])
                                        : paper(all_regs[k]);
                r.law = laws[l];
                r.yield_stress = TAU0;
                r.plastic_viscosity = ETA_P;
                r.viscosity = 1.0;
                for (size_t i = 0; i < COUNT(vals); i++)
                    for (size_t j = 0; j < COUNT(vals); j++) {
                        snprintf(ctx, sizeof ctx, "%s/%s/%s D=%g p=%g",
                                 rheology_law_name(laws[l]), regularisation_name(all_regs[k]),
                                 rheology_curve_name(curves[c]), vals[i], vals[j]);
                        struct rheology_point pt = eval(&r, vals[i], vals[j]);
                        assert_finite_point(&pt, ctx);
                        assert_true(pt.eta >= 0.0);
                    }
            }
}

static void test_names(void **state)
{
    (void)state;
    assert_string_equal(rheology_law_name(LAW_MUI), "mui");
    assert_string_equal(rheology_law_name(LAW_BINGHAM), "bingham");
    assert_string_equal(rheology_law_name(LAW_NEWTONIAN), "newtonian");
    assert_string_equal(regularisation_name(REG_SIMPLE), "simple");
    assert_string_equal(regularisation_name(REG_BERCOVIER), "bercovier");
    assert_string_equal(regularisation_name(REG_PAPANASTASIOU), "papanastasiou");
    assert_string_equal(regularisation_name(REG_MC), "mc");
    assert_string_equal(rheology_curve_name(CURVE_JOP), "jop");
    assert_string_equal(rheology_curve_name(CURVE_BARKER_GRAY), "barker_gray");
}

void group_rheology(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mui_closed_forms),
        cmocka_unit_test(test_mui_stress_limit),
        cmocka_unit_test(test_tangents_mui),
        cmocka_unit_test(test_tangents_bingham),
        cmocka_unit_test(test_tangent_pressure),
        cmocka_unit_test(test_limit_shear_zero),
        cmocka_unit_test(test_limit_pressure),
        cmocka_unit_test(test_papanastasiou_series),
        cmocka_unit_test(test_bingham_newtonian),
        cmocka_unit_test(test_mu_of_i),
        cmocka_unit_test(test_bg_thresholds),
        cmocka_unit_test(test_bg_table),
        cmocka_unit_test(test_bg_continuity),
        cmocka_unit_test(test_bg_well_posed_below),
        cmocka_unit_test(test_bg_inverse),
        cmocka_unit_test(test_bg_viscosity),
        cmocka_unit_test(test_bg_refused),
        cmocka_unit_test(test_no_nan_sweep),
        cmocka_unit_test(test_names),
    };
    RUN_GROUP(t, "rheology", tests);
}
