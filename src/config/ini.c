/* The INI engine: file and overrides to an ordered list of events (ini.h). */
#include "config/ini.h"

#include <errno.h>
#include <ini.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int lower(int ch)
{
    return (ch >= 'A' && ch <= 'Z') ? ch - 'A' + 'a' : ch;
}

int ini_equal_nocase(const char *a, const char *b)
{
    for (; *a && *b; a++, b++)
        if (lower((unsigned char)*a) != lower((unsigned char)*b))
            return 0;
    return *a == *b;
}

int ini_is_blank(int ch)
{
    return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\n' || ch == '\v' || ch == '\f';
}

const char *ini_shown(const char *s, char buf[INI_SHOWN_MAX + 4])
{
    size_t i = 0;
    for (; s[i] && i < INI_SHOWN_MAX; i++) {
        unsigned char ch = (unsigned char)s[i];
        buf[i] = (ch < 32 || ch == 127) ? '?' : (char)ch;
    }
    if (s[i]) {
        memcpy(buf + i, "...", 3);
        i += 3;
    }
    buf[i] = '\0';
    return buf;
}

int ini_edit_distance(const char *a, const char *b)
{
    enum { M = 64 };
    size_t la = strlen(a), lb = strlen(b);
    if (la >= M || lb >= M)
        return INT_MAX;
    int d[M + 1][M + 1];
    for (size_t i = 0; i <= la; i++)
        d[i][0] = (int)i;
    for (size_t j = 0; j <= lb; j++)
        d[0][j] = (int)j;
    for (size_t i = 1; i <= la; i++)
        for (size_t j = 1; j <= lb; j++) {
            int cost = a[i - 1] != b[j - 1];
            int v = d[i - 1][j] + 1;
            if (d[i][j - 1] + 1 < v)
                v = d[i][j - 1] + 1;
            if (d[i - 1][j - 1] + cost < v)
                v = d[i - 1][j - 1] + cost;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] &&
                d[i - 2][j - 2] + 1 < v)
                v = d[i - 2][j - 2] + 1;
            d[i][j] = v;
        }
    return d[la][lb];
}

/* ------------------------------------------------------------------------ */
/* The event list */

static char *dup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

static struct ini_event *push(struct ini_events *e)
{
    if (e->count == e->cap) {
        int cap = e->cap ? 2 * e->cap : 64;
        struct ini_event *ev = realloc(e->ev, (size_t)cap * sizeof *ev);
        if (!ev)
            return NULL;
        e->ev = ev;
        e->cap = cap;
    }
    struct ini_event *v = &e->ev[e->count++];
    memset(v, 0, sizeof *v);
    return v;
}

static void free_event(struct ini_event *v)
{
    free(v->section);
    free(v->key);
    free(v->value);
    free(v->message);
}

void ini_events_free(struct ini_events *e)
{
    for (int i = 0; i < e->count; i++)
        free_event(&e->ev[i]);
    free(e->ev);
    memset(e, 0, sizeof *e);
}

/* An INI_ERROR event with a formatted one-line message; 0 or -1 (memory). */
void ini_format_line(char *out, size_t len, const char *fmt, va_list ap)
{
    vsnprintf(out, len, fmt, ap);
    for (char *p = out; *p; p++)
        if ((unsigned char)*p < 32 || (unsigned char)*p == 127)
            *p = '?';
}

static int push_error(struct ini_events *e, int line, const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    ini_format_line(msg, sizeof msg, fmt, ap);
    va_end(ap);
    struct ini_event *v = push(e);
    if (!v)
        return -1;
    v->kind = INI_ERROR;
    v->line = line;
    return (v->message = dup(msg)) ? 0 : -1;
}

/* ------------------------------------------------------------------------ */
/* Reading a file */

struct reading {
    struct ini_events *out;
    const char *where;
    FILE *f;
    int line;          /* lines handed to inih so far */
    int stopped;       /* our reader found an error: no more lines */
    int io_errno;
    int oom;
};

static int handler(void *user, const char *section, const char *name, const char *value)
{
    struct reading *r = user;
    struct ini_event *v = push(r->out);
    if (!v) {
        r->oom = 1;
        return 0;
    }
    v->kind = INI_KEY;
    v->line = r->line;
    v->section = dup(section);
    v->key = dup(name);
    v->value = dup(value ? value : "");
    if (!v->section || !v->key || !v->value)
        r->oom = 1;
    return 1;
}

