/* The decomposed multigrid-CG Poisson solve (docs/numerics/decomposition.md):
 * N^3 cells, a smooth variable coefficient, walls (Neumann) all round,
 * solved to 1e-12 REPEATS times after one warm-up; prints the ranks x
 * threads, the PCG iterations, the set-up and the median solve time, and a
 * `traffic` line per rank: the halo and gather bytes and messages of one
 * cycle and of one solve, measured (grid/decomp.h's tally) and by the model
 * (multigrid_traffic_model), the sums over the ranks, the peak RSS and the
 * solver's bytes per local cell (bench/scaling_model.py reads them).
 *   bench_decomposed N REPEATS                    one process
 *   mpirun -np P bench_decomposed N REPEATS       P ranks (MPI_Dims_create's split)
 * `make bench-decomposed` runs 64^3 and 128^3 on 1, 2 and 4 ranks. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include "bench.h"
#include "grid/decomp.h"
#include "platform/comm.h"
#include "solvers/multigrid.h"

/* One cycle's and one solve's traffic, measured and modelled. */
struct traffic_pair {
    struct decomp_traffic measured, model;
};

static void measure_traffic(struct multigrid *mg, const struct grid *g, const double *rhs,
                            double *phi, struct traffic_pair *cyc, struct traffic_pair *sol,
                            long reductions[2])
{
    struct multigrid_stats st;
    decomp_traffic_reset();
    multigrid_cycle(mg, rhs, phi);
    decomp_traffic_read(&cyc->measured);
    for (size_t p = 0; p < g->size; p++)
        phi[p] = 0.0;
    decomp_traffic_reset();
    const long r0 = comm_reductions();
    multigrid_pcg(mg, rhs, phi, 1e-12, 100, &st);
    reductions[0] = comm_reductions() - r0;
    decomp_traffic_read(&sol->measured);
    multigrid_traffic_model(mg, st.cycles, &cyc->model, &sol->model, &reductions[1]);
}

#define TRAFFIC_KEYS 17

/* Every rank's line, printed by rank 0 (the values summed over the ranks
 * into each rank's row). */
static void report_traffic(const struct decomp *dc, const struct multigrid *mg, int N,
                           int iterations,
                           const struct traffic_pair *cyc, const struct traffic_pair *sol,
                           const long reductions[2], double solve_s, double cpu_s)
{
    static const char *const keys[TRAFFIC_KEYS] = {
        "cells", "cycle_bytes", "cycle_bytes_model", "cycle_messages", "cycle_messages_model",
        "cycle_gather_recv", "cycle_gather_recv_model", "cycle_gathers", "cycle_gathers_model",
        "solve_bytes", "solve_bytes_model", "solve_messages", "solve_messages_model",
        "reductions", "reductions_model", "rss_bytes", "solver_bytes"};
    const int ranks = comm_size(), me = comm_rank();
    double *row = calloc((size_t)ranks * TRAFFIC_KEYS, sizeof(double));
    if (!row)
        abort();
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    const double mine[TRAFFIC_KEYS] = {
        (double)dc->n[0] * dc->n[1] * dc->n[2],
        (double)cyc->measured.bytes, (double)cyc->model.bytes,
        (double)cyc->measured.messages, (double)cyc->model.messages,
        (double)cyc->measured.gather_received, (double)cyc->model.gather_received,
        (double)cyc->measured.gathers, (double)cyc->model.gathers,
        (double)sol->measured.bytes, (double)sol->model.bytes,
        (double)sol->measured.messages, (double)sol->model.messages,
        (double)reductions[0], (double)reductions[1],
        1024.0 * (double)ru.ru_maxrss, (double)multigrid_bytes(mg)};
    memcpy(row + (size_t)me * TRAFFIC_KEYS, mine, sizeof mine);
    comm_sum(row, ranks * TRAFFIC_KEYS);
    if (me == 0)
        for (int r = 0; r < ranks; r++) {
            printf("traffic N=%d ranks=%d threads=%d rank=%d iterations=%d levels=%d "
                   "solve_s=%.4f cpu_s=%.4f", N, ranks, omp_get_max_threads(), r, iterations,
                   multigrid_levels(mg), solve_s, cpu_s);
            for (int k = 0; k < TRAFFIC_KEYS; k++)
                printf(" %s=%.0f", keys[k], row[(size_t)r * TRAFFIC_KEYS + k]);
            printf("\n");
        }
    free(row);
}

int main(int argc, char **argv)
{
    char err[256] = "";
    if (argc != 3 || comm_init(err, sizeof err) != 0) {
        fprintf(stderr, "usage: [mpirun -np P] bench_decomposed N REPEATS %s\n", err);
        return 2;
    }
    const int N = atoi(argv[1]), repeats = atoi(argv[2]);
    const enum poisson_bc bc[3][2] = {{POISSON_NEUMANN, POISSON_NEUMANN},
                                      {POISSON_NEUMANN, POISSON_NEUMANN},
                                      {POISSON_NEUMANN, POISSON_NEUMANN}};
    struct grid gg, g;
    struct comm_cart cart;
    struct decomp dc;
    const int dims[3] = {0, 0, 0}, per[3] = {0, 0, 0}, split[3] = {1, 1, 1};
    bench_blocks("bench_decomposed", N, dims, per, split, &gg, &g, &cart, &dc);
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
    struct traffic_pair cyc, sol;
    long reductions[2];
    measure_traffic(mg, &g, rhs, phi, &cyc, &sol, reductions);
    double *times = calloc((size_t)repeats + 1, sizeof(double));
    struct multigrid_stats st;
    double cpu_total = 0.0;
    for (int r = 0; r <= repeats; r++) {
        for (size_t p = 0; p < g.size; p++)
            phi[p] = 0.0;
        comm_barrier();
        t0 = bench_now();
        const clock_t c0 = clock();
        multigrid_pcg(mg, rhs, phi, 1e-12, 100, &st);
        double t = bench_now() - t0;
        if (r > 0)
            cpu_total += (double)(clock() - c0) / CLOCKS_PER_SEC;
        comm_max(&t, 1);
        times[r] = t;
    }
    if (comm_rank() == 0)
        printf("N %d: %d rank(s) x %d thread(s): %d PCG iterations, %d levels on the ranks, "
               "set-up %.3f s, solve median %.3f s min %.3f s (%d repeats)\n",
               N, comm_size(), omp_get_max_threads(), st.cycles, multigrid_levels(mg), setup,
               bench_median(times + 1, repeats), bench_min(times + 1, repeats), repeats);
    /* rank 0's CPU seconds a solve (on one rank of one thread: the work,
     * whatever else the machine runs; under mpirun it counts the polling) */
    const double cpu_s = cpu_total / repeats;
    report_traffic(&dc, mg, N, st.cycles, &cyc, &sol, reductions,
                   bench_median(times + 1, repeats), cpu_s);
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
