/* The granular bed of the two-fluid model (bed_two_fluid.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <float.h>
#include "kernels/embedded.h"
#include "kernels/kernels.h"
#include "march/step.h"
#include "physics/bed_two_fluid.h"
#include "solvers/suitesparse.h"
#include "solvers/viscous.h"

/* Round-off allowance of the particle residual, in machine epsilons of its
 * terms (as the core's). */
#define ROUNDOFF (16.0 * DBL_EPSILON)

struct two_fluid {
    struct two_fluid_params p;
    double beta;                 /* Darcy drag eta_f / K */
    int configured;
    double *up[3];               /* particle velocity (x component used) */
    double *dup[3];              /* its increment of the step */
    double *rp[3];               /* particle residual R_p */
    double *cn2, *e2[3];         /* particle strains */
    double *shear2, *scratch;    /* cell |D|^2 of u^p, and a cell array the kernel fills */
    double *eta_c, *eta_e[3];    /* particle viscosities */
    double *tan_c[3], *tan_e[3]; /* and their tangents */
    double *b_c, *b_e[3];        /* d eta / d|D| / (2 |D|): the full tangent's coefficient */
    double *pn, *pe[3];          /* d|D|^2[v] of a probe at cells and edges */
    double *Bc, *Be[3];          /* b d|D|^2[v] */
    double *btmp[3];             /* the full tangent's term of a probe */
    double *work[3], *probe[3];  /* stress divergence, probe vectors */
    double *fl[9], *pl[9];       /* probed fluid and particle operators (three combs along
                                    z lines, nine in a cross-section) */
    double residual_max;         /* max |R_p| of the last evaluation */
    double residual_excess;      /* the same beyond the round-off of its terms */
};

double two_fluid_drag(const struct two_fluid_params *p)
{
    double phi = p->bed.phi, eps = 1.0 - phi, d = p->grain_diameter;
    return p->bed.fluid_viscosity * p->kozeny * phi * phi / (eps * eps * eps * d * d);
}

static int create(struct march_state *st, void **state, char *err, size_t errlen)
{
    (void)st;
    struct two_fluid *b = calloc(1, sizeof *b);
    if (!b) {
        snprintf(err, errlen, "two_fluid: out of memory");
        return -1;
    }
    *state = b;
    return 0;
}

static void destroy(void *state)
{
    struct two_fluid *b = state;
    if (b)
        for (int s = 0; s < 9; s++) {
            free(b->fl[s]);
            free(b->pl[s]);
        }
    free(state);
}

