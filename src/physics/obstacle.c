/* Solid obstacles: held nodes, cut links, closed faces (obstacle.h). */
#include "physics/obstacle.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "kernels/embedded.h"
#include "physics/forces_file.h"
#include "march/step.h"
#include "solvers/pressure.h"

/* A link cut closer than this share of h to its fluid node is taken as cut
 * there: the correction (1 - theta) / theta grows without bound as the
 * surface reaches the node, and beyond 1e3 times the link's own coefficient
 * it only worsens the operator's conditioning (the node is 0 to 1e-3 of its
 * neighbours' velocity either way). */
#define THETA_MIN 1e-3

struct obstacle {
    struct shape_set set;
    struct embedded e;
    /* where this block sits in the whole grid (grid/decomp.h): its cell 0
     * is global cell lo, of n_global; border[d][s] a rank border; gact the
     * whole grid's unknown boxes.  One process: lo 0, the grid's own. */
    int lo[3], n_global[3], border[3][2], periodic[3], split;
    struct box gact[3];
    long links_max;
    double *share[3]; /* the faces' open shares (e.share) */
    double *cut;      /* the cut cells (e.cut) */
};

/* Sub-segments of a face searched for the surface's crossings (each holds
 * at most one for a body many cells across). */
#define FACE_PARTS 16

/* The point at share t of the segment from x0 to x1. */
static void segment_point(const double x0[3], const double x1[3], double t, double y[3])
{
    for (int d = 0; d < 3; d++)
        y[d] = x0[d] + t * (x1[d] - x0[d]);
}

/* Where the surface crosses the segment from x0 to x1 between the shares lo
 * and hi (one crossing there): bisection on which side of the surface a
 * point lies, the side of lo kept; the midpoint of the last bracket. */
static double crossing(const struct shape_set *set, const double x0[3], const double x1[3],
                       double lo, double hi, int iterations)
{
    double y[3];
    segment_point(x0, x1, lo, y);
    int open_lo = shape_distance(set, y) > 0.0;
    for (int it = 0; it < iterations; it++) {
        double t = 0.5 * (lo + hi);
        segment_point(x0, x1, t, y);
        if ((shape_distance(set, y) > 0.0) == open_lo)
            lo = t;
        else
            hi = t;
    }
    return 0.5 * (lo + hi);
}

/* The open share of the segment from x0 to x1 (the part with distance > 0). */
static double open_share(const struct shape_set *set, const double x0[3], const double x1[3])
{
    double open = 0.0, y0[3], y1[3];
    for (int q = 0; q < FACE_PARTS; q++) {
        double t0 = (double)q / FACE_PARTS, t1 = (double)(q + 1) / FACE_PARTS;
        segment_point(x0, x1, t0, y0);
        segment_point(x0, x1, t1, y1);
        int f0 = shape_distance(set, y0) > 0.0, f1 = shape_distance(set, y1) > 0.0;
        if (f0 == f1) {
            open += f0 ? t1 - t0 : 0.0;
            continue;
        }
        double tc = crossing(set, x0, x1, t0, t1, 40);
        open += f0 ? tc - t0 : t1 - tc;
    }
    return open;
}

/* The ends of cell idx of direction t, whose centre is at xt. */
static void cell_span(const struct grid *g, int t, int idx, double xt, double *lo, double *hi)
{
    if (g->axis[t]) {
        *lo = grid_xf(g, t, idx);
        *hi = grid_xf(g, t, idx + 1);
    } else {
        *lo = xt - 0.5 * g->h[t];
        *hi = xt + 0.5 * g->h[t];
    }
}

/* The open share of face (i, j, k) of component c: the length share of the
 * face's extent along the plane's other direction (the shapes are extruded,
 * so nothing varies along the third); a face normal to the extrusion takes
 * the mean of FACE_PARTS such lines.  A held face (its node in the body) is
 * closed. */
/* obstacle.boundary = cells: whether the cell whose centre is at x shifted
 * by off along c is solid (its centre in the body). */
static int cell_solid(const struct shape_set *set, const double x[3], int c, double off)
{
    double y[3] = {x[0], x[1], x[2]};
    y[c] += off;
    return shape_distance(set, y) <= 0.0;
}

