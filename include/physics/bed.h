/* A granular bed under a Newtonian fluid in the mixed-fluid form of the
 * two-phase model (Chauchat & Medale 2010, eq. 13; Ouriemi, Aussillous & Guazzelli 2009):
 * a physics module (march/module.h) that sets, in the properties stage,
 * every viscosity and its Newton tangent (cells and edges) from one mixture
 * velocity:
 *   in the bed   eta_bed = eta_e + mu_s p_p f(|D|),  above it eta_f,
 * eta_e = eta_f (1 + 5 phi0 / 2) the mixture's effective (Einstein)
 * viscosity, f the case's regularised yield kernel ~ 1/|D|
 * (rheology.regularisation, rheology.lambda), and p_p the buoyant weight of
 * the grains above, phi0 (rho_p - rho_f) g (h_p - z), averaged over the bed's
 * part of the stress location's control volume.  A control volume that the
 * bed's top (flat, at h_p) cuts, with the bed's share t, takes the two in
 * series: 1/eta = t / eta_bed + (1 - t) / eta_f.
 * The core's law is only a placeholder (the scene asks for newtonian, the
 * cheapest): the module overwrites what it computed.  The bed is held: the
 * volume fraction is not transported. */
#ifndef MUFLOW_PHYSICS_BED_H
#define MUFLOW_PHYSICS_BED_H

#include <stddef.h>
#include "march/march.h"

struct bed_params {
    double height;            /* h_p, from z = 0 */
    double phi;               /* phi0 */
    double fluid_viscosity;   /* eta_f */
    double mu_s;              /* Coulomb friction coefficient */
    double weight;            /* phi0 (rho_p - rho_f) g: d p_p / d(depth) */
};

extern const struct module bed_module;

/* Switches the bed on with p (the module must be in the scene's list).
 * Returns 0, or -1 with the cause in err. */
int bed_configure(struct march_state *st, const struct bed_params *p, char *err, size_t errlen);

/* The bed's share t of the control volume [z - dz/2, z + dz/2] and the
 * mean particle pressure p_p over that share (0 where t = 0). */
void bed_point(const struct bed_params *p, double z, double dz, double *t, double *pp);

/* The viscosity of the stress location at height z (control volume of
 * height dz) at shear rate |D| = shear, and d eta / d|D| in *deta (what the
 * module's tangents are built from; r gives the regularisation). */
double bed_viscosity(const struct bed_params *p, const struct rheology *r, double z, double dz,
                     double shear, double *deta);

/* A law of the stress locations: the viscosity at height z (control volume
 * of height dz) and shear rate |D| = shear, its slope d eta / d|D| in
 * *deta. */
typedef double (*bed_law)(const void *ctx, double z, double dz, double shear, double *deta);

/* Where bed_fill_viscosities writes; a NULL array is not written; k0: the
 * global index of the grid's first layer (a rank's block split along z:
 * its heights are the domain's). */
struct bed_viscosity_out {
    double *eta_c, *tan_c[3], *b_c;    /* cells */
    double *eta_e[3], *tan_e[3], *b_e[3]; /* edges of plane c */
    int k0;
};

/* The law at every interior cell (|D| = sqrt(shear2), NULL: 0) and every
 * edge of plane c (along z at a cell centre when c = z, else on a z face;
 * |D| from cn2 and e2 as kernel_edge_shear2 sums it, cn2 NULL: 0), with the
 * tangent coefficients of kernel_viscosity_cells and _edges for this law's
 * eta and slope (cells: the normal strain rates of vel). */
void bed_fill_viscosities(const struct grid *g, bed_law law, const void *ctx,
                          const double *shear2, const double *cn2, double *const e2[3],
                          double *const vel[3], const struct bed_viscosity_out *out);

#endif
