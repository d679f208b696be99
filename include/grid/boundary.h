/* Boundary conditions, one kind per face of the box.
 *
 * wall     no slip: zero velocity on the face (tangential ghost = -interior).
 * slip     free slip / symmetry: zero normal velocity and zero shear stress.
 * surface  flat (rigid-lid) stress-free free surface: zero normal velocity and
 *          zero shear stress like slip, and the hydrostatic pressure vanishes on
 *          it (Dirichlet p = 0 for the hydrostatic solve).
 * lid      a no-slip wall moving in its own plane: the component lid_direction
 *          of the velocity equals lid_velocity on the face (driven cavity).
 * open     an open boundary (outflow, open top): the dynamic pressure
 *          vanishes on the face (Dirichlet p = 0 for the projection and the
 *          hydrostatic solve), every velocity component has zero normal
 *          gradient, and the normal velocity on the face is not prescribed:
 *          it is state, set by the projection, so mass leaves or enters.
 * inflow   a prescribed velocity: the normal component is inflow_velocity
 *          (into the domain) times the profile, the tangential ones are zero
 *          (no slip); a Neumann face for the pressure, like a wall.
 * periodic both faces of the direction must be periodic. */
#ifndef MUFLOW_BOUNDARY_H
#define MUFLOW_BOUNDARY_H

#include "grid/decomp.h"
#include "grid/grid.h"

enum bc_kind { BC_PERIODIC = 0, BC_WALL, BC_SLIP, BC_SURFACE, BC_LID, BC_OPEN, BC_INFLOW };

/* The inflow's profile across the face: uniform, or the parabola
 * 4 s (L - s) / L^2 in each non-periodic tangential direction (a product of
 * them in 3D), 1 at the middle, 0 on the edges. */
enum inflow_profile { INFLOW_UNIFORM = 0, INFLOW_PARABOLIC };

struct boundary {
    enum bc_kind face[3][2]; /* [direction][0 = low, 1 = high] */
    double lid_velocity;     /* tangential speed of every lid face */
    int lid_direction;       /* the velocity component it drives (0, 1, 2) */
    double inflow_velocity;  /* normal speed into the domain on inflow faces (peak) */
    enum inflow_profile inflow_profile;
    /* a scene's inflow (NULL: inflow_velocity times inflow_profile): the
     * normal speed into the domain at the centre x of a face of direction d,
     * for a shape no key describes (a granular layer's Bagnold profile) */
    double (*inflow_shape)(const void *ctx, int d, const double x[3]);
    const void *inflow_ctx;
    /* the ranks' decomposition of the grid (NULL: one process holds it): a
     * fill takes a rank border's ghosts from the neighbour (decomp_exchange),
     * the face's condition on the domain's own faces only (a bounded
     * direction split: the condition on its end ranks' outer sides); a
     * periodic direction split over ranks wraps through its ranks */
    const struct decomp *dc;
};

/* 1 when direction d of bc's grid is split over ranks (its ghosts on a
 * rank border are the neighbour's). */
static inline int bc_split(const struct boundary *bc, int d)
{
    return bc->dc && (bc->dc->border[d][0] || bc->dc->border[d][1]);
}

/* 1 when side s of direction d is a rank border: its ghosts are the
 * neighbour's nodes (unknowns there), not a condition's image. */
static inline int bc_border(const struct boundary *bc, int d, int s)
{
    return bc->dc && bc->dc->border[d][s];
}

/* 1 when direction d wraps on this grid: periodic and held by one rank
 * (split over ranks, its wrap goes through the neighbours' ghosts). */
static inline int bc_wraps(const struct boundary *bc, int d)
{
    return bc->face[d][0] == BC_PERIODIC && !bc_split(bc, d);
}

const char *bc_kind_name(enum bc_kind kind);

/* Fills the ghost layers of the three velocity components (u on x-faces,
 * v on y-faces, w on z-faces) and sets the normal velocity on non-periodic
 * boundary faces: zero on closed ones, the profile on inflow faces; an open
 * face's normal velocity is state and is left as it is. */
void bc_fill_velocity(const struct grid *g, const struct boundary *bc, double *vel[3]);

/* The same for a velocity increment: every prescribed boundary value is zero
 * (a lid or an inflow does not move the increment); an open face's normal
 * velocity is not an unknown of the implicit step, and its increment is the
 * inner face's (zero normal gradient: the step moves the face with the flow
 * it solves for; the projection then corrects it, stage_projection.c). */
void bc_fill_velocity_homogeneous(const struct grid *g, const struct boundary *bc, double *vel[3]);

/* bc_fill_velocity_homogeneous's ghosts of component c alone, across the
 * two directions other than c (a cross-section's flow component along its
 * one-cell periodic direction: what kernel_flow_block reads; the two
 * ghost planes along c are whole planes of the layout). */
void bc_fill_increment_component(const struct grid *g, const struct boundary *bc, double *vel[3],
                                 int c);

/* The increment's fill with the open faces' normal increments given (kept
 * as they are): the operator's response to an open face's own increment
 * (the coupled step's columns of it, stage_coupled.c). */
void bc_fill_velocity_open_given(const struct grid *g, const struct boundary *bc, double *vel[3]);

/* Fills the ghost layer of a cell-centred field: periodic copy, or a mirror of
 * the interior neighbour (zero normal gradient) on every other face. */
void bc_fill_scalar(const struct grid *g, const struct boundary *bc, double *f);

/* Like bc_fill_scalar, but a Dirichlet ghost (-interior, zero on the face)
 * on open faces: for the projection's pressure and its increments. */
void bc_fill_pressure(const struct grid *g, const struct boundary *bc, double *f);

/* 1 when some face of bc is open. */
int bc_has_open(const struct boundary *bc);

/* 1 when a face of kind k lets mass through (open or inflow). */
int bc_kind_passes_flow(enum bc_kind k);
/* 1 when some face of bc lets mass through. */
int bc_passes_flow(const struct boundary *bc);

/* periodic[d] = 1 for each direction d that is periodic (both faces are). */
void bc_periodic_flags(const struct boundary *bc, int periodic[3]);

/* 1 when direction d lets a mean flow through: periodic, or open at both
 * ends (a direction bounded otherwise holds a body force by its pressure). */
int bc_through_flow(const struct boundary *bc, int d);

/* The inflow's normal velocity (into the domain, sign not applied) on face
 * (i, j, k) of direction d: inflow_velocity times the profile, or the
 * scene's inflow_shape at the face's centre. */
double bc_inflow_value(const struct grid *g, const struct boundary *bc, int d, int i, int j, int k);

/* Like bc_fill_scalar, but extrapolates linearly across non-periodic faces
 * (ghost = 2 f[0] - f[1]): the pressure that enters the rheology on boundary
 * edges is then second-order accurate, and zero on a free surface. */
void bc_fill_scalar_linear(const struct grid *g, const struct boundary *bc, double *f);

/* The boxes of velocity unknowns: for component c, the faces along c that
 * are not prescribed (see bc_face_active) and every cell across; on a rank
 * border's side face 0 is this rank's unknown, face n the neighbour's. */
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
