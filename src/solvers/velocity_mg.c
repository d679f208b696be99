/* Geometric multigrid of the implicit viscous step (velocity_mg.h). */
#include "solvers/velocity_mg.h"
#include "solvers/velocity_mg_internal.h"
#include "kernels/kernels.h"
#include "kernels/mac_transfer.h"
#include "kernels/patch_smoother.h"
#include "kernels/viscous_stencil.h"
#include "solvers/sparse_direct.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


void velocity_mg_default_options(struct velocity_mg_options *o)
{
    o->pre = 2;
    o->post = 2;
    o->coarse_cells = 256;
}

/* The directions a level halves: even, at least four cells. */
static int coarsening(const struct grid *g, int f[3])
{
    int any = 0;
    for (int d = 0; d < 3; d++) {
        f[d] = g->n[d] >= 4 && !(g->n[d] & 1) ? 2 : 1;
        any |= f[d] == 2;
    }
    return any;
}


static void level_free(struct mg_level *l, int finest)
{
    for (int c = 0; c < 3; c++) {
        field_free(l->x[c]);
        field_free(l->b[c]);
        field_free(l->r[c]);
        field_free(l->d[c]);
        field_free(l->st[c].diag);
        for (int d = 0; d < 3; d++) {
            field_free(l->st[c].cp[d]);
            field_free(l->st[c].cm[d]);
        }
        free(l->held[c]);
        free(l->patch[c]);
        for (int d = 0; d < 3; d++) {
            field_free(l->pw[c][d]);
            field_free(l->lf[c][d].inv_b);
            field_free(l->lf[c][d].cprime);
        }
        if (!finest) {
            free(l->emb.held[c]);
            free(l->emb.saved[c]);
        }
    }
    if (!finest) {
        for (int c = 0; c < 3; c++) {
            field_free(l->A_cell[c]);
            field_free(l->A_edge[c]);
            field_free(l->mass_face[c]);
        }
        field_free(l->aug);
    }
    viscous_work_destroy(&l->work);
    sparse_direct_destroy(l->direct);
    memset(l, 0, sizeof *l);
}

static void gathered_free(struct gathered *gt)
{
    if (!gt)
        return;
    for (int c = 0; c < 3; c++) {
        double *fs[] = {gt->A_cell[c], gt->A_edge[c], gt->mass_face[c], gt->b[c], gt->x[c]};
        for (size_t i = 0; i < sizeof fs / sizeof fs[0]; i++)
            field_free(fs[i]);
    }
    field_free(gt->aug);
    free(gt->scratch);
    for (int c = 0; c < 3; c++) {
        free(gt->emb.held[c]);
        free(gt->emb.saved[c]);
    }
    velocity_mg_destroy(gt->serial);
    free(gt);
}

void velocity_mg_destroy(struct velocity_mg *m)
{
    if (!m)
        return;
    for (int l = 0; l < m->nlevels; l++)
        level_free(&m->lv[l], l == 0);
    for (int c = 0; c < 3; c++)
        field_free(m->edge0[c]);
    gathered_free(m->gath);
    free(m);
}

/* The arrays every level needs (coefficients are allocated by setup). */
static int level_alloc(struct mg_level *l)
{
    int ok = viscous_work_create(&l->work, &l->g, 0) == 0;
    for (int c = 0; c < 3; c++) {
        double **fs[] = {&l->x[c], &l->b[c], &l->r[c], &l->d[c], &l->st[c].diag,
                         &l->st[c].cp[0], &l->st[c].cp[1], &l->st[c].cp[2],
                         &l->st[c].cm[0], &l->st[c].cm[1], &l->st[c].cm[2]};
        for (size_t i = 0; i < sizeof fs / sizeof fs[0]; i++)
            ok &= (*fs[i] = field_alloc(&l->g)) != NULL;
        for (int d = 0; d < 3; d++)
            ok &= (l->pw[c][d] = field_alloc(&l->g)) != NULL;
        for (int s = 0; s < l->nlines; s++) {
            struct line_factors *f = &l->lf[c][l->lines[s]];
            ok &= (f->inv_b = field_alloc(&l->g)) != NULL &&
                  (f->cprime = field_alloc(&l->g)) != NULL;
        }
    }
    return ok ? 0 : -1;
}

/* A level's conditions (bc, its decomposition dc: NULL or shared by every
 * level of a serial hierarchy), the directions that wrap on it, its unknowns
 * and its lines: along every bounded direction, cut at the rank borders. */
