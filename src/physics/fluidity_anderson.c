/* Anderson acceleration of the nonlocal fluidity's steady iteration
 * (physics/fluidity_anderson.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "physics/fluidity_anderson.h"
#include "march/march.h"

#define ANDERSON_DEPTH_MAX 16

struct fluidity_anderson {
    size_t n;
    int depth;
    int count;       /* pairs held, <= depth + 1 */
    int newest;      /* the ring's slot of the newest pair */
    double *f, *gx;  /* (depth + 1) x n: G_j - g_j and G_j */
};

struct fluidity_anderson *fluidity_anderson_create(size_t n, int depth)
{
    if (depth < 1 || depth > ANDERSON_DEPTH_MAX)
        return NULL;
    struct fluidity_anderson *a = calloc(1, sizeof *a);
    if (!a)
        return NULL;
    a->n = n;
    a->depth = depth;
    a->f = malloc((size_t)(depth + 1) * n * sizeof(double));
    a->gx = malloc((size_t)(depth + 1) * n * sizeof(double));
    if (!a->f || !a->gx) {
        fluidity_anderson_destroy(a);
        return NULL;
    }
    return a;
}

void fluidity_anderson_destroy(struct fluidity_anderson *a)
{
    if (!a)
        return;
    free(a->f);
    free(a->gx);
    free(a);
}

void fluidity_anderson_reset(struct fluidity_anderson *a) { a->count = 0; }

double *fluidity_anderson_slot(struct fluidity_anderson *a, int map_value, int slot)
{
    return (map_value ? a->gx : a->f) + (size_t)slot * a->n;
}

int fluidity_anderson_newest_slot(const struct fluidity_anderson *a) { return a->newest; }

void fluidity_anderson_get_state(const struct fluidity_anderson *a, double s[2])
{
    s[0] = a->count;
    s[1] = a->newest;
}

int fluidity_anderson_set_state(struct fluidity_anderson *a, const double s[2])
{
    if (!(s[0] >= 0 && s[0] <= a->depth + 1 && s[1] >= 0 && s[1] <= a->depth))
        return -1;
    a->count = (int)s[0];
    a->newest = (int)s[1];
    return 0;
}

double fluidity_anderson_bytes(size_t n, int depth)
{
    return 2.0 * (depth + 1) * (double)n * sizeof(double) + sizeof(struct fluidity_anderson);
}

/* Solves the m x m system M y = b (row-major, overwritten) by elimination
 * with partial pivoting; -1 when a pivot falls below tiny times the
 * largest diagonal entry (columns nearly dependent: the caller drops the
 * oldest). */
static int solve_small(int m, double *M, double *b, double *y)
{
    double diag = 0.0;
    for (int i = 0; i < m; i++)
        diag = fmax(diag, M[i * m + i]);
    const double tiny = 1e-13 * diag;
    for (int c = 0; c < m; c++) {
        int piv = c;
        for (int r = c + 1; r < m; r++)
            if (fabs(M[r * m + c]) > fabs(M[piv * m + c]))
                piv = r;
        if (!(fabs(M[piv * m + c]) > tiny))
            return -1;
        if (piv != c) {
            for (int k = 0; k < m; k++) {
                double t = M[c * m + k];
                M[c * m + k] = M[piv * m + k];
                M[piv * m + k] = t;
            }
            double t = b[c];
            b[c] = b[piv];
            b[piv] = t;
        }
        for (int r = c + 1; r < m; r++) {
            double l = M[r * m + c] / M[c * m + c];
            for (int k = c; k < m; k++)
                M[r * m + k] -= l * M[c * m + k];
            b[r] -= l * b[c];
        }
    }
    for (int c = m - 1; c >= 0; c--) {
        double s = b[c];
        for (int k = c + 1; k < m; k++)
            s -= M[c * m + k] * y[k];
        y[c] = s / M[c * m + c];
    }
    return 0;
}

/* The ring's slot j pairs back from the newest (0: the newest). */
static int slot_back(const struct fluidity_anderson *a, int j)
{
    return (a->newest - j + a->depth + 1) % (a->depth + 1);
}

/* The coefficients gamma of the least-squares problem
 * min || f_k - sum_j gamma_j (f_k - f_{k-j}) ||, j = 1 .. m; the m actually
 * taken (the oldest columns dropped while the system is singular). */
static int least_squares(const struct fluidity_anderson *a, const struct march_state *st, int m,
                         double *gamma)
{
    const size_t n = a->n;
    const double *fk = a->f + (size_t)a->newest * n;
    double sums[ANDERSON_DEPTH_MAX * (ANDERSON_DEPTH_MAX + 1)] = {0};
    /* sums: the Gram matrix of the differences (m x m), then their
     * products with f_k (m) */
    for (int j = 0; j < m; j++) {
        const double *fj = a->f + (size_t)slot_back(a, j + 1) * n;
        for (int l = 0; l <= j; l++) {
            const double *fl = a->f + (size_t)slot_back(a, l + 1) * n;
            double s = 0.0;
            for (size_t q = 0; q < n; q++)
                s += (fk[q] - fj[q]) * (fk[q] - fl[q]);
            sums[j * m + l] = s;
        }
        double s = 0.0;
        for (size_t q = 0; q < n; q++)
            s += (fk[q] - fj[q]) * fk[q];
        sums[m * m + j] = s;
    }
    march_sum_array(st, sums, m * m + m);
    for (int mm = m; mm >= 1; mm--) {
        /* the leading mm columns: the newest differences */
        double M[ANDERSON_DEPTH_MAX * ANDERSON_DEPTH_MAX], b[ANDERSON_DEPTH_MAX];
        for (int j = 0; j < mm; j++) {
            for (int l = 0; l <= j; l++)
                M[j * mm + l] = M[l * mm + j] = sums[j * m + l];
            b[j] = sums[m * m + j];
        }
        if (solve_small(mm, M, b, gamma) == 0)
            return mm;
    }
    return 0;
}

double fluidity_anderson_push(struct fluidity_anderson *a, const struct march_state *st,
                              const double *x, const double *gx)
{
    const size_t n = a->n;
    a->newest = a->count == 0 ? 0 : (a->newest + 1) % (a->depth + 1);
    a->count = a->count < a->depth + 1 ? a->count + 1 : a->count;
    double *fk = a->f + (size_t)a->newest * n, *gk = a->gx + (size_t)a->newest * n;
    double ff = 0.0;
    for (size_t q = 0; q < n; q++) {
        fk[q] = gx[q] - x[q];
        gk[q] = gx[q];
        ff += fk[q] * fk[q];
    }
    return sqrt(march_sum(st, ff));
}

void fluidity_anderson_keep_newest(struct fluidity_anderson *a)
{
    a->count = a->count > 0;
}

void fluidity_anderson_next(const struct fluidity_anderson *a, const struct march_state *st,
                            double *next)
{
    const size_t n = a->n;
    const double *gk = a->gx + (size_t)a->newest * n;
    double gamma[ANDERSON_DEPTH_MAX];
    int m = a->count > 1 ? least_squares(a, st, a->count - 1, gamma) : 0;
    for (size_t q = 0; q < n; q++) {
        double v = gk[q];
        for (int j = 0; j < m; j++)
            v -= gamma[j] * (gk[q] - a->gx[(size_t)slot_back(a, j + 1) * n + q]);
        /* cut at 0; a NaN (a failed solve) is kept: the step is rejected */
        next[q] = v < 0.0 ? 0.0 : v;
    }
}
