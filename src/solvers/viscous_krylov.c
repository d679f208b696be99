/* The implicit viscous solve's Krylov loops (viscous_internal.h): PCG,
 * BiCGStab, GMRES around the AMG, flexible GMRES around the geometric
 * multigrids. */
#include <math.h>
#include <stdlib.h>
#include "solvers/viscous_internal.h"

/* Conjugate gradients for the symmetric operator, preconditioned by the
 * line blocks, the Fourier blocks or a factorisation. */
int visc_pcg(struct viscous_solver *s, const struct viscous_problem *pb, double bnorm,
             double *x[3], double rtol, int maxit, struct viscous_stats *st)
{
    const struct grid *g = s->g;
    const struct box *act = s->act;
    visc_precondition_apply(s, s->r, s->z);
    zero_fields(g, s->p);
    kernel_lincomb(g, act, 1.0, s->z, 0.0, s->p);
    double rz = visc_dot(s, act, s->r, s->z);
    for (int it = 1; it <= maxit; it++) {
        viscous_apply(s, pb, s->p, s->q);
        double pq = visc_dot(s, act, s->p, s->q);
        if (!(pq > 0.0) || !isfinite(pq))
            return -1;
        double alpha = rz / pq;
        kernel_axpy(g, act, alpha, s->p, x);
        kernel_axpy(g, act, -alpha, s->q, s->r);
        double rnorm = sqrt(visc_dot(s, act, s->r, s->r));
        st->iterations = it;
        st->relative_residual = rnorm / bnorm;
        if (!isfinite(rnorm))
            return -1;
        if (rnorm <= rtol * bnorm)
            return 0;
        visc_precondition_apply(s, s->r, s->z);
        double rz_new = visc_dot(s, act, s->r, s->z);
        kernel_lincomb(g, act, 1.0, s->z, rz_new / rz, s->p);
        rz = rz_new;
    }
    return 1;
}

/* BiCGStab's vectors beyond CG's; -1 when out of memory. */
static int bicgstab_alloc(struct viscous_solver *s)
{
    for (int c = 0; c < 3; c++) {
        double **fs[] = {&s->r0[c], &s->v[c], &s->t[c], &s->sh[c]};
        for (size_t m = 0; m < sizeof fs / sizeof fs[0]; m++)
            if (!*fs[m] && !(*fs[m] = field_alloc(s->g)))
                return -1;
    }
    return 0;
}

/* Preconditioned BiCGStab (van der Vorst) for the non-symmetric full tangent. */
int visc_bicgstab(struct viscous_solver *s, const struct viscous_problem *pb, double bnorm,
                  double *x[3], double rtol, int maxit, struct viscous_stats *st)
{
    const struct grid *g = s->g;
    const struct box *act = s->act;
    if (bicgstab_alloc(s) != 0)
        return -1;
    double **r = s->r, **r0 = s->r0, **p = s->p, **v = s->v, **t = s->t, **ph = s->z,
           **sh = s->sh;
    for (int c = 0; c < 3; c++) {
        memcpy(r0[c], r[c], g->size * sizeof(double));
        memset(p[c], 0, g->size * sizeof(double));
        memset(v[c], 0, g->size * sizeof(double));
    }
    double rho = 1.0, alpha = 1.0, omega = 1.0;
    for (int it = 1; it <= maxit; it++) {
        double rho_new = visc_dot(s, act, r0, r);
        if (rho_new == 0.0 || !isfinite(rho_new))
            return -1;
        double beta = (rho_new / rho) * (alpha / omega);
        rho = rho_new;
        kernel_axpy(g, act, -omega, v, p);      /* p = r + beta (p - omega v) */
        kernel_lincomb(g, act, 1.0, r, beta, p);
        visc_precondition_apply(s, p, ph);
        viscous_apply(s, pb, ph, v);
        double r0v = visc_dot(s, act, r0, v);
        if (r0v == 0.0 || !isfinite(r0v))
            return -1;
        alpha = rho / r0v;
        kernel_axpy(g, act, alpha, ph, x);
        kernel_axpy(g, act, -alpha, v, r);      /* r is now s */
        double snorm = sqrt(visc_dot(s, act, r, r));
        st->iterations = it;
        st->relative_residual = snorm / bnorm;
        if (snorm <= rtol * bnorm)
            return 0;
        visc_precondition_apply(s, r, sh);
        viscous_apply(s, pb, sh, t);
        double tt = visc_dot(s, act, t, t);
        if (!(tt > 0.0) || !isfinite(tt))
            return -1;
        omega = visc_dot(s, act, t, r) / tt;
        kernel_axpy(g, act, omega, sh, x);
        kernel_axpy(g, act, -omega, t, r);
        double rnorm = sqrt(visc_dot(s, act, r, r));
        st->relative_residual = rnorm / bnorm;
        if (!isfinite(rnorm))
            return -1;
        if (rnorm <= rtol * bnorm)
            return 0;
        if (omega == 0.0)
            return -1;
    }
    return 1;
}