static void level_geometry(struct mg_level *l, const struct boundary *bc, const struct decomp *dc)
{
    l->bc = *bc;
    l->bc.dc = dc;
    l->split = dc && decomp_split(dc);
    for (int d = 0; d < 3; d++)
        l->periodic[d] = bc_wraps(&l->bc, d);
    bc_unknown_boxes(&l->g, &l->bc, l->act);
    l->nlines = 0;
    for (int d = 0; d < 3; d++)
        if (bc->face[d][0] != BC_PERIODIC && (l->g.n[d] >= 2 || bc_split(&l->bc, d)))
            l->lines[l->nlines++] = d;
}

/* The global levels of grid g0 (the case's whole grid): each halves the one
 * above along coarsening's directions (f[l]), down to coarse_cells.
 * Returns their count, or -1 (a bad coarse grid). */
static int plan_levels(const struct grid *g0, long coarse_cells, struct grid glob[MAX_LEVELS],
                       int f[MAX_LEVELS][3])
{
    glob[0] = *g0;
    f[0][0] = f[0][1] = f[0][2] = 1;
    int nl = 1;
    for (; nl < MAX_LEVELS; nl++) {
        const struct grid *fg = &glob[nl - 1];
        if ((long)grid_cells(fg) <= coarse_cells || !coarsening(fg, f[nl]))
            break;
        int n[3];
        for (int d = 0; d < 3; d++)
            n[d] = fg->n[d] / f[nl][d];
        if (grid_init_like(&glob[nl], n, g0->len, fg) != 0)
            return -1;
    }
    return nl;
}

/* The gathered level's arrays on its global grid gg and its serial
 * hierarchy (conditions bc without the decomposition).  Returns 0, or -1
 * with a message. */
static int gathered_create(struct velocity_mg *m, const struct grid *gg, const struct boundary *bc,
                           char *err, size_t errlen)
{
    struct gathered *gt = m->gath = calloc(1, sizeof *gt);
    if (!gt) {
        snprintf(err, errlen, "velocity multigrid: out of memory");
        return -1;
    }
    gt->gg = *gg;
    gt->bc = *bc;
    gt->bc.dc = NULL;
    int ok = 1;
    for (int c = 0; c < 3; c++) {
        double **fs[] = {&gt->A_cell[c], &gt->A_edge[c], &gt->mass_face[c], &gt->b[c], &gt->x[c]};
        for (size_t i = 0; i < sizeof fs / sizeof fs[0]; i++)
            ok &= (*fs[i] = field_alloc(gg)) != NULL;
    }
    const struct mg_level *last = &m->lv[m->nlevels - 1];
    ok = ok && (gt->scratch = malloc(decomp_gather_len(&last->dc) * sizeof(double))) != NULL;
    if (!ok) {
        snprintf(err, errlen, "velocity multigrid: out of memory");
        return -1;
    }
    struct box act[3];
    bc_unknown_boxes(gg, &gt->bc, act);
    return velocity_mg_create(&gt->serial, gg, &gt->bc, act, &m->opt, err, errlen);
}

/* The levels of a grid split over ranks (bc->dc): the global hierarchy,
 * each level's blocks halved in place (decomp_coarsen), kept on the ranks
 * while the global level above has over GATHER_CELLS cells, the last kept
 * gathered and cycled by a serial hierarchy (gathered_create).  g is this
 * rank's block of the finest level.  Returns 0, or -1 with a message. */
/* The global grid g0 of which g is the block of dc.  Returns 0 or -1. */
static int global_grid(const struct grid *g, const struct decomp *dc, struct grid *g0)
{
    double len[3];
    for (int d = 0; d < 3; d++)
        len[d] = g->h[d] * dc->n_global[d];
    if (grid_init_like(g0, dc->n_global, len, g) != 0)
        return -1;
    for (int d = 0; d < 3; d++)
        g0->h[d] = g->h[d]; /* the global spacing to the bit (decomp_local_grid) */
    return 0;
}

