/* Whole files: written under a temporary name, renamed (output_file.h). */
#define _POSIX_C_SOURCE 200809L /* getline */
#include "platform/output_file.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int output_open(struct output_file *o, const char *dir, const char *name, char *err,
                size_t errlen)
{
    o->f = NULL;
    if (snprintf(o->path, sizeof o->path, "%s/%s", dir, name) >= (int)sizeof o->path ||
        snprintf(o->tmp, sizeof o->tmp, "%s/%s.tmp", dir, name) >= (int)sizeof o->tmp) {
        snprintf(err, errlen, "output path too long in %s", dir);
        return -1;
    }
    o->f = fopen(o->tmp, "w");
    if (!o->f) {
        snprintf(err, errlen, "cannot write %s: %s", o->tmp, strerror(errno));
        return -1;
    }
    return 0;
}

/* On any failure the temporary is removed. */
int output_commit(struct output_file *o, char *err, size_t errlen)
{
    FILE *f = o->f;
    o->f = NULL;
    int bad = ferror(f);
    if (fclose(f) != 0 || bad) {
        snprintf(err, errlen, "cannot write %s: %s", o->tmp, strerror(errno ? errno : EIO));
        remove(o->tmp);
        return -1;
    }
    if (rename(o->tmp, o->path) != 0) {
        snprintf(err, errlen, "cannot rename %s to %s: %s", o->tmp, o->path, strerror(errno));
        remove(o->tmp);
        return -1;
    }
    return 0;
}

FILE *output_previous(const char *dir, const char *name)
{
    char path[600], tmp[620];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *src = fopen(tmp, "r");
    if (src)
        remove(tmp); /* still read through src; output_open makes a new one */
    else
        src = fopen(path, "r");
    return src;
}

long output_copy_rows(FILE *src, FILE *dst, int (*keep)(long step, void *ctx), void *ctx)
{
    char *line = NULL;
    size_t cap = 0;
    int first = 1;
    long last = -1;
    while (getline(&line, &cap, src) > 0) {
        if (first) { /* the header, written by the caller */
            first = 0;
            continue;
        }
        char *end;
        long step = strtol(line, &end, 10);
        if (end != line && *end == ',' && keep(step, ctx)) {
            fputs(line, dst);
            last = step;
        }
    }
    free(line);
    return last;
}
