/* The preconditioner a case names against the case (march.h), kept beside
 * the march that builds it rather than in the case reader, which sits below
 * the solvers (config/case_registry.h). */
#include <stdio.h>
#include "march/march.h"
#include "solvers/saddle_krylov.h"
#include "solvers/viscous_gmg.h"

int march_preconditioner_refusal(const struct muflow_case *cs, char *msg, size_t msglen)
{
    if (cs->coupled) {
        /* the coupled step solves its own saddle-point matrix: by the LU, or
         * by its GMRES with the AMG (stage_coupled.c) */
        const char *why = cs->preconditioner == PRECOND_AMG
                              ? saddle_krylov_refusal(cs->rheo.law, &cs->bc)
                          : cs->preconditioner == PRECOND_GMG
                              ? "with solver.preconditioner = gmg: the coupled step "
                                "solves its own matrix; set solver.preconditioner = lu, amg or "
                                "multigrid"
                          : cs->preconditioner == PRECOND_MULTIGRID && bc_has_open(&cs->bc)
                              ? "with solver.preconditioner = multigrid needs no open face (its "
                                "GMRES is not measured there); set solver.preconditioner = lu"
                              : NULL;
        if (why) {
            snprintf(msg, msglen, "solver.coupled = on %s", why);
            return 1;
        }
    }
    /* the implicit step's geometric multigrid covers the velocity components
     * along periodic directions (viscous_gmg.h) */
    if (cs->preconditioner == PRECOND_GMG) {
        const char *why = viscous_gmg_refusal(cs->n, &cs->bc);
        if (why) {
            snprintf(msg, msglen, "%s", why);
            return 1;
        }
    }
    return 0;
}
