/* Diagnostics of the profile scenes: the layer-averaged profile along an
 * axis (a scene's: scenes/scene.h, scene_profile, which hands its axis,
 * component, an optional slab such as the cavity's mid-line and its exact
 * or reference profile), its error against that profile, and the headline
 * value. */
#ifndef MUFLOW_DIAGNOSTICS_PROFILE_H
#define MUFLOW_DIAGNOSTICS_PROFILE_H

#include "io/output.h"
#include "march/march.h"

/* What a profile is taken along, and compared with. */
struct profile_spec {
    int axis, component;   /* -1: no profile */
    /* limits the profile to the faces and cells of index in [lo, hi] along
     * slab_axis; NULL: every layer's full mean */
    void (*slab)(const struct grid *g, int faces[2], int cells[2]);
    int slab_axis;
    /* u at the n coordinates x along the axis (NaN where undefined); NULL:
     * none */
    void (*exact)(const struct muflow_case *cs, int n, const double *x, double *u);
    const char *exact_name; /* "exact" or "reference" */
};

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
    const char *exact_name; /* "exact" or "reference" (the spec's): the column is
                               <component>_<exact_name> in profile.csv */
};

/* The profile of spec.  Returns 0, or -1 when spec has no profile or memory
 * runs out. */
int profile_extract(struct profile *pr, const struct march_state *st,
                    const struct profile_spec *spec);
void profile_free(struct profile *pr);
/* profile.csv in dir (a whole file, or none: io/output.h). */
int profile_write(const char *dir, const struct profile *pr, char *err, size_t errlen);

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

#endif