int two_fluid_configure(struct march_state *st, const struct two_fluid_params *p, char *err,
                        size_t errlen)
{
    struct two_fluid *b = march_module_state(st, &two_fluid_module);
    if (!b) {
        snprintf(err, errlen, "two_fluid: the module is not switched on");
        return -1;
    }
    if (st->embedded && st->bc.face[1][0] == BC_PERIODIC) {
        snprintf(err, errlen, "two_fluid: with an obstacle the pair's step is solved on a "
                              "cross-section only (boundary.ylo and yhi not periodic)");
        return -1;
    }
    b->p = *p;
    b->beta = two_fluid_drag(p);
    struct field_registry *r = &st->fields;
    const struct field_spec specs[] = {
        {"particle_velocity", FIELD_FACES, FIELD_CHECKPOINT | FIELD_SAVED},
        {"particle_increment", FIELD_FACES, 0},
        {"particle_residual", FIELD_FACES, 0},
        {"particle_strain_normal2", FIELD_CELLS, 0},
        {"particle_strain_shear2", FIELD_EDGES, 0},
        {"particle_shear2", FIELD_CELLS, 0},
        {"particle_scratch", FIELD_CELLS, 0},
        {"particle_viscosity", FIELD_CELLS, 0},
        {"particle_viscosity_edges", FIELD_EDGES, 0},
        {"particle_tangent_cells", FIELD_CELLS3, 0},
        {"particle_tangent_edges", FIELD_EDGES, 0},
        {"particle_work", FIELD_FACES, 0},
        {"particle_probe", FIELD_FACES, 0},
        {"particle_tangent_b_cells", FIELD_CELLS, 0},
        {"particle_tangent_b_edges", FIELD_EDGES, 0},
        {"particle_products_cells", FIELD_CELLS, 0},
        {"particle_products_edges", FIELD_EDGES, 0},
        {"particle_tangent_B_cells", FIELD_CELLS, 0},
        {"particle_tangent_B_edges", FIELD_EDGES, 0},
        {"particle_tangent_work", FIELD_FACES, 0},
    };
    double **into[] = {b->up,     b->dup,   b->rp,    &b->cn2,  b->e2,    &b->shear2, &b->scratch,
                       &b->eta_c, b->eta_e, b->tan_c, b->tan_e, b->work,  b->probe,   &b->b_c,
                       b->b_e,    &b->pn,   b->pe,    &b->Bc,   b->Be,    b->btmp};
    _Static_assert(sizeof specs / sizeof specs[0] == sizeof into / sizeof into[0], "one each");
    int idx0 = -1;
    for (size_t m = 0; m < sizeof specs / sizeof specs[0]; m++) {
        int idx = fields_add(r, &specs[m], into[m]);
        if (idx < 0) {
            snprintf(err, errlen, "two_fluid: out of memory for the particle fields");
            return -1;
        }
        if (m == 0)
            idx0 = idx;
    }
    const struct field_output o = {"particle_velocity", {"up", "vp", "wp"}, idx0, NULL, NULL};
    int combs = st->bc.face[1][0] == BC_PERIODIC ? 3 : 9;
    for (int s = 0; s < combs; s++) {
        b->fl[s] = calloc(st->g.size, sizeof(double));
        b->pl[s] = calloc(st->g.size, sizeof(double));
        if (!b->fl[s] || !b->pl[s]) {
            snprintf(err, errlen, "two_fluid: out of memory for the line operators");
            return -1;
        }
    }
    if (fields_output(r, &o) != 0) {
        snprintf(err, errlen, "two_fluid: too many field outputs");
        return -1;
    }
    b->configured = 1;
    return 0;
}

struct law_ctx {
    const struct bed_params *p;
    const struct rheology *r;
};

/* The fluid stress's viscosity at height z (control volume dz): eta_e in
 * the bed, eta_f above, in series where the bed's top cuts the volume;
 * Newtonian (a bed_law whose slope is 0). */
static double fluid_viscosity(const void *ctx, double z, double dz, double shear, double *deta)
{
    (void)shear;
    const struct bed_params *p = ((const struct law_ctx *)ctx)->p;
    *deta = 0.0;
    double t, pp;
    bed_point(p, z, dz, &t, &pp);
    double ef = p->fluid_viscosity, eb = ef * (1.0 + 2.5 * p->phi);
    if (t <= 0.0)
        return ef;
    if (t >= 1.0)
        return eb;
    return 1.0 / (t / eb + (1.0 - t) / ef);
}

/* The bed's share of the control volume of the u-face at layer k. */
static double face_share(const struct bed_params *p, int k, double dz)
{
    double t, pp;
    bed_point(p, (k + 0.5) * dz, dz, &t, &pp);
    return t;
}

/* The particle viscosity mu_s p_p(z) f(|D|) at the point z (p_p = 0 at and
 * above the bed's top, where the grains carry no stress) and its slope (a
 * bed_law: the point's own p_p, not the control volume's mean). */
static double particle_viscosity(const void *ctx, double z, double dz, double shear,
                                 double *deta)
{
    (void)dz;
    const struct bed_params *p = ((const struct law_ctx *)ctx)->p;
    const struct rheology *r = ((const struct law_ctx *)ctx)->r;
    double pp = p->weight * (p->height - z);
    if (!(pp > 0.0)) {
        *deta = 0.0;
        return 0.0;
    }
    double f, df;
    rheology_yield_kernel(r->reg, shear, r->lambda, &f, &df);
    *deta = p->mu_s * pp * df;
    return p->mu_s * pp * f;
}

