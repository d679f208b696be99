/* The level hierarchy and its coefficients: which directions each level
 * halves, the levels' arrays, and the face coefficients, mass and mixed
 * terms copied to level 0 and coarsened to the others
 * (multigrid_internal.h). */
#include "kernels/kernels.h"
#include "solvers/multigrid_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Smaller levels run on one thread: fork/join costs more than their loops
 * (docs/numerics/threads-and-platform.md). */
#define PAR_CELLS PARALLEL_REGION_MIN
#define ANISO_CELLS 4096 /* above this, coarsen anisotropically rather than stop */

/* ---- hierarchy ------------------------------------------------------------------ */

/* Which directions of g to halve: the even ones (never a direction of one
 * cell) whose spacing is within 1.5 of the finest spacing, so that the point
 * smoother never faces an anisotropy beyond 2.25 (1.5^2) that coarsening made;
 * when none qualifies and the level is still large, any even direction (the
 * coarsest solve must stay small).  With full, every even direction: the
 * line smoother takes the anisotropy, and halving one direction of two
 * leaves a W-cycle's second level half as large as the first, visited
 * twice.  Returns how many were chosen. */
int mg_choose_halving(const struct grid *g, long coarse_cells, int full, int halve[3])
{
    long cells = (long)grid_cells(g);
    halve[0] = halve[1] = halve[2] = 0;
    if (cells <= coarse_cells)
        return 0;
    double hmin = INFINITY;
    for (int d = 0; d < 3; d++)
        if (g->n[d] > 1 && g->h[d] < hmin)
            hmin = g->h[d];
    int count = 0;
    for (int d = 0; d < 3; d++) {
        halve[d] = g->n[d] >= 2 && g->n[d] % 2 == 0 &&
                   (full || g->h[d] <= 1.5 * hmin * (1.0 + 1e-12));
        count += halve[d];
    }
    if (count == 0 && cells > ANISO_CELLS)
        for (int d = 0; d < 3; d++) {
            halve[d] = g->n[d] >= 2 && g->n[d] % 2 == 0;
            count += halve[d];
        }
    return count;
}

void mg_level_free(struct level *lv, int owns_xb)
{
    field_free(lv->mbuf);
    for (int k = 0; k < 3; k++) {
        field_free(lv->lc[k]);
        field_free(lv->li[k]);
    }
    for (int d = 0; d < 3; d++) {
        field_free(lv->a[d]);
        free(lv->pi[d]);
        field_free(lv->pw[d]);
    }
    free(lv->live);
    field_free(lv->kbuf[0]);
    field_free(lv->kbuf[1]);
    field_free(lv->r);
    field_free(lv->bbuf);
    if (owns_xb)
        field_free(lv->x);
}

/* The levels' grids: each halves what mg_choose_halving says of the one above,
 * down to the options' coarse_cells (or MAX_LEVELS). */
static void plan_levels(struct multigrid *mg, const struct grid *g)
{
    mg->lev[0].g = *g;
    mg->nlev = 1;
    while (mg->nlev < MAX_LEVELS) {
        const struct grid *gf = &mg->lev[mg->nlev - 1].g;
        int halve[3];
        if (mg_choose_halving(gf, mg->opt.coarse_cells, mg->opt.full_coarsening, halve) == 0)
            break;
        int n[3];
        for (int d = 0; d < 3; d++)
            n[d] = halve[d] ? gf->n[d] / 2 : gf->n[d];
        struct level *lc = &mg->lev[mg->nlev];
        if (grid_init_like(&lc->g, n, gf->len, gf) != 0)
            break;
        for (int d = 0; d < 3; d++)
            lc->coarse[d] = halve[d];
        mg->nlev++;
    }
}

/* Level l's arrays (and the prolongation tables of the level above it).
 * Returns 1, or 0 out of memory. */
static int allocate_level(struct multigrid *mg, int l)
{
    struct level *lv = &mg->lev[l];
    int ok = 1;
    lv->par = grid_cells(&lv->g) >= PAR_CELLS;
    lv->flat = -1;
    for (int d = 2; d >= 0; d--)
        if (mg_periodic_flat(mg, lv, d))
            lv->flat = d;
    for (int d = 0; d < 3; d++) {
        lv->ih2[d] = 1.0 / (lv->g.h[d] * lv->g.h[d]);
        ok &= (lv->a[d] = field_alloc(&lv->g)) != NULL;
    }
    ok &= (lv->live = calloc(lv->g.size, 1)) != NULL;
    ok &= (lv->r = field_alloc(&lv->g)) != NULL;
    if (l > 0) {
        ok &= (lv->x = field_alloc(&lv->g)) != NULL;
        ok &= (lv->bbuf = field_alloc(&lv->g)) != NULL;
        lv->b = lv->bbuf;
        if (ok)
            ok &= mg_build_prolongation(&mg->lev[l - 1], lv) == 0;
    }
    return ok;
}

