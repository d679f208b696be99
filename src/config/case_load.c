/* Loading a case (case.h): two passes over the events of the INI engine
 * (ini.h), the file then the overrides in order.  The first finds the scene
 * (the last valid case.scene), whose own section is then known; the second
 * applies every event in order and stops at the first error, so that the
 * message names the first bad line or override.  Then the checks that need
 * every key (case_checks.c).  Unknown names get a suggestion of the nearest
 * known one; a key or section given twice in the file is warned about. */
#define _XOPEN_SOURCE 700 /* realpath */
#include "config/case.h"

#include <errno.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "case_internal.h"
#include "config/ini.h"
#include "config/keys.h"

/* The core sections, for the duplicate warnings and near misses. */
static const char *const sections[] = {"case", "domain", "boundary", "obstacle", "physics",
                                       "rheology", "solver", "output"};
_Static_assert(sizeof sections / sizeof sections[0] == CORE_SECTIONS, "CORE_SECTIONS");

/* ------------------------------------------------------------------------ */
/* Names: known ones, near misses */

static int known_section(const struct muflow_case *c, const char *s)
{
    for (int i = 0; i < CORE_SECTIONS; i++)
        if (strcmp(s, sections[i]) == 0)
            return 1;
    const struct key_block *kb = case_scene_keys(c);
    return kb && strcmp(s, kb->section) == 0;
}

struct nearest {
    const char *full;
    int best;
    const struct key *hit;
};

static int nearer(void *vctx, const struct key *k)
{
    struct nearest *n = vctx;
    char cand[96];
    snprintf(cand, sizeof(cand), "%s.%s", k->section, k->name);
    int dist = ini_edit_distance(n->full, cand);
    if (dist < n->best) {
        n->best = dist;
        n->hit = k;
    }
    return 0;
}

struct same_name {
    const char *name;
    const struct key *hit;
};

static int named(void *vctx, const struct key *k)
{
    struct same_name *n = vctx;
    if (strcmp(k->name, n->name) == 0) {
        n->hit = k;
        return 1;
    }
    return 0;
}

/* " (did you mean section.key?)" for a near miss of section.name, or "". */
static void suggest_key(const struct muflow_case *c, const char *section, const char *name,
                        char *out, size_t outlen)
{
    char full[160];
    out[0] = '\0';
    if (snprintf(full, sizeof(full), "%s.%s", section, name) >= (int)sizeof(full))
        return;
    struct nearest n = {full, INT_MAX, NULL};
    case_each_key(c, nearer, &n);
    const struct key *hit = n.hit;
    if (n.best > 2) { /* right key name, wrong (or no) section? */
        struct same_name s = {name, NULL};
        case_each_key(c, named, &s);
        hit = s.hit;
    }
    if (hit)
        snprintf(out, outlen, " (did you mean %s.%s?)", hit->section, hit->name);
}

/* Nearest known section within distance 2, or NULL. */
static const char *near_section(const struct muflow_case *c, const char *s)
{
    int best = 3;
    const char *hit = NULL;
    for (int i = 0; i < CORE_SECTIONS; i++) {
        int dist = ini_edit_distance(s, sections[i]);
        if (dist < best) {
            best = dist;
            hit = sections[i];
        }
    }
    const struct key_block *kb = case_scene_keys(c);
    if (kb && ini_edit_distance(s, kb->section) < best)
        hit = kb->section;
    return hit;
}

/* " (a section of case.scene = NAME)" when s is another scene's section. */
static void owner_hint(const char *s, char *out, size_t outlen)
{
    for (int i = 0; i < case_scene_count(); i++) {
        const struct key_block *kb = case_scene_info(i)->keys;
        if (kb && strcmp(kb->section, s) == 0) {
            snprintf(out, outlen, " (a section of case.scene = %s)",
                     case_scene_info(i)->name);
            return;
        }
    }
}

/* ------------------------------------------------------------------------ */
/* Messages */

/* One warning line (control characters replaced), when a callback is set. */
static void warn(struct case_ctx *x, const char *fmt, ...)
{
    if (!x->warn)
        return;
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    ini_format_line(msg, sizeof msg, fmt, ap);
    va_end(ap);
    x->warn(x->warn_ctx, msg);
}

/* ------------------------------------------------------------------------ */
/* The events: assignments, section headers */

/* One assignment section.name = value, from the file (arg == NULL) or from
 * the override arg.  Returns 1 on success. */
