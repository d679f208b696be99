/* Probing a matrix-free operator into a sparse matrix (probe_matrix.h). */
#include <stdio.h>
#include <math.h>
#include <stdlib.h>
#include <stdint.h>
#include <string.h>
#include "solvers/probe_matrix.h"

#define MAX_PROBES 600
#define NO_ENTRY 255 /* entry's mark of a colour without a column in a row */

struct probe_matrix {
    const struct grid *g;
    int periodic[3];
    int period[3];             /* colour period per direction */
    int reach;
    long n;                    /* unknowns */
    int *index[3];             /* unknown number of each field slot, or -1 */
    int *comp;                 /* component of unknown k */
    int present;               /* the components with unknowns (bit c) */
    ptrdiff_t *slot;           /* field slot of unknown k */
    int *pos;                  /* i, j, k of unknown k (3 per unknown) */
    /* the unknowns each probe sets, by probe: members[start[q] .. start[q+1]) */
    long *start, *members;
    /* an assembly's entries, column by column as the probes find them:
     * the rows and values (trow, tval; tcap allocated), and the columns
     * in their order of appearance, column gcol[m] holding the entries
     * gstart[m] .. gstart[m + 1] (a column's entries all come from its
     * probe, together) */
    int *trow;
    double *tval;
    size_t tcap;
    int *gcol;
    size_t *gstart;
    /* a learnt colouring (probe_matrix_learn), or none (ncolours 0): the
     * columns by colour, cmembers[cstart[q] .. cstart[q+1]); the learnt
     * pattern by rows, columns ascending; and for each colour q and row r
     * the place in its row of the row's column of colour q, entry[q n + r],
     * or NO_ENTRY (a colour has at most one column in a row): a probe's
     * response goes straight to its entries, row by row */
    int ncolours;
    long *cstart, *cmembers;
    int *pat_rowptr, *pat_col;
    unsigned char *entry;
    int *rows;                 /* column_rows' buffers */
    ptrdiff_t *row_slot;
    int *row_comp;
    long broken;               /* assemblies the learnt pattern did not hold */
    /* a colouring of the columns of some components only, from the learnt
     * pattern (subset_colouring): components (bit c; 0: none kept), the
     * columns by colour and the places as above */
    int sub_mask, sub_ncolours;
    long *sub_cstart, *sub_cmembers;
    unsigned char *sub_entry;
};

/* Colours need 2 reach + 1 distinct residues in a row's reach; a periodic
 * direction's period must also divide its cell count, and one of at most
 * 2 reach + 1 cells holds every cell in its own colour. */
static int colour_period(int n, int periodic, int reach)
{
    int p = 2 * reach + 1;
    if (!periodic)
        return p;
    if (n <= p)
        return n;
    for (int q = p; q <= n; q++)
        if (n % q == 0)
            return q;
    return n;
}

int probe_matrix_probes_for(const struct grid *g, const int periodic[3], int reach)
{
    int p = 3;
    for (int d = 0; d < 3; d++)
        p *= colour_period(g->n[d], periodic[d], reach);
    return p;
}

int probe_matrix_max_probes(void) { return MAX_PROBES; }

long probe_matrix_unknowns(const struct probe_matrix *pm) { return pm->n; }

/* The structured colouring's probes. */
static int structured_probes(const struct probe_matrix *pm)
{
    return 3 * pm->period[0] * pm->period[1] * pm->period[2];
}

int probe_matrix_subset_probes(const struct probe_matrix *pm) { return pm->sub_ncolours; }

double probe_matrix_components_norm(const struct probe_matrix *pm, double *const r[3],
                                    int components)
{
    double d = 0.0;
    for (long k = 0; k < pm->n; k++)
        if (components >> pm->comp[k] & 1)
            d += r[pm->comp[k]][pm->slot[k]] * r[pm->comp[k]][pm->slot[k]];
    return sqrt(d);
}

int probe_matrix_probes(const struct probe_matrix *pm)
{
    return pm->ncolours > 0 ? pm->ncolours : structured_probes(pm);
}

long probe_matrix_broken(const struct probe_matrix *pm) { return pm->broken; }

const int *probe_matrix_components(const struct probe_matrix *pm) { return pm->comp; }

/* The probe that sets unknown u: its component and its position's residues
 * (the order of probe_matrix_assemble's loops). */
