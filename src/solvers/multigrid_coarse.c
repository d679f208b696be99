/* The coarsest level: its matrix assembled on the live cells and factorised
 * by CHOLMOD (multigrid_internal.h). */
#include "solvers/multigrid_internal.h"

#include <stdlib.h>
#include <string.h>

static void quiet_handler(int status, const char *file, int line, const char *message)
{
    (void)status, (void)file, (void)line, (void)message; /* reported through return codes */
}

int mg_coarse_start(struct multigrid *mg)
{
    struct coarse_direct *cs = &mg->cs;
    const size_t csize = mg->lev[mg->nlev - 1].g.size;
    cs->slot = malloc(csize * sizeof(ptrdiff_t));
    cs->row = malloc(csize * sizeof(int));
    cs->pinned = malloc(csize);
    cs->queue = malloc(csize * sizeof(int));
    if (!(cs->slot && cs->row && cs->pinned && cs->queue))
        return -1;
    suitesparse_cholmod_start(&cs->cm);
    cs->started = 1;
    cs->cm.error_handler = quiet_handler;
    cs->cm.print = 0;
    if (mg->opt.coarse_simplicial)
        cs->cm.supernodal = CHOLMOD_SIMPLICIAL;
    return 0;
}

void mg_coarse_free(struct multigrid *mg)
{
    struct coarse_direct *cs = &mg->cs;
    if (cs->started) {
        suitesparse.cholmod_free_sparse(&cs->A, &cs->cm);
        suitesparse.cholmod_free_factor(&cs->L, &cs->cm);
        suitesparse.cholmod_free_dense(&cs->B, &cs->cm);
        suitesparse.cholmod_free_dense(&cs->X, &cs->cm);
        suitesparse.cholmod_free_dense(&cs->Y, &cs->cm);
        suitesparse.cholmod_free_dense(&cs->E, &cs->cm);
        suitesparse.cholmod_finish(&cs->cm);
    }
    free(cs->slot);
    free(cs->row);
    free(cs->pinned);
    free(cs->queue);
    free(cs->pattern);
}

size_t mg_coarse_bytes(const struct multigrid *mg)
{
    const size_t cells = mg->lev[mg->nlev - 1].g.size;
    size_t b = cells * (sizeof(ptrdiff_t) + 2 * sizeof(int) + 1);
    if (mg->cs.started)
        b += mg->cs.cm.memory_inuse;
    return b;
}

/* Neighbour slot of cell (c) across its face (d, side s = -1/+1) inside the
 * level, wrapping periodic directions; -1 across a non-periodic boundary. */
static ptrdiff_t neighbour_slot(const struct multigrid *mg, const struct grid *g, const int c[3],
                                int d, int s)
{
    int q[3] = {c[0], c[1], c[2]};
    q[d] += s;
    if (q[d] < 0 || q[d] >= g->n[d]) {
        if (!mg->periodic[d])
            return -1;
        q[d] = q[d] < 0 ? g->n[d] - 1 : 0;
    }
    return grid_idx(g, q[0], q[1], q[2]);
}

/* Coupling coefficient w of cell c's face (d, s). */
static double face_weight(const struct level *lv, const int c[3], int d, int s)
{
    const struct grid *g = &lv->g;
    ptrdiff_t p = grid_idx(g, c[0], c[1], c[2]);
    return lv->ih2[d] * lv->a[d][s < 0 ? p : p + g->stride[d]];
}

/* The rows: one per live cell of the coarsest level, in field order. */
static long number_rows(struct coarse_direct *cs, const struct level *lv)
{
    const struct grid *g = &lv->g;
    long n = 0;
    for (size_t p = 0; p < g->size; p++)
        cs->row[p] = -1;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                if (lv->live[p]) {
                    cs->slot[n] = p;
                    cs->row[p] = (int)n++;
                }
            }
    return n;
}

/* The cell indices of field slot p. */
static void slot_cell(const struct grid *g, ptrdiff_t p, int c[3])
{
    grid_slot_index(g, p, c);
}

/* Each connected component of live cells that neither a Dirichlet face nor
 * a mass term holds is singular (constants): its first row is pinned
 * (pinned[r] = 1), found by breadth-first search. */