static void properties(struct march_state *st, void *state)
{
    struct two_fluid *b = state;
    if (!b->configured)
        return;
    const struct grid *g = &st->g;
    const struct muflow_case *cs = st->cs;
    const struct rheology *r = &st->rheo;
    const struct bed_params *p = &b->p.bed;
    /* the mixture: the fluid stress alone (Newtonian, tangent = viscosity) */
    for (size_t q = 0; q < g->size; q++)
        if (st->b_c)
            st->b_c[q] = 0.0;
    const struct law_ctx l = {p, r};
    struct bed_viscosity_out fluid = {.eta_c = st->field.viscosity};
    for (int a = 0; a < 3; a++) {
        fluid.tan_c[a] = cs->newton ? st->field.tangent_cells[a] : NULL;
        fluid.eta_e[a] = st->field.viscosity_edges[a];
        fluid.tan_e[a] = cs->newton ? st->field.tangent_edges[a] : NULL;
        fluid.b_e[a] = st->b_e[a];
    }
    bed_fill_viscosities(g, fluid_viscosity, &l, NULL, NULL, NULL, st->field.velocity, &fluid);
    bc_fill_scalar(g, &st->bc, st->field.viscosity);
    if (cs->newton)
        for (int a = 0; a < 3; a++)
            bc_fill_scalar(g, &st->bc, st->field.tangent_cells[a]);

    /* the particles: strains of u^p, |D| at cells as the core's kernel
     * computes it (its Newtonian viscosity is overwritten below) */
    bc_fill_velocity(g, &st->bc, b->up);
    kernel_strain(g, b->up, b->cn2, b->e2);
    bc_fill_scalar(g, &st->bc, b->cn2);
    struct rheology newt = *r;
    newt.law = LAW_NEWTONIAN;
    newt.viscosity = 1.0;
    kernel_viscosity_cells(g, &newt, b->up, b->cn2, b->e2, st->field.pressure, b->eta_c, NULL,
                           b->shear2, b->scratch, NULL);
    struct bed_viscosity_out grains = {.eta_c = b->eta_c, .b_c = b->b_c};
    for (int a = 0; a < 3; a++) {
        grains.tan_c[a] = b->tan_c[a];
        grains.eta_e[a] = b->eta_e[a];
        grains.tan_e[a] = b->tan_e[a];
        grains.b_e[a] = b->b_e[a];
    }
    bed_fill_viscosities(g, particle_viscosity, &l, b->shear2, b->cn2, b->e2, b->up, &grains);
    bc_fill_scalar(g, &st->bc, b->eta_c);
    for (int a = 0; a < 3; a++)
        bc_fill_scalar(g, &st->bc, b->tan_c[a]);
}

/* R_m += div tau^p(u^p); R_p = div tau^p(u^p) + beta t (u^m - u^p) on the
 * bed's faces (x component), 0 elsewhere. */