static int probe_of(const struct probe_matrix *pm, long u)
{
    const int *at = pm->pos + 3 * u;
    return ((pm->comp[u] * pm->period[0] + at[0] % pm->period[0]) * pm->period[1] +
            at[1] % pm->period[1]) * pm->period[2] + at[2] % pm->period[2];
}

/* The most rows column_rows gives: 3 components over the reach's box. */
static int max_column_rows(const struct probe_matrix *pm)
{
    int m = 3;
    for (int d = 0; d < 3; d++) {
        int span = 2 * pm->reach + 1;
        if (pm->periodic[d] && pm->g->n[d] < span)
            span = pm->g->n[d];
        m *= span;
    }
    return m;
}

int probe_matrix_create(struct probe_matrix **out, const struct grid *g, const int periodic[3],
                        const struct box act[3], int reach, char *err, size_t errlen)
{
    struct probe_matrix *pm = calloc(1, sizeof *pm);
    if (!pm) {
        snprintf(err, errlen, "probed matrix: out of memory");
        return -1;
    }
    pm->g = g;
    pm->reach = reach;
    for (int d = 0; d < 3; d++) {
        pm->periodic[d] = periodic[d];
        pm->period[d] = colour_period(g->n[d], periodic[d], reach);
    }
    if (structured_probes(pm) > MAX_PROBES) {
        snprintf(err, errlen,
                 "probed matrix: %d probes needed (periodic cell counts without a small "
                 "divisor); use solver.preconditioner = line",
                 structured_probes(pm));
        free(pm);
        return -1;
    }
    for (int c = 0; c < 3; c++) {
        const struct box *b = &act[c];
        pm->n += (long)(b->hi[0] - b->lo[0]) * (b->hi[1] - b->lo[1]) * (b->hi[2] - b->lo[2]);
    }
    int ok = 1;
    for (int c = 0; c < 3; c++) {
        pm->index[c] = malloc(g->size * sizeof(int));
        ok &= pm->index[c] != NULL;
    }
    pm->comp = malloc((size_t)pm->n * sizeof(int));
    pm->slot = malloc((size_t)pm->n * sizeof(ptrdiff_t));
    pm->pos = malloc((size_t)pm->n * 3 * sizeof(int));
    ok &= pm->comp && pm->slot && pm->pos;
    if (!ok) {
        probe_matrix_destroy(pm);
        snprintf(err, errlen, "probed matrix: out of memory");
        return -1;
    }
    long k = 0;
    for (int c = 0; c < 3; c++) {
        for (size_t p = 0; p < g->size; p++)
            pm->index[c][p] = -1;
        const struct box *b = &act[c];
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++)
                for (int kk = b->lo[2]; kk < b->hi[2]; kk++, k++) {
                    ptrdiff_t p = grid_idx(g, i, j, kk);
                    pm->index[c][p] = (int)k;
                    pm->comp[k] = c;
                    pm->present |= 1 << c;
                    pm->slot[k] = p;
                    pm->pos[3 * k] = i;
                    pm->pos[3 * k + 1] = j;
                    pm->pos[3 * k + 2] = kk;
                }
    }
    /* the probes' members by a counting sort of the unknowns on their probe */
    int nprobes = structured_probes(pm);
    pm->start = calloc((size_t)nprobes + 1, sizeof(long));
    pm->members = malloc((size_t)(pm->n > 0 ? pm->n : 1) * sizeof(long));
    pm->rows = malloc((size_t)max_column_rows(pm) * sizeof(int));
    pm->row_slot = malloc((size_t)max_column_rows(pm) * sizeof(ptrdiff_t));
    pm->row_comp = malloc((size_t)max_column_rows(pm) * sizeof(int));
    if (!pm->start || !pm->members || !pm->rows || !pm->row_slot || !pm->row_comp) {
        probe_matrix_destroy(pm);
        snprintf(err, errlen, "probed matrix: out of memory");
        return -1;
    }
    for (long u = 0; u < pm->n; u++)
        pm->start[probe_of(pm, u) + 1]++;
    for (int q = 0; q < nprobes; q++)
        pm->start[q + 1] += pm->start[q];
    for (long u = 0; u < pm->n; u++)
        pm->members[pm->start[probe_of(pm, u)]++] = u;
    for (int q = nprobes; q > 0; q--)
        pm->start[q] = pm->start[q - 1];
    pm->start[0] = 0;
    *out = pm;
    return 0;
}

