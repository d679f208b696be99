/* What the collapse measures on a state (scenes/collapse.h). */
#include <math.h>
#include "scenes/collapse.h"

const double *collapse_tracer(const struct march_state *st)
{
    int t = fields_find(&st->fields, "tracer");
    return t >= 0 ? st->fields.e[t].v[0] : NULL;
}

void collapse_heights(const struct grid *g, const double *T, double *h)
{
    for (int i = 0; i < g->n[0]; i++) {
        double s = 0.0;
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++)
                s += T[grid_idx(g, i, j, k)];
        h[i] = s * g->h[2] / g->n[1];
    }
}

void collapse_heights_ranks(const struct march_state *st, const double *T, double *h)
{
    const struct grid *g = &st->g, *G = march_global_grid(st);
    const int lo = st->ranks ? st->ranks->dc.lo[0] : 0;
    for (int i = 0; i < G->n[0]; i++)
        h[i] = 0.0;
    for (int i = 0; i < g->n[0]; i++) /* this rank's part of its columns */
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++)
                h[lo + i] += T[grid_idx(g, i, j, k)];
    march_sum_array(st, h, G->n[0]);
    for (int i = 0; i < G->n[0]; i++)
        h[i] *= G->h[2] / G->n[1];
}

/* check() ties the column to its y faces: a slab's are periodic, a
 * square's low one the symmetry plane (slip). */
void collapse_row_heights(const struct grid *g, const double *T, int j, double *h)
{
    for (int i = 0; i < g->n[0]; i++) {
        double s = 0.0;
        for (int k = 0; k < g->n[2]; k++)
            s += T[grid_idx(g, i, j, k)];
        h[i] = s * g->h[2];
    }
}

/* The largest distance from the axis where T crosses 1/2 along the line of
 * cells (di m, j0 + dj m, k), m = 0 .. n - 1, or 0 when the line has no
 * grains: linear between the centres, m0 + m + 1/2 steps of |(di hx, dj hy)|
 * from the axis (m0: the global index of the line's cell 0).  A line that
 * goes on past cell n - 1 (more: a rank border's ghost holds the next
 * cell) and has grains there gives 0: the crossing is the next rank's. */
static double line_front(const struct grid *g, const double *T, int di, int dj, int j0, int k,
                         int n, int m0, int more)
{
    double step = hypot(di * g->h[0], dj * g->h[1]);
    for (int m = n - 1; m >= 0; m--) {
        double t = T[grid_idx(g, di * m, j0 + dj * m, k)];
        if (t < 0.5)
            continue;
        double xc = (m0 + m + 0.5) * step;
        if (m == n - 1 && !more)
            return xc;
        double tn = T[grid_idx(g, di * (m + 1), j0 + dj * (m + 1), k)];
        if (tn >= 0.5)
            return 0.0;
        return xc + step * (t - 0.5) / (t - tn);
    }
    return 0.0;
}

/* The largest x where T crosses 1/2 along a row of this rank's block (m0:
 * its global x index; more: a rank border above), or 0 when the row has
 * no grains. */
static double row_front(const struct grid *g, const double *T, int j, int k, int m0, int more)
{
    return line_front(g, T, 1, 0, j, k, g->n[0], m0, more);
}

/* The square column's fronts and height on the axis (scenes/collapse.h). */
static void square_measures(const struct grid *g, const double *T, struct collapse_sample *s)
{
    int diagonal = g->n[0] == g->n[1] && g->h[0] == g->h[1];
    for (int k = 0; k < g->n[2]; k++) {
        s->x_front = fmax(s->x_front, row_front(g, T, 0, k, 0, 0));
        s->y_front = fmax(s->y_front, line_front(g, T, 0, 1, 0, k, g->n[1], 0, 0));
        if (diagonal)
            s->d_front = fmax(s->d_front, line_front(g, T, 1, 1, 0, k, g->n[0], 0, 0));
    }
    /* h = a + b r^2 through the cell columns (0, 0) at r^2 = h^2 / 2 and
     * (1, 0) at 5 h^2 / 2: a = (5 h_00 - h_10) / 4 */
    double h00 = 0.0, h10 = 0.0;
    for (int k = 0; k < g->n[2]; k++) {
        h00 += T[grid_idx(g, 0, 0, k)];
        if (g->n[0] > 1)
            h10 += T[grid_idx(g, 1, 0, k)];
    }
    h00 *= g->h[2];
    h10 *= g->h[2];
    s->h_axis = g->n[0] > 1 ? (5.0 * h00 - h10) / 4.0 : h00;
}

