/* Solid obstacles inside the box (case section [obstacle], grid/shapes.h): a
 * physics module that every case with shapes gets (scenes/scene.h:
 * scene_march_setup adds it; a case without shapes runs without it).
 *
 * - Velocity nodes inside the body (distance <= 0) are held at 0: not
 *   unknowns of the implicit step (kernels/embedded.h), their residual 0,
 *   and closed faces for the projection.
 * - sharp: every grid link from a fluid node to a held one ends on the
 *   surface, where the velocity is 0 (the diagonal correction of
 *   kernels/embedded.h), so no slip holds at the true surface;
 *   staircase: none (the held nodes' 0 is the condition, first order).
 * - The projection takes the face coefficient beta = 0 on the held faces
 *   (the multigrid path: an obstacle leaves the FFT solver), so div u = 0 in
 *   every cell with the held faces closed.
 * The forces on the body and the surface record are obstacle_forces.h. */
#ifndef MUFLOW_PHYSICS_OBSTACLE_H
#define MUFLOW_PHYSICS_OBSTACLE_H

#include <stddef.h>
#include "grid/shapes.h"
#include "march/march.h"

extern const struct module obstacle_module;

/* Bytes the body adds to a run on g, bounded from above from the case
 * alone (no geometry is computed): its arrays, its held nodes (at most
 * every node), its cut links (at most two per shape and grid line of the
 * plane: each shape is convex) and the variable-coefficient projection a
 * body implies (two multigrid pressure solvers while the hydrostatic split
 * runs beside the projection's). */
double obstacle_memory_bound(const struct muflow_case *cs, const struct grid *g);

/* Position of node (i, j, k) of velocity component c (c = -1: the cell
 * centre), the box's low corner at the origin. */
void obstacle_node_position(const struct grid *g, int c, int i, int j, int k, double x[3]);
/* The same of a block whose cell 0 is the whole grid's cell lo (a rank's
 * block, grid/decomp.h): global indices, so every rank places a node as
 * one process does, to the bit. */
void obstacle_node_position_at(const struct grid *g, const int lo[3], int c, int i, int j, int k,
                               double x[3]);

#endif
