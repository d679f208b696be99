/* A scene: one file under src/scenes/ that says everything muflow knows of
 * one flow problem, registered with one line in src/scenes/registry.c.
 * Nothing outside the registry and the scene's own file switches on it.
 *
 * What a scene declares (every member but name may be left out):
 *   keys        its own case-file section ([heap]), with ranges and checks
 *   check       what it needs of the core keys (boundaries, law, grid)
 *   modules     the physics modules it switches on (march/module.h)
 *   setup       forcing and initial state after the fields exist (default:
 *               rest, gravity along the tilted plane)
 *   profile     the axis and velocity component of its profile, an optional
 *               slab (the cavity's mid-line), the exact or reference profile
 *   headline    the name of its headline value and of its error, and how
 *               both are computed from the profile (and the state)
 *   comparison  whether the profile and headline are compared with an exact
 *               solution or published reference data (solution_name), which
 *               names the outputs (u_exact / u_reference, psi_max_reference),
 *               whether it has an err_rms_paper, and the parameters that
 *               select the data (for "no reference data" messages)
 *   keys' help  a one-line help text per key (muflow --list prints it)
 *   drive       a driver in place of the plain march (the heap's tilt search)
 *   results     extra summary lines and one line for the terminal
 *   write       extra output files (heap.csv), also during the run when
 *               write_running is set (the collapse's record) */
#ifndef MUFLOW_SCENES_INTERFACE_H
#define MUFLOW_SCENES_INTERFACE_H

#include <stddef.h>
#include "config/keys.h"

struct grid;
struct march_setup;
struct march_state;
struct module;
struct muflow_case;
struct profile;
struct profile_spec;
struct result_names;
struct run_result;
struct scene_errors;

/* What a driver gets from the run (app/run.c): the march to drive, the
 * working copy of the case it may change (a tilt), the observer that does
 * the run's per-step outputs, and room for what its results need later. */
typedef int (*march_observer_fn)(void *ctx, const struct march_state *st);
struct scene_drive {
    struct march_state *st;
    struct muflow_case *cs;
    march_observer_fn observe;
    void *observe_ctx;
    int verbose;                   /* progress lines wanted */
    int restarted;                 /* the march continues from a checkpoint (its
                                      loop state is the checkpoint's): go on with
                                      it, do not start it afresh */
    const char *dir;               /* the output folder, NULL when the run writes
                                      no files or on a rank other than 0 (a
                                      driver's own record goes there) */
    union {                        /* the driver's own results, for results() */
        max_align_t align;
        unsigned char bytes[512];
    } data;
};

struct scene {
    const char *name;
    const char *title;             /* one line, for --list and the header */
    const struct key_block *keys;
    const struct module *const *modules; /* NULL-terminated, or NULL */
    int (*check)(const struct muflow_case *cs, char *msg, size_t msglen);
    int (*setup)(struct march_state *st, char *err, size_t errlen);

    int stretched_grid;            /* 1: setup and results read positions and
                                      sizes through grid_xc / grid_hc (a
                                      domain.<d>_band is allowed) */
    /* 1: the flow runs along the grid's periodic direction of one cell, the
     * grid a cross-section of it, and the implicit step's solver solves it
     * (the heap, the duct's mixed model): solver.preconditioner = auto takes
     * the implicit step's geometric multigrid for its steady Newton solves
     * (precond_policy.c); NULL: 0 */
    int (*cross_section_flow)(const struct muflow_case *cs);
    /* 1: the case runs over the ranks of an MPI job, its periodic
     * directions split (docs/numerics/decomposition.md; march_create
     * refuses the options and the case's modules that do not), its own
     * modules with these keys too; NULL: the scene runs on one process only */
    int (*decomposed)(const struct muflow_case *cs);
    const char *not_decomposed;    /* the keys for which decomposed is 0 (its refusal) */
    int profile_axis, profile_component; /* -1: no profile */
    /* limits the profile to the faces and cells of index in [lo, hi] (both
     * inclusive) along profile_slab_axis (0: x, the cavity's mid-line; 1: y,
     * the duct's mid-plane); NULL: every layer's full mean */
    void (*profile_slab)(const struct grid *g, int faces[2], int cells[2]);
    int profile_slab_axis;
    /* u at the n coordinates x along the axis (NaN where undefined) */
    void (*exact_profile)(const struct muflow_case *cs, int n, const double *x, double *u);