/* GMRES's operator and preconditioner on the probed unknowns: the operator
 * acts on fields, the V-cycle on the gathered vectors. */
struct gmres_ctx {
    struct viscous_solver *s;
    const struct viscous_problem *pb;
};

static void gmres_operator(void *ctx, const double *x, double *y)
{
    const struct gmres_ctx *c = ctx;
    struct viscous_solver *s = c->s;
    probe_matrix_scatter(s->probe, x, s->z);
    viscous_apply(s, c->pb, s->z, s->q);
    probe_matrix_gather(s->probe, s->q, y);
}

static void gmres_precondition(void *ctx, const double *x, double *y)
{
    const struct gmres_ctx *c = ctx;
    amg_hypre_apply(c->s->amg, x, y);
}

/* Restarted GMRES (gmres.h), right-preconditioned by the AMG, from x = 0. */
int visc_gmres(struct viscous_solver *s, const struct viscous_problem *pb, double *const rhs[3],
               double *x[3], double rtol, int maxit, struct viscous_stats *st)
{
    const long n = probe_matrix_unknowns(s->probe);
    struct gmres_ctx ctx = {s, pb};
    struct gmres_stats gs;
    probe_matrix_gather(s->probe, rhs, s->amg_b);
    memset(s->amg_x, 0, (size_t)n * sizeof(double));
    int rc = gmres_solve(s->gm, gmres_operator, gmres_precondition, &ctx, s->amg_b, s->amg_x, rtol,
                         maxit, &gs);
    probe_matrix_scatter(s->probe, s->amg_x, x);
    st->iterations = gs.iterations;
    st->relative_residual = gs.relative_residual;
    return rc;
}

/* The unknowns of the components of mask (bits). */
static long gmg_unknowns(const struct viscous_solver *s, int mask)
{
    long n = 0;
    for (int c = 0; c < 3; c++)
        if (mask >> c & 1)
            n += (long)(s->act[c].hi[0] - s->act[c].lo[0]) *
                 (s->act[c].hi[1] - s->act[c].lo[1]) * (s->act[c].hi[2] - s->act[c].lo[2]);
    return n;
}

/* Between the field triple f and the vector v of the components of
 * s->gmg_mask. */
static void gmg_move(const struct viscous_solver *s, double *f[3], double *v, int to_vector)
{
    long n = 0;
    for (int c = 0; c < 3; c++) {
        if (!(s->gmg_mask >> c & 1))
            continue;
        const struct box *b = &s->act[c];
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++) {
                double *row = f[c] + grid_idx(s->g, i, j, 0);
                for (int k = b->lo[2]; k < b->hi[2]; k++, n++) {
                    if (to_vector)
                        v[n] = row[k];
                    else
                        row[k] = v[n];
                }
            }
    }
}

/* The flow component of a cross-section solved alone (the others left
 * out): its column of the operator, kernel_flow_block, in three passes
 * over the cross-section, a fraction of viscous_apply's time, which
 * computes every component's strain products and stresses on the three
 * planes of the field layout (docs/numerics/multigrid.md). */
static int flow_block_serves(const struct viscous_solver *s, const struct viscous_problem *pb)
{
    const int c = __builtin_ctz((unsigned)s->gmg_mask);
    return s->gmg_mask == 1 << c && s->bc->face[c][0] == BC_PERIODIC && s->g->n[c] == 1 &&
           !pb->embedded && !pb->open_given && !grid_stretched(s->g);
}

/* The operator's rows of the mask's components only: the flow block, or
 * the kernels writing the boxes act[c], which are emptied for the others
 * while it runs (their rows are not gathered; on the heap two thirds of
 * the stress divergence). */
