/* The smoothers: red-black point Gauss-Seidel and zebra line Gauss-Seidel
 * (multigrid_internal.h). */
#include "solvers/multigrid_internal.h"

/* One red-black half sweep of Gauss-Seidel: the cells with (i+j+k) % 2 == colour
 * solve their own row with the neighbours' current values (ghosts filled in
 * HALO_OPERATOR mode before the call).  Dead cells are set to 0. */
static inline __attribute__((always_inline)) void
smooth_colour_body(const struct level *lv, int colour, const int flat)
{
    const struct grid *g = &lv->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2];
    const double *restrict b = lv->b;
    double *restrict x = lv->x;
#pragma omp for collapse(2) schedule(static)
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) {
            const ptrdiff_t row = grid_idx(g, i, j, 0);
            for (int k = (i + j + colour) & 1; k < nz; k += 2) {
                const ptrdiff_t p = row + k;
                double S;
                const double D = row_sums(lv, x, p, flat, &S);
                if (lv->km[0])
                    S += mixed_row(lv, x, p);
                x[p] = D > 0.0 ? (S - b[p]) / D : 0.0;
            }
        }
}

static void smooth_colour(const struct level *lv, int colour)
{
#define CALL(flat) smooth_colour_body(lv, colour, flat)
    FLAT_DISPATCH(lv->flat, CALL);
#undef CALL
}

/* The first cell of the line along d through index u along e1, v along e2. */
static inline ptrdiff_t line_start(const struct grid *g, int d, int e1, int e2, int u, int v)
{
    int c[3];
    c[d] = 0;
    c[e1] = u;
    c[e2] = v;
    return grid_idx(g, c[0], c[1], c[2]);
}

/* The forward and backward Thomas passes of m (1 or 2, a constant after
 * inlining) lines of one colour along d from their first cells p0[j], mx[j]
 * their mixed terms (NULL: none).  Two lines go through the passes side by
 * side: each pass is a chain of dependent multiply-adds along its line, and
 * a second, independent chain fills the latency of the first.  Every line's
 * arithmetic and order are those of one line alone. */
static inline __attribute__((always_inline)) void
solve_lines(const struct level *lv, int k, int d, int e1, int e2, const int across1,
            const ptrdiff_t p0[2], double *const mx[2], const int m)
{
    const struct grid *g = &lv->g;
    const int n = g->n[d];
    const ptrdiff_t sd = g->stride[d], s1 = g->stride[e1], s2 = g->stride[e2];
    const double h1 = lv->ih2[e1], h2 = lv->ih2[e2], hd = lv->ih2[d];
    const double *restrict b = lv->b, *restrict a1 = lv->a[e1], *restrict a2 = lv->a[e2],
                           *restrict ad = lv->a[d];
    const double *restrict cp = lv->lc[k], *restrict inv = lv->li[k];
    double *restrict x = lv->x;
    double prev[2] = {0.0, 0.0};
    for (int t = 0; t < n; t++)
        for (int j = 0; j < m; j++) {
            const ptrdiff_t p = p0[j] + (ptrdiff_t)t * sd;
            double S = h2 * (a2[p] * x[p - s2] + a2[p + s2] * x[p + s2]) - b[p];
            if (across1)
                S += h1 * (a1[p] * x[p - s1] + a1[p + s1] * x[p + s1]);
            if (mx[0])
                S += mx[j][t];
            prev[j] = x[p] = (S + hd * ad[p] * prev[j]) * inv[p];
        }
    double next[2] = {0.0, 0.0};
    for (int t = n - 1; t >= 0; t--)
        for (int j = 0; j < m; j++) {
            const ptrdiff_t p = p0[j] + (ptrdiff_t)t * sd;
            next[j] = x[p] += cp[p] * next[j];
        }
}

/* One half sweep of zebra line Gauss-Seidel along direction d (the k-th line
 * direction): the lines along d whose index across (the sum of the other
 * two indices) has the parity colour solve their own tridiagonal rows
 * exactly, with the neighbouring lines' current values.  A line smoother is
 * what survives anisotropy along it (the viscous tangent's: the shear
 * direction's coefficient is the tangent, far below the viscosity across
 * it), and alternating the directions covers anisotropy that changes its
 * direction over the domain.  d is not periodic (a cyclic line is not
 * solved here), so the line ends read ghosts of 0 (HALO_OPERATOR).  The
 * Thomas factors (mg_line_factors) are the level's: the forward pass keeps its
 * values in x itself, which the line's own rows do not read.  The lines of
 * a colour go in pairs two apart along e2 (solve_lines); lines of one colour
 * do not read each other, so the pairing changes no result. */
static inline __attribute__((always_inline)) void
smooth_lines_body(const struct level *lv, int k, int d, int colour, const int across1,
                  double *mxbuf, int mxlen)
{
    const struct grid *g = &lv->g;
    const int e1 = d == 0 ? 1 : 0, e2 = d == 2 ? 1 : 2, n = g->n[d];
    const int n1 = g->n[e1], n2 = g->n[e2];
    const ptrdiff_t sd = g->stride[d], s2 = g->stride[e2];
    const double *x = lv->x;
    const int pairs = (n2 + 3) / 4; /* of the about n2 / 2 lines of a colour per u */
#pragma omp for collapse(2) schedule(static)
    for (int u = 0; u < n1; u++)
        for (int w = 0; w < pairs; w++) {
            const int v = ((colour - u) & 1) + 4 * w; /* the pair's first line */
            if (v >= n2)
                continue;
            const int m = v + 2 < n2 ? 2 : 1;
            const ptrdiff_t p0[2] = {line_start(g, d, e1, e2, u, v),
                                     line_start(g, d, e1, e2, u, v) + 2 * s2};
            /* the mixed term from the values before the lines' update (their
             * own nodes are overwritten by the forward pass) */
            double *mx[2] = {NULL, NULL};
            if (lv->km[0]) {
                mx[0] = mxbuf + (size_t)thread_id() * (size_t)(2 * mxlen);
                mx[1] = mx[0] + mxlen;
                for (int j = 0; j < m; j++)
                    for (int t = 0; t < n; t++)
                        mx[j][t] = mixed_row(lv, x, p0[j] + (ptrdiff_t)t * sd);
            }
            if (m == 2)
                solve_lines(lv, k, d, e1, e2, across1, p0, mx, 2);
            else
                solve_lines(lv, k, d, e1, e2, across1, p0, mx, 1);
        }
}

