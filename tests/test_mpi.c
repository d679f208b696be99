/* The domain decomposition (grid/decomp.h) and the decomposed multigrid,
 * run under mpirun on 1, 2 and 4 ranks (`make test`) and alone.  Every
 * check reduces its result over the ranks first, so all ranks pass or
 * fail together (no rank waits in a collective for one that failed). */
#define _POSIX_C_SOURCE 200809L /* getpid, mkdir */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "app/run.h"
#include "grid/decomp.h"
#include "io/fields_h5.h"
#include "io/h5blocks.h"
#include "platform/comm.h"
#include "scenes/scene.h"
#include "solvers/multigrid.h"
#include "test_main.h"
#include "test_mpi.h"
#include "test_util.h"

/* A value no two global slots share (the global ghost slots too). */
static double pattern(int i, int j, int k)
{
    return 1e4 * (i + 2) + 1e2 * (j + 2) + (k + 2) + 0.25;
}

/* The global index of local index t along d, wrapped when periodic. */
static int global_index(const struct decomp *dc, int d, int t, int periodic)
{
    int G = dc->lo[d] + t, N = dc->n_global[d];
    if (periodic)
        G = (G + N) % N;
    return G;
}

/* This rank's block of the global n cells split over dims (periodic as
 * given), of unit spacing, and one field on it. */
struct unit_block {
    struct test_blocks blocks;
    double *f;
};

static void unit_block_open(struct unit_block *b, const int dims[3], const int periodic[3],
                            const int n[3])
{
    const double len[3] = {n[0], n[1], n[2]};
    test_blocks_open(&b->blocks, dims, periodic, n, len);
    b->f = field_alloc(&b->blocks.g);
    assert_non_null(b->f);
}

static void unit_block_close(struct unit_block *b)
{
    field_free(b->f);
    test_blocks_close(&b->blocks);
}

/* Each rank fills its cells with the global pattern and its ghosts with
 * -1, exchanges direction after direction, and checks every ghost slot
 * (edges and corners too): a rank border's holds the neighbour's cell, a
 * periodic end's the wrapped cell, a wall's keeps -1.  A face array of
 * normal d is the same check: its slot t along d is global face lo + t
 * (grid/decomp.h), so the ghost n must hold the next rank's face 0. */
static void check_exchange(const int dims[3], const int periodic[3], const int n[3])
{
    struct unit_block b;
    unit_block_open(&b, dims, periodic, n);
    const struct decomp *dc = &b.blocks.dc;
    const struct grid *g = &b.blocks.g;
    double *f = b.f;
    for (size_t p = 0; p < g->size; p++)
        f[p] = -1.0;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++)
                f[grid_idx(g, i, j, k)] = pattern(dc->lo[0] + i, dc->lo[1] + j, dc->lo[2] + k);
    for (int d = 0; d < 3; d++)
        decomp_exchange(dc, g, f, d);
    double bad = 0.0;
    for (int i = -1; i <= g->n[0]; i++)
        for (int j = -1; j <= g->n[1]; j++)
            for (int k = -1; k <= g->n[2]; k++) {
                const int t[3] = {i, j, k};
                int G[3], outside = 0;
                for (int d = 0; d < 3; d++) {
                    /* a slot beyond the local box is the neighbour's only
                     * across a border; else (a wall, a one-rank periodic
                     * direction: local fills) it stays -1 */
                    const int beyond = t[d] < 0 ? 0 : t[d] >= g->n[d] ? 1 : -1;
                    if (beyond >= 0 && !dc->border[d][beyond])
                        outside = 1;
                    G[d] = global_index(dc, d, t[d], periodic[d]);
                }
                const double want = outside ? -1.0 : pattern(G[0], G[1], G[2]);
                bad += f[grid_idx(g, i, j, k)] != want;
            }
    comm_sum(&bad, 1);
    unit_block_close(&b);
    assert_true(bad == 0.0);
}

static void test_exchange_walls(void **state)
{
    (void)state;
    const int n[3] = {6, 5, 8}, per[3] = {0, 0, 0};
    const int along_x[3] = {comm_size(), 1, 1}, along_z[3] = {1, 1, comm_size()};
    const int any[3] = {0, 0, 0};
    check_exchange(along_x, per, n);
    check_exchange(along_z, per, n);
    check_exchange(any, per, n);
}

static void test_exchange_periodic(void **state)
{
    (void)state;
    const int n[3] = {8, 4, 7}, per[3] = {1, 1, 0}, per_z[3] = {0, 1, 1};
    const int along_x[3] = {comm_size(), 1, 1}, along_z[3] = {1, 1, comm_size()};
    const int any[3] = {0, 0, 0};
    check_exchange(along_x, per, n);
    check_exchange(along_z, per_z, n);
    check_exchange(any, per, n);
    check_exchange(any, per_z, n);
}

/* The blocks tile the global grid: their counts add up along each
 * direction, each rank's block is where its coordinates say. */
static void test_blocks_tile(void **state)
{
    (void)state;
    struct comm_cart cart;
    struct decomp dc;
    char err[256];
    const int dims[3] = {0, 0, 0}, per[3] = {0, 0, 0}, split[3] = {1, 1, 1}, n[3] = {9, 7, 5};
    assert_int_equal(comm_cart_create(&cart, dims, per, split, err, sizeof err), 0);
    assert_int_equal(decomp_create(&dc, &cart, n, err, sizeof err), 0);
    double cells = (double)dc.n[0] * dc.n[1] * dc.n[2];
    comm_sum(&cells, 1);
    assert_true(cells == 9.0 * 7 * 5);
    for (int d = 0; d < 3; d++) {
        assert_int_equal(dc.start[d][0], 0);
        assert_int_equal(dc.start[d][cart.dims[d]], n[d]);
        assert_true(dc.n[d] >= n[d] / cart.dims[d]);
    }
    decomp_free(&dc);
    comm_cart_free(&cart);
}

/* ---- the decomposed multigrid against the undecomposed one ------------------------ */

/* Face coefficient of direction d at global face (i, j, k): smooth, or with
 * a jump of 100 across a slab (jump). */
static double coefficient(int d, int i, int j, int k, int jump)
{
    if (jump)
        return (i >= 15 && i < 33 && k >= 7 && k < 23) ? 100.0 : 1.0;
    return 1.0 + 0.5 * sin(0.21 * i + 0.1 * d) * cos(0.17 * k + 0.3 * j);
}

static double source(int i, int j, int k)
{
    return sin(0.3 * i + 0.2 * j) * cos(0.11 * k) + 0.01 * ((i * 7 + j * 3 + k * 5) % 11);
}

/* Fills the face coefficients and the rhs of a grid g whose cell 0 is the
 * global cell lo (lo = 0: the global grid). */
static void fill_problem(const struct grid *g, const int lo[3], double *a[3], double *rhs,
                         int jump)
{
    for (int d = 0; d < 3; d++)
        for (int i = 0; i <= g->n[0]; i++)
            for (int j = 0; j <= g->n[1]; j++)
                for (int k = 0; k <= g->n[2]; k++)
                    a[d][grid_idx(g, i, j, k)] =
                        coefficient(d, lo[0] + i, lo[1] + j, lo[2] + k, jump);
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++)
                rhs[grid_idx(g, i, j, k)] = source(lo[0] + i, lo[1] + j, lo[2] + k);
}

