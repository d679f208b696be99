/* Forces on the case's obstacles (physics/obstacle.h), per unit length of
 * the extrusion, from the steady state of a march:
 *
 * - surface: the traction integrated over the body's surface as the
 *   discretisation applies it.  Every term of the momentum residual (the
 *   stress, the pressure gradient, the conservative advection, the cut
 *   cells' grad-div) is a flux between two neighbouring nodes, so the
 *   fluxes between fluid nodes and the body's held nodes are the body's
 *   discrete surface: the force is their sum, the cut links' Gibou
 *   corrections with it.  It is the force the discrete momentum balance
 *   puts on the body, so it converges as the flow does (second order:
 *   README, "Flow past a cylinder"); pressure_part is the pressure
 *   gradient's share.  That split is the staircase's (the pressure of the
 *   cut cells, the rest in the viscous fluxes), not the smooth surface's.
 * - reconstructed: the traction sigma n = -p n + eta du/dn sampled around
 *   the body's outline (finely; the midpoint rule on a smooth periodic
 *   integrand).  At a no-slip surface the velocity's gradient is du/dn n^T
 *   alone and du_n/dn = 0 (continuity), so the viscous traction is
 *   eta du/dn; du/dn from the quadratic through u = 0 on the surface and
 *   the velocity interpolated at 1.5 h and 3 h along the normal, p
 *   extrapolated linearly from the same two points.  The pointwise
 *   pressure and shear around the body (obstacle_surface.csv); its
 *   integral converges slowly, the fields within a few cells of the
 *   body being the least accurate (docs/numerics/obstacles.md).
 * - control volume: the momentum balance of the fluid in a box around the
 *   body, F = surface integral over the box of (sigma n - rho u (u . n)),
 *   midpoint rule on the grid's faces (second order): a check of the
 *   surface integral on a surface away from the body (it agrees with it
 *   as far as the scheme conserves momentum and the state is steady).
 *   With a body force, its share on the fluid in the box is added.
 * A body whose centre lies on a slip face of the box (a symmetry plane: the
 * run holds half of a symmetric flow) has its outline sampled in the box,
 * the box's side on that face (no momentum along the face crosses it), and
 * the whole body's forces reported: twice the half's along the plane, 0
 * across it; the front and back points along a are then not both there.
 * Coefficients 2 F / (rho U^2 D) with U the inflow's mean velocity (2/3 of
 * the peak of a parabola across one direction) and D the bodies' extent
 * across the flow (direction b of the plane). */
#ifndef MUFLOW_PHYSICS_OBSTACLE_FORCES_H
#define MUFLOW_PHYSICS_OBSTACLE_FORCES_H

#include <stddef.h>
#include "march/march.h"
#include "march/results.h"

struct obstacle_forces {
    double surface[2];        /* along the plane's a (drag) and b (lift) */
    double pressure_part[2];  /* the pressure gradient's share of surface */
    double reconstructed[2];  /* the sampled traction's integral */
    double reconstructed_pressure[2];
    double control_volume[2];
    double front_back;        /* p at the front point less p at the back point, each
                                 by the normal momentum balance from 6 h out
                                 (uniform eta and rho), else extrapolated */
    double u_ref, d_ref;      /* the coefficients' velocity and length (0: none) */
    int mirror[2];            /* a symmetry plane normal to a / b (-1: the low
                                 face, 1: the high one, 0: none): the run holds
                                 half the body, the forces are the whole's */
};

/* Returns 0, -1 when some sample's interpolation reached into the body
 * (a body thinner than a few cells: the reconstructed traction misses
 * them), -2 when out of memory for the surface's sum (then 0). */
int obstacle_forces(const struct march_state *st, struct obstacle_forces *f);

/* obstacle_forces without the reconstructed traction and the control
 * volume (their members 0): the surface integral, front_back and the
 * scales, each the same number as obstacle_forces gives, at a fraction of
 * its cost (a record of every step). */
int obstacle_forces_surface(const struct march_state *st, struct obstacle_forces *f);

/* The scales and symmetry planes of obstacle_forces alone (u_ref, d_ref,
 * mirror; the forces 0), from the case and the grid: what names the
 * force lines, on one rank of many too (not collective). */
void obstacle_forces_scales(const struct march_state *st, struct obstacle_forces *f);

/* The mean over the box of the velocity component the body force drives
 * (the body's own faces hold 0), signed along the force: a flow rate per
 * unit area across the flow.  NaN without a force along that component. */
double obstacle_mean_velocity(const struct march_state *st);

/* The summary lines of a body in a flow: drag_force along the flow
 * (positive downstream: the inflow's direction, else the body force's),
 * lift_force across it in the plane (positive along the grid's axis), each
 * by the surface integral, the reconstructed traction (_reconstructed) and
 * the control volume (_control_volume); the coefficients, pressure_drop
 * (a flow along the plane's first direction) and mean_velocity.  With the
 * flow along the extrusion, or none, the forces are named by their axes
 * (force_x, force_x_control_volume, ...).  A wall around the fluid
 * (obstacle.invert) has none of these lines. */
void obstacle_results(const struct march_state *st, struct result_values *res);

/* The summary's headline force lines of f (obstacle_results' names and
 * numbers, from f's surface integral): drag_force, lift_force, then
 * drag_coefficient and lift_coefficient (an inflow: a velocity scale) and
 * pressure_drop (the flow along the plane's first direction, no symmetry
 * plane across it); force_<axis> twice without a flow in the plane.  None
 * (n = 0) without a body in a flow (no shapes, obstacle.invert). */
#define OBSTACLE_FORCE_LINES 5
struct obstacle_force_lines {
    int n;
    const char *name[OBSTACLE_FORCE_LINES];
    double value[OBSTACLE_FORCE_LINES];
};
void obstacle_force_lines(const struct march_state *st, const struct obstacle_forces *f,
                          struct obstacle_force_lines *l);

/* obstacle_surface.csv in dir: per sample, its angle, position, p, the
 * normal and tangential stresses.  Returns 0, or -1 with the cause.  On
 * ranks every rank calls it (the samples read every block), rank 0 writes;
 * so do the forces above, every rank with the same numbers. */
int obstacle_write(const char *dir, const struct march_state *st, char *err, size_t errlen);

#endif
