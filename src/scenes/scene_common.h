/* Small pieces shared by the scene files (internal to src/scenes/). */
#ifndef MUFLOW_SCENES_COMMON_H
#define MUFLOW_SCENES_COMMON_H

#include <math.h>
#include "config/case.h"
#include "march/march.h"

/* sqrt(p / rho_s) / d per unit sqrt(p): the shear rate at I = 1 is
 * sqrt(p) * this. */
static inline double shear_per_sqrt_p(const struct rheology *r)
{
    return 1.0 / (r->grain_diameter * sqrt(r->grain_density));
}

/* A length the grid must resolve: at least one cell of size h (to the
 * round-off of h = l / n, so that the bound a message prints is accepted). */
static inline int scene_at_least_a_cell(double length, double h)
{
    return length >= h * (1.0 - 1e-9);
}

/* A layer from the base to height inside a box of height lz: it and the
 * layer above it each at least a cell of size h. */
static inline int scene_layer_fits(double height, double lz, double h)
{
    return scene_at_least_a_cell(height, h) && scene_at_least_a_cell(lz - height, h);
}

/* u[i] = f(cs, x[i]) for a pointwise exact profile. */
#define POINTWISE_PROFILE(name, f)                                                       \
    static void name(const struct muflow_case *cs, int n, const double *x, double *u)   \
    {                                                                                    \
        for (int i = 0; i < n; i++)                                                      \
            u[i] = f(cs, x[i]);                                                          \
    }

/* The exact profile of a scene whose velocity has no closed form: NaN (its
 * results name what is checked instead). */
static inline void scene_no_exact_profile(const struct muflow_case *cs, int n, const double *x,
                                          double *u)
{
    (void)cs;
    (void)x;
    for (int i = 0; i < n; i++)
        u[i] = NAN;
}

/* A scene that runs decomposed whatever its keys (scene.h: decomposed):
 * a layered flow whose lines and profile stay whole on a rank. */
static inline int scene_decomposed_always(const struct muflow_case *cs)
{
    (void)cs;
    return 1;
}

/* The global index of this rank's first cell along d (0: one process
 * holds the grid). */
static inline int scene_block_lo(const struct march_state *st, int d)
{
    return st->ranks ? st->ranks->dc.lo[d] : 0;
}

/* A scene's [SECTION] keys over its parameter struct TYPE: the key block
 * NAME (parse, check, write back: config/keys.h) with INTRO, the section's
 * description in docs/case_keys.md (Markdown), the compile-time check that
 * TYPE fits the case's scene block, and params(cs), the block of a loaded
 * case. */
#define SCENE_PARAMS(NAME, SECTION, INTRO, TYPE, KEYS, DEFAULTS)                         \
    static const struct key_block NAME = {                                              \
        .section = SECTION,                                                              \
        .intro = INTRO,                                                                  \
        .keys = KEYS,                                                                    \
        .nkeys = (int)(sizeof KEYS / sizeof KEYS[0]),                                    \
        .size = sizeof(TYPE),                                                            \
        .defaults = DEFAULTS,                                                            \
    };                                                                                   \
    _Static_assert(sizeof(TYPE) <= sizeof(((struct muflow_case *)0)->scene_params),      \
                   SECTION " parameters fit the case's scene block");                   \
    static const TYPE *params(const struct muflow_case *cs) { return case_scene_params(cs); }

#endif
