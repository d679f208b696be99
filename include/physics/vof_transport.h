/* Transport of the volume fraction T (1 = grains, 0 = air) over whole time
 * steps: owns the work arrays of the VOF kernels (kernels/vof.h), fills the
 * ghost layers, and runs one conservative sweep per direction that has more
 * than one cell, in the order x, y, z on even steps and z, y, x on odd ones
 * (alternating the order cancels the leading splitting error, Strang-like,
 * over pairs of steps).
 *
 * Fluxes for the momentum of a two-phase flow: flux[d] holds, on the faces of
 * direction d (face i = low face of cell i, faces 0..n[d]), the grain volume
 * per unit area and time that crossed it in d's sweep of the last step, in
 * the units of the velocity.  The mass flux consistent with the transported
 * density rho = rho_air + (rho_grains - rho_air) T is then
 *   rho_air u_d + (rho_grains - rho_air) flux[d]
 * on the same faces, sweep by sweep in the order given by order[].  Over a
 * whole step T (hence rho) is conserved to round-off when the velocity is
 * discretely divergence-free; within a step the intermediate T of one sweep
 * is not (the divergence term of Weymouth & Yue cancels only across the
 * sweeps). */
#ifndef MUFLOW_VOF_TRANSPORT_H
#define MUFLOW_VOF_TRANSPORT_H

#include "grid/boundary.h"
#include "grid/grid.h"

struct vof_transport {
    const struct grid *g;
    const struct boundary *bc;
    double *normal[3];  /* interface normal per cell (work) */
    double *alpha;      /* plane constant per cell (work) */
    double *indicator;  /* c_c of the current step (work) */
    double *flux[3];    /* T flux per face of each direction, last step */
    long steps;         /* steps taken; its parity decides the sweep order */
    int nsweeps;        /* sweeps of the last step (directions with n > 1) */
    int order[3];       /* their directions, in the order they ran */
    double cfl[3];      /* sweep CFL numbers of the last step (or refusal) */
};

/* Allocates the work arrays for grid g and boundary bc (both must outlive
 * vt); returns 0, or -1 when memory runs out (vt then holds nothing). */
int vof_transport_init(struct vof_transport *vt, const struct grid *g, const struct boundary *bc);
void vof_transport_free(struct vof_transport *vt);

/* One step of length dt with the face velocity vel (ghost faces filled, e.g.
 * by bc_fill_velocity; closed boundary faces carry no flux, open and inflow
 * faces let the light phase, T = 0, in and any phase out).  T
 * is a cell field; its ghost layer is refilled before each sweep.  Returns 0,
 * or -1 without touching T when a sweep CFL number exceeds VOF_CFL_MAX.
 * *max_cfl (if not NULL) receives the largest sweep CFL number either way. */
int vof_transport_step(struct vof_transport *vt, double *T, double *const vel[3], double dt,
                       double *max_cfl);

#endif
