/* The implicit solve's preconditioner that solver.preconditioner = auto
 * chooses for a case (march_internal.h; docs/numerics/linear-solvers.md). */
#include "march_internal.h"

#include "grid/shapes.h"
#include "solvers/amg_hypre.h"
#include "solvers/sparse_direct.h"
#include "solvers/viscous_gmg.h"

/* The Cholesky (of a transient step or a Picard solve) of a 2D cross-section
 * further (in 3D its fill grows like n^(4/3): FACTOR_MAX_UNKNOWNS stays): the column
 * collapse at 204.8 cells per H0 (1024 x 320, 983,040 unknowns, of which
 * the 655,360 of the plane factorised: docs/design.md, "Blocks of
 * components"), 2 threads, its first 5 steps: 3.7 s a step, 1 CG iteration,
 * peak 2.2 GB; the AMG 5.6 s and 17 iterations, 1.6 GB; the line blocks
 * 14 s and their CG at its cap of 500 iterations, the residual 10 times
 * the right-hand side's. */
#define CHOLESKY_2D_MAX_UNKNOWNS 1000000L

/* Above this many unknowns auto takes BoomerAMG (GMRES(20), one V-cycle an
 * iteration, the inexact Newton forcing term) instead of the LU for a
 * steady flow with Newton's full tangent and no grad-div augmentation.
 * Measured on the heap at the tilt 0.4061 (whole steady solves, the same
 * steps and state with either), one process after the other, 1 thread, CPU
 * s of the whole run, two rounds on a machine loaded 5-6: 25 x 36 (2,700
 * unknowns) LU 1.23-1.27, AMG 1.05-1.15 (a tie; the LU's memory is 33 MB
 * against 40, hypre's library); 35 x 50 (5,250) LU 2.28-3.19, AMG
 * 1.48-1.57 (1.5-2x); 50 x 70 (10,500) LU 8.1-8.2, AMG 3.9-4.0 (2.1x).
 * The heap's crossover is thus near 3e3, but the square duct at 40 x 80
 * (9,600 unknowns, many rejected steps) reaches the same state in 298
 * steps with the AMG against 214 with the LU, 1.55x slower: the threshold
 * stays at 1e4, where it was before the forcing term (whose tie on the heap
 * was at 35 x 50 then).  With the augmentation (the cavity) BoomerAMG's
 * GMRES stalls: the LU stays.  Measured again once the factorisations took
 * METIS and the SkylakeX kernels (about 2x faster, suitesparse.c), 1
 * thread, two rounds: LU / AMG in CPU time 1.3-1.4 at 35 x 50, 1.2-1.3 at
 * 50 x 70, 1.4-1.6 at 70 x 100, 1.4 at 100 x 140: the threshold stands. */
#define AMG_MIN_UNKNOWNS 10000L
/* Where the Cholesky of the diagonal tangent serves (no open faces, no
 * body), the AMG only beyond this: once solves left out the blocks of
 * components that carry round-off and the probing their columns ("Blocks
 * left out of a solve"), whole steady solves on 2 threads, one sitting:
 * the heap at 70 x 100 (21,000 unknowns) a tie (1.56 s against the AMG's
 * 1.52 s, 52 MB against 66), at 100 x 140 (42,000) 3.74 s against 2.98 s
 * (66 MB against 94), at 140 x 200 (84,000) 11.2 s against 6.5 s, at
 * 280 x 400 77.3 s against 26.3 s; but the square duct at 80 x 160
 * (38,400) 3.5-3.9 s against 5.6-5.8 s and at 120 x 240 (86,400) 3.2 s
 * against 5.0 s, steady from rest in 59-93 steps.  Between the two: the
 * duct's meshes of the paper (to 80 x 160) keep the Cholesky, the heap's
 * doubled mesh takes the AMG. */
#define AMG_OVER_CHOLESKY_MIN_UNKNOWNS 50000L

/* Whether auto may choose hypre's AMG: amg 1 or 0 as given, -1 the
 * library's answer (it is opened to find out). */
int march_amg_allowed(int amg)
{
    char err[160];
    return amg >= 0 ? amg : amg_hypre_available(err, sizeof err);
}

/* The implicit solve's preconditioner for the case on g (amg: see
 * march_amg_allowed). */
