/* The messages of a load (case_internal.h): its first failure, and a
 * check's refusal, which names what set the keys it is about. */
#include <ctype.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include "case_internal.h"
#include "config/ini.h"
#include "config/keys.h"

void case_fail(struct case_ctx *x, const char *fmt, ...)
{
    if (x->failed)
        return;
    x->failed = 1;
    if (!x->err || x->errlen == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    ini_format_line(x->err, x->errlen, fmt, ap);
    va_end(ap);
}

/* 1 when text names the key section.name as a whole word ("domain.nx", not
 * "domain.nx_band" nor "xdomain.nx"). */
static int names_key(const char *text, const char *section, const char *name)
{
    char full[160];
    if (snprintf(full, sizeof full, "%s.%s", section, name) >= (int)sizeof full)
        return 0;
    size_t n = strlen(full);
    for (const char *p = strstr(text, full); p; p = strstr(p + 1, full)) {
        unsigned char before = p == text ? ' ' : (unsigned char)p[-1], after = (unsigned char)p[n];
        if (!(isalnum(before) || before == '_' || before == '.') &&
            !(isalnum(after) || after == '_'))
            return 1;
    }
    return 0;
}

struct blame {
    const struct case_ctx *x;
    const char *text;       /* the check's message */
    char *out;              /* "override a=1, override b=2" */
    size_t len, used;
};

static int blame_key(void *vctx, const struct key *k)
{
    struct blame *b = vctx;
    int slot = case_key_slot(b->x->c, k);
    const char *arg = slot >= 0 ? b->x->origin[slot] : NULL;
    if (!arg || !names_key(b->text, k->section, k->name) || b->used >= b->len)
        return 0;
    char sh[SHOWN_MAX + 4];
    b->used += (size_t)snprintf(b->out + b->used, b->len - b->used, "%soverride %s",
                                b->used ? ", " : "", shown(arg, sh));
    return 0;
}

/* A check of the loaded case failed: one line, the message after what set
 * the keys it names: the overrides among them ("override a=1, override
 * b=2: ..."), else the file (its keys or the defaults). */
void case_refuse(struct case_ctx *x, const char *fmt, ...)
{
    if (x->failed)
        return;
    char text[1024], who[1024], b[SHOWN_MAX + 4];
    va_list ap;
    va_start(ap, fmt);
    ini_format_line(text, sizeof text, fmt, ap);
    va_end(ap);
    struct blame bl = {x, text, who, sizeof who, 0};
    who[0] = '\0';
    case_each_key(x->c, blame_key, &bl);
    case_fail(x, "%s: %s", bl.used ? who : shown(x->where, b), text);
}