/* obstacle.boundary = cells: a face is closed when a cell on either side is
 * solid, so that every cell is whole fluid or whole solid: the open shares
 * are 0 or 1 and a tracer's fluxes through the faces are the projection's. */
static int face_closed_at(const struct shape_set *set, const int at[3], const struct grid *g,
                          int c, int i, int j, int k)
{
    double x[3];
    const int t = at[c] + (c == 0 ? i : c == 1 ? j : k);
    obstacle_node_position_at(g, at, c, i, j, k, x);
    double lo = g->axis[c] ? grid_xc(g, c, t - 1) - x[c] : -0.5 * g->h[c];
    double hi = g->axis[c] ? grid_xc(g, c, t) - x[c] : 0.5 * g->h[c];
    return cell_solid(set, x, c, lo) || cell_solid(set, x, c, hi);
}

/* The same of the block's node (i, j, k). */
static int cells_face_closed(const struct obstacle *ob, const struct grid *g, int c, int i,
                             int j, int k)
{
    return face_closed_at(&ob->set, ob->lo, g, c, i, j, k);
}

static double face_share(const struct obstacle *ob, const struct grid *g, int c, int i, int j,
                         int k, int cells)
{
    const struct shape_set *set = &ob->set;
    double x[3];
    const int idx[3] = {ob->lo[0] + i, ob->lo[1] + j, ob->lo[2] + k};
    if (cells)
        return cells_face_closed(ob, g, c, i, j, k) ? 0.0 : 1.0;
    obstacle_node_position_at(g, ob->lo, c, i, j, k, x);
    if (shape_distance(set, x) <= 0.0)
        return 0.0;
    int a = set->plane_a, b = set->plane_b;
    if (c == a || c == b) {
        int t = c == a ? b : a;
        double x0[3] = {x[0], x[1], x[2]}, x1[3] = {x[0], x[1], x[2]};
        cell_span(g, t, idx[t], x[t], &x0[t], &x1[t]);
        return open_share(set, x0, x1);
    }
    double s = 0.0, b0, b1;
    cell_span(g, b, idx[b], x[b], &b0, &b1);
    for (int q = 0; q < FACE_PARTS; q++) {
        double x0[3] = {x[0], x[1], x[2]}, x1[3];
        if (g->axis[b])
            x0[b] = b0 + (q + 0.5) / FACE_PARTS * (b1 - b0);
        else
            x0[b] += ((q + 0.5) / FACE_PARTS - 0.5) * g->h[b];
        for (int d = 0; d < 3; d++)
            x1[d] = x0[d];
        cell_span(g, a, idx[a], x[a], &x0[a], &x1[a]);
        s += open_share(set, x0, x1);
    }
    return s / FACE_PARTS;
}

double obstacle_memory_bound(const struct muflow_case *cs, const struct grid *g)
{
    struct shape_set set;
    case_obstacle_shapes(cs, &set);
    double points = (double)g->size;
    /* the faces' open shares, the cut flags and the work field (build_shares);
     * each component's held slots and saved values (build_component) */
    double bytes = 5.0 * points * sizeof(double) + 3.0 * points * (sizeof(ptrdiff_t) + sizeof(double));
    /* the links: the distance changes sign at most twice per shape along a
     * line of the plane (none along the extrusion); the array grows by
     * doubling (twice the count, the old one beside the new as it moves) */
    double lines = 0.0;
    for (int c = 0; c < 3; c++)
        lines += points / g->ext[set.plane_a] + points / g->ext[set.plane_b];
    bytes += 3.0 * 2.0 * set.n * lines * sizeof(struct embedded_link);
    /* the cut cells' list and their faces' (cut_lists: three faces a cell
     * per component at most), the cells two a crossing at most */
    bytes += 10.0 * 2.0 * 2.0 * set.n * lines * sizeof(ptrdiff_t);
    /* march_density_changed: beta and the faces' mass, the cut coefficient
     * while it is set; the projection's multigrid and the hydrostatic split's */
    bytes += 9.0 * points * sizeof(double) + 2.0 * pressure_variable_memory_estimate(g);
    return bytes;
}

void obstacle_node_position_at(const struct grid *g, const int lo[3], int c, int i, int j, int k,
                               double x[3])
{
    int idx[3] = {i, j, k};
    for (int d = 0; d < 3; d++)
        x[d] = d == c ? grid_xf(g, d, lo[d] + idx[d]) : grid_xc(g, d, lo[d] + idx[d]);
}

