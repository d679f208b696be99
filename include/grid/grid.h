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
 * Such a direction (x or y, periodic, one cell) may be compact
 * (grid_init_compact): ext = 1 and stride 0, one slot for indices -1, 0 and 1,
 * so that its ghosts are the node itself, exactly its periodic images, and a
 * field holds one copy of the plane instead of three.  Loops over the slots
 * of a direction run grid_slot_lo .. grid_slot_hi (one pass when compact);
 * the ghost fills leave a compact direction alone.  z, the contiguous
 * direction, is never compact (kernels step along it with p +- 1).
 * Kernels work on boxes of local indices and never assume they own the global
 * domain, so a later domain decomposition adds halo exchanges, not a rewrite. */
#ifndef MUFLOW_GRID_H
#define MUFLOW_GRID_H

#include <stddef.h>

/* The spacing of a stretched direction, ghosts included (index i + 1 holds
 * index i): faces -1 .. n + 1, cells -1 .. n.  A ghost cell mirrors the
 * width of the cell across its face (the wall sits half-way between the two
 * centres, as the ghost-mirror conditions assume), or of its periodic image. */
struct grid_axis {
    int n;
    double *xf;  /* face coordinates, faces -1 .. n + 1 */
    double *xc;  /* cell centres, cells -1 .. n */
    double *hc;  /* cell widths xf[i + 1] - xf[i], cells -1 .. n */
    double *hf;  /* centre distances xc[i] - xc[i - 1], faces -1 .. n + 1 */
};

struct grid {
    int n[3];            /* cells per direction */
    double len[3];       /* domain lengths */
    double h[3];         /* cell sizes len/n; NaN for a stretched direction */
    /* NULL: direction d is uniform (h[d] everywhere); else its spacing,
     * owned by whoever set it (grid_axis_build_bands) */
    const struct grid_axis *axis[3];
    int ext[3];          /* allocated extent per direction, n + 2 (1 compact) */
    ptrdiff_t stride[3]; /* array strides: stride[2] = 1, 0 along a compact direction */
    size_t size;         /* doubles per field array */
    /* the slots of the layout with every ghost, (n + 2) per direction: the
     * work measure of the thresholds (threads, cycles) whichever the layout,
     * so that a compact grid makes the same choices as the full one */
    size_t padded;
};

/* Linear index of (i, j, k), each in -1 .. n (any of them, the same slot,
 * along a compact direction). */
static inline ptrdiff_t grid_idx(const struct grid *g, int i, int j, int k)
{
    return (ptrdiff_t)(i + 1) * g->stride[0] + (ptrdiff_t)(j + 1) * g->stride[1] + (k + 1);
}

/* 1 when direction d is compact: one slot, its ghosts the node itself. */
static inline int grid_compact(const struct grid *g, int d)
{
    return g->ext[d] == 1;
}

/* The first and last index of direction d with a slot of its own: -1 and
 * n, or 0 and 0 when compact (a loop over the slots visits each once). */
static inline int grid_slot_lo(const struct grid *g, int d)
{
    return g->ext[d] == 1 ? 0 : -1;
}
static inline int grid_slot_hi(const struct grid *g, int d)
{
    return g->ext[d] == 1 ? 0 : g->n[d];
}

/* A box of local indices [lo, hi) per direction. */
struct box {
    int lo[3], hi[3];
};

/* 1 when slot (i, j, k) lies in box b (lo inclusive, hi exclusive). */
static inline int box_holds(const struct box *b, int i, int j, int k)
{
    return i >= b->lo[0] && i < b->hi[0] && j >= b->lo[1] && j < b->hi[1] && k >= b->lo[2] &&
           k < b->hi[2];
}

/* Width of cell i (-1 .. n) of direction d. */
static inline double grid_hc(const struct grid *g, int d, int i)
{
    return g->axis[d] ? g->axis[d]->hc[i + 1] : g->h[d];
}

/* Distance between the centres of cells i - 1 and i (face i, -1 .. n + 1). */
static inline double grid_hf(const struct grid *g, int d, int i)
{
    return g->axis[d] ? g->axis[d]->hf[i + 1] : g->h[d];
}

/* Coordinate of the centre of cell i (-1 .. n) of direction d. */
static inline double grid_xc(const struct grid *g, int d, int i)
{
    return g->axis[d] ? g->axis[d]->xc[i + 1] : (i + 0.5) * g->h[d];
}

