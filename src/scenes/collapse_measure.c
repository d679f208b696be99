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

/* The largest x where T crosses 1/2 along a row, or 0 when the row has no
 * grains. */
static double row_front(const struct grid *g, const double *T, int j, int k)
{
    for (int i = g->n[0] - 1; i >= 0; i--) {
        double t = T[grid_idx(g, i, j, k)];
        if (t < 0.5)
            continue;
        double xc = (i + 0.5) * g->h[0];
        if (i == g->n[0] - 1)
            return xc;
        double tn = T[grid_idx(g, i + 1, j, k)];
        return xc + g->h[0] * (t - 0.5) / (t - tn);
    }
    return 0.0;
}

void collapse_measure(const struct march_state *st, const double *T, struct collapse_sample *s)
{
    const struct grid *g = &st->g;
    s->t = st->time;
    s->x_front = 0.0;
    s->t_min = INFINITY;
    s->t_max = -INFINITY;
    double vol = 0.0;
    for (int j = 0; j < g->n[1]; j++)
        for (int k = 0; k < g->n[2]; k++) {
            s->x_front = fmax(s->x_front, row_front(g, T, j, k));
            for (int i = 0; i < g->n[0]; i++) {
                double t = T[grid_idx(g, i, j, k)];
                vol += t;
                s->t_min = fmin(s->t_min, t);
                s->t_max = fmax(s->t_max, t);
            }
        }
    s->volume = vol * g->h[0] * g->h[2] / g->n[1];
    /* h(x) = a + b x^2 through the first two column heights (x = h/2, 3h/2):
     * a = (9 h_0 - h_1) / 8 */
    double h0 = 0.0, h1 = 0.0;
    for (int j = 0; j < g->n[1]; j++)
        for (int k = 0; k < g->n[2]; k++) {
            h0 += T[grid_idx(g, 0, j, k)];
            if (g->n[0] > 1)
                h1 += T[grid_idx(g, 1, j, k)];
        }
    h0 *= g->h[2] / g->n[1];
    h1 *= g->h[2] / g->n[1];
    s->h_axis = g->n[0] > 1 ? (9.0 * h0 - h1) / 8.0 : h0;
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
    s->kinetic = ke * g->h[0] * g->h[2] / g->n[1];
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
