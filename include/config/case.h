/* The case description: what a case file (INI format) and its command-line
 * overrides say, validated, with defaults filled in.  Data flows one way:
 * case file -> struct muflow_case -> grid + fields -> time loop -> output. */
#ifndef MUFLOW_CASE_H
#define MUFLOW_CASE_H

#include <stddef.h>
#include <stdio.h>
#include "config/rheology_params.h"
#include "grid/boundary.h"
#include "grid/grid.h"

/* obstacle.plane: the shapes' coordinates (A, B) are along these directions */
enum obstacle_plane { OBSTACLE_XZ = 0, OBSTACLE_XY, OBSTACLE_YZ };
/* obstacle.boundary: sharp (cut links, second order) or staircase (nodes in
 * the body held at 0, first order: for comparison) */
enum obstacle_boundary { OBSTACLE_SHARP = 0, OBSTACLE_STAIRCASE, OBSTACLE_CELLS };

enum preconditioner { PRECOND_AUTO = 0, PRECOND_LINE, PRECOND_CHOLESKY, PRECOND_LU, PRECOND_AMG,
                     PRECOND_FOURIER, PRECOND_GMG, PRECOND_MULTIGRID };
enum solver_mode { MODE_STEADY = 0, MODE_TRANSIENT };
enum advection_scheme {
    ADVECTION_CENTRED = 0,
    ADVECTION_UPWIND,
    ADVECTION_VANLEER,
    ADVECTION_QUICK
};
/* solver.time_scheme (stage_time_scheme.c) */
enum time_scheme { TIME_EULER = 0, TIME_BDF2 };

struct muflow_case {
    char name[128];          /* case name: the file's base name without .ini */
    int scene;               /* case.scene: the scene's index in the registry's order, as
                                registered with the case reader (case_registry.h);
                                case_scene() of scenes/scene.h gives the scene itself */
    char reference[512];     /* case.reference: published data to compare with (a path
                                relative to the case file's folder; stored absolute) */

    /* [domain] */
    double len[3];           /* lx ly lz */
    int n[3];                /* nx ny nz */
    char band[3][128];       /* x_band y_band z_band: "lo hi h", a direction refined to
                                cells of h in [lo, hi] (empty: uniform len / n) */
    double growth;           /* the stretched cells' size ratio outside a band */

    /* [boundary] xlo xhi ylo yhi zlo zhi */
    struct boundary bc;

    /* [obstacle]: solid bodies inside the box (grid/shapes.h); no shapes: none */
    struct {
        char shapes[512];    /* "circle A B R; rectangle A0 B0 A1 B1" (a union) */
        int plane;           /* enum obstacle_plane: the two grid directions of A, B */
        int invert;          /* 1: the fluid is inside the shapes */
        int boundary;        /* enum obstacle_boundary: how no slip on the body is taken */
    } obstacle;

    /* [physics] */
    double tilt;             /* rad: gravity = g (sin tilt, 0, -cos tilt) */
    double gravity;          /* g, magnitude of gravity */
    double density;          /* bulk density (phi rho_s) in the momentum equation */
    double confining_pressure; /* added to the pressure that enters the rheology */
    int advection;           /* 1: explicit advection of momentum; 0: Stokes-like */
    int advection_scheme;    /* enum advection_scheme */

    /* [rheology] */
    struct rheology rheo;

    /* [solver] */
    enum solver_mode mode;
    double tolerance;        /* steady: stop when the relative residual falls below */
    long max_steps;
    double end_time;         /* transient: time to reach */
    double steady_tolerance;  /* transient: stop at a steady state below this (0: off) */
    double dt;               /* initial (steady) or fixed upper bound (transient) */
    double dt_max;           /* steady: cap of the growing pseudo-time step */
    double cfl;              /* advective CFL number (when advection is on) */
    int time_scheme;         /* enum time_scheme: transient steps' order in time */
    int newton;              /* 1: consistent tangent viscosity; 0: Picard (lagged) */
    double continuation;     /* steady: the regularisation starts at this multiple of
                                rheology.lambda, lowered 10-fold per stage (1: off) */
    double newton_below;     /* the tangent is used once residual / first residual
                                falls below this (Picard before): 1 = always */
    int coupled;             /* steady: velocity and pressure solved together each step
                                (solver.coupled, stage_coupled.c) */
    char initial_state[512]; /* solver.initial_state: a checkpoint whose fields start this
                                run, interpolated to its grid (empty: the scene's start) */
    int inexact_newton;      /* 1: Eisenstat-Walker forcing on Krylov Newton steps */
    int pressure_factorisation; /* 1: small 2D variable-coefficient projections factorised whole */
    double linear_tolerance; /* relative tolerance of the implicit viscous CG */
    int max_linear_iterations;
    int preconditioner_reuse;
    int line_direction;      /* -1 auto, or 0/1/2: preconditioner lines */
    enum preconditioner preconditioner; /* of the implicit viscous solve */
    double augmentation;     /* kappa: the grad-div (augmented Lagrangian) term has
                                r = kappa * eta per cell; 0 switches it off */
    double progress_interval; /* wall seconds between progress lines (0: every step) */

