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
    case BC_OPEN: return "open";
    case BC_INFLOW: return "inflow";
    }
    return "?";
}

/* The plane of direction d as rows: a the direction across the rows, b
 * the one along them, the smaller stride, so that a row runs along memory.
 * The plane normal to y of a 2D x-z grid is the whole grid, and with b = x
 * every point of its rows was a cache line and a page of its own: the
 * fills were 5 % of the column collapse at 102.4 cells per H0.  A compact
 * direction (one slot) goes across. */
static void plane_axes(const struct grid *g, int d, int *a, int *b)
{
    *a = (d + 1) % 3;
    *b = (d + 2) % 3;
    if (grid_compact(g, *b) || (g->stride[*b] > g->stride[*a] && !grid_compact(g, *a))) {
        int t = *a;
        *a = *b;
        *b = t;
    }
}

/* Sets f[ghost] = sign * f[source] + sign2 * f[source2] (or 0) on the whole
 * plane of direction d.  The offsets are hoisted out of the loops: on thin
 * grids the fills run once per operator application and dominated the
 * probed preconditioners' set-up when each point recomputed its index. */
static void ghost_plane2(const struct grid *g, int d, int ghost, int source, int source2, double *f,
                         double sign, double sign2, int zero_ghost)
{
    int a, b;
    plane_axes(g, d, &a, &b);
    ptrdiff_t sa = g->stride[a], sb = g->stride[b], sd = g->stride[d];
    ptrdiff_t from = (ptrdiff_t)(source - ghost) * sd, from2 = (ptrdiff_t)(source2 - ghost) * sd;
    int gi[3];
    gi[d] = ghost; gi[a] = -1; gi[b] = -1;
    ptrdiff_t corner = grid_idx(g, gi[0], gi[1], gi[2]);
    int na = g->ext[a], nb = g->ext[b];
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
    int a, b;
    plane_axes(g, d, &a, &b);
    ptrdiff_t sa = g->stride[a], sb = g->stride[b];
    int gi[3];
    gi[d] = ghost; gi[a] = -1; gi[b] = -1;
    ptrdiff_t corner = grid_idx(g, gi[0], gi[1], gi[2]);
    int na = g->ext[a], nb = g->ext[b];
    for (int ia = 0; ia < na; ia++)
        for (int ib = 0; ib < nb; ib++) f[corner + ia * sa + ib * sb] += value;
}

double bc_inflow_value(const struct grid *g, const struct boundary *bc, int d, int i, int j, int k)
{
    /* a rank's block: its indices from the whole grid's origin (decomp.h) */
    const int *lo = bc->dc ? bc->dc->lo : NULL;
    const int idx[3] = {i + (lo ? lo[0] : 0), j + (lo ? lo[1] : 0), k + (lo ? lo[2] : 0)};
    if (bc->inflow_shape) {
        /* the face's centre in the whole domain (idx is global) */
        double x[3];
        for (int a = 0; a < 3; a++)
            x[a] = (idx[a] + (a == d ? 0.0 : 0.5)) * g->h[a];
        return bc->inflow_shape(bc->inflow_ctx, d, x);
    }
    double v = bc->inflow_velocity;
    if (bc->inflow_profile != INFLOW_PARABOLIC)
        return v;
    for (int a = 0; a < 3; a++) {
        if (a == d || bc->face[a][0] == BC_PERIODIC)
            continue;
        /* the face's centre across a: s = (idx + 1/2) h, in [0, L] */
        double len = bc->dc ? g->h[a] * bc->dc->n_global[a] : g->len[a],
               s = (idx[a] + 0.5) * g->h[a];
        if (s < 0.0)
            s = 0.0;
        if (s > len)
            s = len;
        v *= 4.0 * s * (len - s) / (len * len);
    }
    return v;
}

/* The inflow's normal velocity on the boundary face of direction d, side
 * (0 low, 1 high), over the whole plane (ghost rows clipped to the edges'
 * zero of a parabola); positive into the domain. */
static void inflow_plane(const struct grid *g, const struct boundary *bc, int d, int side, double *f)
{
    int a = (d + 1) % 3, b = (d + 2) % 3;
    double sign = side == 0 ? 1.0 : -1.0;
    int idx[3];
    idx[d] = side == 0 ? 0 : g->n[d];
    for (idx[a] = grid_slot_lo(g, a); idx[a] <= grid_slot_hi(g, a); idx[a]++)
        for (idx[b] = grid_slot_lo(g, b); idx[b] <= grid_slot_hi(g, b); idx[b]++)
            f[grid_idx(g, idx[0], idx[1], idx[2])] =
                sign * bc_inflow_value(g, bc, d, idx[0], idx[1], idx[2]);
}

