/* The least-squares slope of ln A(t) (diagnostics/growth.h). */
#include <math.h>
#include "diagnostics/growth.h"

struct growth_fit growth_fit_window(const double *t, const double *a, long n, double t0,
                                    double t1)
{
    struct growth_fit f = {NAN, NAN, NAN, NAN, NAN, 0};
    /* centred sums: the times of a short window late in a run differ in
     * their last digits only */
    double st = 0.0, sy = 0.0;
    for (long m = 0; m < n; m++)
        if (t[m] >= t0 && t[m] <= t1 && a[m] > 0.0) {
            st += t[m];
            sy += log(a[m]);
            if (f.n == 0)
                f.t0 = t[m];
            f.t1 = t[m];
            f.n++;
        }
    if (f.n < 3)
        return f;
    double tm = st / f.n, ym = sy / f.n, stt = 0.0, sty = 0.0, syy = 0.0;
    for (long m = 0; m < n; m++)
        if (t[m] >= t0 && t[m] <= t1 && a[m] > 0.0) {
            double dt = t[m] - tm, dy = log(a[m]) - ym;
            stt += dt * dt;
            sty += dt * dy;
            syy += dy * dy;
        }
    if (!(stt > 0.0))
        return f;
    f.rate = sty / stt;
    f.intercept = ym - f.rate * tm;
    f.r2 = syy > 0.0 ? sty * sty / (stt * syy) : 1.0;
    return f;
}
