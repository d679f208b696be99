/* Geometric multigrid for the cell-centred variable-coefficient Poisson problem
 * on the MAC grid,
 *
 *   sum_d [ a_{i+1/2} (phi_{i+1} - phi_i) - a_{i-1/2} (phi_i - phi_{i-1}) ] / h_d^2 = rhs,
 *
 * with face coefficients a[d] in the layout of grid.h (a[d] at (i,j,k) is the
 * low face of cell (i,j,k) along d, like the velocity components): the
 * variable-density projection div((1/rho) grad p) = f, and obstacles (a = 0 on
 * the faces a solid blocks: no flux).  Boundary conditions per face as in the
 * FFT solver (poisson.h): periodic, Neumann (zero flux; the coefficient of a
 * Neumann face is not read), Dirichlet (phi = 0 on the face: ghost =
 * -interior, the coefficient of the face is used).  For a periodic direction
 * face 0 is read and face n (its image) is not.
 *
 * A cell whose faces all have a = 0 (inside an obstacle, or a one-cell
 * periodic grid) is an identity row: phi = 0 there, its rhs is ignored.
 * Without a Dirichlet face the problem is singular: the mean of rhs over the
 * live cells is removed and phi is returned with zero mean over them, like
 * poisson_fft_solve.  (A fluid region that obstacles cut off from the rest is
 * solved up to a constant of its own and its rhs is not made compatible.)
 *
 * Method (docs/numerics/multigrid.md has the measurements): a hierarchy of
 * local boxes halved in every direction that is even and not much coarser
 * than the finest spacing (directions of one cell are never coarsened), red-
 * black Gauss-Seidel smoothing, operator-dependent (flux-continuous)
 * prolongation and its transpose as restriction, coarse operators
 * rediscretised from the fine faces each coarse face covers, W-cycles, the
 * coarsest level factorised by CHOLMOD.  The cycle is symmetric, so it serves
 * as a CG preconditioner: multigrid_pcg is the robust solver (rough or
 * strongly varying coefficients); multigrid_solve (stationary cycles) is
 * enough for piecewise-smooth coefficients.
 *
 * Every array argument is a field array of the grid given to create (grid.h
 * layout).  Nothing is allocated by the solves, the cycle or apply. */
#ifndef MUFLOW_MULTIGRID_H
#define MUFLOW_MULTIGRID_H

#include <stddef.h>
#include "grid/grid.h"
#include "solvers/poisson.h"

struct multigrid;

enum multigrid_prolong {
    MG_PROLONG_FLUX = 0,   /* operator-dependent: flux-continuous along each grid line */
    MG_PROLONG_LINEAR,     /* cell-centred (tri)linear, weights 3/4, 1/4 per direction */
    MG_PROLONG_CONSTANT    /* injection into the children */
};
enum multigrid_average {
    MG_AVERAGE_HARMONIC = 0, /* series resistance of three fine faces along the normal,
                                arithmetic across (measured worse: docs/numerics/multigrid.md) */
    MG_AVERAGE_ARITHMETIC    /* arithmetic mean of the fine faces the coarse face covers
                                (the default) */
};

enum multigrid_smoother {
    MG_SMOOTH_POINT = 0,   /* red-black point Gauss-Seidel */
    MG_SMOOTH_LINES        /* zebra line Gauss-Seidel along each non-periodic direction in
                              turn (anisotropic coefficients: the viscous tangent) */
};

struct multigrid_options {
    int pre, post;          /* red-black Gauss-Seidel sweeps before / after the coarse
                               correction (equal for a symmetric cycle) */
    enum multigrid_prolong prolong;
    enum multigrid_average average;
    long coarse_cells;      /* stop coarsening at or below this many cells */
    int gamma;              /* coarse visits per level: 1 V-cycle, 2 W-cycle */
    enum multigrid_smoother smoother;
    int full_coarsening;    /* 1: halve every even direction, whatever the cells' aspect
                               ratio (with MG_SMOOTH_LINES, whose lines take the
                               anisotropy); 0: only the directions within 1.5 times
                               the finest spacing */
    int split_finest;       /* 1: with MG_SMOOTH_LINES along two directions, the finest
                               level's pre-smoother sweeps the second direction's lines
                               only and its post-smoother the first's (half the
                               smoothing of the costliest level; the coarse levels
                               sweep both); 0: both in each */
    int coarse_simplicial;  /* 1: the coarsest level's factorisation is CHOLMOD's
                               simplicial one, which calls no BLAS, so that it can run
                               beside another thread's factorisation (the serial
                               OpenBLAS muflow loads shares its buffers between
                               calls); 0: CHOLMOD chooses */
};

