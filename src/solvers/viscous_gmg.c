/* Geometric multigrid preconditioner of the implicit viscous step
 * (include/solvers/viscous_gmg.h; docs/numerics/multigrid.md).  One
 * multigrid.h hierarchy per covered component, with its mass term; the
 * coefficient arrays are shared by the components, since each hierarchy
 * copies what it is given. */
#include "solvers/viscous_gmg.h"
#include "grid/decomp.h"
#include "solvers/multigrid.h"
#include "kernels/kernels.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The operator's arrays a gathered cross-section takes (struct
 * viscous_gmg_operator's, in this order): A_cell, A_edge, mass_face, b_edge,
 * base (three each), the augmentation. */
#define GATHERED_ARRAYS 16

/* Over the ranks of a split grid (bc->dc) the cross-section is gathered on
 * every rank and its hierarchies cycled there, serially, as on one process:
 * the zebra lines and the cross term are not decomposed, and a cross-section
 * is one plane (the shipped heap's 70 x 100 a 56 kB gather). */
struct gmg_gathered {
    const struct decomp *dc;
    const struct grid *local;    /* this rank's block */
    struct grid gg;              /* the whole cross-section, the hierarchies' grid */
    double *op[GATHERED_ARRAYS]; /* the operator's arrays on gg (allocated when given) */
    double *r, *z, *scratch;     /* a component's right-hand side and cycle; the gather's */
    const struct embedded *from; /* the body gathered into body (NULL: none yet) */
    struct embedded body;        /* its held nodes and cut links on gg (gather_body) */
};

struct viscous_gmg {
    const struct grid *g;        /* the hierarchies' grid (gathered: gath->gg) */
    struct gmg_gathered *gath;   /* NULL: this process holds the grid */
    struct multigrid *mg[3];     /* NULL: component not covered */
    double *a[3], *mass;         /* the block's face coefficients and mass, set-up work */
    double *km[2];               /* the tangent's cross term (mixed_coefficients) */
    unsigned char *held;         /* a body's held nodes of the block being set (or NULL) */
};

const char *viscous_gmg_refusal(const int n[3], const struct boundary *bc)
{
    int periodic = 0;
    for (int d = 0; d < 3; d++) {
        if (bc->face[d][0] != BC_PERIODIC)
            continue;
        periodic = 1;
        if (n[d] > 1)
            return "solver.preconditioner = gmg needs every periodic direction to be one cell "
                   "across (a cross-section: its lines run along the bounded directions only, "
                   "and a periodic direction of two or more cells couples its nodes through the "
                   "viscosity, beyond a point smoother: bagnold's 2 x 1 x 40 took 13-55 "
                   "multigrid iterations a block and stalled); use line, fourier, cholesky or amg";
    }
    return periodic ? NULL
                    : "solver.preconditioner = gmg needs a periodic direction (its multigrid "
                      "serves the velocity components along periodic directions); use cholesky, "
                      "lu or amg";
}

int viscous_gmg_components(const struct viscous_gmg *m)
{
    int bits = 0;
    for (int c = 0; c < 3; c++)
        bits |= m->mg[c] ? 1 << c : 0;
    return bits;
}

int viscous_gmg_levels(const struct viscous_gmg *m, int c)
{
    return m->mg[c] ? multigrid_levels(m->mg[c]) : 0;
}

void viscous_gmg_destroy(struct viscous_gmg *m)
{
    if (!m)
        return;
    for (int c = 0; c < 3; c++) {
        multigrid_destroy(m->mg[c]);
        field_free(m->a[c]);
    }
    field_free(m->km[0]);
    field_free(m->km[1]);
    field_free(m->mass);
    free(m->held);
    if (m->gath) {
        for (int a = 0; a < GATHERED_ARRAYS; a++)
            field_free(m->gath->op[a]);
        field_free(m->gath->r);
        field_free(m->gath->z);
        free(m->gath->scratch);
        for (int c = 0; c < 3; c++)
            free(m->gath->body.held[c]);
        free(m->gath->body.links);
        free(m->gath);
    }
    free(m);
}

/* The component's unknowns fill the cell box: it lies along a periodic
 * direction (its faces normal to it are as many as the cells). */