/* MG_SMOOTH_LINES: the directions of its lines and their factors' arrays.
 * Returns 1, or 0 out of memory. */
static int allocate_lines(struct multigrid *mg, const struct grid *g)
{
    int ok = 1;
    /* lines along every direction that is not periodic and has cells to
     * couple; none (a periodic box): the point smoother */
    for (int d = 0; d < 3; d++)
        if (!mg->periodic[d] && g->n[d] > 1)
            mg->line_dirs[mg->nline_dirs++] = d;
    /* the coarsest level is solved, not smoothed: no factors there */
    for (int l = 0; l < mg->nlev - 1 && ok; l++)
        for (int k = 0; k < mg->nline_dirs; k++)
            ok &= (mg->lev[l].lc[k] = field_alloc(&mg->lev[l].g)) != NULL &&
                  (mg->lev[l].li[k] = field_alloc(&mg->lev[l].g)) != NULL;
    return ok;
}

int mg_build_levels(struct multigrid *mg, const struct grid *g)
{
    plan_levels(mg, g);
    int ok = 1;
    for (int l = 0; l < mg->nlev && ok; l++)
        ok = allocate_level(mg, l);
    if (ok && mg->opt.smoother == MG_SMOOTH_LINES)
        ok = allocate_lines(mg, g);
    return ok ? 0 : -1;
}

/* The levels of a decomposed grid: the global hierarchy planned as
 * plan_levels plans it, kept on the ranks (each block halved in place)
 * while the global level above has more than MG_GATHER_CELLS cells and
 * every block along each halved direction starts and ends on an even cell;
 * the last level kept is the one gathered (mg->gg its global grid).
 * Returns 0, or -1 out of memory. */
int mg_build_levels_decomposed(struct multigrid *mg, const struct grid *gglobal,
                               const struct decomp *dc)
{
    struct grid glob[MAX_LEVELS];
    int halve_at[MAX_LEVELS][3] = {{0}};
    glob[0] = *gglobal;
    int nglob = 1;
    while (nglob < MAX_LEVELS) {
        const struct grid *gf = &glob[nglob - 1];
        int *halve = halve_at[nglob], n[3];
        if (mg_choose_halving(gf, mg->opt.coarse_cells, mg->opt.full_coarsening, halve) == 0)
            break;
        for (int d = 0; d < 3; d++)
            n[d] = halve[d] ? gf->n[d] / 2 : gf->n[d];
        if (grid_init_like(&glob[nglob], n, gf->len, gf) != 0)
            break;
        nglob++;
    }
    mg->dlev[0] = *dc;
    mg->dlev[0].owns_buf = 0;
    int kept = 1;
    while (kept < nglob && (long)grid_cells(&glob[kept - 1]) > MG_GATHER_CELLS &&
           decomp_coarsen(&mg->dlev[kept - 1], halve_at[kept], &mg->dlev[kept]) == 0)
        kept++;
    mg->nlev = kept;
    for (int l = 0; l < kept; l++) {
        struct level *lv = &mg->lev[l];
        if (decomp_local_grid(&mg->dlev[l], &glob[l], &lv->g) != 0)
            return -1;
        for (int d = 0; d < 3; d++)
            lv->coarse[d] = halve_at[l][d];
        lv->dc = &mg->dlev[l];
        lv->parity = (mg->dlev[l].lo[0] + mg->dlev[l].lo[1] + mg->dlev[l].lo[2]) & 1;
    }
    mg->gg = glob[kept - 1];
    int ok = 1;
    for (int l = 0; l < mg->nlev && ok; l++)
        ok = allocate_level(mg, l);
    return ok ? 0 : -1;
}

/* ---- coefficients --------------------------------------------------------------- */

/* 1 / (1/4 a1^-1 + 1/2 a0^-1 + 1/4 a2^-1): the series resistance between two
 * coarse centres, which sit on the fine faces either side of the coarse face;
 * a blocked face on the path blocks it. */
static double harmonic3(double a1, double a0, double a2)
{
    if (!(a1 > 0.0 && a0 > 0.0 && a2 > 0.0))
        return 0.0;
    return 1.0 / (0.25 / a1 + 0.5 / a0 + 0.25 / a2);
}

