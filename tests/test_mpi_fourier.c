/* The plane Fourier line blocks over ranks (solvers/fourier_lines.h) in the
 * group mpi (test_mpi.c): the preconditioner of each rank's block against
 * the serial one of the whole grid, and the scenes that take it (bagnold3d,
 * bagnold2) split against one process.  Skipped on one rank.  Each check
 * reduces over the ranks before asserting (all pass or fail together). */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "app/run.h"
#include "grid/decomp.h"
#include "platform/comm.h"
#include "solvers/fourier_lines.h"
#include "solvers/viscous.h"
#include "test_main.h"
#include "test_mpi.h"
#include "test_util.h"

/* A viscosity with a contrast of 100 along z and a 30 % variation across x
 * and y (the averages over the planes see every rank's lines), periodic in
 * x and y: a ghost's value is its image's. */
static double viscosity(const struct grid *gg, double x, double y, double z)
{
    const double tx = 2.0 * M_PI / (gg->n[0] * gg->h[0]), ty = 2.0 * M_PI / (gg->n[1] * gg->h[1]);
    const double lz = gg->n[2] * gg->h[2];
    return (z < 0.5 * lz ? 1.0 : 1e-2) * (1.0 + 0.3 * cos(tx * x) * sin(ty * y + 0.2));
}

/* The coefficients and a right-hand side r of a box of cells lo .. lo + n
 * of the global grid gg on g (its ghosts too). */
struct layer {
    double *A[3], *E[3], *aug, *r[3], *z[3];
};

static void layer_fill(struct layer *L, const struct grid *g, const struct grid *gg,
                       const int lo[3])
{
    for (int c = 0; c < 3; c++) {
        L->A[c] = field_alloc(g);
        L->E[c] = field_alloc(g);
        L->r[c] = field_alloc(g);
        L->z[c] = field_alloc(g);
        assert_true(L->A[c] && L->E[c] && L->r[c] && L->z[c]);
    }
    L->aug = field_alloc(g);
    assert_non_null(L->aug);
    for (int i = -1; i <= g->n[0]; i++)
        for (int j = -1; j <= g->n[1]; j++)
            for (int k = -1; k <= g->n[2]; k++) {
                const ptrdiff_t p = grid_idx(g, i, j, k);
                const int I = lo[0] + i, J = lo[1] + j;
                const double xc = (I + 0.5) * gg->h[0], yc = (J + 0.5) * gg->h[1],
                             zc = (k + 0.5) * gg->h[2], zf = k * gg->h[2];
                for (int c = 0; c < 3; c++)
                    L->A[c][p] = viscosity(gg, xc, yc, zc);
                L->E[0][p] = L->E[1][p] = viscosity(gg, xc, yc, zf);
                L->E[2][p] = viscosity(gg, xc, yc, zc);
                L->aug[p] = 10.0 * (1.0 + 0.2 * sin(2.0 * M_PI * I / gg->n[0]));
                /* every plane wavenumber, no symmetry */
                for (int c = 0; c < 3; c++)
                    L->r[c][p] = sin(0.7 * I + 1.3 * J + 0.4 * k + c) +
                                 0.1 * (double)((I * 7 + J * 13 + k * 5 + c) % 11);
            }
}

static void layer_free(struct layer *L)
{
    for (int c = 0; c < 3; c++) {
        field_free(L->A[c]);
        field_free(L->E[c]);
        field_free(L->r[c]);
        field_free(L->z[c]);
    }
    field_free(L->aug);
}

/* The Fourier blocks of the viscous operator of L on g (faces bc) set up
 * and applied to L->r into L->z. */
static void precondition(const struct grid *g, const struct boundary *bc, struct layer *L)
{
    struct box act[3];
    bc_unknown_boxes(g, bc, act);
    char err[256] = "";
    struct viscous_solver *vs;
    struct fourier_lines *f;
    assert_int_equal(viscous_create(&vs, g, bc, act, 2, VISCOUS_LINE, err, sizeof err), 0);
    if (fourier_lines_create(&f, g, bc, act, 2, err, sizeof err) != 0)
        print_error("%s\n", err);
    struct viscous_problem pb = {.mass = 0.1,
                                 .augmentation = bc->face[2][1] == BC_OPEN ? NULL : L->aug};
    for (int c = 0; c < 3; c++) {
        pb.A_cell[c] = L->A[c];
        pb.A_edge[c] = L->E[c];
    }
    struct viscous_operator op = {vs, &pb};
    double *p[3], *q[3];
    for (int c = 0; c < 3; c++) {
        p[c] = field_alloc(g);
        q[c] = field_alloc(g);
    }
    assert_int_equal(fourier_lines_setup(f, viscous_operator_apply, &op, p, q), 0);
    fourier_lines_apply(f, L->r, L->z);
    for (int c = 0; c < 3; c++) {
        field_free(p[c]);
        field_free(q[c]);
    }
    fourier_lines_destroy(f);
    viscous_destroy(vs);
}