/* fgets-like reader for inih (see ini.h). */
static char *reader(char *buf, int num, void *stream)
{
    struct reading *r = stream;
    if (r->stopped || r->oom || num < 4)
        return NULL;
    size_t limit = (size_t)num - 3, len = 0;
    int ch, any = 0, too_long = 0, nul = 0;
    errno = 0;
    while ((ch = getc(r->f)) != EOF) {
        any = 1;
        if (ch == '\n')
            break;
        if (ch == '\0')
            nul = 1;
        if (len < limit)
            buf[len++] = (char)ch;
        else
            too_long = 1;
    }
    if (ch == EOF && ferror(r->f)) {
        r->io_errno = errno ? errno : EIO;
        return NULL;
    }
    if (!any)
        return NULL;
    buf[len] = '\0';
    r->line++;
    char b[INI_SHOWN_MAX + 4];
    if (too_long || nul) {
        if (too_long)
            r->oom |= push_error(r->out, r->line, "%s: line %d: longer than %zu characters",
                                 ini_shown(r->where, b), r->line, limit) != 0;
        else
            r->oom |= push_error(r->out, r->line, "%s: line %d: contains a NUL byte",
                                 ini_shown(r->where, b), r->line) != 0;
        r->stopped = 1;
        buf[0] = '\0';
        return buf;
    }
    size_t skip = 0;
    if (r->line == 1 && len >= 3 && memcmp(buf, "\xEF\xBB\xBF", 3) == 0)
        skip = 3;
    while (skip < len && ini_is_blank((unsigned char)buf[skip]))
        skip++;
    memmove(buf, buf + skip, len - skip + 1);
    if (buf[0] == '[') {
        char *end = strchr(buf, ']');
        if (end) { /* a header: an event of its own, checked by the key table */
            struct ini_event *v = push(r->out);
            if (!v || !(v->section = malloc((size_t)(end - buf)))) {
                r->oom = 1;
                return NULL;
            }
            v->kind = INI_SECTION;
            v->line = r->line;
            memcpy(v->section, buf + 1, (size_t)(end - buf - 1));
            v->section[end - buf - 1] = '\0';
        }
    }
    return buf;
}

/* Drops the events at or after line `from` (inih goes on after a syntax
 * error, which must end the file's events). */
static void truncate_from(struct ini_events *e, int first, int from)
{
    int keep = first;
    for (int i = first; i < e->count; i++) {
        if (e->ev[i].line < from)
            e->ev[keep++] = e->ev[i];
        else
            free_event(&e->ev[i]);
    }
    e->count = keep;
}

int ini_read_file(struct ini_events *out, const char *path, const char *where, char *err,
                  size_t errlen)
{
    char b[INI_SHOWN_MAX + 4];
    struct reading r = {.out = out, .where = where};
    int first = out->count, rc = 0;
    r.f = fopen(path, "r");
    if (!r.f) {
        rc = push_error(out, 0, "%s: cannot open: %s",
                        ini_shown(path[0] ? path : "(empty file name)", b), strerror(errno));
        goto done;
    }
    errno = 0;
    int ret = ini_parse_stream(reader, &r, handler, &r);
    fclose(r.f);
    if (r.oom) {
        rc = -1;
        goto done;
    }
    if (r.io_errno) {
        rc = push_error(out, 0, "%s: cannot read: %s", ini_shown(path, b), strerror(r.io_errno));
    } else if (ret > 0) {
        /* a syntax error: it is the file's end unless our own error came first */
        int ours = out->count > first && out->ev[out->count - 1].kind == INI_ERROR
                       ? out->ev[out->count - 1].line
                       : 0;
        if (!ours || ret < ours) {
            truncate_from(out, first, ret);
            rc = push_error(out, ret, "%s: line %d: syntax error (expected [section] or key = value)",
                            ini_shown(path, b), ret);
        }
    } else if (ret < 0) {
        rc = push_error(out, 0, "%s: cannot parse (inih error %d)", ini_shown(path, b), ret);
    }
done:
    if (rc != 0)
        snprintf(err, errlen, "%s: out of memory", ini_shown(where, b));
    return rc;
}

int ini_add_override(struct ini_events *out, const char *arg)
{
    char b[INI_SHOWN_MAX + 4];
    const char *eq = strchr(arg, '=');
    const char *dot = NULL;
    if (eq)
        for (const char *p = arg; p < eq; p++)
            if (*p == '.' && !dot)
                dot = p;
    if (!eq || !dot) {
        if (push_error(out, 0, "override %s: expected section.key=value", ini_shown(arg, b)) != 0)
            return -1;
        out->ev[out->count - 1].arg = arg;
        return 0;
    }
    char *copy = dup(arg);
    if (!copy)
        return -1;
    char *section = copy, *name = copy + (dot - arg) + 1, *value = copy + (eq - arg) + 1;
    copy[dot - arg] = '\0';
    copy[eq - arg] = '\0';
    char *parts[3] = {section, name, value};
    for (int i = 0; i < 3; i++) {
        char *s = parts[i];
        while (*s && ini_is_blank((unsigned char)*s))
            s++;
        char *e = s + strlen(s);
        while (e > s && ini_is_blank((unsigned char)e[-1]))
            *--e = '\0';
        parts[i] = s;
    }
    struct ini_event *v = push(out);
    int ok = v != NULL;
    if (ok) {
        v->kind = INI_KEY;
        v->arg = arg;
        ok = (v->section = dup(parts[0])) && (v->key = dup(parts[1])) &&
             (v->value = dup(parts[2]));
    }
    free(copy);
    return ok ? 0 : -1;
}
