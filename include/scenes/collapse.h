/* The granular column collapse (scene "collapse", cases/collapse.ini): what
 * is measured on the state, for the scene, its tests and benchmarks.
 *
 * Coordinates: x from the symmetry axis (the low x face), z from the base;
 * a slab column is a 2D cross-section (x-z, the y cells averaged); a square
 * column (collapse.column = square) a quarter, y from the symmetry plane
 * (the low y face), its measures along the rows next to the planes.  T is the grains' volume
 * fraction (the two_phase module's tracer).  Every measure loops over the
 * grid's own cells and sums: a decomposed grid adds one reduction each. */
#ifndef MUFLOW_SCENES_COLLAPSE_H
#define MUFLOW_SCENES_COLLAPSE_H

#include "march/march.h"

enum collapse_column { COLLAPSE_SLAB, COLLAPSE_SQUARE };

struct collapse_sample {
    double t;
    double x_front;   /* largest x of the T = 1/2 contour (linear between centres);
                         square: along the row of cells next to y = 0 */
    double y_front;   /* square: the same along y, the row next to x = 0 (slab: 0) */
    double d_front;   /* square with nx = ny and square cells: the distance from the
                         axis of the T = 1/2 crossing along the diagonal cells i = j
                         (0 otherwise) */
    double h_axis;    /* height on the axis: the column heights of the first two
                         columns fitted by h = a + b x^2 (symmetric about x = 0);
                         square: a + b (x^2 + y^2) through the cell columns (0, 0)
                         and (1, 0) */
    double kinetic;   /* sum of rho u^2 / 2 over the faces, per unit width (square:
                         over the quarter's volume) */
    double volume;    /* sum of T dx dz, per unit width (square: T dx dy dz) */
    double t_min, t_max; /* the extremes of T over the cells */
};

/* T of the two_phase module (the field "tracer"), or NULL. */
const double *collapse_tracer(const struct march_state *st);

/* The measures of the current state into s (s->t = st->time); square: the
 * quarter of a square column (collapse.column = square), else a slab. */
void collapse_measure(const struct march_state *st, const double *T, int square,
                      struct collapse_sample *s);

/* Column heights h(x_i) = sum_k T dz at the cell centres x_i (n[0] values,
 * averaged over y). */
void collapse_heights(const struct grid *g, const double *T, double *h);

/* collapse_heights over the ranks of st (its global grid's n[0] values,
 * the same on every rank; collective). */
void collapse_heights_ranks(const struct march_state *st, const double *T, double *h);
/* Column heights along the row j of cells: h(x_i, y_j) = sum_k T dz. */
void collapse_row_heights(const struct grid *g, const double *T, int j, double *h);

/* The share of the cell [x0, x0 + hx] x [z0, z0 + hz] inside the rectangle
 * [0, r] x [0, hgt]: the initial column's T. */
double collapse_rectangle_fraction(double x0, double hx, double z0, double hz, double r,
                                   double hgt);

#endif
