/* The time loop.  A step's stages are written out in march/step.h
 * (properties -> residual -> implicit viscous step -> projection -> transport
 * -> end of step); this file owns the loop around them.  Two modes share it:
 *   steady     pseudo-time march, the step grown as the residual falls
 *              (switched evolution relaxation, dt = dt0 * r0 / r); with the
 *              tangent viscosity this becomes Newton's method as dt grows;
 *              stops on the residual criterion, or says why it cannot;
 *   transient  time-accurate to end_time, dt bounded by the CFL limit.
 * The body force is split once into its hydrostatic part (a pressure) and
 * the rest, so the pressure entering the rheology is right from the start. */
#ifndef MUFLOW_MARCH_H
#define MUFLOW_MARCH_H

#include "config/case.h"
#include "grid/boundary.h"
#include "grid/grid.h"
#include "kernels/kernels.h"
#include "march/fields.h"
#include "march/module.h"
#include "solvers/pressure.h"
#include "solvers/viscous.h"

/* A steady march is judged stalled only after this many steps without
 * progress (end_check.c: stalled); the residuals of as many steps are kept. */
#define MARCH_STALL_STEPS 200
#define MARCH_RECENT (MARCH_STALL_STEPS + 1)

enum run_status { STATUS_RUNNING = 0, STATUS_STEADY, STATUS_FINISHED, STATUS_UNSTEADY,
                  STATUS_DIVERGED, STATUS_STOPPED };

/* The march's own fields, declared once: each is a member of struct
 * march_fields (double *name for FIELD_CELLS, double *name[3] for the
 * others) and an entry of the field registry under the same name, with its
 * flags (march/fields.h; src/march/core_fields.c registers them, in this
 * order).  X(name, where, flags, what it holds). */
#define MARCH_CORE_FIELDS(X)                                                                       \
    X(velocity, FIELD_FACES, FIELD_CHECKPOINT | FIELD_SAVED, "velocity on faces")                  \
    X(p_dyn, FIELD_CELLS, FIELD_CHECKPOINT | FIELD_SAVED, "dynamic pressure (projection)")         \
    X(p_hyd, FIELD_CELLS, 0, "hydrostatic pressure of the body force")                             \
    X(force, FIELD_FACES, 0, "body force minus its hydrostatic gradient")                          \
    X(density_faces, FIELD_FACES, 0, "face density rho_f of the mass term (density_uniform)")      \
    X(pressure, FIELD_CELLS, 0, "total pressure: confining + gauge + hydrostatic + dynamic")       \
    X(strain_normal2, FIELD_CELLS, 0, "normal strain^2 per cell")                                  \
    X(strain_shear2, FIELD_EDGES, 0, "shear strain^2 per edge")                                    \
    X(shear2, FIELD_CELLS, 0, "|D|^2 per cell")                                                    \
    X(viscosity, FIELD_CELLS, 0, "viscosity per cell")                                             \
    X(pressure_regularised, FIELD_CELLS, 0, "the pressure the rheology reads")                     \
    X(tangent_cells, FIELD_CELLS3, 0, "normal-stress tangent coefficients (cells)")                \
    X(viscosity_edges, FIELD_EDGES, 0, "shear-stress viscosity (edges)")                           \
    X(tangent_edges, FIELD_EDGES, 0, "shear-stress tangent (edges)")                               \
    X(residual, FIELD_FACES, 0, "momentum residual")                                               \
    X(increment, FIELD_FACES, 0, "velocity increment of the implicit solve")                       \
    X(advection, FIELD_FACES, 0, "advection term (NULL without physics.advection)")                \
    X(divergence, FIELD_CELLS, 0, "the projection's divergence")                                   \
    X(phi, FIELD_CELLS, 0, "the projection's potential")                                           \
    X(velocity_previous, FIELD_FACES, FIELD_CHECKPOINT | FIELD_SAVED | FIELD_START_OPTIONAL,       \
      "the velocity a step before (solver.time_scheme = bdf2)")                                    \
    X(advection_previous, FIELD_FACES, FIELD_CHECKPOINT | FIELD_SAVED | FIELD_START_OPTIONAL,      \
      "the advection term a step before (bdf2 with advection)")