enum viscous_precond march_choose_preconditioner(const struct muflow_case *cs,
                                                 const struct march_setup *su,
                                                 const struct grid *g, int amg)
{
    switch (cs->preconditioner) {
    case PRECOND_LINE: return VISCOUS_LINE;
    case PRECOND_CHOLESKY: return VISCOUS_CHOLESKY;
    case PRECOND_LU: return VISCOUS_LU;
    case PRECOND_AMG: return VISCOUS_AMG;
    case PRECOND_FOURIER: return VISCOUS_FOURIER;
    case PRECOND_GMG: return VISCOUS_GMG;
    case PRECOND_MULTIGRID: return VISCOUS_MG;
    case PRECOND_AUTO: break;
    }
    /* the coupled step probes and factorises its own matrix: the viscous
     * solver is never asked to solve, and the LU's kind is the cheapest
     * that keeps the full tangent (the AMG would open hypre for nothing) */
    if (cs->coupled)
        return cs->newton ? VISCOUS_LU : VISCOUS_CHOLESKY;
    /* the directions the flow varies in: bounded ones, and periodic ones
     * in a body's plane (a periodic row of bodies: measured, the line
     * blocks took 53-500 CG iterations a step around a cylinder in a flow
     * periodic along z, the LU 1) */
    int varying = 0, periodic[3], in_plane[3] = {0, 0, 0};
    if (case_obstacle_active(cs)) {
        struct shape_set set;
        case_obstacle_shapes(cs, &set);
        in_plane[set.plane_a] = in_plane[set.plane_b] = 1;
    }
    bc_periodic_flags(&cs->bc, periodic);
    for (int d = 0; d < 3; d++)
        varying += g->n[d] > 2 && (!periodic[d] || in_plane[d]);
    long unknowns = 3L * (long)grid_cells(g);
    if (varying < 2)
        return VISCOUS_LINE;
    /* measured on 2D cross-sections only: a grid that varies in three
     * directions keeps the LU (or the line blocks beyond its size) */
    int wide = 0;
    for (int d = 0; d < 3; d++)
        wide += g->n[d] > 2;
    /* a flow along the one-cell periodic direction of a cross-section that
     * the implicit step solves (the scene says so): the geometric multigrid
     * of the implicit step, whose cycle has the tangent's cross term
     * (docs/design.md, "Geometric multigrid for the implicit step"): at
     * least as fast as every other kind at every size measured, whole
     * steady solves on 2 threads, the heap at the tilt 0.4061 at 35 x 50
     * 0.16 s against the Cholesky's 0.20 s, at 70 x 100 0.57 against
     * 1.55 s, at 140 x 200 2.5 s against the AMG's 6.6 s and the LU's
     * 8.2 s; the square duct at 20 x 40 0.10 against 0.12 s, at 80 x 160
     * 1.65 against 3.29 s, at 120 x 240 1.90 s against the AMG's 5.15 s;
     * the same steps and states.  Measured with Newton in steady mode,
     * without the augmentation and without a body (whose cut cells it
     * does not hold) */
    if (su->cross_section_flow && cs->newton &&
        cs->mode == MODE_STEADY && wide == 2 && !(cs->augmentation > 0.0) &&
        !case_obstacle_active(cs) && !grid_stretched(g) &&
        !viscous_gmg_refusal(g->n, &cs->bc))
        return VISCOUS_GMG;
    /* in a flow that varies in two directions the strain components couple
     * through |D|: Newton needs the full tangent, which is not symmetric
     * (and reaches two nodes, the symmetric operator one); the LU and the
     * AMG both take it from the same probes.  On a 2D cross-section the
     * Cholesky of the diagonal tangent (symmetric, one node) preconditions
     * BiCGStab on the full tangent instead of the LU: the same steps and
     * states, measured (1 thread, whole steady solves): the heap at 35 x 50
     * 0.34 s against 0.64 s, the Bingham cavity 0.65 against 1.49 s, the
     * square duct 0.44 against 1.10 s, and less memory in each (docs/design.md, "The Cholesky of the
     * diagonal tangent").  Not with open faces: there the Cholesky path
     * stalls (the Newtonian chute open at both ends, nz 8: no steady state
     * after 231 steps, the LU's in 49).  Nor with a body: the cut cells'
     * grad-div correction (docs/design.md, "The Laplacian form near the
     * body") leaves the operator indefinite where the viscosity varies, and
     * the circular duct at 40 x 80 failed the Cholesky from step 1 (683
     * fallbacks to the line blocks, unsteady after 586 steps; the LU steady
     * in 381) */
    int lu = wide != 2 || bc_passes_flow(&cs->bc) || case_obstacle_active(cs);
    enum viscous_precond kind = cs->newton && lu ? VISCOUS_LU : VISCOUS_CHOLESKY;
    int reach = kind == VISCOUS_LU ? 2 : 1;
    if (sparse_direct_probes_for(g, periodic, reach) > sparse_direct_max_probes())
        return VISCOUS_LINE;
    /* the AMG has no fill: it serves beyond the factorisation's limit too;
     * without hypre's library (opened here, as the AMG would) the LU or the
     * line blocks as before */
    /* a transient step lags the viscosity (the tangent is for steady
     * solves), where the AMG was not measured: the LU as before */
    /* with a body too: the circular duct at 80 x 160 from rest (38,400
     * unknowns) got the AMG, whose GMRES reached its cap from the tangent's
     * first steps on (steady in 122 steps, 31 s on 2 threads, by the LU it
     * then gave way to), where the LU from the start takes 78 steps and
     * 10.8 s; at 120 x 240 (86,400) the AMG serves: 72 steps, 14.2 s
     * against the LU's 17.8 s */
    long amg_min = kind == VISCOUS_CHOLESKY || case_obstacle_active(cs)
                       ? AMG_OVER_CHOLESKY_MIN_UNKNOWNS
                       : AMG_MIN_UNKNOWNS;
    if (cs->newton && wide == 2 && cs->mode == MODE_STEADY && !(cs->augmentation > 0.0) &&
        unknowns > amg_min && march_amg_allowed(amg))
        return VISCOUS_AMG;
    /* beyond the factorisation's limit a 2D cross-section takes the AMG
     * (measured above: the line blocks do not converge there) */
    if (unknowns > (kind == VISCOUS_CHOLESKY && wide == 2 ? CHOLESKY_2D_MAX_UNKNOWNS
                                                          : FACTOR_MAX_UNKNOWNS))
        return wide == 2 && !(cs->augmentation > 0.0) && march_amg_allowed(amg)
                   ? VISCOUS_AMG
                   : VISCOUS_LINE;
    return kind;
}
