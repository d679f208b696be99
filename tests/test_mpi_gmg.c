/* The implicit step's geometric multigrid (solvers/viscous_gmg.h) over
 * ranks, in the group mpi (test_mpi.c): the cross-section gathered on
 * every rank and cycled there, so that one cycle is one process's to the
 * bit and a GMRES solve differs only by the order of its dot products'
 * sums; and the heap (its tilt search and measures over the ranks) split
 * along each bounded direction and both.  Each check reduces over the
 * ranks before asserting (all pass or fail together). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "app/run.h"
#include "grid/boundary.h"
#include "grid/decomp.h"
#include "platform/comm.h"
#include "solvers/viscous.h"
#include "solvers/viscous_gmg.h"
#include "test_main.h"
#include "test_mpi.h"
#include "test_util.h"

/* log10 of a viscosity over the cross-section (y, z in the unit box): a
 * jump of two decades along a tilted, wavy front, as the heap's flowing
 * layer over its creeping base. */
static double log_eta(double y, double z)
{
    return 1.0 + tanh((z - 0.5 - 0.2 * y - 0.05 * sin(6.0 * y)) / 0.05);
}

/* A right-hand side no symmetry maps to itself, by global cell. */
static double forcing(int j, int k)
{
    return sin(0.37 * j + 0.3) * cos(0.23 * k - 0.7) + 0.1 * ((j * 3 + k * 5) % 7);
}

/* The heap's cross-section on this rank's block (dc NULL: the whole):
 * x periodic of one cell, y wall and slip, z wall and free surface. */
struct section {
    struct grid g;
    struct boundary bc;
    struct box act[3];
    double *A_cell[3], *A_edge[3], *b_edge[3], *base[3], *rhs[3], *x[3], *z[3];
    struct viscous_problem pb;
};

static void section_make(struct section *s, const struct grid *gg, const struct decomp *dc)
{
    memset(s, 0, sizeof *s);
    static const enum bc_kind face[3][2] = {
        {BC_PERIODIC, BC_PERIODIC}, {BC_WALL, BC_SLIP}, {BC_WALL, BC_SURFACE}};
    for (int d = 0; d < 3; d++) {
        s->bc.face[d][0] = face[d][0];
        s->bc.face[d][1] = face[d][1];
    }
    s->bc.dc = dc;
    s->g = *gg;
    int lo[3] = {0, 0, 0};
    if (dc) {
        assert_int_equal(decomp_local_grid(dc, gg, &s->g), 0);
        memcpy(lo, dc->lo, sizeof lo);
    }
    const struct grid *g = &s->g;
    bc_unknown_boxes(g, &s->bc, s->act);
    for (int c = 0; c < 3; c++) {
        double **fs[] = {&s->A_cell[c], &s->A_edge[c], &s->b_edge[c], &s->base[c],
                         &s->rhs[c],    &s->x[c],      &s->z[c]};
        for (int f = 0; f < 7; f++)
            assert_non_null(*fs[f] = field_alloc(g));
    }
    /* every slot at its global position (ghosts too, as the march's
     * filled arrays): a cell's viscosity at its centre, an edge's at its
     * corner; b (Newton's edge term) -0.4 of A; the base flow u(y, z) */
    const double *h = gg->h;
    for (int j = -1; j <= g->n[1]; j++)
        for (int k = -1; k <= g->n[2]; k++) {
            const int J = lo[1] + j, K = lo[2] + k;
            const double yc = (J + 0.5) * h[1], zc = (K + 0.5) * h[2];
            for (int i = grid_slot_lo(g, 0); i <= grid_slot_hi(g, 0); i++) {
                const ptrdiff_t q = grid_idx(g, i, j, k);
                for (int c = 0; c < 3; c++) {
                    const double ye = c == 1 ? yc : J * h[1], ze = c == 2 ? zc : K * h[2];
                    s->A_cell[c][q] = pow(10.0, log_eta(yc, zc));
                    s->A_edge[c][q] = pow(10.0, log_eta(ye, ze));
                    s->b_edge[c][q] = -0.4 * s->A_edge[c][q];
                    s->base[c][q] = c == 0 ? yc * (2.0 - yc) * zc * zc * (1.0 + 0.3 * yc * zc)
                                           : 0.0;
                }
            }
        }
    const struct box *b = &s->act[0];
    for (int j = b->lo[1]; j < b->hi[1]; j++)
        for (int k = b->lo[2]; k < b->hi[2]; k++)
            s->rhs[0][grid_idx(g, 0, j, k)] = forcing(lo[1] + j, lo[2] + k);
    for (int c = 0; c < 3; c++) {
        s->pb.A_cell[c] = s->A_cell[c];
        s->pb.A_edge[c] = s->A_edge[c];
    }
    s->pb.mass = 1.0;
}

static void section_free(struct section *s)
{
    for (int c = 0; c < 3; c++) {
        field_free(s->A_cell[c]);
        field_free(s->A_edge[c]);
        field_free(s->b_edge[c]);
        field_free(s->base[c]);
        field_free(s->rhs[c]);
        field_free(s->x[c]);
        field_free(s->z[c]);
    }
}

/* One gmg cycle of the flow component (with the full tangent's cross term)
 * into s->z. */