static void residual(struct march_state *st, void *state)
{
    struct two_fluid *b = state;
    if (!b->configured)
        return;
    const struct grid *g = &st->g;
    const double *ac[3] = {b->eta_c, b->eta_c, b->eta_c};
    kernel_stress_divergence(g, st->act, ac, (const double *const *)b->eta_e, b->up, b->work);
    if (st->embedded) { /* the grains' no slip on the body too; no rows at its held nodes */
        viscous_embedded_terms(g, &st->bc, st->act, st->embedded, ac,
                               (const double *const *)b->eta_e, -1.0, b->up, b->work);
        embedded_zero(st->embedded, b->work);
    }
    kernel_axpy(g, st->act, 1.0, b->work, st->field.residual);
    for (int c = 0; c < 3; c++)
        memset(b->rp[c], 0, g->size * sizeof(double));
    /* the round-off of R_p: a few epsilons of its terms' magnitudes (the
     * drag's beta |u| is 3e6 Pa/m for set A: its rounding alone reaches the
     * tolerance for a ten times finer grain) */
    kernel_stress_magnitude(g, st->act, ac, (const double *const *)b->eta_e, b->up, b->probe);
    const struct box *bx = &st->act[0];
    double m = 0.0, x = 0.0;
    for (int i = bx->lo[0]; i < bx->hi[0]; i++)
        for (int j = bx->lo[1]; j < bx->hi[1]; j++)
            for (int k = bx->lo[2]; k < bx->hi[2]; k++) {
                double t = face_share(&b->p.bed, k, g->h[2]);
                if (t <= 0.0)
                    continue;
                ptrdiff_t q = grid_idx(g, i, j, k);
                double rp = b->work[0][q] + b->beta * t * (st->field.velocity[0][q] - b->up[0][q]);
                b->rp[0][q] = rp;
                m = fmax(m, fabs(rp));
                double mag = b->probe[0][q] +
                             b->beta * t * (fabs(st->field.velocity[0][q]) + fabs(b->up[0][q]));
                x = fmax(x, fabs(rp) - ROUNDOFF * mag);
            }
    b->residual_max = m;
    b->residual_excess = x;
}

static double residual_max(const struct march_state *st, void *state, double *excess)
{
    (void)st;
    const struct two_fluid *b = state;
    *excess = b->configured ? b->residual_excess : 0.0;
    return b->configured ? b->residual_max : 0.0;
}

/* The line operator L v = -div(A gamma(v)) of the x component along z,
 * probed with three combs uniform across the lines: out[s] holds, at every
 * face, the sum of its row's entries in the columns k = s (mod 3). */
static void probe_line(struct march_state *st, struct two_fluid *b, const double *const A_cell[3],
                       const double *const A_edge[3], double *out[3])
{
    const struct grid *g = &st->g;
    const struct box *bx = &st->act[0];
    for (int s = 0; s < 3; s++) {
        for (int c = 0; c < 3; c++)
            memset(b->probe[c], 0, g->size * sizeof(double));
        for (int i = bx->lo[0]; i < bx->hi[0]; i++)
            for (int j = bx->lo[1]; j < bx->hi[1]; j++)
                for (int k = bx->lo[2]; k < bx->hi[2]; k++)
                    if (k % 3 == s)
                        b->probe[0][grid_idx(g, i, j, k)] = 1.0;
        bc_fill_velocity_homogeneous(g, &st->bc, b->probe);
        kernel_stress_divergence(g, st->act, A_cell, A_edge, b->probe, b->work);
        for (size_t q = 0; q < g->size; q++)
            out[s][q] = -b->work[0][q];
    }
}

/* 2 x 2 blocks, row-major {a00, a01, a10, a11} */
static int inv2(const double a[4], double r[4])
{
    double det = a[0] * a[3] - a[1] * a[2];
    if (!(fabs(det) > 0.0) || !isfinite(det))
        return -1;
    r[0] = a[3] / det;
    r[1] = -a[1] / det;
    r[2] = -a[2] / det;
    r[3] = a[0] / det;
    return 0;
}

static void mul2(const double a[4], const double b[4], double r[4])
{
    r[0] = a[0] * b[0] + a[1] * b[2];
    r[1] = a[0] * b[1] + a[1] * b[3];
    r[2] = a[2] * b[0] + a[3] * b[2];
    r[3] = a[2] * b[1] + a[3] * b[3];
}

/* The block-tridiagonal solve on one line of n faces: D[k] diagonal blocks,
 * lower[k] = diag(Fl, Pl) (coupling to k - 1), upper[k] = diag(Fu, Pu);
 * x (2 n) from rhs (2 n), D overwritten.  Block Gaussian elimination:
 * the matrix is symmetric positive definite, no pivoting needed. */
