/* A uniform granular layer under air fed at the inflow face x = 0 of a
 * two-phase incline (scenes front and wall_shock; Barker & Rauter 2018,
 * "Two-fluid regularised mu(I)-rheology with OpenFOAM", sec. 4): the exact
 * uniform two-layer flow (Bagnold in the grains, the air's gravity-driven
 * film above them under the open top), the feed column that holds it, the
 * column heights' crossings, and the time series a scene records at every
 * step (saved and restored with a checkpoint). */
#ifndef MUFLOW_SCENES_LAYER_FEED_H
#define MUFLOW_SCENES_LAYER_FEED_H

#include "march/march.h"
#include "march/module_record.h"
#include "physics/two_phase.h"

/* The layer: the case (its tilt, gravity, grains and box height lz) and
 * the scene's depth and air.  A scene keeps it for the run: it is the
 * inflow hook's context. */
struct layer_feed {
    const struct muflow_case *cs;
    double depth;           /* the fed layer's depth */
    double fluid_density;   /* rho_f of the air */
    double fluid_viscosity; /* eta_f */
};

/* The checks a scene of a fed layer (scene names it) makes of the case:
 * mu(I) in transient mode; the inflow at x = 0, face xhi at x = lx (its
 * key's value xhi_name), a wall below, an open top, periodic y of one cell;
 * a tilt whose uniform flow neither stops nor accelerates; the bulk density
 * phi rho_s.  0, or 1 with the message naming the key. */
int layer_feed_check(const struct muflow_case *c, const char *scene, enum bc_kind xhi,
                     const char *xhi_name, char *msg, size_t msglen);

/* I of the uniform flow: the curve's inverse at tan(tilt). */
double layer_uniform_i(const struct muflow_case *cs);

/* u(z) of the uniform two-layer flow of depth h under the open top at lz
 * (bagnold2's solution: the weight above as the stress, Bagnold in the
 * grains, the air's film above). */
double layer_uniform_u(const struct layer_feed *lf, double h, double z);

/* The grains' mean speed in the uniform layer of depth h. */
double layer_uniform_mean(const struct layer_feed *lf, double h);

/* The share of cell k (height dz, from the base) under the level h. */
double layer_fraction(double h, int k, double dz);

/* The two_phase module configured for the layer (the grains' viscosity at
 * least floor rho_g d sqrt(g d), on the bed at its hydrostatic pressure if
 * bed_pressure, the VOF's sweep CFL at most vof_cfl) and
 * the inflow face's normal velocity set to the uniform layer's (ctx lf,
 * which must outlive the run); T, or NULL with err. */
double *layer_feed_configure(struct march_state *st, const struct layer_feed *lf, int mixture,
                             double floor, int bed_pressure, double vof_cfl, char *err,
                             size_t errlen);

/* The feed: the first column's T back to the layer of depth lf->depth
 * (the VOF brings only air in through an inflow face).  Call after every
 * step. */
void layer_feed_hold(struct march_state *st, const struct layer_feed *lf);

/* The column heights h[i] = sum T dz (over k, and y's mean) of the whole
 * domain's columns (the global grid's n[0]), and with flux the grains'
 * fluxes h[n[0] + i] = sum_k T u dz (u the mean of the cell's two x faces,
 * y = 0: domain.ny = 1): this rank's part of each column summed over the
 * ranks, the same on every rank.  Collective. */
void layer_columns(const struct march_state *st, const double *T, double *h, int flux);

/* The last x, from downstream, where the column heights h (at the centres
 * (i + 1/2) dx) reach level; linear between the centres; 0 if none does. */
double layer_crossing(const double *h, int n, double dx, double level);

/* Time series of up to LAYER_SERIES_MAX named columns, one row a step. */
#define LAYER_SERIES_MAX 8
struct layer_series {
    int ncol;
    const char *const *names;
    double *v[LAYER_SERIES_MAX];
    long n, cap;
    long last_step; /* the step of the last row, -1 before any */
};

void layer_series_init(struct layer_series *s, int ncol, const char *const *names);
void layer_series_free(struct layer_series *s);
/* Room for need rows; 0 or -1 (out of memory). */
int layer_series_reserve(struct layer_series *s, long need);
/* A new row for step (its values set by the caller through v[m][n - 1]);
 * 0, 1 if step is the last row's already, -1 out of memory. */
int layer_series_row(struct layer_series *s, long step);
int layer_series_save(const struct layer_series *s, struct module_record *rec);
/* The series from rec (-1 if there is none: the record covers the run from
 * its start). */
int layer_series_load(struct layer_series *s, struct module_record *rec);
/* The least-squares slope of column y against column x over rows with x >= x0. */
double layer_series_slope(const struct layer_series *s, int x, int y, double x0);

/* The head of a fed-layer scene's module state, its first member, so that
 * the hooks below take the state as the march hands it: the step record
 * and the feed. */
struct layer_record {
    struct layer_series s;
    struct layer_feed feed;
};
/* The module hooks of such a state: the feed held after every step
 * (layer_feed_hold); the record saved into and loaded from the checkpoint
 * (a checkpoint without it: -1, the record covers the run from its start). */
void layer_record_end_step(struct march_state *st, void *state, double dt);
int layer_record_save(const struct march_state *st, void *state, struct module_record *rec);
int layer_record_load(struct march_state *st, void *state, struct module_record *rec);

#endif
