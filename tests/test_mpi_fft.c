/* The ranks' FFT Poisson solve (solvers/poisson_fft_ranks.h) against the
 * serial one (poisson_fft), in the group mpi (test_mpi.c): under mpirun on
 * 2 and 4 ranks; on one (alone or under mpirun: no communicator, the
 * pressure solver takes the serial FFT, pressure.c) skipped.  Each check
 * reduces over the ranks before asserting (all pass or fail together). */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "grid/decomp.h"
#include "platform/comm.h"
#include "solvers/poisson_fft_ranks.h"
#include "test_main.h"
#include "test_mpi.h"
#include "test_util.h"

/* A right-hand side with every mode in it (no symmetry across x, y, z),
 * or, uniform = 1, one of z alone. */
static double manufactured(const struct grid *gg, int i, int j, int k, int uniform)
{
    const double x = (i + 0.5) / gg->n[0], y = (j + 0.5) / gg->n[1], z = (k + 0.5) / gg->n[2];
    if (uniform)
        return cos(3.0 * z) + 0.3 * z * z;
    return sin(2.0 * M_PI * x + 0.3) * cos(4.0 * M_PI * y) + exp(z) * x * (1.0 - y) +
           0.1 * (double)((i * 7 + j * 13 + k * 5) % 11);
}

struct fft_check {
    double diff, size, spread; /* max |ranks - serial|, max |serial|, max column spread */
};

/* The ranks' solve on dims ranks of the global grid n (bc) against the
 * serial solve of the global grid (every rank makes it: a test's
 * reference); spread: over every rank, the largest difference of phi
 * between two columns at one z (0 for a uniform right-hand side). */
static struct fft_check solve_on_ranks(const int dims[3], const int n[3],
                                       const enum poisson_bc bc[3][2], int uniform)
{
    const double len[3] = {1.0, 0.7, 0.5};
    int periodic[3];
    test_poisson_periodic(bc, periodic);
    struct test_blocks b;
    test_blocks_open(&b, dims, periodic, n, len);
    const int *o = b.dc.lo; /* the global index of this block's cell 0 */
    char err[256] = "";
    double *whole = field_alloc(&b.whole), *phi = field_alloc(&b.g);
    assert_true(whole && phi);
    for (int i = 0; i < n[0]; i++)
        for (int j = 0; j < n[1]; j++)
            for (int k = 0; k < n[2]; k++)
                whole[grid_idx(&b.whole, i, j, k)] = manufactured(&b.whole, i, j, k, uniform);
    for (int i = 0; i < b.g.n[0]; i++)
        for (int j = 0; j < b.g.n[1]; j++)
            for (int k = 0; k < b.g.n[2]; k++)
                phi[grid_idx(&b.g, i, j, k)] =
                    whole[grid_idx(&b.whole, o[0] + i, o[1] + j, o[2] + k)];
    struct poisson_fft *serial;
    struct poisson_fft_ranks *ranks;
    assert_int_equal(poisson_fft_create(&serial, &b.whole, bc, err, sizeof err), 0);
    if (poisson_fft_ranks_create(&ranks, &b.g, &b.whole, &b.dc, bc, err, sizeof err) != 0)
        print_error("%s\n", err);
    assert_non_null(ranks);
    poisson_fft_solve(serial, whole, whole);
    poisson_fft_ranks_solve(ranks, phi, phi); /* in place, as the projection calls it */
    double m[2] = {0.0, 0.0}, hi[64], lo[64];
    assert_true(n[2] <= 64);
    for (int k = 0; k < n[2]; k++)
        hi[k] = lo[k] = -INFINITY;
    for (int i = 0; i < b.g.n[0]; i++)
        for (int j = 0; j < b.g.n[1]; j++)
            for (int k = 0; k < b.g.n[2]; k++) {
                const double w = whole[grid_idx(&b.whole, o[0] + i, o[1] + j, o[2] + k)],
                             v = phi[grid_idx(&b.g, i, j, k)];
                m[0] = fmax(m[0], fabs(v - w));
                m[1] = fmax(m[1], fabs(w));
                hi[o[2] + k] = fmax(hi[o[2] + k], v);
                lo[o[2] + k] = fmax(lo[o[2] + k], -v);
            }
    comm_max(m, 2);
    comm_max(hi, n[2]);
    comm_max(lo, n[2]);
    struct fft_check c = {m[0], m[1], 0.0};
    for (int k = 0; k < n[2]; k++)
        c.spread = fmax(c.spread, hi[k] + lo[k]);
    if (comm_rank() == 0) {
        printf("    %d x %d x %d cells on %d x %d x %d ranks: |ranks - serial| %.2e of max "
               "|phi| %.3g", n[0], n[1], n[2], b.cart.dims[0], b.cart.dims[1], b.cart.dims[2],
               c.diff / c.size, c.size);
        if (uniform)
            printf("; uniform across x, y: column spread %.2e", c.spread);
        printf("\n");
    }
    poisson_fft_destroy(serial);
    poisson_fft_ranks_destroy(ranks);
    field_free(whole);
    field_free(phi);
    test_blocks_close(&b);
    return c;
}

