/* The two phases' parts over ranks in the group mpi (test_mpi.c): the
 * geometric VOF transport (physics/vof_transport.h), a disc turned by a
 * closed vortex between slip walls and a square carried across a doubly
 * periodic box, each rank's block against the transport of the whole grid
 * by one process and the volume over the ranks against the start's; the
 * variable-density pressure solve (solvers/pressure.h) against one
 * process's.  Each check reduces over the ranks before asserting (all pass
 * or fail together). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "grid/decomp.h"
#include "physics/vof_transport.h"
#include "platform/comm.h"
#include "solvers/pressure.h"
#include "test_main.h"
#include "test_mpi.h"
#include "test_util.h"

struct vof_case {
    int n[3];
    double len[3];
    enum bc_kind face[3][2];
    int vortex; /* 1: the disc in the vortex; 0: the square carried diagonally */
    int steps;
};

/* The stream function's amplitude and the square's velocity: |u| <= 1. */
#define VORTEX_PSI 0.25
#define CARRY_U 1.0
#define CARRY_W 0.6
/* The sweeps' CFL number (the solver's sub-steps keep it below 0.45). */
#define TEST_CFL 0.4

/* The stream function at the global node (i, k): zero on the walls to
 * the bit, so the normal velocity there is exactly 0. */
static double psi(const struct vof_case *vc, int i, int k)
{
    if (i <= 0 || i >= vc->n[0] || k <= 0 || k >= vc->n[2])
        return 0.0;
    return VORTEX_PSI * sin(M_PI * i / vc->n[0]) * sin(M_PI * k / vc->n[2]);
}

/* The face velocity of direction d at global face (I, K): the vortex's
 * from psi's differences (discretely divergence-free), or the uniform
 * carry. */
static double face_velocity(const struct vof_case *vc, const struct grid *g, int d, int I, int K)
{
    if (!vc->vortex)
        return d == 0 ? CARRY_U : d == 2 ? CARRY_W : 0.0;
    if (d == 0)
        return (psi(vc, I, K + 1) - psi(vc, I, K)) / g->h[2];
    if (d == 2)
        return -(psi(vc, I + 1, K) - psi(vc, I, K)) / g->h[0];
    return 0.0;
}

/* T of global cell (I, K): the disc of radius 0.25 at (0.6, 0.55) by
 * 32 x 32 samples, or the square [0.3, 0.7] x [0.2, 0.55] exactly. */
static double initial_fraction(const struct vof_case *vc, const struct grid *g, int I, int K)
{
    const double hx = g->h[0], hz = g->h[2], x0 = I * hx, z0 = K * hz;
    if (!vc->vortex) {
        double ox = fmax(0.0, fmin(x0 + hx, 0.7) - fmax(x0, 0.3)),
               oz = fmax(0.0, fmin(z0 + hz, 0.55) - fmax(z0, 0.2));
        return ox * oz / (hx * hz);
    }
    int in = 0;
    for (int a = 0; a < 32; a++)
        for (int b = 0; b < 32; b++) {
            double x = x0 + (a + 0.5) * hx / 32 - 0.6, z = z0 + (b + 0.5) * hz / 32 - 0.55;
            in += x * x + z * z <= 0.0625;
        }
    return in / 1024.0;
}

/* The transport of vc's T on the block of g whose cell 0 is global cell
 * lo (lo = 0, bc->dc NULL: the whole grid), vc->steps steps; T out. */
