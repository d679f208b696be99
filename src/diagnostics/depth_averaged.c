/* The depth-averaged granular layer along a slope (diagnostics/depth_averaged.h;
 * the scheme and its measurements: docs/numerics/depth-averaged.md). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "diagnostics/depth_averaged.h"

#define NG 2 /* ghost cells on each side: the edges of the first ghost need a slope */

struct da_solver {
    long n;
    double x0, dx;
    struct da_params p;
    struct da_bc bc[2];
    double *sin_z, *cos_z; /* n: the bed's slope at the centres */
    double *gf;            /* n + 1: K g cos(zeta) at the faces */
    double *hc, *uc;       /* n + 2 NG: the stage's h and u, ghosts included */
    double *hl, *ul;       /* n + 1: the state left of face f (cell f - 1's right edge) */
    double *hr, *ur;       /* n + 1: the state right of face f (cell f's left edge) */
    double *fh;            /* n + 1: mass flux */
    double *fm;            /* n + 1: momentum flux */
    double *fv;            /* n + 1: viscous flux nu h^{3/2} u_x */
    unsigned char *held;   /* n + 1: the face is between two cells held at rest */
    unsigned char *holds;  /* n: the cell is at rest and its friction holds it */
    double *h0, *m0;       /* n: the step's start */
    double *dh, *rm, *tf;  /* n: a stage's rates: h_t, m_t but for friction, friction's bound */
    double *rm0, *tf0;     /* n: the first stage's rm and tf */
};

struct da_params da_params_default(void)
{
    struct da_params p;
    memset(&p, 0, sizeof p);
    p.g = 1.0;
    p.K = 1.0;
    p.chi = 1.0;
    p.law = DA_COULOMB;
    p.flux = DA_FLUX_HLL;
    p.limiter = DA_LIMITER_MC;
    p.cfl = 0.45;
    p.h_dry = 1e-12;
    return p;
}

double da_basal_friction(const struct da_params *p, double cos_zeta, double h, double speed)
{
    if (p->law == DA_COULOMB)
        return p->mu;
    if (!(speed > 0.0))
        return p->mu1;
    /* mu1 + (mu2 - mu1) / (1 + beta h / (L Fr)), written so that Fr -> 0 is
     * mu1 and h -> 0 is mu2 without a division by zero */
    double stop = p->beta * h * sqrt(p->g * cos_zeta * fmax(h, 0.0)) / p->L;
    return p->mu1 + (p->mu2 - p->mu1) * speed / (speed + stop);
}

double da_gray_edwards_nu(const struct da_params *p, double zeta)
{
    double t = tan(zeta);
    if (!(t > p->mu1 && t < p->mu2))
        return NAN;
    return (2.0 / 9.0) * (p->L * sqrt(p->g) / p->beta) * (sin(zeta) / sqrt(cos(zeta))) *
           (p->mu2 - t) / (t - p->mu1);
}

static int param_error(char *err, int len, const char *what)
{
    if (err && len > 0)
        snprintf(err, (size_t)len, "depth-averaged model: %s", what);
    return -1;
}

static int check_params(long n, double dx, const double *zeta, const struct da_params *p,
                        const struct da_bc bc[2], char *err, int len)
{
    if (n < 2 || !(dx > 0.0) || !zeta)
        return param_error(err, len, "needs n >= 2 cells, dx > 0 and the slope of each");
    if (!(p->g > 0.0) || !(p->K > 0.0) || !(p->chi >= 1.0))
        return param_error(err, len, "needs g > 0, K > 0 and chi >= 1");
    if (!(p->cfl > 0.0 && p->cfl <= 0.5) || !(p->h_dry > 0.0) || !(p->nu >= 0.0))
        return param_error(err, len, "needs 0 < cfl <= 1/2, h_dry > 0 and nu >= 0");
    if (p->law == DA_COULOMB && !(p->mu >= 0.0))
        return param_error(err, len, "Coulomb friction needs mu >= 0");
    if (p->law == DA_POULIQUEN &&
        !(p->mu1 >= 0.0 && p->mu2 >= p->mu1 && p->beta > 0.0 && p->L > 0.0))
        return param_error(err, len, "Pouliquen's law needs 0 <= mu1 <= mu2, beta > 0, L > 0");
    for (long i = 0; i < n; i++)
        if (!(cos(zeta[i]) > 0.0))
            return param_error(err, len, "needs |zeta| < pi/2 in every cell");
    for (int s = 0; s < 2; s++)
        if (bc[s].kind == DA_BC_GIVEN && !bc[s].ghost)
            return param_error(err, len, "a given boundary needs its ghost function");
    return 0;
}

