/* GMRES with a block-triangular preconditioner for the coupled step
 * (saddle_krylov.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "solvers/gmres.h"
#include "solvers/saddle_krylov.h"

/* GMRES's restart: above the iterations a step takes on the cavity up to
 * 128 x 128, so that a solve rarely restarts (a restart costs iterations:
 * docs/numerics/coupled-step.md) */
#define SADDLE_RESTART 64
/* the multigrid variant's: on the granular cylinder at D/4 GMRES(64)
 * stagnated (a relative residual of 5e-2 after 500 iterations) where
 * GMRES(300) converged (docs/numerics/coupled-step.md) */
#define SADDLE_RESTART_MG 300

const char *saddle_krylov_refusal(enum rheology_law law, const struct boundary *bc)
{
    if (law == LAW_MUI)
        return "needs a law without the pressure's dependence (rheology.law = bingham or "
               "newtonian) with solver.preconditioner = amg: on mu(I) its GMRES steps diverged "
               "(the granular cylinder); set solver.preconditioner = lu";
    if (bc_has_open(bc))
        return "with solver.preconditioner = amg needs no open face (its GMRES is not measured "
               "there); set solver.preconditioner = lu";
    return NULL;
}

struct saddle_krylov {
    int n, nu;
    struct amg_hypre *amg;     /* NULL: the caller's velocity preconditioner */
    const struct saddle_velocity_precond *vp; /* the solve under way's, or NULL */
    /* the pressures' rows: the free cells' (a divergence row, no diagonal)
       take the least-squares commutator; the others S's diagonal */
    int nf;                    /* free rows */
    int *free_of;              /* row r - nu's free number, -1 if not free */
    int *free_row;             /* free number's row */
    struct amg_hypre *amg_m;   /* on M, created with the first system */
    struct csr_matrix M;       /* -D W B on the free rows, W = diag(A)^-1 */
    double *pf, *pg;           /* free-sized work */
    double *u1, *u2;           /* velocity-sized work */
    struct gmres *gm;
    struct csr_matrix A;       /* K's velocity block, handed to the AMG (which
                                  releases it) */
    const struct csr_matrix *K; /* the system of the solve under way */
    double *schur_inv;         /* 1 / S per unknown beyond nu (0 on free rows) */
    double *diag;              /* A's diagonal */
    double *t;                 /* velocity-sized work */
};

int saddle_krylov_create(struct saddle_krylov **out, int n, int nu, const int *comp,
                         const struct amg_options *o, char *err, size_t errlen)
{
    struct saddle_krylov *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "coupled step's GMRES: out of memory");
        return -1;
    }
    s->n = n;
    s->nu = nu;
    if (amg_hypre_create(&s->amg, nu, comp, o, err, errlen) != 0) {
        saddle_krylov_destroy(s);
        return -1;
    }
    size_t np = (size_t)(n - nu) + 1, nv = (size_t)nu + 1;
    s->schur_inv = malloc(np * sizeof(double));
    s->diag = malloc(nv * sizeof(double));
    s->t = malloc(nv * sizeof(double));
    s->u1 = malloc(nv * sizeof(double));
    s->u2 = malloc(nv * sizeof(double));
    s->free_of = malloc(np * sizeof(int));
    s->free_row = malloc(np * sizeof(int));
    s->pf = malloc(np * sizeof(double));
    s->pg = malloc(np * sizeof(double));
    if (!s->schur_inv || !s->diag || !s->t || !s->u1 || !s->u2 || !s->free_of ||
        !s->free_row || !s->pf || !s->pg ||
        gmres_create(&s->gm, n, SADDLE_RESTART) != 0) {
        saddle_krylov_destroy(s);
        snprintf(err, errlen, "coupled step's GMRES: out of memory");
        return -1;
    }
    *out = s;
    return 0;
}

int saddle_krylov_create_mg(struct saddle_krylov **out, int n, int nu, char *err, size_t errlen)
{
    struct saddle_krylov *s = calloc(1, sizeof *s);
    size_t np = (size_t)(n - nu) + 1, nv = (size_t)nu + 1;
    if (s) {
        s->n = n;
        s->nu = nu;
        s->schur_inv = malloc(np * sizeof(double));
        s->diag = malloc(nv * sizeof(double));
        s->t = malloc(nv * sizeof(double));
        s->free_of = malloc(np * sizeof(int));
        s->free_row = malloc(np * sizeof(int));
    }
    if (!s || !s->schur_inv || !s->diag || !s->t || !s->free_of || !s->free_row ||
        gmres_create(&s->gm, n, SADDLE_RESTART_MG) != 0) {
        saddle_krylov_destroy(s);
        snprintf(err, errlen, "coupled step's GMRES: out of memory");
        return -1;
    }
    *out = s;
    return 0;
}