#define MARCH_FIELD_MEMBER_FIELD_CELLS(name) double *name;
#define MARCH_FIELD_MEMBER_FIELD_FACES(name) double *name[3];
#define MARCH_FIELD_MEMBER_FIELD_EDGES(name) double *name[3];
#define MARCH_FIELD_MEMBER_FIELD_CELLS3(name) double *name[3];
#define MARCH_FIELD_MEMBER(name, where, flags, what) MARCH_FIELD_MEMBER_##where(name)

struct march_fields {
    MARCH_CORE_FIELDS(MARCH_FIELD_MEMBER)
};

/* A run over the ranks of an MPI job (docs/numerics/decomposition.md): the
 * Cartesian communicator, this rank's block, the global grid; the march's
 * grid g is then the block's local grid and bc.dc points at dc. */
struct march_ranks {
    struct comm_cart cart;
    struct decomp dc;
    struct grid global;
};

struct march_state {
    const struct muflow_case *cs;
    struct grid g;
    struct march_ranks *ranks; /* NULL: one process holds the grid */
    struct grid_axis axes[3]; /* the stretched directions' spacing (g.axis) */
    struct boundary bc;
    struct box act[3];          /* velocity unknowns per component */
    struct field_registry fields; /* every array below is registered there */
    struct march_fields field;  /* the march's own fields (MARCH_CORE_FIELDS) */
    /* the physics modules of the scene (and of the caller), their states */
    int nmodules;
    const struct module *modules[MODULES_MAX];
    void *module_state[MODULES_MAX];
    /* variable coefficients: the face density rho_f of the mass term
     * (field.density_faces) and beta = rho_ref / rho_f of the projection.
     * While density_uniform the density is cs->density on every face: the
     * mass term is the scalar rho / dt and the projection uses the FFT
     * solver. */
    int density_uniform;
    double rho_ref;
    double *mass_face[3];       /* rho_f / dt of the step (variable density) */
    double *beta[3];            /* rho_ref / rho_f (variable density) */
    /* a constant a scene adds to the pressure the rheology reads (0 unless
     * set): the projection fixes only p_dyn's gradient, the rheology needs
     * its level (the collapse: the top at -rho_f g lz, scenes/collapse.c) */
    double pressure_gauge;
    double *aug;                /* augmentation r = kappa max(eta) per cell, or NULL */
    enum viscous_precond precond; /* of the implicit solve (automatic or the case's) */
    double memory_estimate;     /* bytes the run was estimated to need before allocating */
    int full_tangent;           /* Newton with the full (non-symmetric) tangent */
    double *b_c, *b_e[3];       /* its coefficients (d eta/d|D|)/(2|D|), or NULL */
    const struct embedded *embedded; /* a solid body in the grid (physics/obstacle.h), or NULL */
    struct pressure_solver *pressure_solver;
    struct viscous_solver *viscous;
    struct coupled_state *coupled; /* solver.coupled's numbering and solver (stage_coupled.c) */