static void transport(const struct vof_case *vc, const struct grid *g, const struct boundary *bc,
                      const int lo[3], double *T)
{
    double *vel[3] = {field_alloc(g), field_alloc(g), field_alloc(g)};
    assert_true(vel[0] && vel[1] && vel[2]);
    /* the faces this block owns (grid/decomp.h): 0 .. n - 1 along d, and
     * n at the domain's end; the exchange gives a rank border's face n */
    for (int d = 0; d < 3; d++)
        for (int i = 0; i <= g->n[0]; i++)
            for (int j = 0; j < g->n[1]; j++)
                for (int k = 0; k <= g->n[2]; k++) {
                    const int idx[3] = {i, j, k};
                    int skip = 0;
                    for (int e = 0; e < 3; e++)
                        skip |= e == d ? idx[e] == g->n[e] && bc_border(bc, e, 1)
                                       : idx[e] == g->n[e];
                    if (!skip)
                        vel[d][grid_idx(g, i, j, k)] =
                            face_velocity(vc, g, d, lo[0] + i, lo[2] + k);
                }
    bc_fill_velocity(g, bc, vel);
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++)
                T[grid_idx(g, i, j, k)] = initial_fraction(vc, g, lo[0] + i, lo[2] + k);
    struct vof_transport vt;
    assert_int_equal(vof_transport_init(&vt, g, bc), 0);
    const double dt = TEST_CFL * fmin(g->h[0], g->h[2]);
    double refused = 0.0;
    for (int s = 0; s < vc->steps; s++)
        refused += vof_transport_step(&vt, T, vel, dt, NULL) != 0;
    vof_transport_free(&vt);
    for (int d = 0; d < 3; d++)
        field_free(vel[d]);
    assert_true(refused == 0.0);
}

static double cell_sum(const struct grid *g, const double *T)
{
    double s = 0.0;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++)
                s += T[grid_idx(g, i, j, k)];
    return s;
}

/* vc split over this run's ranks as dims asks (0: MPI's choice) against
 * one process: every cell within 1e-12, the volume over the ranks the
 * start's within 1e-12 (relative), and the shape moved (T changed by more
 * than 1/2 somewhere: the check sees the transport). */
static void check_vof(const struct vof_case *vc, const int dims[3])
{
    struct boundary whole = {0};
    for (int d = 0; d < 3; d++)
        for (int s = 0; s < 2; s++)
            whole.face[d][s] = vc->face[d][s];
    int periodic[3];
    bc_periodic_flags(&whole, periodic);
    struct test_blocks b;
    test_blocks_open(&b, dims, periodic, vc->n, vc->len);
    const struct grid *gg = &b.whole, *g = &b.g;
    const int *lo = b.dc.lo;
    double *Tw = field_alloc(gg), *T0 = field_alloc(gg);
    assert_true(Tw && T0);
    const int zero[3] = {0, 0, 0};
    transport(vc, gg, &whole, zero, Tw);
    for (int i = 0; i < gg->n[0]; i++)
        for (int k = 0; k < gg->n[2]; k++)
            T0[grid_idx(gg, i, 0, k)] = initial_fraction(vc, gg, i, k);
    const double v0 = cell_sum(gg, T0);

    struct boundary part = whole;
    part.dc = &b.dc;
    double *T = field_alloc(g);
    assert_non_null(T);
    transport(vc, g, &part, lo, T);
    double m[2] = {0.0, 0.0}; /* max |T - one process's|, max |T - T at the start| */
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                const ptrdiff_t q = grid_idx(gg, lo[0] + i, lo[1] + j, lo[2] + k);
                const double t = T[grid_idx(g, i, j, k)];
                m[0] = fmax(m[0], fabs(t - Tw[q]));
                m[1] = fmax(m[1], fabs(t - T0[q]));
            }
    comm_max(m, 2);
    double v = cell_sum(g, T);
    comm_sum(&v, 1);
    const double vw = cell_sum(gg, Tw);
    if (comm_rank() == 0)
        printf("    %s, %d x %d x %d on %d x %d x %d ranks, %d steps: T within %.1e of one "
               "process's, volume %.2e (one process %.2e) off the start's, moved %.2f\n",
               vc->vortex ? "disc in a vortex" : "square carried", vc->n[0], vc->n[1], vc->n[2],
               b.cart.dims[0], b.cart.dims[1], b.cart.dims[2], vc->steps, m[0], v / v0 - 1.0,
               vw / v0 - 1.0, m[1]);
    field_free(T);
    field_free(Tw);
    field_free(T0);
    test_blocks_close(&b);
    assert_true(m[0] <= 1e-12);
    assert_true(fabs(v / v0 - 1.0) <= 1e-12);
    assert_true(m[1] > 0.5);
}

