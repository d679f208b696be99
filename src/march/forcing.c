/* The linear tolerance of a Newton step solved by a Krylov method with the
 * algebraic multigrid or the Cholesky of the diagonal tangent (step.h,
 * implicit_tolerance): an inexact Newton
 * forcing term (Eisenstat and Walker's second choice).
 *
 * Far from the steady state a Newton step is limited by its pseudo-time
 * step and by the linearisation, not by how exactly its linear system is
 * solved: solving it to 1e-8 there buys nothing.  Eisenstat and Walker tie
 * the tolerance to how much the nonlinear residual fell in the last step,
 * eta_k = gamma (r_k / r_(k-1))^alpha, which keeps Newton's final rate
 * (alpha = 2: quadratic while the residual falls quadratically).  The
 * probed LU solves exactly in one iteration whatever the tolerance, so
 * only the Krylov paths take it: the AMG, the Cholesky of the diagonal
 * tangent, the cross-section multigrid and the velocity multigrid (whose
 * GMRES took 134-500 iterations a Newton step of the Bingham cavity at
 * 64^2-128^2 solved to 1e-8). */
#include <math.h>
#include <stdlib.h>
#include "march/step.h"

#define FORCING_GAMMA 0.9
#define FORCING_ALPHA 2.0
/* the loosest tolerance, and the threshold of the safeguard that keeps a
 * tolerance from falling faster than the last one allows (Eisenstat and
 * Walker's gamma eta_(k-1)^alpha when that exceeds 0.1) */
#define FORCING_MAX 0.1
#define FORCING_SAFEGUARD 0.1
/* the loosest with the geometric multigrid: with the tangent's cross term in
 * its cycle, GMRES meets 0.1 in one or two iterations far from the steady
 * state, and those steps are poor ones: the heap at the tilt 0.4061 took 69
 * steps (11 rejected) at 140 x 200 and 729 (210 rejected) at 280 x 400,
 * against 54 and 57 with 0.01, the LU's own march
 * (docs/numerics/implicit-step-and-newton.md) */
#define FORCING_MAX_GMG 0.01

/* Whether the solver of st's Newton steps takes the forcing term. */
static int krylov_newton(const struct march_state *st)
{
    switch (st->precond) {
    case VISCOUS_AMG:
    case VISCOUS_CHOLESKY:
    case VISCOUS_GMG:
        return 1;
    case VISCOUS_MG:
        /* not the coupled step's multigrid GMRES: its loose steps took the
         * cavity at 32 x 32 to steady in 51 steps against 34 */
        return !st->cs->coupled;
    default:
        return 0;
    }
}

double implicit_tolerance(struct march_state *st, int tangent)
{
    const struct muflow_case *cs = st->cs;
    double floor = cs->linear_tolerance;
    if (!cs->inexact_newton || !tangent || !krylov_newton(st) || cs->mode != MODE_STEADY)
        return floor;
    /* a step retried with a smaller dt (rejected) starts from the same
     * state: the same tolerance */
    if (st->forcing > 0.0 && st->forcing_step == st->step)
        return st->forcing;
    const double loosest = st->precond == VISCOUS_GMG ? FORCING_MAX_GMG : FORCING_MAX;
    double r = st->residual_rms, eta = loosest;
    if (st->forcing > 0.0 && st->forcing_rms > 0.0 && r > 0.0) {
        eta = FORCING_GAMMA * pow(r / st->forcing_rms, FORCING_ALPHA);
        double keep = FORCING_GAMMA * pow(st->forcing, FORCING_ALPHA);
        if (keep > FORCING_SAFEGUARD)
            eta = fmax(eta, keep);
    }
    /* and no looser than the residual itself (relative to the force): the
     * last steps then converge as exact Newton steps do and overshoot the
     * steady tolerance the same way (without it the heap at 35 x 50 stopped
     * two steps earlier just below the tolerance, its Q* 3e-8 off the LU's) */
    eta = fmax(fmin(fmin(eta, loosest), st->residual), floor);
    st->forcing = eta;
    st->forcing_rms = r;
    st->forcing_step = st->step;
    return eta;
}
