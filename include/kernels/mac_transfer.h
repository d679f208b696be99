/* Transfers between two levels of the velocity multigrid
 * (solvers/velocity_mg.h): a coarse grid halves the fine one along the
 * directions with f[d] = 2 (coarse face I is fine face 2 I, coarse cell I
 * holds fine cells 2 I and 2 I + 1) and keeps it along the others.
 *
 * Prolongation P of a velocity component a is the tensor product of one
 * rule per direction: along a (the nodes are faces) linear between the
 * coarse faces, across (cells) 3/4 and 1/4 of the two nearest coarse
 * cells.  A coarse node that is not an unknown is folded in by the rule
 * its ghost follows (boundary.h): 0 on a closed face, the inner face on an
 * open one, -1 or +1 times the mirror for a tangential component, the
 * periodic image; past a rank border (bc->dc) the neighbour's node in the
 * ghost slot, which the caller fills before a prolongation and hands to its
 * owner after a restriction (decomp_exchange_add).  Restriction is P's transpose over 2^D (D the directions
 * halved): a weighted mean, as the coarse operator is the fine one
 * rediscretised (not summed over the children).
 *
 * The coefficients are carried by means: a cell's over its children (the
 * normal-stress coefficients harmonic, as resistances in series), a face's
 * over the fine faces of its plane, an edge's over the fine edges that lie
 * on it. */
#ifndef MUFLOW_KERNELS_MAC_TRANSFER_H
#define MUFLOW_KERNELS_MAC_TRANSFER_H

#include "grid/boundary.h"
#include "grid/grid.h"

/* The prolongation's weights of component a's fine nodes, per direction d
 * that the coarse level halves (w[d], a field array of the fine grid): the
 * weight of the second coarse node a fine node draws on (along a: the
 * upper face of an odd face; across: the farther coarse cell), the
 * operator-dependent weights of a flux-continuous 1D profile through the
 * node's own couplings (Alcouffe, Brandt, Dendy and Painter 1981): 1/2 and
 * 1/4 where the coefficients are uniform, and a jump in them is followed.
 * A_cell, A_edge, aug: the fine level's coefficients (aug NULL: none).
 * linear 1: the plain weights 1/2 and 1/4; 2: 1/2 along the component and
 * 0 across (the fine faces on a coarse face take its value), which keeps a
 * coarse field's divergence in each fine cell: a divergence-free coarse
 * correction stays one, as the grad-div augmented operator needs.  Past a
 * low rank border w[d] gets the ghost cells' weights too (the low
 * neighbour's last cells, whose profile reads two cells past its block);
 * the high border's last cells are left to them. */
void kernel_prolong_weights(const struct grid *fine, const struct boundary *bc, const int f[3],
                            int a, const struct box *act_f, const double *const A_cell[3],
                            const double *const A_edge[3], const double *aug, int linear,
                            double *w[3]);

/* y (coarse) = P^T x (fine) / 2^D on the coarse box act_c, for component a;
 * w the fine level's weights (kernel_prolong_weights). */
void kernel_restrict_velocity(const struct grid *fine, const struct grid *coarse,
                              const struct boundary *bc, const int f[3], int a,
                              const struct box *act_f, const struct box *act_c,
                              double *const w[3], const double *x, double *y);

/* x (fine) += P y (coarse) on the fine box act_f, for component a. */
void kernel_prolong_velocity(const struct grid *fine, const struct grid *coarse,
                             const struct boundary *bc, const int f[3], int a,
                             const struct box *act_f, const struct box *act_c,
                             double *const w[3], const double *y, double *x);

/* Coarse cell values, the mean of their children (interior cells):
 * arithmetic, or harmonic (0 where a child is 0). */
void kernel_coarsen_cells(const struct grid *fine, const struct grid *coarse, const int f[3],
                          int harmonic, const double *x, double *y);

/* Coarse values on the faces normal to a (faces 0..n along a), the mean of
 * the fine faces of the plane they lie on. */
void kernel_coarsen_faces(const struct grid *fine, const struct grid *coarse, const int f[3],
                          int a, const double *x, double *y);

/* Coarse values on the edges along k (faces 0..n of the two other
 * directions, cells 0..n-1 along k), the mean of the fine edges along k
 * that make them up. */
void kernel_coarsen_edges(const struct grid *fine, const struct grid *coarse, const int f[3],
                          int k, const double *x, double *y);

#endif