void saddle_krylov_destroy(struct saddle_krylov *s)
{
    if (!s)
        return;
    amg_hypre_destroy(s->amg);
    amg_hypre_destroy(s->amg_m);
    csr_free(&s->M);
    free(s->free_of);
    free(s->free_row);
    free(s->pf);
    free(s->pg);
    free(s->u1);
    free(s->u2);
    gmres_destroy(s->gm);
    csr_free(&s->A);
    free(s->schur_inv);
    free(s->diag);
    free(s->t);
    free(s);
}

/* K's entry (r, c), 0 if not stored (columns ascending). */
static double entry(const struct csr_matrix *K, int r, int c)
{
    int lo = K->rowptr[r], hi = K->rowptr[r + 1] - 1;
    while (lo <= hi) {
        int mid = (lo + hi) / 2;
        if (K->col[mid] == c)
            return K->val[mid];
        if (K->col[mid] < c)
            lo = mid + 1;
        else
            hi = mid - 1;
    }
    return 0.0;
}

/* The free rows: a pressure row with a divergence (columns below nu) and
 * no diagonal. */
static void number_free(struct saddle_krylov *s, const struct csr_matrix *K)
{
    s->nf = 0;
    for (int r = s->nu; r < s->n; r++) {
        int reaches = 0;
        double d = 0.0;
        for (int q = K->rowptr[r]; q < K->rowptr[r + 1]; q++) {
            reaches |= K->col[q] < s->nu;
            if (K->col[q] == r)
                d = K->val[q];
        }
        s->free_of[r - s->nu] = reaches && d == 0.0 ? s->nf : -1;
        if (s->free_of[r - s->nu] >= 0)
            s->free_row[s->nf++] = r;
    }
}

/* M = -D W B on the free rows and columns, W = diag(A)^-1: a pressure
 * Laplacian weighted by each face's inverse diagonal (positive diagonal). */
static int form_M(struct saddle_krylov *s, const struct csr_matrix *K)
{
    const int nu = s->nu, nf = s->nf;
    int *mark = malloc(((size_t)nf + 1) * sizeof *mark);
    if (!mark)
        return -1;
    for (int c = 0; c < nf; c++)
        mark[c] = -1;
    /* pass 0 counts the entries, pass 1 fills them */
    for (int pass = 0; pass < 2; pass++) {
        long nz = 0;
        if (pass == 1)
            s->M.rowptr[0] = 0;
        for (int f = 0; f < nf; f++) {
            int r = s->free_row[f];
            long row_start = nz;
            for (int q = K->rowptr[r]; q < K->rowptr[r + 1]; q++) {
                int k = K->col[q];
                if (k >= nu || s->diag[k] == 0.0)
                    continue;
                double dw = -K->val[q] / s->diag[k];
                for (int b = K->rowptr[k + 1] - 1; b >= K->rowptr[k] && K->col[b] >= nu; b--) {
                    int c = s->free_of[K->col[b] - nu];
                    if (c < 0)
                        continue;
                    if (mark[c] < row_start) {
                        mark[c] = (int)nz;
                        if (pass == 1) {
                            s->M.col[nz] = c;
                            s->M.val[nz] = 0.0;
                        }
                        nz++;
                    }
                    if (pass == 1)
                        s->M.val[mark[c]] += dw * K->val[b];
                }
            }
            if (pass == 1)
                s->M.rowptr[f + 1] = (int)nz;
        }
        for (int c = 0; c < nf; c++)
            mark[c] = -1;
        if (pass == 0 && csr_reserve(&s->M, nf, (size_t)nz) != 0) {
            free(mark);
            return -1;
        }
    }
    free(mark);
    /* columns ascending within each row */
    for (int f = 0; f < nf; f++)
        for (int a = s->M.rowptr[f] + 1; a < s->M.rowptr[f + 1]; a++)
            for (int b = a; b > s->M.rowptr[f] && s->M.col[b - 1] > s->M.col[b]; b--) {
                int tc = s->M.col[b];
                double tv = s->M.val[b];
                s->M.col[b] = s->M.col[b - 1];
                s->M.val[b] = s->M.val[b - 1];
                s->M.col[b - 1] = tc;
                s->M.val[b - 1] = tv;
            }
    return 0;
}

