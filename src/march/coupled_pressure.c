/* The viscosity's pressure columns of the coupled step (coupled_pressure.h). */
#include "march/coupled_pressure.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "march/coupled_view.h"
#include "march/step.h"
#include "solvers/probe_matrix.h"
#include "solvers/viscous.h"

/* Residues per direction: 3, and two more for the remainder of a periodic
 * direction (so the colour index fits 5 x 5 x 5). */
#define RESIDUES 5
#define MAX_CANDIDATES 18 /* 2 x 3 x 3 cells */

/* The relative size of a pressure perturbation: the viscous residual's
 * response is about linear over it (eta ~ p) and its round-off, about
 * 1e-16 of the stresses' terms, stays 1e-9 of the derivative. */
#define PERTURBATION 1e-7

struct pressure_columns {
    int nu, nc;
    int n[3], periodic[3];
    int *start;          /* row k's entries: start[k] .. start[k + 1] */
    int *cells;
    double *values;
    unsigned char *colour; /* per cell number */
    const int *cell;     /* each cell slot's number, periodic images included */
    const unsigned char *held;
    const struct probe_matrix *pm;
    struct coupled_view *view;
    double *work[3], *saved_p; /* the viscous residual before it is gathered */
    /* over ranks (view->gathered): the residual, the pressure and p_dyn on
     * the whole grid, and p_dyn as it was (NULL on one process) */
    double *whole[3], *pressure, *p_dyn, *p_dyn0;
    double *r0, *r1, *eps;
};

static int residue(const struct pressure_columns *pc, int d, int i)
{
    int n = pc->n[d];
    if (!pc->periodic[d])
        return i % 3;
    if (n < 3)
        return i;
    int whole = 3 * (n / 3);
    return i < whole ? i % 3 : 3 + (i - whole);
}

static int cell_colour(const struct pressure_columns *pc, const int idx[3])
{
    return residue(pc, 0, idx[0]) + RESIDUES * (residue(pc, 1, idx[1]) + RESIDUES * residue(pc, 2, idx[2]));
}

/* The candidate cells of the face of component a at indices f (cells -1
 * to n along each direction: the numbering's ghosts, periodic images or
 * -1 beyond a bounded face). */
static int candidates(const struct pressure_columns *pc, const struct grid *g, int a,
                      const int f[3], int out[MAX_CANDIDATES])
{
    int lo[3], hi[3], m = 0;
    for (int d = 0; d < 3; d++) {
        lo[d] = f[d] - 1;
        hi[d] = d == a ? f[d] : f[d] + 1;
    }
    for (int i = lo[0]; i <= hi[0]; i++)
        for (int j = lo[1]; j <= hi[1]; j++)
            for (int k = lo[2]; k <= hi[2]; k++) {
                int q = pc->cell[grid_idx(g, i, j, k)];
                if (q < 0 || pc->held[q])
                    continue;
                int seen = 0;
                for (int s = 0; s < m; s++)
                    seen |= out[s] == q;
                if (!seen)
                    out[m++] = q;
            }
    return m;
}

void pressure_columns_destroy(struct pressure_columns *pc)
{
    if (!pc)
        return;
    free(pc->start);
    free(pc->cells);
    free(pc->values);
    free(pc->colour);
    for (int c = 0; c < 3; c++) {
        field_free(pc->work[c]);
        field_free(pc->whole[c]);
    }
    field_free(pc->saved_p);
    field_free(pc->pressure);
    field_free(pc->p_dyn);
    field_free(pc->p_dyn0);
    free(pc->r0);
    free(pc->r1);
    free(pc->eps);
    free(pc);
}

struct pressure_columns *pressure_columns_create(struct coupled_view *view,
                                                 const struct probe_matrix *pm,
                                                 const ptrdiff_t *slot, int nu, const int *cell,
                                                 const unsigned char *held)
{
    const struct grid *g = view->g;
    struct pressure_columns *pc = calloc(1, sizeof *pc);
    if (!pc)
        return NULL;
    pc->view = view;
    pc->nu = nu;
    pc->nc = g->n[0] * g->n[1] * g->n[2];
    pc->cell = cell;
    pc->held = held;
    pc->pm = pm;
    for (int d = 0; d < 3; d++)
        pc->n[d] = g->n[d];
    memcpy(pc->periodic, view->periodic, sizeof pc->periodic);
    pc->start = malloc(((size_t)nu + 1) * sizeof *pc->start);
    pc->cells = malloc((size_t)nu * MAX_CANDIDATES * sizeof *pc->cells);
    pc->colour = malloc((size_t)pc->nc);
    pc->r0 = malloc((size_t)nu * sizeof *pc->r0);
    pc->r1 = malloc((size_t)nu * sizeof *pc->r1);
    pc->eps = malloc((size_t)pc->nc * sizeof *pc->eps);
    pc->saved_p = field_alloc(&view->st->g);
    if (!pc->start || !pc->cells || !pc->colour || !pc->r0 || !pc->r1 || !pc->eps || !pc->saved_p)
        goto fail;
    for (int c = 0; c < 3; c++)
        if (!(pc->work[c] = field_alloc(&view->st->g)))
            goto fail;
    if (view->gathered) {
        for (int c = 0; c < 3; c++)
            if (!(pc->whole[c] = coupled_view_field(view)))
                goto fail;
        if (!(pc->pressure = coupled_view_field(view)) || !(pc->p_dyn = coupled_view_field(view)) ||
            !(pc->p_dyn0 = coupled_view_field(view)))
            goto fail;
    }
    for (int k = 0; k < g->n[2]; k++)
        for (int j = 0; j < g->n[1]; j++)
            for (int i = 0; i < g->n[0]; i++)
                pc->colour[i + g->n[0] * (j + g->n[1] * k)] = (unsigned char)cell_colour(pc, (int[3]){i, j, k});
    const int *comp = probe_matrix_components(pm);
    long n = 0;
    for (int k = 0; k < nu; k++) {
        ptrdiff_t p = slot[k];
        int f[3];
        grid_slot_index(g, p, f);
        pc->start[k] = (int)n;
        /* a face held in a body keeps its row, the mass term alone */
        if (!view->share[comp[k]] || view->share[comp[k]][p] > 0.0)
            n += candidates(pc, g, comp[k], f, pc->cells + n);
    }
    pc->start[nu] = (int)n;
    pc->values = calloc((size_t)(n > 0 ? n : 1), sizeof *pc->values);
    if (!pc->values)
        goto fail;
    return pc;
fail:
    pressure_columns_destroy(pc);
    return NULL;
}