    long step;
    double time, dt;            /* dt: the last step's */
    long bdf2_steps;            /* steps since velocity_previous holds the state a step
                                   before (solver.time_scheme = bdf2; 0: the next is Euler's) */
    double residual;            /* max |momentum residual| / (rho g) */
    double residual_excess;     /* the same beyond the round-off of its terms: what the
                                   steady criterion tests */
    double divergence;          /* max |div u| h / max |u| */
    double velocity_max;        /* max |u| of the evaluated state */
    double residual_rms;        /* root mean square of the residual / force scale */
    double residual0;
    double force_ref;           /* what residuals are relative to: rho g, or without
                                   gravity the first residual */
    double wall_seconds;
    int linear_iterations;      /* of the last step */
    long rejected;              /* pseudo-time steps retried with a smaller dt */
    long pressure_iterations;   /* the projection's multigrid-CG iterations, every step */
    long pressure_solves;       /* the projection's solves, every step */
    /* what the last try of a step (its advance and evaluation) sent over the
     * ranks (grid/decomp.h's tallies; nothing on one process): halo planes
     * and gathers, the collectives */
    struct decomp_traffic step_halo;
    struct comm_traffic step_collectives;
    long pressure_unconverged;  /* its solves that ended above their tolerance */
    long linear_unconverged;    /* implicit solves stopped at solver.max_linear_iterations */
    long grid_matrices;         /* matrices of the grid's unknowns probed for the implicit
                                   step (viscous.h: viscous_precond_info), the run's */
    long hydrostatic_matrices;  /* whole-grid factorisations of the hydrostatic split's
                                   solves in this process (pressure.h: pressure_direct) */
    double linear_residual;     /* relative residual of the last implicit solve */
    /* loop state that a restart must recover to continue bit for bit */
    double best_residual;       /* best residual so far (stall detection) */
    long best_step;             /* the step it was reached at */
    double best_time;           /* and the pseudo-time */
    /* the accepted residual of each of the last MARCH_RECENT steps, at
     * step % MARCH_RECENT (NAN: not reached since the problem began) */
    double recent_residual[MARCH_RECENT];
    double peak_residual;       /* the largest of them since the problem began */
    /* the largest max |u| of the accepted states whose residual was within
     * ten times max(1, residual0) (the weight, or the start's): the velocity
     * scale a blow-up is measured against (end_check.c) */
    double sane_velocity;
    /* the mean acceleration each time the pseudo-time doubled (newest
     * first): whether an acceleration is sustained or decaying */
    double mark_time;
    double mark_acc[3];
    long marks;
    double dt_scale;            /* pseudo-time step reduction after rejections */
    /* continuation in the regularisation (solver.continuation): the rheology
     * the march evaluates, whose lambda starts above the case's and is
     * lowered stage by stage, and the residual a stage started from */
    struct rheology rheo;
    double stage_residual0;
    /* the Picard steps (solver.newton_below) have stalled: the tangent from
     * now on (in this continuation stage) */
    int picard_stalled;
    /* the inexact Newton forcing term (forcing.c): the last linear tolerance,
     * the RMS residual it was chosen at and the step (0: none yet) */
    double forcing, forcing_rms;
    long forcing_step;
    /* the step, time and dt of the saved (last accepted) fields: a run that
     * ends on a bad state goes back to them as a whole */
    long good_step;
    double good_time, good_dt;
    enum run_status status;
    char message[256];          /* why the run ended */
    char step_error[160];       /* why the last step's solve failed, when a stage says */
};

/* Called after every residual evaluation (also the final one); return non-zero
 * to stop the run with status STATUS_STOPPED. */
typedef int (*march_observer)(void *ctx, const struct march_state *st);

/* What the march takes of the layers above it, which its caller looks up
 * once from the case's scene and hands in (scenes/scene.h:
 * scene_march_setup): nothing in the march switches on a scene or a
 * module. */
struct march_setup {
    /* the physics modules, NULL-terminated lists (or NULL) taken in this
     * order: the scene's, the caller's (a program embedding muflow, a
     * test), the case's own (a body: obstacle.shapes) */
    const struct module *const *modules[3];
    /* the scene's forcing and initial state, after the fields exist and
     * before the hydrostatic split, which may depend on them (a restart
     * overwrites the fields afterwards); NULL: rest */
    int (*setup)(struct march_state *st, char *err, size_t errlen);
    /* 1: the flow runs along the grid's periodic direction of one cell and
     * the implicit step solves it (the scene's cross_section_flow) */
    int cross_section_flow;
    /* 1: the grid is split over the ranks of the MPI job when it has
     * several (comm.h; struct march_ranks); 0: this process holds it all */
    int decompose;
    /* the ranks along each direction (0: MPI_Dims_create's choice; a
     * test's split along one direction) */
    int dims[3];
};

/* Over the ranks of the run (the value itself on one process): a sum, a
 * maximum (a NaN on any rank is everyone's), n sums in place, n maxima in
 * place (of values that are no NaN).  Collective. */
double march_sum(const struct march_state *st, double v);
double march_max(const struct march_state *st, double v);
void march_sum_array(const struct march_state *st, double *v, int n);
void march_max_array(const struct march_state *st, double *v, int n);
/* The whole domain's grid: st->g, or the global grid of a decomposed run. */
const struct grid *march_global_grid(const struct march_state *st);

/* Creates the march of the case: its grid, fields, solvers and modules,
 * the scene's setup, the hydrostatic split.  Returns 0, or -1 with the
 * cause in err (nothing to destroy then). */
int march_create(struct march_state *st, const struct muflow_case *cs,
                 const struct march_setup *su, char *err, size_t errlen);

