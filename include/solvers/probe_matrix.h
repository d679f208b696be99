/* The matrix of a matrix-free operator, recovered by probing.
 *
 * The unknowns are the velocity faces of the boxes act[c], numbered component
 * by component.  An unknown reaches at most `reach` nodes in each direction,
 * so unknowns of one component whose positions agree modulo 2 reach + 1 in
 * every direction (one colour) never meet in a row: one operator application
 * per colour and component gives every entry.  The result is a compressed
 * sparse row matrix (exact zeros dropped, columns sorted in each row), which
 * feeds a sparse factorisation (sparse_direct.h) or algebraic multigrid
 * (amg_hypre.h) alike. */
#ifndef MUFLOW_PROBE_MATRIX_H
#define MUFLOW_PROBE_MATRIX_H

#include <stddef.h>
#include "grid/grid.h"
#include "solvers/csr.h"

/* The operator to probe: out = A v (v's ghosts may be overwritten). */
typedef void (*operator_fn)(void *ctx, double *v[3], double *out[3]);

struct probe_matrix;

/* Numbering of the unknowns of act and the colouring for a stencil of the
 * given reach.  -1 with a message when the colouring needs too many probes
 * (a periodic cell count without a small divisor) or memory runs out. */
int probe_matrix_create(struct probe_matrix **out, const struct grid *g, const int periodic[3],
                        const struct box act[3], int reach, char *err, size_t errlen);
void probe_matrix_destroy(struct probe_matrix *pm);

long probe_matrix_unknowns(const struct probe_matrix *pm);
int probe_matrix_probes(const struct probe_matrix *pm);
/* Velocity component (0, 1, 2) of each unknown. */
const int *probe_matrix_components(const struct probe_matrix *pm);

/* Probes op (work: two field triples, overwritten) into A (its arrays are
 * reused and grown as needed; zero-initialise A before the first call).
 * lower: keep only the lower triangle (columns <= row), for a symmetric
 * operator.  Returns 0, or -1 when memory runs out. */
int probe_matrix_assemble(struct probe_matrix *pm, operator_fn op, void *ctx, double *probe[3],
                          double *resp[3], int lower, struct csr_matrix *A);
/* The same for the columns of the given components only (bit c for
 * component c), the rows of the others made the identity's: the matrix of
 * a solve that leaves those components out (their part of the right-hand
 * side negligible), at the probes of a colouring of the columns kept (the
 * heap's full tangent: 13 for its flow component instead of 41 for all).
 * Needs the learnt colouring; without it, or with every component present,
 * the whole matrix.  *probed: the components whose columns were probed (7:
 * all).  Returns as probe_matrix_assemble. */
int probe_matrix_assemble_components(struct probe_matrix *pm, operator_fn op, void *ctx,
                                     double *probe[3], double *resp[3], int lower,
                                     int components, struct csr_matrix *A, int *probed);
/* Probes of the last such assembly's colouring (0 before any). */
int probe_matrix_subset_probes(const struct probe_matrix *pm);
/* The norm of r over the unknowns of the given components. */
double probe_matrix_components_norm(const struct probe_matrix *pm, double *const r[3],
                                    int components);

/* Learns the pattern of op (an operator whose pattern holds that of every
 * operator this matrix will assemble: generic coefficients) with the
 * structured colouring, and colours its columns greedily so that no two of
 * a colour share a row: later assemblies probe once per colour (the 2D
 * Picard operator: 9 probes instead of 27; the 2D full tangent: 41 instead
 * of 75, its rows holding 29 columns) and write each response straight to
 * its entry, row by row.  The pattern is kept (4 bytes an entry and a byte
 * per colour and unknown).  A probe whose response reaches a row where its
 * colour has no column (an operator outside the pattern) makes the
 * assembly start again with the structured colouring, which is kept from
 * then on (probe_matrix_broken counts these); a response in a row where its
 * colour has a column is taken as that column's.  Returns 0, or -1 when the
 * structured colouring stays (no memory, no fewer probes, or a row of 255
 * columns or more). */
int probe_matrix_learn(struct probe_matrix *pm, operator_fn op, void *ctx, double *probe[3],
                       double *resp[3]);
/* Back to the structured colouring. */
void probe_matrix_forget(struct probe_matrix *pm);
/* Assemblies whose operator left the learnt pattern. */
long probe_matrix_broken(const struct probe_matrix *pm);

/* b[k] = r at unknown k; z at unknown k = x[k] (z elsewhere untouched). */
void probe_matrix_gather(const struct probe_matrix *pm, double *const r[3], double *b);
void probe_matrix_scatter(const struct probe_matrix *pm, const double *x, double *z[3]);

/* The probes a matrix of this grid would need, and the most that are
 * accepted (beyond it the colouring is refused: periodic cell counts without
 * a small divisor). */
int probe_matrix_probes_for(const struct grid *g, const int periodic[3], int reach);
int probe_matrix_max_probes(void);

#endif