static void gmg_gmres_operator(void *ctx, const double *x, double *y)
{
    const struct gmres_ctx *c = ctx;
    struct viscous_solver *s = c->s;
    gmg_move(s, s->z, (double *)x, 0); /* the components left out stay 0 */
    if (flow_block_serves(s, c->pb)) {
        const struct viscous_problem *pb = c->pb;
        const int k = __builtin_ctz((unsigned)s->gmg_mask);
        bc_fill_increment_component(s->g, s->bc, s->z, k);
        double *pe[2] = {s->pe[0], s->pe[1]}, *S[2] = {s->tmp[0], s->tmp[1]};
        const double *gb[2] = {s->flow_gb[0], s->flow_gb[1]};
        kernel_flow_block(s->g, k, gb, s->z[k], pb->A_edge,
                          pb->b_cell ? pb->b_edge : NULL, pb->mass_face[k], pb->mass, pe, S,
                          s->q[k]);
        gmg_move(s, s->q, y, 1);
        return;
    }
    struct box kept[3], part[3];
    masked_boxes(s, s->gmg_mask, part);
    memcpy(kept, s->act, sizeof kept);
    memcpy(s->act, part, sizeof part);
    viscous_apply(s, c->pb, s->z, s->q);
    memcpy(s->act, kept, sizeof kept);
    gmg_move(s, s->q, y, 1);
}

static void gmg_gmres_precondition(void *ctx, const double *x, double *y)
{
    const struct gmres_ctx *c = ctx;
    gmg_move(c->s, c->s->p, (double *)x, 0);
    visc_precondition_apply(c->s, c->s->p, c->s->q); /* the multigrid, the others' line blocks */
    gmg_move(c->s, c->s->q, y, 1);
}

/* GMRES on the components of the mask s->gmg_mask (the multigrid's, and the
 * others unless they are left out): their unknowns gathered from the boxes
 * act[c] into one vector.  GMRES rather than BiCGStab, which stalls in the
 * heap's last Newton steps where GMRES converges, also with the two
 * components across the flow in the solve on their line blocks
 * (docs/numerics/multigrid.md, "The implicit step's geometric multigrid"). */
int visc_gmg_gmres(struct viscous_solver *s, const struct viscous_problem *pb, double *x[3],
                   double rtol, int maxit, struct viscous_stats *st)
{
    const int all = s->gmg_mask != viscous_gmg_components(s->gmg);
    const long n = gmg_unknowns(s, s->gmg_mask);
    if (!s->gmg_gm[all]) {
        /* the vectors for every component, the basis for the mask's */
        const long most = gmg_unknowns(s, 7);
        if ((!s->gmg_b && !(s->gmg_b = malloc((size_t)most * sizeof(double)))) ||
            (!s->gmg_x && !(s->gmg_x = malloc((size_t)most * sizeof(double)))) ||
            gmres_create_flexible(&s->gmg_gm[all], n, GMG_RESTART) != 0)
            return -1;
        gmres_set_decomp(s->gmg_gm[all], s->bc->dc); /* its dots over the ranks */
    }
    if (flow_block_serves(s, pb) && pb->b_cell) {
        /* the base strains of the flow block's Newton term, once a solve */
        for (int t = 0; t < 2; t++)
            if (!s->flow_gb[t] && !(s->flow_gb[t] = field_alloc(s->g)))
                return -1;
        kernel_flow_gammas(s->g, __builtin_ctz((unsigned)s->gmg_mask), pb->base, s->flow_gb);
    }
    zero_fields(s->g, s->z);
    struct gmres_ctx ctx = {s, pb};
    struct gmres_stats gs;
    gmg_move(s, s->r, s->gmg_b, 1);
    memset(s->gmg_x, 0, (size_t)n * sizeof(double));
    int rc = gmres_solve(s->gmg_gm[all], gmg_gmres_operator, gmg_gmres_precondition, &ctx,
                         s->gmg_b, s->gmg_x, rtol, maxit, &gs);
    gmg_move(s, x, s->gmg_x, 0);
    st->iterations = gs.iterations;
    st->relative_residual = gs.relative_residual;
    return rc;
}

/* The unknowns of every component's box, in one vector. */
long visc_box_unknowns(const struct box act[3])
{
    long n = 0;
    for (int c = 0; c < 3; c++)
        if (act[c].hi[0] > act[c].lo[0] && act[c].hi[1] > act[c].lo[1] &&
            act[c].hi[2] > act[c].lo[2])
            n += (long)(act[c].hi[0] - act[c].lo[0]) * (act[c].hi[1] - act[c].lo[1]) *
                 (act[c].hi[2] - act[c].lo[2]);
    return n;
}

/* Between the field triple f and the vector v of every unknown. */
static void box_move(const struct grid *g, const struct box act[3], double *f[3], double *v,
                     int to_vector)
{
    long n = 0;
    for (int c = 0; c < 3; c++) {
        const struct box *b = &act[c];
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++) {
                double *row = f[c] + grid_idx(g, i, j, 0);
                for (int k = b->lo[2]; k < b->hi[2]; k++, n++) {
                    if (to_vector)
                        v[n] = row[k];
                    else
                        row[k] = v[n];
                }
            }
    }
}

