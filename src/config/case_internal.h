/* What the files of the case reader share (case.h is their public face):
 * the core key table and the defaults (case.c), the case's scene
 * (case_scenes.c), its keys with the scene's (case_keys.c), the loading
 * context (case_load.c) and its messages (case_messages.c), the checks that
 * need every key (case_checks.c) and writing back (case_write.c). */
#ifndef MUFLOW_CONFIG_CASE_INTERNAL_H
#define MUFLOW_CONFIG_CASE_INTERNAL_H

#include <stddef.h>
#include "config/case.h"
#include "config/case_registry.h"
#include "config/ini.h"
#include "config/keys.h"

#define SHOWN_MAX INI_SHOWN_MAX
#define shown ini_shown

/* The core key table (case.c), in the order case_write_ini writes it. */
#define CORE_KEYS_MAX 128   /* room in the loading context's per-key tables */
#define SCENE_KEYS_MAX 64   /* a scene's keys beyond this are not checked for duplicates */
#define CORE_SECTIONS 8     /* case domain boundary obstacle physics rheology solver output */
extern const struct key case_core_keys[];
extern const int case_core_nkeys;
/* Index of the core key section.name, or -1. */
int case_core_key_index(const char *section, const char *name);
/* The choices whose names the checks' messages repeat (value = index). */
extern const struct choice case_bc_choices[];
extern const struct choice case_plane_choices[];

/* What the layers above registered (case_scenes.c): the scenes, in order,
 * case.scene's choices (their names, {NULL, 0} after them), the checks. */
int case_scene_count(void);
const struct case_scene_info *case_scene_info(int index); /* NULL out of range */
/* The case's scene (the default when its index is out of range), or NULL
 * before any is registered. */
const struct case_scene_info *case_scene_of(const struct muflow_case *c);
extern struct choice case_scene_choices[CASE_SCENES_MAX + 1];
const struct case_checks *case_registered_checks(void);

/* The scene's section of keys (case_scenes.c). */
const struct key_block *case_scene_keys(const struct muflow_case *c);
/* The case's keys (case_keys.c): the core table, and the scene's section
 * before [output]. */
/* The key section.name and the struct it describes a member of (*base). */
const struct key *case_find_key(const struct muflow_case *c, const char *section,
                                const char *name, void **base);
/* Calls visit on every key until one returns non-zero (returned). */
int case_each_key(const struct muflow_case *c, int (*visit)(void *ctx, const struct key *k),
                  void *ctx);
/* The struct key k describes a member of: c or its scene's block. */
const void *case_key_base(const struct muflow_case *c, const struct key *k);
/* Slot of key k in the loading context's per-key tables, or -1. */
int case_key_slot(const struct muflow_case *c, const struct key *k);

/* One load (case_load.c): the case being built and what the messages need. */
struct case_ctx {
    struct muflow_case *c;
    const char *where;      /* file name for messages ("case" without file) */
    int failed;
    char *err;
    size_t errlen;
    unsigned char set[CORE_KEYS_MAX]; /* core key given explicitly */
    case_warn_fn warn;      /* warnings (duplicates in the file), or NULL */
    void *warn_ctx;
    int keys_given;         /* key lines of the file and overrides */
    /* the file's last line and value of each key (core, then the scene's),
     * and the first line of each section header, for the duplicate warnings */
    int key_line[CORE_KEYS_MAX + SCENE_KEYS_MAX];
    const char *key_value[CORE_KEYS_MAX + SCENE_KEYS_MAX];
    int section_line[CORE_SECTIONS + 1];
    /* the override that set each key last (its "section.key=value"), NULL
     * for the file's keys and the defaults: a check's message blames it */
    const char *origin[CORE_KEYS_MAX + SCENE_KEYS_MAX];
};

/* The messages (case_messages.c).  Records the first error only; the
 * message is one line. */
void case_fail(struct case_ctx *x, const char *fmt, ...);
/* A check of the loaded case failed: the message after what set the keys it
 * names (the overrides among them, else the file). */
void case_refuse(struct case_ctx *x, const char *fmt, ...);

/* The checks that need every key, after the file and all overrides
 * (case_checks.c). */
void case_check_all(struct case_ctx *x);

#endif