/* The coarse face cc of direction d from the fine face array fa: the mean
 * across it of the fine faces it coincides with, each replaced by harmonic3
 * of the three fine faces along the normal when harmonic. */
static inline double coarse_face_mean(const struct level *f, const struct level *c, int d,
                                      const double *fa, const int cc[3], int harmonic)
{
    const struct grid *gf = &f->g;
    const int e1 = d == 0 ? 1 : 0, e2 = d == 2 ? 1 : 2;
    const int n1 = c->coarse[e1] ? 2 : 1, n2 = c->coarse[e2] ? 2 : 1;
    const ptrdiff_t sd = gf->stride[d];
    double s = 0.0;
    for (int p = 0; p < n1; p++)
        for (int q = 0; q < n2; q++) {
            int fc[3];
            fc[d] = c->coarse[d] ? 2 * cc[d] : cc[d];
            fc[e1] = n1 * cc[e1] + p;
            fc[e2] = n2 * cc[e2] + q;
            const ptrdiff_t pf = grid_idx(gf, fc[0], fc[1], fc[2]);
            s += harmonic ? harmonic3(fa[pf - sd], fa[pf], fa[pf + sd]) : fa[pf];
        }
    return s * (1.0 / (n1 * n2));
}

/* Coarse face coefficients of c from the fine level f: for each coarse face,
 * the mean across the face of the fine lines' values, each line's value being
 * harmonic3 of the three fine faces along the normal (harmonic mode, interior
 * faces of a halved direction) or the coincident fine face (otherwise, and on
 * boundary faces, whose folded-in conditions are linear in a). */
static void coarsen_coefficients(const struct multigrid *mg, const struct level *f,
                                 struct level *c)
{
    const struct grid *gc = &c->g;
    for (int d = 0; d < 3; d++) {
        const int nc = gc->n[d];
        const int phys_lo = mg_physical_side(mg, c, d, 0), phys_hi = mg_physical_side(mg, c, d, 1);
        int hi[3] = {gc->n[0], gc->n[1], gc->n[2]};
        hi[d] = mg_faces_held(mg, c, d);
        const double *fa = f->a[d];
        double *ca = c->a[d];
        const int harmonic = mg->opt.average == MG_AVERAGE_HARMONIC && c->coarse[d];
#pragma omp parallel for collapse(2) schedule(static) if (c->par)
        for (int I = 0; I < hi[0]; I++)
            for (int J = 0; J < hi[1]; J++)
                for (int K = 0; K < hi[2]; K++) {
                    const int cc[3] = {I, J, K};
                    const int boundary = (phys_lo && cc[d] == 0) || (phys_hi && cc[d] == nc);
                    ca[grid_idx(gc, I, J, K)] = coarse_face_mean(f, c, d, fa, cc,
                                                                 harmonic && !boundary);
                }
    }
}

/* Per-level fix-ups once a[] is filled: a periodic direction of one cell
 * couples a cell to itself (no flux: a = 0), face halos, the live mask. */
static void finish_level_coefficients(const struct multigrid *mg, struct level *lv)
{
    const struct grid *g = &lv->g;
    for (int d = 0; d < 3; d++) {
        if (mg_periodic_flat(mg, lv, d))
            for (size_t p = 0; p < g->size; p++)
                lv->a[d][p] = 0.0;
        mg_halo_faces(mg, lv, lv->a[d], d);
    }
    const ptrdiff_t sx = g->stride[0], sy = g->stride[1];
    memset(lv->live, 0, g->size); /* ghosts: dead */
#pragma omp parallel for collapse(2) schedule(static) if (lv->par)
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                const ptrdiff_t p = grid_idx(g, i, j, k);
                const double D = lv->a[0][p] + lv->a[0][p + sx] + lv->a[1][p] + lv->a[1][p + sy] +
                                 lv->a[2][p] + lv->a[2][p + 1] + (lv->m ? lv->m[p] : 0.0);
                lv->live[p] = D > 0.0;
            }
}

/* Level 0's face coefficients of direction d from src, the conditions
 * folded in (see multigrid_internal.h).  Returns 0, or -1 with a message
 * naming the first bad face. */
