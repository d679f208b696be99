/* Exact solutions of the depth-averaged layer (diagnostics/depth_averaged.h),
 * chi = 1, on a uniform slope zeta:
 *
 * - the steady travelling front of Pouliquen (1999), "On the shape of
 *   granular fronts down rough inclined planes", with the friction law of
 *   Pouliquen & Forterre (2002) as Gray & Edwards (2014) write it: behind a
 *   front moving at the uniform flow's speed u_f the velocity is u_f
 *   throughout, and K h_x = tan(zeta) - mu_b(h, u_f), integrated in closed
 *   form;
 * - the dam break with Coulomb friction of Mangeney, Heinrich & Roche (2000),
 *   "Analytical solution for testing debris avalanche numerical models": the
 *   shallow-water rarefaction in the frame of the constant acceleration
 *   g (sin zeta - mu cos zeta) > 0. */
#ifndef MUFLOW_DIAGNOSTICS_DEPTH_AVERAGED_EXACT_H
#define MUFLOW_DIAGNOSTICS_DEPTH_AVERAGED_EXACT_H

struct da_front {
    double K;     /* earth-pressure coefficient */
    double a, b;  /* tan zeta - mu1 > 0, mu2 - tan zeta > 0 */
    double hstar; /* mu_b(h, u_f) = mu1 + (mu2 - mu1) / (1 + (h / hstar)^{3/2}) */
    double r;     /* sqrt(h_inf / hstar) = (b / a)^{1/3} */
    double h_inf; /* the uniform depth far behind the front */
    double u_f;   /* the front's (and the layer's) speed */
};

/* The front of uniform depth h_inf behind it, for the Pouliquen law of
 * (mu1, mu2, beta, L) on a slope zeta, gravity g.  Returns 0, or -1 unless
 * mu1 < tan zeta < mu2 and h_inf > 0. */
int da_front_setup(struct da_front *f, double g, double zeta, double K, double mu1, double mu2,
                   double beta, double L, double h_inf);

/* The position, relative to the tip, where the depth is h (0 < h < h_inf):
 * negative, -> -infinity as h -> h_inf. */
double da_front_position(const struct da_front *f, double h);

/* The depth at xi = x - x_tip: 0 for xi >= 0 (bisection of the position,
 * to round-off). */
double da_front_depth(const struct da_front *f, double xi);

/* The dam break: depth h0 for x < 0 at t = 0, dry beyond, at rest; (h, u) at
 * (x, t).  Valid while the acceleration g (sin zeta - mu cos zeta) is
 * positive (the whole mass slides); g' = K g cos zeta. */
void da_dambreak_exact(double g, double K, double zeta, double mu, double h0, double x, double t,
                       double *h, double *u);

/* The dam break's tail (upslope end of the rarefaction) and front at t. */
void da_dambreak_edges(double g, double K, double zeta, double mu, double h0, double t,
                       double *x_tail, double *x_front);

#endif
