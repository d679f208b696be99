/* Restarted, right-preconditioned GMRES on flat vectors (gmres.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "solvers/gmres.h"
#include "grid/decomp.h"

struct gmres {
    long n;
    int m;
    double **v;  /* the basis, m + 1 vectors */
    double **zs; /* flexible: the preconditioned basis M^-1 v_k, m vectors; NULL: none */
    double *H;   /* H[i * m + j], (m + 1) x m, the rotated Hessenberg matrix */
    double *cs, *sn, *e, *y;
    double *r, *z;
    const struct decomp *dc; /* NULL: one process holds the vectors */
};

static int create(struct gmres **out, long n, int m, int flexible)
{
    struct gmres *g = calloc(1, sizeof *g);
    if (!g)
        return -1;
    g->n = n;
    g->m = m;
    size_t len = (size_t)(n > 0 ? n : 1);
    g->v = calloc((size_t)m + 1, sizeof *g->v);
    g->H = malloc(((size_t)(m + 1) * (size_t)m + 4 * (size_t)(m + 1)) * sizeof(double));
    g->r = malloc(len * sizeof(double));
    g->z = malloc(len * sizeof(double));
    if (flexible)
        g->zs = calloc((size_t)m, sizeof *g->zs);
    int ok = g->v && g->H && g->r && g->z && (!flexible || g->zs);
    for (int i = 0; ok && i <= m; i++)
        ok = (g->v[i] = malloc(len * sizeof(double))) != NULL;
    for (int i = 0; ok && flexible && i < m; i++)
        ok = (g->zs[i] = malloc(len * sizeof(double))) != NULL;
    if (!ok) {
        gmres_destroy(g);
        return -1;
    }
    g->cs = g->H + (size_t)(m + 1) * (size_t)m;
    g->sn = g->cs + m + 1;
    g->e = g->sn + m + 1;
    g->y = g->e + m + 1;
    *out = g;
    return 0;
}

int gmres_create(struct gmres **out, long n, int m)
{
    return create(out, n, m, 0);
}

int gmres_create_flexible(struct gmres **out, long n, int m)
{
    return create(out, n, m, 1);
}

void gmres_destroy(struct gmres *g)
{
    if (!g)
        return;
    for (int i = 0; g->v && i <= g->m; i++)
        free(g->v[i]);
    for (int i = 0; g->zs && i < g->m; i++)
        free(g->zs[i]);
    free(g->zs);
    free(g->v);
    free(g->H);
    free(g->r);
    free(g->z);
    free(g);
}

/* Serial sums: the order does not depend on the threads.  Four partial
 * sums (entries k mod 4), added in a fixed order at the end: one running
 * sum is a chain of dependent additions, four let the core overlap them
 * (and the compiler vectorise), and the order stays the same for any
 * thread count. */
static double local_dot(long n, const double *a, const double *b)
{
    double d[4] = {0.0, 0.0, 0.0, 0.0};
    long k = 0;
    for (; k + 4 <= n; k += 4)
        for (int j = 0; j < 4; j++)
            d[j] += a[k + j] * b[k + j];
    for (; k < n; k++)
        d[k & 3] += a[k] * b[k];
    return (d[0] + d[1]) + (d[2] + d[3]);
}

/* The dot product of the whole vectors (every rank's share). */
static double dot(const struct gmres *g, const double *a, const double *b)
{
    return decomp_sum(g->dc, local_dot(g->n, a, b));
}

void gmres_set_decomp(struct gmres *g, const struct decomp *dc) { g->dc = dc; }

static void axpy(long n, double a, const double *x, double *y)
{
    for (long k = 0; k < n; k++)
        y[k] += a * x[k];
}

/* r = b - A x */
static void residual(struct gmres *g, gmres_apply_fn op, void *ctx, const double *b,
                     const double *x)
{
    op(ctx, x, g->r);
    for (long k = 0; k < g->n; k++)
        g->r[k] = b[k] - g->r[k];
}