static int copy_faces(struct multigrid *mg, int d, const double *src, char *err, size_t errlen)
{
    struct level *l0 = &mg->lev[0];
    const struct grid *g = &l0->g;
    const int n = g->n[d];
    const int phys_lo = mg_physical_side(mg, l0, d, 0), phys_hi = mg_physical_side(mg, l0, d, 1);
    int hi[3] = {g->n[0], g->n[1], g->n[2]};
    /* the faces read: a periodic direction's face n is face 0, a rank
     * border's the next rank's */
    hi[d] = mg_faces_held(mg, l0, d);
    double *dst = l0->a[d];
    long bad = -1;
#pragma omp parallel for collapse(2) schedule(static) if (l0->par) reduction(max : bad)
    for (int i = 0; i < hi[0]; i++)
        for (int j = 0; j < hi[1]; j++)
            for (int k = 0; k < hi[2]; k++) {
                const int c[3] = {i, j, k}, t = c[d];
                const ptrdiff_t p = grid_idx(g, i, j, k);
                const int boundary = (phys_lo && t == 0) || (phys_hi && t == n);
                double val = src[p];
                if (boundary && mg->bc[d][t == 0 ? 0 : 1] == POISSON_NEUMANN)
                    val = 0.0; /* not read */
                else if (!(val >= 0.0) || !isfinite(val))
                    bad = p > bad ? p : bad;
                else if (boundary)
                    val *= 2.0; /* Dirichlet: half a cell from the centre to the face */
                dst[p] = val;
            }
    if (bad >= 0) {
        int c[3];
        grid_slot_index(g, bad, c);
        mg_set_err(err, errlen, "multigrid: coefficient %g on face (%d,%d,%d) of direction %c",
                   src[bad], c[0], c[1], c[2], "xyz"[d]);
        return -1;
    }
    return 0;
}

int mg_set_faces(struct multigrid *mg, double *const a[3], char *err, size_t errlen)
{
    long bad = 0;
    for (int d = 0; d < 3 && !bad; d++)
        bad = copy_faces(mg, d, a[d], err, errlen) != 0;
    if (mg->lev[0].dc) /* every rank returns alike */
        comm_sum_long(&bad, 1);
    if (bad) {
        if (err && !err[0])
            mg_set_err(err, errlen, "multigrid: a coefficient refused on another rank");
        return -1;
    }
    mg_coarsen_faces(mg);
    return 0;
}

void mg_coarsen_faces(struct multigrid *mg)
{
    struct level *l0 = &mg->lev[0];
    const struct grid *g = &l0->g;
    finish_level_coefficients(mg, l0);
    for (int l = 1; l < mg->nlev; l++) {
        coarsen_coefficients(mg, &mg->lev[l - 1], &mg->lev[l]);
        finish_level_coefficients(mg, &mg->lev[l]);
        mg_transfer_weights(mg, &mg->lev[l - 1], &mg->lev[l]);
    }
    long live = 0;
#pragma omp parallel for schedule(static) if (l0->par) reduction(+ : live)
    for (size_t p = 0; p < g->size; p++)
        live += l0->live[p];
    if (l0->dc)
        comm_sum_long(&live, 1);
    mg->live = live;
}

/* ---- mass and mixed terms ------------------------------------------------------- */

/* The mass term of every level: level 0's copied from mass (>= 0 and finite
 * on the interior), each coarser one the mean of its children, the scaling
 * of the restriction (a constant residual restricts to itself), so the
 * coarse operator stays the rediscretised L - m.  mass NULL: none. */
int mg_set_mass(struct multigrid *mg, const double *mass, char *err, size_t errlen)
{
    for (int l = 0; l < mg->nlev; l++) {
        struct level *lv = &mg->lev[l];
        lv->m = NULL;
        if (mass && !lv->mbuf && !(lv->mbuf = field_alloc(&lv->g))) {
            mg_set_err(err, errlen, "multigrid: out of memory (mass term)");
            return -1;
        }
    }
    if (!mass)
        return 0;
    const struct grid *g = &mg->lev[0].g;
    double *m0 = mg->lev[0].mbuf;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                const ptrdiff_t p = grid_idx(g, i, j, k);
                if (!(mass[p] >= 0.0) || !isfinite(mass[p])) {
                    mg_set_err(err, errlen, "multigrid: mass term %g in cell (%d,%d,%d)", mass[p],
                               i, j, k);
                    return -1;
                }
                m0[p] = mass[p];
            }
    mg_coarsen_mass(mg);
    return 0;
}