void pressure_columns_row(const struct pressure_columns *pc, int k, int *n, const int **cells,
                          const double **values)
{
    *n = pc->start[k + 1] - pc->start[k];
    *cells = pc->cells + pc->start[k];
    *values = pc->values + pc->start[k];
}

long pressure_columns_count(const struct pressure_columns *pc)
{
    return pc->start[pc->nu];
}

/* The viscous part of the residual, + div tau with the body's cut links,
 * as stage_residual and the obstacle's module add it, gathered into r. */
static void viscous_part(struct pressure_columns *pc, struct march_state *st, double *r)
{
    double **out = pc->work;
    const double *eta_cell[3] = {st->field.viscosity, st->field.viscosity, st->field.viscosity};
    kernel_stress_divergence(&st->g, st->act, eta_cell,
                             (const double *const *)st->field.viscosity_edges, st->field.velocity,
                             out);
    if (st->embedded)
        viscous_embedded_terms(&st->g, &st->bc, st->act, st->embedded, eta_cell,
                               (const double *const *)st->field.viscosity_edges, -1.0,
                               st->field.velocity, out);
    double *whole[3];
    for (int c = 0; c < 3; c++)
        whole[c] = (double *)coupled_view_whole(pc->view, out[c], pc->whole[c]);
    probe_matrix_gather(pc->pm, whole, r);
}

int pressure_columns_probe(struct pressure_columns *pc, struct march_state *st)
{
    const struct grid *g = pc->view->g; /* the whole grid */
    const int gathered = pc->view->gathered;
    viscous_part(pc, st, pc->r0);
    memcpy(pc->saved_p, st->field.p_dyn, st->g.size * sizeof(double));
    const double *pressure = coupled_view_whole(pc->view, st->field.pressure, pc->pressure);
    /* the pressure moved: st's own on one process, the whole grid's over
     * ranks (each rank's block of it taken back before the properties) */
    double *p_dyn = st->field.p_dyn;
    if (gathered) {
        p_dyn = (double *)coupled_view_whole(pc->view, st->field.p_dyn, pc->p_dyn);
        memcpy(pc->p_dyn0, p_dyn, g->size * sizeof(double));
    }
    double pmax = 0.0;
    for (int k = 0; k < g->n[2]; k++)
        for (int j = 0; j < g->n[1]; j++)
            for (int i = 0; i < g->n[0]; i++)
                pmax = fmax(pmax, fabs(pressure[grid_idx(g, i, j, k)]));
    for (int colour = 0; colour < RESIDUES * RESIDUES * RESIDUES; colour++) {
        int any = 0;
        for (int k = 0; k < g->n[2]; k++)
            for (int j = 0; j < g->n[1]; j++)
                for (int i = 0; i < g->n[0]; i++) {
                    int q = i + g->n[0] * (j + g->n[1] * k);
                    if (pc->colour[q] != colour || pc->held[q])
                        continue;
                    ptrdiff_t p = grid_idx(g, i, j, k);
                    double e = PERTURBATION * (fabs(pressure[p]) + 1e-3 * pmax + 1e-300);
                    /* the perturbation as the sum will hold it */
                    double moved = p_dyn[p] + e;
                    pc->eps[q] = moved - p_dyn[p];
                    p_dyn[p] = moved;
                    any = 1;
                }
        if (!any)
            continue;
        coupled_view_part(pc->view, p_dyn, st->field.p_dyn);
        stage_properties(st);
        viscous_part(pc, st, pc->r1);
        for (int k = 0; k < pc->nu; k++)
            for (int m = pc->start[k]; m < pc->start[k + 1]; m++) {
                int q = pc->cells[m];
                if (pc->colour[q] == colour)
                    pc->values[m] = -(pc->r1[k] - pc->r0[k]) / pc->eps[q];
            }
        memcpy(st->field.p_dyn, pc->saved_p, st->g.size * sizeof(double));
        if (gathered)
            memcpy(p_dyn, pc->p_dyn0, g->size * sizeof(double));
    }
    stage_properties(st);
    return 0;
}