static void pin_floating(const struct multigrid *mg, struct coarse_direct *cs,
                         const struct level *lv)
{
    const struct grid *g = &lv->g;
    const long n = cs->n;
    for (long r = 0; r < n; r++)
        cs->pinned[r] = 2; /* unvisited */
    for (long r0 = 0; r0 < n; r0++) {
        if (cs->pinned[r0] != 2)
            continue;
        long head = 0, tail = 0;
        int held = 0; /* a Dirichlet face or a mass term holds the component */
        cs->queue[tail++] = (int)r0;
        cs->pinned[r0] = 0;
        while (head < tail) {
            long r = cs->queue[head++];
            ptrdiff_t p = cs->slot[r];
            int c[3];
            slot_cell(g, p, c);
            if (lv->m && lv->m[p] > 0.0)
                held = 1;
            for (int d = 0; d < 3; d++)
                for (int s = -1; s <= 1; s += 2) {
                    double w = face_weight(lv, c, d, s);
                    if (!(w > 0.0))
                        continue;
                    ptrdiff_t q = neighbour_slot(mg, g, c, d, s);
                    if (q < 0) {
                        held = 1; /* a non-periodic boundary face with a > 0: Dirichlet */
                        continue;
                    }
                    int rq = cs->row[q];
                    if (rq >= 0 && cs->pinned[rq] == 2) {
                        cs->pinned[rq] = 0;
                        cs->queue[tail++] = rq;
                    }
                }
        }
        if (!held)
            cs->pinned[r0] = 1;
    }
}

/* The upper triangle of -L (stype 1), a pinned row an identity row and
 * column; duplicates (two periodic faces between the same pair of cells)
 * are summed by the conversion.  NULL: out of memory. */
static cholmod_sparse *assemble_matrix(const struct multigrid *mg, struct coarse_direct *cs,
                                       const struct level *lv)
{
    const struct grid *g = &lv->g;
    const long n = cs->n;
    size_t nzmax = (size_t)n * 4;
    cholmod_triplet *T = suitesparse.cholmod_allocate_triplet((size_t)n, (size_t)n, nzmax, 1,
                                                              CHOLMOD_REAL, &cs->cm);
    if (!T)
        return NULL;
    int *Ti = T->i, *Tj = T->j;
    double *Tx = T->x;
    size_t nz = 0;
    for (long r = 0; r < n; r++) {
        ptrdiff_t p = cs->slot[r];
        int c[3];
        slot_cell(g, p, c);
        double D = 0.0;
        for (int d = 0; d < 3; d++)
            for (int s = -1; s <= 1; s += 2) {
                double w = face_weight(lv, c, d, s);
                D += w;
                if (s < 0 || !(w > 0.0))
                    continue;
                ptrdiff_t q = neighbour_slot(mg, g, c, d, s);
                if (q < 0)
                    continue;
                int rq = cs->row[q];
                if (rq < 0 || cs->pinned[r] || cs->pinned[rq])
                    continue;
                Ti[nz] = (int)(r < rq ? r : rq);
                Tj[nz] = (int)(r < rq ? rq : r);
                Tx[nz] = -w;
                nz++;
            }
        if (lv->m)
            D += lv->m[p];
        Ti[nz] = Tj[nz] = (int)r;
        Tx[nz] = cs->pinned[r] ? 1.0 : D;
        nz++;
    }
    T->nnz = nz;
    cholmod_sparse *A = suitesparse.cholmod_triplet_to_sparse(T, nz, &cs->cm);
    suitesparse.cholmod_free_triplet(&T, &cs->cm);
    return A;
}

/* The analysis (the fill-reducing ordering, the supernodes) depends on the
 * pattern only, which a new density on the same cells keeps: a coarsest
 * level as large as a whole small grid (pressure.c) is refactorised every
 * step, and is analysed only when its pattern changes. */
static void analyse_if_new(struct coarse_direct *cs, cholmod_sparse *A)
{
    const long n = cs->n;
    size_t len = (size_t)n + 1 + (size_t)((const int *)A->p)[n];
    int same = cs->L && cs->pattern && cs->pattern_len == len &&
               memcmp(cs->pattern, A->p, ((size_t)n + 1) * sizeof(int)) == 0 &&
               memcmp(cs->pattern + n + 1, A->i, (len - (size_t)n - 1) * sizeof(int)) == 0;
    if (same)
        return;
    /* and the solves' workspace is set up again after the factorisation */
    suitesparse.cholmod_free_dense(&cs->B, &cs->cm);
    suitesparse.cholmod_free_factor(&cs->L, &cs->cm);
    cs->L = suitesparse.cholmod_analyze(A, &cs->cm);
    free(cs->pattern);
    cs->pattern_len = 0;
    if ((cs->pattern = malloc(len * sizeof(int)))) {
        memcpy(cs->pattern, A->p, ((size_t)n + 1) * sizeof(int));
        memcpy(cs->pattern + n + 1, A->i, (len - (size_t)n - 1) * sizeof(int));
        cs->pattern_len = len;
    }
}