static int assign(struct case_ctx *x, const char *section, const char *name, const char *value,
                  const char *arg)
{
    char b1[SHOWN_MAX + 4], b2[SHOWN_MAX + 4], b3[SHOWN_MAX + 4], prefix[SHOWN_MAX + 40];
    char hint[160], msg[160];
    if (arg)
        snprintf(prefix, sizeof(prefix), "override %s", shown(arg, b1));
    else
        snprintf(prefix, sizeof(prefix), "%s", shown(x->where, b1));

    void *base;
    const struct key *k = case_find_key(x->c, section, name, &base);
    if (!k) {
        if (!known_section(x->c, section)) {
            if (!arg && section[0] == '\0') {
                suggest_key(x->c, section, name, hint, sizeof(hint));
                case_fail(x, "%s: key %s before any [section]%s", prefix, shown(name, b2), hint);
                return 0;
            }
            suggest_key(x->c, section, name, hint, sizeof(hint));
            if (!hint[0])
                owner_hint(section, hint, sizeof(hint));
            if (!hint[0]) {
                const char *near = near_section(x->c, section);
                if (near)
                    snprintf(hint, sizeof(hint), " (did you mean %s?)", near);
            }
            case_fail(x, "%s: unknown section %s%s", prefix, shown(section, b2), hint);
            return 0;
        }
        suggest_key(x->c, section, name, hint, sizeof(hint));
        case_fail(x, "%s: unknown key %s.%s%s", prefix, section, shown(name, b2), hint);
        return 0;
    }
    const char *why = key_parse(base, k, value, msg, sizeof(msg));
    if (why) {
        if (arg)
            case_fail(x, "%s: %s", prefix, why);
        else
            case_fail(x, "%s: %s.%s = %s: %s", prefix, section, name, shown(value, b3), why);
        return 0;
    }
    if (base == (void *)x->c)
        x->set[k - case_core_keys] = 1;
    int slot = case_key_slot(x->c, k);
    if (slot >= 0)
        x->origin[slot] = arg;
    return 1;
}

/* A key line of the file that was applied: warns when the same key was
 * given on an earlier line of the file (the later value is used).
 * Overrides replace file values by design and never warn. */
static void note_file_key(struct case_ctx *x, const struct ini_event *v)
{
    char b1[SHOWN_MAX + 4], b2[SHOWN_MAX + 4], b3[SHOWN_MAX + 4];
    const struct key *k = case_find_key(x->c, v->section, v->key, NULL);
    int slot = k ? case_key_slot(x->c, k) : -1;
    if (slot < 0)
        return;
    if (x->key_line[slot] > 0)
        warn(x, "%s: %s.%s given twice: line %d (%s) and line %d (%s); the later replaces the "
                "earlier",
             shown(x->where, b1), k->section, k->name, x->key_line[slot],
             shown(x->key_value[slot], b2), v->line, shown(v->value, b3));
    x->key_line[slot] = v->line;
    x->key_value[slot] = v->value;
}

/* A [section] header of the file that was accepted: warns when the section
 * was opened before (its keys are then read as one section). */
static void note_file_section(struct case_ctx *x, const struct ini_event *v)
{
    char b[SHOWN_MAX + 4];
    int slot = -1;
    for (int i = 0; i < CORE_SECTIONS; i++)
        if (strcmp(v->section, sections[i]) == 0)
            slot = i;
    const struct key_block *kb = case_scene_keys(x->c);
    if (slot < 0 && kb && strcmp(v->section, kb->section) == 0)
        slot = CORE_SECTIONS;
    if (slot < 0)
        return;
    if (x->section_line[slot] > 0)
        warn(x, "%s: section [%s] given twice: line %d and line %d (their keys are read as one "
                "section)",
             shown(x->where, b), v->section, x->section_line[slot], v->line);
    else
        x->section_line[slot] = v->line;
}

/* A [section] header of the file. */
static int header(struct case_ctx *x, const char *name)
{
    if (strlen(name) <= SHOWN_MAX && known_section(x->c, name))
        return 1;
    char b[SHOWN_MAX + 4], b2[SHOWN_MAX + 4], hint[96] = "";
    if (strlen(name) <= SHOWN_MAX) {
        owner_hint(name, hint, sizeof(hint));
        const char *near = hint[0] ? NULL : near_section(x->c, name);
        if (near)
            snprintf(hint, sizeof(hint), " (did you mean [%s]?)", near);
    }
    case_fail(x, "%s: unknown section [%s]%s", shown(x->where, b), shown(name, b2), hint);
    return 0;
}

/* ------------------------------------------------------------------------ */
/* Loading */

/* c->name: base name of path without directory and a trailing ".ini". */
static int set_name(struct case_ctx *x, const char *path)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    size_t len = strlen(base);
    if (len > 4 && strcmp(base + len - 4, ".ini") == 0)
        len -= 4;
    if (len >= sizeof(x->c->name)) {
        char b[SHOWN_MAX + 4];
        case_fail(x, "%s: case name longer than %zu characters", shown(path, b),
             sizeof(x->c->name) - 1);
        return 0;
    }
    memcpy(x->c->name, base, len);
    x->c->name[len] = '\0';
    return 1;
}

