/* Vector operations over the velocity unknowns.  Reductions are summed per
 * thread and then in thread order, so that a run is bit-for-bit repeatable
 * with a given thread count (restart and regression depend on it). */
#include <math.h>
#include <omp.h>
#include "kernels/kernels.h"

#define MAX_THREADS 256

/* Deterministic reduction of f(p) over the unknowns of one box. */
#define BOX_REDUCE(bx, result, combine, init, expr)                                   \
    do {                                                                               \
        double part_[MAX_THREADS];                                                     \
        int nt_ = 1;                                                                   \
        _Pragma("omp parallel if (kernel_parallel(g))")                                \
        {                                                                              \
            int t_ = omp_get_thread_num();                                             \
            _Pragma("omp single") nt_ = omp_get_num_threads();                         \
            double acc_ = (init);                                                      \
            _Pragma("omp for collapse(2) schedule(static)")                            \
            for (int i = (bx)->lo[0]; i < (bx)->hi[0]; i++)                            \
                for (int j = (bx)->lo[1]; j < (bx)->hi[1]; j++)                        \
                    for (int k = (bx)->lo[2]; k < (bx)->hi[2]; k++) {                  \
                        ptrdiff_t p = grid_idx(g, i, j, k);                            \
                        double x_ = (expr);                                            \
                        acc_ = combine(acc_, x_);                                      \
                    }                                                                  \
            if (t_ < MAX_THREADS)                                                      \
                part_[t_] = acc_;                                                      \
        }                                                                              \
        for (int t_ = 0; t_ < nt_ && t_ < MAX_THREADS; t_++)                           \
            result = combine(result, part_[t_]);                                       \
    } while (0)

static inline double add(double a, double b) { return a + b; }
/* fmax(v, 0), NaN giving 0 as in fmax, written out (see maxabs) */
static inline double positive(double v) { return v > 0.0 ? v : 0.0; }

/* fmax(|a|, |b|), NaN ignored as fmax ignores it, written out: GCC calls
 * libm's fmax rather than inline it (1.5 % of the heap's run) */
static inline double maxabs(double a, double b)
{
    const double x = fabs(a), y = fabs(b);
    return x > y || y != y ? x : y;
}

double kernel_dot(const struct grid *g, const struct box act[3], double *const a[3],
                  double *const b[3])
{
    double s = 0.0;
    for (int c = 0; c < 3; c++) {
        const double *ac = a[c], *bc = b[c];
        double sc = 0.0;
        BOX_REDUCE(&act[c], sc, add, 0.0, ac[p] * bc[p]);
        s += sc;
    }
    return s;
}

double kernel_max_abs(const struct grid *g, const struct box act[3], double *const a[3])
{
    double m = 0.0;
    for (int c = 0; c < 3; c++) {
        const double *ac = a[c];
        BOX_REDUCE(&act[c], m, maxabs, 0.0, ac[p]);
    }
    return m;
}

void kernel_axpy(const struct grid *g, const struct box act[3], double alpha, double *const x[3],
                 double *y[3])
{
    for (int c = 0; c < 3; c++) {
        const struct box *bx = &act[c];
        const double *xc = x[c];
        double *yc = y[c];
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
        for (int i = bx->lo[0]; i < bx->hi[0]; i++)
            for (int j = bx->lo[1]; j < bx->hi[1]; j++)
                for (int k = bx->lo[2]; k < bx->hi[2]; k++) {
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    yc[p] += alpha * xc[p];
                }
    }
}

void kernel_lincomb(const struct grid *g, const struct box act[3], double alpha, double *const x[3],
                    double beta, double *y[3])
{
    for (int c = 0; c < 3; c++) {
        const struct box *bx = &act[c];
        const double *xc = x[c];
        double *yc = y[c];
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
        for (int i = bx->lo[0]; i < bx->hi[0]; i++)
            for (int j = bx->lo[1]; j < bx->hi[1]; j++)
                for (int k = bx->lo[2]; k < bx->hi[2]; k++) {
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    yc[p] = alpha * xc[p] + beta * yc[p];
                }
    }
}

static void interior_box(const struct grid *g, struct box *bx)
{
    for (int d = 0; d < 3; d++) {
        bx->lo[d] = 0;
        bx->hi[d] = g->n[d];
    }
}

double kernel_sum(const struct grid *g, const double *f)
{
    struct box bx;
    interior_box(g, &bx);
    double s = 0.0;
    BOX_REDUCE(&bx, s, add, 0.0, f[p]);
    return s;
}

double kernel_box_mean(const struct grid *g, const struct box *b, const double *f)
{
    double s = 0.0;
    BOX_REDUCE(b, s, add, 0.0, f[p]);
    long n = (long)(b->hi[0] - b->lo[0]) * (b->hi[1] - b->lo[1]) * (b->hi[2] - b->lo[2]);
    return n > 0 ? s / (double)n : 0.0;
}

double kernel_component_mean(const struct grid *g, const struct box *b, int c, const double *f)
{
    if (!grid_stretched(g))
        return kernel_box_mean(g, b, f);
    /* each node weighs its control volume: the cell's width across c's
     * other directions, the two half cells' along c */
    double s = 0.0, vol = 0.0;
    for (int i = b->lo[0]; i < b->hi[0]; i++)
        for (int j = b->lo[1]; j < b->hi[1]; j++)
            for (int k = b->lo[2]; k < b->hi[2]; k++) {
                const int idx[3] = {i, j, k};
                double w = 1.0;
                for (int d = 0; d < 3; d++)
                    w *= grid_node_width(g, c, d, idx[d]);
                s += w * f[grid_idx(g, i, j, k)];
                vol += w;
            }
    return vol > 0.0 ? s / vol : 0.0;
}

double kernel_norm2_cells(const struct grid *g, const double *f)
{
    struct box bx;
    interior_box(g, &bx);
    double s = 0.0;
    BOX_REDUCE(&bx, s, add, 0.0, f[p] * f[p]);
    return sqrt(s);
}

double kernel_max_abs_cells(const struct grid *g, const double *f)
{
    struct box bx;
    interior_box(g, &bx);
    double m = 0.0;
    BOX_REDUCE(&bx, m, maxabs, 0.0, f[p]);
    return m;
}

double kernel_residual_excess(const struct grid *g, const struct box act[3], double *const r[3],
                              double *const m[3], double *const f[3], double eps_factor)
{
    double x = 0.0;
    for (int c = 0; c < 3; c++) {
        const double *rc = r[c], *mc = m[c], *fc = f[c];
        BOX_REDUCE(&act[c], x, maxabs, 0.0,
                   positive(fabs(rc[p]) - eps_factor * (fabs(mc[p]) + fabs(fc[p]))));
    }
    return x;
}