static int levels_on_ranks(struct velocity_mg *m, const struct grid *g, const struct boundary *bc,
                           char *err, size_t errlen)
{
    const struct decomp *dc = bc->dc;
    struct grid g0;
    struct grid glob[MAX_LEVELS];
    int f[MAX_LEVELS][3];
    int nglob = global_grid(g, dc, &g0);
    if (nglob == 0)
        nglob = plan_levels(&g0, m->opt.coarse_cells, glob, f);
    if (nglob < 0) {
        snprintf(err, errlen, "velocity multigrid: bad coarse grid");
        return -1;
    }
    int kept = 1, halve[3];
    while (kept < nglob && (long)grid_cells(&glob[kept - 1]) > GATHER_CELLS &&
           (halve[0] = f[kept][0] == 2, halve[1] = f[kept][1] == 2, halve[2] = f[kept][2] == 2,
            decomp_coarsen(&m->lv[kept - 1].dc, halve, &m->lv[kept].dc) == 0))
        kept++;
    m->nlevels = kept;
    for (int l = 1; l < kept; l++) {
        struct mg_level *c = &m->lv[l];
        memcpy(c->f, f[l], sizeof c->f);
        if (decomp_local_grid(&c->dc, &glob[l], &c->g) != 0) {
            snprintf(err, errlen, "velocity multigrid: bad coarse grid");
            return -1;
        }
        level_geometry(c, bc, &c->dc);
    }
    for (int l = 0; l < kept; l++)
        if (level_alloc(&m->lv[l]) != 0) {
            snprintf(err, errlen, "velocity multigrid: out of memory");
            return -1;
        }
    return gathered_create(m, &glob[kept - 1], bc, err, errlen);
}

/* With the grad-div augmentation a decomposed hierarchy gathers its finest
 * level, every level below cycled serially on every rank: the edge patches
 * smooth the augmented operator's near-kernel (the divergence-free fields,
 * the curls of the edges' hats), and a patch cut at a rank border leaves
 * the field around that edge unsmoothed (a plane box of 128^2, viscosity
 * over three decades, r = 1e6, split in two along x, each colour of patches
 * exchanged: 789 CG iterations against one process's 34).  The split levels
 * kept for the lines are freed. */
static int gather_finest(struct velocity_mg *m, char *err, size_t errlen)
{
    for (int l = 1; l < m->nlevels; l++)
        level_free(&m->lv[l], 0);
    m->nlevels = 1;
    gathered_free(m->gath);
    m->gath = NULL;
    struct grid g0;
    if (global_grid(&m->lv[0].g, &m->lv[0].dc, &g0) != 0) {
        snprintf(err, errlen, "velocity multigrid: bad coarse grid");
        return -1;
    }
    return gathered_create(m, &g0, m->bc, err, errlen);
}

int velocity_mg_create(struct velocity_mg **out, const struct grid *g, const struct boundary *bc,
                       const struct box act[3], const struct velocity_mg_options *opt, char *err,
                       size_t errlen)
{
    *out = NULL;
    if (grid_stretched(g)) {
        snprintf(err, errlen, "velocity multigrid: stretched grids are not supported yet");
        return -1;
    }
    struct velocity_mg *m = calloc(1, sizeof *m);
    if (!m) {
        snprintf(err, errlen, "velocity multigrid: out of memory");
        return -1;
    }
    m->bc = bc;
    if (opt)
        m->opt = *opt;
    else
        velocity_mg_default_options(&m->opt);
    struct mg_level *l = &m->lv[0];
    l->g = *g;
    const int ranks = bc->dc && decomp_split(bc->dc);
    if (ranks) {
        l->dc = *bc->dc;
        l->dc.owns_buf = 0;
    }
    level_geometry(l, bc, ranks ? &l->dc : bc->dc);
    memcpy(l->act, act, sizeof l->act);
    if (ranks) {
        if (levels_on_ranks(m, g, bc, err, errlen) != 0) {
            velocity_mg_destroy(m);
            return -1;
        }
        *out = m;
        return 0;
    }
    struct grid glob[MAX_LEVELS];
    int f[MAX_LEVELS][3];
    m->nlevels = plan_levels(g, m->opt.coarse_cells, glob, f);
    if (m->nlevels < 0) {
        m->nlevels = 1;
        velocity_mg_destroy(m);
        snprintf(err, errlen, "velocity multigrid: bad coarse grid");
        return -1;
    }
    for (int i = 1; i < m->nlevels; i++) {
        m->lv[i].g = glob[i];
        memcpy(m->lv[i].f, f[i], sizeof m->lv[i].f);
        level_geometry(&m->lv[i], bc, bc->dc);
    }
    for (int i = 0; i < m->nlevels; i++)
        if (level_alloc(&m->lv[i]) != 0) {
            velocity_mg_destroy(m);
            snprintf(err, errlen, "velocity multigrid: out of memory");
            return -1;
        }
    struct mg_level *cl = &m->lv[m->nlevels - 1];
    if (sparse_direct_create(&cl->direct, &cl->g, cl->periodic, cl->act,
                             1, 1, err, errlen) != 0) {
        velocity_mg_destroy(m);
        return -1;
    }
    *out = m;
    return 0;
}

int velocity_mg_levels(const struct velocity_mg *m) { return m->nlevels; }