void probe_matrix_destroy(struct probe_matrix *pm)
{
    if (!pm)
        return;
    for (int c = 0; c < 3; c++)
        free(pm->index[c]);
    free(pm->comp);
    free(pm->slot);
    free(pm->pos);
    free(pm->start);
    free(pm->members);
    free(pm->rows);
    free(pm->row_slot);
    free(pm->row_comp);
    free(pm->trow);
    free(pm->tval);
    free(pm->gcol);
    free(pm->gstart);
    probe_matrix_forget(pm);
    free(pm);
}

/* Drops the colouring of some components' columns (subset_colouring). */
static void forget_subset(struct probe_matrix *pm)
{
    free(pm->sub_cstart);
    free(pm->sub_cmembers);
    free(pm->sub_entry);
    pm->sub_cstart = pm->sub_cmembers = NULL;
    pm->sub_entry = NULL;
    pm->sub_mask = pm->sub_ncolours = 0;
}

void probe_matrix_forget(struct probe_matrix *pm)
{
    free(pm->cstart);
    free(pm->cmembers);
    free(pm->pat_rowptr);
    free(pm->pat_col);
    free(pm->entry);
    pm->cstart = pm->cmembers = NULL;
    pm->pat_rowptr = pm->pat_col = NULL;
    pm->entry = NULL;
    pm->ncolours = 0;
    forget_subset(pm);
}

static int grow_triplets(struct probe_matrix *pm, size_t cap)
{
    int *r = realloc(pm->trow, cap * sizeof(int));
    if (r)
        pm->trow = r;
    double *v = realloc(pm->tval, cap * sizeof(double));
    if (v)
        pm->tval = v;
    if (!r || !v)
        return -1;
    pm->tcap = cap;
    return 0;
}

static void free_entries(struct probe_matrix *pm)
{
    free(pm->trow);
    free(pm->tval);
    free(pm->gcol);
    free(pm->gstart);
    pm->trow = pm->gcol = NULL;
    pm->tval = NULL;
    pm->gstart = NULL;
    pm->tcap = 0;
}

/* Appends entry (row r, value v) of the current column. */
static int add_entry(struct probe_matrix *pm, size_t *nz, int r, double v)
{
    if (*nz == pm->tcap && grow_triplets(pm, 2 * pm->tcap) != 0)
        return -1;
    pm->trow[*nz] = r;
    pm->tval[*nz] = v;
    (*nz)++;
    return 0;
}

/* The rows column col may reach, in a fixed order, into pm->rows: the
 * unknowns of any component within reach of its position (every position
 * of a periodic direction that is its own colour period and no longer than
 * the stencil), and their field slots and components in row_slot and
 * row_comp.  Returns their count (at most 3 (2 reach + 1)^3). */
static int column_rows(struct probe_matrix *pm, long col)
{
    const struct grid *g = pm->g;
    const int *at = pm->pos + 3 * col;
    int lo[3], hi[3], nr = 0;
    for (int d = 0; d < 3; d++) {
        int n = g->n[d];
        if (pm->periodic[d] && pm->period[d] == n && n <= 2 * pm->reach + 1) {
            lo[d] = 0;
            hi[d] = n - 1;
        } else {
            lo[d] = at[d] - pm->reach;
            hi[d] = at[d] + pm->reach;
            if (!pm->periodic[d]) { /* the ghost layer's unknowns: none, index -1 */
                lo[d] = lo[d] < -1 ? -1 : lo[d];
                hi[d] = hi[d] > n ? n : hi[d];
            }
        }
    }
    for (int t0 = lo[0]; t0 <= hi[0]; t0++)
        for (int t1 = lo[1]; t1 <= hi[1]; t1++)
            for (int t2 = lo[2]; t2 <= hi[2]; t2++) {
                int t[3] = {t0, t1, t2};
                for (int d = 0; d < 3; d++)
                    if (pm->periodic[d])
                        t[d] = (t[d] % g->n[d] + g->n[d]) % g->n[d];
                ptrdiff_t p = grid_idx(g, t[0], t[1], t[2]);
                for (int m = 0; m < 3; m++)
                    if (pm->index[m][p] >= 0) {
                        pm->row_slot[nr] = p;
                        pm->row_comp[nr] = m;
                        pm->rows[nr++] = pm->index[m][p];
                    }
            }
    return nr;
}

