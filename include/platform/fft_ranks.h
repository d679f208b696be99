/* FFTW's MPI transforms for the ranks of an mpirun.
 *
 * libfftw3_mpi needs libmpi: linked, it would load libmpi in every run.  It
 * is opened with dlopen under mpirun only, after comm_init has opened libmpi
 * (docs/numerics/decomposition.md); its plans are ordinary fftw_plans of the
 * linked libfftw3, run by fftw_execute on every rank at once.  The global
 * array of n[0] x n[1] x n[2] doubles (row-major, n[2] fastest) is split
 * along n[0] into slabs; a transform's output is transposed (n[1] split,
 * FFTW_MPI_TRANSPOSED_OUT) and the inverse takes that layout back
 * (FFTW_MPI_TRANSPOSED_IN), which spares FFTW two of its four transposes. */
#ifndef MUFLOW_PLATFORM_FFT_RANKS_H
#define MUFLOW_PLATFORM_FFT_RANKS_H
#include <fftw3.h>
#include <stddef.h>
#include "platform/comm.h"

/* This rank's slab: x0 .. x0 + nx - 1 of the input, y0 .. y0 + ny - 1 of
 * the transposed output; len doubles hold either (FFTW's local size). */
struct fft_ranks_slab {
    ptrdiff_t x0, nx, y0, ny, len;
};

/* Opens and initialises the library (once; FFTW's threads first).  0, or -1
 * with the cause (not under mpirun, the library missing). */
int fft_ranks_open(char *err, size_t errlen);

/* The slab of this rank of c for the global sizes n. */
void fft_ranks_slab(const struct comm_cart *c, const int n[3], struct fft_ranks_slab *s);

/* The in-place r2r plan of kinds kind[d] over c on buf (s.len doubles):
 * forward (transposed = FFTW_MPI_TRANSPOSED_OUT) or inverse (TRANSPOSED_IN),
 * with flags as fftw_plan_r2r_3d's.  NULL when FFTW cannot make it.
 * Collective. */
fftw_plan fft_ranks_plan(const struct comm_cart *c, const int n[3], double *buf,
                         const fftw_r2r_kind kind[3], int inverse, unsigned flags);

/* The real 2D transform of n[0] x n[1] points of howmany interleaved values
 * each (a value's planes: point (a, b)'s values at (a rows + b) howmany, rows
 * = 2 (n[1] / 2 + 1), FFTW's padding), in place: this rank's slab x0 .. x0 +
 * nx - 1 along n[0] in, its wavenumbers y0 .. y0 + ny - 1 of n[1]'s half
 * spectrum out, transposed (wavenumber (k1, k0)'s howmany complex values at
 * ((k1 - y0) n[0] + k0) howmany); len doubles hold either. */
void fft_ranks_plane_slab(const struct comm_cart *c, const int n[2], ptrdiff_t howmany,
                          struct fft_ranks_slab *s);
/* Its forward (r2c, FFTW_MPI_TRANSPOSED_OUT) or inverse (c2r, unnormalised,
 * TRANSPOSED_IN) plan on buf; NULL when FFTW cannot make it.  Collective. */
fftw_plan fft_ranks_plane_plan(const struct comm_cart *c, const int n[2], ptrdiff_t howmany,
                               double *buf, int inverse, unsigned flags);

/* fftw_execute of a plan above, counted in comm_traffic's fft_executions. */
void fft_ranks_execute(fftw_plan plan);
#endif