void velocity_mg_level_size(const struct velocity_mg *m, int l, int n[3])
{
    for (int d = 0; d < 3; d++)
        n[d] = m->lv[l].g.n[d];
}

/* Field arrays a level holds: x, b, r, d and the stencils of each
 * component, the prolongation's weights, the line factors, the work's
 * divergence, and below the finest the coefficients of its operator. */
static double level_fields(int nlines, int coarse)
{
    return 3.0 * (4.0 + 7.0 + 3.0 + 2.0 * nlines) + 1.0 + (coarse ? 10.0 : 0.0);
}

size_t velocity_mg_bytes(const struct velocity_mg *m)
{
    double bytes = 0.0;
    for (int l = 0; l < m->nlevels; l++) {
        int planes = 0;
        for (int n = 0; n < 3; n++)
            planes += m->lv[l].patch[n] != NULL;
        bytes += (level_fields(m->lv[l].nlines, l > 0) + PATCH_FACTOR * planes) *
                 (double)m->lv[l].g.size * sizeof(double);
    }
    if (m->gath) /* the finest edges' copies; the gathered level's 15 arrays (16 with the
                    augmentation's) and hierarchy */
        bytes += 3.0 * (double)m->lv[0].g.size * sizeof(double) +
                 (m->gath->aug ? 16.0 : 15.0) * (double)m->gath->gg.size * sizeof(double) +
                 (double)decomp_gather_len(&m->lv[m->nlevels - 1].dc) * sizeof(double) +
                 (double)velocity_mg_bytes(m->gath->serial);
    return (size_t)bytes;
}

double velocity_mg_memory_estimate(const struct grid *g, const struct boundary *bc,
                                   const struct velocity_mg_options *opt)
{
    struct velocity_mg_options o;
    if (opt)
        o = *opt;
    else
        velocity_mg_default_options(&o);
    int lines = 0, planes = 0;
    for (int d = 0; d < 3; d++)
        lines += (!bc || bc->face[d][0] != BC_PERIODIC) && g->n[d] >= 2;
    /* the edge patches' factors where the operator is augmented (bc NULL:
     * counted on every plane of two directions of two cells or more) */
    for (int n = 0; n < 3; n++)
        planes += g->n[(n + 1) % 3] >= 2 && g->n[(n + 2) % 3] >= 2 &&
                  (!bc || kernel_patch_plane_ok(g, bc, n));
    /* the levels as velocity_mg_create builds them */
    int n[3] = {g->n[0], g->n[1], g->n[2]};
    double bytes = 0.0;
    for (int l = 0; l < MAX_LEVELS; l++) {
        double size = 1.0; /* a level's slots: one along a compact direction (grid.h) */
        for (int d = 0; d < 3; d++)
            size *= d < 2 && n[d] == 1 && bc && bc->face[d][0] == BC_PERIODIC ? 1.0 : n[d] + 2.0;
        bytes += (level_fields(lines, l > 0) + PATCH_FACTOR * planes) * size * sizeof(double);
        int any = 0;
        for (int d = 0; d < 3; d++)
            any |= n[d] >= 4 && !(n[d] & 1);
        if ((double)n[0] * n[1] * n[2] <= (double)o.coarse_cells || !any)
            break;
        for (int d = 0; d < 3; d++)
            if (n[d] >= 4 && !(n[d] & 1))
                n[d] /= 2;
    }
    return bytes;
}




/* Level l's coefficients from level l - 1's. */
static int carry_coefficients(struct velocity_mg *m, int l)
{
    struct mg_level *lv = &m->lv[l];
    const struct mg_level *fl = &m->lv[l - 1];
    const struct grid *g = &lv->g;
    const struct viscous_problem *fp = &fl->pb;
    struct viscous_problem *pb = &lv->pb;
    memset(pb, 0, sizeof *pb);
    pb->mass = fp->mass;
    for (int c = 0; c < 3; c++) {
        if ((!lv->A_cell[c] && !(lv->A_cell[c] = field_alloc(g))) ||
            (!lv->A_edge[c] && !(lv->A_edge[c] = field_alloc(g))))
            return -1;
        kernel_coarsen_cells(&fl->g, g, lv->f, 1, fp->A_cell[c], lv->A_cell[c]);
        bc_fill_scalar(g, &lv->bc, lv->A_cell[c]);
        pb->A_cell[c] = lv->A_cell[c];
        kernel_coarsen_edges(&fl->g, g, lv->f, c, fp->A_edge[c], lv->A_edge[c]);
        vmg_exchange_ghosts(lv, lv->A_edge[c]);
        pb->A_edge[c] = lv->A_edge[c];
        if (fp->mass_face[c]) {
            if (!lv->mass_face[c] && !(lv->mass_face[c] = field_alloc(g)))
                return -1;
            kernel_coarsen_faces(&fl->g, g, lv->f, c, fp->mass_face[c], lv->mass_face[c]);
            pb->mass_face[c] = lv->mass_face[c];
        }
    }
    if (fp->augmentation) {
        if (!lv->aug && !(lv->aug = field_alloc(g)))
            return -1;
        kernel_coarsen_cells(&fl->g, g, lv->f, 0, fp->augmentation, lv->aug);
        bc_fill_scalar(g, &lv->bc, lv->aug);
        pb->augmentation = lv->aug;
    }
    if (m->has_body)
        pb->embedded = &lv->emb;
    return 0;
}

