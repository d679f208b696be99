/* The open faces of the coupled step (coupled_open.h). */
#include "march/coupled_open.h"

#include <stdlib.h>
#include <string.h>
#include "march/open_faces.h"
#include "march/step.h"
#include "solvers/probe_matrix.h"
#include "solvers/viscous.h"

#define REACH 2       /* an open face reaches the rows of faces this far */
#define PERIOD 5      /* 2 REACH + 1: faces this far apart share no row */
#define RESIDUES 9    /* PERIOD and a periodic direction's remainder */
#define COLOURS (RESIDUES * RESIDUES * 6)

struct coupled_open {
    int n, nu;
    struct open_link *link;
    int *start;         /* face m's column: start[m] .. start[m + 1] */
    int *rows;          /* velocity unknowns */
    double *values;
    const ptrdiff_t *slot;
    const int *comp;
    double *probe[3], *resp[3];
};

void coupled_open_destroy(struct coupled_open *co)
{
    if (!co)
        return;
    free(co->link);
    free(co->start);
    free(co->rows);
    free(co->values);
    for (int c = 0; c < 3; c++) {
        field_free(co->probe[c]);
        field_free(co->resp[c]);
    }
    free(co);
}

static int residue(int n, int periodic, int i)
{
    if (!periodic)
        return i % PERIOD;
    if (n < PERIOD)
        return i;
    int whole = PERIOD * (n / PERIOD);
    return i < whole ? i % PERIOD : PERIOD + (i - whole);
}

/* The distinct face indices within REACH of i along a direction of n cells
 * (slots -1 .. n; a periodic direction wraps into 0 .. n - 1). */
static int within_reach(int n, int periodic, int i, int out[2 * REACH + 1])
{
    int m = 0;
    for (int o = -REACH; o <= REACH; o++) {
        int j = i + o;
        if (periodic)
            j = ((j % n) + n) % n;
        else if (j < -1 || j > n)
            continue;
        int seen = 0;
        for (int q = 0; q < m; q++)
            seen |= out[q] == j;
        if (!seen)
            out[m++] = j;
    }
    return m;
}

static int count_faces(const struct march_state *st)
{
    int n = 0;
    FOR_OPEN_FACES(st, {
        (void)pf;
        (void)pi;
        (void)pc;
        (void)s;
        n++;
    })
    return n;
}

/* The links, their colours and the unknowns their columns may reach
 * (every unknown within REACH of the face). */
static int list_links(struct coupled_open *co, const struct march_state *st, const int *unknown,
                      const int *cell)
{
    const struct grid *g = &st->g;
    int periodic[3];
    bc_periodic_flags(&st->bc, periodic);
    int m = 0;
    long cap = 0;
    FOR_OPEN_FACES(st, {
        struct open_link *o = &co->link[m];
        *o = (struct open_link){.pf = pf, .pi = pi, .pc = pc, .d = d, .s = s, .h = g->h[d]};
        o->share = st->embedded ? st->embedded->share[d][pf] : 1.0;
        o->ki = unknown[(size_t)d * g->size + (size_t)pi];
        o->qc = cell[pc];
        o->qhi = cell[pi];
        o->qlo = cell[pi - od];
        if (o->ki < 0 || o->qc < 0 || o->qlo < 0 || o->qhi < 0)
            return -2;
        o->colour = residue(g->n[a_], periodic[a_], idx_[a_]) +
                    RESIDUES * (residue(g->n[b_], periodic[b_], idx_[b_]) +
                                RESIDUES * (2 * d + side));
        int near[3][2 * REACH + 1], cnt[3];
        for (int e = 0; e < 3; e++)
            cnt[e] = within_reach(g->n[e], periodic[e], idx_[e], near[e]);
        long need = (long)co->start[m] + 3L * cnt[0] * cnt[1] * cnt[2];
        if (need > cap) {
            cap = 2 * need;
            int *r = realloc(co->rows, (size_t)cap * sizeof *r);
            if (!r)
                return -1;
            co->rows = r;
        }
        int e = co->start[m];
        for (int c = 0; c < 3; c++)
            for (int x = 0; x < cnt[0]; x++)
                for (int y = 0; y < cnt[1]; y++)
                    for (int z = 0; z < cnt[2]; z++) {
                        ptrdiff_t q = grid_idx(g, near[0][x], near[1][y], near[2][z]);
                        int k = unknown[(size_t)c * g->size + (size_t)q];
                        if (k >= 0)
                            co->rows[e++] = k;
                    }
        co->start[++m] = e;
    })
    co->values = calloc((size_t)co->start[co->n] + 1, sizeof *co->values);
    return co->values ? 0 : -1;
}