void obstacle_node_position(const struct grid *g, int c, int i, int j, int k, double x[3])
{
    static const int zero[3] = {0, 0, 0};
    obstacle_node_position_at(g, zero, c, i, j, k, x);
}

/* The share theta of the segment from x0 (fluid) to x1 (solid) at which
 * the surface cuts it (exact to 1e-12 of h). */
static double cut_share(const struct shape_set *set, const double x0[3], const double x1[3])
{
    return crossing(set, x0, x1, 0.0, 1.0, 45);
}

static int add_link(struct obstacle *ob, const struct embedded_link *l)
{
    if (ob->e.nlinks == ob->links_max) {
        long m = ob->links_max ? 2 * ob->links_max : 1024;
        struct embedded_link *nl = realloc(ob->e.links, (size_t)m * sizeof *nl);
        if (!nl)
            return -1;
        ob->e.links = nl;
        ob->links_max = m;
    }
    ob->e.links[ob->e.nlinks++] = *l;
    return 0;
}

/* obstacle.boundary = cells: the links of the fluid node (i, j, k) of
 * component c to held nodes across its direction d != c end halfway, on the
 * solid cell's face (theta = 1/2, the box walls' rule); a held node along c
 * lies on that face itself (theta = 1: no correction). */
static int cells_links(struct obstacle *ob, const struct march_state *st, int c, int i, int j,
                       int k)
{
    const struct grid *g = &st->g;
    const int idx[3] = {i, j, k};
    for (int d = 0; d < 3; d++) {
        if (d == c || ob->n_global[d] < 2)
            continue;
        for (int side = -1; side <= 1; side += 2) {
            int nb[3] = {i, j, k};
            nb[d] += side;
            /* beyond the box: the boundary's (a rank border's ghost is a node) */
            if (ob->lo[d] + nb[d] < 0 || ob->lo[d] + nb[d] > ob->n_global[d] - 1)
                continue;
            if (!cells_face_closed(ob, g, c, nb[0], nb[1], nb[2]))
                continue;
            struct embedded_link l = {.p = grid_idx(g, i, j, k), .c = c};
            double hh = g->h[d] * g->h[d];
            if (g->axis[d])
                hh = fabs(grid_xc(g, d, nb[d]) - grid_xc(g, d, idx[d])) *
                     grid_node_width(g, c, d, idx[d]);
            l.w = 1.0 / hh; /* (1 - theta) / theta = 1 */
            l.coef = 3 + (3 - c - d);
            l.at = side > 0 ? l.p + g->stride[d] : l.p;
            if (add_link(ob, &l) != 0)
                return -1;
        }
    }
    return 0;
}

/* A block's ghost slots that image a node of the whole grid's unknowns
 * across a rank border (a periodic wrap's included), held when that node is:
 * appended to component c's held list after its own nh (the stencils read
 * the neighbour's held node as 0, as one process does; the forces sum the
 * block's own alone).  Returns the new count. */
static long ghost_held(struct obstacle *ob, const struct march_state *st, int c, int cells,
                       long nh)
{
    const struct grid *g = &st->g;
    const struct box *bx = &st->act[c];
    for (int i = -1; i <= g->n[0]; i++)
        for (int j = -1; j <= g->n[1]; j++)
            for (int k = -1; k <= g->n[2]; k++) {
                const int idx[3] = {i, j, k};
                int image = !box_holds(bx, i, j, k), G[3];
                for (int d = 0; d < 3 && image; d++) {
                    const int out = idx[d] < bx->lo[d] ? 0 : idx[d] >= bx->hi[d] ? 1 : -1;
                    if (out >= 0 && !ob->border[d][out])
                        image = 0; /* a domain's face: the condition's ghost */
                    G[d] = ob->lo[d] + idx[d];
                    if (ob->periodic[d])
                        G[d] = (G[d] + ob->n_global[d]) % ob->n_global[d];
                    image &= G[d] >= ob->gact[c].lo[d] && G[d] < ob->gact[c].hi[d];
                }
                if (!image)
                    continue;
                /* the owner's decision, at the node's own global position */
                double x[3];
                static const int zero[3] = {0, 0, 0};
                obstacle_node_position_at(g, zero, c, G[0], G[1], G[2], x);
                const int held = cells ? face_closed_at(&ob->set, zero, g, c, G[0], G[1], G[2])
                                       : shape_distance(&ob->set, x) <= 0.0;
                if (held)
                    ob->e.held[c][nh++] = grid_idx(g, i, j, k);
            }
    return nh;
}

