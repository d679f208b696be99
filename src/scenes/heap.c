/* Heap-scene diagnostics (heap.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "scenes/heap.h"

/* Value at the boundary of a field with zero normal slope there, from the
 * two nearest cell centres (a quadratic a + b s^2 in the distance s through
 * both): u(0) = (9 u(h/2) - u(3h/2)) / 8.  The free surface carries no shear
 * stress and the mid-plane is a symmetry plane, so both have zero slope. */
static double zero_slope_end(double nearest, double next)
{
    return (9.0 * nearest - next) / 8.0;
}

/* u of column j, layer k: the mean over the x-faces of the periodic x. */
static double column_u(const struct march_state *st, int j, int k)
{
    const struct grid *g = &st->g;
    double s = 0.0;
    for (int i = 0; i < g->n[0]; i++)
        s += st->vel[0][grid_idx(g, i, j, k)];
    return s / g->n[0];
}

double heap_flow_rate(const struct march_state *st)
{
    const struct grid *g = &st->g;
    const struct muflow_case *cs = st->cs;
    double flux = 0.0;
    for (int j = 0; j < g->n[1]; j++)
        for (int k = 0; k < g->n[2]; k++)
            flux += column_u(st, j, k);
    flux *= g->h[1] * g->h[2];
    double d = cs->rheo.grain_diameter;
    return flux / g->len[1] / (d * sqrt(cs->gravity * d));
}

/* Depth below the surface where u first falls to target, scanning down. */
static double column_depth(const struct march_state *st, int j, double target)
{
    const struct grid *g = &st->g;
    double h = g->h[2], above = column_u(st, j, g->n[2] - 1);
    if (!(above > target))
        return 0.0;
    for (int k = g->n[2] - 2; k >= 0; k--) {
        double u = column_u(st, j, k);
        if (u <= target) {
            double z = (k + 0.5 + (target - u) / (above - u)) * h;
            return g->len[2] - z;
        }
        above = u;
    }
    return g->len[2];
}

void heap_profile_free(struct heap_profile *hp)
{
    free(hp->y);
    free(hp->u_surface);
    free(hp->depth);
    memset(hp, 0, sizeof *hp);
}

int heap_profile_extract(struct heap_profile *hp, const struct march_state *st, double fraction)
{
    memset(hp, 0, sizeof *hp);
    const struct grid *g = &st->g;
    int n = g->n[1], top = g->n[2] - 1;
    if (n < 2 || top < 1)
        return -1;
    hp->n = n;
    hp->y = malloc((size_t)n * sizeof(double));
    hp->u_surface = malloc((size_t)n * sizeof(double));
    hp->depth = malloc((size_t)n * sizeof(double));
    if (!hp->y || !hp->u_surface || !hp->depth) {
        heap_profile_free(hp);
        return -1;
    }
    for (int j = 0; j < n; j++) {
        hp->y[j] = (j + 0.5) * g->h[1];
        hp->u_surface[j] = zero_slope_end(column_u(st, j, top), column_u(st, j, top - 1));
        hp->depth[j] = column_depth(st, j, fraction * hp->u_surface[j]);
    }
    hp->u_surface_mid = zero_slope_end(hp->u_surface[n - 1], hp->u_surface[n - 2]);
    hp->depth_mid = zero_slope_end(hp->depth[n - 1], hp->depth[n - 2]);
    return 0;
}
