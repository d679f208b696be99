/* Plane Fourier modes times line blocks: a preconditioner of the implicit
 * viscous operator (the symmetric one: per-component tangent, grad-div
 * augmentation) for grids periodic in the two directions across the lines
 * (a layer on an incline: periodic x and y, lines along z).
 *
 * The operator's couplings, averaged over the periodic planes, make an
 * operator that commutes with the shifts along x and y: in the planes'
 * Fourier modes it is one banded block along the lines per mode, the three
 * velocity components coupled (interleaved node by node: a band of 5).  The
 * averaged couplings come from probing, as the line blocks' do: comb
 * vectors along the lines (every third node), on one component at a time,
 * each also times (-1)^i across the first, the second and both periodic
 * directions (36 operator applications); the responses of all three
 * components, averaged over the lines, are the block at the plane
 * wavenumbers (0, 0), (pi, 0), (0, pi) and (pi, pi).  A staggered stencil
 * couples nearest neighbours across (a component with itself at offsets
 * -1, 0, 1 alike; a face-normal component with a centred one at 0 and -1 or
 * 0 and +1), so per direction the two measured wavenumbers give both
 * offsets' coefficients and the block at any (t0, t1) follows with its
 * phases (fourier_lines.c).  The preconditioner transforms the planes
 * (FFTW, real), solves each mode's Hermitian block (banded Cholesky; with
 * an open face, whose edges make the operator non-symmetric, the block as
 * probed, by a banded LU) and transforms back.  It is exact for an operator whose coefficients vary
 * only along the lines (the layer's uniform flow, whatever its viscosity
 * contrast, with the grad-div term of a uniform r), where the line blocks
 * are exact only for the plane-uniform mode and a line smoother for the
 * others.  Over the ranks of a decomposition (bc->dc; the lines whole on
 * every rank): the averages from each rank's lines summed over the ranks,
 * the planes transformed by FFTW's MPI interface (platform/fft_ranks.h) and
 * each rank's share of the modes' blocks factorised and solved there. */
#ifndef MUFLOW_FOURIER_LINES_H
#define MUFLOW_FOURIER_LINES_H

#include <stddef.h>
#include "grid/boundary.h"
#include "grid/grid.h"
#include "solvers/probe_matrix.h"

struct fourier_lines;

/* Lines along line_dir in each component's box act[c]; the two other
 * directions must be periodic (the boxes span them, or the rank's block of
 * them, whole).  Returns 0, or -1 with a message in err (every rank alike).
 * Over ranks, this and the calls below are collective. */
int fourier_lines_create(struct fourier_lines **out, const struct grid *g,
                         const struct boundary *bc, const struct box act[3], int line_dir,
                         char *err, size_t errlen);
void fourier_lines_destroy(struct fourier_lines *f);

/* Probes op (36 applications: 3 components x 4 plane patterns x 3 combs;
 * p and q are work fields, overwritten) and factorises the blocks of every
 * mode.  Returns the number of blocks that were not positive definite (they
 * fall back to their diagonal). */
int fourier_lines_setup(struct fourier_lines *f, operator_fn op, void *ctx, double *p[3],
                        double *q[3]);

/* z = M^-1 r on each component's box (r is not changed). */
void fourier_lines_apply(struct fourier_lines *f, double *const r[3], double *z[3]);

/* 1: the blocks are general (an open face makes the operator
 * non-symmetric: a Krylov method for non-symmetric operators is needed);
 * 0: Hermitian (CG). */
int fourier_lines_general(const struct fourier_lines *f);

/* Bytes fourier_lines_create allocates on g with the faces bc (a rank's
 * block: about its share). */
double fourier_lines_memory_estimate(const struct grid *g, const struct boundary *bc);

#endif
