/* Geometric multigrid for the variable-coefficient cell-centred Poisson
 * problem (include/solvers/multigrid.h): its creation, options and
 * operator; the parts are multigrid_levels.c (the hierarchy and its
 * coefficients), multigrid_operator.c (halos, residual), multigrid_smooth.c,
 * multigrid_transfer.c, multigrid_coarse.c (CHOLMOD) and multigrid_pcg.c
 * (the cycle and the solvers), sharing multigrid_internal.h. */
#include "solvers/multigrid_internal.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

void multigrid_default_options(struct multigrid_options *o)
{
    o->pre = 2;
    o->post = 2;
    o->prolong = MG_PROLONG_FLUX;
    o->average = MG_AVERAGE_ARITHMETIC;
    o->coarse_cells = 64;
    o->gamma = 2;
    o->smoother = MG_SMOOTH_POINT;
    o->full_coarsening = 0;
    o->split_finest = 0;
    o->coarse_simplicial = 0;
}

void multigrid_destroy(struct multigrid *mg)
{
    if (!mg)
        return;
    for (int l = 0; l < mg->nlev; l++)
        mg_level_free(&mg->lev[l], l > 0);
    free(mg->mxbuf);
    mg_coarse_free(mg);
    multigrid_destroy(mg->sub);
    field_free(mg->gx);
    field_free(mg->gb);
    free(mg->gscratch);
    field_free(mg->wr);
    field_free(mg->wz);
    field_free(mg->wp);
    field_free(mg->wq);
    field_free(mg->wbest);
    free(mg);
}

/* The grid and conditions create accepts.  Returns 0, or -1 with a message. */
static int check_problem(const struct grid *g, const enum poisson_bc bc[3][2], char *err,
                         size_t errlen)
{
    for (int d = 0; d < 3; d++) {
        if (g->n[d] < 1 || !(g->h[d] > 0.0) || !isfinite(g->h[d])) {
            mg_set_err(err, errlen, "multigrid: invalid grid in direction %c", "xyz"[d]);
            return -1;
        }
        for (int s = 0; s < 2; s++)
            if ((int)bc[d][s] < (int)POISSON_PERIODIC || (int)bc[d][s] > (int)POISSON_DIRICHLET) {
                mg_set_err(err, errlen, "multigrid: invalid condition %d in direction %c",
                           (int)bc[d][s], "xyz"[d]);
                return -1;
            }
        if ((bc[d][0] == POISSON_PERIODIC) != (bc[d][1] == POISSON_PERIODIC)) {
            mg_set_err(err, errlen, "multigrid: periodic must be on both faces of direction %c",
                       "xyz"[d]);
            return -1;
        }
    }
    if ((size_t)grid_cells(g) >= (size_t)INT32_MAX) {
        mg_set_err(err, errlen, "multigrid: grid too large");
        return -1;
    }
    return 0;
}

/* The options create accepts.  Returns 0, or -1 with a message. */
static int check_options(const struct multigrid_options *o, char *err, size_t errlen)
{
    if (o->gamma < 1 || o->gamma > 2) {
        mg_set_err(err, errlen, "multigrid: gamma must be 1 (V-cycle) or 2 (W-cycle)");
        return -1;
    }
    if (o->pre < 0 || o->post < 0 || o->pre + o->post < 1) {
        mg_set_err(err, errlen, "multigrid: need at least one smoothing sweep");
        return -1;
    }
    return 0;
}

double multigrid_memory_estimate(const struct grid *g, const struct multigrid_options *opt)
{
    struct multigrid_options o;
    if (opt)
        o = *opt;
    else
        multigrid_default_options(&o);
    /* the levels as multigrid_create builds them */
    struct grid lev[MAX_LEVELS];
    lev[0] = *g;
    int nlev = 1;
    while (nlev < MAX_LEVELS) {
        int halve[3], n[3];
        if (mg_choose_halving(&lev[nlev - 1], o.coarse_cells, o.full_coarsening, halve) == 0)
            break;
        for (int d = 0; d < 3; d++)
            n[d] = halve[d] ? lev[nlev - 1].n[d] / 2 : lev[nlev - 1].n[d];
        if (grid_init_like(&lev[nlev], n, lev[nlev - 1].len, &lev[nlev - 1]) != 0)
            break;
        nlev++;
    }
    int lines = 0;
    for (int d = 0; d < 3; d++)
        lines += o.smoother == MG_SMOOTH_LINES && g->n[d] > 1;
    double bytes = 0.0;
    for (int l = 0; l < nlev; l++) {
        double points = (double)lev[l].size;
        /* a[3] and r; x and b below the finest; the prolongation's weights
         * above the coarsest; the line factors on all but the coarsest */
        double arrays = 4.0 + (l > 0 ? 2.0 : 0.0) + (l < nlev - 1 ? 3.0 + 2.0 * lines : 0.0);
        bytes += (arrays * sizeof(double) + 1.0) * points; /* and live */
    }
    bytes += 5.0 * (double)g->size * sizeof(double); /* the Krylov work arrays */
    double coarse = (double)grid_cells(&lev[nlev - 1]);
    bytes += (double)lev[nlev - 1].size * (sizeof(ptrdiff_t) + 2.0 * sizeof(int) + 1.0);
    bytes += coarse * (4.0 * log2(coarse + 1.0) + 10.0) * (sizeof(double) + sizeof(int));
    return bytes;
}