/* The entries of column col: every row it may reach, where no other column
 * of its probe reaches (the structured colouring). */
static int probe_column(struct probe_matrix *pm, long col, double *resp[3], int lower,
                        size_t *nz)
{
    int nr = column_rows(pm, col);
    for (int b = 0; b < nr; b++) {
        int r = pm->rows[b];
        if (lower && col > r)
            continue;
        double v = resp[pm->row_comp[b]][pm->row_slot[b]];
        if (v != 0.0 && add_entry(pm, nz, r, v) != 0)
            return -1;
    }
    return 0;
}

/* resp = op(the probe of members[from .. to)), probe its work. */
static void apply_probe(const struct probe_matrix *pm, operator_fn op, void *ctx,
                        const long *members, long from, long to, double *probe[3],
                        double *resp[3])
{
    for (int m = 0; m < 3; m++)
        memset(probe[m], 0, pm->g->size * sizeof(double));
    for (long a = from; a < to; a++) {
        long u = members[a];
        probe[pm->comp[u]][pm->slot[u]] = 1.0;
    }
    op(ctx, probe, resp);
}

/* Probes op colour by colour of the structured colouring into the
 * triplets.  Returns 0, or -1 when memory runs out. */
static int probe_all(struct probe_matrix *pm, operator_fn op, void *ctx, double *probe[3],
                     double *resp[3], int lower, size_t *nzp, size_t *ngp)
{
    size_t nz = 0, ng = 0;
    for (int q = 0; q < structured_probes(pm); q++) {
        if (pm->start[q] == pm->start[q + 1])
            continue;
        apply_probe(pm, op, ctx, pm->members, pm->start[q], pm->start[q + 1], probe, resp);
        for (long a = pm->start[q]; a < pm->start[q + 1]; a++) {
            long col = pm->members[a];
            pm->gcol[ng] = (int)col;
            pm->gstart[ng++] = nz;
            if (probe_column(pm, col, resp, lower, &nz) != 0)
                return -1;
        }
    }
    *nzp = nz;
    *ngp = ng;
    return 0;
}

static int subset_colouring(struct probe_matrix *pm, int components);

/* Probes op colour by colour of the learnt colouring, each response
 * straight into the learnt pattern's entries of A, row by row; then drops
 * the exact zeros (and with lower the upper triangle) in place.  Every
 * column (components 7), or the given components' columns alone (their
 * colouring: subset_colouring), the others' rows then the identity's;
 * *probed says which.  Returns 0, -1 when memory runs out, 1 when a
 * response reaches a row where its colour has no column in the pattern
 * (the operator left the pattern). */
static int learnt_assemble(struct probe_matrix *pm, operator_fn op, void *ctx,
                           double *probe[3], double *resp[3], int lower, int components,
                           struct csr_matrix *A, int *probed)
{
    const int n = (int)pm->n;
    const int *rp = pm->pat_rowptr;
    if (csr_reserve(A, n, (size_t)rp[n]) != 0)
        return -1;
    int ncolours = pm->ncolours;
    const long *cstart = pm->cstart, *cmembers = pm->cmembers;
    const unsigned char *entry = pm->entry;
    int part = components != 7;
    /* a left-out row's identity entry takes its first place in the
     * pattern, compacted in place: a row without one takes the whole */
    for (int r = 0; part && r < n; r++)
        if (!(components >> pm->comp[r] & 1) && rp[r + 1] == rp[r])
            part = 0;
    *probed = part ? components : 7;
    if (part) {
        if (subset_colouring(pm, components) != 0)
            return -1;
        ncolours = pm->sub_ncolours;
        cstart = pm->sub_cstart;
        cmembers = pm->sub_cmembers;
        entry = pm->sub_entry;
    }
    for (int q = 0; q < ncolours; q++) {
        apply_probe(pm, op, ctx, cmembers, cstart[q], cstart[q + 1], probe, resp);
        const unsigned char *at = entry + (size_t)q * n;
        int outside = 0;
        /* on the threads: a serial loop here was a tenth of the heap's
         * probing at 140 x 200, the other thread idle */
#pragma omp parallel for schedule(static) reduction(| : outside) if (n > 20000)
        for (int r = 0; r < n; r++) {
            double v = resp[pm->comp[r]][pm->slot[r]];
            if (at[r] != NO_ENTRY)
                A->val[rp[r] + at[r]] = v;
            else if (v != 0.0)
                outside = 1;
        }
        if (outside)
            return 1;
    }
    int w = 0;
    for (int r = 0; r < n; r++) {
        int e0 = rp[r];
        A->rowptr[r] = w;
        if (part && !(components >> pm->comp[r] & 1)) {
            /* a component left out: its row the identity's (w <= e0: the
             * rows before gave at most their places) */
            A->col[w] = r;
            A->val[w++] = 1.0;
            continue;
        }
        for (int e = e0; e < rp[r + 1]; e++) {
            int c = pm->pat_col[e];
            /* (a column left out holds a value of an earlier assembly) */
            if (A->val[e] == 0.0 || (lower && c > r) || (part && !(components >> pm->comp[c] & 1)))
                continue;
            A->col[w] = c;
            A->val[w++] = A->val[e];
        }
    }
    A->rowptr[n] = w;
    return 0;
}

