/* Pressure Poisson solver by FFTW real-to-real transforms (see include/solvers/poisson.h).
 *
 * Each direction is diagonalised by the transform whose basis functions satisfy
 * the discrete boundary conditions of the cell-centred 7-point Laplacian
 * (mirror ghost = Neumann, negated mirror ghost = Dirichlet, wrap = periodic):
 *
 *   bc (low/high)         forward  backward  eigenvalue * h^2          norm
 *   periodic/periodic     R2HC     HC2R      -4 sin^2(pi k / n)         n
 *   neumann/neumann       REDFT10  REDFT01   -4 sin^2(pi k / (2n))      2n
 *   dirichlet/dirichlet   RODFT10  RODFT01   -4 sin^2(pi (k+1) / (2n))  2n
 *   neumann/dirichlet     REDFT11  REDFT11   -4 sin^2(pi (k+1/2) / (2n)) 2n
 *   dirichlet/neumann     RODFT11  RODFT11   -4 sin^2(pi (k+1/2) / (2n)) 2n
 *
 * (4 sin^2(t/2) = 2 - 2 cos t, written with the sine to keep small eigenvalues
 * accurate on fine grids.)  In FFTW's halfcomplex order index k and n-k hold
 * the same frequency, and the periodic eigenvalue is symmetric in k <-> n-k, so
 * it is indexed by the storage index directly.  The transforms are unnormalised:
 * forward followed by backward multiplies by the product of the norms. */
#include "solvers/poisson.h"
#include "solvers/poisson_fft_ranks.h"

#include <fftw3.h>
#include "kernels/kernels.h"
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#ifdef _OPENMP
#include <omp.h>
#endif

struct poisson_fft {
    struct grid g;            /* copy of the grid the plans were made for */
    double *buf;              /* nx*ny*nz transform buffer, x slowest, z fastest */
    double *eig[3];           /* per-direction eigenvalues of the 1D operator */
    double norm;              /* product of the per-direction normalisations */
    int singular;             /* no Dirichlet face: mode (0,0,0) has eigenvalue 0 */
    fftw_plan fwd, bwd;
};

static const double pi = 3.14159265358979323846;
static const char dir_name[3] = {'x', 'y', 'z'};