/* Split along x, along y, both (MPI_Dims_create's; 2 x 2 on 4 ranks), along
 * z (the chute's periodic z) and x and z.  10 x 6 cells across: FFTW's
 * slabs uneven (4 ranks: 3, 3, 3, 1 planes of x, 2, 2, 2, 0 of y), the
 * blocks not aligned with them. */
static void check_splits(const enum poisson_bc bc[3][2])
{
    const int n[3] = {10, 6, 8}, P = comm_size();
    const int splits[5][3] = {{P, 1, 1}, {1, P, 1}, {0, 0, 1}, {1, 1, P}, {0, 1, 0}};
    int dims[5][3];
    const int count = test_splits(5, splits, dims);
    for (int s = 0; s < count; s++) {
        struct fft_check c = solve_on_ranks(dims[s], n, bc, 0);
        /* the same transforms of the same numbers, FFTW's steps in another
         * order (its MPI plans split the sums differently): round-off of a
         * few hundred cells' sums, far below 1e-12 */
        assert_true(c.size > 0.0 && c.diff <= 1e-12 * c.size);
    }
}

void test_fft_ranks_periodic(void **state)
{
    (void)state;
    if (comm_size() < 2)
        skip();
    const enum poisson_bc bc[3][2] = {{POISSON_PERIODIC, POISSON_PERIODIC},
                                      {POISSON_PERIODIC, POISSON_PERIODIC},
                                      {POISSON_NEUMANN, POISSON_NEUMANN}};
    check_splits(bc);
}

void test_fft_ranks_dirichlet(void **state)
{
    (void)state;
    if (comm_size() < 2)
        skip();
    const enum poisson_bc bc[3][2] = {{POISSON_DIRICHLET, POISSON_DIRICHLET},
                                      {POISSON_PERIODIC, POISSON_PERIODIC},
                                      {POISSON_NEUMANN, POISSON_DIRICHLET}};
    check_splits(bc);
}

/* A right-hand side of z alone (the layer at rest): the solution is the
 * same in every column to the bit on every rank, as the serial FFT's (the
 * transforms of a constant along x, y give exact zeros off mode 0). */
void test_fft_ranks_uniform(void **state)
{
    (void)state;
    if (comm_size() < 2)
        skip();
    const enum poisson_bc bc[3][2] = {{POISSON_PERIODIC, POISSON_PERIODIC},
                                      {POISSON_PERIODIC, POISSON_PERIODIC},
                                      {POISSON_NEUMANN, POISSON_DIRICHLET}};
    const int n[3] = {32, 32, 16}, dims[3] = {0, 0, 1};
    struct fft_check c = solve_on_ranks(dims, n, bc, 1);
    assert_true(c.size > 0.0 && c.diff <= 1e-12 * c.size);
    assert_true(c.spread == 0.0);
}