int probe_matrix_assemble(struct probe_matrix *pm, operator_fn op, void *ctx, double *probe[3],
                          double *resp[3], int lower, struct csr_matrix *A)
{
    int probed;
    return probe_matrix_assemble_components(pm, op, ctx, probe, resp, lower, 7, A, &probed);
}

int probe_matrix_assemble_components(struct probe_matrix *pm, operator_fn op, void *ctx,
                                     double *probe[3], double *resp[3], int lower,
                                     int components, struct csr_matrix *A, int *probed)
{
    /* a mask of every component present is the whole */
    components &= pm->present;
    if (components == pm->present || components == 0)
        components = 7;
    *probed = 7;
    if (pm->ncolours > 0) {
        int rc = learnt_assemble(pm, op, ctx, probe, resp, lower, components, A, probed);
        if (rc <= 0)
            return rc;
        *probed = 7;
        /* the operator left the learnt pattern: the structured colouring,
         * which needs no pattern, from now on */
        pm->broken++;
        probe_matrix_forget(pm);
    }
    if (!pm->tcap && grow_triplets(pm, (size_t)pm->n * (lower ? 16 : 40) + 16) != 0)
        return -1;
    if (!pm->gcol) {
        pm->gcol = malloc(((size_t)pm->n + 1) * sizeof(int));
        pm->gstart = malloc(((size_t)pm->n + 1) * sizeof(size_t));
        if (!pm->gcol || !pm->gstart) {
            free_entries(pm);
            return -1;
        }
    }
    size_t nz = 0, ng = 0;
    if (probe_all(pm, op, ctx, probe, resp, lower, &nz, &ng) != 0) {
        free_entries(pm);
        return -1;
    }
    pm->gstart[ng] = nz;
    /* rows by a counting sort, the columns taken in ascending order so that
     * each row's come out sorted; every (row, column) comes from exactly
     * one probe.  Each entry's row becomes its place in the rows; the
     * values move there, then the columns, each array allocated when the
     * one before is freed: at most 20 bytes an entry at once (the triplets
     * and a separate matrix held 28, and the peak memory of an AMG step was
     * there) */
    int n = (int)pm->n;
    int *rp = realloc(A->rowptr, ((size_t)n + 1) * sizeof(int));
    int *group = malloc(((size_t)n + 1) * sizeof(int)); /* each column's in gcol */
    if (rp)
        A->rowptr = rp;
    if (!rp || !group) {
        free(group);
        free_entries(pm);
        return -1;
    }
    A->n = n;
    free(A->col);
    free(A->val);
    A->col = NULL;
    A->val = NULL;
    A->cap = 0;
    memset(rp, 0, ((size_t)n + 1) * sizeof(int));
    for (size_t q = 0; q < nz; q++)
        rp[pm->trow[q] + 1]++;
    for (int r = 0; r < n; r++)
        rp[r + 1] += rp[r];
    for (int c = 0; c < n; c++)
        group[c] = -1;
    for (size_t m = 0; m < ng; m++)
        group[pm->gcol[m]] = (int)m;
    for (int c = 0; c < n; c++)
        if (group[c] >= 0)
            for (size_t q = pm->gstart[group[c]]; q < pm->gstart[group[c] + 1]; q++)
                pm->trow[q] = rp[pm->trow[q]]++; /* the entry's place */
    free(group);
    for (int r = n; r > 0; r--)
        rp[r] = rp[r - 1];
    rp[0] = 0;
    size_t cap = nz > 0 ? nz : 1;
    A->val = malloc(cap * sizeof(double));
    if (!A->val) {
        free_entries(pm);
        return -1;
    }
    for (size_t q = 0; q < nz; q++)
        A->val[pm->trow[q]] = pm->tval[q];
    free(pm->tval);
    pm->tval = NULL;
    A->col = malloc(cap * sizeof(int));
    if (!A->col) {
        free_entries(pm);
        return -1;
    }
    for (size_t m = 0; m < ng; m++)
        for (size_t q = pm->gstart[m]; q < pm->gstart[m + 1]; q++)
            A->col[pm->trow[q]] = pm->gcol[m];
    A->cap = cap;
    /* the entries are as large as the matrix: not kept between assemblies */
    free_entries(pm);
    return 0;
}

