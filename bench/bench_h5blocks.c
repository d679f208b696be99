/* Writing a field with its ghosts (the checkpoint's layout, (N+2)^3
 * doubles) into one HDF5 file by the ranks together (io/h5blocks.h,
 * docs/numerics/decomposition.md), split along x: REPEATS files after one
 * warm-up into DIR, each made durable (fsync, rename); prints the ranks,
 * the median and least time from the first rank's create to the last
 * rank's commit, and the bandwidth of the median.
 *   bench_h5blocks N REPEATS DIR                  one process (serial HDF5)
 *   mpirun -np 2 bench_h5blocks N REPEATS DIR     two ranks (parallel HDF5)
 * Run without `make bench` (mpirun is the caller's choice). */
#include <stdio.h>
#include <stdlib.h>
#include "bench.h"
#include "grid/decomp.h"
#include "io/h5blocks.h"
#include "platform/comm.h"

int main(int argc, char **argv)
{
    char err[1200] = "";
    if (argc != 4 || comm_init(err, sizeof err) != 0) {
        fprintf(stderr, "usage: [mpirun -np P] bench_h5blocks N REPEATS DIR %s\n", err);
        return 2;
    }
    const int N = atoi(argv[1]), repeats = atoi(argv[2]);
    struct grid gg, g;
    struct comm_cart cart;
    struct decomp dc;
    const int dims[3] = {comm_size(), 1, 1}, per[3] = {0, 0, 0}, split[3] = {1, 1, 1};
    bench_blocks("bench_h5blocks", N, dims, per, split, &gg, &g, &cart, &dc);
    double *f = field_alloc(&g), *buf = field_alloc(&g);
    for (size_t p = 0; p < g.size; p++)
        f[p] = 1.0 + (double)p * 1e-7;
    char path[1100];
    snprintf(path, sizeof path, "%s/bench_h5blocks.h5", argv[3]);
    double *times = calloc((size_t)repeats + 1, sizeof(double));
    for (int r = 0; r <= repeats; r++) {
        struct h5blocks w;
        comm_barrier();
        double t0 = bench_now();
        if (h5blocks_create(&w, &cart, path, err, sizeof err) != 0 ||
            h5blocks_put_full(&w, "pressure", &dc, &g, f, buf, err, sizeof err) != 0 ||
            h5blocks_finish(&w, "bench", NULL, NULL, err, sizeof err) != 0) {
            fprintf(stderr, "bench_h5blocks: %s\n", err);
            return 2;
        }
        double t = bench_now() - t0;
        comm_max(&t, 1);
        times[r] = t;
    }
    const double mb = (double)(N + 2) * (N + 2) * (N + 2) * sizeof(double) / 1e6;
    const double med = bench_median(times + 1, repeats);
    if (comm_rank() == 0)
        printf("N %d (%.1f MB): %d rank(s): write median %.3f s min %.3f s, %.0f MB/s "
               "(%d repeats)\n", N, mb, comm_size(), med, bench_min(times + 1, repeats),
               mb / med, repeats);
    if (comm_rank() == 0)
        remove(path);
    free(times);
    field_free(f);
    field_free(buf);
    decomp_free(&dc);
    comm_cart_free(&cart);
    return 0;
}
