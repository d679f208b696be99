/* The implicit step's velocity multigrid (solvers/velocity_mg.h) split over
 * ranks along bounded directions, in the group mpi (test_mpi.c): the CG it
 * preconditions against the same solve on one process (every rank makes
 * that too: the test's reference).  Alone or on one rank nothing is split
 * and the two solves are one.  Each check reduces over the ranks before
 * asserting (all pass or fail together). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "app/run.h"
#include "grid/boundary.h"
#include "grid/decomp.h"
#include "platform/comm.h"
#include "solvers/velocity_mg.h"
#include "solvers/viscous.h"
#include "test_main.h"
#include "test_mpi.h"
#include "test_util.h"

/* log10 of the viscosity at x, z (unit box): 0 on one side of a wavy front,
 * 3 on the other, the jump over a few cells (a contrast of 1e3, as a
 * granular layer's bed against its flowing surface). */
static double log_eta(double x, double y, double z)
{
    const double front = 0.5 + 0.15 * sin(2.0 * M_PI * z) + 0.05 * cos(2.0 * M_PI * y);
    return 1.5 + 1.5 * tanh((x - front) / 0.04);
}

/* A right-hand side no symmetry of the box maps to itself, by global node;
 * 0 for the components along a direction of one cell. */
static double forcing(int c, int i, int j, int k)
{
    return sin(0.37 * i + 1.3 * c) * cos(0.23 * k - 0.7 * j) + 0.1 * ((i * 7 + j * 3 + k * 5 + c) % 5);
}

struct vmg_problem {
    struct grid g;
    struct boundary bc;
    struct box act[3];
    double *A_cell[3], *A_edge[3], *rhs[3], *x[3];
    double *aug; /* the grad-div augmentation's r, uniform (NULL: none) */
    struct viscous_problem pb;
};

/* The problem on this rank's block of the global grid gg (dc NULL: the
 * whole grid), its coefficients at global positions: a cell's viscosity at
 * its centre, an edge's along k at its midpoint (faces across k). */
static void problem_make(struct vmg_problem *p, const struct grid *gg, const struct decomp *dc,
                         const struct boundary *bc, double aug)
{
    memset(p, 0, sizeof *p);
    int lo[3] = {0, 0, 0};
    p->g = *gg;
    p->bc = *bc;
    p->bc.dc = dc;
    if (dc) {
        assert_int_equal(decomp_local_grid(dc, gg, &p->g), 0);
        memcpy(lo, dc->lo, sizeof lo);
    }
    const struct grid *g = &p->g;
    bc_unknown_boxes(g, &p->bc, p->act);
    for (int c = 0; c < 3; c++) {
        double **fs[] = {&p->A_cell[c], &p->A_edge[c], &p->rhs[c], &p->x[c]};
        for (int f = 0; f < 4; f++)
            assert_non_null(*fs[f] = field_alloc(g));
    }
    const double *h = gg->h;
    for (int i = -1; i <= g->n[0]; i++)
        for (int j = grid_slot_lo(g, 1); j <= grid_slot_hi(g, 1); j++)
            for (int k = -1; k <= g->n[2]; k++) {
                const int G[3] = {lo[0] + i, lo[1] + j, lo[2] + k};
                const ptrdiff_t q = grid_idx(g, i, j, k);
                for (int c = 0; c < 3; c++) {
                    double at[3], ctr[3];
                    for (int d = 0; d < 3; d++) {
                        ctr[d] = (G[d] + 0.5) * h[d];
                        at[d] = d == c ? ctr[d] : G[d] * h[d];
                    }
                    p->A_cell[c][q] = pow(10.0, log_eta(ctr[0], ctr[1], ctr[2]));
                    p->A_edge[c][q] = pow(10.0, log_eta(at[0], at[1], at[2]));
                }
            }
    for (int c = 0; c < 3; c++) {
        bc_fill_scalar(g, &p->bc, p->A_cell[c]); /* as the march fills them */
        const struct box *b = &p->act[c];
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++)
                for (int k = b->lo[2]; k < b->hi[2]; k++)
                    p->rhs[c][grid_idx(g, i, j, k)] =
                        gg->n[c] == 1 ? 0.0 : forcing(c, lo[0] + i, lo[1] + j, lo[2] + k);
        p->pb.A_cell[c] = p->A_cell[c];
        p->pb.A_edge[c] = p->A_edge[c];
    }
    p->pb.mass = 1.0; /* rho / dt: the viscous part dominates it by 1e4 and more */
    if (aug > 0.0) {
        assert_non_null(p->aug = field_alloc(g));
        for (size_t q = 0; q < g->size; q++)
            p->aug[q] = aug;
        p->pb.augmentation = p->aug;
    }
}

