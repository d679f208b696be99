/* The implicit solve's preconditioner that solver.preconditioner = auto
 * chooses for a case (march_internal.h; docs/numerics/linear-solvers.md). */
#include "march_internal.h"

#include "grid/shapes.h"
#include "platform/comm.h"
#include "solvers/amg_hypre.h"
#include "solvers/sparse_direct.h"
#include "solvers/viscous_gmg.h"

/* auto's thresholds; docs/numerics/linear-solvers.md holds the measurement
 * behind each.  The Cholesky of a 2D cross-section's Picard or diagonal
 * operator serves further than the LU (its fill grows slower). */
#define CHOLESKY_2D_MAX_UNKNOWNS 1000000L
/* A steady Newton flow takes BoomerAMG instead of the LU above this... */
#define AMG_MIN_UNKNOWNS 10000L
/* ...and instead of the Cholesky of the diagonal tangent (no open faces,
 * no body) or with a body only above this. */
#define AMG_OVER_CHOLESKY_MIN_UNKNOWNS 50000L

/* Whether auto may choose hypre's AMG: amg 1 or 0 as given, -1 the
 * library's answer (it is opened to find out). */
int march_amg_allowed(int amg)
{
    char err[160];
    return amg >= 0 ? amg : amg_hypre_available(err, sizeof err);
}

/* auto's pick on one process. */
static enum viscous_precond one_process_choice(const struct muflow_case *cs,
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
     * in a body's plane (the line blocks do not converge around a periodic
     * row of bodies) */
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
    /* the multigrids and the AMG serve 2D cross-sections: a grid that varies
     * in three directions keeps the LU (or the line blocks beyond its size) */
    int wide = 0;
    for (int d = 0; d < 3; d++)
        wide += g->n[d] > 2;
    /* a flow along the one-cell periodic direction of a cross-section that
     * the implicit step solves (the scene says so): the geometric multigrid
     * of that component, whose cycle has the tangent's cross term, faster
     * than every other kind at every size; a body's held nodes and cut
     * links folded into its coefficients (the circular duct) */
    if (su->cross_section_flow && cs->newton &&
        cs->mode == MODE_STEADY && wide == 2 && !(cs->augmentation > 0.0) &&
        !grid_stretched(g) && !viscous_gmg_refusal(g->n, &cs->bc))
        return VISCOUS_GMG;
    /* a time-accurate step (the lagged viscosity, newton or not:
     * implicit_uses_tangent) of a plane flow without the grad-div
     * augmentation: the multigrid of every velocity component, which ties
     * with the Cholesky in time, in less memory, with no grid-sized
     * factorisation, a body's held nodes and cut links included (the
     * cylinder benchmark, kept across its steps at a fixed dt:
     * docs/numerics/velocity-multigrid.md).  A flow along a cross-section's
     * periodic direction with newton keeps the Cholesky of its one flow
     * component (the heap at 70 x 100, 30 steps: 0.18 s CPU against 0.42 s) */
    if (cs->mode == MODE_TRANSIENT && wide == 2 && !(cs->newton && su->cross_section_flow) &&
        !(cs->augmentation > 0.0) && !grid_stretched(g))
        return VISCOUS_MG;
    /* in a flow that varies in two directions the strain components couple
     * through |D|: Newton needs the full tangent (not symmetric); the LU and
     * the AMG take it from the same probes.  On a 2D cross-section the
     * Cholesky of the diagonal tangent (symmetric) preconditions BiCGStab on
     * the full tangent instead: the same steps, faster, in less memory.  Not
     * with open faces (the Cholesky path stalls there), nor with a body (the
     * cut cells' grad-div correction leaves the operator indefinite where
     * the viscosity varies) */
    int lu = wide != 2 || bc_passes_flow(&cs->bc) || case_obstacle_active(cs);
    enum viscous_precond kind = cs->newton && lu ? VISCOUS_LU : VISCOUS_CHOLESKY;
    int reach = kind == VISCOUS_LU ? 2 : 1;
    if (sparse_direct_probes_for(g, periodic, reach) > sparse_direct_max_probes())
        return VISCOUS_LINE;
    /* the AMG has no fill: it serves beyond the factorisation's limit too,
     * for a steady Newton solve (a transient step was not measured with it);
     * without hypre's library (opened here, as the AMG would) the LU or the
     * line blocks */
    long amg_min = kind == VISCOUS_CHOLESKY || case_obstacle_active(cs)
                       ? AMG_OVER_CHOLESKY_MIN_UNKNOWNS
                       : AMG_MIN_UNKNOWNS;
    if (cs->newton && wide == 2 && cs->mode == MODE_STEADY && !(cs->augmentation > 0.0) &&
        unknowns > amg_min && march_amg_allowed(amg))
        return VISCOUS_AMG;
    /* beyond the factorisation's limit a 2D cross-section takes the AMG
     * (the line blocks do not converge there); with the augmentation, which
     * defeats the AMG, the velocity multigrid's edge patches (the line
     * blocks: the cavity at 32^2 unsteady after 40 steps, 57 solves at their
     * cap; the multigrid steady in the Cholesky's 34), where no open or
     * inflow face stops the patches */
    if (unknowns > (kind == VISCOUS_CHOLESKY && wide == 2 ? CHOLESKY_2D_MAX_UNKNOWNS
                                                          : FACTOR_MAX_UNKNOWNS)) {
        if (wide == 2 && cs->augmentation > 0.0)
            return !case_obstacle_active(cs) && !bc_passes_flow(&cs->bc) && !grid_stretched(g)
                       ? VISCOUS_MG
                       : VISCOUS_LINE;
        return wide == 2 && march_amg_allowed(amg) ? VISCOUS_AMG : VISCOUS_LINE;
    }
    return kind;
}

/* Over the ranks of an MPI job no factorisation or AMG is decomposed, and
 * gmg gathers its cross-section on every rank (viscous_gmg.c; kept, a
 * body's held nodes and cut links gathered with it): auto takes the velocity multigrid in the others' place
 * where it serves the run (it runs decomposed, the Newton tangent's
 * symmetric part in its cycle, the augmentation's edge patches gathered:
 * docs/numerics/velocity-multigrid.md), not with a body (its held nodes
 * and cut links are not decomposed), nor with the augmentation and an open
 * or inflow face (the edge patches refuse them), nor on a stretched grid.
 * A preconditioner named by solver.preconditioner is kept (march_create
 * refuses those that do not run decomposed). */
enum viscous_precond march_choose_preconditioner(const struct muflow_case *cs,
                                                 const struct march_setup *su,
                                                 const struct grid *g, int amg)
{
    const enum viscous_precond kind = one_process_choice(cs, su, g, amg);
    const int ranks = su->decompose && comm_size() > 1;
    if (!ranks || cs->preconditioner != PRECOND_AUTO || cs->coupled ||
        !(kind == VISCOUS_CHOLESKY || kind == VISCOUS_LU || kind == VISCOUS_AMG))
        return kind;
    const int serves = !case_obstacle_active(cs) && !grid_stretched(g) &&
                       !(cs->augmentation > 0.0 && bc_passes_flow(&cs->bc));
    return serves ? VISCOUS_MG : kind;
}
