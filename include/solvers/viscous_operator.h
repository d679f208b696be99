/* The implicit viscous step's operator, matrix-free,
 *   (mass) v - div tau(v) [- grad(r div v)] [- div(b d|D|^2[v] gamma(base))],
 * on any grid and its boxes of unknowns: what the Krylov solvers apply, and
 * what every level of the velocity multigrid applies on its own grid. */
#ifndef MUFLOW_VISCOUS_OPERATOR_H
#define MUFLOW_VISCOUS_OPERATOR_H

#include <stddef.h>
#include "grid/boundary.h"
#include "grid/grid.h"
#include "kernels/embedded.h"

struct viscous_problem {
    double mass;                  /* rho / dt (the scale, and the mass term when
                                     mass_face is NULL) */
    const double *mass_face[3];   /* rho_f / dt per face (variable density), or NULL */
    const double *augmentation;   /* cell field r >= 0 (ghosts filled) or NULL: adds
                                     -grad(r div x), the augmented-Lagrangian term that
                                     lets the pressure converge in few steps */
    const double *A_cell[3];      /* normal-stress coefficients, ghosts filled */
    const double *A_edge[3];      /* shear-stress coefficients per edge plane */
    /* Full consistent tangent (non-symmetric): with b_cell set, the operator
     * adds -div(b d|D|^2[x] gamma(base)) (kernels.h); A_* are then the
     * viscosities.  NULL: the symmetric operator above. */
    const double *b_cell;
    const double *b_edge[3];
    double *const *base;          /* the velocity the tangent is taken at */
    /* With the full tangent, the coefficients of the symmetric operator a
     * Cholesky factorisation takes instead (VISCOUS_CHOLESKY): the diagonal
     * tangent, normal and shear; NULL: A_* (the lagged viscosity) */
    const double *sym_cell[3];
    const double *sym_edge[3];
    /* an embedded solid body (kernels/embedded.h), or NULL: its nodes are
     * held at 0 with mass-only rows, and the links the surface cuts end on it */
    const struct embedded *embedded;
    /* 1: the open faces' normal increments are given, not the inner faces'
     * (boundary.h, bc_fill_velocity_open_given) */
    int open_given;
};

/* Work arrays of the operator on one grid: the augmentation's divergence,
 * and (with the full tangent) the strain products and tangent stresses. */
struct viscous_work {
    double *divbuf;
    double *pn, *pe[3], *Bc, *Be[3], *tmp[3]; /* NULL: no full tangent */
};

/* Allocates the work of g (full: also the full tangent's).  Returns 0, or -1
 * when out of memory (nothing held). */
int viscous_work_create(struct viscous_work *w, const struct grid *g, int full);
void viscous_work_destroy(struct viscous_work *w);
/* Bytes of the work arrays on g. */
double viscous_work_bytes(const struct grid *g, int full);

/* out = operator(v) on the boxes act; v's ghosts are overwritten (filled
 * from bc); the full tangent's terms only when pb->b_cell is set and w has
 * their work arrays. */
void viscous_operator_eval(const struct grid *g, const struct boundary *bc,
                           const struct box act[3], const struct viscous_work *w,
                           const struct viscous_problem *pb, double *v[3], double *out[3]);

/* The operator's rows of component c alone: out[c] on act[c] (the other
 * components of out are left as they are, or hold work values), for the
 * symmetric operator (pb's full tangent is not applied). */
void viscous_operator_rows(const struct grid *g, const struct boundary *bc, const struct box act[3],
                           const struct viscous_work *w, const struct viscous_problem *pb, int c,
                           double *v[3], double *out[3]);

/* An embedded body's share of -div tau (kernels/embedded.h): the links the
 * surface cuts end on it, and the Laplacian form, -div tau + grad(A div v)
 * with A = A_cell[0] (the cut cells' plain divergence is not 0).  scale 1:
 * the implicit operator's (mass - div tau) v; -1: the residual's + div tau.
 * One place for both, so the operator stays the residual's linearisation. */
void viscous_embedded_terms(const struct grid *g, const struct boundary *bc,
                            const struct box act[3], const struct embedded *e,
                            const double *const A_cell[3], const double *const A_edge[3],
                            double scale, double *const v[3], double *out[3]);

#endif
