/* The own-component block of the implicit viscous operator, and line
 * Gauss-Seidel on it: the velocity multigrid's smoother
 * (solvers/velocity_mg.h).
 *
 * For velocity component a the symmetric operator (viscous_operator.h)
 *   mass v - div tau(v) - grad(r div v)  [+ a body's terms]
 * couples node P of a to its six neighbours of the same component (the
 * normal stress and the augmentation along a, the shear stresses across)
 * and to the other components (the transpose part of the strain).  The
 * block of a alone is the seven-point stencil
 *   diag[P] v_P - sum_d (cp[d][P] v_{P+e_d} + cm[d][P] v_{P-e_d}),
 * computed here from the coefficients, with the boundary conditions folded
 * in: a neighbour that is not an unknown gets coupling 0, and the value a
 * ghost takes (-v_P at a wall, +v_P at a slip face, the inner face's at an
 * open one, 0 on a closed face) moves its share into diag.  A periodic
 * neighbour wraps around (on one rank); past a rank border (bc->dc) the
 * neighbour's node in the ghost slot is coupled as an unknown, and a line
 * ends at the border (the neighbour's part of a sweep is 0 there).  A body's held node is a row of the mass alone,
 * and its neighbours' couplings to it are 0 (it is held at 0).
 *
 * Nothing is allocated; every array is a field array of g (grid.h). */
#ifndef MUFLOW_KERNELS_VISCOUS_STENCIL_H
#define MUFLOW_KERNELS_VISCOUS_STENCIL_H

#include "grid/boundary.h"
#include "grid/grid.h"
#include "kernels/embedded.h"

struct own_stencil {
    double *diag;
    double *cp[3]; /* coupling to the neighbour at +e_d (0: none) */
    double *cm[3]; /* to the neighbour at -e_d */
};

/* The coefficients one level's symmetric operator reads (viscous_problem's,
 * without the full tangent). */
struct stencil_coefficients {
    const double *A_cell[3];
    const double *A_edge[3];
    const double *mass_face; /* of component a, or NULL: mass */
    double mass;
    const double *aug;       /* or NULL */
    const struct embedded *e; /* or NULL */
    const unsigned char *held; /* of component a: 1 at a held node (NULL: none) */
};

/* The stencil of component a on its box of unknowns act_a. */
void kernel_own_stencil(const struct grid *g, const struct boundary *bc, const struct box *act_a,
                        int a, const struct stencil_coefficients *k, struct own_stencil *out);

/* The lines along L of the stencil factorised (Thomas' elimination):
 * inv_b the reciprocal pivots, cprime the eliminated upper couplings. */
struct line_factors {
    double *inv_b, *cprime;
};
void kernel_line_factor(const struct grid *g, const struct box *act_a, int L,
                        const struct own_stencil *s, struct line_factors *f);

/* One line Gauss-Seidel sweep along the non-periodic direction L on
 * A_aa d = r over the box act_a, with the lines' factors f: the lines in
 * two colours (red-black across them, each colour's lines in parallel),
 * then, serially, the lines next to the seam of a periodic direction across
 * of odd length; reverse: the colours in the opposite order (the symmetric
 * cycle's post-smoother).  d is read and written on the box. */
void kernel_line_gauss_seidel(const struct grid *g, const int periodic[3], const struct box *act_a,
                              int L, const struct own_stencil *s, const struct line_factors *f,
                              const double *r, double *d, int reverse);

#endif
