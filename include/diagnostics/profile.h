/* Diagnostics of the profile scenes: the layer-averaged profile along the
 * scene's axis (scenes/scene.h: profile_axis, profile_component, an optional
 * slab such as the cavity's mid-line), its error against the scene's exact
 * or reference profile, and the headline value. */
#ifndef MUFLOW_DIAGNOSTICS_PROFILE_H
#define MUFLOW_DIAGNOSTICS_PROFILE_H

#include "march/march.h"

struct profile {
    int n;                 /* layers (cells along the axis) */
    int axis, component;
    double *coord;         /* cell-centre coordinate along the axis */
    double *velocity;      /* flow component, mean over the layer's nodes */
    double *pressure;      /* total pressure */
    double *shear_rate;    /* |D| */
    double *inertial;      /* I, from |D| and the regularised pressure */
    double *viscosity;
    double *exact;         /* analytic or reference velocity (NaN where undefined) */
    const char *exact_name; /* "exact" or "reference" (scene_solution_name): the
                               column is <component>_<exact_name> in profile.csv */
};

struct scene_errors {
    int valid;             /* the scene has an analytic solution here */
    double err_rms;        /* sqrt(mean (u - u_ex)^2) over layers; for the cavity the
                              RMS difference from the reference curve at its points
                              (err_midline) */
    double err_max;        /* max |u - u_ex| */
    double err_rms_paper;  /* sqrt(sum (u - u_ex)^2) / N, the papers' form */
    double headline, headline_exact;
};

/* The profile along the scene's axis.  Returns 0, or -1 when the scene has
 * no profile or memory runs out. */
int profile_extract(struct profile *pr, const struct march_state *st);
void profile_free(struct profile *pr);

/* The errors and headline of the scene (its errors callback, or the
 * default below). */
void profile_errors(const struct profile *pr, const struct march_state *st, struct scene_errors *e);

/* The default: err_rms, err_max, err_rms_paper of the profile against
 * pr->exact (NaN and valid = 0 where exact is undefined), headline the
 * centre value (profile_centre_value) against exact_centre. */
void profile_errors_default(const struct profile *pr, double exact_centre, struct scene_errors *e);

/* The centre layer, or the mean of the two centre layers (a plug). */
double profile_centre_value(const struct profile *pr);

/* Value at the boundary of a field with zero normal slope there, from the
 * two nearest cell centres (a quadratic a + b s^2 in the distance s through
 * both): u(0) = (9 u(h/2) - u(3h/2)) / 8. */
static inline double profile_zero_slope_end(double nearest, double next)
{
    return (9.0 * nearest - next) / 8.0;
}

/* The scene's exact profile at one coordinate (NaN without one). */
double profile_exact_at(const struct muflow_case *cs, double x);

/* Only the errors (for the history), without keeping a profile. */
void scene_errors_of(const struct march_state *st, struct scene_errors *e);

#endif