    const char *headline_name;     /* NULL: no headline and no error lines */
    const char *error_name;        /* name of err_rms in the summary and on the
                                      terminal (NULL: "err_rms") */
    /* what exact_profile and the headline's comparison value are: NULL for an
     * exact solution ("exact": u_exact, u_surface_exact), "reference" for
     * published data (the cavity: u_reference, psi_max_reference, and "no
     * reference data" where the data have none) */
    const char *solution_name;
    int no_err_rms_paper;          /* 1: the scene has no err_rms_paper (its error is
                                      not over the profile's layers): not written */
    /* the parameters that select the reference data, for the message when
     * the data have none for them ("Bn = 1.414 (Vola's convention)"); NULL:
     * none named */
    void (*reference_parameters)(const struct muflow_case *cs, char *out, size_t outlen);
    /* the errors and the headline; NULL: profile_errors_default with the
     * plug (centre) value as headline */
    void (*errors)(const struct march_state *st, const struct profile *pr,
                   struct scene_errors *e);

    int (*drive)(struct scene_drive *d);
    /* a message when the case cannot continue from a checkpoint (a search),
     * else NULL */
    const char *(*not_restartable)(const struct muflow_case *cs);
    void (*results)(const struct march_state *st, const struct scene_drive *d,
                    struct run_result *res);
    int (*write)(const char *dir, const struct march_state *st, char *err, size_t errlen);
    const char *const *files;      /* the names write() produces (NULL-terminated) */
    /* 1: write() also runs during the run, with each field file and every
     * solver.progress_interval of wall time, each file replaced whole (a
     * long transient's record can be read while it runs) */
    int write_running;
};

/* "exact" or the scene's solution_name ("reference"). */
const char *scene_solution_name(const struct scene *s);
/* The scene's error name: error_name or "err_rms". */
const char *scene_error_name(const struct scene *s);
/* 1 when the scene compares with published data rather than an exact solution. */
int scene_has_reference(const struct scene *s);

/* The registry (src/scenes/registry.c). */
/* Hands the case reader each scene's name, title, section of keys, check
 * and stretched_grid (config/case_registry.h), in registry order: the
 * values of case.scene.  run_init (app/run.h) calls it. */
void scenes_register(void);
int scene_count(void);
const struct scene *scene_at(int index);
/* Index of the scene called name, or -1. */
int scene_find(const char *name);
/* The case's scene (case.scene; the default, none, out of range). */
const struct scene *case_scene(const struct muflow_case *c);
/* Every name of an output file that a scene or a physics module of muflow
 * writes besides the run's own (summary.ini, ...): each scene's files, its
 * modules' files, those of scene_case_modules and of extra (a program's
 * own modules, NULL-terminated, or NULL); each once, NULL-terminated, into
 * names (room for max).  Returns their count, or -1 when max is too small.
 * A fresh run removes them all from its folder (io/output.h). */
#define SCENE_OUTPUT_FILES_MAX 64
int scene_output_files(const char **names, int max, const struct module *const *extra);

/* What the layers below take of the case's scene, looked up once here and
 * handed to them (src/scenes/scene_parts.c). */

/* The physics modules a case's own keys add to any scene's (the obstacle,
 * [obstacle] shapes), NULL-terminated. */
extern const struct module *const scene_case_modules[];
/* Those of scene_case_modules the case switches on (obstacle.shapes,
 * rheology.law = ngf): a NULL-terminated list, or NULL. */
const struct module *const *scene_case_module_list(const struct muflow_case *cs);
/* The march's setup for the case (march/march.h): the scene's modules, the
 * extra ones (NULL-terminated, or NULL), the case's own when it has a body;
 * the scene's setup and cross_section_flow. */
void scene_march_setup(const struct muflow_case *cs, const struct module *const *extra,
                       struct march_setup *su);
/* march_create with that setup. */
int scene_march_create(struct march_state *st, const struct muflow_case *cs,
                       const struct module *const *extra, char *err, size_t errlen);
/* The scene's profile: its axis, component, slab and exact or reference
 * profile (diagnostics/profile.h). */
void scene_profile_spec(const struct scene *sc, struct profile_spec *spec);
/* The profile of the case's scene.  Returns 0, or -1 when the scene has no
 * profile or memory runs out. */
int scene_profile(struct profile *pr, const struct march_state *st);
/* The errors and headline of the case's scene (its errors hook, or
 * profile_errors_default against the exact profile at the centre). */
void scene_profile_errors(const struct profile *pr, const struct march_state *st,
                          struct scene_errors *e);
/* The scene's exact profile at one coordinate (NaN without one). */
double scene_exact_at(const struct muflow_case *cs, double x);
/* Only the errors (for the history), without keeping a profile. */
void scene_errors_of(const struct march_state *st, struct scene_errors *e);
/* The names of the scene's comparison lines in [result] (io/output.h). */
void scene_result_names(const struct scene *sc, struct result_names *names);

#endif