/* A disc turned by the vortex between slip walls (a quarter turn of its
 * centre in 60 steps), then a square carried diagonally through the
 * doubly periodic box past its wrap; each split along x, along z, and
 * both (two by two on four ranks). */
void test_vof_ranks(void **state)
{
    (void)state;
    const int p = comm_size();
    const int splits[3][3] = {{p, 1, 1}, {1, 1, p}, {0, 1, 0}};
    int dims[3][3];
    const int count = test_splits(3, splits, dims);
    const struct vof_case vortex = {{24, 1, 20},
                                    {1.2, 0.05, 1.0},
                                    {{BC_SLIP, BC_SLIP}, {BC_PERIODIC, BC_PERIODIC},
                                     {BC_WALL, BC_SLIP}},
                                    1,
                                    60};
    const struct vof_case carry = {{24, 1, 20},
                                   {1.2, 0.05, 1.0},
                                   {{BC_PERIODIC, BC_PERIODIC}, {BC_PERIODIC, BC_PERIODIC},
                                    {BC_PERIODIC, BC_PERIODIC}},
                                   0,
                                   70};
    for (int s = 0; s < count; s++)
        check_vof(&vortex, dims[s]);
    for (int s = 0; s < count; s++)
        check_vof(&carry, dims[s]);
}

/* ---- the variable-density pressure solve ------------------------------------------ */

/* The projection's coefficient beta = rho_ref / rho of a layer of grains
 * (rho 1) under a light phase (rho 1e-3), its surface wavy along x, the
 * face's density the mean of its two cells' (two_phase.c's `mean`): at the
 * global face (I, J, K) of direction d of gg. */
static double layer_beta(const struct grid *gg, int d, int I, int J, int K)
{
    double rho = 0.0;
    for (int s = 0; s < 2; s++) {
        int c[3] = {I, J, K};
        c[d] -= s;
        const double x = (c[0] + 0.5) * gg->h[0], z = (c[2] + 0.5) * gg->h[2];
        const double lx = gg->n[0] * gg->h[0], lz = gg->n[2] * gg->h[2];
        const double surface = lz * (0.45 + 0.2 * cos(2.0 * M_PI * x / lx) + 0.01 * c[1]);
        rho += 0.5 * (z < surface ? 1.0 : 1e-3);
    }
    return 1.0 / rho;
}

/* The right-hand side at global cell (I, J, K): every wavenumber, no
 * symmetry (a Dirichlet top: no compatibility needed). */
static double pressure_rhs(int I, int J, int K)
{
    return sin(0.7 * I + 1.3 * J + 0.4 * K) + 0.1 * (double)((I * 7 + J * 13 + K * 5) % 11);
}

/* pressure_solve of layer_beta on the block of g whose cell 0 is global
 * cell lo (dc NULL: the whole grid gg): phi, and its iterations. */