/* Declares that the face density (field.density_faces) changed: a module's
 * properties stage calls it after writing it; uniform says whether it is
 * still cs->density everywhere.  With an embedded body (st->embedded) the
 * projection's coefficient gets the body's closed faces and open shares
 * here, whichever module changed the density.  Returns 0, or -1 when the
 * pressure solver cannot take the new coefficient (cause in err). */
int march_density_changed(struct march_state *st, int uniform, char *err, size_t errlen);

/* The state of module m in this march, or NULL when it is not switched on
 * (a scene's setup configures its modules through it). */
void *march_module_state(const struct march_state *st, const struct module *m);
void march_destroy(struct march_state *st);

/* Starts a new march from the current fields after the body force of the
 * case st->cs points to changed (tilt, gravity): the force is split again and
 * the loop state reset, so that march_run solves the new problem from the
 * previous solution (continuation).  Returns 0, or -1 with the cause in err. */
int march_reforce(struct march_state *st, char *err, size_t errlen);

/* Runs to the end of the case (steady state, end time, or failure).  It can be
 * called on a state whose fields and loop state were loaded from a checkpoint:
 * the march continues exactly as the uninterrupted run would have. */
enum run_status march_run(struct march_state *st, march_observer obs, void *ctx);

const char *run_status_name(enum run_status s);

/* Bytes of memory available to a new allocation: MemAvailable of
 * /proc/meminfo, else sysconf's available pages; the environment variable
 * MUFLOW_AVAILABLE_MEMORY (bytes) replaces it (tests).  0 when unknown.
 * march_create refuses a grid whose estimate (memory_estimate) exceeds it. */
double march_available_memory(void);

/* The same refusal from the case and its setup alone, before any field or
 * geometry (its grid and bands, the preconditioner auto would choose, the
 * modules' memory_bound: a body bounded from above): 1 with one line in
 * msg naming the grid keys when the run needs more than
 * march_available_memory, else 0 (also when that is unknown).
 * Where auto's choice depends on hypre's library, which this does not open,
 * the smaller of the two estimates counts (march_create's check has the
 * library's answer). */
int march_memory_check(const struct muflow_case *cs, const struct march_setup *su, char *msg,
                       size_t msglen);

/* The preconditioner solver.preconditioner names against the case, where
 * the march picks the solvers: the coupled step's (solver.coupled) GMRES
 * (saddle_krylov_refusal) and its refusal of gmg, and the implicit step's
 * geometric multigrid (viscous_gmg_refusal).  1 with one line in msg naming
 * the keys, else 0.  The case reader calls it when a case is loaded
 * (case_registry.h), so that the command refuses before any allocation. */
int march_preconditioner_refusal(const struct muflow_case *cs, char *msg, size_t msglen);

/* What residuals are relative to (rho g, or the first residual), and the
 * smallest cell size of the directions with more than one cell. */
double march_force_scale(const struct march_state *st);
double march_min_spacing(const struct grid *g);

/* The steady momentum residual R(u) of the current state into
 * st->field.residual (and the viscosities and tangent coefficients at it). */
void march_evaluate(struct march_state *st);

/* out = -dR/du v, the linearised operator of the implicit step without its
 * mass term, at the state of the last march_evaluate (tests check it against
 * finite differences of the residual). */
void march_apply_tangent(struct march_state *st, double *v[3], double *out[3]);

/* The component the body force drives: of x and z, the one with the larger
 * force, or the other where that one is neither periodic nor open at both
 * ends (a bounded direction's force is held by the pressure): the mean flow
 * direction. */
int march_driven_component(const struct march_state *st);

/* The mean of f (an array of component a's faces) over the unknowns of
 * component a, over the ranks: each block's mean weighted by its nodes.
 * Collective. */
double march_component_mean(const struct march_state *st, int a, const double *f);

/* The mean of the momentum residual along the driven component per unit
 * mass: the mean acceleration of the layer. */
double march_mean_acceleration(const struct march_state *st);

/* What a Picard-first solve's drop is measured from (solver.newton_below):
 * the stage's first residual, or the largest since if the residual climbed
 * (a start from rest: the square duct's climbs from 1 to 27). */
double march_picard_reference(const struct march_state *st);

#endif
