/* Grid geometry and field arrays (layout described in include/grid/grid.h). */
#include "grid/grid.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "platform/num_text.h" /* numbers in messages as case files write them */

#define FIELD_ALIGN 64

int grid_init_compact(struct grid *g, const int n[3], const double len[3], const int periodic[3])
{
    if (!g || !n || !len)
        return -1;
    for (int d = 0; d < 3; d++) {
        /* !(len > 0) also rejects NaN */
        if (n[d] < 1 || n[d] > INT_MAX - 2 || !(len[d] > 0.0))
            return -1;
    }
    size_t size = 1, padded = 1;
    int ext[3];
    for (int d = 0; d < 3; d++) {
        size_t e = (size_t)n[d] + 2;
        if (padded > SIZE_MAX / sizeof(double) / e)
            return -1; /* the field would not fit in memory */
        padded *= e;
        ext[d] = d < 2 && periodic && periodic[d] && n[d] == 1 ? 1 : n[d] + 2;
        size *= (size_t)ext[d];
    }
    for (int d = 0; d < 3; d++) {
        g->n[d] = n[d];
        g->len[d] = len[d];
        g->h[d] = len[d] / n[d];
        g->ext[d] = ext[d];
        g->axis[d] = NULL;
    }
    g->stride[2] = 1;
    g->stride[1] = ext[1] == 1 ? 0 : ext[2];
    g->stride[0] = ext[0] == 1 ? 0 : (ptrdiff_t)ext[1] * ext[2];
    g->size = size;
    g->padded = padded;
    return 0;
}

int grid_init(struct grid *g, const int n[3], const double len[3])
{
    return grid_init_compact(g, n, len, NULL);
}

int grid_init_like(struct grid *g, const int n[3], const double len[3], const struct grid *like)
{
    int compact[3];
    for (int d = 0; d < 3; d++)
        compact[d] = grid_compact(like, d);
    return grid_init_compact(g, n, len, compact);
}

double grid_min_width(const struct grid *g, int d)
{
    if (!g->axis[d])
        return g->h[d];
    double h = grid_hc(g, d, 0);
    for (int i = 1; i < g->n[d]; i++)
        h = fmin(h, grid_hc(g, d, i));
    return h;
}

void grid_bracket(const struct grid *g, int d, int at_faces, double x, int *i0, double *w)
{
    if (!g->axis[d]) {
        double t = x / g->h[d] - (at_faces ? 0.0 : 0.5);
        *i0 = (int)floor(t);
        *w = t - *i0;
        return;
    }
    int c = grid_locate(g, d, x);
    if (at_faces) {
        *i0 = c;
        *w = (x - grid_xf(g, d, c)) / grid_hc(g, d, c);
    } else {
        *i0 = x < grid_xc(g, d, c) ? c - 1 : c;
        *w = (x - grid_xc(g, d, *i0)) / grid_hf(g, d, *i0 + 1);
    }
}

