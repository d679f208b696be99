/* Reading and interpolating reference curves (reference.h). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "diagnostics/reference.h"

void curve_free(struct curve *c)
{
    free(c->x);
    free(c->y);
    memset(c, 0, sizeof *c);
}

static int by_x(const void *a, const void *b)
{
    const double *p = a, *q = b;
    return (p[0] > q[0]) - (p[0] < q[0]);
}

int reference_curve(const char *path, const char *dataset, double param, struct curve *c,
                    char *err, size_t errlen)
{
    memset(c, 0, sizeof *c);
    FILE *f = fopen(path, "r");
    if (!f) {
        snprintf(err, errlen, "reference %s: %s", path, strerror(errno));
        return -1;
    }
    char line[512];
    int cap = 0;
    double *xy = NULL;
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '#' || strncmp(line, dataset, strlen(dataset)) != 0 ||
            line[strlen(dataset)] != ',')
            continue;
        double p, x, y;
        if (sscanf(line + strlen(dataset) + 1, "%lf,%lf,%lf", &p, &x, &y) != 3)
            continue;
        if (!isnan(param) && fabs(p - param) > 1e-6 * fmax(1.0, fabs(param)))
            continue;
        if (c->n == cap) {
            cap = cap ? 2 * cap : 64;
            double *t = realloc(xy, (size_t)cap * 2 * sizeof(double));
            if (!t) {
                free(xy);
                fclose(f);
                snprintf(err, errlen, "reference %s: out of memory", path);
                return -1;
            }
            xy = t;
        }
        xy[2 * c->n] = isnan(param) ? p : x;
        xy[2 * c->n + 1] = y;
        c->n++;
    }
    fclose(f);
    if (c->n == 0) {
        free(xy);
        return 0;
    }
    qsort(xy, (size_t)c->n, 2 * sizeof(double), by_x);
    c->x = malloc((size_t)c->n * sizeof(double));
    c->y = malloc((size_t)c->n * sizeof(double));
    if (!c->x || !c->y) {
        free(xy);
        curve_free(c);
        snprintf(err, errlen, "reference %s: out of memory", path);
        return -1;
    }
    for (int i = 0; i < c->n; i++) {
        c->x[i] = xy[2 * i];
        c->y[i] = xy[2 * i + 1];
    }
    free(xy);
    return 0;
}

double curve_at(const struct curve *c, double x)
{
    if (c->n == 0)
        return NAN;
    if (c->n == 1)
        return c->y[0];
    int i = 1;
    while (i < c->n - 1 && c->x[i] < x)
        i++;
    double t = (x - c->x[i - 1]) / (c->x[i] - c->x[i - 1]);
    return c->y[i - 1] + t * (c->y[i] - c->y[i - 1]);
}
