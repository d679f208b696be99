/* The scene registry: one line per scene (scenes/scene.h).  The first is the
 * default ("none").  A new scene is its own file under src/scenes/ that
 * defines `const struct scene scene_NAME`, plus its line here. */
#include <string.h>
#include "config/case.h"
#include "config/case_registry.h"
#include "config/keys.h"
#include "march/march.h"
#include "march/module.h"
#include "physics/ngf.h"
#include "physics/obstacle.h"
#include "scenes/scene.h"

#define SCENE_LIST(X)      \
    X(none)                \
    X(bagnold)             \
    X(chute)               \
    X(bingham_channel)     \
    X(bingham_cavity)      \
    X(heap)                \
    X(couette)             \
    X(bagnold2)            \
    X(bedload)             \
    X(collapse)            \
    X(duct)                \
    X(cylinder)            \
    X(slope_release)       \
    X(front)               \
    X(wall_shock)          \
    X(ngf_chute)           \
    X(ngf_shear)

#define DECLARE(s) extern const struct scene scene_##s;
SCENE_LIST(DECLARE)

#define ENTRY(s) &scene_##s,
static const struct scene *const registry[] = {SCENE_LIST(ENTRY)};
#define NSCENES ((int)(sizeof registry / sizeof registry[0]))

_Static_assert(NSCENES <= CASE_SCENES_MAX, "CASE_SCENES_MAX: room for every scene");

void scenes_register(void)
{
    struct case_scene_info info[NSCENES];
    for (int i = 0; i < NSCENES; i++)
        info[i] = (struct case_scene_info){registry[i]->name, registry[i]->title,
                                           registry[i]->keys, registry[i]->check,
                                           registry[i]->stretched_grid};
    case_register_scenes(info, NSCENES); /* cannot fail: NSCENES fits */
}

int scene_count(void) { return NSCENES; }

const struct scene *scene_at(int index)
{
    return index >= 0 && index < NSCENES ? registry[index] : NULL;
}

int scene_find(const char *name)
{
    for (int i = 0; i < NSCENES; i++)
        if (strcmp(registry[i]->name, name) == 0)
            return i;
    return -1;
}

const struct scene *case_scene(const struct muflow_case *c)
{
    const struct scene *s = scene_at(c->scene);
    return s ? s : registry[0];
}

const char *scene_solution_name(const struct scene *s)
{
    return s->solution_name ? s->solution_name : "exact";
}

const char *scene_error_name(const struct scene *s)
{
    return s->error_name ? s->error_name : "err_rms";
}

int scene_has_reference(const struct scene *s)
{
    return strcmp(scene_solution_name(s), "reference") == 0;
}

/* the case's obstacles and its rheology's fluidity are modules of every
 * scene; scene_case_module_list picks those the case switches on */
const struct module *const scene_case_modules[] = {&obstacle_module, &ngf_module, NULL};
static const struct module *const obstacle_only[] = {&obstacle_module, NULL};
static const struct module *const ngf_only[] = {&ngf_module, NULL};

const struct module *const *scene_case_module_list(const struct muflow_case *cs)
{
    int ngf = cs->rheo.law == LAW_NGF;
    if (case_obstacle_active(cs))
        return ngf ? scene_case_modules : obstacle_only;
    return ngf ? ngf_only : NULL;
}

/* Adds the names of list (NULL-terminated, or NULL) not yet in names. */
static int add_names(const char **names, int *n, int max, const char *const *list)
{
    for (const char *const *f = list; f && *f; f++) {
        int seen = 0;
        for (int i = 0; i < *n && !seen; i++)
            seen = strcmp(names[i], *f) == 0;
        if (seen)
            continue;
        if (*n + 1 >= max)
            return -1;
        names[(*n)++] = *f;
    }
    names[*n] = NULL;
    return 0;
}

int scene_output_files(const char **names, int max, const struct module *const *extra)
{
    int n = 0;
    if (max < 1)
        return -1;
    names[0] = NULL;
    const struct module *const *common[2] = {scene_case_modules, extra};
    for (int i = 0; i < NSCENES; i++) {
        if (add_names(names, &n, max, registry[i]->files) != 0)
            return -1;
        for (const struct module *const *m = registry[i]->modules; m && *m; m++)
            if (add_names(names, &n, max, (*m)->files) != 0)
                return -1;
    }
    for (int l = 0; l < 2; l++)
        for (const struct module *const *m = common[l]; m && *m; m++)
            if (add_names(names, &n, max, (*m)->files) != 0)
                return -1;
    return n;
}