/* The stencils of level l's symmetric operator. */
static void level_stencils(const struct velocity_mg *m, struct mg_level *lv)
{
    const struct viscous_problem *pb = &lv->pb;
    for (int c = 0; c < 3; c++) {
        if (vmg_box_size(&lv->act[c]) == 0)
            continue;
        struct stencil_coefficients k = {.mass_face = pb->mass_face[c], .mass = pb->mass,
                                         .aug = pb->augmentation, .e = pb->embedded,
                                         .held = m->has_body ? lv->held[c] : NULL};
        for (int a = 0; a < 3; a++) {
            k.A_cell[a] = pb->A_cell[a];
            k.A_edge[a] = pb->A_edge[a];
        }
        kernel_own_stencil(&lv->g, &lv->bc, &lv->act[c], c, &k, &lv->st[c]);
        for (int s = 0; s < lv->nlines; s++)
            kernel_line_factor(&lv->g, &lv->act[c], lv->lines[s], &lv->st[c],
                               &lv->lf[c][lv->lines[s]]);
    }
}

/* The edge patches' factors of level lv where the operator is augmented
 * (no body: its held nodes and cut cells are not in the patches' rows). */
static int level_patches(const struct velocity_mg *m, struct mg_level *lv)
{
    lv->patch_on = 0;
    if (!lv->pb.augmentation || m->has_body)
        return 0;
    const struct patch_operator op = {lv->st, {lv->pb.A_edge[0], lv->pb.A_edge[1],
                                               lv->pb.A_edge[2]}, lv->pb.augmentation, 0};
    for (int n = 0; n < 3; n++) {
        if (!kernel_patch_plane_ok(&lv->g, &lv->bc, n))
            continue;
        if (!lv->patch[n] &&
            !(lv->patch[n] = malloc(PATCH_FACTOR * lv->g.size * sizeof(double))))
            return -1;
        kernel_patch_factor(&lv->g, lv->periodic, lv->act, n, &op, lv->patch[n]);
        lv->patch_on = 1;
    }
    return 0;
}

struct level_op {
    const struct velocity_mg *m;
    struct mg_level *lv;
};

static void level_apply(void *ctx, double *v[3], double *out[3])
{
    struct level_op *o = ctx;
    viscous_operator_eval(&o->lv->g, &o->lv->bc, o->lv->act, &o->lv->work, &o->lv->pb, v, out);
}

/* A decomposed finest level's edge coefficients: fp's copied, their ghosts
 * past the rank borders exchanged (a prolongation weight reads the edge
 * beyond the ghost cell), fp pointed at the copies. */
static int finest_edges(struct velocity_mg *m, struct viscous_problem *fp)
{
    const struct mg_level *lv = &m->lv[0];
    for (int a = 0; a < 3; a++) {
        if (!m->edge0[a] && !(m->edge0[a] = field_alloc(&lv->g)))
            return -1;
        memcpy(m->edge0[a], fp->A_edge[a], lv->g.size * sizeof(double));
        vmg_exchange_ghosts(lv, m->edge0[a]);
        fp->A_edge[a] = m->edge0[a];
    }
    return 0;
}

/* The prolongation's weights of a decomposed level's cells next to a high
 * rank border (f: the coarser level's halving): their profile reads a
 * coefficient two cells past the block, so the rank above computed them in
 * its ghost slot -1 (kernel_prolong_weights); they are handed down. */