/* A = K's velocity block, its diagonal, S's inverse diagonal and M. */
static int split(struct saddle_krylov *s, const struct csr_matrix *K)
{
    const int nu = s->nu;
    if (s->amg) {
        long nz = 0;
        for (int r = 0; r < nu; r++)
            for (int q = K->rowptr[r]; q < K->rowptr[r + 1]; q++)
                nz += K->col[q] < nu;
        if (csr_reserve(&s->A, nu, (size_t)nz) != 0)
            return -1;
        long at = 0;
        s->A.rowptr[0] = 0;
        for (int r = 0; r < nu; r++) {
            for (int q = K->rowptr[r]; q < K->rowptr[r + 1]; q++)
                if (K->col[q] < nu) {
                    s->A.col[at] = K->col[q];
                    s->A.val[at++] = K->val[q];
                }
            s->A.rowptr[r + 1] = (int)at;
        }
    }
    for (int r = 0; r < nu; r++)
        s->diag[r] = entry(K, r, r);
    number_free(s, K);
    for (int r = nu; r < s->n; r++) {
        double S = 0.0;
        if (s->free_of[r - nu] >= 0) { /* the commutator's (apply_P) */
            s->schur_inv[r - nu] = 0.0;
            continue;
        }
        for (int q = K->rowptr[r]; q < K->rowptr[r + 1]; q++) {
            int k = K->col[q];
            if (k == r)
                S += K->val[q];
            else if (k < nu && s->diag[k] != 0.0)
                S -= K->val[q] * entry(K, k, r) / s->diag[k];
        }
        /* a row S leaves at 0 (none of its columns reach a velocity with a
           diagonal) is left as it is */
        s->schur_inv[r - nu] = S != 0.0 ? 1.0 / S : 1.0;
    }
    return s->amg ? form_M(s, K) : 0;
}

static void apply_K(void *ctx, const double *x, double *y)
{
    const struct saddle_krylov *s = ctx;
    const struct csr_matrix *K = s->K;
#pragma omp parallel for schedule(static)
    for (int r = 0; r < K->n; r++) {
        double a = 0.0;
        for (int q = K->rowptr[r]; q < K->rowptr[r + 1]; q++)
            a += K->val[q] * x[K->col[q]];
        y[r] = a;
    }
}

/* y = D W A W B x on the free rows and columns (x, y free-sized). */
static void apply_Y(struct saddle_krylov *s, const double *x, double *y)
{
    const struct csr_matrix *K = s->K;
    const int nu = s->nu;
    for (int k = 0; k < nu; k++) {
        double a = 0.0;
        for (int b = K->rowptr[k + 1] - 1; b >= K->rowptr[k] && K->col[b] >= nu; b--) {
            int c = s->free_of[K->col[b] - nu];
            if (c >= 0)
                a += K->val[b] * x[c];
        }
        s->u1[k] = s->diag[k] != 0.0 ? a / s->diag[k] : 0.0;
    }
    for (int k = 0; k < nu; k++) { /* A: the velocity columns, first in K's rows */
        double a = 0.0;
        for (int q = K->rowptr[k]; q < K->rowptr[k + 1] && K->col[q] < nu; q++)
            a += K->val[q] * s->u1[K->col[q]];
        s->u2[k] = s->diag[k] != 0.0 ? a / s->diag[k] : 0.0;
    }
    for (int f = 0; f < s->nf; f++) {
        int r = s->free_row[f];
        double a = 0.0;
        for (int q = K->rowptr[r]; q < K->rowptr[r + 1] && K->col[q] < nu; q++)
            a += K->val[q] * s->u2[K->col[q]];
        y[f] = a;
    }
}

/* z = P^-1 v: the pressures by S, then the velocities by the V-cycle of
 * A with B's part of them moved to the right-hand side.  On the free rows
 * S = -D A^-1 B is taken as -M Y^-1 M (the least-squares commutator,
 * Elman's BFBt with A's diagonal as the weight: robust to the viscosity's
 * contrast where the diagonal's 1 / S is not), so S^-1 = -M^-1 Y M^-1,
 * each M^-1 a V-cycle. */
static void apply_P(void *ctx, const double *v, double *z)
{
    struct saddle_krylov *s = ctx;
    const struct csr_matrix *K = s->K;
    const int nu = s->nu;
    for (int r = nu; r < s->n; r++)
        z[r] = s->schur_inv[r - nu] * v[r];
    if (s->vp) { /* the viscosity-scaled mass on the free rows */
        for (int f = 0; f < s->nf; f++)
            z[s->free_row[f]] = s->vp->schur_weight[s->free_row[f] - nu] * v[s->free_row[f]];
    } else if (s->nf > 0) {
        for (int f = 0; f < s->nf; f++)
            s->pf[f] = v[s->free_row[f]];
        amg_hypre_apply(s->amg_m, s->pf, s->pg);
        apply_Y(s, s->pg, s->pf);
        amg_hypre_apply(s->amg_m, s->pf, s->pg);
        for (int f = 0; f < s->nf; f++)
            z[s->free_row[f]] = -s->pg[f];
    }
    for (int r = 0; r < nu; r++) {
        double a = v[r];
        for (int q = K->rowptr[r + 1] - 1; q >= K->rowptr[r] && K->col[q] >= nu; q--)
            a -= K->val[q] * z[K->col[q]];
        s->t[r] = a;
    }
    if (s->vp)
        s->vp->apply(s->vp->ctx, s->t, z);
    else
        amg_hypre_apply(s->amg, s->t, z);
}

