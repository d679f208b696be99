/* The projection's Poisson solve: FFT while the coefficient is uniform,
 * multigrid-preconditioned CG otherwise (pressure.h); over ranks FFTW's
 * MPI transforms and the decomposed multigrid. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "kernels/kernels.h"
#include "solvers/multigrid.h"
#include "grid/decomp.h"
#include "solvers/poisson_fft_ranks.h"
#include "solvers/pressure.h"

/* Relative residual of the variable-coefficient solve: the projection then
 * leaves div u at this fraction of div u*, far below the steady tolerance
 * relative to the step's increment. */
#define PRESSURE_RTOL 1e-12
#define PRESSURE_MAX_ITER 500
#define PRESSURE_RESTARTS 4

/* A 2D grid of at most this many cells is the multigrid's coarsest level
 * itself: one level, factorised by CHOLMOD whenever the coefficient changes,
 * which makes the CG's preconditioner exact.  Up to this size the
 * factorisation beats the cycles; beyond it its fill overtakes them
 * (docs/numerics/pressure.md).  3D grids keep the cycles: their fill grows
 * faster.  Over ranks the limit is the whole grid's, as on one process: every
 * rank gathers it and solves it alike (the decomposed multigrid's gathered
 * level is then the finest), so the ranks' solve is the one process's. */
#define PRESSURE_DIRECT_CELLS 32768L

struct pressure_solver {
    const struct grid *g;
    enum poisson_bc bc[3][2];
    struct poisson_fft *fft;
    struct multigrid *mg;   /* created with the first variable coefficient */
    int uniform;
    double *rhs;            /* the multigrid path's copy of rhs (may alias phi) */
    long iterations;        /* multigrid-CG iterations of every solve so far */
    char message[256];
    int direct;        /* the multigrid is one level: the whole grid factorised */
    long direct_factorisations; /* those factorisations so far */
    int no_direct;     /* pressure_allow_direct(ps, 0): the cycles whatever the grid */
    /* a grid split over ranks (pressure_create_decomposed): FFTW's MPI
     * transforms (NULL: one process); g is the rank's block */
    struct poisson_fft_ranks *ranks;
    const struct grid *gg;     /* the whole grid and the blocks (ranks only) */
    const struct decomp *dc;
};

/* A solver of the uniform coefficient on g (the rank's block), its FFT to
 * be made by the caller; NULL when out of memory. */
static struct pressure_solver *pressure_alloc(const struct grid *g,
                                              const enum poisson_bc bc[3][2], char *err,
                                              size_t errlen)
{
    struct pressure_solver *ps = calloc(1, sizeof *ps);
    if (!ps) {
        snprintf(err, errlen, "pressure solver: out of memory");
        return NULL;
    }
    ps->g = g;
    memcpy(ps->bc, bc, sizeof ps->bc);
    ps->uniform = 1;
    return ps;
}

int pressure_create(struct pressure_solver **out, const struct grid *g,
                    const enum poisson_bc bc[3][2], char *err, size_t errlen)
{
    struct pressure_solver *ps = pressure_alloc(g, bc, err, errlen);
    if (!ps)
        return -1;
    if (poisson_fft_create(&ps->fft, g, bc, err, errlen) != 0) {
        free(ps);
        return -1;
    }
    *out = ps;
    return 0;
}

int pressure_create_decomposed(struct pressure_solver **out, const struct grid *g,
                               const struct grid *gg, const struct decomp *dc,
                               const enum poisson_bc bc[3][2], char *err, size_t errlen)
{
    if (!dc->cart->comm) /* no mpirun: the block is the whole grid */
        return pressure_create(out, g, bc, err, errlen);
    struct pressure_solver *ps = pressure_alloc(g, bc, err, errlen);
    if (!ps)
        return -1;
    if (poisson_fft_ranks_create(&ps->ranks, g, gg, dc, bc, err, errlen) != 0) {
        free(ps);
        return -1;
    }
    ps->gg = gg;
    ps->dc = dc;
    *out = ps;
    return 0;
}

void pressure_destroy(struct pressure_solver *ps)
{
    if (!ps)
        return;
    if (ps->fft)
        poisson_fft_destroy(ps->fft);
    if (ps->mg)
        multigrid_destroy(ps->mg);
    poisson_fft_ranks_destroy(ps->ranks);
    field_free(ps->rhs);
    free(ps);
}

/* The multigrid's options for a variable coefficient on g: 1 when it is
 * the whole grid's factorisation (a small 2D grid), else 0. */
static int variable_options(const struct grid *g, int allow, struct multigrid_options *o)
{
    multigrid_default_options(o);
    long cells = (long)grid_cells(g);
    int flat = g->n[0] == 1 || g->n[1] == 1 || g->n[2] == 1;
    if (!(allow && flat && cells <= PRESSURE_DIRECT_CELLS))
        return 0;
    o->coarse_cells = cells;
    /* the whole grid's factorisation runs beside the implicit step
     * (pressure_finish, march/step.c): no BLAS in it, which the implicit
     * step's factorisation calls at the same time */
    o->coarse_simplicial = 1;
    return 1;
}