/* A slab's measures over ranks (the square runs on one process): the
 * fronts and extremes their maxima, the volume, energy and the axis's
 * columns their sums; the axis's two columns are one rank's along x
 * (blocks of two cells at least: two_phase.c), its share of them along z. */
static void reduce_over_ranks(const struct march_state *st, struct collapse_sample *s,
                              double sums[4])
{
    s->x_front = march_max(st, s->x_front);
    s->t_min = -march_max(st, -s->t_min);
    s->t_max = march_max(st, s->t_max);
    march_sum_array(st, sums, 4);
}

void collapse_measure(const struct march_state *st, const double *T, int square,
                      struct collapse_sample *s)
{
    const struct grid *g = &st->g;
    /* this rank's block: its first global x cell, a rank border above it
     * along x, the axis's columns here */
    const int m0 = st->ranks ? st->ranks->dc.lo[0] : 0;
    const int more = m0 + g->n[0] < march_global_grid(st)->n[0], axis = m0 == 0;
    s->t = st->time;
    s->x_front = s->y_front = s->d_front = 0.0;
    s->t_min = INFINITY;
    s->t_max = -INFINITY;
    double vol = 0.0;
    for (int j = 0; j < g->n[1]; j++)
        for (int k = 0; k < g->n[2]; k++) {
            if (!square)
                s->x_front = fmax(s->x_front, row_front(g, T, j, k, m0, more));
            for (int i = 0; i < g->n[0]; i++) {
                double t = T[grid_idx(g, i, j, k)];
                vol += t;
                s->t_min = fmin(s->t_min, t);
                s->t_max = fmax(s->t_max, t);
            }
        }
    /* per unit width (slab), or the quarter column's (square) */
    double cell = square ? g->h[0] * g->h[1] * g->h[2] : g->h[0] * g->h[2] / g->n[1];
    if (square)
        square_measures(g, T, s);
    double h0 = 0.0, h1 = 0.0;
    for (int j = 0; j < g->n[1] && axis; j++)
        for (int k = 0; k < g->n[2]; k++) {
            h0 += T[grid_idx(g, 0, j, k)];
            if (g->n[0] > 1)
                h1 += T[grid_idx(g, 1, j, k)];
        }
    /* kinetic energy: each face's velocity with the face density, over the
     * face's share of volume (the velocity unknowns' boxes) */
    double ke = 0.0;
    for (int c = 0; c < 3; c++) {
        const struct box *b = &st->act[c];
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++)
                for (int k = b->lo[2]; k < b->hi[2]; k++) {
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    ke += 0.5 * st->field.density_faces[c][p] * st->field.velocity[c][p] *
                          st->field.velocity[c][p];
                }
    }
    double sums[4] = {vol, h0, h1, ke};
    if (st->ranks)
        reduce_over_ranks(st, s, sums);
    const struct grid *G = march_global_grid(st);
    s->volume = sums[0] * cell;
    /* h(x) = a + b x^2 through the first two column heights (x = h/2, 3h/2):
     * a = (9 h_0 - h_1) / 8 */
    h0 = sums[1] * (g->h[2] / g->n[1]);
    h1 = sums[2] * (g->h[2] / g->n[1]);
    if (!square)
        s->h_axis = G->n[0] > 1 ? (9.0 * h0 - h1) / 8.0 : h0;
    s->kinetic = sums[3] * cell;
}

/* Length of [a, a + w] inside [0, r]. */
static double overlap(double a, double w, double r)
{
    return fmax(0.0, fmin(a + w, r) - fmax(a, 0.0));
}

double collapse_rectangle_fraction(double x0, double hx, double z0, double hz, double r,
                                   double hgt)
{
    return overlap(x0, hx, r) / hx * overlap(z0, hz, hgt) / hz;
}
