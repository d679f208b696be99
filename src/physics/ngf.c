/* The nonlocal granular fluidity (physics/ngf.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "physics/ngf.h"
#include "grid/boundary.h"
#include "kernels/rheology.h"
#include "solvers/line_screened.h"

/* the largest coefficient mu_s + b I taken: beyond it g is 0 to round-off,
 * and the elimination keeps finite numbers */
#define NGF_COEF_MAX 1e300

struct ngf {
    double *fluidity;      /* the registered cell field */
    double *line;          /* 5 arrays of nz: coefficient, |D|, g, work, hc */
    double *hf;            /* nz + 1 centre distances along z */
    struct line_screened L;
};

/* The four-cell mean of an edge, as the viscosity kernels take it
 * (kernels/stencil.h: mean4). */
static double edge_mean(const double *f, ptrdiff_t e, ptrdiff_t s1, ptrdiff_t s2)
{
    return 0.25 * (f[e] + f[e - s1] + f[e - s2] + f[e - s1 - s2]);
}

static enum line_end end_condition(enum bc_kind k)
{
    return k == BC_WALL || k == BC_LID ? LINE_ZERO : LINE_NO_FLUX;
}

/* Ghosts: periodic copies along x and y, then along z the mirror of a zero
 * value (-g) on walls and lids, of a zero gradient elsewhere. */
static void fill_ghosts(const struct march_state *st, double *f)
{
    const struct grid *g = &st->g;
    bc_fill_scalar(g, &st->bc, f);
    const int nz = g->n[2];
    for (int i = grid_slot_lo(g, 0); i <= grid_slot_hi(g, 0); i++)
        for (int j = grid_slot_lo(g, 1); j <= grid_slot_hi(g, 1); j++) {
            if (end_condition(st->bc.face[2][0]) == LINE_ZERO)
                f[grid_idx(g, i, j, -1)] = -f[grid_idx(g, i, j, 0)];
            if (end_condition(st->bc.face[2][1]) == LINE_ZERO)
                f[grid_idx(g, i, j, nz)] = -f[grid_idx(g, i, j, nz - 1)];
        }
}

static int create(struct march_state *st, void **state, char *err, size_t errlen)
{
    const struct grid *g = &st->g;
    if (st->ranks && st->ranks->dc.n[2] != st->ranks->dc.n_global[2]) {
        snprintf(err, errlen, "ngf: the fluidity's z lines split over MPI ranks (a periodic z)");
        return -1;
    }
    struct ngf *m = calloc(1, sizeof *m);
    if (!m) {
        snprintf(err, errlen, "ngf: out of memory");
        return -1;
    }
    *state = m;
    const int nz = g->n[2];
    m->line = calloc(5 * (size_t)nz, sizeof(double));
    m->hf = calloc((size_t)nz + 1, sizeof(double));
    if (!m->line || !m->hf) {
        snprintf(err, errlen, "ngf: out of memory");
        return -1;
    }
    if (fields_add_written(&st->fields, "fluidity", FIELD_CHECKPOINT | FIELD_SAVED,
                           &m->fluidity) != 0) {
        snprintf(err, errlen, "ngf: cannot register the fluidity field");
        return -1;
    }
    double *hc = m->line + 4 * (size_t)nz;
    for (int k = 0; k < nz; k++)
        hc[k] = grid_hc(g, 2, k);
    for (int k = 0; k <= nz; k++)
        m->hf[k] = grid_hf(g, 2, k);
    const struct rheology *r = &st->rheo;
    m->L = (struct line_screened){
        .n = nz,
        .a2 = r->nonlocal_a * r->nonlocal_a * r->grain_diameter * r->grain_diameter,
        .hc = hc,
        .hf = m->hf,
        .lo = end_condition(st->bc.face[2][0]),
        .hi = end_condition(st->bc.face[2][1]),
    };
    return 0;
}

/* eta = p_reg / (g + lambda) on the cells and the edges, their tangents the
 * same (Picard), the Newton coefficients of the full tangent zero. */
static void replace_viscosities(struct march_state *st, const double *f)
{
    const struct grid *g = &st->g;
    const ptrdiff_t *o = g->stride;
    const double lam = st->rheo.lambda;
    const int newton = st->cs->newton;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t q = grid_idx(g, i, j, k);
                double eta = st->field.pressure_regularised[q] / (f[q] + lam);
                st->field.viscosity[q] = eta;
                if (newton)
                    for (int a = 0; a < 3; a++)
                        st->field.tangent_cells[a][q] = eta;
                if (st->b_c)
                    st->b_c[q] = 0.0;
            }
    for (int c = 0; c < 3; c++) {
        int a = (c + 1) % 3, b = (c + 2) % 3;
        int hi[3];
        hi[a] = g->n[a];
        hi[b] = g->n[b];
        hi[c] = g->n[c] - 1;
        for (int i = 0; i <= hi[0]; i++)
            for (int j = 0; j <= hi[1]; j++)
                for (int k = 0; k <= hi[2]; k++) {
                    ptrdiff_t e = grid_idx(g, i, j, k);
                    double pe = rheology_pressure(
                        &st->rheo, edge_mean(st->field.pressure, e, o[a], o[b]), NULL);
                    double eta = pe / (edge_mean(f, e, o[a], o[b]) + lam);
                    st->field.viscosity_edges[c][e] = eta;
                    if (newton)
                        st->field.tangent_edges[c][e] = eta;
                    if (st->full_tangent && st->b_e[c])
                        st->b_e[c][e] = 0.0;
                }
    }
    bc_fill_scalar(g, &st->bc, st->field.viscosity);
    if (newton)
        for (int a = 0; a < 3; a++)
            bc_fill_scalar(g, &st->bc, st->field.tangent_cells[a]);
}