struct solve_result {
    double *phi;
    int iterations, levels;
};

/* multigrid_pcg of the problem on g (dc NULL: undecomposed) to 1e-12 (the pressure's tolerance). */
static struct solve_result solve(const struct grid *gglobal, const struct decomp *dc,
                                 const enum poisson_bc bc[3][2], int jump)
{
    struct multigrid *mg = NULL;
    char err[256] = "";
    struct grid g = *gglobal;
    int lo[3] = {0, 0, 0};
    if (dc) {
        assert_int_equal(decomp_local_grid(dc, gglobal, &g), 0);
        memcpy(lo, dc->lo, sizeof lo);
        assert_int_equal(multigrid_create_decomposed(&mg, gglobal, dc, bc, NULL, err, sizeof err),
                         0);
    } else {
        assert_int_equal(multigrid_create(&mg, gglobal, bc, NULL, err, sizeof err), 0);
    }
    double *a[3] = {field_alloc(&g), field_alloc(&g), field_alloc(&g)};
    double *rhs = field_alloc(&g);
    struct solve_result r = {field_alloc(&g), 0, 0};
    fill_problem(&g, lo, a, rhs, jump);
    assert_int_equal(multigrid_set_coefficients(mg, a, err, sizeof err), 0);
    struct multigrid_stats st;
    assert_int_equal(multigrid_pcg(mg, rhs, r.phi, 1e-12, 100, &st), 0);
    r.iterations = st.cycles;
    r.levels = multigrid_levels(mg);
    for (int d = 0; d < 3; d++)
        field_free(a[d]);
    field_free(rhs);
    multigrid_destroy(mg);
    return r;
}

/* The decomposed solve over dims ranks equals the undecomposed one (every
 * rank solves that too) to 1e-10 of its largest value: both converge to
 * 1e-12, and their cycles differ only in the order of the dot products'
 * sums, so they also take the same iterations within one. */
static void check_solve_n(const int dims[3], const enum poisson_bc bc[3][2], int jump,
                          const int n[3])
{
    const double h = 1.0 / 48;
    const double len[3] = {n[0] * h, n[1] * h, n[2] * h};
    int periodic[3];
    test_poisson_periodic(bc, periodic);
    struct test_blocks b;
    test_blocks_open(&b, dims, periodic, n, len);
    struct solve_result whole = solve(&b.whole, NULL, bc, jump);
    struct solve_result part = solve(&b.whole, &b.dc, bc, jump);
    double m[2] = {0.0, 0.0}; /* max |difference|, max |phi| */
    for (int i = 0; i < b.g.n[0]; i++)
        for (int j = 0; j < b.g.n[1]; j++)
            for (int k = 0; k < b.g.n[2]; k++) {
                const double w =
                    whole.phi[grid_idx(&b.whole, b.dc.lo[0] + i, b.dc.lo[1] + j, b.dc.lo[2] + k)];
                const double diff = fabs(part.phi[grid_idx(&b.g, i, j, k)] - w);
                m[0] = diff > m[0] ? diff : m[0];
                m[1] = fabs(w) > m[1] ? fabs(w) : m[1];
            }
    comm_max(m, 2);
    if (comm_rank() == 0)
        printf("    ranks %d x %d x %d, %s: %d iterations (undecomposed %d), %d levels on the "
               "ranks, difference %.2e\n", b.cart.dims[0], b.cart.dims[1], b.cart.dims[2],
               jump ? "jump 100" : "smooth a", part.iterations, whole.iterations, part.levels,
               m[0] / m[1]);
    field_free(whole.phi);
    field_free(part.phi);
    test_blocks_close(&b);
    assert_true(m[0] <= 1e-10 * m[1]);
    assert_true(abs(part.iterations - whole.iterations) <= 1);
}

/* 48 x 16 x 48: three levels on the ranks (48, 24 and 12 cells across,
 * the last gathered: 576 cells), blocks of 3 cells there on 4 ranks */
static void check_solve(const int dims[3], const enum poisson_bc bc[3][2], int jump)
{
    const int n[3] = {48, 16, 48};
    check_solve_n(dims, bc, jump, n);
}

/* check_solve on each of test_splits(n, ask). */
static void check_solve_splits(int n, const int ask[][3], const enum poisson_bc bc[3][2],
                               int jump)
{
    int dims[2][3];
    assert_true(n <= 2);
    for (int s = 0, count = test_splits(n, ask, dims); s < count; s++)
        check_solve(dims[s], bc, jump);
}

static void test_multigrid_walls(void **state)
{
    (void)state;
    const enum poisson_bc neumann[3][2] = {{POISSON_NEUMANN, POISSON_NEUMANN},
                                           {POISSON_NEUMANN, POISSON_NEUMANN},
                                           {POISSON_NEUMANN, POISSON_NEUMANN}};
    const enum poisson_bc mixed[3][2] = {{POISSON_NEUMANN, POISSON_DIRICHLET},
                                         {POISSON_NEUMANN, POISSON_NEUMANN},
                                         {POISSON_DIRICHLET, POISSON_NEUMANN}};
    const int p = comm_size();
    const int x_both[2][3] = {{p, 1, 1}, {0, 1, 0}}, z_both[2][3] = {{1, 1, p}, {0, 1, 0}};
    for (int jump = 0; jump < 2; jump++) { /* both: the walls smooth, the mixed faces jump */
        check_solve_splits(jump ? 1 : 2, x_both, neumann, jump);
        check_solve_splits(jump ? 2 : 1, z_both, mixed, jump);
    }
}

static void test_multigrid_periodic(void **state)
{
    (void)state;
    const enum poisson_bc per_x[3][2] = {{POISSON_PERIODIC, POISSON_PERIODIC},
                                         {POISSON_PERIODIC, POISSON_PERIODIC},
                                         {POISSON_NEUMANN, POISSON_DIRICHLET}};
    const enum poisson_bc all[3][2] = {{POISSON_PERIODIC, POISSON_PERIODIC},
                                       {POISSON_PERIODIC, POISSON_PERIODIC},
                                       {POISSON_PERIODIC, POISSON_PERIODIC}};
    const int p = comm_size();
    const int x_both[2][3] = {{p, 1, 1}, {0, 1, 0}}, z_both[2][3] = {{1, 1, p}, {0, 1, 0}};
    for (int jump = 0; jump < 2; jump++) { /* both: x periodic smooth, all periodic jumps */
        check_solve_splits(jump ? 1 : 2, x_both, per_x, jump);
        check_solve_splits(jump ? 2 : 1, z_both, all, jump);
    }
    /* 8 x 64 x 64 on 4 ranks along x: the gathered level's blocks hold one
     * cell of the 4 of the periodic x (coupled across the borders, not the
     * one-cell periodic direction's decoupled cell: 95 iterations then) */
    const int thin[3] = {8, 64, 64}, along[3] = {p, 1, 1};
    check_solve_n(along, per_x, 0, thin);
}

/* ---- the traffic's model (docs/numerics/decomposition.md) ----------------------------- */

