/* The coupled steady step (solver.coupled): velocity and pressure
 * increments from one saddle-point (Newton) system,
 *
 *     [ A  G ] [du]   [ R       ]
 *     [ D  0 ] [dp] = [ -div u  ],
 *
 * A the implicit operator of the step (pseudo-time mass, viscosity and its
 * tangent, the body's cut links), probed into a sparse matrix; G the
 * residual's pressure gradient, (dp_hi - dp_lo) / h on each velocity
 * unknown's face, and on a Newton step of a pressure-dependent law the
 * viscosity's own dependence on p (coupled_pressure.h); D the divergence
 * as stage_divergence takes it (the faces' open shares with a body).  Faces held in a body and cells with no open
 * face are left out (their dp is 0), and one pressure is pinned (the
 * constant mode of a closed or periodic box) unless the box has an open
 * face.  UMFPACK factorises it (saddle_point.h), or with
 * solver.preconditioner = amg or multigrid GMRES solves it (saddle_krylov.h,
 * coupled_mg.h), giving way to the LU for the rest of the run if it fails.
 *
 * A module's border (march/module.h: the prescribed mean velocity, whose
 * force's size is one more unknown) borders K: a second right-hand side of
 * the same LU.
 *
 * An open face is not a velocity unknown; each has one more unknown, its
 * own increment beyond its inner face's, with the face's balance for its
 * row (coupled_open.h).
 *
 * Why: the projection's pseudo-time march updates the pressure by
 * (rho / dt) phi, which stops moving a pressure error once nu dt / h^2 is
 * large; a flow whose pressure matters (around a body, the cavity) then
 * stalls unless the grad-div augmentation carries the pressure, and that
 * augmentation defeats the AMG.  Measured (docs/numerics/coupled-step.md):
 * a Newtonian square in a periodic channel steady in 22 steps where the
 * projection march found no steady state; the Bingham cavity steady without
 * augmentation in the augmented run's 31 steps and psi_max.
 *
 * The numbering, the probing's colouring and the solver live from the first
 * coupled step to march_destroy; the matrices are the step's. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "march/coupled_mg.h"
#include "march/coupled_pressure.h"
#include "march/coupled_open.h"
#include "march/coupled_view.h"
#include "march/step.h"
#include "solvers/probe_matrix.h"
#include "solvers/saddle_krylov.h"
#include "solvers/saddle_point.h"
#include "solvers/viscous.h"

struct entry {
    int row, col;
    double val;
};

/* The velocity unknowns that carry a pressure gradient: unknown k on a face
 * of open share s and spacing h between cells lo and hi (either -1 beyond a
 * bounded face).  Faces held in the body and a face between a cell and its
 * own periodic image carry none. */
struct gradient_face {
    int k, lo, hi;
    double s, h;       /* open share; distance of the centres lo and hi */
    double h_lo, h_hi; /* widths of the cells lo and hi (their divergences) */
};

struct coupled_state {
    struct coupled_view *view;   /* the whole grid (st's own on one process) */
    double *whole[3], *whole_p, *whole_div; /* over ranks: fields gathered onto it */
    struct probe_matrix *pm;
    int pattern;                 /* the kind of operator pm learnt (viscous_learn_pattern) */
    double *probe[3], *resp[3];
    int nu, nc;
    ptrdiff_t *slot;            /* each velocity unknown's field slot */
    int *cell;                  /* each cell slot's number (periodic images
                                   included), -1 for a bounded face's ghosts */
    unsigned char *held;        /* cells whose dp is held (at 0, or the pin's) */
    int pinned;                 /* the cell whose p_dyn fixes the pressure's
                                   level (-1: an open face fixes it) */
    struct gradient_face *faces;
    int nfaces;
    struct coupled_open *open;  /* the open faces, unknowns nu + nc + m */
    int nopen;
    struct csr_matrix A, K;
    struct entry *e;            /* assembly work */
    long cap;
    double *b, *x;
    struct saddle_point *solver;
    struct saddle_krylov *krylov;   /* solver.preconditioner = amg or multigrid: GMRES
                                       instead of the LU */
    struct coupled_mg *mg;          /* multigrid: GMRES's preconditioner */
    long fallbacks;                 /* GMRES solves that failed: the LU took over */
    char cause[200];
    struct pressure_columns *pcols; /* a pressure-dependent law's d(div tau)/dp */
    int pcols_on;                   /* this step's matrix has them (the tangent's) */
    int idle[3];                    /* components this step leaves at du = 0 (idle_components) */
    double *f, *x2;                 /* a module's border: the bordered solve's second
                                       column and its solution (march/module.h) */
    int bordered;                   /* this step's solve has them */
};

