/* A case written back: every key with its value in the case file's own
 * format (summary.ini's case, so that a run documents what it used and
 * reads back to the same case), and muflow --list (every key with its
 * default, allowed values and meaning). */
#include <stdio.h>
#include <string.h>
#include "case_internal.h"
#include "config/case.h"
#include "config/keys.h"

/* ------------------------------------------------------------------------ */
/* The key list (muflow --list) */

void case_write_key_list(FILE *out)
{
    static struct muflow_case d; /* static: the case is large */
    case_defaults(&d);
    fprintf(out, "Scenes (case.scene):\n");
    for (int i = 0; i < case_scene_count(); i++)
        fprintf(out, "  %-16s %s\n", case_scene_info(i)->name, case_scene_info(i)->title);
    fprintf(out, "\nKeys: section.key = default  (allowed values)\n      meaning\n");
    const char *section = NULL;
    for (int i = 0; i < case_core_nkeys; i++) {
        if (strcmp(case_core_keys[i].section, "output") == 0 && strcmp(section, "output") != 0)
            for (int sc = 0; sc < case_scene_count(); sc++) { /* the scenes' own sections */
                const struct key_block *kb = case_scene_info(sc)->keys;
                if (!kb)
                    continue;
                static struct muflow_case ds;
                case_defaults(&ds);
                case_set_scene(&ds, sc);
                fprintf(out, "\n[%s]  (only with case.scene = %s)\n", kb->section,
                        case_scene_info(sc)->name);
                for (int j = 0; j < kb->nkeys; j++)
                    key_write_help(case_scene_params(&ds), &kb->keys[j], out);
            }
        if (!section || strcmp(section, case_core_keys[i].section) != 0) {
            section = case_core_keys[i].section;
            fprintf(out, "\n[%s]\n", section);
        }
        key_write_help(&d, &case_core_keys[i], out);
    }
}

/* ------------------------------------------------------------------------ */
/* Writing */

struct visit_ctx {
    const struct muflow_case *c;
    int (*visit)(void *ctx, const char *section, const char *key, const char *value);
    void *ctx;
};

static int visit_one(void *vctx, const struct key *k)
{
    struct visit_ctx *v = vctx;
    char val[sizeof(v->c->output_dir) + 8];
    key_text(case_key_base(v->c, k), k, val, sizeof(val));
    return v->visit(v->ctx, k->section, k->name, val);
}

int case_visit_keys(const struct muflow_case *c,
                    int (*visit)(void *ctx, const char *section, const char *key,
                                 const char *value),
                    void *ctx)
{
    struct visit_ctx v = {c, visit, ctx};
    return case_each_key(c, visit_one, &v);
}

struct write_ctx {
    FILE *out;
    const char *section;
};

static int write_one(void *vctx, const char *section, const char *key, const char *value)
{
    struct write_ctx *w = vctx;
    if (!w->section || strcmp(w->section, section) != 0) {
        fprintf(w->out, "%s[%s]\n", w->section ? "\n" : "", section);
        w->section = section;
    }
    if (value[0] == '\0') /* an unset string key (no reference): its default */
        fprintf(w->out, "; %s is not set\n", key);
    else
        fprintf(w->out, "%s = %s\n", key, value);
    return 0;
}

void case_write_ini(const struct muflow_case *c, FILE *out)
{
    char b[SHOWN_MAX + 4];
    fprintf(out, "; muflow case: %s\n", shown(c->name, b));
    struct write_ctx w = {out, NULL};
    case_visit_keys(c, write_one, &w);
}