/* 1 where the velocity's condition on z's face (0 low, 1 high) holds the
 * shear rate at 0: a free surface or a slip wall. */
static int shear_held(const struct march_state *st, int side)
{
    enum bc_kind k = st->bc.face[2][side];
    return k == BC_SURFACE || k == BC_SLIP;
}

/* |D|^2 of cell (i, j, k) as the viscosity kernels sum it (kernels/viscosity.c:
 * cell_edges_sum), but on a face whose condition holds the shear rate at 0
 * the edges there take their inner neighbours' values.  A free surface has
 * tau = 0 through p = 0, and the fluidity's shear rate g mu is finite there
 * (g' = 0): the condition's zero, averaged into the top cell's |D| (a source
 * of 1/sqrt(2) of its value), raised the stopping height by 78% on 10 cells
 * per layer at 22 degrees and converged at first order (the discrete
 * linear stability; docs/numerics/rheology.md). */
static double cell_shear2(const struct march_state *st, int i, int j, int k)
{
    const struct grid *g = &st->g;
    const int nz = g->n[2];
    const ptrdiff_t q = grid_idx(g, i, j, k);
    double s2 = st->field.strain_normal2[q];
    for (int c = 0; c < 3; c++) {
        int a = (c + 1) % 3, b = (c + 2) % 3;
        const double *e2 = st->field.strain_shear2[c];
        double sum = 0.0;
        for (int da = 0; da <= 1; da++)
            for (int db = 0; db <= 1; db++) {
                int face[3] = {i, j, k};
                face[a] += da;
                face[b] += db;
                /* along z (a or b is 2) an edge on a held face: its neighbour */
                if (c != 2 && face[2] == nz && shear_held(st, 1))
                    face[2] = nz - 1;
                if (c != 2 && face[2] == 0 && shear_held(st, 0))
                    face[2] = 1;
                sum += e2[grid_idx(g, face[0], face[1], face[2])];
            }
        s2 += 0.25 * sum;
    }
    return s2;
}

/* Every column's fluidity from its shear rates: with mu = |D| / g the steady
 * equation is linear in g,
 *   -A^2 d^2 g'' + (mu_s + b I) g = |D|,  I = |D| d sqrt(rho_s / p_reg),
 * one tridiagonal solve per column (physics/ngf.h says why this form). */
static void properties(struct march_state *st, void *state)
{
    struct ngf *m = state;
    const struct grid *g = &st->g;
    const struct rheology *r = &st->rheo;
    const int nz = g->n[2];
    double *coef = m->line, *shear = m->line + nz, *gcol = m->line + 2 * (size_t)nz;
    double *work = m->line + 3 * (size_t)nz;
    double *f = m->fluidity;
    const double rate = r->nonlocal_b * r->grain_diameter * sqrt(r->grain_density);
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++) {
            for (int k = 0; k < nz; k++) {
                ptrdiff_t q = grid_idx(g, i, j, k);
                double p = st->field.pressure_regularised[q];
                shear[k] = sqrt(cell_shear2(st, i, j, k));
                /* b I; p = 0 (a free surface without the pressure
                 * regularisation) has I infinite and g = 0 */
                double bi = p > 0.0 ? rate * shear[k] / sqrt(p) : (shear[k] > 0.0 ? INFINITY : 0.0);
                coef[k] = fmin(r->mu_s + bi, NGF_COEF_MAX);
            }
            if (line_screened_solve(&m->L, coef, shear, work, gcol) != 0)
                for (int k = 0; k < nz; k++)
                    gcol[k] = 0.0; /* not reached: the matrix is diagonally dominant */
            for (int k = 0; k < nz; k++)
                f[grid_idx(g, i, j, k)] = gcol[k];
        }
    fill_ghosts(st, f);
    replace_viscosities(st, f);
}

static void destroy(void *state)
{
    struct ngf *m = state;
    if (!m)
        return;
    free(m->line);
    free(m->hf);
    free(m);
}

static double memory_bound(const struct muflow_case *cs, const struct grid *g)
{
    (void)cs;
    return (double)g->size * sizeof(double) + (6.0 * g->n[2] + 1.0) * sizeof(double);
}

const struct module ngf_module = {
    .name = "ngf",
    .create = create,
    .properties = properties,
    .destroy = destroy,
    .memory_bound = memory_bound,
    .decomposed = 1, /* per z line, z unsplit; ghosts by bc_fill_scalar */
};
