/* The lines a scene or a physics module adds to a run's result (the
 * [result] section of summary.ini: io/output.h, run_result), in order. */
#ifndef MUFLOW_MARCH_RESULTS_H
#define MUFLOW_MARCH_RESULTS_H

#include <stdarg.h>

struct result_value {
    char key[40];
    char text[88];
};
#define RESULT_VALUES_MAX 32

struct result_values {
    int n;
    struct result_value v[RESULT_VALUES_MAX];
};

/* Adds the line key = printf(fmt, ...) (dropped beyond RESULT_VALUES_MAX). */
void result_values_add(struct result_values *r, const char *key, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
void result_values_vadd(struct result_values *r, const char *key, const char *fmt, va_list ap)
    __attribute__((format(printf, 3, 0)));

#endif