    /* The scene's own section ([heap], ...): its parameter block, declared
     * and parsed by the scene (its key_block), stored here so that a case
     * stays a plain value.  case_scene_params() gives it. */
    union {
        max_align_t align;
        unsigned char bytes[512];
    } scene_params;

    /* [output] */
    char output_dir[512];
    int quiet;               /* output.quiet: no progress lines */
    int fields;              /* output.fields: write HDF5 field files */
    long fields_every;       /* steps between field files (0: none by count) */
    double fields_interval;  /* time between field files (0: none by time) */
    long checkpoint_every;   /* steps between checkpoints (0: only when stopped) */
    long forces_every;       /* steps between rows of forces.csv (0: no file) */
};

/* The case's scene's parameter block (the scene's key_block struct). */
const void *case_scene_params(const struct muflow_case *c);
void *case_scene_params_mut(struct muflow_case *c);

/* Loads path (an INI file) then applies overrides "section.key=value" in order.
 * On failure returns 2 and writes one line naming the file / key, the value and
 * what is allowed into err; nothing is written to disk.  Returns 0 on success.
 * The scenes and the checks of the layers above are registered first
 * (run_init of app/run.h; case_registry.h): until the scenes are, every
 * case is refused. */
int case_load(struct muflow_case *c, const char *path, int noverrides,
              char *const overrides[], char *err, size_t errlen);

/* case_load that also reports warnings: each one line (naming the file, the
 * key and the lines), passed to warn(ctx, line) as found.  Warned: a key
 * given twice in the file (the later line is used) and a section header
 * given twice (its keys are read as one section).  Overrides replace file
 * values by design and are never warned about.  case_load warns nobody. */
typedef void (*case_warn_fn)(void *ctx, const char *line);
int case_load_warn(struct muflow_case *c, const char *path, int noverrides,
                   char *const overrides[], case_warn_fn warn, void *warn_ctx, char *err,
                   size_t errlen);

/* Defaults for every key (what a case file may leave out), scene "none". */
void case_defaults(struct muflow_case *c);

/* Sets the scene (a registered index) and its keys' defaults. */
void case_set_scene(struct muflow_case *c, int scene);

/* Writes every key with its value in the case file's own format (used in the
 * summary so that a run documents the parameters it used). */
void case_write_ini(const struct muflow_case *c, FILE *out);

/* Calls visit(ctx, section, key, value) for every key, in the order of
 * case_write_ini and with the text it writes (so "section.key=value" read back
 * as an override gives the identical value).  Stops at the first non-zero
 * return of visit and returns it; 0 when every key was visited. */
int case_visit_keys(const struct muflow_case *c,
                    int (*visit)(void *ctx, const char *section, const char *key,
                                 const char *value),
                    void *ctx);

/* The core key table (keys.h), in the order case_write_ini writes it; a
 * scene's own keys are its key_block (case_registry.h). */
struct key;
int case_key_count(void);
const struct key *case_key_at(int i); /* NULL out of range */

/* muflow --list: the scenes (name and title) and every key, core and each
 * scene's section, with its default, allowed values and meaning, all from
 * the key tables. */
void case_write_key_list(FILE *out);

/* The Markdown text before a core section's table in docs/case_keys.md (the
 * key table's section intros), or NULL. */
const char *case_section_intro(const char *section);

/* muflow --list=markdown: docs/case_keys.md, every section and key with its
 * meaning, allowed values, default and units, all from the key tables and
 * the scene registry (src/config/key_doc.c); `make case-keys` writes it. */
void case_write_key_markdown(FILE *out);

/* The spacing of direction d from domain.<d>_band, domain.growth, the far
 * size l / n and the periodicity: 1 with ax built (grid_axis_free frees it),
 * 0 for a uniform direction (the key empty), -1 with msg when the key is
 * not 'lo hi h' triples separated by ';' (msg empty) or the bands do not
 * fit (msg says why). */
int case_axis(const struct muflow_case *c, int d, struct grid_axis *ax, char *msg,
              size_t msglen);

/* 1 when the case has obstacle shapes (a body in the flow). */
int case_obstacle_active(const struct muflow_case *c);
/* The case's shapes with their plane and inversion (the case was checked:
 * the shapes parse). */
struct shape_set;
void case_obstacle_shapes(const struct muflow_case *c, struct shape_set *set);

#endif