static int covered(const struct grid *g, const struct boundary *bc, const struct box act[3], int c)
{
    if (bc->face[c][0] != BC_PERIODIC)
        return 0;
    for (int d = 0; d < 3; d++)
        if (act[c].lo[d] != 0 || act[c].hi[d] != g->n[d])
            return 0;
    return 1;
}

/* The multigrid's condition for a tangential component on face (d, side): the
 * velocity held (ghost = -interior, boundary.c) is Dirichlet, the mirror
 * (slip, surface, open) Neumann. */
static enum poisson_bc tangential_bc(enum bc_kind k)
{
    switch (k) {
    case BC_PERIODIC: return POISSON_PERIODIC;
    case BC_WALL:
    case BC_LID:
    case BC_INFLOW: return POISSON_DIRICHLET;
    case BC_SLIP:
    case BC_SURFACE:
    case BC_OPEN: break;
    }
    return POISSON_NEUMANN;
}

/* The gathered cross-section of a split grid (struct gmg_gathered): its
 * global grid (the global spacing to the bit, as decomp_local_grid), its
 * conditions without the decomposition and its unknown boxes.  Returns 0,
 * or -1 out of memory. */
static int gathered_create(struct viscous_gmg *m, const struct grid *g, const struct boundary *bc,
                           struct boundary *gbc, struct box gact[3])
{
    struct gmg_gathered *gt = m->gath = calloc(1, sizeof *gt);
    if (!gt)
        return -1;
    gt->dc = bc->dc;
    gt->local = g;
    double len[3];
    for (int d = 0; d < 3; d++)
        len[d] = g->h[d] * gt->dc->n_global[d];
    if (grid_init_like(&gt->gg, gt->dc->n_global, len, g) != 0)
        return -1;
    for (int d = 0; d < 3; d++)
        gt->gg.h[d] = g->h[d];
    *gbc = *bc;
    gbc->dc = NULL;
    bc_unknown_boxes(&gt->gg, gbc, gact);
    m->g = &gt->gg;
    return (gt->r = field_alloc(&gt->gg)) && (gt->z = field_alloc(&gt->gg)) &&
                   (gt->scratch = malloc(decomp_gather_len(gt->dc) * sizeof(double)))
               ? 0
               : -1;
}

int viscous_gmg_create(struct viscous_gmg **out, const struct grid *g, const struct boundary *bc,
                       const struct box act[3], char *err, size_t errlen)
{
    *out = NULL;
    if (grid_stretched(g)) {
        snprintf(err, errlen, "the geometric multigrid of the implicit step needs uniform cells "
                              "(solver.preconditioner = gmg with a domain band)");
        return -1;
    }
    /* past the refusal every periodic direction is one cell across, and a
     * component along one has unknowns on the whole cell box: one at least
     * is covered */
    const char *refused = viscous_gmg_refusal(bc->dc ? bc->dc->n_global : g->n, bc);
    if (refused) {
        snprintf(err, errlen, "%s", refused);
        return -1;
    }
    struct viscous_gmg *m = calloc(1, sizeof *m);
    if (!m) {
        snprintf(err, errlen, "viscous multigrid: out of memory");
        return -1;
    }
    m->g = g;
    struct boundary gbc;
    struct box gact[3];
    if (bc->dc && decomp_split(bc->dc)) {
        if (gathered_create(m, g, bc, &gbc, gact) != 0) {
            snprintf(err, errlen, "viscous multigrid: out of memory");
            viscous_gmg_destroy(m);
            return -1;
        }
        g = m->g;
        bc = &gbc;
        act = gact;
    }
    /* the same conditions for every covered component: across it they are
     * a tangential component's, along it periodic */
    enum poisson_bc pbc[3][2];
    for (int d = 0; d < 3; d++)
        for (int s = 0; s < 2; s++)
            pbc[d][s] = tangential_bc(bc->face[d][s]);
    for (int c = 0; c < 3; c++) {
        if (!covered(g, bc, act, c))
            continue;
        char why[200];
        struct multigrid_options opt;
        multigrid_default_options(&opt);
        /* zebra lines in both directions, W(1,1), the finest level's
         * smoothing split between them: the fastest on the heap
         * (docs/numerics/multigrid.md) */
        opt.smoother = MG_SMOOTH_LINES;
        opt.pre = opt.post = 1;
        opt.full_coarsening = 1;
        opt.split_finest = 1;
        if (multigrid_create(&m->mg[c], g, (const enum poisson_bc(*)[2])pbc, &opt, why,
                             sizeof why) != 0) {
            snprintf(err, errlen, "the geometric multigrid of velocity component %c: %s",
                     "xyz"[c], why);
            viscous_gmg_destroy(m);
            return -1;
        }
    }
    int ok = (m->mass = field_alloc(g)) != NULL && (m->km[0] = field_alloc(g)) != NULL &&
             (m->km[1] = field_alloc(g)) != NULL;
    for (int d = 0; d < 3; d++)
        ok &= (m->a[d] = field_alloc(g)) != NULL;
    if (!ok) {
        snprintf(err, errlen, "viscous multigrid: out of memory");
        viscous_gmg_destroy(m);
        return -1;
    }
    *out = m;
    return 0;
}

