/* The keys of a case, the core table's and its scene's section, found by
 * name or visited in the order case_write_ini writes them
 * (case_internal.h). */
#include <string.h>
#include "case_internal.h"
#include "config/case.h"
#include "config/keys.h"

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