static void problem_free(struct vmg_problem *p)
{
    for (int c = 0; c < 3; c++) {
        field_free(p->A_cell[c]);
        field_free(p->A_edge[c]);
        field_free(p->rhs[c]);
        field_free(p->x[c]);
    }
    field_free(p->aug);
}

/* CG with the velocity multigrid to rtol; its iterations. */
static int solve_vmg(struct vmg_problem *p, double rtol)
{
    return test_viscous_solve(&p->g, &p->bc, p->act, VISCOUS_MG, &p->pb, p->rhs, p->x, rtol);
}

/* The solve over dims ranks (0: MPI's choice, 1: whole) of the global
 * n-cell box with conditions bc (and the grad-div augmentation aug, 0:
 * none) against the one on one process: the largest difference over the
 * unknowns within 1e-10 of the largest value (both converge to 1e-13;
 * their cycles differ in the rank borders' smoothing, lines cut there), iterations within one. */
static void check_vmg(const int dims[3], const int n[3], const enum bc_kind face[3][2],
                      double aug)
{
    int periodic[3];
    struct boundary bc;
    memset(&bc, 0, sizeof bc);
    for (int d = 0; d < 3; d++) {
        bc.face[d][0] = face[d][0];
        bc.face[d][1] = face[d][1];
    }
    bc_periodic_flags(&bc, periodic);
    const double len[3] = {1.0, n[1] / (double)n[0], n[2] / (double)n[0]};
    struct test_blocks b;
    test_blocks_open(&b, dims, periodic, n, len);
    struct vmg_problem whole, part;
    problem_make(&whole, &b.whole, NULL, &bc, aug);
    problem_make(&part, &b.whole, &b.dc, &bc, aug);
    const double rtol = 1e-13;
    const int it_whole = solve_vmg(&whole, rtol), it_part = solve_vmg(&part, rtol);
    const int *lo = b.dc.lo;
    double m[2] = {0.0, 0.0}; /* max |difference|, max |x| */
    for (int c = 0; c < 3; c++) {
        const struct box *a = &part.act[c];
        for (int i = a->lo[0]; i < a->hi[0]; i++)
            for (int j = a->lo[1]; j < a->hi[1]; j++)
                for (int k = a->lo[2]; k < a->hi[2]; k++) {
                    const double w = whole.x[c][grid_idx(&b.whole, lo[0] + i, lo[1] + j,
                                                         lo[2] + k)];
                    const double diff = fabs(part.x[c][grid_idx(&part.g, i, j, k)] - w);
                    m[0] = diff > m[0] ? diff : m[0];
                    m[1] = fabs(w) > m[1] ? fabs(w) : m[1];
                }
    }
    comm_max(m, 2);
    if (comm_rank() == 0)
        printf("    %d x %d x %d on %d x %d x %d ranks%s: %d CG iterations (one process %d), "
               "difference %.2e\n", n[0], n[1], n[2], b.cart.dims[0], b.cart.dims[1],
               b.cart.dims[2], aug > 0.0 ? ", augmented" : "", it_part, it_whole, m[0] / m[1]);
    problem_free(&whole);
    problem_free(&part);
    test_blocks_close(&b);
    assert_true(m[1] > 0.0);
    assert_true(m[0] <= 1e-10 * m[1]);
    assert_true(abs(it_part - it_whole) <= 1);
}

/* check_vmg on each split of test_splits: along x, along z, both (two by
 * two on four ranks). */
