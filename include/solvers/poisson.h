/* Pressure Poisson solver by FFTW real-to-real transforms.
 *
 * Solves the standard second-order (7-point) Laplacian on cell centres,
 *   sum_d (phi[i+1] - 2 phi[i] + phi[i-1]) / h_d^2 = rhs,
 * with per-face conditions chosen through the transform kind of each direction:
 *   periodic/periodic   DFT (R2HC / HC2R)
 *   neumann/neumann     DCT-II / DCT-III (REDFT10 / REDFT01)
 *   dirichlet/dirichlet DST-II / DST-III (RODFT10 / RODFT01)
 *   neumann/dirichlet   DCT-IV (REDFT11), dirichlet/neumann DST-IV (RODFT11)
 * Neumann: zero normal gradient on the face; Dirichlet: phi = 0 on the face
 * (ghost = -interior).  Planned once per grid, no allocation in solve. */
#ifndef MUFLOW_POISSON_H
#define MUFLOW_POISSON_H

#include "grid/grid.h"

enum poisson_bc { POISSON_PERIODIC = 0, POISSON_NEUMANN, POISSON_DIRICHLET };

struct poisson_fft;

/* Plans the transforms for grid g and conditions bc[d][side].  Returns 0, or
 * -1 with a message in err (size errlen) for an invalid combination (periodic on
 * one side only) or a planning failure. */
int poisson_fft_create(struct poisson_fft **out, const struct grid *g,
                       const enum poisson_bc bc[3][2], char *err, size_t errlen);

/* Solves lap(phi) = rhs.  rhs and phi are field arrays in the layout of grid.h
 * (only interior cells are read / written; phi's ghosts are left alone); phi
 * may alias rhs.  Without a Dirichlet face the problem is singular: the mean of
 * rhs is removed and phi is returned with zero mean. */
void poisson_fft_solve(struct poisson_fft *ps, const double *rhs, double *phi);

void poisson_fft_destroy(struct poisson_fft *ps);

#endif
