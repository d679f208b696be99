/* The saddle-point system of a coupled velocity-pressure step,
 *
 *     K = [ A  G ]    nu velocity unknowns, then nc pressures (cells);
 *         [ D  C ]    C is the identity on the cells whose pressure is held
 *                     (no open face, or pinned) and 0 elsewhere,
 *
 * solved by UMFPACK's sparse LU.  The symbolic analysis (the fill-reducing
 * ordering) depends on K's pattern only, which a steady march keeps from
 * step to step: it is kept and redone only when the pattern changes. */
#ifndef MUFLOW_SADDLE_POINT_H
#define MUFLOW_SADDLE_POINT_H

#include <stddef.h>
#include "solvers/probe_matrix.h"

struct saddle_point;

/* Returns 0, or -1 with a message (SuiteSparse's library missing). */
int saddle_point_create(struct saddle_point **out, char *err, size_t errlen);
void saddle_point_destroy(struct saddle_point *s);

/* K x = rhs, K by compressed rows: factorised, solved, the factors freed.
 * Returns 0, or -1 when K is singular or memory runs out, with the cause in
 * err (UMFPACK's status, the unknowns, its estimate of the peak memory). */
int saddle_point_solve(struct saddle_point *s, const struct csr_matrix *K, const double *rhs,
                       double *x, char *err, size_t errlen);

/* The same for nrhs right-hand sides with one factorisation. */
int saddle_point_solve_many(struct saddle_point *s, const struct csr_matrix *K, int nrhs,
                            const double *const *rhs, double *const *x, char *err, size_t errlen);

/* Bytes of the LU of a saddle-point system of this many unknowns on a grid
 * of dims dimensions (a model fitted to measured peaks, for the run's memory
 * estimate: docs/numerics/memory-estimate.md). */
double saddle_point_memory_estimate(long unknowns, int dims);
/* Bytes of the coupled matrices alone (no factorisation): what the coupled
 * GMRES holds beside its preconditioner. */
double saddle_point_matrix_estimate(long unknowns, int dims);

#endif
