/* Viscosity laws of muflow (see include/kernels/rheology.h for the formulas).
 * The per-point evaluation lives in kernels/rheology_inline.h, inlined in the
 * viscosity kernels; the public functions here call the same code.
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
#include "rheology_inline.h"

double rheology_pressure(const struct rheology *r, double p, double *dpreg_dp)
{
    return rheo_pressure(r, p, dpreg_dp);
}

void rheology_eval(const struct rheology *r, double shear, double p_reg, struct rheology_point *out)
{
    rheo_eval(r, r->law, r->reg, shear, p_reg, out);
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