int multigrid_create(struct multigrid **out, const struct grid *g, const enum poisson_bc bc[3][2],
                     const struct multigrid_options *opt, char *err, size_t errlen)
{
    if (out)
        *out = NULL;
    if (!out || !g || !bc) {
        mg_set_err(err, errlen, "multigrid: missing argument");
        return -1;
    }
    if (suitesparse_load(err, errlen) != 0) /* the coarsest level's factorisation */
        return -1;
    if (check_problem(g, bc, err, errlen) != 0)
        return -1;
    struct multigrid *mg = calloc(1, sizeof(*mg));
    if (!mg) {
        mg_set_err(err, errlen, "multigrid: out of memory");
        return -1;
    }
    if (opt)
        mg->opt = *opt;
    else
        multigrid_default_options(&mg->opt);
    if (check_options(&mg->opt, err, errlen) != 0) {
        free(mg);
        return -1;
    }
    for (int d = 0; d < 3; d++) {
        mg->bc[d][0] = bc[d][0];
        mg->bc[d][1] = bc[d][1];
        mg->periodic[d] = bc[d][0] == POISSON_PERIODIC;
    }
    int ok = mg_build_levels(mg, g) == 0;
    mg->total_levels = mg->nlev;
    ok = ok && (mg->wr = field_alloc(g)) && (mg->wz = field_alloc(g)) && (mg->wp = field_alloc(g)) &&
         (mg->wq = field_alloc(g)) && (mg->wbest = field_alloc(g));
    ok = ok && mg_coarse_start(mg) == 0;
    if (!ok) {
        multigrid_destroy(mg);
        mg_set_err(err, errlen, "multigrid: out of memory");
        return -1;
    }
    *out = mg;
    return 0;
}

/* What the decomposed solver does not take (multigrid.h).  Returns 0, or
 * -1 with a message. */
static int check_decomposed(const struct grid *g, const struct decomp *dc,
                            const enum poisson_bc bc[3][2], const struct multigrid_options *o,
                            char *err, size_t errlen)
{
    for (int d = 0; d < 3; d++) {
        if (grid_compact(g, d) || g->axis[d]) {
            mg_set_err(err, errlen, "multigrid: a decomposed grid is uniform and not compact");
            return -1;
        }
        if (dc->n_global[d] != g->n[d] ||
            (dc->cart->dims[d] > 1 && dc->cart->periodic[d] != (bc[d][0] == POISSON_PERIODIC))) {
            mg_set_err(err, errlen, "multigrid: the decomposition is not of this grid");
            return -1;
        }
    }
    if (o->smoother != MG_SMOOTH_POINT) {
        mg_set_err(err, errlen, "multigrid: a decomposed grid takes the point smoother only");
        return -1;
    }
    return 0;
}

int multigrid_create_decomposed(struct multigrid **out, const struct grid *g,
                                const struct decomp *dc, const enum poisson_bc bc[3][2],
                                const struct multigrid_options *opt, char *err, size_t errlen)
{
    *out = NULL;
    struct multigrid_options o;
    if (opt)
        o = *opt;
    else
        multigrid_default_options(&o);
    if (check_problem(g, bc, err, errlen) != 0 || check_options(&o, err, errlen) != 0 ||
        check_decomposed(g, dc, bc, &o, err, errlen) != 0)
        return -1;
    struct multigrid *mg = calloc(1, sizeof(*mg));
    if (!mg) {
        mg_set_err(err, errlen, "multigrid: out of memory");
        return -1;
    }
    mg->opt = o;
    for (int d = 0; d < 3; d++) {
        mg->bc[d][0] = bc[d][0];
        mg->bc[d][1] = bc[d][1];
        mg->periodic[d] = bc[d][0] == POISSON_PERIODIC;
    }
    int ok = mg_build_levels_decomposed(mg, g, dc) == 0;
    const struct grid *g0 = &mg->lev[0].g;
    ok = ok && (mg->wr = field_alloc(g0)) && (mg->wz = field_alloc(g0)) &&
         (mg->wp = field_alloc(g0)) && (mg->wq = field_alloc(g0)) && (mg->wbest = field_alloc(g0));
    ok = ok && (mg->gx = field_alloc(&mg->gg)) && (mg->gb = field_alloc(&mg->gg)) &&
         (mg->gscratch = malloc(decomp_gather_len(&mg->dlev[mg->nlev - 1]) * sizeof(double)));
    if (!ok) {
        multigrid_destroy(mg);
        mg_set_err(err, errlen, "multigrid: out of memory");
        return -1;
    }
    if (multigrid_create(&mg->sub, &mg->gg, bc, &o, err, errlen) != 0) {
        multigrid_destroy(mg);
        return -1;
    }
    mg->total_levels = mg->nlev - 1 + mg->sub->nlev;
    *out = mg;
    return 0;
}

