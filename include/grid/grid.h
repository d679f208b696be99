/* Staggered (MAC) grid and the layout of every field array.
 *
 * A field is one contiguous array of ext[0]*ext[1]*ext[2] doubles with
 * ext[d] = n[d] + 2: one ghost layer on each side, z fastest.  Index i of
 * direction d runs from -1 to n[d]:
 *   - cell-centred quantities (pressure, viscosity): cells 0..n-1, ghosts -1, n;
 *   - the velocity component normal to d lives on the faces of d: face i is
 *     the low face of cell i, faces 0..n; face n sits in the high ghost slot and
 *     face -1 is the periodic image of face n-1.
 * A direction of one cell collapses: with periodic faces its derivatives vanish,
 * so 1D-like profile scenes run through the same 3D code on a thin grid.
 * Kernels work on boxes of local indices and never assume they own the global
 * domain, so a later domain decomposition adds halo exchanges, not a rewrite. */
#ifndef MUFLOW_GRID_H
#define MUFLOW_GRID_H

#include <stddef.h>

struct grid {
    int n[3];            /* cells per direction */
    double len[3];       /* domain lengths */
    double h[3];         /* cell sizes len/n */
    int ext[3];          /* allocated extent per direction, n + 2 */
    ptrdiff_t stride[3]; /* array strides: stride[2] = 1 */
    size_t size;         /* doubles per field array */
};

/* Linear index of (i, j, k), each in -1 .. n. */
static inline ptrdiff_t grid_idx(const struct grid *g, int i, int j, int k)
{
    return (ptrdiff_t)(i + 1) * g->stride[0] + (ptrdiff_t)(j + 1) * g->stride[1] + (k + 1);
}

/* A box of local indices [lo, hi) per direction. */
struct box {
    int lo[3], hi[3];
};

/* Fills a grid from cell counts and lengths; returns 0, or -1 for a count < 1
 * or a length <= 0. */
int grid_init(struct grid *g, const int n[3], const double len[3]);

/* Zero-initialised field array of g->size doubles (64-byte aligned), or NULL. */
double *field_alloc(const struct grid *g);
void field_free(double *f);

/* Number of interior cells n[0]*n[1]*n[2]. */
size_t grid_cells(const struct grid *g);

#endif
