/* The coupled step's preconditioner without a factorisation
 * (solver.preconditioner = multigrid with solver.coupled): the velocity
 * block by one cycle of the velocity multigrid (solvers/velocity_mg.h) on
 * the step's symmetric operator (the Newton tangent's symmetric part), the
 * pressure Schur complement by the viscosity-scaled pressure mass, per cell
 * 1 / (2 eta + (rho / dt) / diag(-lap)) (May and Moresi 2008; Elman,
 * Silvester and Wathen): for -div(2 eta D u) + grad p on gradients the
 * operator is 2 eta (-lap), so S = D A^-1 G is 1 / (2 eta), and where the
 * pseudo-time mass dominates S = -lap dt / rho, whose diagonal the second
 * term takes.  saddle_krylov.h's GMRES applies it. */
#ifndef MUFLOW_MARCH_COUPLED_MG_H
#define MUFLOW_MARCH_COUPLED_MG_H

#include <stddef.h>
#include "solvers/saddle_krylov.h"
#include "solvers/viscous_operator.h"

struct march_state;
struct probe_matrix;
struct coupled_mg;

/* For st's grid and unknowns, pm's numbering of the nu velocity unknowns
 * and nc cells (cell[] per cell slot).  Returns 0, or -1 with a message. */
int coupled_mg_create(struct coupled_mg **out, const struct march_state *st,
                      const struct probe_matrix *pm, int nu, int nc, const int *cell, char *err,
                      size_t errlen);
void coupled_mg_destroy(struct coupled_mg *m);

/* The multigrid on pb's symmetric operator and the Schur weights of pb's
 * viscosity; idle[c]: component c's rows are K's identity (stage_coupled.c).
 * Fills *vp for saddle_krylov_solve_mg (the weights of nc rows beyond nu,
 * pad further rows).  Returns 0, or -1 with a message. */
int coupled_mg_setup(struct coupled_mg *m, const struct march_state *st,
                     const struct viscous_problem *pb, const int idle[3], int pad,
                     struct saddle_velocity_precond *vp, char *err, size_t errlen);

/* Bytes the multigrid holds. */
size_t coupled_mg_bytes(const struct coupled_mg *m);

#endif