double pressure_variable_memory_estimate(const struct grid *g)
{
    struct multigrid_options o;
    variable_options(g, 1, &o);
    return multigrid_memory_estimate(g, &o) + (double)g->size * sizeof(double);
}

int pressure_set_coefficient(struct pressure_solver *ps, double *const beta[3], char *err,
                             size_t errlen)
{
    ps->uniform = beta == NULL;
    if (ps->uniform)
        return 0;
    if (!ps->mg) {
        /* the options of the whole grid: the one process's hierarchy */
        struct multigrid_options o;
        ps->direct = variable_options(ps->ranks ? ps->gg : ps->g, !ps->no_direct, &o);
        const enum poisson_bc(*bc)[2] = (const enum poisson_bc(*)[2])ps->bc;
        if ((ps->ranks ? multigrid_create_decomposed(&ps->mg, ps->gg, ps->dc, bc, &o, err, errlen)
                       : multigrid_create(&ps->mg, ps->g, bc, &o, err, errlen)) != 0)
            return -1;
        if (!(ps->rhs = field_alloc(ps->g))) {
            snprintf(err, errlen, "pressure solver: out of memory");
            return -1;
        }
    }
    return multigrid_set_operator_deferred(ps->mg, beta, NULL, err, errlen);
}

int pressure_direct(const struct pressure_solver *ps)
{
    return !ps->uniform && ps->direct;
}

int pressure_pending(const struct pressure_solver *ps)
{
    return !ps->uniform && ps->mg && multigrid_pending(ps->mg);
}

int pressure_finish(struct pressure_solver *ps, char *err, size_t errlen)
{
    if (!pressure_pending(ps))
        return 0;
    if (multigrid_finish_operator(ps->mg, err, errlen) != 0)
        return -1;
    ps->direct_factorisations += ps->direct;
    return 0;
}

long pressure_direct_factorisations(const struct pressure_solver *ps)
{
    return ps->direct_factorisations;
}

void pressure_allow_direct(struct pressure_solver *ps, int allow)
{
    ps->no_direct = !allow;
}

int pressure_uniform(const struct pressure_solver *ps) { return ps->uniform; }

const char *pressure_message(const struct pressure_solver *ps) { return ps->message; }

long pressure_iterations(const struct pressure_solver *ps) { return ps->iterations; }

int pressure_solve(struct pressure_solver *ps, const double *rhs, double *phi, double floor)
{
    if (ps->uniform) {
        if (ps->ranks)
            poisson_fft_ranks_solve(ps->ranks, rhs, phi);
        else
            poisson_fft_solve(ps->fft, rhs, phi);
        return 0;
    }
    char why[200];
    if (pressure_finish(ps, why, sizeof why) != 0) {
        snprintf(ps->message, sizeof ps->message, "pressure solve: the operator's set-up: %s",
                 why);
        return -1;
    }
    memcpy(ps->rhs, rhs, ps->g->size * sizeof(double));
    memset(phi, 0, ps->g->size * sizeof(double));
    /* A right-hand side at the round-off of its own computation (a flow
     * uniform along the periodic direction has div u* ~ 1e-16 |u| / h) cannot
     * be reduced 1e12-fold: the operator's own round-off, amplified by the
     * coefficient's jumps, is above that, and the iteration would run into
     * its cap with restarts, most of bagnold2's run (docs/numerics/pressure.md,
     * "The floor").  The floor ends it where the result no longer changes. */
    double rtol = PRESSURE_RTOL;
    if (floor > 0.0) {
        double norm = kernel_norm2_cells(ps->g, ps->rhs);
        if (ps->ranks) /* every rank's cells: the ranks stop alike */
            norm = sqrt(decomp_sum(ps->dc, norm * norm));
        if (norm <= floor)
            return 0; /* phi = 0: nothing above the floor to project */
        rtol = fmax(rtol, floor / norm);
    }
    struct multigrid_stats stats;
    int rc = multigrid_pcg(ps->mg, ps->rhs, phi, rtol, PRESSURE_MAX_ITER, &stats);
    /* CG in floating point can stagnate (its directions lose conjugacy): a
     * restart from the iterate reached, with a fresh residual, recovers, where
     * a stalled solve taken as it was left the grains' volume off.
     * multigrid_pcg stops a stalled iteration once its residual has grown
     * 100-fold above its best (returning the best iterate), so a restart comes
     * early, and one already at the residual's rounding level is converged
     * (docs/numerics/pressure.md). */
    long cycles = stats.cycles;
    int restarts = 0;
    for (; rc != 0 && restarts < PRESSURE_RESTARTS; restarts++) {
        rc = multigrid_pcg(ps->mg, ps->rhs, phi, rtol, PRESSURE_MAX_ITER, &stats);
        cycles += stats.cycles;
    }
    ps->iterations += cycles;
    if (rc != 0) {
        /* The tolerance beside the residual: a solve that stalls just above it
         * (the residual's own rounding on a large grid) reads differently from
         * one that is far off. */
        snprintf(ps->message, sizeof ps->message,
                 "pressure solve: relative residual %.2e (tolerance %.0e) after %ld "
                 "multigrid-CG iterations and %d restarts",
                 stats.rel, rtol, cycles, restarts);
        return -1;
    }
    return 0;
}