/* One exchange per direction sends, per rank border side of d, one plane
 * of (n_e1 + 2)(n_e2 + 2) doubles: the tally equals that exactly. */
static double exchange_traffic_misses(const int dims[3], const int periodic[3], const int n[3])
{
    struct unit_block b;
    unit_block_open(&b, dims, periodic, n);
    const struct decomp *dc = &b.blocks.dc;
    const struct grid *g = &b.blocks.g;
    double *f = b.f;
    long want_bytes = 0, want_messages = 0;
    for (int d = 0; d < 3; d++) {
        const int sides = dc->border[d][0] + dc->border[d][1];
        const long plane = (long)(dc->n[d == 0 ? 1 : 0] + 2) * (dc->n[d == 2 ? 1 : 2] + 2);
        want_messages += sides;
        want_bytes += sides * plane * 8;
    }
    decomp_traffic_reset();
    for (int d = 0; d < 3; d++)
        decomp_exchange(dc, g, f, d);
    struct decomp_traffic t;
    decomp_traffic_read(&t);
    unit_block_close(&b);
    return (t.bytes != want_bytes) + (t.messages != want_messages) +
           (comm_size() > 1 && want_bytes == 0); /* every rank has a border */
}

/* One cycle and one PCG solve of check_solve's problem (three levels on
 * the ranks, W-cycles, the gathered level cold and warm): the tally, the
 * gathers and the sums over the ranks equal multigrid_traffic_model. */
static double multigrid_traffic_misses(const int dims[3], const enum poisson_bc bc[3][2])
{
    const int n[3] = {48, 16, 48};
    const double h = 1.0 / 48;
    const double len[3] = {n[0] * h, n[1] * h, n[2] * h};
    int periodic[3];
    test_poisson_periodic(bc, periodic);
    struct test_blocks b;
    test_blocks_open(&b, dims, periodic, n, len);
    struct multigrid *mg = NULL;
    char err[256];
    assert_int_equal(
        multigrid_create_decomposed(&mg, &b.whole, &b.dc, bc, NULL, err, sizeof err), 0);
    double *a[3] = {field_alloc(&b.g), field_alloc(&b.g), field_alloc(&b.g)};
    double *rhs = field_alloc(&b.g), *phi = field_alloc(&b.g);
    fill_problem(&b.g, b.dc.lo, a, rhs, 0);
    assert_int_equal(multigrid_set_coefficients(mg, a, err, sizeof err), 0);
    struct decomp_traffic cycle, solve, cycle_model, solve_model;
    decomp_traffic_reset();
    multigrid_cycle(mg, rhs, phi);
    decomp_traffic_read(&cycle);
    for (size_t p = 0; p < b.g.size; p++)
        phi[p] = 0.0;
    struct multigrid_stats st;
    decomp_traffic_reset();
    const long r0 = comm_reductions();
    assert_int_equal(multigrid_pcg(mg, rhs, phi, 1e-12, 100, &st), 0);
    const long reductions = comm_reductions() - r0;
    decomp_traffic_read(&solve);
    long reductions_model;
    multigrid_traffic_model(mg, st.cycles, &cycle_model, &solve_model, &reductions_model);
    const double misses = (memcmp(&cycle, &cycle_model, sizeof cycle) != 0) +
                          (memcmp(&solve, &solve_model, sizeof solve) != 0) +
                          (comm_size() > 1 && reductions != reductions_model) +
                          (comm_size() > 1 && (cycle.gathers == 0 || cycle.bytes == 0));
    for (int d = 0; d < 3; d++)
        field_free(a[d]);
    field_free(rhs);
    field_free(phi);
    multigrid_destroy(mg);
    test_blocks_close(&b);
    return misses;
}

static void test_traffic_model(void **state)
{
    (void)state;
    const int p = comm_size();
    const int along_x[3] = {p, 1, 1}, along_z[3] = {1, 1, p}, any[3] = {0, 0, 0};
    const int walls[3] = {0, 0, 0}, per[3] = {1, 1, 0}, n[3] = {6, 5, 8};
    const enum poisson_bc neumann[3][2] = {{POISSON_NEUMANN, POISSON_NEUMANN},
                                           {POISSON_NEUMANN, POISSON_NEUMANN},
                                           {POISSON_NEUMANN, POISSON_NEUMANN}};
    const enum poisson_bc per_x[3][2] = {{POISSON_PERIODIC, POISSON_PERIODIC},
                                         {POISSON_PERIODIC, POISSON_PERIODIC},
                                         {POISSON_NEUMANN, POISSON_DIRICHLET}};
    double misses = exchange_traffic_misses(along_x, walls, n) +
                    exchange_traffic_misses(along_z, walls, n) +
                    exchange_traffic_misses(any, per, n) +
                    multigrid_traffic_misses(along_x, neumann) +
                    multigrid_traffic_misses(any, per_x);
    comm_sum(&misses, 1);
    assert_true(misses == 0.0);
}

/* ---- the ranks' HDF5 files (io/h5blocks.h) ------------------------------------------ */

/* Differences between dataset name of files a and b (shape and every
 * byte); 1 when either lacks it. */
static int dataset_differs(hid_t a, hid_t b, const char *name)
{
    hid_t f[2] = {a, b};
    double *v[2] = {NULL, NULL};
    hsize_t dims[2][4] = {{0}};
    int rank[2] = {-1, -1};
    size_t n[2] = {0, 0};
    for (int s = 0; s < 2; s++) {
        if (H5Lexists(f[s], name, H5P_DEFAULT) <= 0)
            return 1;
        hid_t set = H5Dopen2(f[s], name, H5P_DEFAULT), space = H5Dget_space(set);
        rank[s] = H5Sget_simple_extent_ndims(space);
        H5Sget_simple_extent_dims(space, dims[s], NULL);
        n[s] = (size_t)H5Sget_simple_extent_npoints(space);
        v[s] = malloc(n[s] * sizeof(double) + 1);
        if (H5Dread(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v[s]) < 0)
            rank[s] = -2 - s;
        H5Sclose(space);
        H5Dclose(set);
    }
    int bad = rank[0] != rank[1] || n[0] != n[1] || rank[0] < 0 ||
              memcmp(dims[0], dims[1], sizeof dims[0]) != 0 ||
              memcmp(v[0], v[1], n[0] * sizeof(double)) != 0;
    if (bad) {
        size_t at = 0;
        while (rank[0] >= 0 && at < n[0] && at < n[1] &&
               memcmp(&v[0][at], &v[1][at], sizeof(double)) == 0)
            at++;
        print_error("dataset %s differs, first at %zu of %zu: %.17g, %.17g\n", name, at, n[0],
                    at < n[0] ? v[0][at] : 0.0, at < n[1] ? v[1][at] : 0.0);
    }
    free(v[0]);
    free(v[1]);
    return bad;
}

/* Attribute name of a and b: the same type, the same bytes. */
struct attribute_check {
    hid_t b;
    int bad;
};

