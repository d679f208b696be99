/* Divergence of face fields and gradient of cell fields (projection step). */
#include "kernels/kernels.h"

void kernel_divergence(const struct grid *g, double *const vel[3], double *div)
{
    const ptrdiff_t *o = g->stride;
    const double *h = g->h;
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                const int idx[3] = {i, j, k};
                double s = 0.0;
                for (int a = 0; a < 3; a++)
                    s += (vel[a][p + o[a]] - vel[a][p]) / (g->axis[a] ? grid_hc(g, a, idx[a]) : h[a]);
                div[p] = s;
            }
}

void kernel_gradient_update(const struct grid *g, const struct box act[3], const double *p,
                            double scale, double *vel[3])
{
    const ptrdiff_t *o = g->stride;
    for (int a = 0; a < 3; a++) {
        const struct box *bx = &act[a];
        double c = scale / g->h[a];
        double *va = vel[a];
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
        for (int i = bx->lo[0]; i < bx->hi[0]; i++)
            for (int j = bx->lo[1]; j < bx->hi[1]; j++)
                for (int k = bx->lo[2]; k < bx->hi[2]; k++) {
                    ptrdiff_t q = grid_idx(g, i, j, k);
                    /* a stretched direction: the distance of the two centres */
                    const int ia = a == 0 ? i : a == 1 ? j : k;
                    double ca = g->axis[a] ? scale / grid_hf(g, a, ia) : c;
                    va[q] -= ca * (p[q] - p[q - o[a]]);
                }
    }
}