/* Held nodes of component c (in the unknowns' box) and, for a sharp
 * boundary, the cut links of its fluid nodes. */
static int build_component(struct obstacle *ob, const struct march_state *st, int c, int sharp,
                           int cells)
{
    const struct grid *g = &st->g;
    const struct box *bx = &st->act[c];
    long nbox = (long)(bx->hi[0] - bx->lo[0]) * (bx->hi[1] - bx->lo[1]) * (bx->hi[2] - bx->lo[2]);
    if (st->ranks) /* the ghosts' held images too (ghost_held) */
        nbox = (long)g->size;
    ob->e.held[c] = malloc((size_t)(nbox > 0 ? nbox : 1) * sizeof(ptrdiff_t));
    if (!ob->e.held[c])
        return -1;
    long nh = 0;
    for (int i = bx->lo[0]; i < bx->hi[0]; i++)
        for (int j = bx->lo[1]; j < bx->hi[1]; j++)
            for (int k = bx->lo[2]; k < bx->hi[2]; k++) {
                double x[3];
                obstacle_node_position_at(g, ob->lo, c, i, j, k, x);
                ptrdiff_t p = grid_idx(g, i, j, k);
                if (cells ? cells_face_closed(ob, g, c, i, j, k)
                          : shape_distance(&ob->set, x) <= 0.0) {
                    ob->e.held[c][nh++] = p;
                    continue;
                }
                if (cells) {
                    if (cells_links(ob, st, c, i, j, k) != 0)
                        return -1;
                    continue;
                }
                if (!sharp)
                    continue;
                int idx[3] = {i, j, k};
                for (int d = 0; d < 3; d++) {
                    if (ob->n_global[d] < 2 && d != c)
                        continue; /* one cell across: no link along d */
                    for (int side = -1; side <= 1; side += 2) {
                        double y[3] = {x[0], x[1], x[2]};
                        if (g->axis[d])
                            y[d] = d == c ? grid_xf(g, d, idx[d] + side)
                                          : grid_xc(g, d, idx[d] + side);
                        else
                            y[d] += side * g->h[d];
                        /* a neighbour beyond the box is the boundary's (a
                         * rank border's ghost is the next block's node) */
                        int nidx = ob->lo[d] + idx[d] + side;
                        if (nidx < 0 || nidx > ob->n_global[d] - (d == c ? 0 : 1))
                            continue;
                        if (shape_distance(&ob->set, y) > 0.0)
                            continue;
                        double theta = fmax(cut_share(&ob->set, x, y), THETA_MIN);
                        struct embedded_link l = {.p = p, .c = c};
                        /* c = A / (the link's length x the node's control width) */
                        double hh = g->h[d] * g->h[d];
                        if (g->axis[d])
                            hh = fabs(y[d] - x[d]) * grid_node_width(g, c, d, idx[d]);
                        l.w = (1.0 - theta) / theta / hh;
                        if (d == c) { /* the normal stress of the cell above or below */
                            l.coef = c;
                            l.at = side > 0 ? p : p - g->stride[d];
                        } else {      /* the shear stress of the edge above or below */
                            l.coef = 3 + (3 - c - d);
                            l.at = side > 0 ? p + g->stride[d] : p;
                        }
                        if (add_link(ob, &l) != 0)
                            return -1;
                    }
                }
            }
    if (st->ranks)
        nh = ghost_held(ob, st, c, cells, nh);
    ob->e.nheld[c] = nh;
    ob->e.saved[c] = malloc((size_t)(nh > 0 ? nh : 1) * sizeof(double));
    return ob->e.saved[c] ? 0 : -1;
}