static long pressure_layer(const struct grid *gg, const struct grid *g, const struct decomp *dc,
                           const int lo[3], double *phi)
{
    const enum poisson_bc bc[3][2] = {{POISSON_NEUMANN, POISSON_NEUMANN},
                                      {POISSON_PERIODIC, POISSON_PERIODIC},
                                      {POISSON_NEUMANN, POISSON_DIRICHLET}};
    struct pressure_solver *ps = NULL;
    char err[256] = "";
    int rc = dc ? pressure_create_decomposed(&ps, g, gg, dc, bc, err, sizeof err)
                : pressure_create(&ps, g, bc, err, sizeof err);
    if (rc != 0)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
    double *beta[3] = {field_alloc(g), field_alloc(g), field_alloc(g)}, *rhs = field_alloc(g);
    assert_true(beta[0] && beta[1] && beta[2] && rhs);
    for (int d = 0; d < 3; d++)
        for (int i = -1; i <= g->n[0]; i++)
            for (int j = -1; j <= g->n[1]; j++)
                for (int k = -1; k <= g->n[2]; k++)
                    beta[d][grid_idx(g, i, j, k)] =
                        layer_beta(gg, d, lo[0] + i, (lo[1] + j + gg->n[1]) % gg->n[1], lo[2] + k);
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++)
                rhs[grid_idx(g, i, j, k)] = pressure_rhs(lo[0] + i, lo[1] + j, lo[2] + k);
    rc = pressure_set_coefficient(ps, beta, err, sizeof err);
    if (rc != 0)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
    rc = pressure_solve(ps, rhs, phi, 0.0);
    if (rc != 0)
        print_error("%s\n", pressure_message(ps));
    assert_int_equal(rc, 0);
    const long it = pressure_iterations(ps);
    pressure_destroy(ps);
    for (int d = 0; d < 3; d++)
        field_free(beta[d]);
    field_free(rhs);
    return it;
}

/* n's layer split as dims asks against one process: phi within 1e-10 of
 * its largest value, the iterations within one. */
static void check_pressure(const int n[3], const int dims[3])
{
    const double len[3] = {n[0] * 0.05, n[1] * 0.05, n[2] * 0.05};
    const int zero[3] = {0, 0, 0}, per[3] = {0, 1, 0};
    struct test_blocks b;
    test_blocks_open(&b, dims, per, n, len);
    const struct grid *gg = &b.whole, *g = &b.g;
    const int *lo = b.dc.lo;
    double *whole = field_alloc(gg);
    assert_non_null(whole);
    const long it_whole = pressure_layer(gg, gg, NULL, zero, whole);
    double *phi = field_alloc(g);
    assert_non_null(phi);
    const long it = pressure_layer(gg, g, &b.dc, lo, phi);
    double m[2] = {0.0, 0.0}; /* max |phi - one process's|, max |phi| */
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                const double w = whole[grid_idx(gg, lo[0] + i, lo[1] + j, lo[2] + k)];
                m[0] = fmax(m[0], fabs(phi[grid_idx(g, i, j, k)] - w));
                m[1] = fmax(m[1], fabs(w));
            }
    comm_max(m, 2);
    if (comm_rank() == 0)
        printf("    density 1 : 1e-3, %d x %d x %d on %d x %d x %d ranks: %ld multigrid-CG "
               "iterations (one process %ld), phi within %.2e\n",
               n[0], n[1], n[2], b.cart.dims[0], b.cart.dims[1], b.cart.dims[2], it, it_whole,
               m[0] / m[1]);
    field_free(phi);
    field_free(whole);
    test_blocks_close(&b);
    assert_true(m[1] > 0.0);
    assert_true(m[0] <= 1e-10 * m[1]);
    assert_true(labs(it - it_whole) <= 1);
}

/* A 2D cross-section (the whole grid factorised: the gathered level is the
 * finest) and a 3D box (the cycles: its finest level split, 8,192 cells
 * over the multigrid's 4,096), split along x, z and both. */
void test_pressure_ranks_variable(void **state)
{
    (void)state;
    const int p = comm_size();
    const int splits[3][3] = {{p, 1, 1}, {1, 1, p}, {0, 1, 0}};
    int dims[3][3];
    const int count = test_splits(3, splits, dims);
    const int plane[3] = {40, 1, 24}, box[3] = {32, 8, 32};
    for (int s = 0; s < count; s++)
        check_pressure(plane, dims[s]);
    for (int s = 0; s < count; s++)
        check_pressure(box, dims[s]);
}