static void set_err(char *err, size_t errlen, const char *fmt, ...)
{
    if (!err || errlen == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
}

/* fftw_init_threads once per process; like the FFTW planner itself, creation
 * is not meant to be called concurrently from several threads. */
static int threads_ready;

static int init_threads(void)
{
    if (!threads_ready) {
        if (!fftw_init_threads())
            return -1;
        threads_ready = 1;
    }
    return 0;
}

/* FFTW's threads for a grid: one below FFTW_THREADS_MIN cells, where a
 * wake-up of the other threads per transform stage costs more than they
 * save (docs/numerics/threads-and-platform.md). */
#define FFTW_THREADS_MIN 65536

int poisson_fft_threads(const struct grid *g)
{
#ifdef _OPENMP
    return grid_cells(g) >= FFTW_THREADS_MIN ? omp_get_max_threads() : 1;
#else
    (void)g;
    return 1;
#endif
}

void poisson_fft_destroy(struct poisson_fft *ps)
{
    if (!ps)
        return;
    if (ps->fwd)
        fftw_destroy_plan(ps->fwd);
    if (ps->bwd)
        fftw_destroy_plan(ps->bwd);
    fftw_free(ps->buf);
    for (int d = 0; d < 3; d++)
        free(ps->eig[d]);
    free(ps);
}

/* The grid's cells and sizes and the faces' conditions: 0, or -1 with a
 * message. */
static int check_problem(const struct grid *g, const enum poisson_bc bc[3][2], char *err,
                         size_t errlen)
{
    static const char *side_name[2] = {"low", "high"};
    for (int d = 0; d < 3; d++) {
        if (g->n[d] < 1) {
            set_err(err, errlen, "poisson: %d cells in direction %c (need at least 1)",
                    g->n[d], dir_name[d]);
            return -1;
        }
        if (!(g->h[d] > 0.0) || !isfinite(g->h[d])) {
            set_err(err, errlen, "poisson: invalid cell size %g in direction %c",
                    g->h[d], dir_name[d]);
            return -1;
        }
        for (int s = 0; s < 2; s++) {
            if ((int)bc[d][s] < (int)POISSON_PERIODIC || (int)bc[d][s] > (int)POISSON_DIRICHLET) {
                set_err(err, errlen, "poisson: invalid condition %d on the %s face of direction %c",
                        (int)bc[d][s], side_name[s], dir_name[d]);
                return -1;
            }
        }
        if ((bc[d][0] == POISSON_PERIODIC) != (bc[d][1] == POISSON_PERIODIC)) {
            set_err(err, errlen, "poisson: periodic must be on both faces of direction %c",
                    dir_name[d]);
            return -1;
        }
    }
    return 0;
}

/* Direction d's transforms, eigenvalues (eig[d], allocated) and
 * normalisation (times *norm) for the conditions bc of its faces (the table
 * above); *singular = 0 with a Dirichlet face; -1 when out of memory. */
static int direction_transform(const struct grid *g, int d, const enum poisson_bc bc[2],
                               fftw_r2r_kind *fwd_kind, fftw_r2r_kind *bwd_kind, double **eig,
                               double *norm, int *singular)
{
    int n = g->n[d];
    double h2 = g->h[d] * g->h[d];
    enum poisson_bc lo = bc[0], hi = bc[1];
    double shift, period; /* eigenvalue k: -4 sin^2(pi (k + shift) / period) / h^2 */
    if (lo == POISSON_PERIODIC) {
        *fwd_kind = FFTW_R2HC;
        *bwd_kind = FFTW_HC2R;
        shift = 0.0;
        period = n;
        *norm *= n;
    } else {
        *norm *= 2.0 * n;
        period = 2.0 * n;
        if (lo == POISSON_NEUMANN && hi == POISSON_NEUMANN) {
            *fwd_kind = FFTW_REDFT10;
            *bwd_kind = FFTW_REDFT01;
            shift = 0.0;
        } else if (lo == POISSON_DIRICHLET && hi == POISSON_DIRICHLET) {
            *fwd_kind = FFTW_RODFT10;
            *bwd_kind = FFTW_RODFT01;
            shift = 1.0;
        } else if (lo == POISSON_NEUMANN) { /* neumann low, dirichlet high */
            *fwd_kind = *bwd_kind = FFTW_REDFT11;
            shift = 0.5;
        } else {                            /* dirichlet low, neumann high */
            *fwd_kind = *bwd_kind = FFTW_RODFT11;
            shift = 0.5;
        }
        if (lo == POISSON_DIRICHLET || hi == POISSON_DIRICHLET)
            *singular = 0;
    }
    eig[d] = malloc((size_t)n * sizeof(double));
    if (!eig[d])
        return -1;
    for (int k = 0; k < n; k++) {
        double s = sin(pi * (k + shift) / period);
        eig[d][k] = -4.0 * s * s / h2; /* exactly 0 for the k = 0 mode of periodic / NN */
    }
    return 0;
}

int poisson_fft_modes(const struct grid *g, const enum poisson_bc bc[3][2],
                      fftw_r2r_kind fwd_kind[3], fftw_r2r_kind bwd_kind[3], double *eig[3],
                      double *norm, int *singular, char *err, size_t errlen)
{
    if (check_problem(g, bc, err, errlen) != 0)
        return -1;
    *norm = 1.0;
    *singular = 1;
    for (int d = 0; d < 3; d++)
        if (direction_transform(g, d, bc[d], &fwd_kind[d], &bwd_kind[d], eig, norm,
                                singular) != 0) {
            set_err(err, errlen, "poisson: out of memory");
            return -1;
        }
    return 0;
}

/* The forward and backward plans on ps->buf; -1 when FFTW cannot make them.
 * FFTW_ESTIMATE: the plan is a function of the sizes, kinds, thread count,
 * buffer alignment and the FFTW build alone, so two processes with the same
 * input, threads and machine make the same plan and compute the same bits,
 * where FFTW_MEASURE may pick another plan in every process, for a gain
 * that does not pay for its planning (docs/numerics/reproducibility.md).
 * Wisdom imported before planning (a checkpoint's, see io/checkpoint.h) is
 * still used, so a run continued from a checkpoint of a binary that
 * measured keeps that binary's plans. */
static int make_plans(struct poisson_fft *ps, const fftw_r2r_kind fwd_kind[3],
                      const fftw_r2r_kind bwd_kind[3])
{
    const struct grid *g = &ps->g;
    fftw_plan_with_nthreads(poisson_fft_threads(g));
    ps->fwd = fftw_plan_r2r_3d(g->n[0], g->n[1], g->n[2], ps->buf, ps->buf,
                               fwd_kind[0], fwd_kind[1], fwd_kind[2], FFTW_ESTIMATE);
    ps->bwd = fftw_plan_r2r_3d(g->n[0], g->n[1], g->n[2], ps->buf, ps->buf,
                               bwd_kind[0], bwd_kind[1], bwd_kind[2], FFTW_ESTIMATE);
    return ps->fwd && ps->bwd ? 0 : -1;
}

int poisson_fft_create(struct poisson_fft **out, const struct grid *g,
                       const enum poisson_bc bc[3][2], char *err, size_t errlen)
{
    if (out)
        *out = NULL;
    if (!out || !g || !bc) {
        set_err(err, errlen, "poisson: missing argument");
        return -1;
    }
    if (init_threads() != 0) {
        set_err(err, errlen, "poisson: fftw_init_threads failed");
        return -1;
    }

    struct poisson_fft *ps = calloc(1, sizeof(*ps));
    if (!ps) {
        set_err(err, errlen, "poisson: out of memory");
        return -1;
    }
    ps->g = *g;
    fftw_r2r_kind fwd_kind[3], bwd_kind[3];
    if (poisson_fft_modes(g, bc, fwd_kind, bwd_kind, ps->eig, &ps->norm, &ps->singular, err,
                          errlen) != 0) {
        poisson_fft_destroy(ps);
        return -1;
    }

    size_t cells = grid_cells(g);
    ps->buf = fftw_malloc(cells * sizeof(double));
    if (!ps->buf) {
        set_err(err, errlen, "poisson: out of memory (%zu cells)", cells);
        poisson_fft_destroy(ps);
        return -1;
    }
    if (make_plans(ps, fwd_kind, bwd_kind) != 0) {
        set_err(err, errlen, "poisson: FFTW planning failed for %d x %d x %d cells",
                g->n[0], g->n[1], g->n[2]);
        poisson_fft_destroy(ps);
        return -1;
    }
    *out = ps;
    return 0;
}

void poisson_fft_solve(struct poisson_fft *ps, const double *rhs, double *phi)
{
    const struct grid *g = &ps->g;
    const int nx = g->n[0], ny = g->n[1], nz = g->n[2];
    double *restrict buf = ps->buf;
    const int par = kernel_parallel(g);

    /* gather the interior of rhs (may alias phi: everything is read first) */
#pragma omp parallel for collapse(2) schedule(static) if (par)
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) {
            const double *src = rhs + grid_idx(g, i, j, 0);
            double *dst = buf + ((size_t)i * (size_t)ny + (size_t)j) * (size_t)nz;
            for (int k = 0; k < nz; k++)
                dst[k] = src[k];
        }

    fftw_execute(ps->fwd);

    const double *ex = ps->eig[0], *ey = ps->eig[1], *ez = ps->eig[2];
    const double norm = ps->norm;
#pragma omp parallel for collapse(2) schedule(static) if (par)
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) {
            double *b = buf + ((size_t)i * (size_t)ny + (size_t)j) * (size_t)nz;
            const double exy = ex[i] + ey[j];
            for (int k = 0; k < nz; k++) {
                double lam = (exy + ez[k]) * norm;
                /* lam is 0 only for mode (0,0,0) of a singular problem:
                 * dropping it removes the mean of rhs and of phi */
                b[k] = lam != 0.0 ? b[k] / lam : 0.0;
            }
        }
    if (ps->singular)
        buf[0] = 0.0; /* explicit, whatever the rounding of the sum above */

    fftw_execute(ps->bwd);

#pragma omp parallel for collapse(2) schedule(static) if (par)
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++) {
            const double *src = buf + ((size_t)i * (size_t)ny + (size_t)j) * (size_t)nz;
            double *dst = phi + grid_idx(g, i, j, 0);
            for (int k = 0; k < nz; k++)
                dst[k] = src[k];
        }
}
