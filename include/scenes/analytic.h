/* Analytic steady solutions of the profile scenes (seeds/000 app. A and B),
 * in the case's units (bulk density rho, gravity g, grain d and rho_s). */
#ifndef MUFLOW_ANALYTIC_H
#define MUFLOW_ANALYTIC_H

#include "config/case.h"

/* Flow velocity of the scene at coordinate x along its profile axis; NaN when
 * the scene has no steady solution (e.g. bagnold above mu_s + dmu). */
double analytic_velocity(const struct muflow_case *cs, double x);

/* Bagnold: surface velocity; chute: plug velocity.  NaN when undefined. */
double analytic_headline(const struct muflow_case *cs);

/* Profile axis and velocity component of a scene (bagnold: z and u; chute:
 * y and w); returns 0, or -1 for SCENE_NONE. */
int scene_profile_axes(enum scene s, int *axis, int *component);

const char *scene_name(enum scene s);
/* Name of the scene's headline value ("u_surface", "u_plug", "psi_max") or NULL. */
const char *scene_headline_name(enum scene s);

/* Name of its RMS error: "err_rms", or "err_midline" for the cavity. */
const char *scene_error_name(enum scene s);

/* Yield-stress number of the cavity in the convention of its reference data
 * (Vola et al.: sqrt(2) times muflow's simple-shear yield stress). */
double cavity_reference_bn(const struct muflow_case *cs);

#endif