/* The first direction across (e1 < e2) is left out where it is a periodic
 * direction of one cell, whose coefficients are 0 (a 2D cross-section:
 * its two ghost planes would be read for nothing, a third of the loads). */
static void smooth_lines(const struct multigrid *mg, const struct level *lv, int k, int d,
                         int colour)
{
    const int e1 = d == 0 ? 1 : 0;
    if (mg->periodic[e1] && lv->g.n[e1] == 1)
        smooth_lines_body(lv, k, d, colour, 0, mg->mxbuf, mg->mxlen);
    else
        smooth_lines_body(lv, k, d, colour, 1, mg->mxbuf, mg->mxlen);
}

/* The Thomas factors of every line along the k-th line direction d of level
 * lv: for the rows -lo x[t-1] + D x[t] - hi x[t+1] (the face weights along
 * d, D the whole diagonal), inv = 1 / (D - lo c'[t-1]) and c' = hi inv;
 * dead cells (D = 0) get 0 for both, which holds them at 0 and cuts the
 * line there.  lo is 0 at t = 0 and hi at t = n - 1: the boundary face's
 * weight stays in D only (ghost 0). */
void mg_line_factors(const struct level *lv, int k, int d)
{
    const struct grid *g = &lv->g;
    const int e1 = d == 0 ? 1 : 0, e2 = d == 2 ? 1 : 2, n = g->n[d];
    const ptrdiff_t sd = g->stride[d];
    double *cp = lv->lc[k], *inv = lv->li[k];
#pragma omp parallel for collapse(2) schedule(static) if (lv->par)
    for (int u = 0; u < g->n[e1]; u++)
        for (int v = 0; v < g->n[e2]; v++) {
            const ptrdiff_t p0 = line_start(g, d, e1, e2, u, v);
            double prev = 0.0;
            for (int t = 0; t < n; t++) {
                const ptrdiff_t p = p0 + (ptrdiff_t)t * sd;
                double w[6];
                const double D = cell_weights(lv, p, -1, w);
                if (!(D > 0.0)) {
                    cp[p] = inv[p] = prev = 0.0;
                    continue;
                }
                const double lo = t > 0 ? w[2 * d] : 0.0, hi = t + 1 < n ? w[2 * d + 1] : 0.0;
                inv[p] = 1.0 / (D - lo * prev);
                prev = cp[p] = hi * inv[p];
            }
        }
}

/* Whether the operator's halo of level lv changes as its interior does: a
 * periodic direction of two or more cells wraps values around; every other
 * ghost the operator reads is 0 (HALO_OPERATOR), and the smoothers write
 * interior cells only, so once filled it stays filled. */
int mg_halo_wraps(const struct multigrid *mg, const struct level *lv)
{
    if (lv->dc && decomp_split(lv->dc))
        return 1; /* a rank border's ghosts are the neighbour's cells */
    for (int d = 0; d < 3; d++)
        if (mg->periodic[d] && lv->g.n[d] > 1)
            return 1;
    return 0;
}

/* Called by every thread of a team (or outside any parallel region): the
 * kernels are orphaned worksharing loops, whose implicit barriers order the
 * half sweeps and their halo fills.  The halo is filled before each half
 * sweep where it wraps, else once. */
void mg_smooth(const struct multigrid *mg, const struct level *lv, int first_colour, int sweeps)
{
    const int wraps = mg_halo_wraps(mg, lv);
    if (!wraps)
        mg_halo_fill(mg, lv, lv->x, HALO_OPERATOR);
    if (mg->opt.smoother == MG_SMOOTH_LINES && mg->nline_dirs > 0) {
        /* the post-smoother (first_colour 1) runs the pre-smoother's half
         * sweeps in reverse order: its adjoint, so the cycle stays symmetric */
        const int nd = mg->nline_dirs;
        /* split_finest: the finest level's pre-smoother takes the lines
         * of direction 1, its post-smoother those of direction 0 */
        const int only = mg->opt.split_finest && nd == 2 && lv == &mg->lev[0]
                             ? (first_colour ? 0 : 1)
                             : -1;
        for (int s = 0; s < sweeps; s++)
            for (int q = 0; q < 2 * nd; q++) {
                const int k = first_colour ? 2 * nd - 1 - q : q;
                if (only >= 0 && k / 2 != only)
                    continue;
                if (wraps)
                    mg_halo_fill(mg, lv, lv->x, HALO_OPERATOR);
                smooth_lines(mg, lv, k / 2, mg->line_dirs[k / 2], k & 1);
            }
        return;
    }
    for (int s = 0; s < sweeps; s++)
        for (int c = 0; c < 2; c++) {
            if (wraps)
                mg_halo_fill(mg, lv, lv->x, HALO_OPERATOR);
            smooth_colour(lv, first_colour ^ c ^ lv->parity); /* the global colour */
        }
}

