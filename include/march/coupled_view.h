/* The whole grid as the coupled step sees it (stage_coupled.c).
 *
 * The coupled step numbers every velocity face and cell of the domain and
 * factorises one saddle-point matrix.  On one process the view is st's own
 * grid, unknown boxes, open shares and fields: no copy.  Over several ranks
 * (a decomposed march) it is the global grid, its unknown boxes and open
 * shares, and the fields the step reads are gathered onto every rank
 * (decomp_gather); the step's operator is applied block by block and its
 * response gathered, so every rank probes, factorises and solves the same
 * matrix and scatters back its own block of the increments.  This gathers
 * the plane on every rank (as gmg does its cross-section): the 2D bodies
 * the coupled step serves, not a 3D grid of 10^7 cells
 * (docs/numerics/decomposition.md). */
#ifndef MUFLOW_MARCH_COUPLED_VIEW_H
#define MUFLOW_MARCH_COUPLED_VIEW_H

#include <stddef.h>
#include "grid/grid.h"
#include "solvers/probe_matrix.h"
#include "solvers/viscous.h"

struct march_state;

struct coupled_view {
    const struct grid *g;     /* the whole grid (st->g on one process) */
    struct box act[3];        /* its velocity unknowns */
    int periodic[3];
    int lo[3];                /* the global index of st's cell 0 */
    const double *share[3];   /* the body's open shares on g, or NULL (no body) */
    int gathered;             /* 1: over ranks, the arrays below in use */
    struct march_state *st;
    struct viscous_operator op; /* the operator of this step (st's block) */
    double *own_share[3];     /* g's shares (gathered) */
    double *whole[3], *scratch;
    double *in[3], *out[3];   /* st's grid: the operator's block */
};

/* The view of st's grid (st kept, not copied).  NULL when out of memory. */
struct coupled_view *coupled_view_create(struct march_state *st);
void coupled_view_destroy(struct coupled_view *v);

/* f (an array of st's grid) on the whole grid: f itself on one process,
 * else gathered into buf (an array of v->g).  Collective over ranks. */
const double *coupled_view_whole(struct coupled_view *v, const double *f, double *buf);

/* The cells and faces of st's block from whole (an array of v->g) into f;
 * f's ghosts left alone.  Nothing on one process (f is whole). */
void coupled_view_part(const struct coupled_view *v, const double *whole, double *f);

/* A field array of v->g: on one process none is needed (NULL is
 * returned); free with field_free. */
double *coupled_view_field(const struct coupled_view *v);

/* The step's operator (pb, st's viscous solver) on whole-grid arrays, for
 * the probe matrix of v->g: on one process the solver's own. */
void coupled_view_operator(struct coupled_view *v, const struct viscous_problem *pb,
                           operator_fn *op, void **ctx);

/* The whole grid's slot of st's slot p. */
ptrdiff_t coupled_view_slot(const struct coupled_view *v, ptrdiff_t p);

#endif
