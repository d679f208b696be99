/* Sparse direct factorisation of the implicit operator, as a preconditioner.
 *
 * The operator stays matrix-free; this module recovers its matrix by probing
 * it with coloured vectors (an unknown reaches at most `reach` nodes in each
 * direction, so colours 2 reach + 1 nodes apart never meet in one row) and
 * factorises it: CHOLMOD's Cholesky for the symmetric positive definite
 * Picard and per-component tangent operators, UMFPACK's LU for the full
 * (non-symmetric) Newton Jacobian.  Used for two-dimensional scenes (cavity,
 * heap cross-section), where line blocks leave Krylov solvers with thousands
 * of iterations; with the exact factorisation a step is a Newton step whose
 * linear solve is exact, as with a direct solver.  Memory and time grow
 * faster than the unknowns: meant for up to a few hundred thousand unknowns. */
#ifndef MUFLOW_SPARSE_DIRECT_H
#define MUFLOW_SPARSE_DIRECT_H

#include <stddef.h>
#include "grid/grid.h"
#include "solvers/probe_matrix.h"

struct sparse_direct;

/* Numbering of the unknowns of act and the colouring for a stencil of the
 * given reach; symmetric selects Cholesky (else LU).  -1 with a message when
 * the colouring needs too many probes. */
int sparse_direct_create(struct sparse_direct **out, const struct grid *g, const int periodic[3],
                         const struct box act[3], int reach, int symmetric, char *err,
                         size_t errlen);
void sparse_direct_destroy(struct sparse_direct *s);

/* The probes (operator applications per factorisation) the colouring of
 * sparse_direct_create needs on g, and the most it accepts. */
int sparse_direct_probes_for(const struct grid *g, const int periodic[3], int reach);
int sparse_direct_max_probes(void);

/* Bytes of the matrix and factorisation for that many unknowns on a grid
 * varying in dims directions (a model fitted to measured peaks:
 * docs/numerics/memory-estimate.md). */
double sparse_direct_memory_estimate(long unknowns, int dims);
/* c log2(n) bytes an unknown on a 2D grid (nested dissection's fill), c
 * n^(1/3) 8 in 3D: the model of both sparse LUs' estimates. */
double sparse_fill_bytes(long unknowns, int dims, double c);

/* Probes op (work: two field triples, overwritten) and assembles its matrix,
 * to be factorised by sparse_direct_prepare: the columns of the given
 * components (bit c; 7: all), the others' rows the identity's
 * (probe_matrix_assemble_components; *probed: the components probed).
 * Returns 0, or -1 when memory runs out (sparse_direct_cause). */
int sparse_direct_factor(struct sparse_direct *s, operator_fn op, void *ctx, double *probe[3],
                         double *resp[3], int components, int *probed);

/* Factorises the blocks of components (those the matrix couples: one, or
 * two for a flow in a plane or along one direction) that r reaches and
 * that are not factorised yet: call it with the right-hand side before a
 * Krylov solve.  A block no right-hand side reaches is never factorised (a
 * plane flow's component across the plane).  Of two or more blocks, one
 * whose part of r has a norm of at most negligible (< 0: none) is left
 * out: sparse_direct_solve gives it 0 until the next prepare (the Krylov
 * method leaves its residual as it is).  Returns 0, or -1 when a
 * factorisation fails (sparse_direct_cause says why). */
int sparse_direct_prepare(struct sparse_direct *s, double *const r[3], double negligible);

/* Blocks the last sparse_direct_prepare left out, and their components
 * (bit c). */
int sparse_direct_dropped(const struct sparse_direct *s);
int sparse_direct_dropped_components(const struct sparse_direct *s);

/* z = A^-1 r on the unknowns (z elsewhere untouched); a block that r
 * reaches but sparse_direct_prepare did not (nor left out) is factorised
 * here (its part of z 0 if that fails). */
void sparse_direct_solve(struct sparse_direct *s, double *const r[3], double *z[3]);

/* The probed matrix it factorises (to teach it a pattern: probe_matrix_learn). */
struct probe_matrix *sparse_direct_probe_matrix(struct sparse_direct *s);
/* Why the last sparse_direct_factor failed, in words. */
const char *sparse_direct_cause(const struct sparse_direct *s);
long sparse_direct_unknowns(const struct sparse_direct *s);
int sparse_direct_probes(const struct sparse_direct *s);

#endif