static int by_row(const void *a, const void *b)
{
    const struct entry *x = a, *y = b;
    if (x->row != y->row)
        return x->row < y->row ? -1 : 1;
    return (x->col > y->col) - (x->col < y->col);
}

void stage_coupled_destroy(struct coupled_state *c)
{
    if (!c)
        return;
    for (int k = 0; k < 3; k++) {
        field_free(c->probe[k]);
        field_free(c->resp[k]);
        field_free(c->whole[k]);
    }
    field_free(c->whole_p);
    field_free(c->whole_div);
    coupled_view_destroy(c->view);
    if (c->pm)
        probe_matrix_destroy(c->pm);
    csr_free(&c->A);
    csr_free(&c->K);
    saddle_point_destroy(c->solver);
    saddle_krylov_destroy(c->krylov);
    coupled_mg_destroy(c->mg);
    pressure_columns_destroy(c->pcols);
    free(c->slot);
    free(c->cell);
    free(c->held);
    free(c->faces);
    coupled_open_destroy(c->open);
    free(c->e);
    free(c->b);
    free(c->x);
    free(c->f);
    free(c->x2);
    free(c);
}

/* Cell number (x fastest) of every cell slot, periodic images included;
 * -1 for the ghosts of a bounded face. */
static void number_cells(const struct grid *g, const int periodic[3], int *cell)
{
    for (size_t p = 0; p < g->size; p++)
        cell[p] = -1;
    for (int i = grid_slot_lo(g, 0); i <= grid_slot_hi(g, 0); i++)
        for (int j = grid_slot_lo(g, 1); j <= grid_slot_hi(g, 1); j++)
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

static int list_gradient_faces(struct coupled_state *c)
{
    const struct grid *g = c->view->g;
    const int *comp_of = probe_matrix_components(c->pm);
    c->faces = malloc((size_t)c->nu * sizeof *c->faces);
    if (!c->faces)
        return -1;
    c->nfaces = 0;
    for (int k = 0; k < c->nu; k++) {
        int comp = comp_of[k];
        ptrdiff_t p = c->slot[k];
        double s = c->view->share[comp] ? c->view->share[comp][p] : 1.0;
        int hi = c->cell[p], lo = c->cell[p - g->stride[comp]];
        if (s == 0.0 || (hi >= 0 && hi == lo))
            continue;
        int idx[3];
        grid_slot_index(g, p, idx);
        c->faces[c->nfaces++] = (struct gradient_face){
            k, lo, hi, s, grid_hf(g, comp, idx[comp]), grid_hc(g, comp, idx[comp] - 1),
            grid_hc(g, comp, idx[comp])};
    }
    return 0;
}

/* The module that borders the step (the first with a border), or -1. */
static int border_module(const struct march_state *st)
{
    for (int m = 0; m < st->nmodules; m++)
        if (st->modules[m]->border)
            return m;
    return -1;
}

static struct coupled_state *create(struct march_state *st, char *err, size_t errlen)
{
    struct coupled_state *c = calloc(1, sizeof *c);
    if (!c)
        return NULL;
    if (!(c->view = coupled_view_create(st)))
        goto oom;
    const struct grid *g = c->view->g;
    const int *periodic = c->view->periodic;
    if (probe_matrix_create(&c->pm, g, periodic, c->view->act, 2, err, errlen) != 0)
        goto fail;
    if (c->view->gathered) {
        for (int k = 0; k < 3; k++)
            if (!(c->whole[k] = coupled_view_field(c->view)))
                goto oom;
        if (!(c->whole_p = coupled_view_field(c->view)) ||
            !(c->whole_div = coupled_view_field(c->view)))
            goto oom;
    }
    for (int k = 0; k < 3; k++)
        if (!(c->probe[k] = field_alloc(g)) || !(c->resp[k] = field_alloc(g)))
            goto oom;
    c->nu = (int)probe_matrix_unknowns(c->pm);
    c->nc = g->n[0] * g->n[1] * g->n[2];
    double *slot = malloc((size_t)c->nu * sizeof *slot);
    c->slot = malloc((size_t)c->nu * sizeof *c->slot);
    c->cell = malloc(g->size * sizeof *c->cell);
    c->held = malloc((size_t)c->nc);
    if (!slot || !c->slot || !c->cell || !c->held) {
        free(slot);
        goto oom;
    }
    /* each unknown's slot: the slot numbers gathered like a residual */
    for (int k = 0; k < 3; k++)
        for (size_t p = 0; p < g->size; p++)
            c->probe[k][p] = (double)p;
    probe_matrix_gather(c->pm, c->probe, slot);
    for (int k = 0; k < c->nu; k++)
        c->slot[k] = (ptrdiff_t)slot[k];
    free(slot);
    number_cells(g, periodic, c->cell);
    /* a cell's dp is free when a gradient face touches it; the first free
     * cell is pinned (the rows of D sum to zero over a closed or periodic
     * box: one of them is redundant) */
    if (list_gradient_faces(c) != 0)
        goto oom;
    /* over ranks no open face (march_create refuses them) */
    int rc = c->view->gathered ? 0 : coupled_open_create(&c->open, st, c->pm, c->slot, c->nu, c->cell);
    c->nopen = coupled_open_count(c->open);
    if (rc == -2) {
        snprintf(err, errlen, "coupled step: an open face's inner face is held in a body");
        goto fail;
    }
    if (rc != 0)
        goto oom;
    size_t nall = (size_t)c->nu + (size_t)c->nc + (size_t)c->nopen;
    c->b = malloc(nall * sizeof *c->b);
    c->x = malloc(nall * sizeof *c->x);
    if (!c->b || !c->x)
        goto oom;
    if (border_module(st) >= 0 &&
        (!(c->f = calloc(nall, sizeof *c->f)) || !(c->x2 = malloc(nall * sizeof *c->x2))))
        goto oom;
    memset(c->held, 1, (size_t)c->nc);
    for (int f = 0; f < c->nfaces; f++) {
        if (c->faces[f].hi >= 0)
            c->held[c->faces[f].hi] = 0;
        if (c->faces[f].lo >= 0)
            c->held[c->faces[f].lo] = 0;
    }
    c->pinned = -1;
    for (int q = 0; q < c->nc && c->nopen == 0; q++)
        if (!c->held[q]) {
            c->held[q] = 1;
            c->pinned = q;
            break;
        }
    if (st->rheo.law == LAW_MUI && st->cs->newton &&
        !(c->pcols = pressure_columns_create(c->view, c->pm, c->slot, c->nu, c->cell, c->held)))
        goto oom;
    if (saddle_point_create(&c->solver, err, errlen) != 0)
        goto fail;
    if (st->precond == VISCOUS_AMG) {
        struct amg_options o;
        amg_options_default(&o);
        /* V(1,1): on the cavity 27, 31, 43 GMRES iterations a step at 32,
           64, 128 cells across against V(0,1)'s 33, 41, 57
           (docs/numerics/coupled-step.md) */
        o.pre_sweeps = 1;
        if (saddle_krylov_create(&c->krylov, (int)nall, c->nu, probe_matrix_components(c->pm),
                                 &o, err, errlen) != 0)
            goto fail;
    }
    if (st->precond == VISCOUS_MG &&
        (saddle_krylov_create_mg(&c->krylov, (int)nall, c->nu, err, errlen) != 0 ||
         coupled_mg_create(&c->mg, st, c->pm, c->nu, c->nc, c->cell, err, errlen) != 0))
        goto fail;
    return c;
oom:
    snprintf(err, errlen, "coupled step: out of memory");
fail:
    stage_coupled_destroy(c);
    return NULL;
}

static int grow_entries(struct coupled_state *c, long need)
{
    if (need <= c->cap)
        return 0;
    struct entry *e = realloc(c->e, (size_t)need * sizeof *e);
    if (!e)
        return -1;
    c->e = e;
    c->cap = need;
    return 0;
}

/* Compressed rows of n x n from the entries (sorted here, duplicates
 * summed). */
static int to_csr(struct entry *e, long m, int n, struct csr_matrix *M)
{
    qsort(e, (size_t)m, sizeof *e, by_row);
    if (csr_reserve(M, n, (size_t)m) != 0)
        return -1;
    memset(M->rowptr, 0, ((size_t)n + 1) * sizeof *M->rowptr);
    long nz = 0;
    for (long i = 0; i < m; i++) {
        if (nz > 0 && i > 0 && e[i].row == e[i - 1].row && e[i].col == M->col[nz - 1]) {
            M->val[nz - 1] += e[i].val;
            continue;
        }
        M->col[nz] = e[i].col;
        M->val[nz] = e[i].val;
        M->rowptr[e[i].row + 1]++;
        nz++;
    }
    for (int r = 0; r < n; r++)
        M->rowptr[r + 1] += M->rowptr[r];
    return 0;
}

/* K from A, G and D. */
/* The velocity components this step need not solve for.  A velocity
 * unknown whose row is its diagonal alone and whose right-hand side is 0 (a
 * node held in the body) has du = 0, whatever its column holds; a component
 * whose right-hand side is 0 and that nothing couples to the rest of the
 * system but through such nodes (the operator, the pressure gradient, the
 * viscosity's pressure columns, the open faces) has du = 0 too.  A flow in a
 * plane leaves the component across it so (the cylinder's, the cavity's: the
 * x-z plane, y one periodic cell; at the body its rows reach held u and w
 * nodes); its rows then hold their diagonal alone, which UMFPACK takes out as
 * singletons before it factorises the rest. */
static void idle_components(struct coupled_state *c)
{
    const int *comp = probe_matrix_components(c->pm);
    const struct csr_matrix *A = &c->A;
    int busy[3] = {0, 0, 0};
    unsigned char *touched = calloc((size_t)c->nu + 1, 1); /* reached beyond A: not inert */
    if (!touched) {
        c->idle[0] = c->idle[1] = c->idle[2] = 0;
        return;
    }
    for (int f = 0; f < c->nfaces; f++) {
        busy[comp[c->faces[f].k]] = 1;
        touched[c->faces[f].k] = 1;
    }
    for (int r = 0; c->pcols_on && r < c->nu; r++) {
        int m;
        const int *cells;
        const double *val;
        pressure_columns_row(c->pcols, r, &m, &cells, &val);
        for (int q = 0; q < m; q++)
            if (val[q] != 0.0)
                busy[comp[r]] = touched[r] = 1;
    }
    for (int m = 0; m < c->nopen; m++) {
        int nr;
        const int *rows;
        const double *val;
        coupled_open_column(c->open, m, &nr, &rows, &val);
        for (int q = 0; q < nr; q++)
            busy[comp[rows[q]]] = touched[rows[q]] = 1;
        int ki = coupled_open_link(c->open, m)->ki;
        busy[comp[ki]] = touched[ki] = 1;
    }
    for (int r = 0; r < c->nu; r++) {
        if (c->b[r] != 0.0 || (c->bordered && c->f[r] != 0.0))
            busy[comp[r]] = 1;
        for (int q = A->rowptr[r]; q < A->rowptr[r + 1]; q++) {
            int k = A->col[q];
            int inert = !touched[k] && c->b[k] == 0.0 && A->rowptr[k + 1] - A->rowptr[k] == 1 &&
                        A->col[A->rowptr[k]] == k;
            if (comp[k] != comp[r] && !inert)
                busy[comp[r]] = busy[comp[k]] = 1;
        }
    }
    free(touched);
    for (int k = 0; k < 3; k++)
        c->idle[k] = !busy[k];
}

static int assemble(struct coupled_state *c)
{
    const int *comp = probe_matrix_components(c->pm);
    const int nu = c->nu, nc = c->nc;
    long extra = c->pcols ? pressure_columns_count(c->pcols) : 0;
    extra += coupled_open_entries(c->open) + 5L * c->nopen;
    if (grow_entries(c, csr_nnz(&c->A) + 4L * nu + nc + extra) != 0)
        return -1;
    long n = 0;
    for (int r = 0; r < nu; r++) {
        if (c->idle[comp[r]]) { /* du = 0 (idle_components) */
            c->e[n++] = (struct entry){r, r, 1.0};
            continue;
        }
        for (int q = c->A.rowptr[r]; q < c->A.rowptr[r + 1]; q++)
            c->e[n++] = (struct entry){r, c->A.col[q], c->A.val[q]};
    }
    /* the pattern keeps these entries in every step (0 in a Picard step),
     * so the symbolic factorisation stays */
    for (int r = 0; c->pcols && r < nu; r++) {
        if (c->idle[comp[r]])
            continue;
        int m;
        const int *cells;
        const double *val;
        pressure_columns_row(c->pcols, r, &m, &cells, &val);
        for (int q = 0; q < m; q++)
            c->e[n++] = (struct entry){r, nu + cells[q], c->pcols_on ? val[q] : 0.0};
    }
    for (int f = 0; f < c->nfaces; f++) {
        const struct gradient_face *a = &c->faces[f];
        double ih = 1.0 / a->h;
        if (a->hi >= 0) {
            c->e[n++] = (struct entry){a->k, nu + a->hi, ih};
            if (!c->held[a->hi])
                c->e[n++] = (struct entry){nu + a->hi, a->k, -a->s * (1.0 / a->h_hi)};
        }
        if (a->lo >= 0) {
            c->e[n++] = (struct entry){a->k, nu + a->lo, -ih};
            if (!c->held[a->lo])
                c->e[n++] = (struct entry){nu + a->lo, a->k, a->s * (1.0 / a->h_lo)};
        }
    }
    for (int q = 0; q < nc; q++)
        if (c->held[q])
            c->e[n++] = (struct entry){nu + q, nu + q, 1.0};
    for (int m = 0; m < c->nopen; m++) {
        const struct open_link *o = coupled_open_link(c->open, m);
        int row = nu + nc + m, nr;
        const int *rows;
        const double *val;
        /* the momentum rows the face's own increment reaches */
        coupled_open_column(c->open, m, &nr, &rows, &val);
        for (int q = 0; q < nr; q++)
            c->e[n++] = (struct entry){rows[q], row, val[q]};
        /* the boundary cell's divergence: the face moves by du_i + e */
        double dv = o->s * o->share / o->h;
        c->e[n++] = (struct entry){nu + o->qc, o->ki, dv};
        c->e[n++] = (struct entry){nu + o->qc, row, dv};
        /* dG_f - dG_i, G_f = -2 s p_c / h, G_i = (p_hi - p_lo) / h */
        c->e[n++] = (struct entry){row, nu + o->qc, -2.0 * o->s / o->h};
        c->e[n++] = (struct entry){row, nu + o->qhi, -1.0 / o->h};
        c->e[n++] = (struct entry){row, nu + o->qlo, 1.0 / o->h};
    }
    return to_csr(c->e, n, nu + nc + c->nopen, &c->K);
}

/* The increments x of the unknowns into st's field.increment (0 elsewhere). */
static void scatter_increment(struct march_state *st, struct coupled_state *c, const double *x)
{
    for (int k = 0; k < 3; k++)
        memset(st->field.increment[k], 0, st->g.size * sizeof(double));
    if (!c->view->gathered) {
        probe_matrix_scatter(c->pm, x, st->field.increment);
        return;
    }
    for (int k = 0; k < 3; k++)
        memset(c->whole[k], 0, c->view->g->size * sizeof(double));
    probe_matrix_scatter(c->pm, x, c->whole);
    for (int k = 0; k < 3; k++)
        coupled_view_part(c->view, c->whole[k], st->field.increment[k]);
}

/* b at the unknowns from a field triple f of st's grid. */
static void gather_unknowns(struct coupled_state *c, double *const f[3], double *b)
{
    double *whole[3];
    for (int k = 0; k < 3; k++)
        whole[k] = (double *)coupled_view_whole(c->view, f[k], c->whole[k]);
    probe_matrix_gather(c->pm, whole, b);
}

/* The bordered step (march/module.h: module_border): x = x1 + dg x2 with
 * dg such that the border's row of u + x is its target. */
static void border(struct march_state *st, struct coupled_state *c, double gap)
{
    int m = border_module(st);
    const struct module_border *b = st->modules[m]->border;
    void *state = st->module_state[m];
    size_t nall = (size_t)c->nu + (size_t)c->nc + (size_t)c->nopen;
    double w[2];
    const double *sol[2] = {c->x, c->x2};
    for (int r = 0; r < 2; r++) {
        scatter_increment(st, c, sol[r]);
        w[r] = b->row(st, state, st->field.increment);
    }
    double dg = w[1] != 0.0 ? (gap - w[0]) / w[1] : 0.0;
    for (size_t q = 0; q < nall; q++)
        c->x[q] += dg * c->x2[q];
    b->increment(st, state, dg);
}

int stage_coupled(struct march_state *st, const struct viscous_problem *pb)
{
    char err[256];
    if (!st->coupled && !(st->coupled = create(st, err, sizeof err))) {
        fprintf(stderr, "muflow: %s\n", err);
        return -1;
    }
    struct coupled_state *c = st->coupled;
    struct coupled_view *v = c->view;
    const struct grid *g = v->g; /* the whole grid */
    const int nu = c->nu;
    operator_fn op;
    void *ctx;
    coupled_view_operator(v, pb, &op, &ctx);
    /* over ranks the structured colouring: learning the pattern probes
     * st's block alone (the entries are the same either way) */
    if (!v->gathered)
        viscous_learn_pattern(st->viscous, c->pm, &c->pattern, pb);
    if (probe_matrix_assemble(c->pm, op, ctx, c->probe, c->resp, 0, &c->A) != 0)
        return -1;
    st->grid_matrices++;
    c->pcols_on = c->pcols && implicit_uses_tangent(st);
    if (c->pcols_on && pressure_columns_probe(c->pcols, st) != 0)
        return -1;
    if (c->open && coupled_open_probe(c->open, st, pb) != 0)
        return -1;
    gather_unknowns(c, st->field.residual, c->b);
    double gap = 0.0;
    int m = border_module(st);
    c->bordered = c->f && st->modules[m]->border->column(st, st->module_state[m],
                                                         st->field.increment, &gap) == 0;
    if (c->bordered)
        gather_unknowns(c, st->field.increment, c->f); /* its pressure rows stay 0 */
    idle_components(c);
    if (assemble(c) != 0)
        return -1;
    const double *p_dyn = coupled_view_whole(v, st->field.p_dyn, c->whole_p);
    const double *divergence = coupled_view_whole(v, st->field.divergence, c->whole_div);
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t p = grid_idx(g, i, j, k);
                int q = c->cell[p];
                /* the pin's row takes p_dyn there to 0, whatever the state
                 * started from: an interpolated start (solver.initial_state)
                 * brings its own value, and a pressure-dependent law sees
                 * the level (D/8 from a D/4 state: F_D 57.374 against
                 * 57.658 from rest, both steady to round-off) */
                c->b[nu + q] = q == c->pinned ? -p_dyn[p] : c->held[q] ? 0.0 : -divergence[p];
            }
    for (int m = 0; m < c->nopen; m++)
        c->b[nu + c->nc + m] = coupled_open_rhs(c->open, st, m);
    struct saddle_krylov_stats ks = {0, 0.0};
    int rc = 1;
    if (c->krylov && !c->bordered) { /* the bordered solve is the LU's */
        double tol = implicit_tolerance(st, pb->b_cell != NULL);
        struct saddle_velocity_precond vp;
        if (!c->mg)
            rc = saddle_krylov_solve(c->krylov, &c->K, c->b, c->x, tol,
                                     st->cs->max_linear_iterations, &ks, c->cause,
                                     sizeof c->cause);
        else if (coupled_mg_setup(c->mg, st, pb, c->idle, c->nopen, &vp, c->cause,
                                  sizeof c->cause) != 0)
            rc = -1;
        else
            rc = saddle_krylov_solve_mg(c->krylov, &c->K, &vp, c->b, c->x, tol,
                                        st->cs->max_linear_iterations, &ks, c->cause,
                                        sizeof c->cause);
        st->linear_iterations = ks.iterations;
        st->linear_residual = ks.relative_residual;
        /* a GMRES that fails (its cap, a breakdown) leaves this step and
           the rest of the run to the LU, which solves whatever GMRES could
           not: never an unconverged iterate taken as a Newton step */
        if (rc != 0) {
            if (rc == 1)
                snprintf(c->cause, sizeof c->cause,
                         "the coupled step's GMRES stopped at solver.max_linear_iterations = %d "
                         "with a relative residual of %.1e",
                         st->cs->max_linear_iterations, ks.relative_residual);
            c->fallbacks++;
            saddle_krylov_destroy(c->krylov);
            c->krylov = NULL;
            coupled_mg_destroy(c->mg);
            c->mg = NULL;
        }
    }
    if (rc != 0) {
        const double *rhs[2] = {c->b, c->f};
        double *sol[2] = {c->x, c->x2};
        char why[sizeof st->step_error - 32];
        if (saddle_point_solve_many(c->solver, &c->K, c->bordered ? 2 : 1, rhs, sol, why,
                                    sizeof why) != 0) {
            snprintf(st->step_error, sizeof st->step_error, "the implicit coupled solve: %s", why);
            return -1;
        }
        st->linear_iterations = 1;
    }
    if (c->bordered)
        border(st, c, gap);
    scatter_increment(st, c, c->x);
    for (int m = 0; m < c->nopen; m++) {
        const struct open_link *o = coupled_open_link(c->open, m);
        st->field.increment[o->d][o->pf] = c->x[o->ki] + c->x[nu + c->nc + m];
    }
    for (int i = 0; i < st->g.n[0]; i++)
        for (int j = 0; j < st->g.n[1]; j++)
            for (int k = 0; k < st->g.n[2]; k++) {
                ptrdiff_t p = grid_idx(&st->g, i, j, k);
                st->field.p_dyn[p] += c->x[nu + c->cell[coupled_view_slot(v, p)]];
            }
    return 0;
}

long stage_coupled_fallbacks(const struct coupled_state *c, const char **cause)
{
    if (cause)
        *cause = c && c->fallbacks ? c->cause : NULL;
    return c ? c->fallbacks : 0;
}

void stage_coupled_update(struct march_state *st)
{
    kernel_axpy(&st->g, st->act, 1.0, st->field.increment, st->field.velocity);
    const struct coupled_state *c = st->coupled;
    for (int m = 0; m < c->nopen; m++) { /* the open faces are state, not unknowns */
        const struct open_link *o = coupled_open_link(c->open, m);
        st->field.velocity[o->d][o->pf] += st->field.increment[o->d][o->pf];
    }
    bc_fill_velocity(&st->g, &st->bc, st->field.velocity);
}
