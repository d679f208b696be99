/* Compressed sparse rows (csr.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "solvers/csr.h"

int csr_reserve(struct csr_matrix *A, int n, size_t nz)
{
    if (A->n != n || !A->rowptr) {
        int *rp = realloc(A->rowptr, ((size_t)n + 1) * sizeof(int));
        if (!rp)
            return -1;
        A->rowptr = rp;
        A->n = n;
    }
    if (nz > A->cap || !A->col) {
        size_t cap = nz > 0 ? nz : 1;
        int *c = realloc(A->col, cap * sizeof(int));
        if (c)
            A->col = c;
        double *v = realloc(A->val, cap * sizeof(double));
        if (v)
            A->val = v;
        if (!c || !v)
            return -1;
        A->cap = cap;
    }
    return 0;
}

int csr_permute_lower(const struct csr_matrix *A, const int *place, int n, struct csr_matrix *P,
                      long *slot)
{
    const long nz = csr_nnz(A);
    int *row_next = calloc((size_t)n + 1, sizeof(int));
    int *col_next = malloc(((size_t)n + 1) * sizeof(int));
    int *by_row = malloc(((size_t)nz + 1) * sizeof(int)); /* entries by their new row */
    int *new_row = malloc(((size_t)nz + 1) * sizeof(int));
    int *new_col = malloc(((size_t)nz + 1) * sizeof(int));
    int ok = row_next && col_next && by_row && new_row && new_col;
    long kept = 0;
    if (ok) {
        /* entry e (column j, row A->col[e]) lands at the row max(place) of
         * the column min(place): the entries are bucketed by their new row,
         * then put into their new columns in that order, so that each
         * column's rows ascend */
        for (int j = 0; j < A->n; j++)
            for (int e = A->rowptr[j]; e < A->rowptr[j + 1]; e++) {
                int pi = place[A->col[e]], pj = place[j];
                if (pi < 0 || pj < 0) {
                    new_row[e] = -1;
                    continue;
                }
                new_row[e] = pi > pj ? pi : pj;
                new_col[e] = pi > pj ? pj : pi;
                row_next[new_row[e]]++;
                kept++;
            }
        ok = csr_reserve(P, n, (size_t)kept) == 0;
    }
    if (ok) {
        memset(P->rowptr, 0, ((size_t)n + 1) * sizeof(int));
        for (long e = 0; e < nz; e++)
            if (new_row[e] >= 0)
                P->rowptr[new_col[e] + 1]++;
        for (int k = 0, sum = 0; k < n; k++) { /* counts -> starts */
            int count = row_next[k];
            row_next[k] = sum;
            sum += count;
            P->rowptr[k + 1] += P->rowptr[k];
        }
        for (long e = 0; e < nz; e++)
            if (new_row[e] >= 0)
                by_row[row_next[new_row[e]]++] = (int)e;
            else
                slot[e] = -1;
        memcpy(col_next, P->rowptr, (size_t)n * sizeof(int));
        for (long q = 0; q < kept; q++) {
            int e = by_row[q], at = col_next[new_col[e]]++;
            slot[e] = at;
            P->col[at] = new_row[e];
        }
    }
    free(row_next), free(col_next), free(by_row), free(new_row), free(new_col);
    return ok ? 0 : -1;
}

int csr_transpose(const struct csr_matrix *A, struct csr_matrix *T)
{
    int n = A->n;
    size_t nz = (size_t)csr_nnz(A);
    if (csr_reserve(T, n, nz) != 0)
        return -1;
    memset(T->rowptr, 0, ((size_t)n + 1) * sizeof(int));
    for (size_t q = 0; q < nz; q++)
        T->rowptr[A->col[q] + 1]++;
    for (int r = 0; r < n; r++)
        T->rowptr[r + 1] += T->rowptr[r];
    for (int r = 0; r < n; r++) /* rows ascending: T's columns come out sorted */
        for (int a = A->rowptr[r]; a < A->rowptr[r + 1]; a++) {
            int at = T->rowptr[A->col[a]]++;
            T->col[at] = r;
            T->val[at] = A->val[a];
        }
    for (int r = n; r > 0; r--)
        T->rowptr[r] = T->rowptr[r - 1];
    T->rowptr[0] = 0;
    return 0;
}

int csr_same_pattern(const struct csr_matrix *A, const struct csr_matrix *B)
{
    if (!A->rowptr || !B->rowptr || A->n != B->n)
        return 0;
    if (memcmp(A->rowptr, B->rowptr, ((size_t)A->n + 1) * sizeof(int)) != 0)
        return 0;
    return memcmp(A->col, B->col, (size_t)csr_nnz(A) * sizeof(int)) == 0;
}

long csr_drop_component_roundoff(struct csr_matrix *M, const int *comp, double rel)
{
    /* the diagonals first: rows are rewritten in place below */
    double *diag = malloc(((size_t)M->n + 1) * sizeof(double));
    if (!diag)
        return 0; /* nothing dropped: the matrix stays as it is */
    for (int r = 0; r < M->n; r++) {
        diag[r] = 0.0;
        for (int e = M->rowptr[r]; e < M->rowptr[r + 1]; e++)
            if (M->col[e] == r)
                diag[r] = fabs(M->val[e]);
    }
    int w = 0;
    long dropped = 0;
    for (int r = 0; r < M->n; r++) {
        int e0 = M->rowptr[r], e1 = M->rowptr[r + 1];
        M->rowptr[r] = w;
        for (int e = e0; e < e1; e++) {
            int c = M->col[e];
            if (comp[c] != comp[r] && fabs(M->val[e]) <= rel * sqrt(diag[r] * diag[c])) {
                dropped++;
                continue;
            }
            M->col[w] = c;
            M->val[w++] = M->val[e];
        }
    }
    M->rowptr[M->n] = w;
    free(diag);
    return dropped;
}

void csr_component_groups(const struct csr_matrix *M, const int *comp, int group[3])
{
    int coupled[3][3] = {{0}};
    for (int r = 0; r < M->n; r++)
        for (int e = M->rowptr[r]; e < M->rowptr[r + 1]; e++)
            coupled[comp[r]][comp[M->col[e]]] = 1;
    /* three components: a coupling joins the later one to the earlier's group */
    for (int c = 0; c < 3; c++)
        group[c] = c;
    for (int a = 0; a < 3; a++)
        for (int b = a + 1; b < 3; b++)
            if (coupled[a][b] || coupled[b][a]) {
                int from = group[b], to = group[a];
                for (int c = 0; c < 3; c++)
                    if (group[c] == from)
                        group[c] = to;
            }
    /* numbered 0, 1, ... in the order of their first component */
    int number[3] = {-1, -1, -1}, next = 0;
    for (int c = 0; c < 3; c++) {
        if (number[group[c]] < 0)
            number[group[c]] = next++;
        group[c] = number[group[c]];
    }
}

double csr_vector_norm(const double *v, long n)
{
    double d = 0.0;
    for (long i = 0; i < n; i++)
        d += v[i] * v[i];
    return sqrt(d);
}

void csr_free(struct csr_matrix *A)
{
    free(A->rowptr);
    free(A->col);
    free(A->val);
    memset(A, 0, sizeof *A);
}