/* What a velocity fill is of: the state, an increment, or an increment
 * whose open faces' normal components are given (kept as they are). */
enum fill_mode { FILL_STATE, FILL_INCREMENT, FILL_INCREMENT_OPEN_GIVEN };

/* The ghosts of the components of comps (bits) across the directions of
 * dirs (bits). */
static void fill_velocity(const struct grid *g, const struct boundary *bc, double *vel[3],
                          enum fill_mode mode, int comps, int dirs)
{
    for (int d = 0; d < 3; d++) {
        if (!(dirs >> d & 1) || grid_compact(g, d)) /* compact: its ghosts are the node */
            continue;
        int n = g->n[d];
        for (int c = 0; c < 3; c++) {
            if (!(comps >> c & 1))
                continue;
            double *f = vel[c];
            if (bc_split(bc, d)) {
                decomp_exchange(bc->dc, g, f, d);
                if (bc->face[d][0] == BC_PERIODIC)
                    continue;
            } else if (bc->face[d][0] == BC_PERIODIC) {
                /* faces and cells alike: slot -1 is n-1, slot n is 0 */
                ghost_plane(g, d, -1, n - 1, f, 1.0, 0);
                ghost_plane(g, d, n, 0, f, 1.0, 0);
                continue;
            }
            if (c == d) {
                /* no penetration: the boundary faces carry zero normal velocity;
                 * face -1 is never read by a stencil but is kept defined.  An
                 * open face's velocity is state (the projection's): kept; its
                 * increment is the inner face's (zero normal gradient), so
                 * that the implicit step moves the face with the flow it
                 * solves for (stage_projection.c); an inflow face carries the
                 * profile. */
                if (!bc_border(bc, d, 0))
                    ghost_plane(g, d, -1, -1, f, 0.0, 1);
                for (int side = 0; side < 2; side++) {
                    enum bc_kind kind = bc->face[d][side];
                    if (bc_border(bc, d, side))
                        continue;
                    int face = side == 0 ? 0 : n;
                    if (kind == BC_OPEN && mode != FILL_INCREMENT)
                        continue;
                    if (kind == BC_OPEN && (n > 1 || bc_split(bc, d))) {
                        ghost_plane(g, d, face, side == 0 ? 1 : n - 1, f, 1.0, 0);
                        continue;
                    }
                    ghost_plane(g, d, face, face, f, 0.0, 1);
                    if (kind == BC_INFLOW && mode == FILL_STATE)
                        inflow_plane(g, bc, d, side, f);
                }
            } else {
                for (int side = 0; side < 2; side++) {
                    /* wall, inflow: the face value (ghost + interior)/2 is zero;
                     * slip, surface and open: zero normal gradient, so zero shear;
                     * lid: the face value is the lid's velocity. */
                    enum bc_kind kind = bc->face[d][side];
                    if (bc_border(bc, d, side))
                        continue;
                    int walled = kind == BC_WALL || kind == BC_LID || kind == BC_INFLOW;
                    double sign = walled ? -1.0 : 1.0;
                    int ghost = side == 0 ? -1 : n, inner = side == 0 ? 0 : n - 1;
                    ghost_plane(g, d, ghost, inner, f, sign, 0);
                    if (kind == BC_LID && c == bc->lid_direction && mode == FILL_STATE)
                        ghost_plane_add(g, d, ghost, f, 2.0 * bc->lid_velocity);
                }
            }
        }
    }
}

void bc_fill_velocity(const struct grid *g, const struct boundary *bc, double *vel[3])
{
    fill_velocity(g, bc, vel, FILL_STATE, 7, 7);
}

void bc_fill_velocity_homogeneous(const struct grid *g, const struct boundary *bc, double *vel[3])
{
    fill_velocity(g, bc, vel, FILL_INCREMENT, 7, 7);
}

void bc_fill_increment_component(const struct grid *g, const struct boundary *bc, double *vel[3],
                                 int c)
{
    fill_velocity(g, bc, vel, FILL_INCREMENT, 1 << c, 7 & ~(1 << c));
}

