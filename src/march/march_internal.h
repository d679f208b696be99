/* What the files of the march share beyond march.h, their public face: the
 * auto policy of the implicit solve's preconditioner (precond_policy.c),
 * the march's own fields (core_fields.c), the memory estimate
 * (memory_estimate.c), the loop's state between steps (loop_state.c) and
 * the end of a run (end_check.c). */
#ifndef MUFLOW_MARCH_INTERNAL_H
#define MUFLOW_MARCH_INTERNAL_H

#include <stddef.h>
#include "march/march.h"

/* ---- precond_policy.c ---------------------------------------------------- */

/* Line blocks are exact for flows uniform across lines and cheap; a flow that
 * varies in two or more directions gets a sparse factorisation while it is
 * affordable.  A flow varies only across its bounded (non-periodic)
 * directions and, with a body, the periodic ones of the body's plane: the
 * body force is uniform, so with one such direction the lines along it are
 * exact whatever the periodic extent (measured: bagnold
 * 15 x 5 x 40 took 15.3 s with the LU of 375 probes a step, 0.11 s with the
 * line blocks, same profile; 16 x 8 x 40 needed 960 probes and failed).  The
 * probes are one operator application each per step: beyond the
 * factorisation's limit the line blocks serve instead of failing. */
#define FACTOR_MAX_UNKNOWNS 400000L

/* Whether auto may choose hypre's AMG: amg 1 or 0 as given, -1 the
 * library's answer (it is opened to find out). */
int march_amg_allowed(int amg);
/* The implicit solve's preconditioner for the case on g (amg: see
 * march_amg_allowed). */
enum viscous_precond march_choose_preconditioner(const struct muflow_case *cs,
                                                 const struct march_setup *su,
                                                 const struct grid *g, int amg);

/* ---- core_fields.c ------------------------------------------------------- */

/* The arrays of the march (march/fields.h), march_nspecs of them. */
extern const struct field_spec march_specs[];
extern const size_t march_nspecs;
/* Whether the run needs the array (the advection term's only with
 * advection). */
int march_spec_wanted(const struct muflow_case *cs, const struct field_spec *spec);
/* Registers the wanted ones and the field files' outputs; 0, or -1 when
 * memory runs out. */
int march_register_fields(struct march_state *st);

/* ---- memory_estimate.c --------------------------------------------------- */

/* Bytes the march will allocate on g with the preconditioner kind. */
double march_memory_estimate(const struct muflow_case *cs, const struct march_setup *su,
                             const struct grid *g, enum viscous_precond kind);
/* Bytes the coupled step adds on every rank of a decomposed run: the
 * whole grid gg's matrix, factors and gathered fields (coupled_view.h). */
double march_coupled_gathered_estimate(const struct grid *gg);
/* The preconditioner (*kind) and the estimate of the case on g (amg: see
 * march_amg_allowed), within avail where auto has a choice. */
double march_plan(const struct muflow_case *cs, const struct march_setup *su,
                  const struct grid *g, int amg, double avail, enum viscous_precond *kind);
/* The refusal of a run that needs more than avail: one line naming the grid
 * keys. */
void march_memory_refusal(char *err, size_t errlen, const struct grid *g,
                          enum viscous_precond kind, double need, double avail);

/* ---- loop_state.c -------------------------------------------------------- */

/* A steady march is judged unable to reach a steady state only when the best
 * residual has not improved by 10% for STALL_STEPS steps AND for a
 * pseudo-time of STALL_STEPS unreduced steps (march_choose_dt without the
 * cut of rejected steps), AND no residual of those steps is 10% below the
 * one STALL_STEPS steps ago: each condition alone took a physical start-up,
 * a crawl of cut steps or a residual that first climbs for a stall
 * (docs/numerics/steady-criterion.md). */
#define STALL_STEPS MARCH_STALL_STEPS
#define STALL_FACTOR 0.9
/* A sane residual: within SANE_RESIDUAL times max(1, the start's) (a
 * blow-up's measure: end_check.c). */
#define SANE_RESIDUAL 10.0

/* A new problem (a start, a stage of the continuation, a new forcing): its
 * progress is measured afresh. */
void march_forget_progress(struct march_state *st);
/* Whether a residual of the last `steps` steps (the current one included) is
 * 10% below the one `steps` steps ago; -1 when that one was not recorded. */
int march_fell_over(const struct march_state *st, long steps);
/* The last accepted state as a whole (its fields, step, time and dt): saved,
 * and restored (and evaluated again). */
void march_save_good(struct march_state *st);
void march_restore_good(struct march_state *st);
/* The advective limit of the step (infinite without advection), and the
 * step the mode, the residual and the modules' limits give. */
double march_cfl_dt(const struct march_state *st);
double march_choose_dt(const struct march_state *st);
/* A continuation in the regularisation: the stage's lambda is above the
 * case's. */
int march_continuing(const struct march_state *st);
/* A residual within SANE_RESIDUAL times max(1, the start's). */
int march_sane(const struct march_state *st);

/* ---- end_check.c --------------------------------------------------------- */

/* Sets status and message when the run must end with the current state. */
void march_check_end(struct march_state *st);

#endif