/* Assembles -L of the coarsest level on its live cells (cs->A) and, when
 * its pattern is new, analyses it; mg_coarse_numeric factorises it.  The
 * analysis (the AMD or METIS ordering) stays on the caller's thread: only
 * the numeric factorisation may run beside other work (multigrid.h,
 * multigrid_finish_operator).  A component that nothing holds has its first
 * cell pinned to 0 (identity row and column), which leaves the other rows a
 * nonsingular M-matrix and, for a compatible right-hand side, the same
 * solution up to that component's constant. */
int mg_coarse_assemble(struct multigrid *mg, char *err, size_t errlen)
{
    struct coarse_direct *cs = &mg->cs;
    suitesparse.cholmod_free_sparse(&cs->A, &cs->cm);
    const struct level *lv = &mg->lev[mg->nlev - 1];
    cs->n = number_rows(cs, lv);
    if (cs->n == 0)
        return 0;
    pin_floating(mg, cs, lv);
    cholmod_sparse *A = assemble_matrix(mg, cs, lv);
    if (!A) {
        mg_set_err(err, errlen, "multigrid: out of memory (coarsest level)");
        return -1;
    }
    analyse_if_new(cs, A);
    cs->A = A;
    if (!cs->L) {
        mg_set_err(err, errlen, "multigrid: the coarsest level's analysis failed (status %d)",
                   cs->cm.status);
        return -1;
    }
    return 0;
}

/* The numeric factorisation of what mg_coarse_assemble left in cs->A, and the
 * solves' workspace. */
int mg_coarse_numeric(struct multigrid *mg, char *err, size_t errlen)
{
    struct coarse_direct *cs = &mg->cs;
    if (cs->n == 0)
        return 0;
    const size_t n = (size_t)cs->n;
    struct suitesparse_serial serial = suitesparse_serial_begin();
    int ok = cs->A && cs->L && suitesparse.cholmod_factorize(cs->A, cs->L, &cs->cm) &&
             cs->cm.status == CHOLMOD_OK;
    suitesparse_serial_end(serial);
    suitesparse.cholmod_free_sparse(&cs->A, &cs->cm);
    if (!ok) {
        mg_set_err(err, errlen, "multigrid: the coarsest factorisation failed (status %d)",
                   cs->cm.status);
        return -1;
    }
    if (cs->B && cs->X)
        return 0; /* the solves' workspace is the right size already (the pattern's) */
    suitesparse.cholmod_free_dense(&cs->B, &cs->cm);
    cs->B = suitesparse.cholmod_zeros(n, 1, CHOLMOD_REAL, &cs->cm);
    if (!cs->B) {
        mg_set_err(err, errlen, "multigrid: out of memory (coarsest level)");
        return -1;
    }
    /* one solve here lets cholmod_solve2 allocate its workspace (X, Y, E) now */
    serial = suitesparse_serial_begin();
    suitesparse.cholmod_solve2(CHOLMOD_A, cs->L, cs->B, NULL, &cs->X, NULL, &cs->Y, &cs->E, &cs->cm);
    suitesparse_serial_end(serial);
    if (!cs->X) {
        mg_set_err(err, errlen, "multigrid: out of memory (coarsest level)");
        return -1;
    }
    return 0;
}

/* x = L^-1 b on the coarsest level: gather, solve, scatter (a distributed
 * version gathers the coarsest box to one rank here; nowhere else). */
void mg_coarse_solve(struct multigrid *mg)
{
    struct coarse_direct *cs = &mg->cs;
    struct level *lv = &mg->lev[mg->nlev - 1];
    mg_zero_interior(lv, lv->x);
    if (cs->n == 0)
        return;
    double *B = cs->B->x;
    for (long r = 0; r < cs->n; r++)
        B[r] = cs->pinned[r] ? 0.0 : -lv->b[cs->slot[r]];
    struct suitesparse_serial serial = suitesparse_serial_begin();
    suitesparse.cholmod_solve2(CHOLMOD_A, cs->L, cs->B, NULL, &cs->X, NULL, &cs->Y, &cs->E, &cs->cm);
    suitesparse_serial_end(serial);
    const double *X = cs->X->x;
    for (long r = 0; r < cs->n; r++)
        lv->x[cs->slot[r]] = X[r];
}