static int block_solve(int n, double (*D)[4], double (*lower)[2], double (*upper)[2],
                       double (*x)[2])
{
    double inv[4], w[4], uu[4];
    for (int k = 1; k < n; k++) {
        if (inv2(D[k - 1], inv) != 0)
            return -1;
        double l[4] = {lower[k][0], 0.0, 0.0, lower[k][1]};
        mul2(l, inv, w);
        double u[4] = {upper[k - 1][0], 0.0, 0.0, upper[k - 1][1]};
        mul2(w, u, uu);
        for (int m = 0; m < 4; m++)
            D[k][m] -= uu[m];
        x[k][0] -= w[0] * x[k - 1][0] + w[1] * x[k - 1][1];
        x[k][1] -= w[2] * x[k - 1][0] + w[3] * x[k - 1][1];
    }
    for (int k = n - 1; k >= 0; k--) {
        double r0 = x[k][0], r1 = x[k][1];
        if (k < n - 1) {
            r0 -= upper[k][0] * x[k + 1][0];
            r1 -= upper[k][1] * x[k + 1][1];
        }
        if (inv2(D[k], inv) != 0)
            return -1;
        x[k][0] = inv[0] * r0 + inv[1] * r1;
        x[k][1] = inv[2] * r0 + inv[3] * r1;
    }
    return 0;
}

/* The full tangent's term of the grains' stress, the operator's
 * -div(b d|D|^2[v] gamma(u^p)) (as the core's, solvers/viscous.c), added to
 * the probe's work = div tau[v] as +div(...) (the probe negates work into
 * the operator's rows).  For u(y, z) the shear rate
 * of an edge reads the other shear rate at the four edges around it, so the
 * term couples the nine faces around a face, within the section's combs;
 * the diagonal tangent (tan_e) drops the cross terms u_y u_z, and on the
 * circular duct's curved yield surface its steps diverged
 * (docs/numerics/bed-models.md). */
static void add_full_tangent(struct march_state *st, struct two_fluid *b, double *v[3])
{
    const struct grid *g = &st->g;
    kernel_strain_products(g, b->up, v, b->pn, b->pe);
    bc_fill_scalar(g, &st->bc, b->pn);
    kernel_tangent_cells(g, b->pn, b->pe, b->b_c, b->Bc);
    bc_fill_scalar(g, &st->bc, b->Bc);
    kernel_tangent_edges(g, b->pn, b->pe, b->b_e, b->Be);
    const double *Bcell[3] = {b->Bc, b->Bc, b->Bc};
    kernel_stress_divergence(g, st->act, Bcell, (const double *const *)b->Be, b->up, b->btmp);
    kernel_axpy(g, st->act, 1.0, b->btmp, b->work);
}

/* The cross-section (walls in y): the operator of the x component probed
 * with nine combs, uniform along x, (j mod 3, k mod 3): out[3 sj + sk] holds,
 * at every face, its row's entry in the column of that comb within reach 1
 * (the x stress of u(y, z) couples the nine faces around).  full: the
 * grains' full tangent term too (A_cell, A_edge their viscosity then). */
static void probe_section(struct march_state *st, struct two_fluid *b,
                          const double *const A_cell[3], const double *const A_edge[3], int full,
                          double *out[9])
{
    const struct grid *g = &st->g;
    const struct box *bx = &st->act[0];
    for (int s = 0; s < 9; s++) {
        for (int c = 0; c < 3; c++)
            memset(b->probe[c], 0, g->size * sizeof(double));
        for (int i = bx->lo[0]; i < bx->hi[0]; i++)
            for (int j = bx->lo[1]; j < bx->hi[1]; j++)
                for (int k = bx->lo[2]; k < bx->hi[2]; k++)
                    if (3 * (j % 3) + k % 3 == s)
                        b->probe[0][grid_idx(g, i, j, k)] = 1.0;
        bc_fill_velocity_homogeneous(g, &st->bc, b->probe);
        /* a body: its held nodes are no columns, its cut links shorten the
         * fluid nodes' stencils (a diagonal term: the comb's own entry;
         * the grad-div part of the links vanishes for u(y, z)) */
        if (st->embedded)
            embedded_hold(st->embedded, b->probe);
        kernel_stress_divergence(g, st->act, A_cell, A_edge, b->probe, b->work);
        if (full)
            add_full_tangent(st, b, b->probe);
        if (st->embedded)
            embedded_links(st->embedded, A_cell, A_edge, -1.0, b->probe, b->work);
        for (size_t q = 0; q < g->size; q++)
            out[s][q] = -b->work[0][q];
    }
}