void probe_matrix_gather(const struct probe_matrix *pm, double *const r[3], double *b)
{
    for (long k = 0; k < pm->n; k++)
        b[k] = r[pm->comp[k]][pm->slot[k]];
}

void probe_matrix_scatter(const struct probe_matrix *pm, const double *x, double *z[3])
{
    for (long k = 0; k < pm->n; k++)
        z[pm->comp[k]][pm->slot[k]] = x[k];
}

/* The unknowns ordered by their faces' positions (doubled: a component's
 * own direction at even coordinates, the others at odd ones), the last
 * direction slowest (first_slowest: the first), so that the greedy
 * colouring sweeps the staggered grid's nodes as one lattice: the velocity
 * components' stencils then tile it like one scalar stencil's (the 2D
 * Picard operator: 9 colours for both components, where the structured
 * colouring gives each its own 9; in the components' order, 18). */
struct keyed {
    long key;
    int u;
};

static int by_key(const void *a, const void *b)
{
    long ka = ((const struct keyed *)a)->key, kb = ((const struct keyed *)b)->key;
    return (ka > kb) - (ka < kb);
}

static int *by_position(const struct probe_matrix *pm, int first_slowest)
{
    int *order = malloc(((size_t)pm->n + 1) * sizeof(int));
    struct keyed *k = malloc(((size_t)pm->n + 1) * sizeof *k);
    if (order && k) {
        for (long u = 0; u < pm->n; u++) {
            long key = 0;
            for (int m = 0; m < 3; m++) {
                int d = first_slowest ? m : 2 - m;
                key = key * (2L * pm->g->n[d] + 4) + 2L * (pm->pos[3 * u + d] + 1) +
                      (pm->comp[u] != d);
            }
            k[u] = (struct keyed){key, (int)u};
        }
        qsort(k, (size_t)pm->n, sizeof *k, by_key);
        for (long u = 0; u < pm->n; u++)
            order[u] = k[u].u;
    } else {
        free(order);
        order = NULL;
    }
    free(k);
    return order;
}

/* The rows of column c in the pattern of the masks (its bits over
 * column_rows), into pm->rows.  Returns their count. */
static int masked_rows(struct probe_matrix *pm, long c, const uint64_t *mask, int words)
{
    int nr = column_rows(pm, c), kept = 0;
    for (int b = 0; b < nr; b++)
        if (mask[(size_t)c * words + b / 64] >> (b % 64) & 1u)
            pm->rows[kept++] = pm->rows[b];
    return kept;
}

/* Column c, whose rows are rows[0 .. nr-1], takes the least colour that no
 * column of those rows (the pattern rowptr, cols) holds yet (seen: work,
 * -1 at first).  Returns it. */
static int take_colour(int c, const int *rows, int nr, const int *rowptr, const int *cols,
                       int *seen, int *colour)
{
    for (int b = 0; b < nr; b++)
        for (int f = rowptr[rows[b]]; f < rowptr[rows[b] + 1]; f++)
            if (colour[cols[f]] >= 0)
                seen[colour[cols[f]]] = c;
    int k = 0;
    while (seen[k] == c)
        k++;
    return colour[c] = k;
}

/* Greedy colouring of the columns in the given order, each taking the
 * least colour that no column sharing a row with it holds (seen: work).
 * Returns the colours. */