void bc_fill_velocity_open_given(const struct grid *g, const struct boundary *bc, double *vel[3])
{
    fill_velocity(g, bc, vel, FILL_INCREMENT_OPEN_GIVEN, 7, 7);
}

/* Cell ghosts: periodic images, else the interior value mirrored with the
 * sign open_sign on open faces (p = 0 on the face) and +1 elsewhere. */
static void fill_cells(const struct grid *g, const struct boundary *bc, double *f,
                       double open_sign)
{
    for (int d = 0; d < 3; d++) {
        int n = g->n[d];
        if (grid_compact(g, d)) /* its ghosts are the node */
            continue;
        if (bc_split(bc, d))
            decomp_exchange(bc->dc, g, f, d);
        if (bc_split(bc, d) && bc->face[d][0] == BC_PERIODIC)
            continue;
        if (!bc_split(bc, d) && bc->face[d][0] == BC_PERIODIC) {
            ghost_plane(g, d, -1, n - 1, f, 1.0, 0);
            ghost_plane(g, d, n, 0, f, 1.0, 0);
            continue;
        }
        if (!bc_border(bc, d, 0))
            ghost_plane(g, d, -1, 0, f, bc->face[d][0] == BC_OPEN ? open_sign : 1.0, 0);
        if (!bc_border(bc, d, 1))
            ghost_plane(g, d, n, n - 1, f, bc->face[d][1] == BC_OPEN ? open_sign : 1.0, 0);
    }
}

void bc_fill_scalar(const struct grid *g, const struct boundary *bc, double *f)
{
    fill_cells(g, bc, f, 1.0);
}

void bc_fill_pressure(const struct grid *g, const struct boundary *bc, double *f)
{
    fill_cells(g, bc, f, -1.0);
}

int bc_has_open(const struct boundary *bc)
{
    for (int d = 0; d < 3; d++)
        for (int s = 0; s < 2; s++)
            if (bc->face[d][s] == BC_OPEN)
                return 1;
    return 0;
}

int bc_kind_passes_flow(enum bc_kind k) { return k == BC_OPEN || k == BC_INFLOW; }

int bc_passes_flow(const struct boundary *bc)
{
    for (int d = 0; d < 3; d++)
        for (int s = 0; s < 2; s++)
            if (bc_kind_passes_flow(bc->face[d][s]))
                return 1;
    return 0;
}

void bc_periodic_flags(const struct boundary *bc, int periodic[3])
{
    for (int d = 0; d < 3; d++)
        periodic[d] = bc->face[d][0] == BC_PERIODIC;
}

int bc_through_flow(const struct boundary *bc, int d)
{
    const enum bc_kind *k = bc->face[d];
    return k[0] == BC_PERIODIC || (k[0] == BC_OPEN && k[1] == BC_OPEN);
}

void bc_fill_scalar_linear(const struct grid *g, const struct boundary *bc, double *f)
{
    for (int d = 0; d < 3; d++) {
        int n = g->n[d];
        if (grid_compact(g, d)) /* its ghosts are the node */
            continue;
        if (bc_split(bc, d))
            decomp_exchange(bc->dc, g, f, d);
        if (bc_split(bc, d) && bc->face[d][0] == BC_PERIODIC)
            continue;
        if (!bc_split(bc, d) && bc->face[d][0] == BC_PERIODIC) {
            ghost_plane(g, d, -1, n - 1, f, 1.0, 0);
            ghost_plane(g, d, n, 0, f, 1.0, 0);
        } else if (n == 1) {
            if (!bc_border(bc, d, 0))
                ghost_plane(g, d, -1, 0, f, 1.0, 0);
            if (!bc_border(bc, d, 1))
                ghost_plane(g, d, n, 0, f, 1.0, 0);
        } else {
            if (!bc_border(bc, d, 0))
                ghost_plane2(g, d, -1, 0, 1, f, 2.0, -1.0, 0);
            if (!bc_border(bc, d, 1))
                ghost_plane2(g, d, n, n - 1, n - 2, f, 2.0, -1.0, 0);
        }
    }
}

void bc_unknown_boxes(const struct grid *g, const struct boundary *bc, struct box act[3])
{
    for (int c = 0; c < 3; c++)
        for (int d = 0; d < 3; d++) {
            act[c].lo[d] = (d == c && bc->face[d][0] != BC_PERIODIC && !bc_border(bc, d, 0)) ? 1
                                                                                            : 0;
            act[c].hi[d] = g->n[d];
        }
}
