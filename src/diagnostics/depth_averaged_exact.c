/* Exact solutions of the depth-averaged layer (diagnostics/depth_averaged_exact.h). */
#include <math.h>
#include "diagnostics/depth_averaged_exact.h"

int da_front_setup(struct da_front *f, double g, double zeta, double K, double mu1, double mu2,
                   double beta, double L, double h_inf)
{
    double t = tan(zeta);
    if (!(t > mu1 && t < mu2 && h_inf > 0.0 && K > 0.0 && beta > 0.0 && L > 0.0 && g > 0.0))
        return -1;
    f->K = K;
    f->a = t - mu1;
    f->b = mu2 - t;
    f->h_inf = h_inf;
    f->r = cbrt(f->b / f->a);
    f->hstar = h_inf / (f->r * f->r);
    /* tan zeta = mu_b(h_inf, u_f): beta h / (L Fr) = b / a at h_inf */
    f->u_f = beta * h_inf * sqrt(g * cos(zeta) * h_inf) * f->a / (L * f->b);
    return 0;
}

/* x(s) up to a constant, s = sqrt(h / hstar): dx/dh = K (1 + s^3) / (a s^3 - b)
 * with dh = 2 hstar s ds, and s (1 + s^3) / (a s^3 - b) = s / a + ((a + b) / a^2)
 * s / (s^3 - r^3), whose primitive is in logarithms and an arctangent. */
static double front_primitive(const struct da_front *f, double s)
{
    double r = f->r, a = f->a, b = f->b;
    double q = log(r - s) - 0.5 * log(s * s + r * s + r * r) +
               sqrt(3.0) * atan((2.0 * s + r) / (r * sqrt(3.0)));
    return 2.0 * f->K * f->hstar * (0.5 * s * s / a + (a + b) / (a * a) * q / (3.0 * r));
}

double da_front_position(const struct da_front *f, double h)
{
    double s = sqrt(fmax(h, 0.0) / f->hstar);
    return front_primitive(f, s) - front_primitive(f, 0.0);
}

double da_front_depth(const struct da_front *f, double xi)
{
    if (xi >= 0.0)
        return 0.0;
    /* the position falls from 0 at s = 0 to -infinity at s = r */
    double lo = 0.0, hi = f->r, x0 = front_primitive(f, 0.0);
    for (int k = 0; k < 200; k++) {
        double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi)
            break;
        if (front_primitive(f, mid) - x0 > xi)
            lo = mid;
        else
            hi = mid;
    }
    double s = 0.5 * (lo + hi);
    return f->hstar * s * s;
}

void da_dambreak_edges(double g, double K, double zeta, double mu, double h0, double t,
                       double *x_tail, double *x_front)
{
    double c0 = sqrt(K * g * cos(zeta) * h0);
    double shift = 0.5 * g * (sin(zeta) - mu * cos(zeta)) * t * t;
    *x_tail = shift - c0 * t;
    *x_front = shift + 2.0 * c0 * t;
}

void da_dambreak_exact(double g, double K, double zeta, double mu, double h0, double x, double t,
                       double *h, double *u)
{
    double gp = K * g * cos(zeta), c0 = sqrt(gp * h0);
    double acc = g * (sin(zeta) - mu * cos(zeta));
    double xs = x - 0.5 * acc * t * t; /* in the accelerating frame */
    if (!(t > 0.0)) {
        *h = x < 0.0 ? h0 : 0.0;
        *u = 0.0;
    } else if (xs <= -c0 * t) {
        *h = h0;
        *u = acc * t;
    } else if (xs >= 2.0 * c0 * t) {
        *h = 0.0;
        *u = 0.0;
    } else {
        double w = 2.0 * c0 - xs / t;
        *h = w * w / (9.0 * gp);
        *u = (2.0 / 3.0) * (c0 + xs / t) + acc * t;
    }
}
