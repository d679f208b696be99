/* The coupled step's multigrid preconditioner (coupled_mg.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "march/coupled_mg.h"
#include "march/march.h"
#include "solvers/probe_matrix.h"
#include "solvers/velocity_mg.h"
#include "solvers/viscous.h"

struct coupled_mg {
    const struct probe_matrix *pm;
    const struct grid *g;
    int nu, nc;
    const int *cell;
    struct velocity_mg *mg; /* the viscous solver's (not held here) */
    double *r[3], *z[3]; /* fields of the cycle */
    double *weight;      /* per pressure row: S^-1 on the free rows */
    long nweight;
    int idle[3];
};

void coupled_mg_destroy(struct coupled_mg *m)
{
    if (!m)
        return;
    for (int c = 0; c < 3; c++) {
        field_free(m->r[c]);
        field_free(m->z[c]);
    }
    free(m->weight);
    free(m);
}

int coupled_mg_create(struct coupled_mg **out, const struct march_state *st,
                      const struct probe_matrix *pm, int nu, int nc, const int *cell, char *err,
                      size_t errlen)
{
    struct coupled_mg *m = calloc(1, sizeof *m);
    if (!m) {
        snprintf(err, errlen, "coupled step's multigrid: out of memory");
        return -1;
    }
    m->pm = pm;
    m->g = &st->g;
    m->nu = nu;
    m->nc = nc;
    m->cell = cell;
    /* the viscous solver's, which never solves in a coupled run */
    if (!(m->mg = viscous_velocity_mg(st->viscous))) {
        coupled_mg_destroy(m);
        snprintf(err, errlen, "coupled step's multigrid: the viscous solver holds none");
        return -1;
    }
    for (int c = 0; c < 3; c++)
        if (!(m->r[c] = field_alloc(&st->g)) || !(m->z[c] = field_alloc(&st->g))) {
            coupled_mg_destroy(m);
            snprintf(err, errlen, "coupled step's multigrid: out of memory");
            return -1;
        }
    *out = m;
    return 0;
}

/* z ~ A^-1 r: one cycle; an idle component's rows are K's identity. */
static void apply(void *ctx, const double *r, double *z)
{
    struct coupled_mg *m = ctx;
    for (int c = 0; c < 3; c++) {
        memset(m->r[c], 0, m->g->size * sizeof(double));
        memset(m->z[c], 0, m->g->size * sizeof(double));
    }
    probe_matrix_scatter(m->pm, r, m->r);
    velocity_mg_cycle(m->mg, m->r, m->z);
    probe_matrix_gather(m->pm, m->z, z);
    const int *comp = probe_matrix_components(m->pm);
    for (int k = 0; k < m->nu; k++)
        if (m->idle[comp[k]])
            z[k] = r[k];
}

int coupled_mg_setup(struct coupled_mg *m, const struct march_state *st,
                     const struct viscous_problem *pb, const int idle[3], int pad,
                     struct saddle_velocity_precond *vp, char *err, size_t errlen)
{
    const struct grid *g = &st->g;
    long nw = (long)m->nc + pad + 1;
    if (nw > m->nweight) {
        free(m->weight);
            m->nweight = 0;
        m->weight = malloc((size_t)nw * sizeof *m->weight);
        if (!m->weight) {
            snprintf(err, errlen, "coupled step's multigrid: out of memory");
            return -1;
        }
        m->nweight = nw;
    }
    if (velocity_mg_setup(m->mg, pb, err, errlen) != 0)
        return -1;
    for (int c = 0; c < 3; c++)
        m->idle[c] = idle[c];
    for (long q = 0; q < nw; q++)
        m->weight[q] = 1.0;
    int dims = 0;
    for (int d = 0; d < 3; d++)
        dims += g->n[d] > 1;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                int idx[3] = {i, j, k};
                ptrdiff_t p = grid_idx(g, i, j, k);
                double eta = 0.0, lap = 0.0;
                for (int a = 0; a < 3; a++) {
                    if (g->n[a] < 2)
                        continue;
                    const double *A = pb->sym_cell[a] ? pb->sym_cell[a] : pb->A_cell[a];
                    eta += A[p] / dims;
                    double h = grid_hc(g, a, idx[a]);
                    lap += 2.0 / (h * h);
                }
                m->weight[m->cell[p]] = 2.0 * eta + pb->mass / lap;
            }
    vp->apply = apply;
    vp->ctx = m;
    vp->schur_weight = m->weight;
    return 0;
}

size_t coupled_mg_bytes(const struct coupled_mg *m)
{
    return m ? velocity_mg_bytes(m->mg) : 0;
}
