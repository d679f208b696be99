/* Solid shapes given in a case file, as a signed distance.
 *
 * A shape lives in the plane of two grid directions (plane_a, plane_b: x and
 * z for the 2D scenes, y and z for a duct's cross-section) and is extruded
 * along the third.  Shapes: "circle A B R" (centre, radius) and
 * "rectangle A0 B0 A1 B1" (two opposite corners) and "slope AC BR THETA R"
 * (the ground below an incline bent to a level floor, below), in the plane's
 * coordinates, several joined by ';' as a union.  shape_distance is the
 * signed distance to the union's surface, positive in the fluid: outside
 * every shape, or inside one when inverted (a duct's wall is the outside of
 * a circle). */
#ifndef MUFLOW_GRID_SHAPES_H
#define MUFLOW_GRID_SHAPES_H

#include <stddef.h>

#define SHAPES_MAX 16

enum shape_kind { SHAPE_CIRCLE = 0, SHAPE_RECTANGLE, SHAPE_SLOPE };

/* slope AC BR THETA R: the ground below a bed that descends at THETA
 * (radians, towards +a) along a straight incline, bends through a circular
 * arc of radius R tangent to it and to a level floor b = BR, and meets the
 * floor at a = AC; unbounded below and along a. */
struct shape {
    enum shape_kind kind;
    double v[4]; /* circle: a, b, r; rectangle: a0, b0, a1, b1 (a0 < a1, b0 < b1);
                    slope: ac, br, theta, r */
};

struct shape_set {
    int n;
    struct shape s[SHAPES_MAX];
    int plane_a, plane_b; /* the grid directions of the shapes' two coordinates */
    int invert;           /* 1: the fluid is inside the union */
};

/* Parses text ("circle 0.2 0.2 0.05; rectangle 0 0 1 0.1") into set->s and
 * set->n (plane and invert untouched).  Empty text (or only blanks) is no
 * shape.  Returns 0, or -1 with one line in msg saying what is wrong with
 * which shape. */
int shapes_parse(struct shape_set *set, const char *text, char *msg, size_t msglen);

/* The plane of the shapes (0: xz, 1: xy, 2: yz, the order of the case's
 * obstacle.plane choices) and whether the fluid is inside them. */
void shapes_set_plane(struct shape_set *set, int plane, int invert);

/* Index of the first shape with no point inside the box [0, len] of its
 * plane (touching its edge counts as outside), or -1 when every shape
 * reaches into the box. */
int shapes_outside_box(const struct shape_set *set, const double len[3]);

/* Whether the fluid of a grid of n cells over the box len joins the box's
 * low and high faces along direction axis: 4-connected cells of the plane
 * whose centres lie in the fluid (distance > 0); along the extrusion, any
 * fluid cell joins them.  Returns 1 (joined), 0 (the shapes close the
 * passage on this grid), -1 (out of memory).  Works on the whole box the
 * case describes, before any grid or decomposition exists. */
int shapes_connect(const struct shape_set *set, const int n[3], const double len[3], int axis);

/* The fluid regions a pressure sees on a grid of n cells over the box len:
 * the plane's cells joined through the faces whose centre lies in the fluid
 * (those the body leaves open), across the periodic directions
 * (periodic[d]) too; a cell is part of one when its centre or a face it
 * shares with another cell lies in the fluid.  fixed[d][side] flags the box's faces where the
 * pressure is fixed (a surface or an open face).  Sets *regions (how many)
 * and *floating (how many reach no fixed face).  Returns 0, or -1 (out of
 * memory).  Works on the box the case describes, before any grid exists. */
int shapes_regions(const struct shape_set *set, const int n[3], const double len[3],
                   const int periodic[3], const int fixed[3][2], int *regions, int *floating);

/* The bed's height b at a of a SHAPE_SLOPE. */
double shape_slope_bed(const struct shape *sh, double a);

/* Signed distance from point x (grid coordinates x, y, z) to the surface of
 * the union, positive in the fluid. */
double shape_distance(const struct shape_set *set, const double x[3]);

/* The outward unit normal of the solid at a point near the surface (the
 * gradient of the distance, pointing into the fluid), in grid coordinates. */
void shape_normal(const struct shape_set *set, const double x[3], double n[3]);

#endif