/* case.reference relative to the case file's folder, made absolute so that a
 * summary or checkpoint that repeats the key finds the same file. */
static void resolve_reference(struct case_ctx *x, const char *path)
{
    struct muflow_case *c = x->c;
    char joined[2 * sizeof(c->reference)], real[PATH_MAX], b[SHOWN_MAX + 4], b2[SHOWN_MAX + 4];
    const char *slash = path ? strrchr(path, '/') : NULL;
    if (c->reference[0] != '/' && slash)
        snprintf(joined, sizeof joined, "%.*s/%s", (int)(slash - path), path, c->reference);
    else
        snprintf(joined, sizeof joined, "%s", c->reference);
    if (!realpath(joined, real)) {
        case_refuse(x, "case.reference = %s: %s", shown(joined, b2), strerror(errno));
        return;
    }
    if (strlen(real) >= sizeof(c->reference)) {
        case_refuse(x, "case.reference = %s: the path is longer than %zu characters", shown(joined, b),
               sizeof(c->reference) - 1);
        return;
    }
    memcpy(c->reference, real, strlen(real) + 1); /* fits: checked above */
}

/* The scene the events choose: the last case.scene whose value names one. */
static int scene_of(const struct ini_events *ev)
{
    int scene = 0;
    for (int i = 0; i < ev->count; i++) {
        const struct ini_event *v = &ev->ev[i];
        if (v->kind == INI_ERROR)
            break;
        if (v->kind != INI_KEY || strcmp(v->section, "case") != 0 || strcmp(v->key, "scene") != 0)
            continue;
        for (const struct choice *ch = case_scene_choices; ch->name; ch++)
            if (ini_equal_nocase(v->value, ch->name))
                scene = ch->value;
    }
    return scene;
}

int case_load(struct muflow_case *c, const char *path, int noverrides,
              char *const overrides[], char *err, size_t errlen)
{
    return case_load_warn(c, path, noverrides, overrides, NULL, NULL, err, errlen);
}

int case_load_warn(struct muflow_case *c, const char *path, int noverrides,
                   char *const overrides[], case_warn_fn warn_fn, void *warn_ctx, char *err,
                   size_t errlen)
{
    struct muflow_case work;
    struct case_ctx x;
    memset(&x, 0, sizeof(x));
    case_defaults(c);
    case_defaults(&work);
    x.c = &work;
    x.where = path ? path : "case";
    x.err = err;
    x.errlen = errlen;
    x.warn = warn_fn;
    x.warn_ctx = warn_ctx;
    if (err && errlen)
        err[0] = '\0';
    char b[SHOWN_MAX + 4];
    /* without the scenes, case.scene has no values and the checks of the
     * layers above would be skipped: refused, not read half-checked */
    if (case_scene_count() == 0) {
        case_fail(&x, "%s: no scenes are registered: a program calls run_init() (app/run.h) "
                      "before loading a case",
                  shown(x.where, b));
        return 2;
    }

    struct ini_events ev = {0};
    int oom = 0;
    if (path && set_name(&x, path))
        oom = ini_read_file(&ev, path, x.where, err, errlen) != 0;
    /* overrides up to a missing one (NULL), reported after the events before it */
    for (int i = 0; i < noverrides && !oom && overrides && overrides[i]; i++)
        oom = ini_add_override(&ev, overrides[i]) != 0;
    if (oom && !x.failed)
        case_fail(&x, "%s: out of memory", shown(x.where, b));
    int scene = scene_of(&ev);
    case_set_scene(&work, scene);
    for (int i = 0; i < ev.count; i++)
        x.keys_given += ev.ev[i].kind == INI_KEY;
    for (int i = 0; i < ev.count && !x.failed; i++) {
        const struct ini_event *v = &ev.ev[i];
        if (v->kind == INI_ERROR) {
            case_fail(&x, "%s", v->message);
        } else if (v->kind == INI_SECTION) {
            if (header(&x, v->section))
                note_file_section(&x, v);
        } else {
            if (assign(&x, v->section, v->key, v->value, v->arg) && !v->arg)
                note_file_key(&x, v);
            /* an earlier case.scene does not undo the scene of the first
             * pass: the last one is the case's, and its block is set up */
            work.scene = scene;
        }
    }
    for (int i = 0; i < noverrides && !x.failed; i++)
        if (!overrides || !overrides[i])
            case_fail(&x, "override %d: missing", i + 1);
    ini_events_free(&ev);
    if (!x.failed)
        case_check_all(&x);
    if (!x.failed && work.reference[0])
        resolve_reference(&x, path);
    if (x.failed)
        return 2;
    *c = work;
    return 0;
}