struct da_solver *da_create(long n, double x0, double dx, const double *zeta,
                            const struct da_params *p, struct da_bc left, struct da_bc right,
                            char *err, int err_len)
{
    struct da_bc bc[2] = {left, right};
    if (check_params(n, dx, zeta, p, bc, err, err_len) != 0)
        return NULL;
    struct da_solver *s = calloc(1, sizeof *s);
    /* one block: 9 arrays of n, 8 of n + 1, 2 of n + 2 NG */
    size_t nd = 9 * (size_t)n + 8 * (size_t)(n + 1) + 2 * (size_t)(n + 2 * NG);
    double *a = s ? malloc(nd * sizeof *a) : NULL;
    unsigned char *held = a ? calloc(2 * (size_t)n + 1, 1) : NULL;
    if (!held) {
        free(a);
        free(s);
        param_error(err, err_len, "out of memory");
        return NULL;
    }
    s->n = n;
    s->x0 = x0;
    s->dx = dx;
    s->p = *p;
    s->bc[0] = left;
    s->bc[1] = right;
    s->held = held;
    s->holds = held + n + 1;
    double **n_arrays[] = {&s->sin_z, &s->cos_z, &s->h0, &s->m0, &s->dh,
                           &s->rm, &s->tf, &s->rm0, &s->tf0};
    double **f_arrays[] = {&s->gf, &s->hl, &s->ul, &s->hr, &s->ur,
                           &s->fh, &s->fm, &s->fv};
    double *q = a;
    for (size_t k = 0; k < sizeof n_arrays / sizeof n_arrays[0]; k++, q += n)
        *n_arrays[k] = q;
    for (size_t k = 0; k < sizeof f_arrays / sizeof f_arrays[0]; k++, q += n + 1)
        *f_arrays[k] = q;
    s->hc = q;
    s->uc = q + n + 2 * NG;
    for (long i = 0; i < n; i++) {
        s->sin_z[i] = sin(zeta[i]);
        s->cos_z[i] = cos(zeta[i]);
    }
    /* a face's slope: the mean of its cells' angles (the end faces: the cell's) */
    for (long f = 0; f <= n; f++) {
        double z = f == 0 ? zeta[0] : f == n ? zeta[n - 1] : 0.5 * (zeta[f - 1] + zeta[f]);
        s->gf[f] = p->K * p->g * cos(z);
    }
    return s;
}

void da_free(struct da_solver *s)
{
    if (!s)
        return;
    free(s->sin_z); /* the block's start */
    free(s->held);
    free(s);
}

/* ---- reconstruction ---------------------------------------------------- */

static double minmod(double a, double b)
{
    if (a * b <= 0.0)
        return 0.0;
    return fabs(a) < fabs(b) ? a : b;
}

static double limited_slope(enum da_limiter lim, double dm, double dp)
{
    switch (lim) {
    case DA_LIMITER_MC:
        return minmod(minmod(2.0 * dm, 2.0 * dp), 0.5 * (dm + dp));
    case DA_LIMITER_MINMOD:
        return minmod(dm, dp);
    default:
        return 0.0;
    }
}

/* The ghost cells of one side at time t: side 0 left (cells -1, -2), 1 right. */
static void fill_ghosts(struct da_solver *s, int side, double t)
{
    double *h = s->hc + NG, *u = s->uc + NG;
    long n = s->n;
    for (int k = 1; k <= NG; k++) {
        long g = side == 0 ? -k : n - 1 + k; /* the ghost */
        long in = side == 0 ? k - 1 : n - k; /* its mirror inside */
        long edge = side == 0 ? 0 : n - 1;   /* the cell at the boundary */
        switch (s->bc[side].kind) {
        case DA_BC_WALL:
            h[g] = h[in];
            u[g] = -u[in];
            break;
        case DA_BC_GIVEN:
            s->bc[side].ghost(s->bc[side].ctx, s->x0 + (g + 0.5) * s->dx, t, &h[g], &u[g]);
            break;
        default:
            h[g] = h[edge];
            u[g] = u[edge];
        }
    }
}