static herr_t attribute_differs(hid_t a, const char *name, const H5A_info_t *info, void *vc)
{
    (void)info;
    struct attribute_check *check = vc;
    hid_t b = check->b;
    if (H5Aexists(b, name) <= 0) {
        print_error("attribute %s missing\n", name);
        check->bad++;
        return 0;
    }
    hid_t at[2] = {H5Aopen(a, name, H5P_DEFAULT), H5Aopen(b, name, H5P_DEFAULT)};
    hid_t type[2] = {H5Aget_type(at[0]), H5Aget_type(at[1])};
    hid_t space[2] = {H5Aget_space(at[0]), H5Aget_space(at[1])};
    size_t size = H5Tget_size(type[0]) * (size_t)H5Sget_simple_extent_npoints(space[0]);
    char *x = calloc(2, size + 1);
    int same = H5Tequal(type[0], type[1]) > 0 &&
               H5Sget_simple_extent_npoints(space[1]) == H5Sget_simple_extent_npoints(space[0]) &&
               H5Aread(at[0], type[0], x) >= 0 && H5Aread(at[1], type[0], x + size + 1) >= 0 &&
               memcmp(x, x + size + 1, size) == 0;
    if (!same) {
        print_error("attribute %s differs\n", name);
        check->bad++;
    }
    free(x);
    for (int s = 0; s < 2; s++) {
        H5Sclose(space[s]);
        H5Tclose(type[s]);
        H5Aclose(at[s]);
    }
    return 0;
}

/* Differences between two field files of st's registry: every dataset and
 * every root attribute (both ways: the same set). */
