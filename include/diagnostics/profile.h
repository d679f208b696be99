/* Diagnostics of the profile scenes: the layer-averaged profile along the
 * scene's axis, its error against the analytic solution and the headline value. */
#ifndef MUFLOW_PROFILE_H
#define MUFLOW_PROFILE_H

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
    double psi_max;        /* largest |stream function| in the x-z plane (cavity) */
};

struct scene_errors {
    int valid;             /* the scene has an analytic solution here */
    double err_rms;        /* sqrt(mean (u - u_ex)^2) over layers; for the cavity the
                              RMS difference from the reference curve at its points
                              (err_midline) */
    double err_max;        /* max |u - u_ex| */
    double err_rms_paper;  /* sqrt(sum (u - u_ex)^2) / N, the seeds' form */
    double headline, headline_exact;
};

/* The profile along the scene's axis: layer means, or for the cavity the
 * vertical mid-line x = lx/2.  Returns 0, or -1 when the scene has no profile
 * or memory runs out. */
int profile_extract(struct profile *pr, const struct march_state *st);
void profile_free(struct profile *pr);
void profile_errors(const struct profile *pr, const struct muflow_case *cs, struct scene_errors *e);

/* Only the errors (for the history), without keeping a profile. */
void scene_errors_of(const struct march_state *st, struct scene_errors *e);

#endif
