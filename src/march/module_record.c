/* A module's record in the checkpoint, over the store the checkpoint gives
 * (module_record.h). */
#include "march/module_record.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

int module_record_fail(struct module_record *r, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(r->err, sizeof r->err, fmt, ap);
    va_end(ap);
    return -1;
}

int module_record_put(struct module_record *r, const char *name, const double *v, long n)
{
    return r->store->put(r->ctx, name, v, n, r->err, sizeof r->err);
}

long module_record_count(struct module_record *r, const char *name)
{
    return r->store->count(r->ctx, name, r->err, sizeof r->err);
}

int module_record_get(struct module_record *r, const char *name, double *v, long n)
{
    return r->store->get(r->ctx, name, v, n, r->err, sizeof r->err);
}

/* A field in the layout with every ghost (as the checkpoint stores fields). */
int module_record_put_field(struct module_record *r, const char *name, const struct grid *g,
                            const double *f)
{
    if (g->size == g->padded)
        return module_record_put(r, name, f, (long)g->size);
    double *full = malloc(g->padded * sizeof *full);
    if (!full)
        return module_record_fail(r, "%s: out of memory", name);
    field_to_full(g, f, full);
    int rc = module_record_put(r, name, full, (long)g->padded);
    free(full);
    return rc;
}

int module_record_get_field(struct module_record *r, const char *name, const struct grid *g,
                            double *f)
{
    if (g->size == g->padded)
        return module_record_get(r, name, f, (long)g->size);
    double *full = malloc(g->padded * sizeof *full);
    if (!full)
        return module_record_fail(r, "%s: out of memory", name);
    int rc = module_record_get(r, name, full, (long)g->padded);
    if (rc == 0)
        field_from_full(g, full, f);
    free(full);
    return rc;
}