static void cycle_gmg(struct section *s)
{
    struct viscous_gmg *m = NULL;
    char err[256] = "";
    int rc = viscous_gmg_create(&m, &s->g, &s->bc, s->act, err, sizeof err);
    if (rc != 0)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
    assert_int_equal(viscous_gmg_components(m), 1);
    struct viscous_gmg_operator op = {.mass = 1.0, .base = s->base};
    for (int c = 0; c < 3; c++) {
        op.A_cell[c] = s->A_cell[c];
        op.A_edge[c] = s->A_edge[c];
        op.b_edge[c] = s->b_edge[c];
    }
    rc = viscous_gmg_setup(m, &op, err, sizeof err);
    if (rc != 0)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
    viscous_gmg_apply(m, s->rhs, s->z);
    viscous_gmg_destroy(m);
}

/* GMRES with gmg on the operator of pb to rtol into s->x; its iterations. */
static int solve_gmg(struct section *s, double rtol)
{
    return test_viscous_solve(&s->g, &s->bc, s->act, VISCOUS_GMG, &s->pb, s->rhs, s->x, rtol);
}

/* The largest difference of f between the block and the whole, over the
 * flow component's unknowns, and the largest |whole|, over the ranks. */
static void differences(const struct section *part, double *const fp[3],
                        const struct section *whole, double *const fw[3], const int lo[3],
                        double m[2])
{
    m[0] = m[1] = 0.0;
    const struct box *b = &part->act[0];
    for (int j = b->lo[1]; j < b->hi[1]; j++)
        for (int k = b->lo[2]; k < b->hi[2]; k++) {
            const double w = fw[0][grid_idx(&whole->g, 0, lo[1] + j, lo[2] + k)];
            const double diff = fabs(fp[0][grid_idx(&part->g, 0, j, k)] - w);
            m[0] = fmax(m[0], diff);
            m[1] = fmax(m[1], fabs(w));
        }
    comm_max(m, 2);
}

/* The cross-section 1 x ny x nz over dims ranks (0: MPI's choice) against
 * one process: a cycle to the bit (the gathered cycle is one process's
 * arithmetic on the same values), and a GMRES solve to 1e-12 within 1e-12
 * of the largest value (the ranks' dots summed in another order: 6e-16 to
 * 7.4e-16 measured on 2 and 4 ranks), its iterations within one. */
static void check_gmg(const int dims[3], int ny, int nz)
{
    const int periodic[3] = {1, 0, 0}, n[3] = {1, ny, nz};
    const double len[3] = {1.0 / ny, 1.0, (double)nz / ny};
    struct test_blocks b;
    test_blocks_open(&b, dims, periodic, n, len);
    struct section whole, part;
    section_make(&whole, &b.whole, NULL);
    section_make(&part, &b.whole, &b.dc);
    cycle_gmg(&whole);
    cycle_gmg(&part);
    double cyc[2], sol[2];
    differences(&part, part.z, &whole, whole.z, b.dc.lo, cyc);
    const int it_whole = solve_gmg(&whole, 1e-12), it_part = solve_gmg(&part, 1e-12);
    differences(&part, part.x, &whole, whole.x, b.dc.lo, sol);
    if (comm_rank() == 0)
        printf("    gmg 1 x %d x %d on 1 x %d x %d ranks: a cycle within %.2e, GMRES %d "
               "iterations (one process %d) within %.2e\n",
               ny, nz, b.cart.dims[1], b.cart.dims[2], cyc[0] / cyc[1], it_part, it_whole,
               sol[0] / sol[1]);
    section_free(&whole);
    section_free(&part);
    test_blocks_close(&b);
    assert_true(cyc[1] > 0.0 && sol[1] > 0.0);
    assert_true(cyc[0] == 0.0);
    assert_true(sol[0] <= 1e-12 * sol[1]);
    assert_true(abs(it_part - it_whole) <= 1);
}

/* 40 x 56: over the 4,096 cells the decomposed pressure multigrid keeps
 * on the ranks, four levels, split along y, along z and both. */
void test_gmg_ranks(void **state)
{
    (void)state;
    const int p = comm_size();
    const int splits[3][3] = {{1, p, 1}, {1, 1, p}, {1, 0, 0}}; /* y, z, both */
    int dims[3][3];
    for (int t = 0, n = test_splits(3, splits, dims); t < n; t++)
        check_gmg(dims[t], 40, 56);
}

/* The heap (cases/heap.ini) at 14 x 20 split along y and along z at a
 * fixed tilt, and its tilt search split along both (MPI's choice): gmg
 * auto's pick on ranks.  Against one process: the same status, steps
 * within one, its tilt, flow rate, surface velocity and flowing depth at
 * the mid-plane within 1e-8 relative, and the search's steps over its
 * solves (steps_total) within one. */
void test_heap_on_ranks(void **state)
{
    (void)state;
    static const char *const keys[] = {"tilt", "flow_rate", "u_surface_mid", "depth_mid", NULL};
    char *fixed[] = {"domain.ny=14", "domain.nz=20", "heap.flow_rate=0", "physics.tilt=0.405"};
    const struct scene_lines at = {.file = "../cases/heap.ini", .n = 4, .ov = fixed,
                                   .keys = keys, .count = "steps_total",
                                   .want = STATUS_STEADY};
    const int p = comm_size();
    const int splits[2][3] = {{1, p, 1}, {1, 1, p}}; /* y, z */
    check_scene_splits(&at, 2, splits);
    char *search[] = {"domain.ny=14", "domain.nz=20"};
    struct scene_lines searched = at;
    searched.n = 2;
    searched.ov = search;
    const int both[3] = {1, 0, 0};
    check_scene_lines(&searched, both);
}
