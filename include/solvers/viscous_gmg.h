/* Geometric multigrid preconditioner of the implicit viscous step, matrix-free
 * (no probing, no factorisation but the multigrid's small coarsest level).
 *
 * A velocity component c along a periodic direction has its unknowns on a
 * box of the cell grid's shape (the faces normal to c, shifted by half a
 * cell along c), and its diagonal block of the operator is the scalar
 * variable-coefficient problem
 *
 *   m u - d_c(2 A_cell[c] d_c u) - sum_{e != c} d_e(A_edge[k] d_e u),  k = 3 - c - e,
 *
 * (plus the augmentation's d_c(r d_c u)), which multigrid.h solves with its
 * mass term: one W-cycle approximates the block's inverse.  The
 * coefficients are those the symmetric operator has (the viscosities, or
 * the diagonal tangent when Newton's full tangent is solved: the Cholesky
 * path's operator), plus, with Newton on a cross-section, the full
 * tangent's cross term between the two bounded directions
 * (multigrid_set_mixed: where the shear is oblique to the grid the
 * tangent's principal directions are too); viscous_krylov.c's GMRES solves
 * the whole operator with it.  The couplings between components (the transpose
 * part of the strain, the full tangent's b terms across components) are
 * left to GMRES: in a flow along one direction (the heap, the ducts, the
 * profile scenes) they vanish.  The other components (those along a
 * bounded direction) are not covered here: viscous_precond.c gives them
 * its line blocks.
 *
 * Conditions of a covered component on the faces across it: a wall or a
 * lid (the velocity held) is the multigrid's Dirichlet face, a slip wall or
 * the free surface (no shear) its Neumann face, periodic stays periodic;
 * open and inflow faces are refused at creation. */
#ifndef MUFLOW_VISCOUS_GMG_H
#define MUFLOW_VISCOUS_GMG_H

#include <stddef.h>
#include "grid/boundary.h"
#include "grid/grid.h"
#include "kernels/embedded.h"

struct viscous_gmg;

/* The operator's coefficients for viscous_gmg_setup (field arrays of the
 * grid, ghosts filled): the normal-stress coefficients per cell, the shear
 * coefficients per edge plane, the mass per face (rho_f / dt) or the
 * scalar mass, the augmentation r per cell or NULL, and for the cross term
 * Newton's edge coefficients b and the velocity the tangent is taken at. */
struct viscous_gmg_operator {
    const double *A_cell[3];
    const double *A_edge[3];
    const double *mass_face[3];
    double mass;
    const double *augmentation;
    /* Newton's full tangent (viscous.h): the edges' b and the velocity it is
     * taken at (ghosts filled), or NULL: its cross term between the two
     * bounded directions of a cross-section enters the multigrid */
    const double *b_edge[3];
    double *const *base;
    /* a body (or NULL): its held nodes become rows of the mass alone, their
     * couplings to the fluid nodes next to them a Dirichlet condition on
     * those (the mass term takes the coefficient), and the cut links join
     * the mass term of their node, as the operator has them */
    const struct embedded *embedded;
};

/* Why a grid of n cells with these conditions cannot take the multigrid
 * (a message naming solver.preconditioner = gmg), or NULL: it needs a
 * periodic direction, and every periodic direction one cell across (the
 * line smoother runs along the bounded directions). */
const char *viscous_gmg_refusal(const int n[3], const struct boundary *bc);

/* Builds the hierarchies of the components along periodic directions whose
 * unknowns fill the cell box (act[c] of bc_unknown_boxes).  Returns 0, or -1
 * with a message naming the cause (no periodic direction, an open or
 * inflow face across a covered component, a stretched grid, no memory).
 * On a grid split over ranks (bc->dc; g, act the rank's block) the
 * hierarchies are the whole cross-section's, on every rank: setup gathers
 * the operator's arrays (no body), apply each right-hand side, and a cycle
 * is one process's to the bit; setup and apply are then collective. */
int viscous_gmg_create(struct viscous_gmg **out, const struct grid *g, const struct boundary *bc,
                       const struct box act[3], char *err, size_t errlen);
void viscous_gmg_destroy(struct viscous_gmg *m);

/* Bit c set: component c is covered. */
int viscous_gmg_components(const struct viscous_gmg *m);

/* Sets each covered component's coefficients and mass (and factorises its
 * coarsest level).  Returns 0, or -1 with a message. */
int viscous_gmg_setup(struct viscous_gmg *m, const struct viscous_gmg_operator *op, char *err,
                      size_t errlen);

/* z[c] ~ (block c)^-1 r[c] for the covered components (one cycle each; the
 * others untouched).  r is read on the interior; z's interior is written. */
void viscous_gmg_apply(struct viscous_gmg *m, double *const r[3], double *z[3]);

/* Bytes held (the hierarchies and the coefficient work arrays). */
size_t viscous_gmg_bytes(const struct viscous_gmg *m);

/* Levels of component c's hierarchy (0: not covered). */
int viscous_gmg_levels(const struct viscous_gmg *m, int c);

#endif
