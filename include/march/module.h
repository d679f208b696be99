/* A physics module: an optional piece of the step that a scene switches on
 * (scenes/scene.h: modules).  It registers its own fields (march/fields.h)
 * when the march is created and fills in the stages of the step it needs
 * (march/step.h); a scene that does not use a module pays nothing for it.
 *
 * Hooks (every one may be NULL):
 *   create      registers fields, allocates its state (*state)
 *   properties  after the core properties (strain rates, pressure,
 *               viscosities): density and mixture properties, ...
 *   residual    adds its own terms to the momentum residual
 *               st->field.residual
 *   residual_max the largest |residual| of the module's own equations (a
 *               field it solves for beside the velocity), in the units of
 *               st->field.residual, and in *excess the same beyond the
 *               round-off of its terms: the steady criterion takes the
 *               larger of the two
 *   implicit    solves the step's implicit problem in place of the viscous
 *               solver (a module whose unknowns are coupled to the velocity
 *               too stiffly for a split step): st->field.increment from
 *               st->field.residual at pseudo-time step dt, its own
 *               increment kept for end_step;
 *               0, -1 when it broke down, 1 when it declines (an idle
 *               module: the viscous solver takes the step, with the
 *               viscosities and residual the hook may have set);
 *               implicit_steady: it acts on steady steps only
 *   transport   after the projection: advects its tracers by the new
 *               velocity over dt; 0, or -1 with the cause in st->step_error
 *               (the step breaks down: the march ends with its last good
 *               state and says why)
 *   end_step    the last stage of an accepted step
 *   max_dt      the largest time step its stages allow at the current state
 *               (a transient step is the smallest of these, the CFL limit
 *               and solver.dt; INFINITY: none)
 *   save        puts what it keeps between steps beyond its fields (a
 *               record of the run, a counter) into the checkpoint
 *               (march/module_record.h): a continued run goes on as if it had
 *               not stopped; 0, or -1 with the cause in the record
 *   load        reads that back when a run continues from a checkpoint,
 *               after the fields and the loop state, and brings what it
 *               derives from them up to date; 0, or -1 with the cause.
 *               rec is NULL for a checkpoint that holds none (written by
 *               an earlier muflow): 0 to go on without it, -1 to refuse
 *   destroy     frees its state
 *   memory_bound the bytes it allocates at most for the case on g, known
 *               before it exists (the march's memory estimate, which
 *               refuses a run the machine cannot hold)
 *   line_search non-zero while the steady steps should take the line search
 *               and the rejection on both norms of the residual (march.c:
 *               searched_steps): a held mean velocity, whose plug's speed
 *               the border fixes
 *   border      a constraint with one unknown of its own that borders the
 *               coupled step's matrix (below)
 *
 * files: the names of the output files it writes into the output folder
 * (NULL-terminated, or NULL), which a fresh run removes with every other
 * run file of an earlier run there (io/output.h).
 * coupled_ok: the coupled step (solver.coupled), which solves the velocity
 * and pressure of one density and one velocity field, takes the module (a
 * body, a border); without it a coupled case with the module is refused.
 * decomposed: the module runs on a rank's block of a decomposed march
 * (docs/numerics/decomposition.md): its work is per cell or per line along
 * the unsplit z, its ghosts filled by bc_fill_*, what it sums over the
 * domain summed over the ranks (march_sum); without it a case that switches
 * it on is refused on several ranks (a scene's own modules: the scene's
 * decomposed, scenes/scene.h, which knows those its case leaves idle). */
#ifndef MUFLOW_MARCH_MODULE_H
#define MUFLOW_MARCH_MODULE_H

#include <stddef.h>

struct grid;
struct march_state;
struct module_record;
struct muflow_case;

/* The bordered coupled step (stage_coupled.c): with K the step's matrix, b
 * its right-hand side and f = column, K x1 = b and K x2 = f share one
 * factorisation, and the step is x1 + d x2 with d = (gap - row(x1)) /
 * row(x2), so that the constraint row(u) = target holds after the step.
 * One module at most borders a step (the first with a border). */
struct module_border {
    /* into f (a face field triple, overwritten) the residual's derivative
     * in the unknown, into *gap the target less the constraint's value;
     * 0, or -1 while the constraint is idle */
    int (*column)(struct march_state *st, void *state, double *f[3], double *gap);
    /* the constraint's linear functional of the face field triple u */
    double (*row)(const struct march_state *st, void *state, double *const u[3]);
    /* the step's increment d of the unknown (applied with the velocity's) */
    void (*increment)(struct march_state *st, void *state, double d);
};

struct module {
    const char *name;
    int (*create)(struct march_state *st, void **state, char *err, size_t errlen);
    void (*properties)(struct march_state *st, void *state);
    void (*residual)(struct march_state *st, void *state);
    double (*residual_max)(const struct march_state *st, void *state, double *excess);
    int (*implicit)(struct march_state *st, void *state, double dt);
    int (*transport)(struct march_state *st, void *state, double dt);
    void (*end_step)(struct march_state *st, void *state, double dt);
    double (*max_dt)(const struct march_state *st, void *state);
    int (*save)(const struct march_state *st, void *state, struct module_record *rec);
    int (*load)(struct march_state *st, void *state, struct module_record *rec);
    void (*destroy)(void *state);
    double (*memory_bound)(const struct muflow_case *cs, const struct grid *g);
    int (*line_search)(const struct march_state *st, void *state);
    const struct module_border *border;
    const char *const *files;
    int coupled_ok;
    int decomposed;
    int implicit_steady;
};

#define MODULES_MAX 8

#endif