/* The stage's cell values with ghosts, and the face states from the limited
 * slopes of h and u: a limited edge lies between its cell and the neighbour,
 * so no edge depth is negative. */
static void reconstruct(struct da_solver *s, const double *h, const double *m, double t)
{
    long n = s->n;
    double *hc = s->hc + NG, *uc = s->uc + NG;
    for (long i = 0; i < n; i++) {
        hc[i] = h[i];
        uc[i] = h[i] > s->p.h_dry ? m[i] / h[i] : 0.0;
    }
    fill_ghosts(s, 0, t);
    fill_ghosts(s, 1, t);
    for (long i = -1; i <= n; i++) {
        double sh = limited_slope(s->p.limiter, hc[i] - hc[i - 1], hc[i + 1] - hc[i]);
        double su = limited_slope(s->p.limiter, uc[i] - uc[i - 1], uc[i + 1] - uc[i]);
        if (hc[i] <= s->p.h_dry)
            sh = su = 0.0;
        if (i >= 0) { /* the left edge of cell i is the right state of face i */
            s->hr[i] = hc[i] - 0.5 * sh;
            s->ur[i] = uc[i] - 0.5 * su;
        }
        if (i < n) { /* its right edge, the left state of face i + 1 */
            s->hl[i + 1] = hc[i] + 0.5 * sh;
            s->ul[i + 1] = uc[i] + 0.5 * su;
        }
    }
    for (int side = 0; side < 2; side++) {
        if (s->bc[side].kind != DA_BC_WALL)
            continue;
        /* the exact mirror of the inner edge: no mass through the wall */
        long f = side == 0 ? 0 : n;
        if (side == 0) {
            s->hl[f] = s->hr[f];
            s->ul[f] = -s->ur[f];
        } else {
            s->hr[f] = s->hl[f];
            s->ur[f] = -s->ul[f];
        }
    }
}

/* ---- fluxes ------------------------------------------------------------ */

/* The characteristic speeds chi u -+ c of a state, c^2 = g' h + chi (chi - 1) u^2. */
static double sound(const struct da_params *p, double gp, double h, double u)
{
    return sqrt(gp * h + p->chi * (p->chi - 1.0) * u * u);
}

static void phys_flux(const struct da_params *p, double gp, double h, double u, double *fh,
                      double *fm)
{
    *fh = h * u;
    *fm = p->chi * h * u * u + 0.5 * gp * h * h;
}

/* The numerical flux of face f between (hl, ul) and (hr, ur), g' = gp.  A dry
 * side takes the dry front's speed u + 2c of the wet one (shallow water). */
static void face_flux(const struct da_params *p, double gp, double hl, double ul, double hr,
                      double ur, double *fh, double *fm)
{
    int wl = hl > p->h_dry, wr = hr > p->h_dry;
    if (!wl && !wr) {
        *fh = 0.0;
        *fm = 0.0;
        return;
    }
    if (!wl)
        hl = ul = 0.0;
    if (!wr)
        hr = ur = 0.0;
    double cl = sound(p, gp, hl, ul), cr = sound(p, gp, hr, ur);
    double sl, sr;
    if (!wr) {
        sl = p->chi * ul - cl;
        sr = ul + 2.0 * cl;
    } else if (!wl) {
        sl = ur - 2.0 * cr;
        sr = p->chi * ur + cr;
    } else {
        sl = fmin(p->chi * ul - cl, p->chi * ur - cr);
        sr = fmax(p->chi * ul + cl, p->chi * ur + cr);
    }
    double fhl, fml, fhr, fmr;
    phys_flux(p, gp, hl, ul, &fhl, &fml);
    phys_flux(p, gp, hr, ur, &fhr, &fmr);
    if (p->flux == DA_FLUX_RUSANOV) {
        double a = fmax(fabs(sl), fabs(sr));
        *fh = 0.5 * (fhl + fhr) - 0.5 * a * (hr - hl);
        *fm = 0.5 * (fml + fmr) - 0.5 * a * (hr * ur - hl * ul);
        return;
    }
    if (sl >= 0.0) {
        *fh = fhl;
        *fm = fml;
    } else if (sr <= 0.0) {
        *fh = fhr;
        *fm = fmr;
    } else {
        double w = 1.0 / (sr - sl);
        *fh = (sr * fhl - sl * fhr + sl * sr * (hr - hl)) * w;
        *fm = (sr * fml - sl * fmr + sl * sr * (hr * ur - hl * ul)) * w;
    }
}

