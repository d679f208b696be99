/* The field registry (fields.h). */
#include <stdlib.h>
#include <string.h>
#include "march/fields.h"

void fields_init(struct field_registry *r, const struct grid *g)
{
    memset(r, 0, sizeof *r);
    r->g = g;
}

int fields_add(struct field_registry *r, const struct field_spec *s, double **v)
{
    if (r->count >= FIELDS_MAX)
        return -1;
    struct field_entry *e = &r->e[r->count];
    memset(e, 0, sizeof *e);
    e->spec = *s;
    int n = field_arrays(s->where), ok = 1;
    for (int c = 0; c < n; c++) {
        ok &= (e->v[c] = field_alloc(r->g)) != NULL;
        if (s->flags & FIELD_SAVED)
            ok &= (e->saved[c] = field_alloc(r->g)) != NULL;
    }
    r->count++; /* even when incomplete: fields_free releases what was allocated */
    if (!ok)
        return -1;
    for (int c = 0; c < n; c++)
        v[c] = e->v[c];
    return r->count - 1;
}

int fields_output(struct field_registry *r, const struct field_output *o)
{
    if (r->noutputs >= FIELDS_MAX || o->source < 0 || o->source >= r->count)
        return -1;
    r->out[r->noutputs++] = *o;
    return 0;
}

int fields_add_written(struct field_registry *r, const char *name, unsigned flags, double **v)
{
    const struct field_spec spec = {name, FIELD_CELLS, flags};
    int idx = fields_add(r, &spec, v);
    const struct field_output out = {name, {NULL}, idx, NULL, NULL};
    return idx < 0 ? -1 : fields_output(r, &out);
}

int fields_find(const struct field_registry *r, const char *name)
{
    for (int i = 0; i < r->count; i++)
        if (strcmp(r->e[i].spec.name, name) == 0)
            return i;
    return -1;
}

void fields_save(struct field_registry *r)
{
    for (int i = 0; i < r->count; i++)
        if (r->e[i].spec.flags & FIELD_SAVED)
            for (int c = 0; c < field_arrays(r->e[i].spec.where); c++)
                memcpy(r->e[i].saved[c], r->e[i].v[c], r->g->size * sizeof(double));
}

void fields_restore(struct field_registry *r)
{
    for (int i = 0; i < r->count; i++)
        if (r->e[i].spec.flags & FIELD_SAVED)
            for (int c = 0; c < field_arrays(r->e[i].spec.where); c++)
                memcpy(r->e[i].v[c], r->e[i].saved[c], r->g->size * sizeof(double));
}

void fields_blend(struct field_registry *r, double alpha)
{
    for (int i = 0; i < r->count; i++)
        if (r->e[i].spec.flags & FIELD_SAVED)
            for (int c = 0; c < field_arrays(r->e[i].spec.where); c++) {
                double *v = r->e[i].v[c];
                const double *s = r->e[i].saved[c];
                for (size_t p = 0; p < r->g->size; p++)
                    v[p] = s[p] + alpha * (v[p] - s[p]);
            }
}

int fields_snapshot_take(struct field_snapshot *s, const struct field_registry *r)
{
    size_t bytes = r->g->size * sizeof(double);
    int k = 0;
    for (int i = 0; i < r->count; i++) {
        if (!(r->e[i].spec.flags & FIELD_CHECKPOINT))
            continue;
        for (int c = 0; c < field_arrays(r->e[i].spec.where); c++, k++) {
            if (!s->a[k] && !(s->a[k] = malloc(bytes)))
                return -1;
            memcpy(s->a[k], r->e[i].v[c], bytes);
        }
    }
    s->n = k;
    return 0;
}

void fields_snapshot_put(const struct field_snapshot *s, const struct field_snapshot *older,
                         double w, struct field_registry *r)
{
    int k = 0;
    for (int i = 0; i < r->count; i++) {
        if (!(r->e[i].spec.flags & FIELD_CHECKPOINT))
            continue;
        for (int c = 0; c < field_arrays(r->e[i].spec.where); c++, k++) {
            double *v = r->e[i].v[c];
            if (older && w != 0.0)
                for (size_t p = 0; p < r->g->size; p++)
                    v[p] = s->a[k][p] + w * (s->a[k][p] - older->a[k][p]);
            else
                memcpy(v, s->a[k], r->g->size * sizeof(double));
        }
    }
}

void fields_snapshot_free(struct field_snapshot *s)
{
    for (int k = 0; k < 3 * FIELDS_MAX; k++)
        free(s->a[k]);
    memset(s, 0, sizeof *s);
}

void fields_free(struct field_registry *r)
{
    for (int i = 0; i < r->count; i++)
        for (int c = 0; c < 3; c++) {
            field_free(r->e[i].v[c]);
            field_free(r->e[i].saved[c]);
        }
    r->count = r->noutputs = 0;
}
