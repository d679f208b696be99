/* The FFT Poisson solve over ranks (solvers/poisson_fft_ranks.h). */
#include "solvers/poisson_fft_ranks.h"

#include <stdio.h>
#include <stdlib.h>
#include "kernels/kernels.h"
#include "platform/fft_ranks.h"

struct poisson_fft_ranks {
    const struct grid *g;          /* this rank's block */
    const struct decomp *dc;
    int n[3];                      /* the global grid's cells */
    struct fft_ranks_slab slab;
    double *buf;                   /* the slab, transformed in place (slab.len) */
    double *block;                 /* the block's cells, x slowest, z fastest */
    double *slabs;                 /* the slab's cells as the blocks send them */
    /* per rank: block -> slab sends and displacements, slab <- block
     * receives and displacements, and each received piece's y0, y cells,
     * x0, z0 and z cells (global) */
    int *counts;
    double *eig[3];
    double norm;
    int singular, ranks;
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
    free(ps->slabs);
    free(ps->counts);
    for (int d = 0; d < 3; d++)
        free(ps->eig[d]);
    free(ps);
}

static long overlap(long a0, long na, long b0, long nb)
{
    long lo = a0 > b0 ? a0 : b0, hi = a0 + na < b0 + nb ? a0 + na : b0 + nb;
    return hi > lo ? hi - lo : 0;
}

/* Every rank's block (x0, nx, y0, ny, z0, nz) and slab (x0, nx) gathered,
 * the counts of the two all-to-alls from them; -1 when out of memory. */
#define BLOCK_FACTS 8
static int exchange_counts(struct poisson_fft_ranks *ps)
{
    const int P = ps->ranks;
    const struct decomp *dc = ps->dc;
    double mine[BLOCK_FACTS] = {dc->lo[0], dc->n[0], dc->lo[1], dc->n[1], (double)ps->slab.x0,
                                (double)ps->slab.nx, dc->lo[2], dc->n[2]};
    double *all = malloc((size_t)P * BLOCK_FACTS * sizeof(double));
    int *sizes = malloc((size_t)P * 2 * sizeof(int));
    ps->counts = malloc((size_t)P * 9 * sizeof(int));
    if (!all || !sizes || !ps->counts) {
        free(all);
        free(sizes);
        return -1;
    }
    for (int r = 0; r < P; r++) {
        sizes[r] = BLOCK_FACTS;
        sizes[P + r] = BLOCK_FACTS * r;
    }
    comm_cart_allgather(dc->cart, mine, BLOCK_FACTS, all, sizes, sizes + P);
    free(sizes);
    int *send = ps->counts, *sdis = send + P, *recv = sdis + P, *rdis = recv + P;
    int *y0 = rdis + P, *yn = y0 + P, *x0 = yn + P, *z0 = x0 + P, *zn = z0 + P;
    int s = 0, t = 0;
    for (int r = 0; r < P; r++) {
        const double *o = all + BLOCK_FACTS * r;
        /* my block's cells in r's slab: x slowest, so in rank order */
        send[r] = (int)(overlap(dc->lo[0], dc->n[0], (long)o[4], (long)o[5]) * dc->n[1] *
                        dc->n[2]);
        sdis[r] = s;
        s += send[r];
        /* r's block's cells in my slab */
        recv[r] = (int)(overlap((long)o[0], (long)o[1], ps->slab.x0, ps->slab.nx) * (long)o[3] *
                        (long)o[7]);
        rdis[r] = t;
        t += recv[r];
        y0[r] = (int)o[2];
        yn[r] = (int)o[3];
        x0[r] = (int)(o[0] > ps->slab.x0 ? o[0] : ps->slab.x0);
        z0[r] = (int)o[6];
        zn[r] = (int)o[7];
    }
    free(all);
    return 0;
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
    ps->ranks = dc->cart->size;
    for (int d = 0; d < 3; d++)
        ps->n[d] = gg->n[d];
    fftw_r2r_kind fwd_kind[3], bwd_kind[3];
    if (poisson_fft_modes(gg, bc, fwd_kind, bwd_kind, ps->eig, &ps->norm, &ps->singular, err,
                          errlen) != 0) {
        poisson_fft_ranks_destroy(ps);
        return -1;
    }
    fft_ranks_slab(dc->cart, ps->n, &ps->slab);
    const size_t block = (size_t)dc->n[0] * dc->n[1] * dc->n[2],
                 slab = (size_t)ps->slab.nx * ps->n[1] * ps->n[2];
    ps->buf = fftw_malloc((size_t)(ps->slab.len > 0 ? ps->slab.len : 1) * sizeof(double));
    ps->block = malloc((block ? block : 1) * sizeof(double));
    ps->slabs = malloc((slab ? slab : 1) * sizeof(double));
    int failed = !ps->buf || !ps->block || !ps->slabs || exchange_counts(ps) != 0;
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

/* The blocks' pieces of the slab (ps->slabs: rank after rank, each x, y,
 * z over the rank's block's y and z) into the slab buffer (x, y, z over
 * every y and z), or back (to_slab = 0). */
static void slab_copy(struct poisson_fft_ranks *ps, int to_slab)
{
    const int P = ps->ranks, ny = ps->n[1], nz = ps->n[2];
    const int *recv = ps->counts + 2 * P, *rdis = recv + P;
    const int *y0 = rdis + P, *yn = y0 + P, *x0 = yn + P, *z0 = x0 + P, *zn = z0 + P;
    for (int r = 0; r < P; r++) {
        if (!recv[r])
            continue;
        const long xn = recv[r] / ((long)yn[r] * zn[r]);
        for (long i = 0; i < xn; i++)
            for (int j = 0; j < yn[r]; j++) {
                double *slab =
                    ps->buf + ((x0[r] + i - ps->slab.x0) * ny + y0[r] + j) * nz + z0[r];
                double *piece = ps->slabs + rdis[r] + (i * yn[r] + j) * zn[r];
                if (to_slab)
                    for (int k = 0; k < zn[r]; k++)
                        slab[k] = piece[k];
                else
                    for (int k = 0; k < zn[r]; k++)
                        piece[k] = slab[k];
            }
    }
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
    const int bx = g->n[0], by = g->n[1], nz = g->n[2], P = ps->ranks;
    const int *send = ps->counts, *sdis = send + P, *recv = sdis + P, *rdis = recv + P;
    const int par = kernel_parallel(g);
#pragma omp parallel for collapse(2) schedule(static) if (par)
    for (int i = 0; i < bx; i++)
        for (int j = 0; j < by; j++) {
            const double *src = rhs + grid_idx(g, i, j, 0);
            double *dst = ps->block + ((size_t)i * (size_t)by + (size_t)j) * (size_t)nz;
            for (int k = 0; k < nz; k++)
                dst[k] = src[k];
        }
    comm_cart_alltoall(ps->dc->cart, ps->block, send, sdis, ps->slabs, recv, rdis);
    slab_copy(ps, 1);
    fftw_execute(ps->fwd);
    divide(ps);
    fftw_execute(ps->bwd);
    slab_copy(ps, 0);
    comm_cart_alltoall(ps->dc->cart, ps->slabs, recv, rdis, ps->block, send, sdis);
#pragma omp parallel for collapse(2) schedule(static) if (par)
    for (int i = 0; i < bx; i++)
        for (int j = 0; j < by; j++) {
            const double *src = ps->block + ((size_t)i * (size_t)by + (size_t)j) * (size_t)nz;
            double *dst = phi + grid_idx(g, i, j, 0);
            for (int k = 0; k < nz; k++)
                dst[k] = src[k];
        }
}