/* The pair's Newton system on each plane i of the cross-section,
 *   [M + F + beta t      -beta t     ] [dm]   [R_m - R_p]
 *   [-beta t       M + P + beta t    ] [dp] = [R_p      ],
 * 2 ny nz unknowns (dp = 0 on faces without grains, both 0 at the nodes
 * held in an embedded body), assembled in
 * compressed rows from the probes and solved by UMFPACK. */
static int section_solve(struct march_state *st, struct two_fluid *b, double mass)
{
    const struct grid *g = &st->g;
    const struct box *bx = &st->act[0];
    int nj = bx->hi[1] - bx->lo[1], nk = bx->hi[2] - bx->lo[2], N = nj * nk, n = 2 * N;
    char err[256];
    if (suitesparse_load(err, sizeof err) != 0) {
        fprintf(stderr, "two_fluid: %s\n", err);
        return -1;
    }
    int *rowptr = malloc((size_t)(n + 1) * sizeof *rowptr);
    int *col = malloc((size_t)n * 10 * sizeof *col);
    double *val = malloc((size_t)n * 10 * sizeof *val);
    double *rhs = malloc((size_t)n * sizeof *rhs), *x = malloc((size_t)n * sizeof *x);
    double *share = malloc((size_t)nk * sizeof *share);
    int rc = rowptr && col && val && rhs && x && share ? 0 : -1;
    for (int m = 0; rc == 0 && m < nk; m++)
        share[m] = face_share(&b->p.bed, bx->lo[2] + m, g->h[2]);
    for (int i = bx->lo[0]; rc == 0 && i < bx->hi[0]; i++) {
        int e = 0;
        for (int part = 0; part < 2; part++) /* 0: u^m rows, 1: u^p rows */
            for (int jj = 0; jj < nj; jj++)
                for (int kk = 0; kk < nk; kk++) {
                    int r = part * N + jj * nk + kk;
                    int j = bx->lo[1] + jj, k = bx->lo[2] + kk;
                    ptrdiff_t q = grid_idx(g, i, j, k);
                    double t = share[kk], bt = b->beta * t;
                    double *const *op = part ? b->pl : b->fl;
                    rowptr[r] = e;
                    /* no grains, or a node held in a body: d = 0 */
                    int held = st->embedded && !(st->embedded->share[0][q] > 0.0);
                    if (held || (part == 1 && !(t > 0.0))) {
                        col[e] = r;
                        val[e++] = 1.0;
                        rhs[r] = 0.0;
                        continue;
                    }
                    if (part == 1) { /* the drag's coupling to u^m, left of the P block */
                        col[e] = jj * nk + kk;
                        val[e++] = -bt;
                    }
                    for (int dj = -1; dj <= 1; dj++)
                        for (int dk = -1; dk <= 1; dk++) {
                            int j2 = jj + dj, k2 = kk + dk;
                            if (j2 < 0 || j2 >= nj || k2 < 0 || k2 >= nk)
                                continue;
                            /* a coupling to a face without grains is zero (p_p = 0 there) */
                            if (part == 1 && !(share[k2] > 0.0))
                                continue;
                            int s = 3 * ((bx->lo[1] + j2) % 3) + (bx->lo[2] + k2) % 3;
                            double a = op[s][q];
                            if (dj == 0 && dk == 0)
                                a += mass + bt;
                            col[e] = part * N + j2 * nk + k2;
                            val[e++] = a;
                        }
                    if (part == 0 && t > 0.0) { /* the drag's coupling to u^p, right of F */
                        col[e] = N + jj * nk + kk;
                        val[e++] = -bt;
                    }
                    rhs[r] = part ? b->rp[0][q] : st->field.residual[0][q] - b->rp[0][q];
                }
        rowptr[n] = e;
        /* the rows, read as compressed columns, are the transpose: solve with it */
        void *sym = NULL, *num = NULL;
        if (suitesparse.umfpack_di_symbolic(n, n, rowptr, col, val, &sym, NULL, NULL) !=
                UMFPACK_OK ||
            suitesparse.umfpack_di_numeric(rowptr, col, val, sym, &num, NULL, NULL) != UMFPACK_OK ||
            suitesparse.umfpack_di_solve(UMFPACK_At, rowptr, col, val, x, rhs, num, NULL, NULL) !=
                UMFPACK_OK)
            rc = -1;
        if (sym)
            suitesparse.umfpack_di_free_symbolic(&sym);
        if (num)
            suitesparse.umfpack_di_free_numeric(&num);
        for (int jj = 0; rc == 0 && jj < nj; jj++)
            for (int kk = 0; kk < nk; kk++) {
                ptrdiff_t q = grid_idx(g, i, bx->lo[1] + jj, bx->lo[2] + kk);
                st->field.increment[0][q] = x[jj * nk + kk];
                b->dup[0][q] = x[N + jj * nk + kk];
            }
    }
    free(rowptr);
    free(col);
    free(val);
    free(rhs);
    free(x);
    free(share);
    st->linear_iterations = 1;
    return rc;
}

