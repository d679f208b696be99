/* The scenes the layers above register (case_registry.h), the case's
 * scene and its parameter block (which lives inside the case, so that a
 * case can be copied). */
#include <stdio.h>
#include <string.h>
#include "case_internal.h"
#include "config/case.h"
#include "config/case_registry.h"
#include "config/keys.h"

/* ------------------------------------------------------------------------ */
/* What the layers above registered: copies, so that theirs may be locals */

static struct case_scene_info scenes[CASE_SCENES_MAX];
static int nscenes;
/* case.scene's values: the scenes' names and indices, {NULL, 0} after them */
struct choice case_scene_choices[CASE_SCENES_MAX + 1];
static struct case_checks checks;

int case_register_scenes(const struct case_scene_info *list, int count)
{
    if (count < 0 || count > CASE_SCENES_MAX)
        return -1;
    for (int i = 0; i < count; i++) {
        scenes[i] = list[i];
        case_scene_choices[i] = (struct choice){list[i].name, i};
    }
    case_scene_choices[count] = (struct choice){NULL, 0};
    nscenes = count;
    return 0;
}

void case_register_checks(const struct case_checks *above) { checks = *above; }

int case_scene_count(void) { return nscenes; }

const struct case_scene_info *case_scene_info(int index)
{
    return index >= 0 && index < nscenes ? &scenes[index] : NULL;
}

const struct case_checks *case_registered_checks(void) { return &checks; }

/* ------------------------------------------------------------------------ */
/* The scene and its parameter block */

const struct case_scene_info *case_scene_of(const struct muflow_case *c)
{
    const struct case_scene_info *s = case_scene_info(c->scene);
    return s ? s : case_scene_info(0);
}

const void *case_scene_params(const struct muflow_case *c)
{
    return c->scene_params.bytes;
}

void *case_scene_params_mut(struct muflow_case *c)
{
    return c->scene_params.bytes;
}

void case_set_scene(struct muflow_case *c, int scene)
{
    c->scene = scene;
    memset(&c->scene_params, 0, sizeof c->scene_params);
    const struct key_block *kb = case_scene_keys(c);
    if (kb && kb->defaults)
        kb->defaults(c->scene_params.bytes);
}

const struct key_block *case_scene_keys(const struct muflow_case *c)
{
    const struct case_scene_info *s = case_scene_of(c);
    return s ? s->keys : NULL;
}