/* The defaults chosen by measurement: W(2,2), flux prolongation, coincident
 * (arithmetic) coarse coefficients, coarsest level of at most 64 cells (when
 * the sizes allow). */
void multigrid_default_options(struct multigrid_options *o);

/* Builds the level hierarchy for grid g and conditions bc[d][side] (opt NULL:
 * the defaults).  Returns 0, or -1 with a message in err for an invalid
 * argument or out of memory.  The coefficients must be set before a solve. */
int multigrid_create(struct multigrid **out, const struct grid *g, const enum poisson_bc bc[3][2],
                     const struct multigrid_options *opt, char *err, size_t errlen);

/* multigrid_create over the ranks of a decomposition (grid/decomp.h,
 * docs/numerics/decomposition.md): g is the global grid (uniform, not
 * compact), dc this rank's block of it; every array argument of the
 * functions below is then a field array of the block's local grid
 * (decomp_local_grid), and every call is collective.  The point smoother
 * only; no mixed term.  The solves' results equal the undecomposed ones'
 * up to the order of the dot products' sums. */
struct decomp;
int multigrid_create_decomposed(struct multigrid **out, const struct grid *g,
                                const struct decomp *dc, const enum poisson_bc bc[3][2],
                                const struct multigrid_options *opt, char *err, size_t errlen);

/* This rank's traffic on a decomposed multigrid by its model
 * (docs/numerics/decomposition.md), in decomp_traffic_read's terms: one
 * halo fill of level l sends, per rank border side s of direction d, one
 * plane of (n_e1 + 2)(n_e2 + 2) doubles of l's block (ghost depth 1,
 * corners included); a visit of a level above the gathered one fills it
 * 2 (pre + post) + 2 times and the level below once; level l is visited
 * gamma^l times per cycle (once where the next is the coarsest), the
 * gathered level's visits gather b (and, warm, x) from every rank.  *cycle:
 * one multigrid_cycle; *solve: a multigrid_pcg from phi = 0 converged in
 * `iterations` (iterations cycles, iterations + 2 fills of the finest
 * level besides); *reductions: that solve's sums over the ranks. */
struct decomp_traffic;
void multigrid_traffic_model(const struct multigrid *mg, int iterations,
                             struct decomp_traffic *cycle, struct decomp_traffic *solve,
                             long *reductions);

/* Bytes multigrid_create allocates for g with the options (NULL: the
 * defaults) and the coarsest level's factor, without creating anything:
 * the levels' coefficients, cells and transfer weights, the work arrays
 * and the coarsest level's factor (nested dissection of a 2D or 3D
 * Laplacian, bounded by cells (4 log2 cells + 10) entries). */
double multigrid_memory_estimate(const struct grid *g, const struct multigrid_options *opt);

/* Copies the face coefficients a[0..2] (>= 0 and finite on every face read),
 * coarsens them and factorises the coarsest level.  May be called again with
 * new coefficients (a new density field): the level arrays are reused, only
 * the coarsest level's (small) factorisation is rebuilt.
 * Returns 0, or -1 with a message (a negative or non-finite coefficient, the
 * coarsest factorisation failing). */
int multigrid_set_coefficients(struct multigrid *mg, double *const a[3], char *err,
                               size_t errlen);

/* The same with a cell mass term: the operator becomes L - m, m >= 0 per
 * cell (a field array of the grid; its interior is read), the implicit
 * viscous step's (rho / dt) u - div(eta grad u) with the sign changed.
 * Coarse levels take the mean of their children's m.  mass NULL is
 * multigrid_set_coefficients.  A problem with a mass term is not singular
 * (no mean is removed); a connected group of live cells held by neither
 * a Dirichlet face nor a mass term is pinned on the coarsest level. */
int multigrid_set_operator(struct multigrid *mg, double *const a[3], const double *mass,
                           char *err, size_t errlen);

/* multigrid_set_operator in two parts: the coefficients copied, checked and
 * coarsened, the coarsest level's matrix assembled (and analysed when its
 * pattern is new: the orderings stay on the caller's thread); then its
 * numeric factorisation and the line smoother's factors, which touch only
 * the multigrid's own arrays, so that a caller may run them on another
 * thread beside work that does not use this multigrid (march/step.c).  No
 * solve until the second part has returned 0: multigrid_pending says
 * whether it is due. */