/* GMRES's operator and preconditioner on every unknown: the operator
 * (the full tangent where pb has it), one multigrid cycle. */
static void mg_gmres_operator(void *ctx, const double *x, double *y)
{
    const struct gmres_ctx *c = ctx;
    struct viscous_solver *s = c->s;
    box_move(s->g, s->act, s->z, (double *)x, 0);
    viscous_apply(s, c->pb, s->z, s->q);
    box_move(s->g, s->act, s->q, y, 1);
}

static void mg_gmres_precondition(void *ctx, const double *x, double *y)
{
    const struct gmres_ctx *c = ctx;
    struct viscous_solver *s = c->s;
    box_move(s->g, s->act, s->p, (double *)x, 0);
    velocity_mg_cycle(s->mg, s->p, s->q);
    box_move(s->g, s->act, s->q, y, 1);
}

int visc_mg_gmres(struct viscous_solver *s, const struct viscous_problem *pb, double *x[3],
                  double rtol, int maxit, struct viscous_stats *st)
{
    const long n = visc_box_unknowns(s->act);
    struct gmres_ctx ctx = {s, pb};
    struct gmres_stats gs;
    box_move(s->g, s->act, s->r, s->mg_b, 1);
    memset(s->mg_x, 0, (size_t)n * sizeof(double));
    int rc = gmres_solve(s->mg_gm, mg_gmres_operator, mg_gmres_precondition, &ctx, s->mg_b,
                         s->mg_x, rtol, maxit, &gs);
    box_move(s->g, s->act, x, s->mg_x, 0);
    st->iterations = gs.iterations;
    st->relative_residual = gs.relative_residual;
    return rc;
}

/* Conjugate gradients preconditioned by one multigrid cycle (a symmetric
 * cycle of a symmetric operator) on the unknowns of the boxes act, from
 * x = 0 with the residual in s->r. */
static int mg_pcg_boxes(struct viscous_solver *s, const struct viscous_problem *pb, double bnorm,
                        double *x[3], double rtol, int maxit, struct viscous_stats *st);

/* A component along a periodic direction of one cell is coupled to no
 * other; with no right-hand side (a flow in a plane: the component across)
 * its solution is 0 and it is left out of the solve. */
int visc_mg_pcg(struct viscous_solver *s, const struct viscous_problem *pb, double bnorm,
                double *x[3], double rtol, int maxit, struct viscous_stats *st)
{
    struct box kept[3];
    memcpy(kept, s->act, sizeof kept);
    for (int c = 0; c < 3; c++) {
        if (s->bc->face[c][0] != BC_PERIODIC || s->g->n[c] != 1)
            continue;
        struct box one[3];
        masked_boxes(s, 1 << c, one);
        if (visc_max_abs(s, one, s->r) == 0.0)
            s->act[c].hi[0] = s->act[c].lo[0];
    }
    int rc = mg_pcg_boxes(s, pb, bnorm, x, rtol, maxit, st);
    memcpy(s->act, kept, sizeof kept);
    return rc;
}

static int mg_pcg_boxes(struct viscous_solver *s, const struct viscous_problem *pb, double bnorm,
                        double *x[3], double rtol, int maxit, struct viscous_stats *st)
{
    const struct grid *g = s->g;
    const struct box *act = s->act;
    velocity_mg_cycle(s->mg, s->r, s->z);
    zero_fields(g, s->p);
    kernel_lincomb(g, act, 1.0, s->z, 0.0, s->p);
    double rz = visc_dot(s, act, s->r, s->z);
    for (int it = 1; it <= maxit; it++) {
        viscous_apply(s, pb, s->p, s->q);
        double pq = visc_dot(s, act, s->p, s->q);
        if (!(pq > 0.0) || !isfinite(pq))
            return -1;
        double alpha = rz / pq;
        kernel_axpy(g, act, alpha, s->p, x);
        kernel_axpy(g, act, -alpha, s->q, s->r);
        double rnorm = sqrt(visc_dot(s, act, s->r, s->r));
        st->iterations = it;
        st->relative_residual = rnorm / bnorm;
        if (!isfinite(rnorm))
            return -1;
        if (rnorm <= rtol * bnorm)
            return 0;
        velocity_mg_cycle(s->mg, s->r, s->z);
        double rz_new = visc_dot(s, act, s->r, s->z);
        kernel_lincomb(g, act, 1.0, s->z, rz_new / rz, s->p);
        rz = rz_new;
    }
    return 1;
}