/* The gathered level's coefficients and mass into the serial multigrid
 * below it, coarsened there (decomposed). */
static void gather_operator(struct multigrid *mg, int with_mass)
{
    struct level *lv = &mg->lev[mg->nlev - 1], *s0 = &mg->sub->lev[0];
    for (int d = 0; d < 3; d++)
        decomp_gather(lv->dc, &lv->g, lv->a[d], &mg->gg, s0->a[d], mg->gscratch);
    for (int l = 0; l < mg->sub->nlev; l++)
        mg->sub->lev[l].m = NULL;
    if (with_mass) {
        for (int l = 0; l < mg->sub->nlev; l++)
            if (!mg->sub->lev[l].mbuf)
                mg->sub->lev[l].mbuf = field_alloc(&mg->sub->lev[l].g);
        decomp_gather(lv->dc, &lv->g, lv->mbuf, &mg->gg, s0->mbuf, mg->gscratch);
        mg_coarsen_mass(mg->sub);
    }
    mg_coarsen_faces(mg->sub);
}

/* ---- the operator --------------------------------------------------------------- */

int multigrid_set_coefficients(struct multigrid *mg, double *const a[3], char *err,
                               size_t errlen)
{
    return multigrid_set_operator(mg, a, NULL, err, errlen);
}

int multigrid_set_operator(struct multigrid *mg, double *const a[3], const double *mass,
                           char *err, size_t errlen)
{
    if (multigrid_set_operator_deferred(mg, a, mass, err, errlen) != 0)
        return -1;
    return multigrid_finish_operator(mg, err, errlen);
}

int multigrid_set_operator_deferred(struct multigrid *mg, double *const a[3], const double *mass,
                                    char *err, size_t errlen)
{
    mg->ready = 0;
    mg->pending = 0;
    long bad = mg_set_mass(mg, mass, err, errlen) != 0;
    if (mg->sub) /* every rank returns alike */
        comm_sum_long(&bad, 1);
    if (bad)
        return -1;
    if (mg_set_faces(mg, a, err, errlen) != 0)
        return -1;
    if (mg->sub) {
        gather_operator(mg, mass != NULL);
        mg->sub->ready = 0;
        if (mg_coarse_assemble(mg->sub, err, errlen) != 0)
            return -1;
    } else if (mg_coarse_assemble(mg, err, errlen) != 0) {
        return -1;
    }
    mg->pending = 1;
    return 0;
}

int multigrid_finish_operator(struct multigrid *mg, char *err, size_t errlen)
{
    if (!mg->pending)
        return 0;
    mg->pending = 0;
    if (mg_coarse_numeric(mg->sub ? mg->sub : mg, err, errlen) != 0)
        return -1;
    if (mg->sub)
        mg->sub->ready = 1;
    if (mg->opt.smoother == MG_SMOOTH_LINES)
        for (int l = 0; l < mg->nlev - 1; l++)
            for (int k = 0; k < mg->nline_dirs; k++)
                mg_line_factors(&mg->lev[l], k, mg->line_dirs[k]);
    mg->ready = 1;
    return 0;
}

int multigrid_pending(const struct multigrid *mg)
{
    return mg->pending;
}

/* ---- information ---------------------------------------------------------------- */

int multigrid_levels(const struct multigrid *mg)
{
    return mg->nlev;
}

void multigrid_level_size(const struct multigrid *mg, int l, int n[3])
{
    for (int d = 0; d < 3; d++)
        n[d] = mg->lev[l].g.n[d];
}

size_t multigrid_bytes(const struct multigrid *mg)
{
    size_t b = 0;
    for (int l = 0; l < mg->nlev; l++) {
        const struct level *lv = &mg->lev[l];
        size_t f = lv->g.size * sizeof(double);
        b += 4 * f + lv->g.size; /* a[3], r, live */
        if (lv->mbuf)
            b += f;
        for (int k = 0; k < mg->nline_dirs; k++)
            b += lv->lc[k] ? 2 * f : 0;
        if (l > 0)
            b += 2 * f; /* x, b */
        for (int d = 0; d < 3; d++)
            b += 2 * (size_t)lv->g.n[d] * sizeof(int) + (lv->pw[d] ? f : 0); /* pw: not on the coarsest */
    }
    b += 4 * mg->lev[0].g.size * sizeof(double); /* solver work arrays */
    return b + mg_coarse_bytes(mg);
}
