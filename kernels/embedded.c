/* The embedded body's held nodes and cut links (kernels/embedded.h). */
#include "kernels/embedded.h"
#include "kernels/kernels.h"

void embedded_hold(const struct embedded *e, double *v[3])
{
    for (int c = 0; c < 3; c++)
        for (long i = 0; i < e->nheld[c]; i++) {
            ptrdiff_t p = e->held[c][i];
            e->saved[c][i] = v[c][p];
            v[c][p] = 0.0;
        }
}

void embedded_release(const struct embedded *e, double mass, const double *const mass_face[3],
                      double *v[3], double *out[3])
{
    for (int c = 0; c < 3; c++)
        for (long i = 0; i < e->nheld[c]; i++) {
            ptrdiff_t p = e->held[c][i];
            double m = mass_face[0] ? mass_face[c][p] : mass;
            v[c][p] = e->saved[c][i];
            out[c][p] = m * v[c][p];
        }
}

void embedded_links(const struct embedded *e, const double *const A_cell[3],
                    const double *const A_edge[3], double scale, double *const v[3],
                    double *out[3])
{
    /* serial: a node with several cut links appears in several entries */
    for (long i = 0; i < e->nlinks; i++) {
        const struct embedded_link *l = &e->links[i];
        double A = l->coef < 3 ? A_cell[l->coef][l->at] : A_edge[l->coef - 3][l->at];
        out[l->c][l->p] += scale * A * l->w * v[l->c][l->p];
    }
}

void embedded_zero(const struct embedded *e, double *f[3])
{
    for (int c = 0; c < 3; c++)
        for (long i = 0; i < e->nheld[c]; i++)
            f[c][e->held[c][i]] = 0.0;
}

void embedded_divergence(const struct grid *g, const struct embedded *e, double *const v[3],
                         double *out)
{
    const ptrdiff_t *o = g->stride;
    const double *a0 = e->share[0], *a1 = e->share[1], *a2 = e->share[2];
    const double *u0 = v[0], *u1 = v[1], *u2 = v[2];
    const double i0 = 1.0 / g->h[0], i1 = 1.0 / g->h[1], i2 = 1.0 / g->h[2];
    if (grid_stretched(g)) {
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
        for (int i = 0; i < g->n[0]; i++)
            for (int j = 0; j < g->n[1]; j++)
                for (int k = 0; k < g->n[2]; k++) {
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    out[p] = (a0[p + o[0]] * u0[p + o[0]] - a0[p] * u0[p]) / grid_hc(g, 0, i) +
                             (a1[p + o[1]] * u1[p + o[1]] - a1[p] * u1[p]) / grid_hc(g, 1, j) +
                             (a2[p + o[2]] * u2[p + o[2]] - a2[p] * u2[p]) / grid_hc(g, 2, k);
                }
        return;
    }
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                out[p] = (a0[p + o[0]] * u0[p + o[0]] - a0[p] * u0[p]) * i0 +
                         (a1[p + o[1]] * u1[p + o[1]] - a1[p] * u1[p]) * i1 +
                         (a2[p + o[2]] * u2[p + o[2]] - a2[p] * u2[p]) * i2;
            }
}
