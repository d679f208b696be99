/* The pressure's FFT Poisson solve (periodic x, y, walls in z, as the
 * bagnold and couette scenes') of N^3 cells: REPEATS solves after one
 * warm-up; prints the ranks and threads, the median and least time of a
 * solve (the slowest rank's) and the process's peak RSS.
 *   bench_fft_ranks N REPEATS                  one process: poisson_fft
 *   mpirun -np P bench_fft_ranks N REPEATS     P ranks: poisson_fft_ranks,
 *                                              split x, y (MPI_Dims_create)
 * Run without `make bench` (mpirun and threads are the caller's choice). */
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include "bench.h"
#include "grid/decomp.h"
#include "platform/comm.h"
#include "solvers/poisson_fft_ranks.h"
#ifdef _OPENMP
#include <omp.h>
#endif

int main(int argc, char **argv)
{
    char err[1200] = "";
    if (argc != 3 || comm_init(err, sizeof err) != 0) {
        fprintf(stderr, "usage: [mpirun -np P] bench_fft_ranks N REPEATS %s\n", err);
        return 2;
    }
    const int N = atoi(argv[1]), repeats = atoi(argv[2]);
    const enum poisson_bc bc[3][2] = {{POISSON_PERIODIC, POISSON_PERIODIC},
                                      {POISSON_PERIODIC, POISSON_PERIODIC},
                                      {POISSON_NEUMANN, POISSON_DIRICHLET}};
    struct grid gg, g;
    struct comm_cart cart;
    struct decomp dc;
    const int dims[3] = {0, 0, 1}, per[3] = {1, 1, 0}, split[3] = {1, 1, 0};
    bench_blocks("bench_fft_ranks", N, dims, per, split, &gg, &g, &cart, &dc);
    struct poisson_fft *serial = NULL;
    struct poisson_fft_ranks *ranks = NULL;
    if ((cart.comm ? poisson_fft_ranks_create(&ranks, &g, &gg, &dc, bc, err, sizeof err)
                   : poisson_fft_create(&serial, &g, bc, err, sizeof err)) != 0) {
        fprintf(stderr, "bench_fft_ranks: %s\n", err);
        return 2;
    }
    double *f = field_alloc(&g);
    double *times = calloc((size_t)repeats + 1, sizeof(double));
    for (int r = 0; r <= repeats; r++) {
        for (size_t p = 0; p < g.size; p++)
            f[p] = 1.0 + (double)(p % 97) * 1e-2;
        comm_barrier();
        double t0 = bench_now();
        if (ranks)
            poisson_fft_ranks_solve(ranks, f, f);
        else
            poisson_fft_solve(serial, f, f);
        double t = bench_now() - t0;
        comm_max(&t, 1);
        times[r] = t;
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    double rss = (double)ru.ru_maxrss;
    comm_max(&rss, 1);
    int threads = 1;
#ifdef _OPENMP
    threads = omp_get_max_threads();
#endif
    if (comm_rank() == 0)
        printf("N %d: %d rank(s) (%d x %d) x %d thread(s): solve median %.2f ms min %.2f ms, "
               "peak RSS %.1f MB a rank (%d repeats)\n", N, comm_size(), cart.dims[0],
               cart.dims[1], threads, 1e3 * bench_median(times + 1, repeats),
               1e3 * bench_min(times + 1, repeats), rss / 1024.0, repeats);
    poisson_fft_ranks_destroy(ranks);
    poisson_fft_destroy(serial);
    field_free(f);
    decomp_free(&dc);
    comm_cart_free(&cart);
    comm_finalize();
    return 0;
}
