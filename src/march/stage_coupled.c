/* The coupled steady step (solver.coupled): velocity and pressure
 * increments from one saddle-point (Newton) system,
 *
 *     [ A  G ] [du]   [ R       ]
 *     [ D  0 ] [dp] = [ -div u  ],
 *
 * A the implicit operator of the step (pseudo-time mass, viscosity and its
 * tangent, the body's cut links), probed into a sparse matrix; G the
 * residual's pressure gradient, (dp_hi - dp_lo) / h on each velocity
 * unknown's face; D the divergence as stage_divergence takes it (the faces'
 * open shares with a body).  Faces held in a body and cells with no open
 * face are left out (their dp is 0), and one pressure is pinned (the
 * constant mode of a closed or periodic box).  UMFPACK factorises it.
 *
 * Why: the projection's pseudo-time march updates the pressure by
 * (rho / dt) phi, which stops moving a pressure error once nu dt / h^2 is
 * large; a flow whose pressure matters (around a body, the cavity) then
 * stalls unless the grad-div augmentation carries the pressure, and that
 * augmentation defeats the AMG.  Measured (docs/design.md, "The granular
 * cylinder and the steady mode"): a Newtonian square in a periodic channel
 * steady in 22 steps where the projection march found no steady state; the
 * Bingham cavity steady without augmentation in the augmented run's 31
 * steps and psi_max.
 *
 * The workspace is allocated per step: the matrix and its factors are the
 * step's cost, and the step is meant for the grids the sparse LU serves. */
#include <stdlib.h>
#include <string.h>
#include "march/step.h"
#include "solvers/probe_matrix.h"
#include "solvers/suitesparse.h"
#include "solvers/viscous.h"

struct apply_ctx {
    struct march_state *st;
    const struct viscous_problem *pb;
};

static void apply(void *ctx, double *v[3], double *out[3])
{
    struct apply_ctx *a = ctx;
    viscous_apply(a->st->viscous, a->pb, v, out);
}

struct entry {
    int row, col;
    double val;
};

static int by_column(const void *a, const void *b)
{
    const struct entry *x = a, *y = b;
    if (x->col != y->col)
        return x->col < y->col ? -1 : 1;
    return (x->row > y->row) - (x->row < y->row);
}

/* Cell number (x fastest) of every cell slot, periodic images included;
 * -1 for the ghosts of a bounded face. */
static void number_cells(const struct grid *g, const int periodic[3], int *cell)
{
    for (size_t p = 0; p < g->size; p++)
        cell[p] = -1;
    for (int i = -1; i <= g->n[0]; i++)
        for (int j = -1; j <= g->n[1]; j++)
            for (int k = -1; k <= g->n[2]; k++) {
                int idx[3] = {i, j, k}, inside = 1;
                for (int d = 0; d < 3; d++)
                    if (idx[d] < 0 || idx[d] >= g->n[d]) {
                        if (periodic[d])
                            idx[d] = (idx[d] + g->n[d]) % g->n[d];
                        else
                            inside = 0;
                    }
                if (inside)
                    cell[grid_idx(g, i, j, k)] = idx[0] + g->n[0] * (idx[1] + g->n[1] * idx[2]);
            }
}

struct work {
    struct probe_matrix *pm;
    double *probe[3], *resp[3];
    struct csr_matrix A;
    double *slot;
    int *cell, *has_face, *Ap, *Ai;
    struct entry *e;
    double *Ax, *b, *x;
};

static void work_free(struct work *w)
{
    for (int c = 0; c < 3; c++) {
        field_free(w->probe[c]);
        field_free(w->resp[c]);
    }
    csr_free(&w->A);
    if (w->pm)
        probe_matrix_destroy(w->pm);
    free(w->slot);
    free(w->cell);
    free(w->has_face);
    free(w->Ap);
    free(w->Ai);
    free(w->e);
    free(w->Ax);
    free(w->b);
    free(w->x);
}

/* The saddle-point matrix's entries: A's, then G's and D's per velocity
 * unknown, then the pins.  Returns the count. */
static long fill_entries(const struct march_state *st, struct work *w, int nu, int nc)
{
    const struct grid *g = &st->g;
    const int *comp = probe_matrix_components(w->pm);
    long n = 0;
    for (int r = 0; r < nu; r++)
        for (int q = w->A.rowptr[r]; q < w->A.rowptr[r + 1]; q++)
            w->e[n++] = (struct entry){r, w->A.col[q], w->A.val[q]};
    for (int k = 0; k < nu; k++) {
        int c = comp[k];
        ptrdiff_t p = (ptrdiff_t)w->slot[k];
        double share = st->embedded ? st->embedded->share[c][p] : 1.0;
        int hi = w->cell[p], lo = w->cell[p - g->stride[c]];
        if (share == 0.0 || (hi >= 0 && hi == lo))
            continue; /* held in the body, or its own periodic image */
        double ih = 1.0 / g->h[c];
        if (hi >= 0) {
            w->e[n++] = (struct entry){k, nu + hi, ih};
            w->e[n++] = (struct entry){nu + hi, k, -share * ih};
            w->has_face[hi] = 1;
        }
        if (lo >= 0) {
            w->e[n++] = (struct entry){k, nu + lo, -ih};
            w->e[n++] = (struct entry){nu + lo, k, share * ih};
            w->has_face[lo] = 1;
        }
    }
    /* the pinned pressure: the first cell with an open face loses its
     * divergence row (the rows sum to zero over a closed or periodic box) */
    int pinned = -1;
    for (int q = 0; q < nc && pinned < 0; q++)
        if (w->has_face[q])
            pinned = q;
    long m = 0;
    for (long i = 0; i < n; i++)
        if (pinned < 0 || w->e[i].row != nu + pinned)
            w->e[m++] = w->e[i];
    if (pinned >= 0)
        w->has_face[pinned] = 0; /* pinned like a closed cell: dp = 0, right-hand side 0 */
    for (int q = 0; q < nc; q++)
        if (!w->has_face[q])
            w->e[m++] = (struct entry){nu + q, nu + q, 1.0};
    return m;
}