static void destroy(void *state)
{
    struct obstacle *ob = state;
    if (!ob)
        return;
    for (int c = 0; c < 3; c++) {
        free(ob->e.held[c]);
        free(ob->e.saved[c]);
    }
    free(ob->e.links);
    free(ob->e.cut_cells);
    for (int c = 0; c < 3; c++)
        free(ob->e.cut_faces[c]);
    for (int c = 0; c < 3; c++)
        field_free(ob->share[c]);
    field_free(ob->cut);
    field_free(ob->e.work);
    free(ob);
}

/* The interior cut cells and each component's faces next to one, ghost
 * images included (a face at a box end reads the ghost of the other end's
 * cell or its own mirror): the operator's grad-div of the cut cells visits
 * them alone (solvers/viscous_operator.c), the cells' stress kernels the
 * whole grid. */
static int cut_lists(struct obstacle *ob, const struct grid *g)
{
    long n = 0, ghosts = 0;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++)
                n += ob->cut[grid_idx(g, i, j, k)] != 0.0;
    /* a rank border's ghost cells (the next block's) give faces too */
    for (size_t p = 0; ob->split && p < g->size; p++)
        ghosts += ob->cut[p] != 0.0;
    ob->e.cut_cells = malloc((size_t)(n > 0 ? n : 1) * sizeof(ptrdiff_t));
    const long room = 3 * (n + ghosts) + 1;
    for (int c = 0; c < 3; c++)
        ob->e.cut_faces[c] = malloc((size_t)room * sizeof(ptrdiff_t));
    if (!ob->e.cut_cells || !ob->e.cut_faces[0] || !ob->e.cut_faces[1] || !ob->e.cut_faces[2])
        return -1;
    ob->e.ncut = 0;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++)
                if (ob->cut[grid_idx(g, i, j, k)] != 0.0)
                    ob->e.cut_cells[ob->e.ncut++] = grid_idx(g, i, j, k);
    for (int c = 0; c < 3; c++) {
        long m = 0;
        const int nc = g->n[c];
        for (int i = 0; i < g->n[0] + (c == 0); i++)
            for (int j = 0; j < g->n[1] + (c == 1); j++)
                for (int k = 0; k < g->n[2] + (c == 2); k++) {
                    int idx[3] = {i, j, k}, t = idx[c], near = 0;
                    /* the cells on the two sides: t - 1 and t, a box end's
                     * ghost standing for either end's cell; a rank
                     * border's ghost is the next block's cell, its own */
                    for (int side = -1; side <= 0 && !near; side++) {
                        int u = t + side;
                        const int border = (u < 0 && ob->border[c][0]) || (u >= nc && ob->border[c][1]);
                        int cand[2] = {border ? u : u < 0 ? nc - 1 : u >= nc ? 0 : u, u < 0 ? 0 : nc - 1};
                        for (int q = 0; q < (!border && (u < 0 || u >= nc) ? 2 : 1); q++) {
                            idx[c] = cand[q];
                            near |= ob->cut[grid_idx(g, idx[0], idx[1], idx[2])] != 0.0;
                        }
                    }
                    if (near) {
                        if (m == room) /* two a cut cell, one more at a box end */
                            return -1;
                        ob->e.cut_faces[c][m++] = grid_idx(g, i, j, k);
                    }
                }
        ob->e.ncut_faces[c] = m;
    }
    return 0;
}

/* The open shares of every face slot (ghosts too: a periodic direction's
 * image face takes its own position's share, the same by periodicity of the
 * grid only when the body does not cross the box's face). */
static int build_shares(struct obstacle *ob, const struct grid *g, int cells)
{
    for (int c = 0; c < 3; c++) {
        ob->share[c] = field_alloc(g);
        if (!ob->share[c])
            return -1;
        for (int i = grid_slot_lo(g, 0); i <= grid_slot_hi(g, 0); i++)
            for (int j = grid_slot_lo(g, 1); j <= grid_slot_hi(g, 1); j++)
                for (int k = -1; k <= g->n[2]; k++)
                    ob->share[c][grid_idx(g, i, j, k)] =
                        face_share(ob, g, c, i, j, k, cells);
        ob->e.share[c] = ob->share[c];
    }
    ob->cut = field_alloc(g);
    ob->e.work = field_alloc(g);
    if (!ob->cut || !ob->e.work)
        return -1;
    /* every cell slot (ghosts too): a face of it open below 1 */
    for (int i = grid_slot_lo(g, 0); i < g->n[0]; i++)
        for (int j = grid_slot_lo(g, 1); j < g->n[1]; j++)
            for (int k = -1; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                int cut = 0;
                for (int c = 0; c < 3; c++)
                    cut |= ob->share[c][p] < 1.0 || ob->share[c][p + g->stride[c]] < 1.0;
                ob->cut[p] = cut;
            }
    ob->e.cut = ob->cut;
    return cut_lists(ob, g);
}