static void border_weights(struct mg_level *lv, const int f[3])
{
    for (int d = 0; lv->split && d < 3; d++) {
        if (f[d] != 2 || !bc_split(&lv->bc, d))
            continue;
        for (int c = 0; c < 3; c++) {
            if (c == d)
                continue; /* faces along d: no ghost read */
            double *w = lv->pw[c][d];
            if (bc_border(&lv->bc, d, 1)) {
                const struct box *b = &lv->act[c];
                int idx[3];
                idx[d] = lv->g.n[d] - 1;
                const int e1 = (d + 1) % 3, e2 = (d + 2) % 3;
                for (idx[e1] = b->lo[e1]; idx[e1] < b->hi[e1]; idx[e1]++)
                    for (idx[e2] = b->lo[e2]; idx[e2] < b->hi[e2]; idx[e2]++)
                        w[grid_idx(&lv->g, idx[0], idx[1], idx[2])] = 0.0;
            }
            decomp_exchange_add(&lv->dc, &lv->g, w, d);
        }
    }
}


/* The gathered level's operator: the last decomposed level's coefficients
 * gathered on every rank, the serial hierarchy set up on them. */
static int gathered_setup(struct velocity_mg *m, char *err, size_t errlen)
{
    struct gathered *gt = m->gath;
    const struct mg_level *lv = &m->lv[m->nlevels - 1];
    struct viscous_problem gp;
    memset(&gp, 0, sizeof gp);
    gp.mass = lv->pb.mass;
    for (int c = 0; c < 3; c++) {
        decomp_gather(&lv->dc, &lv->g, lv->pb.A_cell[c], &gt->gg, gt->A_cell[c], gt->scratch);
        bc_fill_scalar(&gt->gg, &gt->bc, gt->A_cell[c]);
        decomp_gather(&lv->dc, &lv->g, lv->pb.A_edge[c], &gt->gg, gt->A_edge[c], gt->scratch);
        gp.A_cell[c] = gt->A_cell[c];
        gp.A_edge[c] = gt->A_edge[c];
        if (lv->pb.mass_face[c]) {
            decomp_gather(&lv->dc, &lv->g, lv->pb.mass_face[c], &gt->gg, gt->mass_face[c],
                          gt->scratch);
            gp.mass_face[c] = gt->mass_face[c];
        }
    }
    if (lv->pb.augmentation) {
        if (!gt->aug && !(gt->aug = field_alloc(&gt->gg))) {
            snprintf(err, errlen, "velocity multigrid: out of memory");
            return -1;
        }
        decomp_gather(&lv->dc, &lv->g, lv->pb.augmentation, &gt->gg, gt->aug, gt->scratch);
        bc_fill_scalar(&gt->gg, &gt->bc, gt->aug);
        gp.augmentation = gt->aug;
    }
    if (m->has_body && vmg_gathered_body(m, lv) != 0) {
        snprintf(err, errlen, "velocity multigrid: out of memory");
        return -1;
    }
    gp.embedded = m->has_body ? &gt->emb : NULL;
    return velocity_mg_setup(gt->serial, &gp, err, errlen);
}

int velocity_mg_setup(struct velocity_mg *m, const struct viscous_problem *pb, char *err,
                      size_t errlen)
{
    struct mg_level *fine = &m->lv[0];
    struct viscous_problem *fp = &fine->pb;
    *fp = *pb;
    /* the symmetric operator: with the full tangent, its symmetric part */
    fp->b_cell = NULL;
    fp->base = NULL;
    fp->open_given = 0;
    for (int a = 0; a < 3; a++) {
        fp->b_edge[a] = NULL;
        if (pb->b_cell && pb->sym_cell[a])
            fp->A_cell[a] = pb->sym_cell[a];
        if (pb->b_cell && pb->sym_edge[a])
            fp->A_edge[a] = pb->sym_edge[a];
        fp->sym_cell[a] = fp->sym_edge[a] = NULL;
    }
    m->has_body = pb->embedded != NULL;
    if (m->gath && m->has_body && pb->augmentation) { /* gather_finest's level: no cut cells */
        snprintf(err, errlen, "velocity multigrid: a body with the grad-div augmentation on "
                              "MPI ranks is not supported");
        return -1;
    }
    if (m->gath && pb->augmentation && m->nlevels > 1 && gather_finest(m, err, errlen) != 0)
        return -1;
    if (m->gath && finest_edges(m, fp) != 0) {
        snprintf(err, errlen, "velocity multigrid: out of memory");
        return -1;
    }
    for (int l = 0; l < m->nlevels; l++) {
        if (l > 0 && carry_coefficients(m, l) != 0) {
            snprintf(err, errlen, "velocity multigrid: out of memory");
            return -1;
        }
        if (m->has_body) {
            if (vmg_carry_body(m, l, pb->embedded) != 0) {
                snprintf(err, errlen, "velocity multigrid: out of memory");
                return -1;
            }
            if (l > 0)
                m->lv[l].pb.embedded = &m->lv[l].emb;
        }
        level_stencils(m, &m->lv[l]);
        if (level_patches(m, &m->lv[l]) != 0) {
            snprintf(err, errlen, "velocity multigrid: out of memory");
            return -1;
        }
    }
    for (int l = 0; l + 1 < m->nlevels; l++) {
        struct mg_level *lv = &m->lv[l];
        for (int c = 0; c < 3; c++)
            if (vmg_box_size(&lv->act[c]) > 0)
                kernel_prolong_weights(&lv->g, &lv->bc, m->lv[l + 1].f, c, &lv->act[c],
                                       lv->pb.A_cell, lv->pb.A_edge, lv->pb.augmentation,
                                       lv->patch_on ? 2 : 0, lv->pw[c]);
        border_weights(lv, m->lv[l + 1].f);
    }
    if (m->gath)
        return gathered_setup(m, err, errlen);
    struct mg_level *cl = &m->lv[m->nlevels - 1];
    struct level_op op = {m, cl};
    int probed = 0;
    /* a right-hand side on every unknown: every block factorised now */
    for (int c = 0; c < 3; c++) {
        const struct box *b = &cl->act[c];
        memset(cl->b[c], 0, cl->g.size * sizeof(double));
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++)
                for (int k = b->lo[2]; k < b->hi[2]; k++)
                    cl->b[c][grid_idx(&cl->g, i, j, k)] = 1.0;
    }
    if (sparse_direct_factor(cl->direct, level_apply, &op, cl->x, cl->r, 7, &probed) != 0 ||
        sparse_direct_prepare(cl->direct, cl->b, -1.0) != 0) {
        snprintf(err, errlen, "velocity multigrid: the coarsest level's factorisation: %s",
                 sparse_direct_cause(cl->direct));
        return -1;
    }
    return 0;
}

