/* Geometric multigrid for the implicit viscous step, matrix-free: every
 * velocity component on the MAC grid at once, coupled through the
 * variable-coefficient stress.
 *
 * Levels: the grid halved along each direction of even length (at least
 * 4 cells) until at most coarse_cells remain; each coarse level is a grid
 * of its own with the same boundary conditions, on which the operator of
 * viscous_operator.h is rediscretised from coefficients carried down by
 * means (mac_transfer.h): the cells' normal-stress coefficients and the
 * augmentation over their children, the edges' shear coefficients over the
 * fine edges on them, a face's mass over the fine faces of its plane.  A
 * body's held nodes carry down where at least half the fine nodes of a
 * coarse face are held; its cut links and cut cells stay on the finest
 * level.
 *
 * Smoother: Gauss-Seidel over the components, each block solved
 * approximately by line Gauss-Seidel along every bounded direction in turn
 * (kernels/viscous_stencil.h) on the residual of the whole operator, so
 * the coupling between components enters through the residual, the stiff
 * and anisotropic part along the lines.  With the grad-div augmentation
 * (and no body or open face) the smoother is the edge patches'
 * (kernels/patch_smoother.h) instead, and the prolongation keeps the
 * divergence (linear along a component, constant across): the augmented
 * operator's near-kernel, the divergence-free fields, is then smoothed and
 * carried to the coarse levels.  Transfers: mac_transfer.h.  The
 * coarsest level is solved by the probed sparse Cholesky factorisation of
 * its operator (a few hundred unknowns).
 *
 * The multigrid works on the symmetric operator: with Newton's full
 * tangent, its symmetric part (pb->sym_cell, sym_edge) is what the cycle
 * approximates and the Krylov method (solvers/viscous_krylov.c) solves the
 * tangent.  The cycle is symmetric (the post-smoother the pre-smoother's
 * reverse), so it preconditions conjugate gradients too.
 *
 * On MPI ranks (bc->dc split, bounded directions too) the levels are the
 * ranks' blocks halved in place (decomp_coarsen) while the global level
 * above has over 4,096 cells; the last kept is gathered on every rank and
 * cycled by a serial hierarchy of its global grid.  The fills exchange at
 * rank borders, the lines are cut there, a restriction's sums on ghosts go
 * to their owners; the cycle is the serial one but for the cut lines
 * (docs/numerics/velocity-multigrid.md).  No body or augmentation there. */
#ifndef MUFLOW_VELOCITY_MG_H
#define MUFLOW_VELOCITY_MG_H

#include <stddef.h>
#include "grid/boundary.h"
#include "grid/grid.h"
#include "solvers/viscous_operator.h"

struct velocity_mg_options {
    int pre, post;       /* smoothing steps before and after the coarse correction */
    long coarse_cells;   /* stop coarsening at or below this many cells */
};

void velocity_mg_default_options(struct velocity_mg_options *o);

struct velocity_mg;

/* The hierarchy for grid g, conditions bc and unknowns act (opt NULL: the
 * defaults).  Returns 0, or -1 with a message. */
int velocity_mg_create(struct velocity_mg **out, const struct grid *g, const struct boundary *bc,
                       const struct box act[3], const struct velocity_mg_options *opt, char *err,
                       size_t errlen);
void velocity_mg_destroy(struct velocity_mg *m);

/* Takes pb's symmetric operator: the coefficients carried to every level,
 * the stencils and the coarsest factorisation.  Returns 0, or -1 with a
 * message. */
int velocity_mg_setup(struct velocity_mg *m, const struct viscous_problem *pb, char *err,
                      size_t errlen);

/* z ~ A^-1 r by one cycle from z = 0 (r read on the unknowns' boxes, z's
 * boxes written). */
void velocity_mg_cycle(struct velocity_mg *m, double *const r[3], double *z[3]);

int velocity_mg_levels(const struct velocity_mg *m);
void velocity_mg_level_size(const struct velocity_mg *m, int l, int n[3]);
/* Bytes held. */
size_t velocity_mg_bytes(const struct velocity_mg *m);
/* Bytes velocity_mg_create and setup would hold on g (bc NULL: every
 * direction of two cells or more taken as a line direction, an upper bound). */
double velocity_mg_memory_estimate(const struct grid *g, const struct boundary *bc,
                                   const struct velocity_mg_options *opt);

#endif