int multigrid_set_operator_deferred(struct multigrid *mg, double *const a[3], const double *mass,
                                    char *err, size_t errlen);
int multigrid_finish_operator(struct multigrid *mg, char *err, size_t errlen);
int multigrid_pending(const struct multigrid *mg);

/* Adds a mixed-derivative term to L on the levels that are smoothed (the
 * coarsest level's direct solve leaves it out): for the two bounded
 * directions d1, d2,
 *   d_d1(k1 <d_d2 phi>) + d_d2(k2 <d_d1 phi>),
 * k1 on the faces of d1 and k2 on those of d2 (field arrays; boundary faces
 * are not read), <d_e phi> at a face the mean of the four differences along
 * e around it.  It is the cross term of an anisotropic coefficient whose
 * principal directions turn over the domain (the viscous tangent of a
 * shear-thinning law); the smoothers take it with the values before each
 * line's update.  Coarse faces take the mean of the fine faces they
 * coincide with.  Call after multigrid_set_operator (which does not clear
 * it); k1 or k2 NULL removes it.  Returns 0, or -1 with a message. */
int multigrid_set_mixed(struct multigrid *mg, int d1, int d2, const double *k1, const double *k2,
                        char *err, size_t errlen);

#define MULTIGRID_HISTORY 64

struct multigrid_stats {
    int cycles;            /* cycles (multigrid_solve) or PCG iterations (multigrid_pcg) */
    int converged;         /* relative residual <= rtol, or roundoff */
    int roundoff;          /* multigrid_pcg: started above rtol but within the
                              rounding of its own residual, 10 eps (|rhs| +
                              |L| |phi|) in the 2-norm: nothing to gain */
    double res0;           /* ||rhs - mean|| over the live cells (2-norm) */
    double rel;            /* final ||rhs - mean - L phi|| / res0 */
    double rate;           /* mean reduction per cycle, rel^(1/cycles) */
    double history[MULTIGRID_HISTORY];   /* relative residual after cycle c+1 (first 64) */
    double reduction[MULTIGRID_HISTORY]; /* reduction by cycle c+1: history[c] over
                                            history[c-1] (the first: over the initial
                                            relative residual) */
};

/* Stationary cycles, phi <- phi + C(rhs - L phi), from the interior of phi
 * as initial guess (zero it for a fresh solve), until the relative residual is
 * <= rtol or max_cycles.  phi's ghost layer is overwritten with the values the
 * conditions imply (periodic images, mirror for Neumann, negated mirror for
 * Dirichlet), so a gradient can be taken right away.  rhs must not alias phi.
 * Returns 0 when converged, 1 otherwise, -1 (nothing done) when no valid
 * coefficients were set.  stats may be NULL. */
int multigrid_solve(struct multigrid *mg, const double *rhs, double *phi, double rtol,
                    int max_cycles, struct multigrid_stats *stats);

/* The same problem by conjugate gradients preconditioned with one cycle per
 * iteration (the robust choice at large coefficient jumps:
 * docs/numerics/multigrid.md).  It also returns 1 early, unconverged, with
 * the iterate of its least residual, when the residual has grown 100-fold
 * above that (round-off: a restart from phi recovers); and 0 at once when
 * phi's true residual is within 1e3 rtol and below its own rounding
 * (stats->roundoff). */
int multigrid_pcg(struct multigrid *mg, const double *rhs, double *phi, double rtol, int max_iter,
                  struct multigrid_stats *stats);

/* One cycle from a zero initial guess (coefficients set): z ~ L^-1 r, a
 * symmetric linear map usable as a preconditioner.  r is read on the
 * interior, z's interior is written and its ghosts overwritten; r must not
 * alias z.  r should be zero on dead cells and, for a singular problem, have
 * zero mean. */
void multigrid_cycle(struct multigrid *mg, const double *r, double *z);

/* y = L x on the interior, 0 on dead cells (x's ghosts are overwritten by the
 * halo fill). */
void multigrid_apply(struct multigrid *mg, double *x, double *y);

/* The level hierarchy: number of levels, cells of level l. */
int multigrid_levels(const struct multigrid *mg);
void multigrid_level_size(const struct multigrid *mg, int l, int n[3]);
/* Bytes held by the solver (levels, work arrays, coarsest factorisation). */
size_t multigrid_bytes(const struct multigrid *mg);

void multigrid_destroy(struct multigrid *mg);

#endif
