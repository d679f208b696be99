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

/* The operator to probe: out = A v (v's ghosts may be overwritten). */
typedef void (*operator_fn)(void *ctx, double *v[3], double *out[3]);

/* Compressed sparse rows: row r's columns col[rowptr[r] .. rowptr[r+1]-1],
 * ascending, with their values.  Read as compressed columns, the same arrays
 * hold the transpose. */
struct csr_matrix {
    int n;            /* rows = columns */
    int *rowptr;      /* n + 1 */
    int *col;
    double *val;
    size_t cap;       /* allocated entries of col and val */
};

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

/* b[k] = r at unknown k; z at unknown k = x[k] (z elsewhere untouched). */
void probe_matrix_gather(const struct probe_matrix *pm, double *const r[3], double *b);
void probe_matrix_scatter(const struct probe_matrix *pm, const double *x, double *z[3]);

/* Room for n rows and nz entries in A (its arrays reused and grown as
 * needed; zero-initialise A before the first call).  Returns 0 or -1. */
int csr_reserve(struct csr_matrix *A, int n, size_t nz);
/* T = A^T (T's arrays reused and grown as needed).  Returns 0 or -1. */
int csr_transpose(const struct csr_matrix *A, struct csr_matrix *T);

/* Drops, in place, the entries between different velocity components (comp
 * of each unknown) at most rel times the geometric mean of their row's and
 * column's diagonals: the round-off that a flow along one direction leaves
 * between its component and the two across it (the tangent's base strain
 * across is the march's round-off), which would couple blocks that are
 * apart.  Returns the entries dropped. */
long csr_drop_component_roundoff(struct csr_matrix *M, const int *comp, double rel);
/* Entries of A. */
static inline long csr_nnz(const struct csr_matrix *A) { return A->n ? A->rowptr[A->n] : 0; }
/* Same rows and columns (pattern) as B. */
int csr_same_pattern(const struct csr_matrix *A, const struct csr_matrix *B);
void csr_free(struct csr_matrix *A);

/* The probes a matrix of this grid would need, and the most that are
 * accepted (beyond it the colouring is refused: periodic cell counts without
 * a small divisor). */
int probe_matrix_probes_for(const struct grid *g, const int periodic[3], int reach);
int probe_matrix_max_probes(void);

#endif
