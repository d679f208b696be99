/* The decomposed multigrid-CG Poisson solve (docs/numerics/decomposition.md):
 * N^3 cells, a smooth variable coefficient, walls (Neumann) all round,
 * solved to 1e-12 REPEATS times after one warm-up; prints the ranks x
 * threads, the PCG iterations, the set-up and the median solve time.
 *   bench_decomposed N REPEATS                    one process
 *   mpirun -np 2 bench_decomposed N REPEATS       two ranks (split along x)
 * Run without `make bench` (mpirun is the caller's choice). */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include "bench.h"
#include "grid/decomp.h"
#include "platform/comm.h"
#include "solvers/multigrid.h"

int main(int argc, char **argv)
{
    char err[256] = "";
    if (argc != 3 || comm_init(err, sizeof err) != 0) {
        fprintf(stderr, "usage: [mpirun -np P] bench_decomposed N REPEATS %s\n", err);
        return 2;
    }
    const int N = atoi(argv[1]), repeats = atoi(argv[2]);
    const int n[3] = {N, N, N};
    const double len[3] = {1.0, 1.0, 1.0};
    const enum poisson_bc bc[3][2] = {{POISSON_NEUMANN, POISSON_NEUMANN},
                                      {POISSON_NEUMANN, POISSON_NEUMANN},
                                      {POISSON_NEUMANN, POISSON_NEUMANN}};
    struct grid gg, g;
    struct comm_cart cart;
    struct decomp dc;
    const int dims[3] = {comm_size(), 1, 1}, per[3] = {0, 0, 0}, split[3] = {1, 1, 1};
    if (grid_init(&gg, n, len) != 0 || comm_cart_create(&cart, dims, per, split, err, sizeof err) ||
        decomp_create(&dc, &cart, n, err, sizeof err) || decomp_local_grid(&dc, &gg, &g)) {
        fprintf(stderr, "bench_decomposed: %s\n", err);
        return 2;
    }
    struct multigrid *mg;
    double t0 = bench_now();
    if (multigrid_create_decomposed(&mg, &gg, &dc, bc, NULL, err, sizeof err) != 0) {
        fprintf(stderr, "bench_decomposed: %s\n", err);
        return 2;
    }
    double *a[3] = {field_alloc(&g), field_alloc(&g), field_alloc(&g)};
    double *rhs = field_alloc(&g), *phi = field_alloc(&g);
    for (int i = 0; i <= g.n[0]; i++)
        for (int j = 0; j <= g.n[1]; j++)
            for (int k = 0; k <= g.n[2]; k++) {
                const int I = dc.lo[0] + i, J = dc.lo[1] + j, K = dc.lo[2] + k;
                const ptrdiff_t p = grid_idx(&g, i, j, k);
                for (int d = 0; d < 3; d++)
                    a[d][p] = 1.0 + 0.5 * sin(6.0 * I / N + d) * cos(5.0 * K / N + J * 3.0 / N);
                rhs[p] = sin(9.0 * I / N) * cos(7.0 * J / N + 4.0 * K / N);
            }
    if (multigrid_set_coefficients(mg, a, err, sizeof err) != 0) {
        fprintf(stderr, "bench_decomposed: %s\n", err);
        return 2;
    }
    const double setup = bench_now() - t0;
    double *times = calloc((size_t)repeats + 1, sizeof(double));
    struct multigrid_stats st;
    for (int r = 0; r <= repeats; r++) {
        for (size_t p = 0; p < g.size; p++)
            phi[p] = 0.0;
        comm_barrier();
        t0 = bench_now();
        multigrid_pcg(mg, rhs, phi, 1e-12, 100, &st);
        double t = bench_now() - t0;
        comm_max(&t, 1);
        times[r] = t;
    }
    if (comm_rank() == 0)
        printf("N %d: %d rank(s) x %d thread(s): %d PCG iterations, %d levels on the ranks, "
               "set-up %.3f s, solve median %.3f s min %.3f s (%d repeats)\n",
               N, comm_size(), omp_get_max_threads(), st.cycles, multigrid_levels(mg), setup,
               bench_median(times + 1, repeats), bench_min(times + 1, repeats), repeats);
    free(times);
    for (int d = 0; d < 3; d++)
        field_free(a[d]);
    field_free(rhs);
    field_free(phi);
    multigrid_destroy(mg);
    decomp_free(&dc);
    comm_cart_free(&cart);
    return 0;
}