static void check_vmg_splits(const int n[3], const enum bc_kind face[3][2], double aug)
{
    const int p = comm_size();
    const int splits[3][3] = {{p, 1, 1}, {1, 1, p}, {0, 1, 0}};
    int dims[3][3];
    for (int t = 0, count = test_splits(3, splits, dims); t < count; t++)
        check_vmg(dims[t], n, face, aug);
}

/* A plane flow (x-z, one periodic cell across y) in a box with walls and a
 * lid, the viscosity over three decades: split along x, along z, and both
 * (two by two on four ranks); 128^2 keeps two levels on the ranks (the
 * second gathered: 64^2 is the pressure multigrid's 4,096 cells), 256^2
 * three. */
void test_vmg_ranks_plane(void **state)
{
    (void)state;
    const enum bc_kind face[3][2] = {{BC_WALL, BC_WALL}, {BC_PERIODIC, BC_PERIODIC},
                                     {BC_WALL, BC_LID}};
    const int n[3] = {128, 1, 128}, both[3] = {0, 1, 0};
    check_vmg_splits(n, face, 0.0);
    const int n3[3] = {256, 1, 256}; /* three levels on the ranks */
    check_vmg(both, n3, face, 0.0);
}

/* A 3D box, walls on every face (an open top), split along x and z. */
void test_vmg_ranks_box(void **state)
{
    (void)state;
    const enum bc_kind face[3][2] = {{BC_WALL, BC_WALL}, {BC_WALL, BC_WALL}, {BC_WALL, BC_OPEN}};
    const int n[3] = {32, 16, 32};
    const int both[3] = {0, 1, 0};
    check_vmg(both, n, face, 0.0);
}

/* The plane box of test_vmg_ranks_plane with the grad-div augmentation of
 * the Bingham cavity (r = 1e3 max(eta), here 1e6): the finest level
 * gathered, the edge patches' cycle serial on every rank (velocity_mg.c:
 * gather_finest), so the iterations are one process's */
void test_vmg_ranks_augmented(void **state)
{
    (void)state;
    const enum bc_kind face[3][2] = {{BC_WALL, BC_WALL}, {BC_PERIODIC, BC_PERIODIC},
                                     {BC_WALL, BC_LID}};
    const int n[3] = {128, 1, 128};
    check_vmg_splits(n, face, 1e6);
}

/* The march on ranks with the velocity multigrid, bounded directions split
 * (march_create.c): bagnold's layer of one column split along z (wall
 * below, surface above: the hydrostatic split's and the fills' rank borders,
 * Newton's GMRES with its dots over the ranks), the chute split across its
 * walls (y; and its periodic z on four ranks).  Both are under 4,096 cells:
 * the cycle is the gathered level's, the ranks' part the march around it. */
void test_vmg_scenes_on_ranks(void **state)
{
    (void)state;
    char *bagnold[] = {"domain.nx=1", "domain.lx=0.35", "solver.preconditioner=multigrid"};
    /* h = H / 40: u_surface 2.2e-4 above Bagnold's (docs/numerics) */
    check_scene_on_ranks("../cases/bagnold.ini", 3, bagnold, 1e-3, STATUS_STEADY);
    char *chute[] = {"solver.dt=100", "solver.preconditioner=multigrid"};
    /* h = b / 80: u_plug 0.56% above the exact plug (docs/validation/chute.md) */
    check_scene_on_ranks("../cases/chute.ini", 2, chute, 6e-3, STATUS_STEADY);
}

/* The Bingham cavity (walls, the lid; no periodic direction split) at
 * 32^2: one process takes the Cholesky (auto), the ranks the velocity
 * multigrid (auto over ranks: precond_policy.c), split along x on 2 ranks,
 * x and z on 4; the finest level gathered (the augmentation's edge
 * patches), the same steady state to the linear tolerance */
void test_bingham_cavity_on_ranks(void **state)
{
    (void)state;
    char *ov[] = {"domain.nx=32", "domain.nz=32", "domain.ly=0.03125"};
    /* h = 1/32: psi_max 0.63% below Vola et al.'s (0.0564347 against 0.0567935) */
    check_scene_on_ranks("../cases/bingham_cavity.ini", 3, ov, 1e-2, STATUS_STEADY);
}