static void zero3(const struct grid *g, double *f[3])
{
    for (int c = 0; c < 3; c++)
        memset(f[c], 0, g->size * sizeof(double));
}

/* One smoothing step on level lv: Gauss-Seidel over the components, each
 * by line Gauss-Seidel along the level's line directions on the residual
 * of the whole operator (its rows of that component); reverse: the
 * components, directions and colours in the opposite order. */
static void smooth_lines(struct velocity_mg *m, struct mg_level *lv, int reverse)
{
    const struct grid *g = &lv->g;
    for (int t = 0; t < 3; t++) {
        const int c = reverse ? 2 - t : t;
        const struct box *b = &lv->act[c];
        if ((vmg_box_size(b) == 0 && !lv->split) || (m->skip >> c & 1))
            continue; /* split: the rows' fills are every rank's exchanges */
        viscous_operator_rows(g, &lv->bc, lv->act, &lv->work, &lv->pb, c, lv->x, lv->r);
        double *r = lv->r[c], *bb = lv->b[c], *d = lv->d[c], *x = lv->x[c];
        if (lv->split) /* a rank border's ghosts: the neighbour's part of this sweep is 0 */
            memset(d, 0, g->size * sizeof(double));
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++)
                for (int k = b->lo[2]; k < b->hi[2]; k++) {
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    r[p] = bb[p] - r[p];
                    d[p] = 0.0;
                }
        for (int s = 0; s < lv->nlines; s++) {
            const int L = lv->lines[reverse ? lv->nlines - 1 - s : s];
            kernel_line_gauss_seidel(g, lv->periodic, b, L, &lv->st[c], &lv->lf[c][L], r, d,
                                     reverse);
        }
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++)
                for (int k = b->lo[2]; k < b->hi[2]; k++) {
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    x[p] += d[p];
                }
    }
}

/* The edge patches' sweeps over the level's planes (reverse: the planes
 * and colours in the opposite order). */
static void smooth_patches(const struct velocity_mg *m, struct mg_level *lv, int reverse)
{
    const struct patch_operator op = {lv->st, {lv->pb.A_edge[0], lv->pb.A_edge[1],
                                               lv->pb.A_edge[2]}, lv->pb.augmentation, m->skip};
    for (int t = 0; t < 3; t++) {
        const int n = reverse ? 2 - t : t;
        if (lv->patch[n])
            kernel_patch_sweep(&lv->g, lv->periodic, lv->act, n, &op, lv->patch[n], lv->b, lv->x,
                               reverse);
    }
}

/* One smoothing step: the edge patches where the operator is augmented
 * (the line smoother after them gave the same iterations on the cavity, at
 * 1.3-1.5x the time), else the component-wise line smoother. */