/* Component c's block: along c the normal stress 2 A_cell[c] (and the
 * augmentation r) of the cell below the node, across it the shear
 * coefficient of the edge plane normal to the third direction, at the
 * node's own index (edge (i,j,k) is the low corner of cell (i,j,k)). */
static void block_coefficients(struct viscous_gmg *m, const struct viscous_gmg_operator *op, int c)
{
    const struct grid *g = m->g;
    const ptrdiff_t sc = g->stride[c];
    const double *Ac = op->A_cell[c], *r = op->augmentation;
    const double *mf = op->mass_face[c];
#pragma omp parallel for schedule(static) if (kernel_parallel(g))
    for (size_t p = (size_t)sc; p < g->size; p++) {
        m->a[c][p] = 2.0 * Ac[p - sc] + (r ? r[p - sc] : 0.0);
        m->mass[p] = mf ? mf[p] : op->mass;
    }
    for (int e = 0; e < 3; e++)
        if (e != c)
            memcpy(m->a[e], op->A_edge[3 - c - e], g->size * sizeof(double));
}

/* A body in component c's block (held nodes of the body, cut links: the
 * operator of viscous_operator.h): a held node's couplings leave the face
 * coefficients, its fluid neighbours keep them in their mass term (the held
 * value is 0: a Dirichlet condition at the node), and the held node is a
 * row of its mass alone; a cut link's term A (1 - theta) / theta / h^2
 * joins the mass of its node.  Returns -1 without memory for the mask. */
static int fold_body(struct viscous_gmg *m, const struct viscous_gmg_operator *op, int c)
{
    const struct grid *g = m->g;
    const struct embedded *e = op->embedded;
    if (!m->held && !(m->held = calloc(g->size, 1)))
        return -1;
    unsigned char *held = m->held;
    memset(held, 0, g->size);
    for (long i = 0; i < e->nheld[c]; i++)
        held[e->held[c][i]] = 1;
    for (long i = 0; i < e->nheld[c]; i++) {
        const ptrdiff_t p = e->held[c][i];
        int idx[3];
        grid_slot_index(g, p, idx);
        for (int d = 0; d < 3; d++) {
            if (g->n[d] == 1)
                continue; /* a one-cell periodic direction: no coupling */
            const ptrdiff_t s = g->stride[d];
            const double ih2 = 1.0 / (g->h[d] * g->h[d]);
            /* the face below p couples it to p - s, the one above to p + s;
             * a neighbour outside the box is a ghost (the domain's faces) */
            if (idx[d] > 0 && !held[p - s])
                m->mass[p - s] += m->a[d][p] * ih2;
            if (idx[d] + 1 < g->n[d] && !held[p + s])
                m->mass[p + s] += m->a[d][p + s] * ih2;
        }
    }
    for (long i = 0; i < e->nheld[c]; i++) {
        const ptrdiff_t p = e->held[c][i];
        for (int d = 0; d < 3; d++)
            m->a[d][p] = m->a[d][p + g->stride[d]] = 0.0;
    }
    for (long i = 0; i < e->nlinks; i++) {
        const struct embedded_link *l = &e->links[i];
        if (l->c == c)
            m->mass[l->p] +=
                (l->coef < 3 ? op->A_cell[l->coef][l->at] : op->A_edge[l->coef - 3][l->at]) *
                l->w;
    }
    return 0;
}