static int greedy_colours(struct probe_matrix *pm, const int *order, const uint64_t *mask,
                          int words, const int *rowptr, const int *cols, int *seen, int *colour)
{
    const int n = (int)pm->n;
    int ncolours = 0;
    for (int c = 0; c <= n; c++) {
        seen[c] = -1;
        colour[c] = -1;
    }
    for (long m = 0; m < pm->n; m++) {
        int c = order[m];
        int nr = masked_rows(pm, c, mask, words);
        int k = take_colour(c, pm->rows, nr, rowptr, cols, seen, colour);
        ncolours = k + 1 > ncolours ? k + 1 : ncolours;
    }
    return ncolours;
}

/* The columns by colour (cstart, cmembers) and each colour's place in each
 * row of the pattern (entry, NO_ENTRY where it has none) for colour[] (-1:
 * a column left without one).  Returns 0, or -1 when memory runs out
 * (nothing allocated then). */
static int colour_tables(const struct probe_matrix *pm, const int *colour, int ncolours,
                         const int *rowptr, const int *cols, long **cstart_out,
                         long **cmembers_out, unsigned char **entry_out)
{
    const int n = (int)pm->n;
    long *cstart = calloc((size_t)ncolours + 1, sizeof(long));
    long *cmembers = malloc(((size_t)n + 1) * sizeof(long));
    unsigned char *entry = malloc((size_t)ncolours * n + 1);
    if (!cstart || !cmembers || !entry) {
        free(cstart);
        free(cmembers);
        free(entry);
        return -1;
    }
    for (int c = 0; c < n; c++)
        if (colour[c] >= 0)
            cstart[colour[c] + 1]++;
    for (int q = 0; q < ncolours; q++)
        cstart[q + 1] += cstart[q];
    for (int c = 0; c < n; c++)
        if (colour[c] >= 0)
            cmembers[cstart[colour[c]]++] = c;
    for (int q = ncolours; q > 0; q--)
        cstart[q] = cstart[q - 1];
    cstart[0] = 0;
    memset(entry, NO_ENTRY, (size_t)ncolours * n);
    for (int r = 0; r < n; r++)
        for (int e = rowptr[r]; e < rowptr[r + 1]; e++)
            if (colour[cols[e]] >= 0)
                entry[(size_t)colour[cols[e]] * n + r] = (unsigned char)(e - rowptr[r]);
    *cstart_out = cstart;
    *cmembers_out = cmembers;
    *entry_out = entry;
    return 0;
}

/* A greedy colouring of the given components' columns over the learnt
 * pattern, in the order of the faces' positions, kept for the next
 * assemblies of the same components.  Returns 0, or -1 when memory runs
 * out. */
static int subset_colouring(struct probe_matrix *pm, int components)
{
    if (pm->sub_mask == components)
        return 0;
    forget_subset(pm);
    const int n = (int)pm->n;
    const int *rp = pm->pat_rowptr, *pc = pm->pat_col;
    /* the pattern by columns (each column's rows) */
    int *crp = calloc((size_t)n + 2, sizeof(int));
    int *crow = malloc(((size_t)rp[n] + 1) * sizeof(int));
    int *colour = malloc(((size_t)n + 1) * sizeof(int));
    int *seen = malloc(((size_t)n + 1) * sizeof(int));
    int *order = by_position(pm, 0);
    int ok = crp && crow && colour && seen && order;
    int ncolours = 0;
    if (ok) {
        for (int e = 0; e < rp[n]; e++)
            crp[pc[e] + 2]++;
        for (int c = 0; c < n; c++)
            crp[c + 2] += crp[c + 1];
        for (int r = 0; r < n; r++)
            for (int e = rp[r]; e < rp[r + 1]; e++)
                crow[crp[pc[e] + 1]++] = r;
        for (int c = 0; c <= n; c++)
            colour[c] = seen[c] = -1;
        for (long m = 0; m < pm->n; m++) {
            int c = order[m];
            if (!(components >> pm->comp[c] & 1))
                continue;
            int k = take_colour(c, crow + crp[c], crp[c + 1] - crp[c], rp, pc, seen, colour);
            ncolours = k + 1 > ncolours ? k + 1 : ncolours;
        }
        ok = colour_tables(pm, colour, ncolours, rp, pc, &pm->sub_cstart, &pm->sub_cmembers,
                           &pm->sub_entry) == 0;
    }
    if (ok) {
        pm->sub_mask = components;
        pm->sub_ncolours = ncolours;
    }
    free(crp);
    free(crow);
    free(colour);
    free(seen);
    free(order);
    return ok ? 0 : -1;
}

