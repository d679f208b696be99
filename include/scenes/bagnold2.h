/* The granular layer under air (scene "bagnold2", cases/bagnold2.ini): the
 * growth of a perturbation of the uniform flow, for the scene, its tests and
 * the study of the rheology's ill-posedness (docs/validation/bagnold2.md,
 * "Ill-posedness of mu(I) as a measured growth rate"). */
#ifndef MUFLOW_SCENES_BAGNOLD2_H
#define MUFLOW_SCENES_BAGNOLD2_H

#include "diagnostics/growth.h"
#include "march/march.h"

/* The amplitudes of the state's departure from a flow uniform along x in
 * the grains: au the largest |v - <v>_x| over their faces (u and w), ap the
 * largest |p - <p>_x| over their cells (NaN without the tracer). */
void bagnold2_amplitudes(const struct march_state *st, double *au, double *ap);

/* The growth becomes nonlinear (its rate falls) once the velocity amplitude
 * exceeds this share of the exact top velocity (docs/validation/bagnold2.md). */
#define BAGNOLD2_SATURATION 0.01

/* The window [t0, t1] of the growth fit of a record of n samples (times t,
 * velocity amplitudes au): t1 the first time au exceeds a_sat, or its own
 * start au[0] if larger (the last sample when it never does), t0 halfway
 * from the first sample to t1; the first half is the initial transient, in
 * which the damped modes decay. */
void bagnold2_growth_window(const double *t, const double *au, long n, double a_sat,
                            double *t0, double *t1);

/* The growth rate of a transient run's record (of au, or of ap with
 * pressure = 1) over bagnold2_growth_window; rate NaN without a record. */
struct growth_fit bagnold2_growth(const struct march_state *st, int pressure);

#endif