/* The cross term leaves the faces whose mean differences read a held node
 * (fold_body made it a row of the mass alone): face p of direction e reads
 * the cells p and p - s_e and their neighbours along the other direction,
 * so a held node h is read by the faces h, h + s_e, each shifted by 0 or
 * +-1 along the other. */
static void mixed_off_body(struct viscous_gmg *m, const struct embedded *e, int c, int d1, int d2)
{
    const struct grid *g = m->g;
    const int dir[2] = {d1, d2};
    for (int t = 0; t < 2; t++) {
        const ptrdiff_t se = g->stride[dir[t]], so = g->stride[dir[1 - t]];
        for (long i = 0; i < e->nheld[c]; i++)
            for (int a = 0; a < 2; a++)
                for (int b = -1; b <= 1; b++)
                    m->km[t][e->held[c][i] + a * se + b * so] = 0.0;
    }
}

/* The full tangent's cross term in component c's block on a cross-section
 * (c along its one-cell periodic direction, d1 < d2 the bounded ones):
 * kernel_cross_coefficients from the base strains of kernel_flow_gammas,
 * which take m->a[0..1] as their work arrays (the multigrid has copied the
 * block's coefficients by then).  Returns 0 when the block has no such term
 * (no tangent, or not a cross-section). */
static int mixed_coefficients(struct viscous_gmg *m, const struct viscous_gmg_operator *op, int c,
                              int *d1, int *d2)
{
    const struct grid *g = m->g;
    if (!op->base || !op->b_edge[0] || g->n[c] != 1)
        return 0;
    *d1 = c == 0 ? 1 : 0;
    *d2 = c == 2 ? 1 : 2;
    if (g->n[*d1] < 2 || g->n[*d2] < 2)
        return 0;
    double *gb[2] = {m->a[0], m->a[1]};
    kernel_flow_gammas(g, c, op->base, gb);
    const double *gbc[2] = {gb[0], gb[1]};
    kernel_cross_coefficients(g, c, gbc, op->b_edge, m->km);
    if (op->embedded)
        mixed_off_body(m, op->embedded, c, *d1, *d2);
    return 1;
}

/* Array a of the operator gathered on the cross-section (NULL stays
 * NULL): every slot the serial set-up reads, ghosts included, travels with
 * its block (decomp_gather: gmg splits no periodic direction).  Returns
 * 0, or -1 out of memory. */
static int gather_array(struct gmg_gathered *gt, int a, const double *f, const double **out)
{
    *out = NULL;
    if (!f)
        return 0;
    if (!gt->op[a] && !(gt->op[a] = field_alloc(&gt->gg)))
        return -1;
    decomp_gather(gt->dc, gt->local, f, &gt->gg, gt->op[a], gt->scratch);
    *out = gt->op[a];
    return 0;
}

/* Component c's held nodes of every block on the gathered cross-section,
 * in slot order as one process lists them (its loops run over the slots):
 * each block's own travel as a mask (a ghost's held image is its owner's
 * node, and decomp_gather takes no rank border's ghost).  mask is a field
 * of the block, gmask of gg.  Returns 0, or -1 out of memory. */
static int gather_held(struct gmg_gathered *gt, const struct embedded *e, int c, double *mask,
                       double *gmask)
{
    const struct grid *gg = &gt->gg;
    struct embedded *ge = &gt->body;
    memset(mask, 0, gt->local->size * sizeof(double));
    for (long i = 0; i < e->nheld[c]; i++)
        mask[e->held[c][i]] = 1.0;
    decomp_gather(gt->dc, gt->local, mask, gg, gmask, gt->scratch);
    long n = 0;
    for (size_t p = 0; p < gg->size; p++)
        n += gmask[p] != 0.0;
    if (!(ge->held[c] = malloc((size_t)(n > 0 ? n : 1) * sizeof(ptrdiff_t))))
        return -1;
    ge->nheld[c] = 0;
    for (size_t p = 0; p < gg->size; p++)
        if (gmask[p] != 0.0)
            ge->held[c][ge->nheld[c]++] = (ptrdiff_t)p;
    return 0;
}