static void smooth(struct velocity_mg *m, struct mg_level *lv, int reverse)
{
    if (lv->patch_on)
        smooth_patches(m, lv, reverse);
    else
        smooth_lines(m, lv, reverse);
}

/* The gathered level: b gathered on every rank, cycled by the serial
 * hierarchy, this rank's block of its x. */
static void gathered_cycle(struct velocity_mg *m, struct mg_level *lv)
{
    struct gathered *gt = m->gath;
    for (int c = 0; c < 3; c++)
        decomp_gather(&lv->dc, &lv->g, lv->b[c], &gt->gg, gt->b[c], gt->scratch);
    velocity_mg_cycle(gt->serial, gt->b, gt->x);
    for (int c = 0; c < 3; c++)
        decomp_scatter(&lv->dc, &gt->gg, gt->x[c], &lv->g, lv->x[c]);
}

/* x ~ A^-1 b on level l, from x = 0. */
static void cycle(struct velocity_mg *m, int l)
{
    struct mg_level *lv = &m->lv[l];
    const struct grid *g = &lv->g;
    if (l == m->nlevels - 1) {
        zero3(g, lv->x);
        if (m->gath)
            gathered_cycle(m, lv);
        else
            sparse_direct_solve(lv->direct, lv->b, lv->x);
        return;
    }
    struct mg_level *cl = &m->lv[l + 1];
    zero3(g, lv->x);
    for (int s = 0; s < m->opt.pre; s++)
        smooth(m, lv, 0);
    struct level_op op = {m, lv};
    level_apply(&op, lv->x, lv->r);
    for (int c = 0; c < 3; c++) {
        double *r = lv->r[c], *b = lv->b[c];
        for (size_t p = 0; p < g->size; p++)
            r[p] = b[p] - r[p];
    }
    zero3(&cl->g, cl->b);
    for (int c = 0; c < 3; c++) {
        /* split: every rank takes part in the exchange, a block without
         * coarse unknowns of c too (its fine nodes may scatter past it) */
        if ((vmg_box_size(&cl->act[c]) == 0 && !cl->split) || (m->skip >> c & 1))
            continue;
        kernel_restrict_velocity(g, &cl->g, &cl->bc, cl->f, c, &lv->act[c], &cl->act[c],
                                 lv->pw[c], lv->r[c], cl->b[c]);
        for (int d = 0; cl->split && d < 3; d++) /* what landed on the ghosts */
            if (bc_split(&cl->bc, d))
                decomp_exchange_add(&cl->dc, &cl->g, cl->b[c], d);
    }
    /* one visit (V-cycle): a second (W) lowered the augmented cavity's Picard
     * iterations at Bn 1000 but cost the collapse 1.5x (velocity-multigrid.md) */
    cycle(m, l + 1);
    if (cl->split) /* the coarse nodes past a rank border */
        bc_fill_velocity_homogeneous(&cl->g, &cl->bc, cl->x);
    for (int c = 0; c < 3; c++)
        if (vmg_box_size(&lv->act[c]) > 0 && !(m->skip >> c & 1))
            kernel_prolong_velocity(g, &cl->g, &cl->bc, cl->f, c, &lv->act[c], &cl->act[c],
                                    lv->pw[c], cl->x[c], lv->x[c]);
    for (int s = 0; s < m->opt.post; s++)
        smooth(m, lv, 1);
}

void velocity_mg_cycle(struct velocity_mg *m, double *const r[3], double *z[3])
{
    struct mg_level *lv = &m->lv[0];
    m->skip = 0;
    for (int c = 0; c < 3; c++) {
        memset(lv->b[c], 0, lv->g.size * sizeof(double));
        const struct box *b = &lv->act[c];
        int zero = 1;
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++)
                for (int k = b->lo[2]; k < b->hi[2]; k++) {
                    ptrdiff_t p = grid_idx(&lv->g, i, j, k);
                    lv->b[c][p] = r[c][p];
                    zero &= r[c][p] == 0.0;
                }
        /* every rank's part of it (a one-cell direction is never split) */
        if (lv->periodic[c] && lv->g.n[c] == 1 && m->gath)
            zero = decomp_max(&lv->dc, zero ? 0.0 : 1.0) == 0.0;
        if (zero && lv->periodic[c] && lv->g.n[c] == 1)
            m->skip |= 1 << c;
    }
    cycle(m, 0);
    for (int c = 0; c < 3; c++) {
        const struct box *b = &lv->act[c];
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++)
                for (int k = b->lo[2]; k < b->hi[2]; k++) {
                    ptrdiff_t p = grid_idx(&lv->g, i, j, k);
                    z[c][p] = lv->x[c][p];
                }
    }
}