/* The ranks' apply on dims ranks of n cells against the whole grid's on
 * every rank: max |ranks - serial| over max |serial|. */
static double apply_on_ranks(const int dims[3], const int n[3], enum bc_kind top)
{
    const double len[3] = {1.0, 0.75, 1.0};
    const int periodic[3] = {1, 1, 0};
    struct test_blocks b;
    test_blocks_open(&b, dims, periodic, n, len);
    const struct grid *gg = &b.whole, *g = &b.g;
    const int *lo = b.dc.lo;
    struct boundary bc = {0};
    for (int d = 0; d < 2; d++)
        bc.face[d][0] = bc.face[d][1] = BC_PERIODIC;
    bc.face[2][0] = BC_WALL;
    bc.face[2][1] = top;
    struct boundary bcg = bc;
    bc.dc = &b.dc;
    const int zero[3] = {0, 0, 0};
    struct layer whole, mine;
    layer_fill(&whole, gg, gg, zero);
    layer_fill(&mine, g, gg, lo);
    precondition(gg, &bcg, &whole);
    precondition(g, &bc, &mine);
    struct box act[3];
    bc_unknown_boxes(g, &bc, act);
    double m[2] = {0.0, 0.0};
    for (int c = 0; c < 3; c++)
        for (int i = act[c].lo[0]; i < act[c].hi[0]; i++)
            for (int j = act[c].lo[1]; j < act[c].hi[1]; j++)
                for (int k = act[c].lo[2]; k < act[c].hi[2]; k++) {
                    const double w = whole.z[c][grid_idx(gg, lo[0] + i, lo[1] + j, k)],
                                 v = mine.z[c][grid_idx(g, i, j, k)];
                    m[0] = fmax(m[0], fabs(v - w));
                    m[1] = fmax(m[1], fabs(w));
                }
    comm_max(m, 2);
    if (comm_rank() == 0)
        printf("    %d x %d x %d cells, %s top, on %d x %d ranks: |ranks - serial| %.2e of max "
               "|z| %.3g\n", n[0], n[1], n[2], top == BC_OPEN ? "open" : "surface",
               b.cart.dims[0], b.cart.dims[1], m[0] / m[1], m[1]);
    layer_free(&whole);
    layer_free(&mine);
    test_blocks_close(&b);
    return m[1] > 0.0 ? m[0] / m[1] : INFINITY;
}

/* Split along x, along y and both (MPI_Dims_create's: 2 x 2 on 4 ranks);
 * 10 x 6 lines across: FFTW's slabs uneven and not aligned with the
 * blocks; under a surface (Hermitian blocks) and an open top (general). */
void test_fourier_lines_ranks(void **state)
{
    (void)state;
    if (comm_size() < 2)
        skip();
    const int n[3] = {10, 6, 12}, P = comm_size();
    const int splits[3][3] = {{P, 1, 1}, {1, P, 1}, {0, 0, 1}};
    int dims[3][3];
    const int count = test_splits(3, splits, dims);
    const enum bc_kind tops[2] = {BC_SURFACE, BC_OPEN};
    for (int t = 0; t < 2; t++)
        for (int s = 0; s < count; s++) {
            if (dims[s][1] > n[1])
                continue;
            /* the same averages and transforms in another order: their
             * round-off times the blocks' condition (measured 2.1e-14 at
             * most; 3.5e-12 with a contrast of 1e4 and a mass of 1e-3) */
            assert_true(apply_on_ranks(dims[s], n, tops[t]) <= 1e-13);
        }
}

/* bagnold3d's small grid (the case file's) from its 3D perturbation to the
 * uniform layer, solver.preconditioner = fourier on the ranks' blocks:
 * split along x (2 ranks) or x and y (2 x 2), along y alone (one cell
 * along x) and x alone (one along y). */
void test_bagnold3d_on_ranks(void **state)
{
    (void)state;
    char *ov[3][5] = {
        {"domain.nx=8", "domain.ny=8", "domain.nz=16", "domain.lx=7", "domain.ly=7"},
        {"domain.nx=1", "domain.ny=8", "domain.nz=16", "domain.lx=0.875", "domain.ly=7"},
        {"domain.nx=8", "domain.ny=1", "domain.nz=16", "domain.lx=7", "domain.ly=0.875"}};
    /* h = H / 16: u_surface 9.6e-4 above Bagnold's */
    for (int s = 0; s < 3; s++)
        check_scene_on_ranks("../cases/bagnold3d.ini", 5, ov[s], 1.5e-3, STATUS_STEADY);
}
