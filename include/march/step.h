/* The step's stages, written out in one place (src/march/step.c), one file
 * per stage:
 *
 *   evaluate (the state's residual, before a step and to judge it):
 *     1. properties   strain rates, total and regularised pressure,
 *                     viscosities and tangents (stage_properties.c); then
 *                     the modules' properties
 *     2. residual     R = f - grad p + div tau - rho div(u u), the modules'
 *                     terms, its norms (stage_residual.c)
 *   advance (one step of size dt from an evaluated state):
 *    2b. time scheme  BDF2's terms of the previous step added to R, the
 *                     step's mass rho a0 / dt (stage_time_scheme.c)
 *     3. implicit     (rho_f / dt) du - div(T : grad du) = R, the face
 *                     density rho_f in the mass term (stage_implicit.c)
 *     4. projection   div(beta grad phi) = div du, beta = rho_ref / rho_f;
 *                     u += du - beta grad phi, p += (rho_ref / dt) phi and
 *                     the augmented-Lagrangian update (stage_projection.c);
 *                     after a coupled step (3 solved for du and dp at
 *                     once, stage_coupled.c) u += du alone
 *     5. transport    the modules' tracers advected by the new velocity
 *                     (a new density leaves the projection's factorisation
 *                     due: where it is the whole grid's, a second thread
 *                     does it beside the next step's stage 3, step.c)
 *     6. end of step  the modules' last word on the step
 * The body force is split once (and again when it changes) into its
 * hydrostatic pressure and the rest (hydrostatic.c). */
#ifndef MUFLOW_MARCH_STEP_H
#define MUFLOW_MARCH_STEP_H

#include "march/march.h"

void step_evaluate(struct march_state *st);
/* Returns 0, or -1 when a stage broke down, its cause in st->step_error
 * when the stage gave one (nothing changed that a restore of the saved
 * fields does not undo). */
int step_advance(struct march_state *st, double dt);

/* The stages (each in its own file). */
void stage_properties(struct march_state *st);
void stage_residual(struct march_state *st);
/* The residual of the evaluated state beyond the round-off it has when every
 * velocity carries an absolute error of the field's round-off (its terms'
 * sizes with each velocity taken as max |u|), relative to the force scale:
 * what a stiff region (a plug, eta ~ mu p / lambda) keeps of the solves'
 * round-off.  Overwrites st->field.increment (scratch after the residual stage). */
double stage_residual_velocity_roundoff(struct march_state *st);
/* solver.time_scheme = bdf2: adds BDF2's terms of the state a step before to
 * the residual and keeps the state for the next step; returns dt / a0, the dt
 * that the implicit step's mass rho / dt and the projection take (dt itself
 * for Euler's step, and with euler). */
double stage_time_scheme(struct march_state *st, double dt);
int stage_implicit(struct march_state *st, double dt);
/* solver.coupled: the steady step's velocity and pressure increments from
 * one saddle-point system (stage_coupled.c), in place of the implicit
 * solve; p takes its increment there.  Returns 0, or -1 when memory runs
 * out or the factorisation fails. */
struct viscous_problem;
int stage_coupled(struct march_state *st, const struct viscous_problem *pb);
/* u += du after a coupled step, in place of the projection: the coupled
 * solve makes u + du solenoidal already, and a projection of its round-off
 * moved a plug's velocity by more than its regularised strain rate
 * (lambda 1e-6: the granular cylinder stalled at a residual of 5e-7 with
 * it, and was steady in one step from that state without it). */
void stage_coupled_update(struct march_state *st);
/* GMRES solves of the coupled step (solver.preconditioner = amg) that
 * failed and left the run to the LU, and, unless cause is NULL, why the last
 * one failed (NULL: none failed, or no coupled step yet). */
long stage_coupled_fallbacks(const struct coupled_state *c, const char **cause);
/* Frees what the coupled steps keep (numbering, colouring, the LU's
 * analysis); NULL is a no-op. */
void stage_coupled_destroy(struct coupled_state *c);
void stage_projection(struct march_state *st, double dt);
/* div v per cell as the projection makes it vanish: the plain MAC sum, or
 * with an embedded body the cut cells' flux form (kernels/embedded.h). */
void stage_divergence(const struct march_state *st, double *const v[3], double *out);

/* The implicit operator at the current state for a step dt (dt = 0: the
 * linearised stress alone, no mass term), as the viscous solver takes it. */
struct viscous_problem implicit_problem(const struct march_state *st, double dt);
/* Whether the next step linearises with the tangent (Newton) rather than the
 * lagged viscosity (Picard). */
int implicit_uses_tangent(const struct march_state *st);
/* The linear tolerance of this step's implicit solve: solver.linear_tolerance,
 * or on a Newton step solved with the algebraic multigrid an inexact Newton
 * forcing term tied to the residual's last decrease (forcing.c). */
double implicit_tolerance(struct march_state *st, int tangent);

/* The hydrostatic split of the body force (hydrostatic.c), and the force
 * rho g (sin tilt, 0, -cos tilt) per unit volume at the case's density. */
int hydrostatic_split(struct march_state *st, char *err, size_t errlen);

/* The force of the current face density less grad p_hyd (after the density
 * changed). */
void hydrostatic_force(struct march_state *st);
void body_force_vector(const struct muflow_case *cs, double f[3]);

/* A pressure solver on st's grid (over its ranks when decomposed), with the
 * case's solver.pressure_factorisation.  Returns 0, or -1 with a message. */
int march_pressure_create(const struct march_state *st, struct pressure_solver **ps,
                          const enum poisson_bc bc[3][2], char *err, size_t errlen);

#endif
