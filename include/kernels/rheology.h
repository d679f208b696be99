/* Every viscosity law of muflow, as pure functions of the shear-rate magnitude
 * |D| = sqrt(0.5 gamma:gamma) (gamma = grad u + grad u^T) and the pressure.
 *
 * mu(I) (Jop et al.), with I = |D| d / sqrt(p / rho_s) and
 * D0(p) = I0 sqrt(p / rho_s) / d, the shear rate at which I = I0
 * (dimensionless runs: d = 1, rho_s = 1/phi, so D0 = I0 sqrt(phi p)):
 *   simple         eta = mu_s p / (|D| + lam) + dmu p / (D0 + |D| + lam)
 *   bercovier      eta = mu_s p / sqrt(|D|^2 + lam^2) + dmu p / (D0 + |D| + lam)
 *   papanastasiou  eta = mu_s p (1 - exp(-|D|/lam)) / |D| + dmu p / (D0 + |D| + lam)
 *   mc             eta = [mu_s + dmu |D| / (D0 + |D|)] p / sqrt(|D|^2 + lam^2)
 * Bingham: the same four forms of the yield term with tau_0 in place of mu_s p,
 * plus the plastic viscosity.  Newtonian: a constant.
 * The pressure entering mu(I) is the regularised total pressure
 *   p_reg = (p + sqrt(p^2 + lam^2)) / 2 .
 * Papanastasiou is evaluated with expm1 and a series near |D| = 0, so a fluid
 * at rest has the finite limit mu_s p / lam, never 0/0.
 *
 * The friction curve mu(I) of the law (rheology.curve):
 *   jop           mu = mu_s + dmu I / (I0 + I), the forms above.
 *   barker_gray   the partially regularised curve of Barker & Gray (2017),
 *                 mu_2 = mu_s + dmu:
 *                   mu = sqrt(alpha / ln(A_minus / I))                  I <= I_1^N
 *                   mu = (mu_s I0 + mu_2 I + mu_inf I^2) / (I0 + I)    I >  I_1^N
 *                 I_1^N is the lower root of the well-posedness function
 *                 C(I) = 4 nu^2 - 4 nu + mu^2 (1 - nu/2)^2, nu = I mu'/mu, of the
 *                 jop curve (well posed where C < 0), and
 *                 A_minus = I_1^N exp(alpha / mu_high(I_1^N)^2) makes mu continuous.
 *                 The low branch has nu = mu^2 / (2 alpha), so it is well posed
 *                 down to I = 0 only for alpha < 2; mu(0) = 0 (no static yield).
 *                 The whole curve takes the place of the yield stress in each
 *                 regularised kernel f(|D|) (the yield kernel of the regularisation:
 *                 simple 1/(|D| + lam), bercovier and mc 1/sqrt(|D|^2 + lam^2),
 *                 papanastasiou (1 - exp(-|D|/lam)) / |D|), with I from |D| itself:
 *                   eta = mu(I) p_reg f(|D|),
 *                 so for mc it is mc's form with the curve in the bracket, and a
 *                 fluid at rest has eta = 0 (mu(0) = 0), finite in every form. */
#ifndef MUFLOW_RHEOLOGY_H
#define MUFLOW_RHEOLOGY_H

#include <stddef.h>
#include "config/rheology_params.h" /* struct rheology: the [rheology] keys */

/* Value and first derivatives of the viscosity at one point. */
struct rheology_point {
    double eta;          /* viscosity */
    double deta_dshear;  /* d eta / d |D| at fixed pressure */
    double deta_dp;      /* d eta / d p_reg at fixed |D| */
};

/* Regularised pressure p_reg(p) and, if dpreg_dp is not NULL, its derivative.
 * Free of cancellation for p << 0 (there p_reg ~ lam^2 / (4 |p|)). */
double rheology_pressure(const struct rheology *r, double p, double *dpreg_dp);

/* Viscosity and its derivatives at shear-rate magnitude shear >= 0 and
 * (already regularised) pressure p_reg >= 0. */
void rheology_eval(const struct rheology *r, double shear, double p_reg, struct rheology_point *out);

/* The regularised yield kernel f(|D|) ~ 1/|D| of reg (simple, bercovier and
 * mc, papanastasiou: the forms above) and f'(|D|), for a module that adds a
 * yield stress of its own (physics/bed.h: the bed's Coulomb friction). */
void rheology_yield_kernel(enum regularisation reg, double shear, double lambda, double *f,
                           double *df);

/* Unregularised mu(I) friction coefficient of r's curve, for analytic
 * solutions and tests (barker_gray needs rheology_curve_setup first). */
double rheology_mu_of_i(const struct rheology *r, double inertial_number);

/* The inverse of rheology_mu_of_i: the I at which r's curve reaches mu
 * (analytic solutions at a given friction, e.g. the Bagnold profile); 0 at or
 * below the curve's value at rest (mu_s; 0 for barker_gray), NAN at or above
 * its bound (mu_s + delta_mu; barker_gray with mu_inf > 0 has none). */
double rheology_i_of_mu(const struct rheology *r, double mu);

/* The well-posedness function C(I) = 4 nu^2 - 4 nu + mu^2 (1 - nu/2)^2,
 * nu = I mu'(I) / mu(I), of the given curve with r's parameters at I > 0
 * (Barker et al. 2015; well posed where C < 0).  curve may differ from
 * r->curve: CURVE_JOP is the standard curve whose lower root is I_1^N. */
double rheology_well_posedness(const struct rheology *r, enum rheology_curve curve, double I);

/* Bracket of I_1^N, [RHEOLOGY_I1N_LOW, the I where the jop curve's mu is
 * tan((atan mu_s + atan mu_2) / 2)], as in the public implementation of
 * Barker & Gray (2017). */
#define RHEOLOGY_I1N_LOW 1e-9

/* Derived values of the curve, once per case: for barker_gray, I_1^N (the
 * lower root of the jop curve's C(I), by GSL's Brent solver) and A_minus
 * into r; for jop nothing.  Returns 0, or 1 with one line in msg naming the
 * keys (rheology.alpha out of (0, 2), or no well-posed I_1^N for
 * rheology.mu_s / delta_mu / i0).  Not for the kernels' loops: it allocates
 * the root finder. */
int rheology_curve_setup(struct rheology *r, char *msg, size_t msglen);

/* Inertial number I = |D| d / sqrt(p / rho_s) (0 when p <= 0). */
double rheology_inertial_number(const struct rheology *r, double shear, double p);

const char *rheology_law_name(enum rheology_law law);
const char *regularisation_name(enum regularisation reg);
const char *rheology_curve_name(enum rheology_curve curve);

#endif
