/* Sparse Cholesky preconditioner for the implicit viscous operator.
 *
 * The operator stays matrix-free; this module recovers its matrix by probing
 * it with coloured vectors (every unknown reaches at most one node in each
 * direction, so colours three nodes apart never meet in one row), and
 * factorises it with CHOLMOD.  Used for two-dimensional scenes (cavity, heap
 * cross-section), where line blocks alone leave CG with thousands of
 * iterations: an exact factorisation turns the step into a Newton step whose
 * linear solve takes one or two CG iterations, as a direct solver would.
 * Memory and time grow faster than the unknowns, so it is meant for grids of
 * up to a few hundred thousand unknowns. */
#ifndef MUFLOW_SPARSE_CHOL_H
#define MUFLOW_SPARSE_CHOL_H

#include <stddef.h>
#include "grid.h"

struct sparse_chol;

/* The operator to probe: out = A v (v's ghosts may be overwritten). */
typedef void (*operator_fn)(void *ctx, double *v[3], double *out[3]);

/* Numbering of the unknowns of act and the colouring; -1 with a message when
 * the colouring needs too many probes (a periodic direction whose cell count
 * has no small divisor). */
int sparse_chol_create(struct sparse_chol **out, const struct grid *g, const int periodic[3],
                       const struct box act[3], char *err, size_t errlen);
void sparse_chol_destroy(struct sparse_chol *s);

/* Probes op (work: two field triples, overwritten), assembles and factorises.
 * Returns 0, or -1 when the matrix is not positive definite. */
int sparse_chol_factor(struct sparse_chol *s, operator_fn op, void *ctx, double *probe[3],
                       double *resp[3]);

/* z = A^-1 r on the unknowns (z elsewhere untouched). */
void sparse_chol_solve(struct sparse_chol *s, double *const r[3], double *z[3]);

/* Unknowns and probes per factorisation. */
long sparse_chol_unknowns(const struct sparse_chol *s);
int sparse_chol_probes(const struct sparse_chol *s);

#endif
