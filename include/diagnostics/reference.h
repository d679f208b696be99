/* Published reference curves shipped with the cases (CSV files in cases/data):
 * rows "dataset,parameter,coord,value" with '#' comment lines. */
#ifndef MUFLOW_REFERENCE_H
#define MUFLOW_REFERENCE_H

#include <stddef.h>

struct curve {
    int n;
    double *x, *y; /* sorted by x */
};

/* The rows of `dataset` whose parameter is within a relative 1e-6 of param
 * (any parameter when param is NaN; then x is the parameter column).
 * Returns 0 (n may be 0), or -1 with the cause in err. */
int reference_curve(const char *path, const char *dataset, double param, struct curve *c,
                    char *err, size_t errlen);
void curve_free(struct curve *c);

/* Linear interpolation in x; linear extrapolation beyond the ends. */
double curve_at(const struct curve *c, double x);

#endif
