/* A run's result lines (results.h). */
#include "march/results.h"

#include <stdio.h>

void result_values_vadd(struct result_values *r, const char *key, const char *fmt, va_list ap)
{
    if (r->n >= RESULT_VALUES_MAX)
        return;
    struct result_value *v = &r->v[r->n++];
    snprintf(v->key, sizeof v->key, "%s", key);
    vsnprintf(v->text, sizeof v->text, fmt, ap);
}

void result_values_add(struct result_values *r, const char *key, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    result_values_vadd(r, key, fmt, ap);
    va_end(ap);
}