/* What both solves begin with: the stats cleared, K's size (and the solver's
 * kind: kind_ok) checked, K split into its blocks. */
static int solve_begin(struct saddle_krylov *s, const struct csr_matrix *K, int kind_ok,
                       struct saddle_krylov_stats *st, char *err, size_t errlen)
{
    st->iterations = 0;
    st->relative_residual = 0.0;
    if (K->n != s->n || !kind_ok) {
        snprintf(err, errlen, "coupled step's GMRES: a system of %d unknowns, %d expected",
                 K->n, s->n);
        return -1;
    }
    if (split(s, K) != 0) {
        snprintf(err, errlen, "coupled step's GMRES: out of memory");
        return -1;
    }
    s->K = K;
    return 0;
}

/* GMRES from x = 0 with the block preconditioner as set up; the stats, and
 * a break-down told in err. */
static int run_gmres(struct saddle_krylov *s, const double *rhs, double *x, double rtol,
                     int maxit, struct saddle_krylov_stats *st, char *err, size_t errlen)
{
    memset(x, 0, (size_t)s->n * sizeof *x);
    struct gmres_stats gs;
    int rc = gmres_solve(s->gm, apply_K, apply_P, s, rhs, x, rtol, maxit, &gs);
    st->iterations = gs.iterations;
    st->relative_residual = gs.relative_residual;
    if (rc < 0)
        snprintf(err, errlen, "coupled step's GMRES: breakdown after %d iterations (relative "
                              "residual %.3g)", gs.iterations, gs.relative_residual);
    return rc;
}

int saddle_krylov_solve_mg(struct saddle_krylov *s, const struct csr_matrix *K,
                           const struct saddle_velocity_precond *vp, const double *rhs, double *x,
                           double rtol, int maxit, struct saddle_krylov_stats *st, char *err,
                           size_t errlen)
{
    if (solve_begin(s, K, !s->amg, st, err, errlen) != 0)
        return -1;
    s->vp = vp;
    int rc = run_gmres(s, rhs, x, rtol, maxit, st, err, errlen);
    s->vp = NULL;
    return rc;
}

int saddle_krylov_solve(struct saddle_krylov *s, const struct csr_matrix *K, const double *rhs,
                        double *x, double rtol, int maxit, struct saddle_krylov_stats *st,
                        char *err, size_t errlen)
{
    if (solve_begin(s, K, 1, st, err, errlen) != 0)
        return -1;
    if (s->nf > 0 && !s->amg_m) {
        int *zero = calloc((size_t)s->nf, sizeof *zero);
        struct amg_options o;
        amg_options_default(&o);
        o.systems = 0;
        int rc = zero ? amg_hypre_create(&s->amg_m, s->nf, zero, &o, err, errlen) : -1;
        free(zero);
        if (rc != 0)
            return -1;
    }
    /* the AMG takes A (and releases it); Y's products read A in K */
    int bad = amg_hypre_setup(s->amg, &s->A) != 0 || amg_hypre_prepare(s->amg, rhs, -1.0) != 0;
    if (s->nf > 0 && !bad) {
        bad = amg_hypre_setup(s->amg_m, &s->M) != 0;
        if (!bad) {
            for (int f = 0; f < s->nf; f++)
                s->pf[f] = 1.0;
            bad = amg_hypre_prepare(s->amg_m, s->pf, -1.0) != 0;
        }
    }
    if (bad) {
        amg_hypre_release(s->amg);
        if (s->amg_m)
            amg_hypre_release(s->amg_m);
        snprintf(err, errlen, "coupled step's GMRES: hypre's BoomerAMG set-up failed");
        return -1;
    }
    int rc = run_gmres(s, rhs, x, rtol, maxit, st, err, errlen);
    amg_hypre_release(s->amg);
    if (s->amg_m)
        amg_hypre_release(s->amg_m);
    return rc;
}

double saddle_krylov_memory_estimate(long n)
{
    /* the basis (restart + 1 vectors), GMRES's residual and work, and the
       velocity- and pressure-sized work here (about seven more) */
    return ((double)SADDLE_RESTART + 10.0) * (double)n * sizeof(double);
}

double saddle_krylov_memory_estimate_mg(long n)
{
    /* the basis and GMRES's work, the work here (the multigrid's is
       velocity_mg_memory_estimate's) */
    return ((double)SADDLE_RESTART_MG + 6.0) * (double)n * sizeof(double);
}
