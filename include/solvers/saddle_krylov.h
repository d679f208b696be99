/* The coupled step's saddle-point system (saddle_point.h's K, nu velocity
 * unknowns first) by GMRES with a block-triangular preconditioner,
 *
 *     P = [ A  B ]     A  K's velocity block, by one V-cycle of BoomerAMG;
 *         [ 0  S ]     B  K's columns beyond nu in the velocity rows (the
 *                         pressure gradient, a pressure-dependent law's
 *                         d(div tau)/dp, the open faces);
 *                      S  on the free cells (a divergence row, no
 *                         diagonal) the least-squares commutator
 *                         S^-1 = -M^-1 Y M^-1, M = -D W B, Y = D W A W B,
 *                         W = diag(A)^-1, each M^-1 a V-cycle of BoomerAMG
 *                         on M; on the other rows (held, pinned, open
 *                         faces) the diagonal C_rr - sum_k D_rk B_kr / A_kk,
 *
 * so that the velocity block's preconditioner needs no augmentation: the
 * pressure is an unknown, not carried by -grad(r div u).  The weight W
 * makes M a pressure Laplacian scaled by the inverse viscosity and, where
 * the pseudo-time mass dominates, by dt / rho.  On the Bingham cavity its
 * iterations a step grow slowly with the grid, where the diagonal alone
 * took hundreds (docs/numerics/coupled-step.md).  It is refused on mu(I) and
 * with open faces (saddle_krylov_refusal). */
#ifndef MUFLOW_SADDLE_KRYLOV_H
#define MUFLOW_SADDLE_KRYLOV_H

#include <stddef.h>
#include "config/rheology_params.h"
#include "grid/boundary.h"
#include "solvers/amg_hypre.h"
#include "solvers/csr.h"

struct saddle_krylov;

/* Why this GMRES cannot serve the coupled step of a case with this law and
 * these faces: a phrase that follows "solver.coupled = on", naming the keys
 * to change; NULL where it can.  It is measured on the Bingham cavity only;
 * on mu(I) it diverged (docs/numerics/coupled-step.md). */
const char *saddle_krylov_refusal(enum rheology_law law, const struct boundary *bc);

/* For systems of n unknowns whose first nu are velocities, comp[k] the
 * component of velocity unknown k.  Returns 0, or -1 with a message (hypre
 * missing: amg_hypre_available's; memory). */
int saddle_krylov_create(struct saddle_krylov **out, int n, int nu, const int *comp,
                         const struct amg_options *o, char *err, size_t errlen);
void saddle_krylov_destroy(struct saddle_krylov *s);

struct saddle_krylov_stats {
    int iterations;
    double relative_residual;
};

/* K x = rhs to |rhs - K x| <= rtol |rhs| from x = 0, at most maxit GMRES
 * iterations.  Returns 0, 1 at maxit (x the last iterate), or -1 (a
 * breakdown, a non-finite residual, hypre's error) with the cause in err. */
int saddle_krylov_solve(struct saddle_krylov *s, const struct csr_matrix *K, const double *rhs,
                        double *x, double rtol, int maxit, struct saddle_krylov_stats *st,
                        char *err, size_t errlen);

/* The multigrid variant (solver.preconditioner = multigrid): P's velocity
 * block by the caller's apply (z ~ A^-1 r on the nu velocity unknowns: the
 * velocity multigrid's cycle), S^-1 on the free rows by schur_weight (per
 * row beyond nu: the viscosity-scaled pressure mass, 2 eta + (rho / dt) /
 * diag(-lap) per cell; May and Moresi 2008), on the others by S's diagonal
 * as above.  No AMG: saddle_krylov_create_mg, saddle_krylov_solve_mg. */
struct saddle_velocity_precond {
    void (*apply)(void *ctx, const double *r, double *z);
    void *ctx;
    const double *schur_weight;
};
int saddle_krylov_create_mg(struct saddle_krylov **out, int n, int nu, char *err, size_t errlen);
int saddle_krylov_solve_mg(struct saddle_krylov *s, const struct csr_matrix *K,
                           const struct saddle_velocity_precond *vp, const double *rhs, double *x,
                           double rtol, int maxit, struct saddle_krylov_stats *st, char *err,
                           size_t errlen);

/* Bytes of the GMRES basis and work vectors for n unknowns (the AMG's
 * hierarchies are amg_hypre_memory_estimate's). */
double saddle_krylov_memory_estimate(long n);
/* The same for the multigrid variant (its longer restart). */
double saddle_krylov_memory_estimate_mg(long n);

#endif