/* A slot of the block as the same node's slot on gg. */
static double global_slot(const struct gmg_gathered *gt, ptrdiff_t p)
{
    int idx[3];
    grid_slot_index(gt->local, p, idx);
    return (double)grid_idx(&gt->gg, gt->dc->lo[0] + idx[0], gt->dc->lo[1] + idx[1],
                            gt->dc->lo[2] + idx[2]);
}

#define LINK_DOUBLES 5 /* a link travels as p, at (gg's slots), c, coef, w */

/* Every block's cut links on gg, rank after rank, each block's in its own
 * order: a node's links are all its owner's, so fold_body adds them to its
 * mass in one process's order.  Returns 0, or -1 out of memory. */
static int gather_links(struct gmg_gathered *gt, const struct embedded *e)
{
    const struct comm_cart *cart = gt->dc->cart;
    const int ranks = cart->dims[0] * cart->dims[1] * cart->dims[2];
    long *n = calloc((size_t)ranks, sizeof *n);
    int *cnt = malloc(2 * (size_t)ranks * sizeof *cnt);
    double *mine = malloc((size_t)(e->nlinks > 0 ? e->nlinks : 1) * LINK_DOUBLES * sizeof *mine);
    int rc = n && cnt && mine ? 0 : -1;
    if (rc == 0) {
        n[cart->rank] = e->nlinks;
        comm_sum_long(n, ranks);
        long total = 0;
        for (int r = 0; r < ranks; r++) {
            cnt[r] = (int)(n[r] * LINK_DOUBLES);
            cnt[ranks + r] = (int)(total * LINK_DOUBLES);
            total += n[r];
        }
        for (long i = 0; i < e->nlinks; i++) {
            const struct embedded_link *l = &e->links[i];
            double *m = mine + i * LINK_DOUBLES;
            m[0] = global_slot(gt, l->p);
            m[1] = global_slot(gt, l->at);
            m[2] = l->c;
            m[3] = l->coef;
            m[4] = l->w;
        }
        double *all = malloc((size_t)(total > 0 ? total : 1) * LINK_DOUBLES * sizeof *all);
        gt->body.links = malloc((size_t)(total > 0 ? total : 1) * sizeof *gt->body.links);
        rc = all && gt->body.links ? 0 : -1;
        if (rc == 0) {
            comm_cart_allgather(cart, mine, (int)(e->nlinks * LINK_DOUBLES), all, cnt,
                                cnt + ranks);
            for (long i = 0; i < total; i++) {
                const double *m = all + i * LINK_DOUBLES;
                gt->body.links[i] = (struct embedded_link){.p = (ptrdiff_t)m[0],
                                                           .at = (ptrdiff_t)m[1],
                                                           .c = (int)m[2],
                                                           .coef = (int)m[3],
                                                           .w = m[4]};
            }
            gt->body.nlinks = total;
        }
        free(all);
    }
    free(n);
    free(cnt);
    free(mine);
    return rc;
}

/* What fold_body and mixed_off_body read of the body (held nodes, cut
 * links) on the gathered cross-section, as one process has it; once, the
 * body being fixed.  Collective.  Returns 0, or -1 out of memory. */
static int gather_body(struct gmg_gathered *gt, const struct embedded *e)
{
    if (gt->from == e)
        return 0;
    double *mask = field_alloc(gt->local), *gmask = field_alloc(&gt->gg);
    int rc = mask && gmask ? 0 : -1;
    for (int c = 0; c < 3 && rc == 0; c++)
        rc = gather_held(gt, e, c, mask, gmask);
    if (rc == 0)
        rc = gather_links(gt, e);
    field_free(mask);
    field_free(gmask);
    gt->from = rc == 0 ? e : NULL;
    return rc;
}

/* op's arrays gathered on every rank into gop (struct gmg_gathered).
 * Returns 0, or -1 with a message. */