int stage_coupled(struct march_state *st, const struct viscous_problem *pb)
{
    const struct grid *g = &st->g;
    struct work w;
    memset(&w, 0, sizeof w);
    int periodic[3], rc = -1;
    for (int d = 0; d < 3; d++)
        periodic[d] = st->bc.face[d][0] == BC_PERIODIC;
    char err[256];
    if (suitesparse_load(err, sizeof err) != 0 ||
        probe_matrix_create(&w.pm, g, periodic, st->act, 2, err, sizeof err) != 0)
        goto done;
    for (int c = 0; c < 3; c++)
        if (!(w.probe[c] = field_alloc(g)) || !(w.resp[c] = field_alloc(g)))
            goto done;
    struct apply_ctx ctx = {st, pb};
    if (probe_matrix_assemble(w.pm, apply, &ctx, w.probe, w.resp, 0, &w.A) != 0)
        goto done;
    int nu = w.A.n, nc = g->n[0] * g->n[1] * g->n[2], n = nu + nc;
    long cap = csr_nnz(&w.A) + 4L * nu + 2L * nc;
    w.slot = malloc((size_t)nu * sizeof *w.slot);
    w.cell = malloc(g->size * sizeof *w.cell);
    w.has_face = calloc((size_t)nc, sizeof *w.has_face);
    w.e = malloc((size_t)cap * sizeof *w.e);
    w.Ap = calloc((size_t)n + 1, sizeof *w.Ap);
    w.Ai = malloc((size_t)cap * sizeof *w.Ai);
    w.Ax = malloc((size_t)cap * sizeof *w.Ax);
    w.b = calloc((size_t)n, sizeof *w.b);
    w.x = calloc((size_t)n, sizeof *w.x);
    if (!w.slot || !w.cell || !w.has_face || !w.e || !w.Ap || !w.Ai || !w.Ax || !w.b || !w.x)
        goto done;
    /* each unknown's slot: the slot numbers gathered like a residual */
    for (int c = 0; c < 3; c++)
        for (size_t p = 0; p < g->size; p++)
            w.probe[c][p] = (double)p;
    probe_matrix_gather(w.pm, w.probe, w.slot);
    number_cells(g, periodic, w.cell);
    long m = fill_entries(st, &w, nu, nc);
    /* compressed columns, duplicates summed */
    qsort(w.e, (size_t)m, sizeof *w.e, by_column);
    long nz = 0;
    for (long i = 0; i < m; i++) {
        if (nz > 0 && w.e[i].col == w.e[i - 1].col && w.e[i].row == w.Ai[nz - 1]) {
            w.Ax[nz - 1] += w.e[i].val;
            continue;
        }
        w.Ai[nz] = w.e[i].row;
        w.Ax[nz] = w.e[i].val;
        w.Ap[w.e[i].col + 1]++;
        nz++;
    }
    for (int c = 0; c < n; c++)
        w.Ap[c + 1] += w.Ap[c];
    probe_matrix_gather(w.pm, st->res, w.b);
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                int q = w.cell[p];
                w.b[nu + q] = w.has_face[q] ? -st->div[p] : 0.0;
            }
    void *symbolic = NULL, *numeric = NULL;
    int status = suitesparse.umfpack_di_symbolic(n, n, w.Ap, w.Ai, w.Ax, &symbolic, NULL, NULL);
    if (status == UMFPACK_OK)
        status = suitesparse.umfpack_di_numeric(w.Ap, w.Ai, w.Ax, symbolic, &numeric, NULL, NULL);
    if (status == UMFPACK_OK)
        status = suitesparse.umfpack_di_solve(UMFPACK_A, w.Ap, w.Ai, w.Ax, w.x, w.b, numeric, NULL,
                                              NULL);
    if (symbolic)
        suitesparse.umfpack_di_free_symbolic(&symbolic);
    if (numeric)
        suitesparse.umfpack_di_free_numeric(&numeric);
    if (status != UMFPACK_OK)
        goto done;
    for (int c = 0; c < 3; c++)
        memset(st->delta[c], 0, g->size * sizeof(double));
    probe_matrix_scatter(w.pm, w.x, st->delta);
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                st->p_dyn[p] += w.x[nu + w.cell[p]];
            }
    st->linear_iterations = 1;
    rc = 0;
done:
    work_free(&w);
    return rc;
}
