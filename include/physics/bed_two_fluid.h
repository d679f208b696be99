/* A granular bed under a Newtonian fluid in the two-fluid form of the
 * two-phase model (Chauchat & Medale 2010, eqs. 5-12; Ouriemi, Aussillous & Guazzelli
 * 2009): a physics module (march/module.h) that holds the particle velocity
 * u^p beside the march's mixture velocity u^m = eps u^f + phi u^p and solves
 * the two coupled steady equations, in the bed (phi = phi0, eps = 1 - phi0)
 *   fluid     0 = -grad p + div(eta_e grad u^m) - beta (u^m - u^p)
 *   particles 0 = div tau^p(u^p) + beta (u^m - u^p)
 * with the Darcy drag beta = eta_f / K, K = eps^3 d^2 / (k_CK phi0^2)
 * (Carman-Kozeny), eta_e = eta_f (1 + 5 phi0 / 2) the fluid stress's
 * viscosity on u^m (eta_f above the bed, the two in series where the bed's
 * top cuts a control volume, as in bed.h), and the Coulomb stress
 * tau^p = mu_s p_p f(|D(u^p)|) gamma(u^p), f the case's regularised 1/|D|
 * and p_p = phi0 (rho_p - rho_f) g (h_p - z) the buoyant weight of the
 * grains above.  The particle equation is the paper's (particle momentum
 * with the generalised buoyancy phi div sigma^f) less phi times the fluid
 * one; the march's residual is their sum, the mixture equation with the
 * particle stress taken on u^p:
 *   R_m = f - grad p + div(eta_e gamma(u^m)) + div tau^p(u^p),
 * and the module's own residual is the particle equation's, R_p; the run is
 * steady when both are.
 *
 * The drag is stiff (beta D^2 / eta_f ~ 1e6 for D/d = 30), so the step
 * solves the two equations together: the Newton step of the pair (dm, dp)
 * on each line of u-faces along z,
 *   [M + F + beta t      -beta t     ] [dm]   [R_m - R_p]
 *   [-beta t       M + P + beta t    ] [dp] = [R_p      ],
 * F and P the linearised fluid and particle stress operators (probed along
 * the line, as the line preconditioner is), M = rho / dt the pseudo-time
 * mass and t the bed's share of the face's control volume: a symmetric
 * positive definite block-tridiagonal system, solved directly.  Exact for
 * the plane flow u(z) (periodic y).  With walls in y (a cross-section
 * u(y, z), the duct scene) the operators are probed with nine combs
 * (j, k mod 3) and the 2 x ny x nz system of each x plane is solved by
 * UMFPACK (docs/numerics/bed-models.md). */
#ifndef MUFLOW_PHYSICS_BED_TWO_FLUID_H
#define MUFLOW_PHYSICS_BED_TWO_FLUID_H

#include <stddef.h>
#include "march/march.h"
#include "physics/bed.h"

struct two_fluid_params {
    struct bed_params bed;    /* h_p, phi0, eta_f, mu_s, the grains' weight */
    double grain_diameter;    /* d */
    double kozeny;            /* k_CK */
};

extern const struct module two_fluid_module;

/* Switches the two-fluid bed on with p (the module must be in the scene's
 * list): registers u^p and its work fields.  Returns 0, or -1 with the cause
 * in err. */
int two_fluid_configure(struct march_state *st, const struct two_fluid_params *p, char *err,
                        size_t errlen);

/* The Darcy drag coefficient beta = eta_f k_CK phi0^2 / ((1 - phi0)^3 d^2). */
double two_fluid_drag(const struct two_fluid_params *p);

/* The mean over each layer k of the grid (0 .. n[2] - 1) of u^p (x
 * component) into up[k], NaN where the layer's control volume holds no bed;
 * and the largest |u^m - u^p| over the bed's faces (NULL: not wanted).
 * Returns 0, or -1 when the module is not configured. */
int two_fluid_particle_profile(const struct march_state *st, double *up, double *slip_max);

/* The largest |R_p| of the last evaluation, relative to the force scale. */
double two_fluid_particle_residual(const struct march_state *st);

#endif
