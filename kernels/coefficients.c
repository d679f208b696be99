/* Face-coefficient variants of the vector and gradient kernels, for a
 * variable density (kernels.h).  One density everywhere takes the scalar
 * kernels instead, so the coefficient costs a scene nothing until it varies. */
#include "kernels/kernels.h"

/* y = a .* x + sign y, face by face over the unknowns. */
static void multiply_combine(const struct grid *g, const struct box act[3],
                             const double *const a[3], double *const x[3], double sign,
                             double *y[3])
{
    for (int c = 0; c < 3; c++) {
        const struct box *bx = &act[c];
        const double *ac = a[c], *xc = x[c];
        double *yc = y[c];
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
        for (int i = bx->lo[0]; i < bx->hi[0]; i++)
            for (int j = bx->lo[1]; j < bx->hi[1]; j++)
                for (int k = bx->lo[2]; k < bx->hi[2]; k++) {
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    yc[p] = ac[p] * xc[p] + sign * yc[p];
                }
    }
}

void kernel_multiply_add(const struct grid *g, const struct box act[3], double *const a[3],
                         double *const x[3], double *y[3])
{
    multiply_combine(g, act, (const double *const *)a, x, 1.0, y);
}

void kernel_multiply_minus(const struct grid *g, const struct box act[3], const double *const a[3],
                           double *const x[3], double *y[3])
{
    multiply_combine(g, act, a, x, -1.0, y);
}

void kernel_gradient_update_coef(const struct grid *g, const struct box act[3], const double *p,
                                 double scale, double *const beta[3], double *vel[3])
{
    const ptrdiff_t *o = g->stride;
    for (int a = 0; a < 3; a++) {
        const struct box *bx = &act[a];
        double c = scale / g->h[a];
        const double *ba = beta[a];
        double *va = vel[a];
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
        for (int i = bx->lo[0]; i < bx->hi[0]; i++)
            for (int j = bx->lo[1]; j < bx->hi[1]; j++)
                for (int k = bx->lo[2]; k < bx->hi[2]; k++) {
                    ptrdiff_t q = grid_idx(g, i, j, k);
                    const int ia = a == 0 ? i : a == 1 ? j : k;
                    double ca = g->axis[a] ? scale / grid_hf(g, a, ia) : c;
                    va[q] -= ca * ba[q] * (p[q] - p[q - o[a]]);
                }
    }
}
