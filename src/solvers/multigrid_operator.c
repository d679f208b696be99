/* The operator on one level: the halo fills (the only writers of ghost
 * values), the residual and the size of its terms (multigrid_internal.h). */
#include "solvers/multigrid_internal.h"

#include <math.h>

/* The two ghosts of one grid line along d (see mg_halo_fill). */
static inline void halo_pair(double *f, const struct grid *g, int d, int e1, int e2, int u,
                             int v, int src_lo, int src_hi, double s_lo, double s_hi)
{
    int c[3];
    c[e1] = u;
    c[e2] = v;
    c[d] = 0;
    const ptrdiff_t base = grid_idx(g, c[0], c[1], c[2]), sd = g->stride[d];
    const int n = g->n[d];
    f[base - sd] = s_lo * f[base + (ptrdiff_t)src_lo * sd];
    f[base + (ptrdiff_t)n * sd] = s_hi * f[base + (ptrdiff_t)src_hi * sd];
}

/* mg_halo_fill on a decomposed level: direction after direction, each
 * over the ghost-extended range of those before, the domain's boundary
 * sides filled here (periodic wrap when one rank holds the direction) and
 * the rank borders' ghosts exchanged.  Plain loops, on one thread. */
static void halo_fill_decomposed(const struct multigrid *mg, const struct level *lv, double *f,
                                 enum halo_kind kind)
{
    const struct grid *g = &lv->g;
    for (int d = 0; d < 3; d++) {
        const int n = g->n[d];
        if ((kind == HALO_OPERATOR || kind == HALO_MIRROR) && mg_periodic_flat(mg, lv, d))
            continue;
        const int e1 = d == 0 ? 1 : 0, e2 = d == 2 ? 1 : 2;
        const int lo1 = e1 < d ? -1 : 0, hi1 = e1 < d ? g->n[e1] + 1 : g->n[e1];
        const int lo2 = e2 < d ? -1 : 0, hi2 = e2 < d ? g->n[e2] + 1 : g->n[e2];
        const ptrdiff_t sd = g->stride[d];
        for (int s = 0; s < 2; s++) {
            if (lv->dc->border[d][s])
                continue;
            int src;
            double sign;
            if (mg->periodic[d]) {
                src = s ? 0 : n - 1;
                sign = 1.0;
            } else {
                src = s ? n - 1 : 0;
                sign = kind == HALO_OPERATOR ? 0.0
                       : kind == HALO_EVEN   ? 1.0
                       : mg->bc[d][s] == POISSON_DIRICHLET ? -1.0 : 1.0;
            }
            const ptrdiff_t ghost = s ? (ptrdiff_t)n * sd : -sd;
            for (int u = lo1; u < hi1; u++)
                for (int v = lo2; v < hi2; v++) {
                    int c[3];
                    c[e1] = u;
                    c[e2] = v;
                    c[d] = 0;
                    const ptrdiff_t base = grid_idx(g, c[0], c[1], c[2]);
                    f[base + ghost] = sign * f[base + (ptrdiff_t)src * sd];
                }
        }
        decomp_exchange(lv->dc, g, f, d);
    }
}

/* Cell field f on level lv (orphaned worksharing: call it from every thread of
 * a team, or outside a parallel region).  Periodic: wrap; otherwise 0
 * (operator), the conditions' value (mirror) or the mirror whatever the
 * condition (even: the transfer weights).  The transfer kinds go direction by
 * direction, each over the ghost-extended range of the directions before it,
 * so edges and corners are filled too (the transfers read them). */
void mg_halo_fill(const struct multigrid *mg, const struct level *lv, double *f,
                  enum halo_kind kind)
{
    if (lv->dc) { /* MPI from the master thread only, the cells written before */
#pragma omp barrier
#pragma omp master
        halo_fill_decomposed(mg, lv, f, kind);
#pragma omp barrier
        return;
    }
    const struct grid *g = &lv->g;
    /* the 7-point operator reads face ghosts only: the three directions then
     * write disjoint ghost sets from interior values and need no barrier
     * between them (one at the end) -- two barriers fewer per half sweep */
    const int faces_only = kind == HALO_OPERATOR;
    for (int d = 0; d < 3; d++) {
        const int e1 = d == 0 ? 1 : 0, e2 = d == 2 ? 1 : 2;
        const int ext1 = e1 < d && !faces_only, ext2 = e2 < d && !faces_only;
        const int lo1 = ext1 ? grid_slot_lo(g, e1) : 0, hi1 = ext1 ? grid_slot_hi(g, e1) + 1 : g->n[e1];
        const int lo2 = ext2 ? grid_slot_lo(g, e2) : 0, hi2 = ext2 ? grid_slot_hi(g, e2) + 1 : g->n[e2];
        const int n = g->n[d];
        /* a periodic direction of one cell has zero coefficients
         * (multigrid_levels.c): the operator reads its ghosts only times 0,
         * and on a 2D cross-section (ny = 1) they are two whole planes, most
         * of a fill's traffic.  The residual's and the correction's fills
         * skip them too: a direction no level halves has the weight 0 for
         * the ghost in the prolongation and none in the restriction, and a
         * ghost no fill writes keeps a finite value (0 from the allocation,
         * or the last fill's).  The transfer weights' fill (even) and the
         * solution's (result) still write them. */
        if ((kind == HALO_OPERATOR || kind == HALO_MIRROR) && mg->periodic[d] && n == 1)
            continue;
        int src_lo, src_hi;
        double s_lo, s_hi;
        if (mg->periodic[d]) {
            src_lo = n - 1;
            src_hi = 0;
            s_lo = s_hi = 1.0;
        } else {
            src_lo = 0;
            src_hi = n - 1;
            if (kind == HALO_OPERATOR) {
                s_lo = s_hi = 0.0;
            } else if (kind == HALO_EVEN) {
                s_lo = s_hi = 1.0;
            } else {
                s_lo = mg->bc[d][0] == POISSON_DIRICHLET ? -1.0 : 1.0;
                s_hi = mg->bc[d][1] == POISSON_DIRICHLET ? -1.0 : 1.0;
            }
        }
        if (faces_only) {
#pragma omp for collapse(2) schedule(static) nowait
            for (int u = lo1; u < hi1; u++)
                for (int v = lo2; v < hi2; v++)
                    halo_pair(f, g, d, e1, e2, u, v, src_lo, src_hi, s_lo, s_hi);
        } else {
#pragma omp for collapse(2) schedule(static)
            for (int u = lo1; u < hi1; u++)
                for (int v = lo2; v < hi2; v++)
                    halo_pair(f, g, d, e1, e2, u, v, src_lo, src_hi, s_lo, s_hi);
        }
    }
    if (faces_only) {
#pragma omp barrier
    }
}

