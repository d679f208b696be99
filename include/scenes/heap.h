/* Diagnostics of the heap scene: surface flow on a heap between rough side
 * walls.  The cross-section is y (across the channel: side wall at y = 0,
 * mid-plane of symmetry at y = ly) by z (up: static base at z = 0, flat free
 * surface at z = lz); the flow u runs along the periodic x.
 *
 * Flowing depth: the depth below the free surface at which the velocity of a
 * column first falls to `fraction` times that column's surface velocity
 * (linear interpolation between cell centres; lz when it never does). */
#ifndef MUFLOW_HEAP_H
#define MUFLOW_HEAP_H

#include "march/march.h"

/* [heap]: the scene's own keys (case_scene_params of a heap case). */
struct heap_params {
    double flow_rate;    /* target Q* = Q / (d sqrt(g d)) per unit width; 0: no
                            search, solve at physics.tilt */
    double tilt_min, tilt_max; /* bracket of the tilt search (rad) */
    double flow_rate_tolerance; /* relative, on Q* */
    int max_solves;      /* steady solves the search may take */
    double depth_fraction; /* flowing depth: where u falls to this fraction of
                              the column's surface velocity */
};

struct heap_profile {
    int n;                 /* columns across the channel (cells along y) */
    double *y;             /* cell-centre distance from the side wall */
    double *u_surface;     /* free-surface velocity of the column */
    double *depth;         /* flowing depth of the column */
    double u_surface_mid;  /* both at the mid-plane y = ly (zero slope there) */
    double depth_mid;
};

/* Dimensionless flow rate per unit width Q* = Q / (d sqrt(g d)), Q the volume
 * flux along x divided by the width (half-width ly: the mid-plane is a
 * symmetry plane, so the whole channel has the same Q). */
double heap_flow_rate(const struct march_state *st);

/* Returns 0, or -1 when memory runs out or the grid has fewer than two cells
 * in y or z. */
int heap_profile_extract(struct heap_profile *hp, const struct march_state *st, double fraction);
void heap_profile_free(struct heap_profile *hp);

#endif