static int gather_operator(struct gmg_gathered *gt, const struct viscous_gmg_operator *op,
                           struct viscous_gmg_operator *gop, char *err, size_t errlen)
{
    *gop = *op;
    if (op->embedded) {
        if (gather_body(gt, op->embedded) != 0) {
            snprintf(err, errlen, "the geometric multigrid: out of memory for the gathered body");
            return -1;
        }
        gop->embedded = &gt->body;
    }
    const double *base[3];
    int rc = 0;
    for (int c = 0; c < 3; c++) {
        rc |= gather_array(gt, c, op->A_cell[c], &gop->A_cell[c]);
        rc |= gather_array(gt, 3 + c, op->A_edge[c], &gop->A_edge[c]);
        rc |= gather_array(gt, 6 + c, op->mass_face[c], &gop->mass_face[c]);
        rc |= gather_array(gt, 9 + c, op->b_edge[c], &gop->b_edge[c]);
        rc |= gather_array(gt, 12 + c, op->base ? op->base[c] : NULL, &base[c]);
    }
    rc |= gather_array(gt, 15, op->augmentation, &gop->augmentation);
    if (rc != 0) {
        snprintf(err, errlen, "the geometric multigrid: out of memory for the gathered operator");
        return -1;
    }
    /* the gathered base velocity: op's own arrays on gg (base[c] is op[12 + c]) */
    gop->base = op->base ? gt->op + 12 : NULL;
    return 0;
}

int viscous_gmg_setup(struct viscous_gmg *m, const struct viscous_gmg_operator *op, char *err,
                      size_t errlen)
{
    struct viscous_gmg_operator gop;
    if (m->gath) {
        if (gather_operator(m->gath, op, &gop, err, errlen) != 0)
            return -1;
        op = &gop;
    }
    for (int c = 0; c < 3; c++) {
        if (!m->mg[c])
            continue;
        block_coefficients(m, op, c);
        if (op->embedded && fold_body(m, op, c) != 0) {
            snprintf(err, errlen, "the geometric multigrid: out of memory for a body's nodes");
            return -1;
        }
        char why[200];
        int d1 = 0, d2 = 0;
        int rc = multigrid_set_operator(m->mg[c], m->a, m->mass, why, sizeof why);
        const int mixed = rc == 0 && mixed_coefficients(m, op, c, &d1, &d2);
        if (rc == 0)
            rc = multigrid_set_mixed(m->mg[c], d1, d2, mixed ? m->km[0] : NULL,
                                     mixed ? m->km[1] : NULL, why, sizeof why);
        if (rc != 0) {
            snprintf(err, errlen, "the geometric multigrid of velocity component %c: %s",
                     "xyz"[c], why);
            return -1;
        }
    }
    return 0;
}

void viscous_gmg_apply(struct viscous_gmg *m, double *const r[3], double *z[3])
{
    const struct grid *g = m->g;
    struct gmg_gathered *gt = m->gath;
    for (int c = 0; c < 3; c++) {
        if (!m->mg[c])
            continue;
        /* the multigrid inverts L - m = -(block) */
        double *zc = gt ? gt->z : z[c];
        if (gt)
            decomp_gather(gt->dc, gt->local, r[c], g, gt->r, gt->scratch);
        multigrid_cycle(m->mg[c], gt ? gt->r : r[c], zc);
#pragma omp parallel for schedule(static) if (kernel_parallel(g))
        for (size_t p = 0; p < g->size; p++)
            zc[p] = -zc[p];
        if (gt)
            decomp_scatter(gt->dc, g, zc, gt->local, z[c]);
    }
}

size_t viscous_gmg_bytes(const struct viscous_gmg *m)
{
    size_t b = 4 * m->g->size * sizeof(double);
    if (m->gath) {
        size_t arrays = 2;
        for (int a = 0; a < GATHERED_ARRAYS; a++)
            arrays += m->gath->op[a] != NULL;
        b += arrays * m->g->size * sizeof(double) +
             decomp_gather_len(m->gath->dc) * sizeof(double);
    }
    for (int c = 0; c < 3; c++)
        b += m->mg[c] ? multigrid_bytes(m->mg[c]) : 0;
    return b;
}

