/* FFTW's MPI transforms opened under mpirun (platform/fft_ranks.h). */
#include "platform/fft_ranks.h"
#include "platform/dynlib.h"

#include <fftw3-mpi.h>
#include <stdio.h>

/* The Makefile passes the soname of libfftw3-mpi-dev's libfftw3_mpi.so. */
#ifndef MUFLOW_FFTW_MPI_LIB
#define MUFLOW_FFTW_MPI_LIB "libfftw3_mpi.so.3"
#endif

#define FFT_RANKS_FUNCTIONS(X) X(fftw_mpi_init) X(fftw_mpi_local_size_3d_transposed) \
    X(fftw_mpi_plan_r2r_3d) X(fftw_mpi_local_size_many_transposed) \
    X(fftw_mpi_plan_many_dft_r2c) X(fftw_mpi_plan_many_dft_c2r)

static struct {
#define POINTER(f) __typeof__(f) *f;
    FFT_RANKS_FUNCTIONS(POINTER)
#undef POINTER
} api;
static int opened;

int fft_ranks_open(char *err, size_t errlen)
{
    if (opened)
        return 0;
    /* libmpi first, in the global scope */
    if (comm_require("FFTW's MPI transforms", err, errlen) != 0)
        return -1;
    void *lib = dynlib_open(MUFLOW_FFTW_MPI_LIB, RTLD_LOCAL, "FFTW's MPI transforms",
                            "libfftw3-mpi-dev", err, errlen);
    if (!lib)
        return -1;
    const char *missing = NULL;
#define RESOLVE(f) DYNLIB_RESOLVE(lib, api, f, missing)
    FFT_RANKS_FUNCTIONS(RESOLVE)
#undef RESOLVE
    if (missing) {
        snprintf(err, errlen, "FFTW's MPI transforms %s lack %s", MUFLOW_FFTW_MPI_LIB, missing);
        dlclose(lib);
        return -1;
    }
    /* FFTW's order: its threads before its MPI (idempotent; the serial
     * solver calls it too) */
    if (!fftw_init_threads()) {
        snprintf(err, errlen, "FFTW's MPI transforms: fftw_init_threads failed");
        dlclose(lib);
        return -1;
    }
    api.fftw_mpi_init();
    opened = 1; /* open for the rest of the run */
    return 0;
}

void fft_ranks_slab(const struct comm_cart *c, const int n[3], struct fft_ranks_slab *s)
{
    s->len = api.fftw_mpi_local_size_3d_transposed(n[0], n[1], n[2], (MPI_Comm)c->comm, &s->nx,
                                                   &s->x0, &s->ny, &s->y0);
}

fftw_plan fft_ranks_plan(const struct comm_cart *c, const int n[3], double *buf,
                         const fftw_r2r_kind kind[3], int inverse, unsigned flags)
{
    flags |= inverse ? FFTW_MPI_TRANSPOSED_IN : FFTW_MPI_TRANSPOSED_OUT;
    return api.fftw_mpi_plan_r2r_3d(n[0], n[1], n[2], buf, buf, (MPI_Comm)c->comm, kind[0],
                                    kind[1], kind[2], flags);
}

void fft_ranks_plane_slab(const struct comm_cart *c, const int n[2], ptrdiff_t howmany,
                          struct fft_ranks_slab *s)
{
    /* the complex sizes: the real transform keeps n[1] / 2 + 1 along n[1] */
    const ptrdiff_t nc[2] = {n[0], n[1] / 2 + 1};
    s->len = 2 * api.fftw_mpi_local_size_many_transposed(
                     2, nc, howmany, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK,
                     (MPI_Comm)c->comm, &s->nx, &s->x0, &s->ny, &s->y0);
}

fftw_plan fft_ranks_plane_plan(const struct comm_cart *c, const int n[2], ptrdiff_t howmany,
                               double *buf, int inverse, unsigned flags)
{
    const ptrdiff_t nr[2] = {n[0], n[1]};
    if (inverse)
        return api.fftw_mpi_plan_many_dft_c2r(2, nr, howmany, FFTW_MPI_DEFAULT_BLOCK,
                                              FFTW_MPI_DEFAULT_BLOCK, (fftw_complex *)buf, buf,
                                              (MPI_Comm)c->comm, flags | FFTW_MPI_TRANSPOSED_IN);
    return api.fftw_mpi_plan_many_dft_r2c(2, nr, howmany, FFTW_MPI_DEFAULT_BLOCK,
                                          FFTW_MPI_DEFAULT_BLOCK, buf, (fftw_complex *)buf,
                                          (MPI_Comm)c->comm, flags | FFTW_MPI_TRANSPOSED_OUT);
}

void fft_ranks_execute(fftw_plan plan)
{
    comm_traffic_fft();
    const double t0 = comm_clock();
    fftw_execute(plan);
    comm_waits_add_fft(comm_clock() - t0);
}
