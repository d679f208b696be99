/* The domain decomposition (grid/decomp.h) and the decomposed multigrid,
 * run under mpirun on 1, 2 and 4 ranks (`make test`) and alone.  Every
 * check reduces its result over the ranks first, so all ranks pass or
 * fail together (no rank waits in a collective for one that failed). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "grid/decomp.h"
#include "platform/comm.h"
#include "solvers/multigrid.h"
#include "test_main.h"

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

/* Each rank fills its cells with the global pattern and its ghosts with
 * -1, exchanges direction after direction, and checks every ghost slot
 * (edges and corners too): a rank border's holds the neighbour's cell, a
 * periodic end's the wrapped cell, a wall's keeps -1.  A face array of
 * normal d is the same check: its slot t along d is global face lo + t
 * (grid/decomp.h), so the ghost n must hold the next rank's face 0. */
static void check_exchange(const int dims[3], const int periodic[3], const int n[3])
{
    struct comm_cart cart;
    struct decomp dc;
    char err[256];
    const int split[3] = {1, 1, 1};
    assert_int_equal(comm_cart_create(&cart, dims, periodic, split, err, sizeof err), 0);
    assert_int_equal(decomp_create(&dc, &cart, n, err, sizeof err), 0);
    struct grid g;
    const double len[3] = {1.0 * dc.n[0], 1.0 * dc.n[1], 1.0 * dc.n[2]};
    assert_int_equal(grid_init(&g, dc.n, len), 0);
    double *f = field_alloc(&g);
    assert_non_null(f);
    for (size_t p = 0; p < g.size; p++)
        f[p] = -1.0;
    for (int i = 0; i < g.n[0]; i++)
        for (int j = 0; j < g.n[1]; j++)
            for (int k = 0; k < g.n[2]; k++)
                f[grid_idx(&g, i, j, k)] = pattern(dc.lo[0] + i, dc.lo[1] + j, dc.lo[2] + k);
    for (int d = 0; d < 3; d++)
        decomp_exchange(&dc, &g, f, d);
    double bad = 0.0;
    for (int i = -1; i <= g.n[0]; i++)
        for (int j = -1; j <= g.n[1]; j++)
            for (int k = -1; k <= g.n[2]; k++) {
                const int t[3] = {i, j, k};
                int G[3], outside = 0;
                for (int d = 0; d < 3; d++) {
                    /* a slot beyond the local box is the neighbour's only
                     * across a border; else (a wall, a one-rank periodic
                     * direction: local fills) it stays -1 */
                    const int beyond = t[d] < 0 ? 0 : t[d] >= g.n[d] ? 1 : -1;
                    if (beyond >= 0 && !dc.border[d][beyond])
                        outside = 1;
                    G[d] = global_index(&dc, d, t[d], periodic[d]);
                }
                const double want = outside ? -1.0 : pattern(G[0], G[1], G[2]);
                bad += f[grid_idx(&g, i, j, k)] != want;
            }
    comm_sum(&bad, 1);
    field_free(f);
    decomp_free(&dc);
    comm_cart_free(&cart);
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
static void check_solve(const int dims[3], const enum poisson_bc bc[3][2], int jump)
{
    /* three levels on the ranks (48, 24 and 12 cells across, the last
     * gathered: 576 cells), blocks of 3 cells there on 4 ranks */
    const int n[3] = {48, 16, 48};
    const double h = 1.0 / 48;
    const double len[3] = {n[0] * h, n[1] * h, n[2] * h};
    struct grid gg;
    assert_int_equal(grid_init(&gg, n, len), 0);
    int periodic[3], split[3] = {1, 1, 1};
    for (int d = 0; d < 3; d++)
        periodic[d] = bc[d][0] == POISSON_PERIODIC;
    struct comm_cart cart;
    struct decomp dc;
    char err[256];
    assert_int_equal(comm_cart_create(&cart, dims, periodic, split, err, sizeof err), 0);
    assert_int_equal(decomp_create(&dc, &cart, n, err, sizeof err), 0);
    struct solve_result whole = solve(&gg, NULL, bc, jump);
    struct solve_result part = solve(&gg, &dc, bc, jump);
    struct grid g;
    assert_int_equal(decomp_local_grid(&dc, &gg, &g), 0);
    double m[2] = {0.0, 0.0}; /* max |difference|, max |phi| */
    for (int i = 0; i < g.n[0]; i++)
        for (int j = 0; j < g.n[1]; j++)
            for (int k = 0; k < g.n[2]; k++) {
                const double w = whole.phi[grid_idx(&gg, dc.lo[0] + i, dc.lo[1] + j, dc.lo[2] + k)];
                const double diff = fabs(part.phi[grid_idx(&g, i, j, k)] - w);
                m[0] = diff > m[0] ? diff : m[0];
                m[1] = fabs(w) > m[1] ? fabs(w) : m[1];
            }
    comm_max(m, 2);
    if (comm_rank() == 0)
        printf("    ranks %d x %d x %d, %s: %d iterations (undecomposed %d), %d levels on the "
               "ranks, difference %.2e\n", cart.dims[0], cart.dims[1], cart.dims[2],
               jump ? "jump 100" : "smooth a", part.iterations, whole.iterations, part.levels,
               m[0] / m[1]);
    field_free(whole.phi);
    field_free(part.phi);
    decomp_free(&dc);
    comm_cart_free(&cart);
    assert_true(m[0] <= 1e-10 * m[1]);
    assert_true(abs(part.iterations - whole.iterations) <= 1);
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
    const int along_x[3] = {p, 1, 1}, along_z[3] = {1, 1, p}, both[3] = {0, 1, 0};
    for (int jump = 0; jump < 2; jump++) {
        check_solve(along_x, neumann, jump);
        check_solve(along_z, mixed, jump);
        check_solve(both, jump ? mixed : neumann, jump);
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
    const int along_x[3] = {p, 1, 1}, along_z[3] = {1, 1, p}, both[3] = {0, 1, 0};
    for (int jump = 0; jump < 2; jump++) {
        check_solve(along_x, per_x, jump);
        check_solve(along_z, all, jump);
        check_solve(both, jump ? all : per_x, jump);
    }
}

/* Started by mpirun on two ranks, muflow refuses the case on every rank
 * (status 2), says so once and writes nothing (no scene runs decomposed
 * yet).  Run only outside mpirun (an mpirun does not start another), in a
 * clean environment: hypre's MPI, initialised in this process by the amg
 * group, leaves Open MPI's variables in it, and an mpirun that inherits them
 * fails (status 1, nothing said); under the sanitizers the leak check is
 * off for that muflow (Open MPI's own allocations at exit, as for the amg
 * group in check-asan). */
static void test_muflow_refuses_ranks(void **state)
{
    (void)state;
    if (comm_launched())
        skip();
    char bin[4096], dir[4096], cmd[9000], path[4200];
    test_muflow_bin(bin, sizeof bin);
    test_tmp_make(dir, sizeof dir, "mpi_refused");
    snprintf(cmd, sizeof cmd,
             "env -i PATH=\"$PATH\" HOME=\"$HOME\" ASAN_OPTIONS=detect_leaks=0 "
             "OMPI_ALLOW_RUN_AS_ROOT=1 "
             "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun -np 2 "
             "--oversubscribe '%s' ../cases/couette.ini output.dir='%s/out' 2>&1; echo \"rc=$?\"",
             bin, dir);
    char *out = NULL;
    assert_int_equal(test_sh(cmd, &out), 0);
    int said = 0;
    for (const char *p = out; (p = strstr(p, "no scene runs decomposed")); p++)
        said++;
    snprintf(path, sizeof path, "%s/out/summary.ini", dir);
    const int wrote = test_file_exists(path), status2 = strstr(out, "rc=2\n") != NULL;
    if (said != 1 || !status2 || wrote)
        print_error("%s", out);
    free(out);
    test_tmp_remove(dir);
    assert_int_equal(said, 1);
    assert_true(status2);
    assert_false(wrote);
}

void group_mpi(struct test_tally *t)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_blocks_tile),
        cmocka_unit_test(test_exchange_walls),
        cmocka_unit_test(test_exchange_periodic),
        cmocka_unit_test(test_multigrid_walls),
        cmocka_unit_test(test_multigrid_periodic),
        cmocka_unit_test(test_muflow_refuses_ranks),
    };
    RUN_GROUP(t, "mpi", tests);
}
