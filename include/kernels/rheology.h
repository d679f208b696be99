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
 * at rest has the finite limit mu_s p / lam, never 0/0. */
#ifndef MUFLOW_RHEOLOGY_H
#define MUFLOW_RHEOLOGY_H

enum rheology_law { LAW_MUI = 0, LAW_BINGHAM, LAW_NEWTONIAN };
enum regularisation { REG_SIMPLE = 0, REG_BERCOVIER, REG_PAPANASTASIOU, REG_MC };

struct rheology {
    enum rheology_law law;
    enum regularisation reg;
    double lambda;            /* regularisation parameter (a shear rate) */
    int pressure_regularisation; /* 1: p_reg as above; 0: max(p, 0) */
    /* mu(I) */
    double mu_s, delta_mu, i0;
    double phi;               /* solid volume fraction */
    double grain_diameter;    /* d */
    double grain_density;     /* rho_s */
    /* Bingham */
    double yield_stress, plastic_viscosity;
    /* Newtonian */
    double viscosity;
};

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

/* Unregularised mu(I) friction coefficient, for analytic solutions and tests. */
double rheology_mu_of_i(const struct rheology *r, double inertial_number);

/* Inertial number I = |D| d / sqrt(p / rho_s) (0 when p <= 0). */
double rheology_inertial_number(const struct rheology *r, double shear, double p);

const char *rheology_law_name(enum rheology_law law);
const char *regularisation_name(enum regularisation reg);

#endif
