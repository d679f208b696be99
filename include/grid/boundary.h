/* Boundary conditions, one kind per face of the box.
 *
 * wall     no slip: zero velocity on the face (tangential ghost = -interior).
 * slip     free slip / symmetry: zero normal velocity and zero shear stress.
 * surface  flat (rigid-lid) stress-free free surface: zero normal velocity and
 *          zero shear stress like slip, and the hydrostatic pressure vanishes on
 *          it (Dirichlet p = 0 for the hydrostatic solve).
 * lid      a no-slip wall moving in its own plane: the component lid_direction
 *          of the velocity equals lid_velocity on the face (driven cavity).
 * periodic both faces of the direction must be periodic. */
#ifndef MUFLOW_BOUNDARY_H
#define MUFLOW_BOUNDARY_H

#include "grid/grid.h"

enum bc_kind { BC_PERIODIC = 0, BC_WALL, BC_SLIP, BC_SURFACE, BC_LID };

struct boundary {
    enum bc_kind face[3][2]; /* [direction][0 = low, 1 = high] */
    double lid_velocity;     /* tangential speed of every lid face */
    int lid_direction;       /* the velocity component it drives (0, 1, 2) */
};

const char *bc_kind_name(enum bc_kind kind);

/* Fills the ghost layers of the three velocity components (u on x-faces,
 * v on y-faces, w on z-faces) and sets the normal velocity on non-periodic
 * boundary faces to zero. */
void bc_fill_velocity(const struct grid *g, const struct boundary *bc, double *vel[3]);

/* The same for a velocity increment: every prescribed boundary value is zero
 * (a lid does not move the increment). */
void bc_fill_velocity_homogeneous(const struct grid *g, const struct boundary *bc, double *vel[3]);

/* Fills the ghost layer of a cell-centred field: periodic copy, or a mirror of
 * the interior neighbour (zero normal gradient) on every other face. */
void bc_fill_scalar(const struct grid *g, const struct boundary *bc, double *f);

/* Like bc_fill_scalar, but extrapolates linearly across non-periodic faces
 * (ghost = 2 f[0] - f[1]): the pressure that enters the rheology on boundary
 * edges is then second-order accurate, and zero on a free surface. */
void bc_fill_scalar_linear(const struct grid *g, const struct boundary *bc, double *f);

/* The boxes of velocity unknowns: for component c, the faces along c that
 * are not prescribed (see bc_face_active) and every cell across. */
void bc_unknown_boxes(const struct grid *g, const struct boundary *bc, struct box act[3]);

/* 1 when face index i along direction d carries an unknown of the velocity
 * component d (periodic: faces 0..n-1; otherwise interior faces 1..n-1). */
static inline int bc_face_active(const struct boundary *bc, const struct grid *g, int d, int i)
{
    if (bc->face[d][0] == BC_PERIODIC)
        return i >= 0 && i < g->n[d];
    return i >= 1 && i < g->n[d];
}

#endif
