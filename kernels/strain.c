/* Strain-rate components at their own locations (kernels.h). */
#include "kernels/kernels.h"
#include "stencil.h"

/* Products of the strain components of u and v where they live:
 * cell = scale * sum_i gamma_ii(u) gamma_ii(v), edge = gamma_ab(u) gamma_ab(v). */
static void strain_pairs(const struct grid *g, double *const u[3], double *const v[3],
                         double scale, double *cell, double *edge[3])
{
    const ptrdiff_t *o = g->stride;
    const double *h = g->h;
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                const int idx[3] = {i, j, k};
                double q = 0.0;
                for (int a = 0; a < 3; a++) {
                    double ha = g->axis[a] ? grid_hc(g, a, idx[a]) : h[a];
                    double gu = 2.0 * (u[a][p + o[a]] - u[a][p]) / ha;
                    double gv = 2.0 * (v[a][p + o[a]] - v[a][p]) / ha;
                    q += scale * gu * gv;
                }
                cell[p] = q;
            }
    for (int c = 0; c < 3; c++) {
        int a, b, lo[3], hi[3];
        edge_range(g, c, &a, &b, lo, hi);
        double *ec = edge[c];
        if (!g->axis[a] && !g->axis[b]) {
            /* uniform cells across the plane: the same arithmetic with the
             * spacings and the components' arrays out of the inner loop
             * (the tangent's strain products are a tenth of a matrix-free
             * Krylov step) */
            const double ha = h[a], hb = h[b];
            const ptrdiff_t oa = o[a], ob = o[b];
            /* |D|^2's squares (u and v the same field): one edge_gamma
             * squared, the same product */
            const int same = u == v;
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
            for (int i = lo[0]; i <= hi[0]; i++)
                for (int j = lo[1]; j <= hi[1]; j++) {
                    const ptrdiff_t row = grid_idx(g, i, j, 0);
                    if (same)
                        for (int k = lo[2]; k <= hi[2]; k++) {
                            const ptrdiff_t e = row + k;
                            const double gu = edge_gamma(u, a, b, e, oa, ob, ha, hb);
                            ec[e] = gu * gu;
                        }
                    else
                        for (int k = lo[2]; k <= hi[2]; k++) {
                            const ptrdiff_t e = row + k;
                            ec[e] = edge_gamma(u, a, b, e, oa, ob, ha, hb) *
                                    edge_gamma(v, a, b, e, oa, ob, ha, hb);
                        }
                }
            continue;
        }
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
        for (int i = lo[0]; i <= hi[0]; i++)
            for (int j = lo[1]; j <= hi[1]; j++)
                for (int k = lo[2]; k <= hi[2]; k++) {
                    ptrdiff_t e = grid_idx(g, i, j, k);
                    const int idx[3] = {i, j, k};
                    /* the edge sits on faces of a and b: the centres' distances */
                    double ha = g->axis[a] ? grid_hf(g, a, idx[a]) : h[a];
                    double hb = g->axis[b] ? grid_hf(g, b, idx[b]) : h[b];
                    ec[e] = edge_gamma(u, a, b, e, o[a], o[b], ha, hb) *
                            edge_gamma(v, a, b, e, o[a], o[b], ha, hb);
                }
    }
}

void kernel_strain(const struct grid *g, double *const vel[3], double *cn2, double *e2[3])
{
    strain_pairs(g, vel, vel, 0.5, cn2, e2);
}

void kernel_strain_products(const struct grid *g, double *const u[3], double *const v[3],
                            double *pn, double *pe[3])
{
    strain_pairs(g, u, v, 1.0, pn, pe);
}
