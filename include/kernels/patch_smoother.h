/* The edge-patch smoother of the velocity multigrid (solvers/velocity_mg.h)
 * for the grad-div augmented operator
 *   mass v - div tau(v) - grad(r div v).
 *
 * With r large the operator's near-kernel is the divergence-free fields,
 * which a component-wise smoother cannot reduce: a correction of one
 * component at a time changes the divergence and meets the stiff r.  Those
 * fields are spanned locally by the curls of stream functions at the grid's
 * edges (a 2D flow's cell corners): the curl of one edge's hat function
 * touches the four faces around the edge (two of each in-plane component).
 * Solving those four faces together, for every edge in turn, reduces the
 * near-kernel as well as the rest: the space decomposition that makes
 * multigrid robust in r (Schoeberl 1999, "Multigrid methods for a
 * parameter dependent problem in primal variables"; Arnold, Falk and
 * Winther 2000, "Multigrid in H(div) and H(curl)").
 *
 * A patch is the edge along the plane's normal n at index (i, j, k) of the
 * plane (a, b), a < b: the a-faces at that index and one below along b, the
 * b-faces at that index and one below along a.  Its 4 x 4 block of the
 * symmetric operator (unknown faces only; a face that is not one is an
 * identity row) is factorised once per set-up (Cholesky, PATCH_FACTOR
 * doubles per edge slot).  A sweep visits the patches multiplicatively,
 * in colours whose patches share no coupling (three apart along a and b,
 * two along n), each colour's in parallel: each patch's residual is
 * evaluated on its faces from the own-component stencils
 * (viscous_stencil.h) and the cross-component couplings (the shear's
 * transpose part and the augmentation), the block solved, the faces
 * corrected.
 *
 * The residual of a patch is the operator's exactly where every face that is
 * not an unknown holds 0 (walls, lids, slip faces, inflow) or wraps
 * (periodic): kernel_patch_plane_ok refuses open faces, and the caller
 * leaves out bodies.  Nothing is allocated; uniform spacing. */
#ifndef MUFLOW_KERNELS_PATCH_SMOOTHER_H
#define MUFLOW_KERNELS_PATCH_SMOOTHER_H

#include "grid/boundary.h"
#include "grid/grid.h"
#include "kernels/viscous_stencil.h"

#define PATCH_FACTOR 10 /* the packed lower triangle of a 4 x 4 factor */

/* The symmetric operator's coefficients a sweep reads. */
struct patch_operator {
    const struct own_stencil *st;  /* the three components' stencils */
    const double *A_edge[3];      /* shear coefficients (the operator's) */
    const double *aug;            /* augmentation per cell (ghosts filled), or NULL */
    int skip;                     /* bit c: component c of x is 0 throughout (a plane
                                     flow's third), its couplings not read */
};

/* 1 when the plane normal to n carries patches on g: both in-plane
 * directions of two cells or more (three when periodic), no open face. */
int kernel_patch_plane_ok(const struct grid *g, const struct boundary *bc, int n);

/* The patches' factors of the plane normal to n into fac (PATCH_FACTOR
 * doubles per slot of g).  Returns the number of blocks whose Cholesky met
 * a non-positive pivot (kept by its diagonal's scale). */
long kernel_patch_factor(const struct grid *g, const int periodic[3], const struct box act[3],
                         int n, const struct patch_operator *op, double *fac);

/* One multiplicative sweep over the plane's patches on A x = b, x updated
 * on its unknowns; reverse: the colours in the opposite order. */
void kernel_patch_sweep(const struct grid *g, const int periodic[3], const struct box act[3],
                        int n, const struct patch_operator *op, const double *fac,
                        double *const b[3], double *x[3], int reverse);

/* (A x) at face idx of component c, evaluated as the sweep does (for
 * tests: it must equal the operator's). */
double kernel_patch_row(const struct grid *g, const int periodic[3], const struct box act[3],
                        const struct patch_operator *op, int c, const int idx[3],
                        double *const x[3]);

#endif
