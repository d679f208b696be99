/* The FFT Poisson solve of a grid split over ranks (grid/decomp.h), the
 * same transforms as poisson_fft (solvers/poisson.h) through FFTW's MPI
 * interface (platform/fft_ranks.h): no rank holds more than its block and
 * its slab of the global grid.
 *
 * The blocks split x and y; FFTW's input splits x alone (slabs of whole y, z
 * planes), its output y alone (transposed).  The right-hand side goes from
 * the blocks to the slabs in one all-to-all (each block's x range meets a
 * run of slabs, in rank order), the transform, the division by the
 * eigenvalues in the transposed layout, the inverse back to the slabs, and
 * the solution from the slabs to the blocks in the reverse all-to-all.
 * A field uniform across x and y stays exactly so, as with one process (the
 * multigrid's red-black round-off did not: docs/numerics/decomposition.md). */
#ifndef MUFLOW_SOLVERS_POISSON_FFT_RANKS_H
#define MUFLOW_SOLVERS_POISSON_FFT_RANKS_H
#include <fftw3.h>
#include "grid/decomp.h"
#include "solvers/poisson.h"

struct poisson_fft_ranks;

/* Plans the transforms of the global grid gg split as dc (this rank's
 * local grid g) for the conditions bc.  Returns 0, or -1 with a message
 * (every rank alike).  Collective; under mpirun only. */
int poisson_fft_ranks_create(struct poisson_fft_ranks **out, const struct grid *g,
                             const struct grid *gg, const struct decomp *dc,
                             const enum poisson_bc bc[3][2], char *err, size_t errlen);

/* poisson_fft_solve over the ranks: rhs and phi are this rank's local
 * fields (g's layout; phi may alias rhs, its ghosts left alone).
 * Collective. */
void poisson_fft_ranks_solve(struct poisson_fft_ranks *ps, const double *rhs, double *phi);

void poisson_fft_ranks_destroy(struct poisson_fft_ranks *ps);

/* What poisson_fft and this solver share (poisson_fft.c): each direction's
 * transform kinds and eigenvalues (eig[d], n[d] of them, allocated), the
 * product of the normalisations, whether mode (0,0,0) is singular; 0, or -1
 * with a message (the conditions, out of memory). */
int poisson_fft_modes(const struct grid *g, const enum poisson_bc bc[3][2],
                      fftw_r2r_kind fwd_kind[3], fftw_r2r_kind bwd_kind[3], double *eig[3],
                      double *norm, int *singular, char *err, size_t errlen);
/* FFTW's threads for a grid of g's cells. */
int poisson_fft_threads(const struct grid *g);
#endif