int gmres_solve(struct gmres *g, gmres_apply_fn op, gmres_apply_fn prec, void *ctx,
                const double *b, double *x, double rtol, int maxit, struct gmres_stats *st)
{
    const long n = g->n;
    const int m = g->m;
    double *H = g->H, *cs = g->cs, *sn = g->sn, *e = g->e, *y = g->y;
    double bnorm = sqrt(dot(g, b, b));
    st->iterations = 0;
    st->relative_residual = 0.0;
    if (!isfinite(bnorm))
        return -1;
    if (bnorm == 0.0) {
        memset(x, 0, (size_t)n * sizeof *x);
        return 0;
    }
    /* from x = 0 (the usual start) r = b without an operator application:
     * A 0 is 0 exactly, so nothing changes but the time */
    long nonzero = 0;
    while (nonzero < n && x[nonzero] == 0.0)
        nonzero++;
    if (nonzero == n)
        memcpy(g->r, b, (size_t)n * sizeof *b);
    else
        residual(g, op, ctx, b, x);
    int it = 0;
    for (;;) {
        double beta = sqrt(dot(g, g->r, g->r));
        st->iterations = it;
        st->relative_residual = beta / bnorm;
        if (!isfinite(beta))
            return -1;
        if (beta <= rtol * bnorm)
            return 0;
        if (it >= maxit)
            return 1;
        for (long q = 0; q < n; q++)
            g->v[0][q] = g->r[q] / beta;
        e[0] = beta;
        int k = 0;
        while (k < m && it < maxit) {
            double *w = g->v[k + 1], *zk = g->zs ? g->zs[k] : g->z;
            prec(ctx, g->v[k], zk); /* w = A M^-1 v_k */
            op(ctx, zk, w);
            it++;
            for (int i = 0; i <= k; i++) { /* modified Gram-Schmidt */
                double h = dot(g, w, g->v[i]);
                H[i * m + k] = h;
                axpy(n, -h, g->v[i], w);
            }
            double hn = sqrt(dot(g, w, w));
            H[(k + 1) * m + k] = hn;
            if (hn > 0.0)
                for (long q = 0; q < n; q++)
                    w[q] /= hn;
            for (int i = 0; i < k; i++) { /* earlier rotations */
                double a = H[i * m + k], c = H[(i + 1) * m + k];
                H[i * m + k] = cs[i] * a + sn[i] * c;
                H[(i + 1) * m + k] = -sn[i] * a + cs[i] * c;
            }
            double a = H[k * m + k], c = H[(k + 1) * m + k], d = hypot(a, c);
            if (!(d > 0.0) || !isfinite(d))
                return -1;
            cs[k] = a / d;
            sn[k] = c / d;
            H[k * m + k] = d;
            H[(k + 1) * m + k] = 0.0;
            e[k + 1] = -sn[k] * e[k];
            e[k] = cs[k] * e[k];
            k++;
            st->iterations = it;
            st->relative_residual = fabs(e[k]) / bnorm;
            if (fabs(e[k]) <= rtol * bnorm || hn == 0.0)
                break;
        }
        for (int i = k - 1; i >= 0; i--) { /* H y = e, upper triangular */
            double t = e[i];
            for (int j = i + 1; j < k; j++)
                t -= H[i * m + j] * y[j];
            y[i] = t / H[i * m + i];
        }
        /* x += M^-1 (V y), as Z y where the preconditioned basis is kept
         * (one preconditioner application less per restart); then the true
         * residual */
        if (g->zs) {
            for (int i = 0; i < k; i++)
                axpy(n, y[i], g->zs[i], x);
        } else {
            double *u = g->r;
            memset(u, 0, (size_t)n * sizeof *u);
            for (int i = 0; i < k; i++)
                axpy(n, y[i], g->v[i], u);
            prec(ctx, u, g->z);
            axpy(n, 1.0, g->z, x);
        }
        residual(g, op, ctx, b, x);
    }
}
