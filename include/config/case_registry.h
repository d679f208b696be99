/* What the case reader needs from the layers above it, handed over at
 * start-up (run_init, app/run.h) because config sits below them all and
 * includes none of them:
 *   - the scenes: their names are the values of case.scene, their own
 *     sections and checks are part of a case (scenes_register, scene.h);
 *   - the checks that need a solver, the friction curve or the march, which
 *     a case must pass when it is loaded, before a run allocates anything.
 * case_load refuses every case until the scenes are registered. */
#ifndef MUFLOW_CONFIG_CASE_REGISTRY_H
#define MUFLOW_CONFIG_CASE_REGISTRY_H

#include <stddef.h>
#include "config/rheology_params.h"

struct key_block;
struct muflow_case;

/* What the case reader knows of one scene. */
struct case_scene_info {
    const char *name;              /* its value of case.scene */
    const char *title;             /* one line, for --list and docs/case_keys.md */
    const struct key_block *keys;  /* its own section, or NULL */
    /* what it needs of the core keys: 0, or non-zero with one line in msg */
    int (*check)(const struct muflow_case *cs, char *msg, size_t msglen);
    int stretched_grid;            /* 1: a domain.<d>_band is allowed */
};

#define CASE_SCENES_MAX 32

/* The scenes, in registry order (the first, "none", is the default): copied,
 * their indices the values of muflow_case.scene.  Returns 0, or -1 (nothing
 * changed) when there are more than CASE_SCENES_MAX. */
int case_register_scenes(const struct case_scene_info *scenes, int count);

/* The checks of the layers above, each called once per load in the order of
 * the case's own checks (case_checks.c); a NULL member is skipped.  Each
 * returns 0, or 1 with one line in msg, which the reader prefixes with what
 * set the keys it names. */
struct case_checks {
    /* the preconditioner solver.preconditioner names against the case (the
     * solvers' limits, the coupled step's), after the coupled step's own keys */
    int (*preconditioner)(const struct muflow_case *cs, char *msg, size_t msglen);
    /* the friction curve's derived values (I_1^N, A_minus) from the final
     * keys, into r, with rheology.law = mui */
    int (*rheology_curve)(struct rheology *r, char *msg, size_t msglen);
    /* the memory the run needs against the machine's, from the case alone,
     * after every check of the keys and before the body's geometry */
    int (*memory)(const struct muflow_case *cs, char *msg, size_t msglen);
};

/* Keeps a copy of checks. */
void case_register_checks(const struct case_checks *checks);

#endif
