/* The growth rate of a perturbation from its measured amplitude A(t): the
 * least-squares slope of ln A against t over a window of the record
 * (docs/validation/bagnold2.md, "Ill-posedness of mu(I) as a measured growth
 * rate"). */
#ifndef MUFLOW_DIAGNOSTICS_GROWTH_H
#define MUFLOW_DIAGNOSTICS_GROWTH_H

struct growth_fit {
    double rate;      /* d ln A / dt over the window (1/time); NaN with < 3 points */
    double intercept; /* ln A at t = 0 of the fitted line */
    double r2;        /* coefficient of determination of the fit (1: exponential) */
    double t0, t1;    /* the window: first and last sample taken */
    long n;           /* samples taken */
};

/* The fit over the samples with t0 <= t[m] <= t1 and a[m] > 0 (n samples of
 * the record, in time order). */
struct growth_fit growth_fit_window(const double *t, const double *a, long n, double t0,
                                    double t1);

#endif