int grid_locate(const struct grid *g, int d, double x)
{
    if (!g->axis[d]) {
        int i = (int)floor(x / g->h[d]);
        return i < -1 ? -1 : i > g->n[d] ? g->n[d] : i;
    }
    const double *xf = g->axis[d]->xf; /* face i at xf[i + 1] */
    int lo = -1, hi = g->n[d];         /* the cell is in [lo, hi] */
    if (x < xf[lo + 1])
        return -1;
    if (x >= xf[hi + 1])
        return hi;
    while (hi - lo > 1) { /* xf[lo + 1] <= x < xf[hi + 1] */
        int mid = lo + (hi - lo) / 2;
        if (xf[mid + 1] <= x)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

void grid_axis_free(struct grid_axis *ax)
{
    if (!ax)
        return;
    free(ax->xf);
    memset(ax, 0, sizeof *ax);
}

/* Widths of the cells of a stretch of length `length` between two bands
 * of cells h1 (its low end) and h2 (its high end), either 0 for none (the
 * box's end): each side grows from its band by the ratio, capped at h_far,
 * the smaller next cell taken first, as many as make their sum nearest to
 * length, scaled to sum to it exactly; in order from the low end (the high
 * side's cells reversed).  Returns the count, writing at most max widths
 * into w (NULL: count only). */
static int gap_cells(double length, double h1, double h2, double growth, double h_far, double *w,
                     int max)
{
    if (length <= 0.0)
        return 0;
    double a = h1, b = h2, sum = 0.0;
    int nl = 0, nr = 0;
    for (;;) {
        double na = h1 > 0.0 ? fmin(a * growth, h_far) : INFINITY;
        double nb = h2 > 0.0 ? fmin(b * growth, h_far) : INFINITY;
        int left = na <= nb;
        double s = left ? na : nb;
        /* m + 1 cells overshoot, m fall short: keep the nearer */
        if (sum + s >= length) {
            if (nl + nr > 0 && length - sum < sum + s - length)
                break;
        }
        sum += s;
        if (left) {
            a = na;
            nl++;
        } else {
            b = nb;
            nr++;
        }
        if (sum >= length)
            break;
    }
    int m = nl + nr;
    if (w) {
        double scale = length / sum;
        a = h1;
        for (int k = 0; k < nl && k < max; k++)
            w[k] = (a = fmin(a * growth, h_far)) * scale;
        b = h2;
        for (int k = 0; k < nr && m - 1 - k < max; k++)
            w[m - 1 - k] = (b = fmin(b * growth, h_far)) * scale;
    }
    return m;
}

int grid_bands_parse(const char *text, struct grid_band *b, int max)
{
    int nb = 0;
    const char *s = text;
    for (;;) {
        while (*s == ' ' || *s == '\t')
            s++;
        if (!*s)
            return nb;
        if (nb == max)
            return -1;
        int used = 0;
        if (sscanf(s, "%lf %lf %lf%n", &b[nb].lo, &b[nb].hi, &b[nb].h, &used) != 3)
            return -1;
        nb++;
        s += used;
        while (*s == ' ' || *s == '\t')
            s++;
        if (*s == ';')
            s++;
        else if (*s)
            return -1;
    }
}

int grid_axis_build_bands(struct grid_axis *ax, double len, double h_far,
                          const struct grid_band *band, int nb, double growth, int periodic,
                          char *msg, size_t msglen)
{
    memset(ax, 0, sizeof *ax);
    if (nb < 1 || nb > GRID_BANDS_MAX) {
        snprintf(msg, msglen, "1 to %d bands, not %d", GRID_BANDS_MAX, nb);
        return -1;
    }
    for (int i = 0; i < nb; i++) {
        double lo = band[i].lo, hi = band[i].hi, h_band = band[i].h;
        if (!(len > 0.0) || !(h_far > 0.0) || !(lo >= 0.0) || !(hi <= len) || !(lo < hi) ||
            !(h_band > 0.0) || !(h_band <= h_far) || !(growth > 1.0)) {
            snprintf(msg, msglen,
                     "the band [%s, %s] must lie in [0, %s] with lo < hi, its cell size "
                     "%s in (0, %.6g] (the far cell size) and the growth %s above 1",
                     num_text(lo).s, num_text(hi).s, num_text(len).s, num_text(h_band).s, h_far,
                     num_text(growth).s);
            return -1;
        }
        if (i > 0 && !(lo >= band[i - 1].hi)) {
            snprintf(msg, msglen,
                     "the bands must be in increasing order without overlap: [%s, %s] "
                     "after [%s, %s]",
                     num_text(lo).s, num_text(hi).s, num_text(band[i - 1].lo).s,
                     num_text(band[i - 1].hi).s);
            return -1;
        }
    }
    /* the counts: the low end, each band and the gap after it (the last's:
     * the high end) */
    int count[2 * GRID_BANDS_MAX + 1];
    count[0] = gap_cells(band[0].lo, 0.0, band[0].h, growth, h_far, NULL, 0);
    double total = count[0];
    for (int i = 0; i < nb; i++) {
        int mb = (int)ceil((band[i].hi - band[i].lo) / band[i].h - 1e-9);
        count[1 + 2 * i] = mb < 1 ? 1 : mb;
        count[2 + 2 * i] = gap_cells((i + 1 < nb ? band[i + 1].lo : len) - band[i].hi,
                                     band[i].h, i + 1 < nb ? band[i + 1].h : 0.0, growth, h_far,
                                     NULL, 0);
        total += (double)count[1 + 2 * i] + count[2 + 2 * i];
    }
    if (total > 100000000.0) {
        snprintf(msg, msglen, "the bands' cell sizes make more than 1e8 cells");
        return -1;
    }
    int n = (int)total;
    size_t slots = (size_t)n + 3;
    double *block = calloc(4 * slots, sizeof(double));
    if (!block) {
        snprintf(msg, msglen, "out of memory for a stretched direction of %d cells", n);
        return -1;
    }
    ax->n = n;
    ax->xf = block;
    ax->xc = block + slots;
    ax->hc = block + 2 * slots;
    ax->hf = block + 3 * slots;
    double *hc = ax->hc + 1; /* hc[i], cells -1 .. n */
    int ml = count[0];
    gap_cells(band[0].lo, 0.0, band[0].h, growth, h_far, hc, ml);
    int at = ml, ends[2 * GRID_BANDS_MAX]; /* the faces at the bands' ends */
    for (int i = 0; i < nb; i++) {
        ends[2 * i] = at;
        for (int k = 0; k < count[1 + 2 * i]; k++)
            hc[at + k] = (band[i].hi - band[i].lo) / count[1 + 2 * i];
        at += count[1 + 2 * i];
        ends[2 * i + 1] = at;
        gap_cells((i + 1 < nb ? band[i + 1].lo : len) - band[i].hi, band[i].h,
                  i + 1 < nb ? band[i + 1].h : 0.0, growth, h_far, hc + at, count[2 + 2 * i]);
        at += count[2 + 2 * i];
    }
    double *xf = ax->xf + 1, *xc = ax->xc + 1, *hf = ax->hf + 1;
    xf[0] = 0.0;
    for (int i = 0; i < n; i++)
        xf[i + 1] = xf[i] + hc[i];
    for (int i = 0; i < nb; i++) { /* exact at the bands' ends and the box's */
        xf[ends[2 * i]] = band[i].lo;
        xf[ends[2 * i + 1]] = band[i].hi;
    }
    xf[n] = len;
    for (int i = 0; i < n; i++)
        hc[i] = xf[i + 1] - xf[i];
    hc[-1] = periodic ? hc[n - 1] : hc[0];
    hc[n] = periodic ? hc[0] : hc[n - 1];
    xf[-1] = -hc[-1];
    xf[n + 1] = len + hc[n];
    for (int i = -1; i <= n; i++)
        xc[i] = 0.5 * (xf[i] + xf[i + 1]);
    for (int i = 0; i <= n; i++)
        hf[i] = xc[i] - xc[i - 1];
    hf[-1] = periodic ? hf[n - 1] : hc[-1];
    hf[n + 1] = periodic ? hf[1] : hc[n];
    return 0;
}

int grid_set_axis(struct grid *g, int d, const struct grid_axis *ax)
{
    int n[3] = {g->n[0], g->n[1], g->n[2]};
    const struct grid_axis *keep[3] = {g->axis[0], g->axis[1], g->axis[2]};
    double h[3] = {g->h[0], g->h[1], g->h[2]};
    n[d] = ax->n;
    if (grid_init_like(g, n, g->len, g) != 0)
        return -1;
    for (int e = 0; e < 3; e++) {
        g->axis[e] = keep[e];
        g->h[e] = h[e];
    }
    g->axis[d] = ax;
    /* no single size: code that reads h[d] where the spacing varies gets
     * NaN, which the march's checks stop on, rather than a wrong number */
    g->h[d] = NAN;
    return 0;
}

double *field_alloc(const struct grid *g)
{
    if (!g || g->size == 0 || g->size > SIZE_MAX / sizeof(double) - FIELD_ALIGN)
        return NULL;
    size_t bytes = g->size * sizeof(double);
    bytes = (bytes + FIELD_ALIGN - 1) / FIELD_ALIGN * FIELD_ALIGN; /* aligned_alloc needs a multiple */
    double *f = aligned_alloc(FIELD_ALIGN, bytes);
    if (f)
        memset(f, 0, bytes);
    return f;
}

void field_free(double *f)
{
    free(f);
}

size_t grid_cells(const struct grid *g)
{
    return (size_t)g->n[0] * (size_t)g->n[1] * (size_t)g->n[2];
}

/* full[q] = f[p] (to_full) or f[p] = full[q] for every full-layout slot q of
 * (i, j, k) and its slot p in g; a compact slot is read back from its node
 * (index 0) only. */
static void full_layout(const struct grid *g, double *f, double *full, int to_full)
{
    const ptrdiff_t s1 = g->n[2] + 2, s0 = (ptrdiff_t)(g->n[1] + 2) * s1;
    for (int i = -1; i <= g->n[0]; i++)
        for (int j = -1; j <= g->n[1]; j++) {
            const int node = (!grid_compact(g, 0) || i == 0) && (!grid_compact(g, 1) || j == 0);
            if (!to_full && !node)
                continue;
            const ptrdiff_t q = (ptrdiff_t)(i + 1) * s0 + (ptrdiff_t)(j + 1) * s1;
            const ptrdiff_t p = grid_idx(g, i, j, -1);
            for (int k = 0; k < g->n[2] + 2; k++) {
                if (to_full)
                    full[q + k] = f[p + k];
                else
                    f[p + k] = full[q + k];
            }
        }
}

void field_to_full(const struct grid *g, const double *f, double *full)
{
    full_layout(g, (double *)f, full, 1);
}

void field_from_full(const struct grid *g, const double *full, double *f)
{
    full_layout(g, f, (double *)full, 0);
}
