/* The FFT Poisson solve over ranks (solvers/poisson_fft_ranks.h). */
#include "solvers/poisson_fft_ranks.h"

#include <stdio.h>
#include <stdlib.h>
#include "kernels/kernels.h"
#include "platform/fft_ranks.h"
#include "solvers/block_slabs.h"

struct poisson_fft_ranks {
    const struct grid *g;          /* this rank's block */
    const struct decomp *dc;
    int n[3];                      /* the global grid's cells */
    struct fft_ranks_slab slab;
    double *buf;                   /* the slab, transformed in place (slab.len) */
    double *block;                 /* the block's cells, x slowest, z fastest */
    struct block_slabs xs;         /* block <-> slab */
    double *eig[3];
    double norm;
    int singular;
    fftw_plan fwd, bwd;
};

void poisson_fft_ranks_destroy(struct poisson_fft_ranks *ps)
{
    if (!ps)
        return;
    if (ps->fwd)
        fftw_destroy_plan(ps->fwd);
    if (ps->bwd)
        fftw_destroy_plan(ps->bwd);
    fftw_free(ps->buf);
    free(ps->block);
    block_slabs_free(&ps->xs);
    for (int d = 0; d < 3; d++)
        free(ps->eig[d]);
    free(ps);
}

int poisson_fft_ranks_create(struct poisson_fft_ranks **out, const struct grid *g,
                             const struct grid *gg, const struct decomp *dc,
                             const enum poisson_bc bc[3][2], char *err, size_t errlen)
{
    *out = NULL;
    if (!dc->cart->comm) {
        snprintf(err, errlen, "poisson: FFTW's MPI transforms need several ranks");
        return -1;
    }
    /* every rank alike: one that fails must not leave the others in FFTW's
     * collectives */
    const int unopened = fft_ranks_open(err, errlen) != 0;
    if (decomp_max(dc, unopened) != 0.0) {
        if (!unopened)
            snprintf(err, errlen, "poisson: FFTW's MPI transforms failed on another rank");
        return -1;
    }
    struct poisson_fft_ranks *ps = calloc(1, sizeof *ps);
    if (!ps) {
        snprintf(err, errlen, "poisson: out of memory");
        return -1;
    }
    ps->g = g;
    ps->dc = dc;
    for (int d = 0; d < 3; d++)
        ps->n[d] = gg->n[d];
    fftw_r2r_kind fwd_kind[3], bwd_kind[3];
    if (poisson_fft_modes(gg, bc, fwd_kind, bwd_kind, ps->eig, &ps->norm, &ps->singular, err,
                          errlen) != 0) {
        poisson_fft_ranks_destroy(ps);
        return -1;
    }
    fft_ranks_slab(dc->cart, ps->n, &ps->slab);
    const size_t block = (size_t)dc->n[0] * dc->n[1] * dc->n[2];
    ps->buf = fftw_malloc((size_t)(ps->slab.len > 0 ? ps->slab.len : 1) * sizeof(double));
    ps->block = malloc((block ? block : 1) * sizeof(double));
    int failed = !ps->buf || !ps->block ||
                 block_slabs_init(&ps->xs, dc->cart, dc->lo, dc->n, ps->n, ps->slab.x0,
                                  ps->slab.nx, ps->n[1]) != 0;
    if (decomp_max(dc, failed) != 0.0) { /* one rank's failure is every rank's */
        snprintf(err, errlen, "poisson: out of memory for a rank's block and slab");
        poisson_fft_ranks_destroy(ps);
        return -1;
    }
    /* FFTW_ESTIMATE as poisson_fft: the plan a function of the sizes, kinds,
     * threads and ranks alone, the same on every run */
    fftw_plan_with_nthreads(poisson_fft_threads(g));
    ps->fwd = fft_ranks_plan(dc->cart, ps->n, ps->buf, fwd_kind, 0, FFTW_ESTIMATE);
    ps->bwd = fft_ranks_plan(dc->cart, ps->n, ps->buf, bwd_kind, 1, FFTW_ESTIMATE);
    if (decomp_max(dc, !ps->fwd || !ps->bwd) != 0.0) {
        snprintf(err, errlen, "poisson: FFTW's MPI planning failed for %d x %d x %d cells",
                 ps->n[0], ps->n[1], ps->n[2]);
        poisson_fft_ranks_destroy(ps);
        return -1;
    }
    *out = ps;
    return 0;
}

/* The transform's output (transposed: y of the slab slowest, then every x,
 * then z) divided by the eigenvalues, as poisson_fft_solve does. */
static void divide(struct poisson_fft_ranks *ps)
{
    const int nx = ps->n[0], nz = ps->n[2], ny = (int)ps->slab.ny, y0 = (int)ps->slab.y0;
    const double *ex = ps->eig[0], *ey = ps->eig[1], *ez = ps->eig[2];
    const double norm = ps->norm;
    double *restrict buf = ps->buf;
    const int par = kernel_parallel(ps->g);
#pragma omp parallel for collapse(2) schedule(static) if (par)
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            double *b = buf + ((size_t)j * (size_t)nx + (size_t)i) * (size_t)nz;
            const double exy = ex[i] + ey[y0 + j];
            for (int k = 0; k < nz; k++) {
                double lam = (exy + ez[k]) * norm;
                b[k] = lam != 0.0 ? b[k] / lam : 0.0; /* 0: mode (0,0,0), singular */
            }
        }
    if (ps->singular && y0 == 0 && ny > 0)
        buf[0] = 0.0;
}

void poisson_fft_ranks_solve(struct poisson_fft_ranks *ps, const double *rhs, double *phi)
{
    const struct grid *g = ps->g;
    const int bx = g->n[0], by = g->n[1], nz = g->n[2];
    const int par = kernel_parallel(g);
#pragma omp parallel for collapse(2) schedule(static) if (par)
    for (int i = 0; i < bx; i++)
        for (int j = 0; j < by; j++) {
            const double *src = rhs + grid_idx(g, i, j, 0);
            double *dst = ps->block + ((size_t)i * (size_t)by + (size_t)j) * (size_t)nz;
            for (int k = 0; k < nz; k++)
                dst[k] = src[k];
        }
    block_slabs_to_slab(&ps->xs, ps->block, ps->buf);
    fft_ranks_execute(ps->fwd);
    divide(ps);
    fft_ranks_execute(ps->bwd);
    block_slabs_to_boxes(&ps->xs, ps->buf, ps->block);
#pragma omp parallel for collapse(2) schedule(static) if (par)
    for (int i = 0; i < bx; i++)
        for (int j = 0; j < by; j++) {
            const double *src = ps->block + ((size_t)i * (size_t)by + (size_t)j) * (size_t)nz;
            double *dst = phi + grid_idx(g, i, j, 0);
            for (int k = 0; k < nz; k++)
                dst[k] = src[k];
        }
}