int probe_matrix_learn(struct probe_matrix *pm, operator_fn op, void *ctx, double *probe[3],
                       double *resp[3])
{
    probe_matrix_forget(pm);
    const int n = (int)pm->n;
    const int words = (max_column_rows(pm) + 63) / 64;
    /* the pattern straight into the columns' masks, probe by probe of the
     * structured colouring: no entries are stored, so learning needs less
     * memory than an assembly */
    uint64_t *mask = calloc((size_t)n * words + 1, sizeof(uint64_t));
    int *rowptr = calloc((size_t)n + 1, sizeof(int));
    int *colour = malloc(((size_t)n + 1) * sizeof(int));
    int *seen = malloc(((size_t)n + 1) * sizeof(int));
    int *cols = NULL, *order = NULL;
    int ok = mask && rowptr && colour && seen;
    for (int q = 0; ok && q < structured_probes(pm); q++) {
        if (pm->start[q] == pm->start[q + 1])
            continue;
        apply_probe(pm, op, ctx, pm->members, pm->start[q], pm->start[q + 1], probe, resp);
        for (long a = pm->start[q]; a < pm->start[q + 1]; a++) {
            long c = pm->members[a];
            int nr = column_rows(pm, c);
            for (int b = 0; b < nr; b++) {
                int r = pm->rows[b];
                if (resp[pm->row_comp[b]][pm->row_slot[b]] != 0.0) {
                    mask[(size_t)c * words + b / 64] |= (uint64_t)1 << (b % 64);
                    rowptr[r + 1]++;
                }
            }
        }
    }
    /* the pattern by rows (each row's columns) for the colouring */
    if (ok) {
        for (int r = 0; r < n; r++)
            rowptr[r + 1] += rowptr[r];
        cols = malloc(((size_t)rowptr[n] + 1) * sizeof(int));
        ok = cols && (order = by_position(pm, 0)) != NULL;
    }
    if (ok) {
        for (int c = 0; c < n; c++) {
            int nr = masked_rows(pm, c, mask, words);
            for (int b = 0; b < nr; b++)
                cols[rowptr[pm->rows[b]]++] = c;
        }
        for (int r = n; r > 0; r--)
            rowptr[r] = rowptr[r - 1];
        rowptr[0] = 0;
    }
    /* the better of two sweeps, the last direction slowest or the first:
     * the heap's full tangent 41 colours either way at 70 x 100, the
     * collapse's Picard operator 9 and 11, the granular cylinder's coupled
     * step 53 and 40, the square duct's 12 and 10 */
    int ncolours = 0;
    int *other = ok ? malloc(((size_t)n + 1) * sizeof(int)) : NULL;
    ok = ok && other;
    if (ok) {
        ncolours = greedy_colours(pm, order, mask, words, rowptr, cols, seen, colour);
        free(order);
        ok = (order = by_position(pm, 1)) != NULL;
    }
    if (ok) {
        int second = greedy_colours(pm, order, mask, words, rowptr, cols, seen, other);
        if (second < ncolours) {
            int *t = colour;
            colour = other;
            other = t;
            ncolours = second;
        }
    }
    free(other);
    free(order);
    free(seen);
    free(mask);
    /* kept only when it saves probes and a row's places fit a byte */
    int longest = 0;
    for (int r = 0; ok && r < n; r++)
        longest = rowptr[r + 1] - rowptr[r] > longest ? rowptr[r + 1] - rowptr[r] : longest;
    ok = ok && ncolours < structured_probes(pm) && longest < NO_ENTRY;
    ok = ok && colour_tables(pm, colour, ncolours, rowptr, cols, &pm->cstart, &pm->cmembers,
                             &pm->entry) == 0;
    if (ok) {
        pm->pat_rowptr = rowptr;
        pm->pat_col = cols;
        rowptr = cols = NULL;
        pm->ncolours = ncolours;
    } else {
        probe_matrix_forget(pm);
    }
    free(rowptr);
    free(cols);
    free(colour);
    return pm->ncolours > 0 ? 0 : -1;
}