int coupled_open_create(struct coupled_open **out, const struct march_state *st,
                        const struct probe_matrix *pm, const ptrdiff_t *slot, int nu,
                        const int *cell)
{
    const struct grid *g = &st->g;
    *out = NULL;
    int n = count_faces(st);
    if (n == 0)
        return 0;
    struct coupled_open *co = calloc(1, sizeof *co);
    int *unknown = malloc(3 * g->size * sizeof *unknown);
    if (!co || !unknown) {
        free(co);
        free(unknown);
        return -1;
    }
    co->n = n;
    co->nu = nu;
    co->slot = slot;
    co->comp = probe_matrix_components(pm);
    co->link = malloc((size_t)n * sizeof *co->link);
    co->start = calloc((size_t)n + 1, sizeof *co->start);
    int rc = co->link && co->start ? 0 : -1;
    for (int c = 0; c < 3 && rc == 0; c++)
        if (!(co->probe[c] = field_alloc(g)) || !(co->resp[c] = field_alloc(g)))
            rc = -1;
    if (rc == 0) {
        for (size_t q = 0; q < 3 * g->size; q++)
            unknown[q] = -1;
        for (int k = 0; k < nu; k++)
            unknown[(size_t)co->comp[k] * g->size + (size_t)slot[k]] = k;
        rc = list_links(co, st, unknown, cell);
    }
    free(unknown);
    if (rc != 0) {
        coupled_open_destroy(co);
        return rc;
    }
    *out = co;
    return 0;
}

int coupled_open_count(const struct coupled_open *co) { return co ? co->n : 0; }

const struct open_link *coupled_open_link(const struct coupled_open *co, int m)
{
    return &co->link[m];
}

int coupled_open_probe(struct coupled_open *co, struct march_state *st,
                       const struct viscous_problem *pb)
{
    const struct grid *g = &st->g;
    struct viscous_problem given = *pb;
    given.open_given = 1;
    unsigned char present[COLOURS] = {0};
    for (int m = 0; m < co->n; m++)
        present[co->link[m].colour] = 1;
    for (int colour = 0; colour < COLOURS; colour++) {
        if (!present[colour])
            continue;
        for (int c = 0; c < 3; c++)
            memset(co->probe[c], 0, g->size * sizeof(double));
        for (int m = 0; m < co->n; m++)
            if (co->link[m].colour == colour)
                co->probe[co->link[m].d][co->link[m].pf] = 1.0;
        viscous_apply(st->viscous, &given, co->probe, co->resp);
        for (int m = 0; m < co->n; m++) {
            if (co->link[m].colour != colour)
                continue;
            for (int e = co->start[m]; e < co->start[m + 1]; e++) {
                int k = co->rows[e];
                co->values[e] = co->resp[co->comp[k]][co->slot[k]];
            }
        }
    }
    return 0;
}

void coupled_open_column(const struct coupled_open *co, int m, int *n, const int **rows,
                         const double **values)
{
    *n = co->start[m + 1] - co->start[m];
    *rows = co->rows + co->start[m];
    *values = co->values + co->start[m];
}

long coupled_open_entries(const struct coupled_open *co) { return co ? co->start[co->n] : 0; }

double coupled_open_rhs(const struct coupled_open *co, const struct march_state *st, int m)
{
    /* one density: the coupled step runs no physics module */
    const struct open_link *o = &co->link[m];
    return st->cs->density * (open_acceleration(st, o->d, o->pf, 1, o->pc, o->s) -
                              open_acceleration(st, o->d, o->pi, 0, o->pc, o->s));
}
