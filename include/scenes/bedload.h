/* What the bed-load scenes share (src/scenes/bedload_common.c): the
 * parameters of a Newtonian fluid over a flat granular bed (the keys of
 * [bedload] and [duct], the same names and meanings in both), their
 * physical checks, the exact plane solution of Ouriemi, Aussillous &
 * Guazzelli (2009) and the measured top of the fixed bed.
 *
 * Exact solution (Ouriemi, Aussillous & Guazzelli 2009, "Sediment dynamics.
 * Part 1. Bed-load transport by laminar shearing flows"): y = z / D,
 * u = U0 u*(y), U0 = (rho_p - rho_f) g D^2 / eta_f,
 * G = (dp/dx) / ((rho_p - rho_f) g), h = h_p / D, eta = 1 + 5 phi0 / 2,
 * A = G + mu_s phi0 (bed load needs A > 0),
 *   mobile layer  delta = eta (1 - h) [sqrt(1 - G / (eta A)) - 1], h_c = h - delta
 *   fixed bed     y < h_c:       u* = 0
 *   mobile layer  h_c <= y <= h: u* = A / (2 eta) (y - h_c)^2
 *   fluid         y > h:         u* = -G/2 (1 - y)(y - h) + A/(2 eta) delta^2 (1 - y)/(1 - h).
 * The driving pressure gradient is the body force:
 * -dp/dx = physics.density * physics.gravity * sin(physics.tilt). */
#ifndef MUFLOW_SCENES_BEDLOAD_H
#define MUFLOW_SCENES_BEDLOAD_H

#include <stddef.h>
#include "config/case.h"
#include "config/keys.h"
#include "physics/bed.h"

struct bedload_params {
    double bed_height;        /* h_p */
    double phi;               /* phi0 */
    double particle_density;  /* rho_p */
    double fluid_density;     /* rho_f */
    double fluid_viscosity;   /* eta_f */
    double mu_s;              /* Coulomb friction */
    double gravity;           /* g in the particle pressure */
    int model;                /* enum bedload_model */
    double grain_diameter;    /* d (two_fluid: the permeability) */
    double kozeny;            /* k_CK (two_fluid) */
};

enum bedload_model { BEDLOAD_MIXED = 0, BEDLOAD_TWO_FLUID };
extern const struct choice bedload_model_choices[];

/* The key table entries both scenes have, in section SEC (a string
 * literal), for the members of struct bedload_params (T). */
#define BEDLOAD_KEYS(T, SEC)                                                                    \
    KEY_DBL(T, SEC, "bed_height", bed_height,                                                   \
            KEY_HELP("height h_p of the flat granular bed above the lower wall: the bed and the "  \
                     "fluid above it each at least a cell, domain.lz / domain.nz",                \
                     "length", NULL),                                                           \
            KEY_GT0),                                                                           \
    KEY_DBL(T, SEC, "phi", phi, "volume fraction phi0 of the grains in the bed",                \
            KEY_RANGE(0.0, 1.0, 0, 0)),                                                         \
    KEY_DBL(T, SEC, "particle_density", particle_density,                                       \
            KEY_HELP("density rho_p of the grains (above fluid_density)", "mass/length^3",      \
                     NULL),                                                                     \
            KEY_GT0),                                                                           \
    KEY_DBL(T, SEC, "fluid_density", fluid_density,                                             \
            KEY_HELP("density rho_f of the fluid", "mass/length^3", NULL), KEY_GT0),            \
    KEY_DBL(T, SEC, "fluid_viscosity", fluid_viscosity,                                         \
            KEY_HELP("viscosity eta_f of the fluid (the bed's is eta_f (1 + 5 phi / 2))",       \
                     "pressure time", NULL),                                                    \
            KEY_GT0),                                                                           \
    KEY_DBL(T, SEC, "mu_s", mu_s,                                                               \
            "Coulomb friction coefficient of the bed (yield stress mu_s p_p)", KEY_GT0),        \
    KEY_DBL(T, SEC, "gravity", gravity,                                                         \
            KEY_HELP("gravity g in the grains' buoyant weight p_p = phi (rho_p - rho_f) g (h_p " \
                     "- z)",                                                                    \
                     "length/time^2", NULL),                                                    \
            KEY_GT0)

/* Set A (the parameters of SedFoam's bed-load tutorial), the mixed model,
 * d = 0.065 / 30 and k_CK = 180. */
void bedload_defaults(struct bedload_params *b);

/* The bed module's parameters (physics/bed.h) of b. */
struct bed_params bedload_bed_params(const struct bedload_params *b);

/* Configures the module of b's model (the mixed model's bed, or the
 * two-fluid model); 0, or -1 with the cause. */
int bedload_configure(struct march_state *st, const struct bedload_params *b, char *err,
                      size_t errlen);

/* The checks of the parameters against the case (the two-fluid model in
 * steady mode on nz >= 3, bed inside the channel,
 * grains heavier than the fluid, a pressure gradient along +x, bed load:
 * A > 0 and 0 < delta <= h), each message naming the key as
 * section.key.  Returns 0, or 1 with the message in msg. */
int bedload_check_params(const struct muflow_case *c, const struct bedload_params *b,
                         const char *section, char *msg, size_t msglen);

/* The exact plane solution's constants for the channel of height
 * D = domain.lz. */
struct bedload_exact {
    double D, U0, G, h, eta, A, delta, hc;
};
struct bedload_exact bedload_exact_of(const struct muflow_case *cs, const struct bedload_params *b);
/* u (m/s) at height z. */
double bedload_exact_u(const struct bedload_exact *x, double z);
/* The largest velocity (in the fluid layer). */
double bedload_exact_max(const struct bedload_exact *x);
/* The flow rate per unit width (the exact integral over 0 < z < D). */
double bedload_exact_flow_rate(const struct bedload_exact *x);

/* The measured top of the fixed bed from a profile u(z) at the n heights
 * z (cell centres, from the bottom): the first layer where u rises above
 * BEDLOAD_MOBILE_FRACTION of umax (the largest velocity), then the zero of the straight
 * line through sqrt(u) of it and the layer above (the exact profile is
 * quadratic above the yield surface, so sqrt(u) is linear and its zero is
 * h_c itself).  NaN when no layer rises above it. */
#define BEDLOAD_MOBILE_FRACTION 1e-3
double bedload_bed_top(int n, const double *z, const double *u, double umax);

#endif