/* Coordinate of face i (-1 .. n + 1) of direction d. */
static inline double grid_xf(const struct grid *g, int d, int i)
{
    return g->axis[d] ? g->axis[d]->xf[i + 1] : i * g->h[d];
}

/* The width along d of the control volume of component c's node of index
 * i along d: the centres' distance along c (the node is a face there), the
 * cell's width across it. */
static inline double grid_node_width(const struct grid *g, int c, int d, int i)
{
    return d == c ? grid_hf(g, d, i) : grid_hc(g, d, i);
}

/* The indices (i, j, k), each -1 .. n, of slot p (the inverse of grid_idx;
 * 0 along a compact direction). */
static inline void grid_slot_index(const struct grid *g, ptrdiff_t p, int idx[3])
{
    ptrdiff_t s2 = g->ext[2];
    idx[0] = g->stride[0] ? (int)(p / g->stride[0]) - 1 : 0;
    if (g->stride[0])
        p %= g->stride[0];
    idx[1] = g->stride[1] ? (int)(p / g->stride[1]) - 1 : 0;
    idx[2] = (int)(p % s2) - 1;
}

/* 1 if any direction is stretched. */
static inline int grid_stretched(const struct grid *g)
{
    return g->axis[0] || g->axis[1] || g->axis[2];
}

/* The cell of direction d whose faces bracket x (clamped to -1 .. n). */
int grid_locate(const struct grid *g, int d, double x);

/* The node of direction d below x and the share w of the way to the next,
 * the nodes at the faces (at_faces) or at the cell centres; not clamped. */
void grid_bracket(const struct grid *g, int d, int at_faces, double x, int *i0, double *w);

/* The smallest cell width of direction d. */
double grid_min_width(const struct grid *g, int d);

/* Fills a grid from cell counts and lengths; returns 0, or -1 for a count < 1
 * or a length <= 0. */
int grid_init(struct grid *g, const int n[3], const double len[3]);

/* grid_init with the directions d < 2 of one cell and periodic[d] set
 * compact (see the top of this file); periodic may be NULL. */
int grid_init_compact(struct grid *g, const int n[3], const double len[3], const int periodic[3]);

/* grid_init for a grid derived from `like` (a coarser level, say): a
 * direction compact in like stays compact while it keeps one cell. */
int grid_init_like(struct grid *g, const int n[3], const double len[3], const struct grid *like);

/* The faces of a direction refined in bands (at most GRID_BANDS_MAX, in
 * increasing order, not overlapping): cells of about h in each band
 * [lo, hi], growing by the ratio `growth` from one cell to the next outside
 * it up to h_far, then h_far to the ends 0 and len; between two bands the
 * cells grow from both, the smaller next cell first (the cells of each
 * stretch scaled to end exactly on the bands and the box).  On success ax
 * holds n cells (ax->n) and 0 is returned; -1 with msg for impossible
 * parameters or no memory.  periodic: the ghosts take the widths of their
 * periodic images. */
#define GRID_BANDS_MAX 8
struct grid_band {
    double lo, hi, h;
};
int grid_axis_build_bands(struct grid_axis *ax, double len, double h_far,
                          const struct grid_band *band, int nb, double growth, int periodic,
                          char *msg, size_t msglen);

/* "lo hi h" triples separated by ';' into b (at most max): their count, 0
 * for an empty text, -1 when malformed or more than max. */
int grid_bands_parse(const char *text, struct grid_band *b, int max);
void grid_axis_free(struct grid_axis *ax);

/* Makes direction d of g stretched by ax (ax->n cells over g->len[d]);
 * the strides and sizes follow the new count (the other directions keep
 * their layout).  Returns 0, or -1 when the
 * field would not fit in memory. */
int grid_set_axis(struct grid *g, int d, const struct grid_axis *ax);

/* Zero-initialised field array of g->size doubles (64-byte aligned), or NULL. */
double *field_alloc(const struct grid *g);
void field_free(double *f);

/* Field f of g copied into full, the same field in the layout with every
 * ghost (g->padded doubles, (n + 2) slots per direction), a compact
 * direction's ghosts its node; and back (each slot of f from its node). */
void field_to_full(const struct grid *g, const double *f, double *full);
void field_from_full(const struct grid *g, const double *full, double *f);

/* Number of interior cells n[0]*n[1]*n[2]. */
size_t grid_cells(const struct grid *g);

#endif
