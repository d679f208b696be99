/* Grid geometry and field arrays (layout described in include/grid/grid.h). */
#include "grid/grid.h"

#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define FIELD_ALIGN 64

int grid_init(struct grid *g, const int n[3], const double len[3])
{
    if (!g || !n || !len)
        return -1;
    for (int d = 0; d < 3; d++) {
        /* !(len > 0) also rejects NaN */
        if (n[d] < 1 || n[d] > INT_MAX - 2 || !(len[d] > 0.0))
            return -1;
    }
    size_t size = 1;
    for (int d = 0; d < 3; d++) {
        size_t e = (size_t)n[d] + 2;
        if (size > SIZE_MAX / sizeof(double) / e)
            return -1; /* the field would not fit in memory */
        size *= e;
    }
    for (int d = 0; d < 3; d++) {
        g->n[d] = n[d];
        g->len[d] = len[d];
        g->h[d] = len[d] / n[d];
        g->ext[d] = n[d] + 2;
    }
    g->stride[2] = 1;
    g->stride[1] = g->ext[2];
    g->stride[0] = (ptrdiff_t)g->ext[1] * g->ext[2];
    g->size = size;
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