/* The momentum's rate of change of cell i but for the friction: the fluxes
 * through its faces, the variable g' (so that a layer of uniform depth feels
 * no pressure force where the slope bends), gravity along the bed and the
 * viscous flux. */
static double cell_rhs(const struct da_solver *s, long i)
{
    double dx = s->dx;
    double el = 0.5 * s->hr[i] * s->hr[i], er = 0.5 * s->hl[i + 1] * s->hl[i + 1];
    double r = -(s->fm[i + 1] - s->fm[i]) / dx;
    r += (s->gf[i + 1] - s->gf[i]) * 0.5 * (el + er) / dx;
    r += s->p.g * s->sin_z[i] * s->hc[NG + i];
    r += (s->fv[i + 1] - s->fv[i]) / dx;
    return r;
}

/* The friction's largest force on cell i, mu_b g cos(zeta) h (stage state). */
static double friction_bound(const struct da_solver *s, long i)
{
    double h = s->hc[NG + i], u = s->uc[NG + i];
    double mu = da_basal_friction(&s->p, s->cos_z[i], h, fabs(u));
    return mu * s->p.g * s->cos_z[i] * h;
}

/* A face between two cells at rest passes no mass and the pressure g' hl hr
 * / 2: each cell's own edge pressure g' h^2 / 2 and the force of half the
 * jump on its edge depth, g' h (hr - hl) / 2, the same on both sides.  The
 * cells feel the jump (a first-order reconstruction has no other gradient),
 * a thin cell in proportion to its depth, friction decides whether they
 * hold, and the Riemann flux's diffusion of h, which would creep a layer at
 * rest, is left out. */
static void held_flux(struct da_solver *s, long f)
{
    s->fh[f] = 0.0;
    s->fm[f] = 0.5 * s->gf[f] * s->hl[f] * s->hr[f];
}

/* Which cells hold: at rest, and friction holds them against the force they
 * feel with both their faces held; which faces are held: both their cells
 * hold. */
static void find_held(struct da_solver *s, const double *m)
{
    long n = s->n;
    for (long f = 0; f <= n; f++) {
        held_flux(s, f);
        s->fv[f] = 0.0;
    }
    for (long i = 0; i < n; i++)
        s->holds[i] = m[i] == 0.0 && fabs(cell_rhs(s, i)) <= friction_bound(s, i);
    s->held[0] = s->held[n] = 0;
    for (long f = 1; f < n; f++)
        s->held[f] = s->holds[f - 1] && s->holds[f];
}

/* A face between a wet cell that holds and one that does not: the moving
 * side's edge state flows in when it moves towards the holding cell, and
 * nothing flows out of that cell.  The Riemann flux's diffusion would drain
 * a deposit into a thin layer sliding beside it (its toe) until the
 * diffusion balanced the advection: a layer that slides forever without
 * moving its mass. */
static void one_sided_flux(struct da_solver *s, long f, int rest_left)
{
    double h = rest_left ? s->hr[f] : s->hl[f], u = rest_left ? s->ur[f] : s->ul[f];
    int toward = rest_left ? u < 0.0 : u > 0.0;
    s->fh[f] = toward ? h * u : 0.0;
    s->fm[f] = (toward ? s->p.chi * h * u * u : 0.0) + 0.5 * s->gf[f] * s->hl[f] * s->hr[f];
}

/* The viscous flux nu k (u_f - u_{f-1}) / dx at each face, k the harmonic
 * mean of the cells' h^{3/2} (bounded by twice the smaller: a thin cell
 * beside a deep one keeps the explicit step's limit). */
static void viscous_flux(struct da_solver *s)
{
    const double *hc = s->hc + NG, *uc = s->uc + NG;
    for (long f = 0; f <= s->n; f++) {
        double a = pow(fmax(hc[f - 1], 0.0), 1.5), b = pow(fmax(hc[f], 0.0), 1.5);
        double k = a + b > 0.0 ? 2.0 * a * b / (a + b) : 0.0;
        s->fv[f] = s->p.nu * k * (uc[f] - uc[f - 1]) / s->dx;
    }
}

/* A stage's rates at the state (h, m) at time t: h_t in dh, the momentum's
 * rate but for friction in rm, the friction's bound in tf. */