/* Face array a (normal d) along its normal: a periodic direction's face n is
 * face 0 and face -1 is face n-1; elsewhere the ghost face -1 is unused (0).
 * Across a rank border both come from the neighbour (grid/decomp.h). */
void mg_halo_faces(const struct multigrid *mg, const struct level *lv, double *a, int d)
{
    const struct grid *g = &lv->g;
    const int e1 = d == 0 ? 1 : 0, e2 = d == 2 ? 1 : 2, n = g->n[d];
    const ptrdiff_t sd = g->stride[d];
    const int per = mg->periodic[d];
    if (lv->dc && (lv->dc->border[d][0] || lv->dc->border[d][1])) {
        if (!lv->dc->border[d][0])
            for (int u = 0; u < g->n[e1]; u++)
                for (int v = 0; v < g->n[e2]; v++) {
                    int c[3];
                    c[e1] = u;
                    c[e2] = v;
                    c[d] = -1;
                    a[grid_idx(g, c[0], c[1], c[2])] = 0.0;
                }
        decomp_exchange(lv->dc, g, a, d);
        return;
    }
    for (int u = 0; u < g->n[e1]; u++)
        for (int v = 0; v < g->n[e2]; v++) {
            int c[3];
            c[e1] = u;
            c[e2] = v;
            c[d] = 0;
            const ptrdiff_t base = grid_idx(g, c[0], c[1], c[2]);
            if (per) {
                a[base + (ptrdiff_t)n * sd] = a[base];
                a[base - sd] = a[base + (ptrdiff_t)(n - 1) * sd];
            } else {
                a[base - sd] = 0.0;
            }
        }
}

/* r = (b - shift) - L x on live cells, 0 on dead ones; with b NULL, r = L x
 * (0 on dead cells).  x's ghosts in HALO_OPERATOR mode.  r may not alias x. */
static inline __attribute__((always_inline)) void
residual_body(const struct level *lv, const double *x, const double *b, double shift, double *r,
              const int flat)
{
    const struct grid *g = &lv->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2];
    const double sign = b ? -1.0 : 1.0;
#pragma omp for collapse(2) schedule(static)
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) {
            const ptrdiff_t row = grid_idx(g, i, j, 0);
            for (int k = 0; k < nz; k++) {
                const ptrdiff_t p = row + k;
                double nb;
                const double D = row_sums(lv, x, p, flat, &nb);
                double Lx = nb - D * x[p];
                if (lv->km[0])
                    Lx += mixed_row(lv, x, p);
                const double bb = b ? b[p] - shift : 0.0;
                r[p] = D > 0.0 ? bb + sign * Lx : 0.0;
            }
        }
}

void mg_residual(const struct level *lv, const double *x, const double *b, double shift,
                 double *r)
{
#define CALL(flat) residual_body(lv, x, b, shift, r, flat)
    FLAT_DISPATCH(lv->flat, CALL);
#undef CALL
}

/* m = |b - shift| + |L| |x| cell by cell (|L|: the operator with every
 * weight taken positive), 0 on dead cells: the size of the terms whose
 * rounding the residual b - L x carries.  x's ghosts in HALO_OPERATOR mode. */
void mg_magnitude(const struct level *lv, const double *x, const double *b, double shift,
                  double *m)
{
    const struct grid *g = &lv->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2];
    const ptrdiff_t sx = g->stride[0], sy = g->stride[1];
#pragma omp for collapse(2) schedule(static)
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) {
            const ptrdiff_t row = grid_idx(g, i, j, 0);
            for (int k = 0; k < nz; k++) {
                const ptrdiff_t p = row + k;
                double w[6];
                const double D = cell_weights(lv, p, -1, w);
                const double A = w[0] * fabs(x[p - sx]) + w[1] * fabs(x[p + sx]) +
                                 w[2] * fabs(x[p - sy]) + w[3] * fabs(x[p + sy]) +
                                 w[4] * fabs(x[p - 1]) + w[5] * fabs(x[p + 1]) + D * fabs(x[p]);
                m[p] = D > 0.0 ? fabs(b[p] - shift) + A : 0.0;
            }
        }
}

void mg_zero_interior(const struct level *lv, double *f)
{
    const struct grid *g = &lv->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2];
#pragma omp for collapse(2) schedule(static)
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) {
            double *row = f + grid_idx(g, i, j, 0);
            for (int k = 0; k < nz; k++)
                row[k] = 0.0;
        }
}

void multigrid_apply(struct multigrid *mg, double *x, double *y)
{
    REGION(mg->lev[0].par, {
        mg_halo_fill(mg, &mg->lev[0], x, HALO_OPERATOR);
        mg_residual(&mg->lev[0], x, NULL, 0.0, y);
    });
}