static int implicit(struct march_state *st, void *state, double dt)
{
    struct two_fluid *b = state;
    const struct grid *g = &st->g;
    const struct muflow_case *cs = st->cs;
    if (!b->configured)
        return 1;
    /* the linearised stresses: the fluid's as the core's step takes them,
     * the particles' tangent on Newton steps, else their viscosity */
    struct viscous_problem pb = implicit_problem(st, 0.0);
    int tangent = implicit_uses_tangent(st);
    const double *pc[3], *pe[3];
    for (int a = 0; a < 3; a++) {
        pc[a] = tangent ? b->tan_c[a] : b->eta_c;
        pe[a] = tangent ? b->tan_e[a] : b->eta_e[a];
    }
    double mass = dt > 0.0 ? cs->density / dt : 0.0;
    for (int c = 0; c < 3; c++) {
        memset(st->field.increment[c], 0, g->size * sizeof(double));
        memset(b->dup[c], 0, g->size * sizeof(double));
    }
    if (st->bc.face[1][0] != BC_PERIODIC) { /* a cross-section u(y, z) */
        /* the grains' Newton step with the full tangent: their viscosity
         * and the term of its slope */
        const double *vc[3] = {b->eta_c, b->eta_c, b->eta_c};
        probe_section(st, b, pb.A_cell, pb.A_edge, 0, b->fl);
        if (tangent)
            probe_section(st, b, vc, (const double *const *)b->eta_e, 1, b->pl);
        else
            probe_section(st, b, pc, pe, 0, b->pl);
        return section_solve(st, b, mass);
    }
    probe_line(st, b, pb.A_cell, pb.A_edge, b->fl);
    probe_line(st, b, pc, pe, b->pl);
    const struct box *bx = &st->act[0];
    int n = bx->hi[2] - bx->lo[2];
    double(*D)[4] = malloc((size_t)n * sizeof *D);
    double(*lo)[2] = malloc((size_t)n * sizeof *lo);
    double(*up)[2] = malloc((size_t)n * sizeof *up);
    double(*x)[2] = malloc((size_t)n * sizeof *x);
    int rc = (D && lo && up && x) ? 0 : -1;
    for (int i = bx->lo[0]; rc == 0 && i < bx->hi[0]; i++)
        for (int j = bx->lo[1]; rc == 0 && j < bx->hi[1]; j++) {
            for (int m = 0; m < n; m++) {
                int k = bx->lo[2] + m;
                ptrdiff_t q = grid_idx(g, i, j, k);
                int s0 = k % 3, sm = (k + 2) % 3, sp = (k + 1) % 3;
                double t = face_share(&b->p.bed, k, g->h[2]), bt = b->beta * t;
                D[m][0] = mass + b->fl[s0][q] + bt;
                lo[m][0] = m > 0 ? b->fl[sm][q] : 0.0;
                up[m][0] = m < n - 1 ? b->fl[sp][q] : 0.0;
                x[m][0] = st->field.residual[0][q] - b->rp[0][q];
                if (t > 0.0) {
                    D[m][1] = D[m][2] = -bt;
                    D[m][3] = mass + b->pl[s0][q] + bt;
                    lo[m][1] = m > 0 ? b->pl[sm][q] : 0.0;
                    up[m][1] = m < n - 1 ? b->pl[sp][q] : 0.0;
                    x[m][1] = b->rp[0][q];
                } else { /* no grains: dp = 0 */
                    D[m][1] = D[m][2] = 0.0;
                    D[m][3] = 1.0;
                    lo[m][1] = up[m][1] = 0.0;
                    x[m][1] = 0.0;
                }
            }
            /* a coupling to a face without grains is zero (p_p = 0 there) */
            for (int m = 0; m < n; m++) {
                if (m > 0 && face_share(&b->p.bed, bx->lo[2] + m - 1, g->h[2]) <= 0.0)
                    lo[m][1] = 0.0;
                if (m < n - 1 && face_share(&b->p.bed, bx->lo[2] + m + 1, g->h[2]) <= 0.0)
                    up[m][1] = 0.0;
            }
            if (block_solve(n, D, lo, up, x) != 0) {
                rc = -1;
                break;
            }
            for (int m = 0; m < n; m++) {
                ptrdiff_t q = grid_idx(g, i, j, bx->lo[2] + m);
                st->field.increment[0][q] = x[m][0];
                b->dup[0][q] = x[m][1];
            }
        }
    free(D);
    free(lo);
    free(up);
    free(x);
    st->linear_iterations = 1;
    return rc;
}

