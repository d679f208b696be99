/* The pressure Poisson solve of the projection, div(beta grad phi) = rhs,
 * with a face coefficient beta (beta = rho_ref / rho on faces for a variable
 * density; 0 on faces a solid blocks).  While beta is uniform (NULL) the FFT
 * solver does it (poisson.h: exact, fastest); a variable beta goes to the
 * multigrid-preconditioned CG (multigrid.h).  The caller does not choose. */
#ifndef MUFLOW_SOLVERS_PRESSURE_H
#define MUFLOW_SOLVERS_PRESSURE_H

#include <stddef.h>
#include "grid/grid.h"
#include "solvers/poisson.h"

struct pressure_solver;

int pressure_create(struct pressure_solver **out, const struct grid *g,
                    const enum poisson_bc bc[3][2], char *err, size_t errlen);
/* The solver of a grid split over ranks (grid/decomp.h): g this rank's
 * local grid, gg the global one, dc the blocks (all kept).  A uniform
 * coefficient: FFTW's MPI transforms (solvers/poisson_fft_ranks.h), each
 * rank holding its block and its slab, never the global grid
 * (docs/numerics/decomposition.md); a variable one: the decomposed
 * multigrid with the whole grid's options (a small 2D grid gathered and
 * factorised on every rank, as one process factorises it).  Every call on
 * it is collective. */
struct decomp;
int pressure_create_decomposed(struct pressure_solver **out, const struct grid *g,
                               const struct grid *gg, const struct decomp *dc,
                               const enum poisson_bc bc[3][2], char *err, size_t errlen);
void pressure_destroy(struct pressure_solver *ps);

/* The coefficient for the next solves: NULL for beta = 1 (the FFT solver),
 * or three face arrays (copied and checked).  The multigrid's factorisation
 * of its coarsest level (on a small 2D grid the whole grid) is left to
 * pressure_finish, which may run on another thread beside work that does
 * not use this solver; the next solve does it otherwise.  Returns 0, or -1
 * with the cause. */
int pressure_set_coefficient(struct pressure_solver *ps, double *const beta[3], char *err,
                             size_t errlen);

/* Bytes a solver on g takes once it has a variable coefficient (its
 * multigrid and right-hand side), without creating one. */
double pressure_variable_memory_estimate(const struct grid *g);

/* 1 while the coefficient's factorisation is due; pressure_finish does it
 * (0, or -1 with the cause: out of memory, a failed factorisation).
 * pressure_direct: 1 when that factorisation is the whole grid's (a 2D grid
 * of at most PRESSURE_DIRECT_CELLS cells with a variable coefficient), the
 * costly case; else the multigrid's small coarsest level. */
int pressure_direct(const struct pressure_solver *ps);
/* How many times the whole grid has been factorised (pressure_direct). */
long pressure_direct_factorisations(const struct pressure_solver *ps);
/* allow 0: the multigrid's cycles whatever the grid (solver.pressure_factorisation =
 * off); before the first variable coefficient. */
void pressure_allow_direct(struct pressure_solver *ps, int allow);
int pressure_pending(const struct pressure_solver *ps);
int pressure_finish(struct pressure_solver *ps, char *err, size_t errlen);

/* 1 while the coefficient is uniform (the FFT path). */
int pressure_uniform(const struct pressure_solver *ps);

/* Solves for phi (interior written; may alias rhs on the FFT path only when
 * the coefficient is uniform: the multigrid path needs a separate rhs, and
 * copies it itself).  The iterative path stops at a relative residual of
 * 1e-12, or once the residual's 2-norm is below floor (0: none), the level
 * below which the caller's result does not change (the projection: the
 * round-off of the divergence it leaves).  Returns 0, or -1 when the
 * iteration did not converge (cause in the solver's last message,
 * pressure_message). */
int pressure_solve(struct pressure_solver *ps, const double *rhs, double *phi, double floor);
const char *pressure_message(const struct pressure_solver *ps);
/* Multigrid-CG iterations of every solve so far (restarts included; the FFT
 * path adds none). */
long pressure_iterations(const struct pressure_solver *ps);

#endif
