/* Compressed sparse rows: the matrices the probing assembles (probe_matrix.h)
 * and the factorisations and algebraic multigrid take. */
#ifndef MUFLOW_CSR_H
#define MUFLOW_CSR_H

#include <stddef.h>

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

/* Room for n rows and nz entries in A (its arrays reused and grown as
 * needed; zero-initialise A before the first call).  Returns 0 or -1. */
int csr_reserve(struct csr_matrix *A, int n, size_t nz);
/* T = A^T (T's arrays reused and grown as needed).  Returns 0 or -1. */
int csr_transpose(const struct csr_matrix *A, struct csr_matrix *T);

/* The lower triangle, by columns, of the symmetric matrix whose unknown
 * place[i] is A's unknown i (place[i] -1: left out), n unknowns, from A's
 * lower triangle by columns (rows >= the column).  Each column's rows
 * ascend; slot[e] is where A's entry e goes in P (-1: left out), so that
 * later values of A's pattern are copied in one pass (P's values are not
 * set here).  Returns 0 or -1 (memory). */
int csr_permute_lower(const struct csr_matrix *A, const int *place, int n, struct csr_matrix *P,
                      long *slot);

/* Drops, in place, the entries between different velocity components (comp
 * of each unknown) at most rel times the geometric mean of their row's and
 * column's diagonals: the round-off that a flow along one direction leaves
 * between its component and the two across it (the tangent's base strain
 * across is the march's round-off), which would couple blocks that are
 * apart.  Returns the entries dropped. */
long csr_drop_component_roundoff(struct csr_matrix *M, const int *comp, double rel);
/* The velocity components (comp of each unknown, 0 to 2) that M's entries
 * couple, directly or through another: group[c] numbers component c's
 * group, 0, 1, ... in the order of the groups' first components. */
void csr_component_groups(const struct csr_matrix *M, const int *comp, int group[3]);
/* Entries of A. */
static inline long csr_nnz(const struct csr_matrix *A) { return A->n ? A->rowptr[A->n] : 0; }
/* Same rows and columns (pattern) as B. */
int csr_same_pattern(const struct csr_matrix *A, const struct csr_matrix *B);
void csr_free(struct csr_matrix *A);

/* The Euclidean norm of v[0 .. n-1] (a vector in a matrix's numbering). */
double csr_vector_norm(const double *v, long n);

#endif
