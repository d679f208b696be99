/* The viscosity law's parameters, as the [rheology] keys of a case give
 * them (config/case.h holds one) and the laws read them
 * (kernels/rheology.h, whose comment has the formulas).  Here, below the
 * kernels, so that a case is a plain value the case reader can fill
 * without knowing how the laws are evaluated. */
#ifndef MUFLOW_CONFIG_RHEOLOGY_PARAMS_H
#define MUFLOW_CONFIG_RHEOLOGY_PARAMS_H

enum rheology_law { LAW_MUI = 0, LAW_BINGHAM, LAW_NEWTONIAN, LAW_NGF };
enum regularisation { REG_SIMPLE = 0, REG_BERCOVIER, REG_PAPANASTASIOU, REG_MC };
enum rheology_curve { CURVE_JOP = 0, CURVE_BARKER_GRAY };
/* ngf: how the fluidity equation is solved (physics/ngf.h) */
enum fluidity_solver { FLUIDITY_AUTO = 0, FLUIDITY_LINES, FLUIDITY_MULTIGRID };

struct rheology {
    enum rheology_law law;
    enum regularisation reg;
    double lambda;            /* regularisation parameter (a shear rate) */
    int pressure_regularisation; /* 1: p_reg = (p + sqrt(p^2 + lambda^2)) / 2;
                                    0: max(p, 0) */
    /* mu(I) */
    double mu_s, delta_mu, i0;
    enum rheology_curve curve; /* the friction curve mu(I) */
    double alpha, mu_inf;     /* barker_gray: low-I exponent, high-I slope */
    /* barker_gray, derived when the case is loaded (rheology_curve_setup of
     * kernels/rheology.h), not keys: the lower well-posed bound I_1^N and
     * A_minus */
    double i1n, a_minus;
    double phi;               /* solid volume fraction */
    double grain_diameter;    /* d */
    double grain_density;     /* rho_s */
    /* Bingham */
    double yield_stress, plastic_viscosity;
    /* Newtonian */
    double viscosity;
    /* ngf, the nonlocal granular fluidity (with mu_s): the nonlocal
     * amplitude A and the rate sensitivity b (physics/ngf.h) */
    double nonlocal_a, nonlocal_b;
    enum fluidity_solver fluidity_solver;
    int fluidity_anderson; /* the steady iteration's Anderson depth; 0: Picard */
};

#endif