static int fields_files_differ(const char *pa, const char *pb, const struct march_state *st)
{
    hid_t a = H5Fopen(pa, H5F_ACC_RDONLY, H5P_DEFAULT), b = H5Fopen(pb, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (a < 0 || b < 0) {
        print_error("cannot open %s or %s\n", pa, pb);
        return 1;
    }
    int bad = 0;
    const struct field_registry *r = &st->fields;
    for (int o = 0; o < r->noutputs; o++) {
        bad += dataset_differs(a, b, r->out[o].name);
        for (int c = 0; c < 3 && r->out[o].components[c]; c++)
            bad += dataset_differs(a, b, r->out[o].components[c]);
    }
    H5O_info_t ia, ib;
    H5Oget_info2(a, &ia, H5O_INFO_NUM_ATTRS);
    H5Oget_info2(b, &ib, H5O_INFO_NUM_ATTRS);
    bad += ia.num_attrs != ib.num_attrs || ia.num_attrs < 10;
    struct attribute_check check = {b, 0};
    H5Aiterate2(a, H5_INDEX_NAME, H5_ITER_INC, NULL, attribute_differs, &check);
    bad += check.bad;
    H5Fclose(a);
    H5Fclose(b);
    return bad;
}

/* The global slot of local slot t along d: across a split periodic
 * direction's end the wrapped one (what the exchange brings). */
static int wrapped(const struct decomp *dc, int d, int t, int periodic)
{
    int G = dc->lo[d] + t, N = dc->n_global[d];
    return periodic && dc->cart->dims[d] > 1 ? (G + N) % N : G;
}

/* A rank's march: st's with the block of every field on local grid gl,
 * ghosts as the exchange leaves them; the maps' context its own. */
static struct march_state *block_march(const struct march_state *st, const struct decomp *dc,
                                       const struct grid *gl)
{
    struct march_state *loc = malloc(sizeof *loc);
    assert_non_null(loc);
    *loc = *st;
    loc->g = *gl;
    loc->fields.g = &loc->g;
    int per[3];
    for (int d = 0; d < 3; d++)
        per[d] = st->bc.face[d][0] == BC_PERIODIC;
    struct field_registry *r = &loc->fields;
    for (int e = 0; e < r->count; e++)
        for (int c = 0; c < 3; c++) {
            const double *src = st->fields.e[e].v[c];
            if (!src || (c > 0 && r->e[e].spec.where == FIELD_CELLS)) {
                r->e[e].v[c] = NULL;
                continue;
            }
            double *f = field_alloc(gl);
            assert_non_null(f);
            for (int i = -1; i <= gl->n[0]; i++)
                for (int j = -1; j <= gl->n[1]; j++)
                    for (int k = -1; k <= gl->n[2]; k++)
                        f[grid_idx(gl, i, j, k)] =
                            src[grid_idx(&st->g, wrapped(dc, 0, i, per[0]),
                                         wrapped(dc, 1, j, per[1]), wrapped(dc, 2, k, per[2]))];
            r->e[e].v[c] = f;
            if (src == st->field.pressure_regularised)
                loc->field.pressure_regularised = f;
        }
    for (int o = 0; o < r->noutputs; o++)
        if (r->out[o].ctx == st)
            r->out[o].ctx = loc;
    return loc;
}

static void block_march_free(struct march_state *loc)
{
    struct field_registry *r = &loc->fields;
    for (int e = 0; e < r->count; e++)
        for (int c = 0; c < 3; c++)
            field_free(r->e[e].v[c]);
    free(loc);
}

/* The field file written by the ranks' blocks (fields_h5_write_decomposed)
 * holds every dataset and attribute of the serial writer's file of the
 * same global state byte for byte: a chute of 8 x 6 x 8 cells (x, z
 * periodic: as many faces as cells; y walls: 7 faces), every slot of every
 * field a value of its own, split along x, y, z and all, on this run's
 * ranks (one: the serial library). */
static void test_fields_file_blocks(void **state)
{
    (void)state;
    char *ov[] = {"domain.nx=8", "domain.lx=2.8", "domain.ny=6", "domain.ly=2.1",
                  "domain.nz=8", "domain.lz=2.8"};
    struct muflow_case cs;
    test_load_case(&cs, "../cases/chute.ini", 6, ov);
    struct march_state st;
    char err[1024] = "", dir[256], serial[512], ranks[512];
    assert_int_equal(scene_march_create(&st, &cs, NULL, err, sizeof err), 0);
    for (int e = 0; e < st.fields.count; e++)
        for (int c = 0; c < 3; c++)
            for (size_t p = 0; st.fields.e[e].v[c] && p < st.g.size; p++)
                st.fields.e[e].v[c][p] = 1e6 * (e + 1) + 1e5 * c + (double)p + 0.125;
    st.step = 42;
    st.time = 1.0 / 3.0;
    st.dt = 0.1;
    test_ranks_dir(dir, sizeof dir, "fields");
    snprintf(serial, sizeof serial, "%s/serial", dir);
    snprintf(ranks, sizeof ranks, "%s/ranks", dir);
    double bad = 0.0;
    if (comm_rank() == 0) {
        mkdir(serial, 0700);
        mkdir(ranks, 0700);
        bad += fields_h5_write(serial, &st, err, sizeof err) != 0;
    }
    comm_barrier();
    const int p = comm_size();
    const int splits[4][3] = {{p, 1, 1}, {1, p, 1}, {1, 1, p}, {0, 0, 0}};
    const int periodic[3] = {1, 0, 1};
    int dims[4][3];
    for (int s = 0, count = test_splits(4, splits, dims); s < count; s++) {
        struct test_blocks b; /* its whole grid the march's: cs.n over cs.len */
        test_blocks_open(&b, dims[s], periodic, cs.n, cs.len);
        struct march_state *loc = block_march(&st, &b.dc, &b.g);
        int rc = fields_h5_write_decomposed(ranks, loc, &st.g, &b.dc, err, sizeof err);
        if (rc != 0)
            print_error("%s\n", err);
        bad += rc != 0;
        if (rc == 0 && comm_rank() == 0) {
            char pa[700], pb[700], name[64];
            fields_h5_name(st.step, name, sizeof name);
            snprintf(pa, sizeof pa, "%s/%s", serial, name);
            snprintf(pb, sizeof pb, "%s/%s", ranks, name);
            const int differ = fields_files_differ(pa, pb, &st);
            if (differ)
                print_error("split %d x %d x %d\n", b.cart.dims[0], b.cart.dims[1],
                            b.cart.dims[2]);
            bad += differ;
        }
        block_march_free(loc);
        test_blocks_close(&b);
        comm_barrier(); /* rank 0 has read the file before the next overwrites it */
    }
    comm_sum(&bad, 1);
    march_destroy(&st);
    test_ranks_dir_remove(dir);
    assert_true(bad == 0.0);
}

/* ---- a checkpoint's fields across rank counts -------------------------------------- */

/* Global arrays with every ghost (the checkpoint's layout) of a 12 x 6 x 10
 * grid periodic along x: a value of its own in each slot, the periodic
 * ghosts the images of the cells (as the boundary fill leaves them). */
#define SET_FIELDS 5
static void fill_global(const struct grid *gg, double *f[SET_FIELDS])
{
    for (int s = 0; s < SET_FIELDS; s++)
        for (int i = -1; i <= gg->n[0]; i++)
            for (int j = -1; j <= gg->n[1]; j++)
                for (int k = -1; k <= gg->n[2]; k++) {
                    const int ii = (i + gg->n[0]) % gg->n[0];
                    f[s][grid_idx(gg, i, j, k)] = s + 0.01 * ii + 1e-4 * j + 1e-6 * k + 1e-9;
                }
}

static const char *const set_names[SET_FIELDS] = {"pressure", "viscosity", "velocity_x",
                                                  "velocity_y", "velocity_z"};

struct full_set {
    const struct grid *gg;
    double *const *f;
};

static int write_full_set(hid_t file, void *vctx, char *err, size_t errlen)
{
    const struct full_set *fs = vctx;
    hsize_t dims[3];
    for (int d = 0; d < 3; d++)
        dims[d] = (hsize_t)fs->gg->n[d] + 2;
    for (int s = 0; s < SET_FIELDS; s++)
        if (h5io_write(file, set_names[s], H5T_NATIVE_DOUBLE, 3, dims, fs->f[s], err, errlen))
            return -1;
    return 0;
}

/* Reads the file back as every block of a decomposition of q ranks
 * (dims), each rank reading them all: the differing slots, ghosts
 * included, against the global arrays. */
static double read_as(const char *path, const struct grid *gg, double *const f[SET_FIELDS],
                      const int dims[3])
{
    double bad = 0.0;
    const int q = dims[0] * dims[1] * dims[2];
    for (int r = 0; r < q; r++) {
        struct comm_cart cart = {.dims = {dims[0], dims[1], dims[2]}};
        cart.coords[0] = r / (dims[1] * dims[2]);
        cart.coords[1] = r / dims[2] % dims[1];
        cart.coords[2] = r % dims[2];
        for (int d = 0; d < 3; d++)
            cart.nbr[d][0] = cart.nbr[d][1] = -1;
        struct decomp dc;
        struct grid g;
        char err[512];
        assert_int_equal(decomp_create(&dc, &cart, gg->n, err, sizeof err), 0);
        assert_int_equal(decomp_local_grid(&dc, gg, &g), 0);
        double *loc = field_alloc(&g), *buf = field_alloc(&g);
        for (int s = 0; s < SET_FIELDS; s++) {
            if (h5blocks_read_full(path, set_names[s], &dc, &g, loc, buf, err, sizeof err)) {
                print_error("%s\n", err);
                bad += 1;
                continue;
            }
            for (int i = -1; i <= g.n[0]; i++)
                for (int j = -1; j <= g.n[1]; j++)
                    for (int k = -1; k <= g.n[2]; k++) {
                        const double w = f[s][grid_idx(gg, dc.lo[0] + i, dc.lo[1] + j,
                                                       dc.lo[2] + k)];
                        bad += memcmp(&w, &loc[grid_idx(&g, i, j, k)], sizeof w) != 0;
                    }
        }
        field_free(loc);
        field_free(buf);
        decomp_free(&dc);
    }
    return bad;
}

/* Fields written by this run's ranks, each its block with the domain's
 * ghosts (h5blocks_put_full), make the serial writer's file byte for byte,
 * and read back as the blocks of 1, 2 and 4 ranks, ghosts included, they
 * are the written arrays bit for bit. */
static void test_checkpoint_fields_any_ranks(void **state)
{
    (void)state;
    const int n[3] = {12, 6, 10}, periodic[3] = {1, 0, 0}, any[3] = {0, 0, 0};
    const double len[3] = {1.2, 0.6, 1.0};
    struct test_blocks b;
    test_blocks_open(&b, any, periodic, n, len);
    double *f[SET_FIELDS];
    for (int s = 0; s < SET_FIELDS; s++)
        assert_non_null(f[s] = field_alloc(&b.whole));
    fill_global(&b.whole, f);
    char dir[256], serial[512], ranks[512], err[1024] = "";
    test_ranks_dir(dir, sizeof dir, "checkpoint");
    snprintf(serial, sizeof serial, "%s/serial.h5", dir);
    snprintf(ranks, sizeof ranks, "%s/ranks.h5", dir);
    double bad = 0.0;
    struct full_set fs = {&b.whole, f};
    if (comm_rank() == 0) {
        char tmp[600];
        snprintf(tmp, sizeof tmp, "%s.tmp", serial);
        bad += h5io_write_file(tmp, serial, "", write_full_set, &fs, err, sizeof err) != 0;
    }
    double *loc = field_alloc(&b.g), *buf = field_alloc(&b.g);
    struct h5blocks w;
    int rc = h5blocks_create(&w, &b.cart, ranks, err, sizeof err);
    for (int s = 0; rc == 0 && s < SET_FIELDS; s++) {
        /* the block, its ghosts as the exchange and the boundary fill leave them */
        for (int i = -1; i <= b.g.n[0]; i++)
            for (int j = -1; j <= b.g.n[1]; j++)
                for (int k = -1; k <= b.g.n[2]; k++)
                    loc[grid_idx(&b.g, i, j, k)] = f[s][grid_idx(
                        &b.whole, wrapped(&b.dc, 0, i, 1), b.dc.lo[1] + j, b.dc.lo[2] + k)];
        rc = h5blocks_put_full(&w, set_names[s], &b.dc, &b.g, loc, buf, err, sizeof err);
    }
    if (rc == 0)
        rc = h5blocks_finish(&w, "checkpoint", NULL, NULL, err, sizeof err);
    if (rc != 0)
        print_error("%s\n", err);
    bad += rc != 0;
    comm_barrier();
    if (rc == 0 && comm_rank() == 0) {
        hid_t a = H5Fopen(serial, H5F_ACC_RDONLY, H5P_DEFAULT);
        hid_t b = H5Fopen(ranks, H5F_ACC_RDONLY, H5P_DEFAULT);
        for (int s = 0; s < SET_FIELDS; s++)
            bad += a < 0 || b < 0 || dataset_differs(a, b, set_names[s]);
        H5Fclose(a);
        H5Fclose(b);
    }
    const int one[3] = {1, 1, 1}, two_x[3] = {2, 1, 1}, two_z[3] = {1, 1, 2}, four[3] = {2, 1, 2};
    if (rc == 0)
        bad += read_as(ranks, &b.whole, f, one) + read_as(ranks, &b.whole, f, two_x) +
               read_as(ranks, &b.whole, f, two_z) + read_as(ranks, &b.whole, f, four);
    comm_sum(&bad, 1);
    if (comm_rank() == 0)
        printf("    written on %d ranks (%d x %d x %d), read as 1, 2, 4: %g slots differ\n",
               comm_size(), b.cart.dims[0], b.cart.dims[1], b.cart.dims[2], bad);
    field_free(loc);
    field_free(buf);
    test_blocks_close(&b);
    for (int s = 0; s < SET_FIELDS; s++)
        field_free(f[s]);
    test_ranks_dir_remove(dir);
    assert_true(bad == 0.0);
}

/* The collapse (two phases, the VOF, the variable-density pressure, its
 * measures over the ranks) at 8 cells per H0 in a box 4 H0 long to t = 0.6
 * (60 steps, the front from the column's 2 to 2.12: across the rank border
 * at x = 2 of a split in two along x; in four, the grains on both sides of
 * the border at 1), split along x, along z and both; with an open top
 * split along z and both (a rank border below the top is no open face: 2 x
 * 2 ranks diverged at step 5 when it was one). */
static void test_collapse_on_ranks(void **state)
{
    (void)state;
    char *ov[] = {"domain.lx=4", "domain.nx=32", "domain.nz=12", "solver.end_time=0.6"};
    static const char *const keys[] = {"x_front", "h_axis", "kinetic_energy",
                                       "kinetic_energy_peak", "x_front_err_max",
                                       "h_axis_err_max", NULL};
    const struct scene_lines closed = {.file = "../cases/collapse.ini", .n = 4, .ov = ov,
                                       .keys = keys, .want = STATUS_FINISHED};
    const int p = comm_size();
    const int splits[3][3] = {{p, 1, 1}, {1, 1, p}, {0, 1, 0}}; /* x, z, both */
    check_scene_splits(&closed, 3, splits);
    char *top[] = {"domain.lx=4", "domain.nx=32", "domain.nz=12", "solver.end_time=0.6",
                   "boundary.zhi=open"};
    struct scene_lines open = closed;
    open.n = 5;
    open.ov = top;
    check_scene_splits(&open, 2, splits + 1);
}

/* 4 x 2 cells across: 2 ranks split x, 4 split x and y (2 x 2) */
static void test_couette_on_ranks(void **state)
{
    (void)state;
    char *ov[] = {"domain.nx=4", "domain.lx=0.2", "domain.ny=2", "domain.ly=0.1"};
    /* the parabola and the line are exact on the grid: u_mid to round-off */
    check_scene_on_ranks("../cases/couette.ini", 4, ov, 1e-12, STATUS_STEADY);
}

static void test_bagnold_on_ranks(void **state)
{
    (void)state;
    char *ov[] = {"domain.nx=4", "domain.lx=1.4", "domain.ny=2", "domain.ly=0.7"};
    /* h = H / 40: u_surface 2.2e-4 above Bagnold's (docs/numerics) */
    check_scene_on_ranks("../cases/bagnold.ini", 4, ov, 1e-3, STATUS_STEADY);
}

static void test_bingham_channel_on_ranks(void **state)
{
    (void)state;
    /* a first step of 1, not 0.01: the same steady state in 11 steps, not 44 */
    char *ov[] = {"domain.nx=4", "domain.lx=0.1", "domain.ny=2", "domain.ly=0.05", "solver.dt=1"};
    /* h = H / 40, lambda 1e-4: u_plug 1.5e-3 above the exact plug */
    check_scene_on_ranks("../cases/bingham_channel.ini", 5, ov, 2e-3, STATUS_STEADY);
}

/* The fluidity's creeping zones on the ranks' z lines: ngf_chute
 * accelerated (50 steps to steady), ngf_shear by the plain Picard steps
 * (108): accelerated, it ends where its residual stalls at the round-off
 * (1e-6), and that stall's step moved with the ranks' order of the sums
 * (39 steps alone, 41 on 2 ranks, the values within 2e-15).  No
 * closed-form velocity (exact NaN) */
static void test_ngf_walls_on_ranks(void **state)
{
    (void)state;
    char *ov[] = {"domain.nx=4", "domain.lx=1", "domain.ny=2", "domain.ly=0.5",
                  "rheology.fluidity_anderson=0"};
    check_scene_on_ranks("../cases/ngf_chute.ini", 4, ov, NAN, STATUS_STEADY);
    check_scene_on_ranks("../cases/ngf_shear.ini", 5, ov, NAN, STATUS_STEADY);
}

/* The nonlocal fluidity's z lines on each rank, its steady iteration
 * accelerated (sums over the ranks): steady in 47 steps; and 60 of the
 * plain Picard's 252 (the flow still growing), so that the ranks' run is
 * cut at the same step as one process's (status unsteady: max_steps); no
 * closed form (exact NaN) */
static void test_ngf_incline_on_ranks(void **state)
{
    (void)state;
    char *ov[] = {"domain.nx=4", "domain.lx=1", "domain.ny=2", "domain.ly=0.5",
                  "solver.max_steps=60", "rheology.fluidity_anderson=0"};
    check_scene_on_ranks("../cases/ngf_incline.ini", 4, ov, NAN, STATUS_STEADY);
    check_scene_on_ranks("../cases/ngf_incline.ini", 6, ov, NAN, STATUS_UNSTEADY);
}

static void test_bedload_on_ranks(void **state)
{
    (void)state;
    char *ov[] = {"domain.nx=4", "domain.lx=0.0065", "domain.ny=2", "domain.ly=0.00325"};
    /* h = D / 40: u_max 1.3e-3 above Ouriemi et al.'s */
    check_scene_on_ranks("../cases/bedload.ini", 4, ov, 2e-3, STATUS_STEADY);
}

/* periodic x and z (the flow) split: 2 ranks along one, 4 along both */
static void test_chute_on_ranks(void **state)
{
    (void)state;
    /* a first step of 100, not 1: the same steady state in 10 steps, not 45 */
    char *ov[] = {"domain.nx=2", "domain.lx=0.7", "solver.dt=100"};
    /* h = b / 80: u_plug 0.56% above the exact plug (docs/validation/chute.md) */
    check_scene_on_ranks("../cases/chute.ini", 3, ov, 6e-3, STATUS_STEADY);
}

/* Transient with advection over the ranks: the perturbed layer to t = 0.5
 * (10 steps of 0.05: the flow varies in x, y and z, and u.grad u with it;
 * CG converges, 90 iterations a step); far from the steady surface
 * velocity, the exact value (tol infinite: not compared) */
static void test_bagnold_transient_on_ranks(void **state)
{
    (void)state;
    char *ov[] = {"domain.nx=4",          "domain.lx=3.5",     "domain.ny=2",
                  "domain.ly=1.75",       "domain.nz=16",      "bagnold.perturbation=0.1",
                  "solver.mode=transient", "solver.end_time=0.5", "solver.dt=0.05",
                  "physics.advection=on"};
    check_scene_on_ranks("../cases/bagnold.ini", 10, ov, INFINITY, STATUS_FINISHED);
}

/* bagnold.perturbation on the ranks: every rank's block of the initial
 * velocity is one process's, bit for bit (the deviates by the global index,
 * the scale by the largest face velocity over the ranks), whose largest
 * face velocity is the perturbation times the exact surface velocity.  A
 * run's steady end is not the check (it forgets its start), nor its first
 * steps: the line-preconditioned CG stops at its 500 iterations there, at
 * a residual that depends on the order of the ranks' sums. */
static void test_bagnold_perturbation_on_ranks(void **state)
{
    (void)state;
    char *ov[] = {"domain.nx=4", "domain.lx=3.5", "domain.ny=2", "domain.ly=1.75",
                  "domain.nz=16", "bagnold.perturbation=0.1"};
    struct muflow_case cs;
    test_load_case(&cs, "../cases/bagnold.ini", 6, ov);
    struct march_setup su;
    scene_march_setup(&cs, NULL, &su);
    struct march_state one, split;
    char err[1024] = "";
    int rc = march_create(&one, &cs, &su, err, sizeof err);
    su.decompose = 1;
    rc |= march_create(&split, &cs, &su, err, sizeof err);
    if (rc != 0)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
    const int *lo = split.ranks ? split.ranks->dc.lo : (const int[3]){0, 0, 0};
    const struct grid *g = &split.g;
    double differ = 0.0, umax = 0.0;
    for (int c = 0; c < 3; c++)
        for (int i = 0; i < g->n[0]; i++)
            for (int j = 0; j < g->n[1]; j++)
                for (int k = 0; k < g->n[2]; k++) {
                    double u = split.field.velocity[c][grid_idx(g, i, j, k)];
                    differ += u != one.field.velocity[c][grid_idx(&one.g, lo[0] + i, lo[1] + j,
                                                                  lo[2] + k)];
                    umax = fmax(umax, fabs(u));
                }
    comm_sum(&differ, 1);
    umax = march_max(&split, umax);
    const double want = 0.1 * scene_exact_at(&cs, cs.len[2]);
    if (comm_rank() == 0)
        printf("    perturbation on %d ranks: %g faces differ from one process's, largest "
               "%.15g (0.1 u(H) %.15g)\n", comm_size(), differ, umax, want);
    march_destroy(&split);
    march_destroy(&one);
    assert_true(differ == 0.0);
    assert_true(fabs(umax - want) <= 1e-14 * want);
}

/* mpirun CMD on two ranks in a clean environment (see below): its output
 * and status line "rc=N" in *out. */
static void mpirun_two(const char *bin, const char *args, char **out)
{
    char cmd[14000];
    snprintf(cmd, sizeof cmd,
             "env -i PATH=\"$PATH\" HOME=\"$HOME\" ASAN_OPTIONS=detect_leaks=0 "
             "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=1 "
             "OMP_WAIT_POLICY=passive mpirun -np 2 --oversubscribe '%s' %s 2>&1; "
             "echo \"rc=$?\"",
             bin, args);
    assert_int_equal(test_sh(cmd, out), 0);
}

/* Started by mpirun on two ranks, muflow refuses an option that does not
 * run decomposed (the coupled step's GMRES: status 2), says so once, naming
 * what does, and writes nothing, and a scene's keys that do not, naming
 * them; couette
 * runs, its header naming the ranks, and writes its outputs once (rank 0),
 * its field files and checkpoint (every rank's block), and `mpirun muflow
 * --restart` continues it, as does one process without mpirun (FFTW's
 * wisdom of the ranks' plans left out).  Run only outside mpirun (an
 * mpirun does not start another), in a clean environment: hypre's MPI, initialised in this process by the amg
 * group, leaves Open MPI's variables in it, and an mpirun that inherits them
 * fails (status 1, nothing said); under the sanitizers the leak check is
 * off for that muflow (Open MPI's own allocations at exit, as for the amg
 * group in check-asan). */
static void test_muflow_on_ranks(void **state)
{
    (void)state;
    if (comm_launched())
        skip();
    char bin[4096], dir[4096], args[9000], path[4200];
    test_muflow_bin(bin, sizeof bin);
    test_tmp_make(dir, sizeof dir, "mpi_ranks");
    snprintf(args, sizeof args,
             "../cases/cylinder.ini solver.preconditioner=multigrid output.dir='%s/cyl'", dir);
    char *out = NULL;
    mpirun_two(bin, args, &out);
    int said = 0;
    /* once, naming the option and what does run */
    for (const char *p = out;
         (p = strstr(p, "solver.coupled = on with solver.preconditioner = amg or multigrid does "
                        "not run decomposed (what does: solver.coupled = off, or on with the LU"));
         p++)
        said++;
    snprintf(path, sizeof path, "%s/cyl/summary.ini", dir);
    const int wrote = test_file_exists(path), status2 = strstr(out, "rc=2\n") != NULL;
    if (said != 1 || !status2 || wrote)
        print_error("%s", out);
    free(out);
    /* a scene that runs decomposed but not with these keys names them */
    snprintf(args, sizeof args, "../cases/bedload.ini bedload.model=two_fluid output.dir='%s/bed'",
             dir);
    mpirun_two(bin, args, &out);
    const int keys_said = strstr(out, "case.scene = bedload with bedload.model = two_fluid does "
                                      "not run decomposed") && strstr(out, "rc=2\n");
    if (!keys_said)
        print_error("%s", out);
    free(out);
    /* a preconditioner named that is not decomposed (auto would take the
     * multigrid) names the key, before the split it would decide */
    snprintf(args, sizeof args, "../cases/bingham_cavity.ini solver.preconditioner=cholesky "
             "output.dir='%s/cavity'", dir);
    mpirun_two(bin, args, &out);
    const int named = strstr(out, "solver.preconditioner = cholesky does not run decomposed") &&
                      strstr(out, "rc=2\n");
    if (!named)
        print_error("%s", out);
    free(out);
    /* the collapse under the nonlocal fluidity, whose box multigrid is one
     * process's, names the fluidity's solver */
    snprintf(args, sizeof args, "../cases/collapse.ini rheology.law=ngf domain.nx=80 "
             "domain.nz=24 domain.ly=0.0625 output.dir='%s/ngf'", dir);
    mpirun_two(bin, args, &out);
    const int ngf_named = strstr(out, "rheology.fluidity_solver = multigrid") &&
                          strstr(out, "runs on one process") && strstr(out, "rc=2\n");
    if (!ngf_named)
        print_error("%s", out);
    free(out);
    /* stopped at step 3 (status 3) with a field file every 2 steps and a
     * checkpoint, continued on the ranks to steady (6 steps, as in one go) */
    snprintf(args, sizeof args,
             "../cases/couette.ini output.dir='%s/couette' solver.max_steps=3 "
             "output.fields_every=2",
             dir);
    mpirun_two(bin, args, &out);
    snprintf(path, sizeof path, "%s/couette/fields_000002.h5", dir);
    int ran = strstr(out, "rc=3\n") && strstr(out, "ranks 2 (2 x 1 x 1)") &&
              strstr(out, "unsteady after 3 steps") && test_file_exists(path);
    snprintf(path, sizeof path, "%s/couette/checkpoint.h5", dir);
    ran = ran && test_file_exists(path);
    if (!ran)
        print_error("%s", out);
    free(out);
    snprintf(args, sizeof args, "--restart '%s/couette' solver.max_steps=100", dir);
    mpirun_two(bin, args, &out);
    snprintf(path, sizeof path, "%s/couette/summary.ini", dir);
    char *summary = test_file_exists(path) ? test_read_file(path, NULL) : NULL;
    snprintf(path, sizeof path, "%s/couette/fields_000006.h5", dir);
    const int continued = strstr(out, "rc=0\n") && strstr(out, "continuing from") &&
                          strstr(out, "steady after 6 steps") && summary &&
                          strstr(summary, "status = steady") && test_file_exists(path);
    if (!continued)
        print_error("%s", out);
    free(out);
    free(summary);
    /* stopped on the ranks again, continued by one process */
    snprintf(args, sizeof args,
             "../cases/couette.ini output.dir='%s/couette1' solver.max_steps=3", dir);
    mpirun_two(bin, args, &out);
    free(out);
    char cmd[9000];
    snprintf(cmd, sizeof cmd,
             "env -i PATH=\"$PATH\" HOME=\"$HOME\" OMP_NUM_THREADS=1 '%s' --restart "
             "'%s/couette1' solver.max_steps=100 2>&1; echo \"rc=$?\"",
             bin, dir);
    assert_int_equal(test_sh(cmd, &out), 0);
    const int serial = strstr(out, "rc=0\n") && strstr(out, "steady after 6 steps");
    if (!serial)
        print_error("%s", out);
    free(out);
    test_tmp_remove(dir);
    assert_int_equal(said, 1);
    assert_true(status2);
    assert_false(wrote);
    assert_true(keys_said);
    assert_true(named);
    assert_true(ngf_named);
    assert_true(ran);
    assert_true(continued);
    assert_true(serial);
}

/* test_mpi_fft.c */
void test_fft_ranks_periodic(void **state);
void test_fft_ranks_dirichlet(void **state);
void test_fft_ranks_uniform(void **state);
/* test_mpi_fourier.c */
void test_fourier_lines_ranks(void **state);
void test_bagnold3d_on_ranks(void **state);
/* test_mpi_traffic.c */
void test_bagnold3d_traffic(void **state);
/* test_mpi_vof.c */
void test_vof_ranks(void **state);
void test_pressure_ranks_variable(void **state);
/* test_mpi_vmg.c */
void test_vmg_ranks_plane(void **state);
void test_vmg_ranks_box(void **state);
void test_vmg_ranks_augmented(void **state);
void test_bingham_cavity_on_ranks(void **state);
void test_vmg_scenes_on_ranks(void **state);
/* test_mpi_gmg.c */
void test_gmg_ranks(void **state);
void test_heap_on_ranks(void **state);
/* test_mpi_bodies.c */
void test_cylinder_benchmark_on_ranks(void **state);
void test_slope_release_on_ranks(void **state);
void test_cylinder_on_ranks(void **state);
void test_cylinder_velocity_on_ranks(void **state);
void test_initial_state_on_ranks(void **state);
/* test_mpi_measures.c */
void test_wall_shock_on_ranks(void **state);
void test_front_on_ranks(void **state);
void test_front_shipped_on_ranks(void **state);
void test_bagnold2_on_ranks(void **state);
void test_duct_square_on_ranks(void **state);
void test_duct_circular_on_ranks(void **state);

void group_mpi(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_blocks_tile),
        cmocka_unit_test(test_exchange_walls),
        cmocka_unit_test(test_exchange_periodic),
        cmocka_unit_test(test_multigrid_walls),
        cmocka_unit_test(test_multigrid_periodic),
        cmocka_unit_test(test_traffic_model),
        cmocka_unit_test(test_fields_file_blocks),
        cmocka_unit_test(test_checkpoint_fields_any_ranks),
        cmocka_unit_test(test_fft_ranks_periodic),
        cmocka_unit_test(test_fft_ranks_dirichlet),
        cmocka_unit_test(test_fft_ranks_uniform),
        cmocka_unit_test(test_fourier_lines_ranks),
        cmocka_unit_test(test_vof_ranks),
        cmocka_unit_test(test_pressure_ranks_variable),
        cmocka_unit_test(test_vmg_ranks_plane),
        cmocka_unit_test(test_vmg_ranks_box),
        cmocka_unit_test(test_vmg_ranks_augmented),
        cmocka_unit_test(test_bingham_cavity_on_ranks),
        cmocka_unit_test(test_vmg_scenes_on_ranks),
        cmocka_unit_test(test_gmg_ranks),
        cmocka_unit_test(test_heap_on_ranks),
        cmocka_unit_test(test_couette_on_ranks),
        cmocka_unit_test(test_bagnold_on_ranks),
        cmocka_unit_test(test_bagnold3d_on_ranks),
        cmocka_unit_test(test_bagnold3d_traffic),
        cmocka_unit_test(test_bagnold_checkpoint_ranks),
        cmocka_unit_test(test_checkpoint_fails_on_ranks),
        cmocka_unit_test(test_bingham_channel_on_ranks),
        cmocka_unit_test(test_ngf_incline_on_ranks),
        cmocka_unit_test(test_ngf_walls_on_ranks),
        cmocka_unit_test(test_bedload_on_ranks),
        cmocka_unit_test(test_chute_on_ranks),
        cmocka_unit_test(test_bagnold_perturbation_on_ranks),
        cmocka_unit_test(test_bagnold_transient_on_ranks),
        cmocka_unit_test(test_collapse_on_ranks),
        cmocka_unit_test(test_collapse_checkpoint_ranks),
        cmocka_unit_test(test_cylinder_benchmark_on_ranks),
        cmocka_unit_test(test_slope_release_on_ranks),
        cmocka_unit_test(test_cylinder_on_ranks),
        cmocka_unit_test(test_cylinder_velocity_on_ranks),
        cmocka_unit_test(test_initial_state_on_ranks),
        cmocka_unit_test(test_wall_shock_on_ranks),
        cmocka_unit_test(test_front_on_ranks),
        cmocka_unit_test(test_front_shipped_on_ranks),
        cmocka_unit_test(test_bagnold2_on_ranks),
        cmocka_unit_test(test_duct_square_on_ranks),
        cmocka_unit_test(test_duct_circular_on_ranks),
        cmocka_unit_test(test_muflow_on_ranks),
    };
    RUN_GROUP(t, "mpi", tests);
}