static void rates(struct da_solver *s, const double *h, const double *m, double t)
{
    long n = s->n;
    reconstruct(s, h, m, t);
    find_held(s, m);
    for (long f = 0; f <= n; f++) {
        if (s->held[f])
            continue;
        int rl = f > 0 && s->holds[f - 1] && s->hc[NG + f - 1] > s->p.h_dry;
        int rr = f < n && s->holds[f] && s->hc[NG + f] > s->p.h_dry;
        if (f > 0 && f < n && rl != rr)
            one_sided_flux(s, f, rl);
        else
            face_flux(&s->p, s->gf[f], s->hl[f], s->ul[f], s->hr[f], s->ur[f], &s->fh[f],
                      &s->fm[f]);
    }
    if (s->p.nu > 0.0)
        viscous_flux(s);
    for (long i = 0; i < n; i++) {
        s->dh[i] = -(s->fh[i + 1] - s->fh[i]) / s->dx;
        s->rm[i] = cell_rhs(s, i);
        s->tf[i] = friction_bound(s, i);
    }
}

/* The friction as a projection of m* with the impulse bound tau: it stops a
 * cell, never reverses it. */
static double project(double mstar, double tau)
{
    return fabs(mstar) <= tau ? 0.0 : mstar - copysign(tau, mstar);
}

double da_max_dt(const struct da_solver *s, const double *h, const double *m)
{
    const struct da_params *p = &s->p;
    double smax = 0.0, hmax = 0.0;
    for (long i = 0; i < s->n; i++) {
        if (!(h[i] > p->h_dry))
            continue;
        double u = m[i] / h[i];
        double gp = p->K * p->g * s->cos_z[i];
        /* the dry front's u + 2c bounds the edge states' speeds too */
        double c = sound(p, gp, h[i], u);
        smax = fmax(smax, fabs(p->chi * u) + 2.0 * c);
        hmax = fmax(hmax, h[i]);
    }
    double rate = smax / (p->cfl * s->dx);
    if (p->nu > 0.0)
        rate += 4.0 * p->nu * sqrt(hmax) / (s->dx * s->dx);
    return rate > 0.0 ? 1.0 / rate : INFINITY;
}

int da_step(struct da_solver *s, double *h, double *m, double t, double dt)
{
    long n = s->n;
    double hd = s->p.h_dry;
    memcpy(s->h0, h, (size_t)n * sizeof *h);
    memcpy(s->m0, m, (size_t)n * sizeof *m);
    /* stage 1, forward Euler: U1 = P(U + dt L(U)) */
    rates(s, h, m, t);
    for (long i = 0; i < n; i++) {
        h[i] = fmax(0.0, s->h0[i] + dt * s->dh[i]); /* < 0 only by round-off */
        m[i] = h[i] > hd ? project(s->m0[i] + dt * s->rm[i], dt * s->tf[i]) : 0.0;
        s->rm0[i] = s->rm[i];
        s->tf0[i] = s->tf[i];
    }
    /* stage 2: h the mean of U and U1 + dt L(U1) (a convex combination of
     * non-negative depths), m projected once with the mean of the two
     * stages' rates and bounds: Heun's step for a sliding cell, an exact stop
     * for a cell whose friction wins over the step */
    rates(s, h, m, t + dt);
    int ok = 1;
    for (long i = 0; i < n; i++) {
        double h2 = fmax(0.0, h[i] + dt * s->dh[i]);
        h[i] = 0.5 * (s->h0[i] + h2);
        double mstar = s->m0[i] + 0.5 * dt * (s->rm0[i] + s->rm[i]);
        m[i] = h[i] > hd ? project(mstar, 0.5 * dt * (s->tf0[i] + s->tf[i])) : 0.0;
        ok &= isfinite(h[i]) && isfinite(m[i]);
    }
    return ok ? 0 : -1;
}

long da_advance(struct da_solver *s, double *h, double *m, double t0, double t1)
{
    long steps = 0;
    double t = t0;
    while (t < t1) {
        double dt = da_max_dt(s, h, m);
        if (!(dt > 0.0))
            return -1;
        int last = dt >= t1 - t;
        if (last)
            dt = t1 - t;
        if (da_step(s, h, m, t, dt) != 0)
            return -1;
        steps++;
        t = last ? t1 : t + dt;
    }
    return steps;
}