void mg_coarsen_mass(struct multigrid *mg)
{
    for (int l = 1; l < mg->nlev; l++) {
        const struct level *f = &mg->lev[l - 1];
        struct level *c = &mg->lev[l];
        const int n0 = c->coarse[0] ? 2 : 1, n1 = c->coarse[1] ? 2 : 1, n2 = c->coarse[2] ? 2 : 1;
        const double inv = 1.0 / (n0 * n1 * n2);
        for (int I = 0; I < c->g.n[0]; I++)
            for (int J = 0; J < c->g.n[1]; J++)
                for (int K = 0; K < c->g.n[2]; K++) {
                    double sum = 0.0;
                    for (int a = 0; a < n0; a++)
                        for (int b = 0; b < n1; b++)
                            for (int q = 0; q < n2; q++)
                                sum += f->mbuf[grid_idx(&f->g, n0 * I + a, n1 * J + b, n2 * K + q)];
                    c->mbuf[grid_idx(&c->g, I, J, K)] = sum * inv;
                }
    }
    for (int l = 0; l < mg->nlev; l++)
        mg->lev[l].m = mg->lev[l].mbuf;
}

/* Face array km of direction d on level c from level f: the mean of the
 * fine faces each coarse face coincides with (boundary faces 0). */
static void coarsen_mixed(const struct level *f, struct level *c, int t)
{
    const int d = c->md[t];
    const struct grid *gc = &c->g;
    double *ck = c->kbuf[t];
    for (int I = 0; I < gc->n[0]; I++)
        for (int J = 0; J < gc->n[1]; J++)
            for (int K = 0; K < gc->n[2]; K++) {
                const int cc[3] = {I, J, K};
                ck[grid_idx(gc, I, J, K)] = cc[d] == 0 ? 0.0 : coarse_face_mean(f, c, d,
                                                                              f->km[t], cc, 0);
            }
}

int multigrid_set_mixed(struct multigrid *mg, int d1, int d2, const double *k1, const double *k2,
                        char *err, size_t errlen)
{
    for (int l = 0; l < mg->nlev; l++)
        mg->lev[l].km[0] = mg->lev[l].km[1] = NULL;
    if (!k1 || !k2)
        return 0;
    if (mg->sub) {
        mg_set_err(err, errlen, "multigrid: no mixed term on a decomposed grid");
        return -1;
    }
    const struct grid *g = &mg->lev[0].g;
    if (d1 == d2 || d1 < 0 || d1 > 2 || d2 < 0 || d2 > 2 || mg->periodic[d1] ||
        mg->periodic[d2]) {
        mg_set_err(err, errlen, "multigrid: the mixed term needs two bounded directions");
        return -1;
    }
    const int md[2] = {d1, d2};
    int longest = 0;
    for (int d = 0; d < 3; d++)
        longest = g->n[d] > longest ? g->n[d] : longest;
#ifdef _OPENMP
    const int nt = omp_get_max_threads();
#else
    const int nt = 1;
#endif
    if (!mg->mxbuf) {
        mg->mxlen = longest;
        if (!(mg->mxbuf = malloc(2 * (size_t)longest * (size_t)nt * sizeof(double)))) {
            mg_set_err(err, errlen, "multigrid: out of memory (mixed term)");
            return -1;
        }
    }
    for (int l = 0; l < mg->nlev; l++) {
        struct level *lv = &mg->lev[l];
        for (int t = 0; t < 2; t++) {
            lv->md[t] = md[t];
            if (!lv->kbuf[t] && !(lv->kbuf[t] = field_alloc(&lv->g))) {
                mg_set_err(err, errlen, "multigrid: out of memory (mixed term)");
                return -1;
            }
        }
    }
    struct level *l0 = &mg->lev[0];
    for (int t = 0; t < 2; t++) {
        const double *src = t ? k2 : k1;
        const int d = md[t], n = g->n[d];
        for (size_t p = 0; p < g->size; p++)
            l0->kbuf[t][p] = 0.0;
        for (int i = 0; i < g->n[0]; i++)
            for (int j = 0; j < g->n[1]; j++)
                for (int k = 0; k < g->n[2]; k++) {
                    const int c[3] = {i, j, k};
                    const ptrdiff_t p = grid_idx(g, i, j, k);
                    if (c[d] == 0 || c[d] == n)
                        continue;
                    if (!isfinite(src[p])) {
                        mg_set_err(err, errlen,
                                   "multigrid: mixed coefficient %g on face (%d,%d,%d)", src[p],
                                   i, j, k);
                        return -1;
                    }
                    l0->kbuf[t][p] = src[p];
                }
        l0->km[t] = l0->kbuf[t];
    }
    for (int l = 1; l < mg->nlev; l++)
        for (int t = 0; t < 2; t++) {
            struct level *c = &mg->lev[l];
            c->km[t] = c->kbuf[t];
            coarsen_mixed(&mg->lev[l - 1], c, t);
        }
    return 0;
}
