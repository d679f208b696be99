/* The scenes the layers above register (case_registry.h), the case's
 * scene and its parameter block (which lives inside the case, so that a
 * case can be copied), and the keys of a case, the core table's and its
 * scene's section, found by name or visited in the order case_write_ini
 * writes them. */
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

/* ------------------------------------------------------------------------ */
/* The keys of the case: the core table's and its scene's section */

/* The key section.name and the struct it describes a member of. */
const struct key *case_find_key(const struct muflow_case *c, const char *section,
                                const char *name, void **base)
{
    for (int i = 0; i < case_core_nkeys; i++)
        if (strcmp(case_core_keys[i].section, section) == 0 &&
            strcmp(case_core_keys[i].name, name) == 0) {
            if (base)
                *base = (void *)c;
            return &case_core_keys[i];
        }
    const struct key_block *kb = case_scene_keys(c);
    if (kb && strcmp(kb->section, section) == 0)
        for (int i = 0; i < kb->nkeys; i++)
            if (strcmp(kb->keys[i].name, name) == 0) {
                if (base)
                    *base = (void *)c->scene_params.bytes;
                return &kb->keys[i];
            }
    return NULL;
}

/* Calls visit on every key the case has: the core keys in order, the
 * scene's section before [output]. */
int case_each_key(const struct muflow_case *c, int (*visit)(void *ctx, const struct key *k),
                  void *ctx)
{
    const struct key_block *kb = case_scene_keys(c);
    for (int i = 0; i < case_core_nkeys; i++) {
        if (kb && strcmp(case_core_keys[i].section, "output") == 0 &&
            (i == 0 || strcmp(case_core_keys[i - 1].section, "output") != 0))
            for (int j = 0; j < kb->nkeys; j++) {
                int rc = visit(ctx, &kb->keys[j]);
                if (rc)
                    return rc;
            }
        int rc = visit(ctx, &case_core_keys[i]);
        if (rc)
            return rc;
    }
    return 0;
}

const void *case_key_base(const struct muflow_case *c, const struct key *k)
{
    return (k >= case_core_keys && k < case_core_keys + case_core_nkeys)
               ? (const void *)c
               : (const void *)c->scene_params.bytes;
}

/* Slot of key k in the loading context's per-key tables. */
int case_key_slot(const struct muflow_case *c, const struct key *k)
{
    if (k >= case_core_keys && k < case_core_keys + case_core_nkeys)
        return (int)(k - case_core_keys);
    const struct key_block *kb = case_scene_keys(c);
    int j = kb ? (int)(k - kb->keys) : -1;
    return j >= 0 && j < SCENE_KEYS_MAX ? CORE_KEYS_MAX + j : -1;
}