static void end_step(struct march_state *st, void *state, double dt)
{
    (void)dt;
    struct two_fluid *b = state;
    if (!b->configured)
        return;
    const struct grid *g = &st->g;
    for (size_t q = 0; q < g->size; q++)
        b->up[0][q] += b->dup[0][q];
}

int two_fluid_particle_profile(const struct march_state *st, double *upro, double *slip_max)
{
    const struct two_fluid *b = march_module_state(st, &two_fluid_module);
    if (!b || !b->configured)
        return -1;
    const struct grid *g = &st->g;
    const struct box *bx = &st->act[0];
    double smax = 0.0;
    for (int k = 0; k < g->n[2]; k++) {
        double t = face_share(&b->p.bed, k, g->h[2]), s = 0.0;
        long cnt = 0;
        for (int i = bx->lo[0]; i < bx->hi[0]; i++)
            for (int j = bx->lo[1]; j < bx->hi[1]; j++, cnt++) {
                ptrdiff_t q = grid_idx(g, i, j, k);
                s += b->up[0][q];
                if (t > 0.0)
                    smax = fmax(smax, fabs(st->field.velocity[0][q] - b->up[0][q]));
            }
        upro[k] = t > 0.0 && cnt > 0 ? s / (double)cnt : NAN;
    }
    if (slip_max)
        *slip_max = smax;
    return 0;
}

double two_fluid_particle_residual(const struct march_state *st)
{
    const struct two_fluid *b = march_module_state(st, &two_fluid_module);
    return b && b->configured ? b->residual_max / march_force_scale(st) : 0.0;
}

const struct module two_fluid_module = {
    .name = "two_fluid",
    .create = create,
    .properties = properties,
    .residual = residual,
    .residual_max = residual_max,
    .implicit = implicit,
    .end_step = end_step,
    .destroy = destroy,
};