/* Where st's block sits in the whole grid (struct obstacle: lo, ...). */
static void place_block(struct obstacle *ob, const struct march_state *st)
{
    const struct decomp *dc = st->ranks ? &st->ranks->dc : NULL;
    struct boundary whole = st->bc;
    whole.dc = NULL;
    bc_periodic_flags(&whole, ob->periodic);
    for (int d = 0; d < 3; d++) {
        ob->lo[d] = dc ? dc->lo[d] : 0;
        ob->n_global[d] = dc ? dc->n_global[d] : st->g.n[d];
        for (int s = 0; s < 2; s++)
            ob->border[d][s] = dc && dc->border[d][s];
    }
    ob->split = dc && decomp_split(dc);
    bc_unknown_boxes(st->ranks ? &st->ranks->global : &st->g, &whole, ob->gact);
}

static int create(struct march_state *st, void **state, char *err, size_t errlen)
{
    struct obstacle *ob = calloc(1, sizeof *ob);
    if (!ob) {
        snprintf(err, errlen, "obstacle: out of memory");
        return -1;
    }
    *state = ob;
    /* march_density_changed applies the body's closed faces and open
     * shares to every density a module sets; a module that moves a tracer
     * would move it through the body (its fluxes do not see the cut cells
     * yet), so it is refused rather than run wrong */
    int cells = st->cs->obstacle.boundary == OBSTACLE_CELLS;
    for (int m = 0; m < st->nmodules && !cells; m++)
        if (st->modules[m]->transport) {
            snprintf(err, errlen, "obstacle.shapes: obstacles do not combine with the physics "
                                  "module '%s' (it transports a tracer, which does not see the "
                                  "body's cut cells yet; obstacle.boundary = cells cuts none)", st->modules[m]->name);
            return -1;
        }
    case_obstacle_shapes(st->cs, &ob->set);
    place_block(ob, st);
    int sharp = st->cs->obstacle.boundary == OBSTACLE_SHARP;
    for (int c = 0; c < 3; c++)
        if (build_component(ob, st, c, sharp, cells) != 0) {
            snprintf(err, errlen, "obstacle: out of memory");
            return -1;
        }
    if (build_shares(ob, &st->g, cells) != 0) {
        snprintf(err, errlen, "obstacle: out of memory");
        return -1;
    }
    embedded_zero(&ob->e, st->field.velocity);
    st->embedded = &ob->e;
    /* the projection: the cut cells' flux form (march_density_changed) */
    return march_density_changed(st, 0, err, errlen);
}

/* The residual with the links ending on the surface; none at held nodes. */
static void residual(struct march_state *st, void *state)
{
    struct obstacle *ob = state;
    const double *eta_cell[3] = {st->field.viscosity, st->field.viscosity, st->field.viscosity};
    viscous_embedded_terms(&st->g, &st->bc, st->act, &ob->e, eta_cell,
                           (const double *const *)st->field.viscosity_edges, -1.0,
                           st->field.velocity, st->field.residual);
    embedded_zero(&ob->e, st->field.residual);
}

/* The held nodes stay 0 (their increment is 0 to the solver's round-off). */
static void end_step(struct march_state *st, void *state, double dt)
{
    (void)dt;
    struct obstacle *ob = state;
    embedded_zero(&ob->e, st->field.velocity);
}

/* obstacle_write's, forces_file's */
static const char *const obstacle_files[] = {"obstacle_surface.csv", FORCES_FILE_NAME, NULL};

const struct module obstacle_module = {
    .name = "obstacle",
    .create = create,
    .residual = residual,
    .end_step = end_step,
    .destroy = destroy,
    .memory_bound = obstacle_memory_bound,
    .files = obstacle_files,
    .coupled_ok = 1,
    .decomposed = 1, /* its geometry on every block from global indices */
};
