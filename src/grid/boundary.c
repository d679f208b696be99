/* Ghost layers of the velocity and of cell-centred fields (see boundary.h). */
#include "grid/boundary.h"

const char *bc_kind_name(enum bc_kind kind)
{
    switch (kind) {
    case BC_PERIODIC: return "periodic";
    case BC_WALL: return "wall";
    case BC_SLIP: return "slip";
    case BC_SURFACE: return "surface";
    case BC_LID: return "lid";
    }
    return "?";
}

/* Sets f[ghost] = sign * f[source] + sign2 * f[source2] (or 0) on the whole
 * plane of direction d.  The offsets are hoisted out of the loops: on thin
 * grids the fills run once per operator application and dominated the
 * probed preconditioners' set-up when each point recomputed its index. */
static void ghost_plane2(const struct grid *g, int d, int ghost, int source, int source2, double *f,
                         double sign, double sign2, int zero_ghost)
{
    int a = (d + 1) % 3, b = (d + 2) % 3;
    ptrdiff_t sa = g->stride[a], sb = g->stride[b], sd = g->stride[d];
    ptrdiff_t from = (ptrdiff_t)(source - ghost) * sd, from2 = (ptrdiff_t)(source2 - ghost) * sd;
    int gi[3];
    gi[d] = ghost; gi[a] = -1; gi[b] = -1;
    ptrdiff_t corner = grid_idx(g, gi[0], gi[1], gi[2]);
    int na = g->n[a] + 2, nb = g->n[b] + 2;
    for (int ia = 0; ia < na; ia++) {
        double *row = f + corner + ia * sa;
        if (zero_ghost) {
            for (int ib = 0; ib < nb; ib++) row[ib * sb] = 0.0;
        } else {
            for (int ib = 0; ib < nb; ib++)
                row[ib * sb] = sign * row[ib * sb + from] + sign2 * row[ib * sb + from2];
        }
    }
}

/* f[ghost] = sign * f[source] on the plane of direction d (the whole extent of
 * the other two directions, so that edges and corners are filled once the
 * three directions have been done in turn). */
static void ghost_plane(const struct grid *g, int d, int ghost, int source, double *f, double sign,
                        int zero_ghost)
{
    ghost_plane2(g, d, ghost, source, source, f, sign, 0.0, zero_ghost);
}

/* f[ghost] += value on the plane of direction d. */
static void ghost_plane_add(const struct grid *g, int d, int ghost, double *f, double value)
{
    int a = (d + 1) % 3, b = (d + 2) % 3;
    ptrdiff_t sa = g->stride[a], sb = g->stride[b];
    int gi[3];
    gi[d] = ghost; gi[a] = -1; gi[b] = -1;
    ptrdiff_t corner = grid_idx(g, gi[0], gi[1], gi[2]);
    int na = g->n[a] + 2, nb = g->n[b] + 2;
    for (int ia = 0; ia < na; ia++)
        for (int ib = 0; ib < nb; ib++) f[corner + ia * sa + ib * sb] += value;
}

static void fill_velocity(const struct grid *g, const struct boundary *bc, double *vel[3],
                          int homogeneous)
{
    for (int d = 0; d < 3; d++) {
        int n = g->n[d];
        for (int c = 0; c < 3; c++) {
            double *f = vel[c];
            if (bc->face[d][0] == BC_PERIODIC) {
                /* faces and cells alike: slot -1 is n-1, slot n is 0 */
                ghost_plane(g, d, -1, n - 1, f, 1.0, 0);
                ghost_plane(g, d, n, 0, f, 1.0, 0);
                continue;
            }
            if (c == d) {
                /* no penetration: the boundary faces carry zero normal velocity;
                 * face -1 is never read by a stencil but is kept defined. */
                ghost_plane(g, d, 0, 0, f, 0.0, 1);
                ghost_plane(g, d, n, n, f, 0.0, 1);
                ghost_plane(g, d, -1, -1, f, 0.0, 1);
            } else {
                for (int side = 0; side < 2; side++) {
                    /* wall: the face value (ghost + interior)/2 is zero;
                     * slip and surface: zero normal gradient, so zero shear;
                     * lid: the face value is the lid's velocity. */
                    enum bc_kind kind = bc->face[d][side];
                    int walled = kind == BC_WALL || kind == BC_LID;
                    double sign = walled ? -1.0 : 1.0;
                    int ghost = side == 0 ? -1 : n, inner = side == 0 ? 0 : n - 1;
                    ghost_plane(g, d, ghost, inner, f, sign, 0);
                    if (kind == BC_LID && c == bc->lid_direction && !homogeneous)
                        ghost_plane_add(g, d, ghost, f, 2.0 * bc->lid_velocity);
                }
            }
        }
    }
}

void bc_fill_velocity(const struct grid *g, const struct boundary *bc, double *vel[3])
{
    fill_velocity(g, bc, vel, 0);
}

void bc_fill_velocity_homogeneous(const struct grid *g, const struct boundary *bc, double *vel[3])
{
    fill_velocity(g, bc, vel, 1);
}

void bc_fill_scalar(const struct grid *g, const struct boundary *bc, double *f)
{
    for (int d = 0; d < 3; d++) {
        int n = g->n[d];
        if (bc->face[d][0] == BC_PERIODIC) {
            ghost_plane(g, d, -1, n - 1, f, 1.0, 0);
            ghost_plane(g, d, n, 0, f, 1.0, 0);
        } else {
            ghost_plane(g, d, -1, 0, f, 1.0, 0);
            ghost_plane(g, d, n, n - 1, f, 1.0, 0);
        }
    }
}

void bc_fill_scalar_linear(const struct grid *g, const struct boundary *bc, double *f)
{
    for (int d = 0; d < 3; d++) {
        int n = g->n[d];
        if (bc->face[d][0] == BC_PERIODIC) {
            ghost_plane(g, d, -1, n - 1, f, 1.0, 0);
            ghost_plane(g, d, n, 0, f, 1.0, 0);
        } else if (n == 1) {
            ghost_plane(g, d, -1, 0, f, 1.0, 0);
            ghost_plane(g, d, n, 0, f, 1.0, 0);
        } else {
            ghost_plane2(g, d, -1, 0, 1, f, 2.0, -1.0, 0);
            ghost_plane2(g, d, n, n - 1, n - 2, f, 2.0, -1.0, 0);
        }
    }
}

void bc_unknown_boxes(const struct grid *g, const struct boundary *bc, struct box act[3])
{
    for (int c = 0; c < 3; c++)
        for (int d = 0; d < 3; d++) {
            act[c].lo[d] = (d == c && bc->face[d][0] != BC_PERIODIC) ? 1 : 0;
            act[c].hi[d] = g->n[d];
        }
}
