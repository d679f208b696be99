/* Forces on the obstacles: surface integral and control volume
 * (obstacle_forces.h). */
#include "physics/obstacle_forces.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "kernels/embedded.h"
#include "platform/comm.h"
#include "platform/output_file.h"
#include "march/step.h"
#include "physics/obstacle.h"
#include "solvers/viscous.h"

static const double PI = 3.14159265358979323846;

/* The plane (a, b), the extrusion m and its middle cell, the shapes, and
 * a symmetry plane through them: mirror[k] = -1 or +1 when the box's low
 * or high face along the plane's k-th direction is a slip face through
 * the centre of every shape (the run holds one half of a symmetric body),
 * else 0. */
#define PLANE_FIELDS 10
struct plane {
    const struct march_state *st;
    struct shape_set set;
    int a, b, m, jm;
    int mirror[2];
    /* the whole grid the samples read and its fields: st's own, or on
     * ranks every rank's blocks gathered (plane_gather) */
    const struct grid *g;
    const double *u[3], *p_dyn, *p_hyd, *eta, *eta_e[3], *rho_a;
    double *whole[PLANE_FIELDS], *scratch;
};

/* The centre of shape sh along the plane's k-th coordinate. */
static double shape_centre(const struct shape *sh, int k)
{
    return sh->kind == SHAPE_CIRCLE ? sh->v[k] : 0.5 * (sh->v[k] + sh->v[k + 2]);
}

/* The ghost planes of a whole-grid field f along the periodic directions
 * split over ranks (decomp_gather leaves them): their images'. */
static void wrap_periodic(const struct grid *gg, const struct comm_cart *cart, double *f)
{
    for (int d = 0; d < 3; d++) {
        if (!(cart->periodic[d] && cart->dims[d] > 1))
            continue;
        const int e1 = d == 0 ? 1 : 0, e2 = d == 2 ? 1 : 2, n = gg->n[d];
        for (int u = -1; u <= gg->n[e1]; u++)
            for (int v = -1; v <= gg->n[e2]; v++) {
                int lo[3], hi[3], from_lo[3], from_hi[3];
                lo[d] = -1, hi[d] = n, from_lo[d] = n - 1, from_hi[d] = 0;
                lo[e1] = hi[e1] = from_lo[e1] = from_hi[e1] = u;
                lo[e2] = hi[e2] = from_lo[e2] = from_hi[e2] = v;
                f[grid_idx(gg, lo[0], lo[1], lo[2])] =
                    f[grid_idx(gg, from_lo[0], from_lo[1], from_lo[2])];
                f[grid_idx(gg, hi[0], hi[1], hi[2])] =
                    f[grid_idx(gg, from_hi[0], from_hi[1], from_hi[2])];
            }
    }
}

/* The samples' view of st: its own grid and fields on one process; on
 * ranks the whole grid's, every rank's blocks gathered on every rank (a
 * sample's stencil may straddle a rank border; the arrays are the whole
 * grid's, a cost of the body's cases, whose planes are small).  Collective.
 * Returns 0, or -1 when out of memory (the view then st's own block). */
static int plane_view(struct plane *pl, const struct march_state *st)
{
    const struct march_fields *fl = &st->field;
    const double *src[PLANE_FIELDS] = {fl->velocity[0], fl->velocity[1], fl->velocity[2],
                                       fl->p_dyn, fl->p_hyd, fl->viscosity,
                                       fl->viscosity_edges[0], fl->viscosity_edges[1],
                                       fl->viscosity_edges[2], fl->density_faces[pl->a]};
    const double **dst[PLANE_FIELDS] = {&pl->u[0], &pl->u[1], &pl->u[2], &pl->p_dyn,
                                        &pl->p_hyd, &pl->eta, &pl->eta_e[0], &pl->eta_e[1],
                                        &pl->eta_e[2], &pl->rho_a};
    pl->g = &st->g;
    for (int f = 0; f < PLANE_FIELDS; f++)
        *dst[f] = src[f];
    if (!st->ranks)
        return 0;
    const struct grid *gg = &st->ranks->global;
    int ok = (pl->scratch = malloc(decomp_gather_len(&st->ranks->dc) * sizeof(double))) != NULL;
    for (int f = 0; f < PLANE_FIELDS; f++)
        ok &= (pl->whole[f] = field_alloc(gg)) != NULL;
    if (march_max(st, !ok) != 0.0)
        return -1;
    for (int f = 0; f < PLANE_FIELDS; f++) {
        decomp_gather(&st->ranks->dc, &st->g, src[f], gg, pl->whole[f], pl->scratch);
        wrap_periodic(gg, &st->ranks->cart, pl->whole[f]);
        *dst[f] = pl->whole[f];
    }
    pl->g = gg;
    return 0;
}

static void plane_free(struct plane *pl)
{
    for (int f = 0; f < PLANE_FIELDS; f++)
        field_free(pl->whole[f]);
    free(pl->scratch);
}

/* view 0: the shapes and the symmetry planes alone, no field read (not
 * collective). */
static void plane_init_view(struct plane *pl, const struct march_state *st, int view)
{
    memset(pl, 0, sizeof *pl);
    pl->st = st;
    case_obstacle_shapes(st->cs, &pl->set);
    pl->a = pl->set.plane_a;
    pl->b = pl->set.plane_b;
    pl->m = 3 - pl->a - pl->b;
    pl->g = march_global_grid(st);
    if (view)
        (void)plane_view(pl, st);
    pl->jm = pl->g->n[pl->m] / 2;
    const int dd[2] = {pl->a, pl->b};
    for (int k = 0; k < 2; k++) {
        int d = dd[k];
        double len = pl->g->len[d];
        pl->mirror[k] = 0;
        for (int side = 0; side < 2 && pl->set.n > 0 && !pl->set.invert; side++) {
            if (st->bc.face[d][side] != BC_SLIP)
                continue;
            int through = 1;
            for (int i = 0; i < pl->set.n; i++)
                through &= fabs(shape_centre(&pl->set.s[i], k) - side * len) <= 1e-9 * len;
            if (through)
                pl->mirror[k] = side ? 1 : -1;
        }
    }
}

static void plane_init(struct plane *pl, const struct march_state *st)
{
    plane_init_view(pl, st, 1);
}

/* Whether x (on the outline) lies in the box along the plane's directions:
 * the half of a mirrored body beyond its symmetry plane does not. */
static int in_box(const struct plane *pl, const double x[3])
{
    const struct grid *g = pl->g;
    const int dd[2] = {pl->a, pl->b};
    for (int k = 0; k < 2; k++) {
        double len = g->len[dd[k]];
        if (pl->mirror[k] && (x[dd[k]] < 0.0 || x[dd[k]] > len))
            return 0;
    }
    return 1;
}

static ptrdiff_t at(const struct plane *pl, int ia, int ib)
{
    int idx[3];
    idx[pl->a] = ia, idx[pl->b] = ib, idx[pl->m] = pl->jm;
    return grid_idx(pl->g, idx[0], idx[1], idx[2]);
}

/* Bilinear interpolation in the plane of field f located as component c
 * (-1: cells) at x; -1 when a node of the stencil is in the body. */
static int interp(const struct plane *pl, const double *f, int c, const double x[3], double *out)
{
    const struct grid *g = pl->g;
    int d2[2] = {pl->a, pl->b}, i0[2];
    double w[2];
    for (int k = 0; k < 2; k++) {
        int d = d2[k];
        grid_bracket(g, d, d == c, x[d], &i0[k], &w[k]);
        int top = d == c ? g->n[d] : g->n[d] - 1;
        if (i0[k] < -1 || i0[k] + 1 > top + 1)
            return -1;
    }
    double s = 0.0;
    for (int da = 0; da < 2; da++)
        for (int db = 0; db < 2; db++) {
            int idx[3];
            idx[pl->a] = i0[0] + da, idx[pl->b] = i0[1] + db, idx[pl->m] = pl->jm;
            double y[3];
            obstacle_node_position(g, c, idx[0], idx[1], idx[2], y);
            double wt = (da ? w[0] : 1.0 - w[0]) * (db ? w[1] : 1.0 - w[1]);
            if (wt == 0.0)
                continue; /* face n + 1 past a box's face has no slot: never read */
            if (idx[pl->a] > g->n[pl->a] || idx[pl->b] > g->n[pl->b] ||
                shape_distance(&pl->set, y) <= 0.0)
                return -1;
            s += wt * f[grid_idx(g, idx[0], idx[1], idx[2])];
        }
    *out = s;
    return 0;
}

/* The traction at surface point x (normal n into the fluid): pressure and
 * viscous parts along a and b.  -1 when the interpolation reached the body. */
struct sample {
    double x[3], n[2], p, tau_t, ta[2];
};

static int surface_sample(const struct plane *pl, struct sample *s)
{
    const struct grid *g = pl->g;
    double h = fmax(g->h[pl->a], g->h[pl->b]);
    if (grid_stretched(g)) /* the cell at the surface point */
        h = fmax(grid_hc(g, pl->a, grid_locate(g, pl->a, s->x[pl->a])),
                 grid_hc(g, pl->b, grid_locate(g, pl->b, s->x[pl->b])));
    const double s1 = 1.5 * h, s2 = 3.0 * h;
    double u[2][2], p[2], eta;
    for (int q = 0; q < 2; q++) {
        double dist = q ? s2 : s1, y[3] = {s->x[0], s->x[1], s->x[2]};
        y[pl->a] += dist * s->n[0];
        y[pl->b] += dist * s->n[1];
        double pd, ph;
        if (interp(pl, pl->u[pl->a], pl->a, y, &u[q][0]) ||
            interp(pl, pl->u[pl->b], pl->b, y, &u[q][1]) ||
            interp(pl, pl->p_dyn, -1, y, &pd) || interp(pl, pl->p_hyd, -1, y, &ph) ||
            (q == 0 && interp(pl, pl->eta, -1, y, &eta)))
            return -1;
        p[q] = pd + ph;
    }
    s->p = (s2 * p[0] - s1 * p[1]) / (s2 - s1);
    double gr[2];
    for (int k = 0; k < 2; k++) /* du/dn at 0 of the quadratic through (0, 0) */
        gr[k] = (u[0][k] * s2 * s2 - u[1][k] * s1 * s1) / (s1 * s2 * (s2 - s1));
    double t[2] = {-s->n[1], s->n[0]};
    s->tau_t = eta * (gr[0] * t[0] + gr[1] * t[1]);
    s->ta[0] = -s->p * s->n[0] + eta * gr[0];
    s->ta[1] = -s->p * s->n[1] + eta * gr[1];
    return 0;
}

/* The surface pressure at a point of a no-slip wall through the momentum
 * balance along its normal (the front and back points of pressure_drop).
 * The extrapolation of surface_sample misses the steepening of p in a thin
 * viscous layer at a stagnation point (2 cells thick at D/20 in Schaefer &
 * Turek's 2D-1: Delta p -2.7 %); the balance integrates that layer from
 * the velocity instead.  Along the line y(r) = x + r n (n into the fluid,
 * t = n rotated by +90 degrees, u_n = u . n) the steady normal momentum of
 * a fluid of uniform viscosity eta, rho (u_n d_r + u_t d_t) u_n = -d_r p +
 * eta (d_rr + d_tt) u_n, integrated from the wall (u = 0, and d_r u_n = 0
 * by continuity) to r = s gives
 *   p(0) = p(s) + rho u_n(s)^2 / 2 - eta d_r u_n(s)
 *          + int_0^s (rho u_t d_t u_n - eta d_tt u_n) dr.
 * Kept: advection (rho = 0 without it) and the whole viscous term.  Left
 * out: the time derivative (pressure_drop is a steady state's; in a march
 * it lags by rho int d_t u_n dr) and the body force, which the hydrostatic
 * part balances: p_dyn comes from the balance, p_hyd (linear where the
 * fluid is at rest) from the two-point extrapolation as before.  The
 * derivatives are central differences of the interpolated velocity with
 * step h; the integrand G is taken every h / 2 from s inward while its
 * stencils stay in the fluid (to r_min), below r_min as G(r_min) r / r_min:
 * u_n = a r'^2 near the wall, r' the distance to it, and along the tangent
 * r' = r + t^2 / 2R (R the wall's radius of curvature), so d_tt u_n =
 * 2 a r / R, linear.  s = 6 h: Delta p of Schaefer & Turek's 2D-1 on D/20
 * is -1.04, -0.71, -0.64, -0.62 % from s = 3, 6, 8, 10 h (the fields within
 * 3 h of the wall the least accurate; docs/numerics/obstacles.md).  A viscosity that varies over the samples (mu(I), a
 * granular dead zone of eta ~ 1e6 beside a flowing layer) falls outside
 * this balance: there the extrapolation stays.  Returns 1 when p_dyn(0)
 * came from the balance (in *p_dyn), 0 when it did not apply. */
#define BALANCE_REACH 6.0
static int velocity_at(const struct plane *pl, const double y[3], double u[2])
{
    return interp(pl, pl->u[pl->a], pl->a, y, &u[0]) || interp(pl, pl->u[pl->b], pl->b, y, &u[1]);
}

static int along_normal(const struct plane *pl, const struct sample *s, double r, double dt,
                        double h, double u[2])
{
    double y[3] = {s->x[0], s->x[1], s->x[2]};
    y[pl->a] += r * s->n[0] - dt * h * s->n[1];
    y[pl->b] += r * s->n[1] + dt * h * s->n[0];
    double v[2];
    if (velocity_at(pl, y, v))
        return -1;
    u[0] = v[0] * s->n[0] + v[1] * s->n[1];  /* u_n */
    u[1] = -v[0] * s->n[1] + v[1] * s->n[0]; /* u_t */
    return 0;
}

/* The integrand rho u_t d_t u_n - eta d_tt u_n at r; -1 off the fluid. */
static int balance_integrand(const struct plane *pl, const struct sample *s, double r, double h,
                             double rho, double eta, double *G)
{
    double um[2], u0[2], up[2];
    if (along_normal(pl, s, r, -1.0, h, um) || along_normal(pl, s, r, 0.0, h, u0) ||
        along_normal(pl, s, r, 1.0, h, up))
        return -1;
    *G = rho * u0[1] * (up[0] - um[0]) / (2.0 * h) - eta * (up[0] - 2.0 * u0[0] + um[0]) / (h * h);
    return 0;
}

static int wall_pressure_balance(const struct plane *pl, const struct sample *s, double h,
                                 double *p_dyn)
{
    const struct march_state *st = pl->st;
    const double rho = st->cs->advection ? st->cs->density : 0.0, rs = BALANCE_REACH * h;
    const double *rho_f = pl->rho_a;
    /* one viscosity and the case's density over the samples, or no balance */
    double eta = 0.0;
    for (int q = 0; q <= 2 * (int)BALANCE_REACH; q++) {
        double y[3] = {s->x[0], s->x[1], s->x[2]}, e, d;
        y[pl->a] += (0.5 * q + 0.5) * h * s->n[0];
        y[pl->b] += (0.5 * q + 0.5) * h * s->n[1];
        if (interp(pl, pl->eta, -1, y, &e))
            continue; /* a cell of the body's stencil: the next ones decide */
        if (eta == 0.0)
            eta = e;
        if (fabs(e - eta) > 1e-9 * eta) /* the interpolation's rounding passes */
            return 0;
        if (rho_f && interp(pl, rho_f, pl->a, y, &d) == 0 &&
            fabs(d - st->cs->density) > 1e-9 * st->cs->density)
            return 0;
    }
    double uo[2], ui[2], us[2], ps, y[3] = {s->x[0], s->x[1], s->x[2]};
    y[pl->a] += rs * s->n[0];
    y[pl->b] += rs * s->n[1];
    if (eta <= 0.0 || interp(pl, pl->p_dyn, -1, y, &ps) ||
        along_normal(pl, s, rs, 0.0, h, us) || along_normal(pl, s, rs + h, 0.0, h, uo) ||
        along_normal(pl, s, rs - h, 0.0, h, ui))
        return 0;
    double integral = 0.0, G_prev = 0.0, r = rs, G;
    if (balance_integrand(pl, s, r, h, rho, eta, &G_prev))
        return 0;
    for (; r - 0.5 * h > 0.25 * h; r -= 0.5 * h) { /* the trapezoids while in the fluid */
        if (balance_integrand(pl, s, r - 0.5 * h, h, rho, eta, &G))
            break;
        integral += 0.25 * h * (G_prev + G);
        G_prev = G;
    }
    integral += G_prev * r / 2.0; /* G(r_min) r / r_min from the wall */
    *p_dyn = ps + 0.5 * rho * us[0] * us[0] - eta * (uo[0] - ui[0]) / (2.0 * h) + integral;
    return 1;
}

/* The pressure at a wall's point: the balance for p_dyn where it applies
 * (wall_pressure_balance), surface_sample's extrapolation otherwise and
 * for p_hyd.  -1 when the interpolation reached the body. */
static int wall_pressure(const struct plane *pl, struct sample *s)
{
    const struct grid *g = pl->g;
    if (surface_sample(pl, s) != 0)
        return -1;
    double h = fmax(g->h[pl->a], g->h[pl->b]);
    if (grid_stretched(g))
        h = fmax(grid_hc(g, pl->a, grid_locate(g, pl->a, s->x[pl->a])),
                 grid_hc(g, pl->b, grid_locate(g, pl->b, s->x[pl->b])));
    double pd;
    if (!wall_pressure_balance(pl, s, h, &pd))
        return 0;
    double ph[2];
    for (int q = 0; q < 2; q++) { /* p_hyd extrapolated from 1.5 h and 3 h */
        double y[3] = {s->x[0], s->x[1], s->x[2]};
        y[pl->a] += 1.5 * (q + 1) * h * s->n[0];
        y[pl->b] += 1.5 * (q + 1) * h * s->n[1];
        if (interp(pl, pl->p_hyd, -1, y, &ph[q]))
            return 0;
    }
    s->p = pd + 2.0 * ph[0] - ph[1];
    return 0;
}

/* Calls fn on every sample of the union's outline with its length ds.
 * Returns -1 when a sample failed. */
typedef void (*sample_fn)(void *ctx, const struct sample *s, double ds, double angle);

static int outline(const struct plane *pl, sample_fn fn, void *ctx)
{
    const struct grid *g = pl->g;
    double h = fmin(grid_min_width(g, pl->a), grid_min_width(g, pl->b)); /* the finest cell */
    int bad = 0;
    for (int i = 0; i < pl->set.n; i++) {
        const struct shape *sh = &pl->set.s[i];
        if (sh->kind == SHAPE_SLOPE)
            continue; /* the ground has no closed outline: the discrete force alone */
        double per = sh->kind == SHAPE_CIRCLE ? 2.0 * PI * sh->v[2]
                                              : 2.0 * (sh->v[2] - sh->v[0] + sh->v[3] - sh->v[1]);
        int N = (int)ceil(8.0 * per / h);
        if (N < 720)
            N = 720;
        for (int k = 0; k < N; k++) {
            double s = (k + 0.5) / N, pa, pb, angle;
            if (sh->kind == SHAPE_CIRCLE) {
                angle = 2.0 * PI * s;
                pa = sh->v[0] + sh->v[2] * cos(angle);
                pb = sh->v[1] + sh->v[2] * sin(angle);
            } else { /* counter-clockwise from the low corner */
                double wa = sh->v[2] - sh->v[0], wb = sh->v[3] - sh->v[1], l = s * per;
                if (l < wa)
                    pa = sh->v[0] + l, pb = sh->v[1];
                else if (l < wa + wb)
                    pa = sh->v[2], pb = sh->v[1] + (l - wa);
                else if (l < 2 * wa + wb)
                    pa = sh->v[2] - (l - wa - wb), pb = sh->v[3];
                else
                    pa = sh->v[0], pb = sh->v[3] - (l - 2 * wa - wb);
                angle = atan2(pb - 0.5 * (sh->v[1] + sh->v[3]), pa - 0.5 * (sh->v[0] + sh->v[2]));
            }
            struct sample smp = {{0.0, 0.0, 0.0}, {0.0, 0.0}, 0.0, 0.0, {0.0, 0.0}};
            smp.x[pl->a] = pa, smp.x[pl->b] = pb;
            smp.x[pl->m] = grid_xc(g, pl->m, pl->jm);
            /* inside another shape of the union: not on its surface */
            if (fabs(shape_distance(&pl->set, smp.x)) > 1e-9 * per || !in_box(pl, smp.x))
                continue;
            double n3[3];
            shape_normal(&pl->set, smp.x, n3);
            smp.n[0] = n3[pl->a], smp.n[1] = n3[pl->b];
            if (surface_sample(pl, &smp) != 0) {
                bad = 1;
                continue;
            }
            fn(ctx, &smp, per / N, angle);
        }
    }
    return bad ? -1 : 0;
}

struct sums {
    double f[2], fp[2];
};

static void add_sample(void *ctx, const struct sample *s, double ds, double angle)
{
    (void)angle;
    struct sums *S = ctx;
    for (int k = 0; k < 2; k++) {
        S->f[k] += s->ta[k] * ds;
        S->fp[k] += -s->p * s->n[k] * ds;
    }
}

/* The momentum balance over one side of the box: the line of faces I along
 * direction N, cells K0..K1-1 along T, outward normal sign along N. */
static void cv_side(const struct plane *pl, int N, int T, int I, int K0, int K1, double sign,
                    double F[3])
{
    const struct march_state *st = pl->st;
    const struct grid *g = pl->g;
    /* the momentum flux belongs to the balance only when the momentum
     * equation carries it: without advection (a Stokes-like steady flow)
     * it is no force, and at the granular cylinder's large velocities it
     * was most of the difference between the two estimates */
    const double rho = st->cs->advection ? st->cs->density : 0.0;
    const double *uN = pl->u[N], *uT = pl->u[T], *etae = pl->eta_e[3 - N - T];
    /* the widths and centres' distances where each difference is taken
     * (one size per direction on a uniform grid) */
    /* at(): indices in (a, b) order */
    for (int k = K0; k < K1; k++) {
#define IX(iN, iT) (N == pl->a ? at(pl, (iN), (iT)) : at(pl, (iT), (iN)))
        double un = uN[IX(I, k)];
        double ut = 0.25 * (uT[IX(I - 1, k)] + uT[IX(I, k)] + uT[IX(I - 1, k + 1)] + uT[IX(I, k + 1)]);
        double p = 0.5 * (pl->p_dyn[IX(I - 1, k)] + pl->p_dyn[IX(I, k)] +
                          pl->p_hyd[IX(I - 1, k)] + pl->p_hyd[IX(I, k)]);
        const double hNm = grid_hc(g, N, I - 1), hNp = grid_hc(g, N, I), hNf = grid_hf(g, N, I);
        const double hT = grid_hc(g, T, k);
        /* the mean of 2 eta dudn */
        double tnn = pl->eta[IX(I - 1, k)] * (uN[IX(I, k)] - uN[IX(I - 1, k)]) / hNm +
                     pl->eta[IX(I, k)] * (uN[IX(I + 1, k)] - uN[IX(I, k)]) / hNp;
        double t0 = etae[IX(I, k)] * ((uN[IX(I, k)] - uN[IX(I, k - 1)]) / grid_hf(g, T, k) +
                                      (uT[IX(I, k)] - uT[IX(I - 1, k)]) / hNf);
        double t1 = etae[IX(I, k + 1)] * ((uN[IX(I, k + 1)] - uN[IX(I, k)]) / grid_hf(g, T, k + 1) +
                                          (uT[IX(I, k + 1)] - uT[IX(I - 1, k + 1)]) / hNf);
#undef IX
        double tnt = 0.5 * (t0 + t1);
        F[N] += sign * (-p + tnn - rho * un * un) * hT;
        F[T] += sign * (tnt - rho * un * ut) * hT;
    }
}

/* The whole body's force from its half: along a symmetry plane's normal
 * the two halves cancel, along the plane they add. */
static void symmetric_whole(const int mirror[2], double F[2])
{
    for (int k = 0; k < 2; k++)
        if (mirror[k]) {
            F[k] = 0.0;
            F[1 - k] *= 2.0;
        }
}

/* Sub-samples per cell side of the fluid area. */
#define AREA_SAMPLES 8

/* The fluid's area in the box of cells [I0, I1) of the plane (the bodies'
 * area taken out by sub-sampling; its error, a share of a cell's area per
 * cell along the outline, cancels to a small fraction of h^2). */
static double fluid_area(const struct plane *pl, const int I0[2], const int I1[2])
{
    const struct grid *g = pl->g;
    if (grid_stretched(g)) { /* each cell's share of its own area */
        double area = 0.0;
        for (int i = I0[0]; i < I1[0]; i++)
            for (int j = I0[1]; j < I1[1]; j++) {
                double ha = grid_hc(g, pl->a, i), hb = grid_hc(g, pl->b, j);
                long solid = 0;
                for (int si = 0; si < AREA_SAMPLES; si++)
                    for (int sj = 0; sj < AREA_SAMPLES; sj++) {
                        double x[3] = {0.0, 0.0, 0.0};
                        x[pl->a] = grid_xf(g, pl->a, i) + (si + 0.5) / AREA_SAMPLES * ha;
                        x[pl->b] = grid_xf(g, pl->b, j) + (sj + 0.5) / AREA_SAMPLES * hb;
                        x[pl->m] = grid_xc(g, pl->m, pl->jm);
                        solid += shape_distance(&pl->set, x) <= 0.0;
                    }
                area += (1.0 - (double)solid / (AREA_SAMPLES * AREA_SAMPLES)) * ha * hb;
            }
        return area;
    }
    const double ha = g->h[pl->a], hb = g->h[pl->b];
    long solid = 0;
    for (int i = I0[0]; i < I1[0]; i++)
        for (int j = I0[1]; j < I1[1]; j++)
            for (int si = 0; si < AREA_SAMPLES; si++)
                for (int sj = 0; sj < AREA_SAMPLES; sj++) {
                    double x[3] = {0.0, 0.0, 0.0};
                    x[pl->a] = (i + (si + 0.5) / AREA_SAMPLES) * ha;
                    x[pl->b] = (j + (sj + 0.5) / AREA_SAMPLES) * hb;
                    x[pl->m] = (pl->jm + 0.5) * g->h[pl->m];
                    solid += shape_distance(&pl->set, x) <= 0.0;
                }
    return ((double)(I1[0] - I0[0]) * (I1[1] - I0[1]) -
            (double)solid / (AREA_SAMPLES * AREA_SAMPLES)) * ha * hb;
}

/* The control area in the plane of component c's node at slot p (per unit
 * length of the extrusion): its cell's width across c, the two half cells'
 * along c.  The residual is a flux difference over that area's widths. */
static double node_area(const struct plane *pl, int c, ptrdiff_t p)
{
    const struct grid *g = &pl->st->g; /* the block's own slot p */
    int idx[3];
    grid_slot_index(g, p, idx);
    return grid_node_width(g, c, pl->a, idx[pl->a]) * grid_node_width(g, c, pl->b, idx[pl->b]);
}

/* The force on the bodies as the discrete momentum equations apply it.
 * The residual's terms are fluxes between neighbouring nodes (the stress,
 * the pressure gradient, the conservative advection, the cut cells'
 * grad-div): each flux between a fluid node and a held one leaves the fluid
 * as it enters the body, and the fluxes among held nodes cancel in pairs.
 * So the body's force is the sum over the held nodes of those terms (body
 * forces left out), plus what the cut links add to the fluid nodes alone
 * (the Gibou correction, not a flux between two nodes).  Per unit length
 * of the extrusion; pressure: the pressure gradient's share.  The terms
 * are the march's own (stage_residual.c and the obstacle module's); a
 * module that adds its own residual terms (the two-fluid bed's second
 * phase) is not in the sum.  Returns -1 when out of memory. */
static int discrete_force(const struct plane *pl, double F[2], double Fp[2])
{
    const struct march_state *st = pl->st;
    const struct grid *g = &st->g;
    const struct embedded *e = st->embedded;
    F[0] = F[1] = Fp[0] = Fp[1] = 0.0;
    if (!e)
        return 0;
    double *r[3] = {field_alloc(g), field_alloc(g), field_alloc(g)};
    double *rp[3] = {field_alloc(g), field_alloc(g), field_alloc(g)};
    int rc = -1;
    if (!r[0] || !r[1] || !r[2] || !rp[0] || !rp[1] || !rp[2])
        goto done;
    const double *eta_cell[3] = {st->field.viscosity, st->field.viscosity, st->field.viscosity};
    kernel_stress_divergence(g, st->act, eta_cell, (const double *const *)st->field.viscosity_edges,
                             st->field.velocity, r);
    /* the obstacle module's own residual terms: the cut cells' grad-div
     * (which reaches the held nodes) and the cut links (on fluid nodes, not
     * summed below: their share is taken from the links themselves) */
    viscous_embedded_terms(g, &st->bc, st->act, e, eta_cell,
                           (const double *const *)st->field.viscosity_edges, -1.0,
                           st->field.velocity, r);
    kernel_gradient_update(g, st->act, st->field.p_dyn, 1.0, rp);
    kernel_gradient_update(g, st->act, st->field.p_hyd, 1.0, rp);
    if (st->cs->advection) { /* st->field.advection: the last evaluation's, held nodes included */
        if (st->density_uniform)
            kernel_axpy(g, st->act, st->cs->density, (double *const *)st->field.advection, r);
        else
            kernel_multiply_add(g, st->act, (double *const *)st->field.density_faces,
                                (double *const *)st->field.advection, r);
    }
    const int nm = march_global_grid(st)->n[pl->m]; /* per unit length of the whole */
    const double vol = g->h[0] * g->h[1] * g->h[2] / (nm * g->h[pl->m]);
    double Fd[3] = {0.0, 0.0, 0.0}, Fpd[3] = {0.0, 0.0, 0.0};
    for (int c = 0; c < 3; c++)
        for (long i = 0; i < e->nheld[c]; i++) {
            ptrdiff_t S = e->held[c][i];
            int at[3];
            grid_slot_index(g, S, at);
            if (st->ranks && !box_holds(&st->act[c], at[0], at[1], at[2]))
                continue; /* a ghost's image of the next block's node: its own */
            double v = grid_stretched(g) ? node_area(pl, c, S) : vol;
            Fd[c] += (r[c][S] + rp[c][S]) * v;
            Fpd[c] += rp[c][S] * v;
        }
    for (long i = 0; i < e->nlinks; i++) { /* the residual's -A w v_P, taken from the fluid */
        const struct embedded_link *l = &e->links[i];
        double A = l->coef < 3 ? st->field.viscosity[l->at]
                               : st->field.viscosity_edges[l->coef - 3][l->at];
        double v = grid_stretched(g) ? node_area(pl, l->c, l->p) : vol;
        Fd[l->c] += A * l->w * st->field.velocity[l->c][l->p] * v;
    }
    if (st->ranks) { /* every block's nodes */
        double both[6] = {Fd[0], Fd[1], Fd[2], Fpd[0], Fpd[1], Fpd[2]};
        march_sum_array(st, both, 6);
        for (int c = 0; c < 3; c++)
            Fd[c] = both[c], Fpd[c] = both[3 + c];
    }
    F[0] = Fd[pl->a], F[1] = Fd[pl->b];
    Fp[0] = Fpd[pl->a], Fp[1] = Fpd[pl->b];
    rc = 0;
done:
    for (int c = 0; c < 3; c++) {
        field_free(r[c]);
        field_free(rp[c]);
    }
    return rc;
}

/* The control volume: the box around the bodies (their bounding box lo, hi
 * in the plane), half their size and two cells beyond them, on the grid's
 * faces, inside the domain. */
static void control_volume(const struct plane *pl, const double lo[2], const double hi[2],
                           struct obstacle_forces *f)
{
    const struct march_state *st = pl->st;
    const struct grid *g = pl->g;
    double margin[2] = {0.5 * (hi[0] - lo[0]) + 2.0 * g->h[pl->a],
                        0.5 * (hi[1] - lo[1]) + 2.0 * g->h[pl->b]}; /* NaN if stretched */
    int dd[2] = {pl->a, pl->b}, I0[2], I1[2];
    for (int k = 0; k < 2; k++) {
        int d = dd[k];
        if (g->axis[d]) { /* two of the local cells beyond, as below */
            int c0 = grid_locate(g, d, lo[k]), c1 = grid_locate(g, d, hi[k]);
            margin[k] = 0.5 * (hi[k] - lo[k]) + 2.0 * fmax(grid_hc(g, d, c0), grid_hc(g, d, c1));
            I0[k] = grid_locate(g, d, lo[k] - margin[k]);
            I1[k] = grid_locate(g, d, hi[k] + margin[k]) + 1;
        } else {
            I0[k] = (int)floor((lo[k] - margin[k]) / g->h[d]);
            I1[k] = (int)ceil((hi[k] + margin[k]) / g->h[d]);
        }
        if (I0[k] < 2)
            I0[k] = 2;
        if (I1[k] > g->n[d] - 2)
            I1[k] = g->n[d] - 2;
        /* a symmetry plane is a side of the box: across a slip face no
         * momentum along it passes (no shear stress, no flow) */
        if (pl->mirror[k] < 0)
            I0[k] = 0;
        if (pl->mirror[k] > 0)
            I1[k] = g->n[d];
    }
    double F[3] = {0.0, 0.0, 0.0};
    if (pl->mirror[0] >= 0)
        cv_side(pl, pl->a, pl->b, I0[0], I0[1], I1[1], -1.0, F);
    if (pl->mirror[0] <= 0)
        cv_side(pl, pl->a, pl->b, I1[0], I0[1], I1[1], 1.0, F);
    if (pl->mirror[1] >= 0)
        cv_side(pl, pl->b, pl->a, I0[1], I0[0], I1[0], -1.0, F);
    if (pl->mirror[1] <= 0)
        cv_side(pl, pl->b, pl->a, I1[1], I0[0], I1[0], 1.0, F);
    /* the body force on the fluid in the box (a flow driven by it) */
    double fb[3];
    body_force_vector(st->cs, fb);
    double fluid = fluid_area(pl, I0, I1);
    F[pl->a] += fb[pl->a] * fluid;
    F[pl->b] += fb[pl->b] * fluid;
    f->control_volume[0] = F[pl->a];
    f->control_volume[1] = F[pl->b];
    symmetric_whole(pl->mirror, f->control_volume);
}

/* obstacle_forces; all = 0: the surface integral, the front and back
 * points and the scales only (obstacle_forces_surface), the same numbers. */
static int forces_of(const struct march_state *st, struct obstacle_forces *f, int all)
{
    memset(f, 0, sizeof *f);
    struct plane pl;
    plane_init_view(&pl, st, all >= 0);
    struct sums S = {{0.0, 0.0}, {0.0, 0.0}};
    int rc = all > 0 ? outline(&pl, add_sample, &S) : 0;
    for (int k = 0; k < 2; k++) {
        f->reconstructed[k] = S.f[k];
        f->reconstructed_pressure[k] = S.fp[k];
        f->mirror[k] = pl.mirror[k];
    }
    if (all >= 0 && discrete_force(&pl, f->surface, f->pressure_part) != 0)
        rc = -2;
    symmetric_whole(pl.mirror, f->surface);
    symmetric_whole(pl.mirror, f->pressure_part);
    symmetric_whole(pl.mirror, f->reconstructed);
    symmetric_whole(pl.mirror, f->reconstructed_pressure);
    /* the bounding box of the union, and the front and back points of the
     * first shape along a */
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    int ground = 0; /* a slope: unbounded, no front, back or control volume */
    for (int i = 0; i < pl.set.n; i++) {
        const struct shape *sh = &pl.set.s[i];
        ground |= sh->kind == SHAPE_SLOPE;
        double l0 = sh->kind == SHAPE_CIRCLE ? sh->v[0] - sh->v[2] : sh->v[0];
        double l1 = sh->kind == SHAPE_CIRCLE ? sh->v[1] - sh->v[2] : sh->v[1];
        double h0 = sh->kind == SHAPE_CIRCLE ? sh->v[0] + sh->v[2] : sh->v[2];
        double h1 = sh->kind == SHAPE_CIRCLE ? sh->v[1] + sh->v[2] : sh->v[3];
        lo[0] = fmin(lo[0], l0), lo[1] = fmin(lo[1], l1);
        hi[0] = fmax(hi[0], h0), hi[1] = fmax(hi[1], h1);
    }
    if (ground) {
        f->front_back = NAN;
        for (int k = 0; k < 2; k++)
            f->control_volume[k] = NAN;
    } else if (pl.set.n > 0 && !pl.set.invert) {
        const struct shape *sh = &pl.set.s[0];
        double cb = sh->kind == SHAPE_CIRCLE ? sh->v[1] : 0.5 * (sh->v[1] + sh->v[3]);
        double fa = sh->kind == SHAPE_CIRCLE ? sh->v[0] - sh->v[2] : sh->v[0];
        double ba = sh->kind == SHAPE_CIRCLE ? sh->v[0] + sh->v[2] : sh->v[2];
        struct sample front = {{0}, {-1.0, 0.0}, 0, 0, {0, 0}}, back = {{0}, {1.0, 0.0}, 0, 0, {0, 0}};
        front.x[pl.a] = fa, front.x[pl.b] = cb, back.x[pl.a] = ba, back.x[pl.b] = cb;
        if (pl.mirror[0]) /* one of the two points is beyond the symmetry plane */
            f->front_back = NAN;
        else if (all < 0)
            f->front_back = 0.0;
        else if (wall_pressure(&pl, &front) == 0 && wall_pressure(&pl, &back) == 0)
            f->front_back = front.p - back.p;
        else
            rc = -1;
        if (all > 0)
            control_volume(&pl, lo, hi, f);
    }
    /* the coefficients' scales: the inflow's mean velocity, the extent across */
    const struct boundary *bc = &st->bc;
    for (int d = 0; d < 3; d++)
        for (int side = 0; side < 2; side++)
            if (bc->face[d][side] == BC_INFLOW) {
                int across = 0;
                for (int e = 0; e < 3; e++)
                    if (e != d && bc->face[e][0] != BC_PERIODIC)
                        across++;
                double mean = bc->inflow_profile == INFLOW_PARABOLIC ? pow(2.0 / 3.0, across) : 1.0;
                f->u_ref = fabs(bc->inflow_velocity) * mean;
            }
    f->d_ref = pl.set.n > 0 && !pl.set.invert && !ground ? hi[1] - lo[1] : 0.0;
    plane_free(&pl);
    return rc;
}

int obstacle_forces(const struct march_state *st, struct obstacle_forces *f)
{
    return forces_of(st, f, 1);
}

int obstacle_forces_surface(const struct march_state *st, struct obstacle_forces *f)
{
    return forces_of(st, f, 0);
}

void obstacle_forces_scales(const struct march_state *st, struct obstacle_forces *f)
{
    (void)forces_of(st, f, -1);
}

/* The mean over the box of the velocity component the body force drives
 * (march_driven_component; the body's own faces hold 0), signed along the
 * force: a flow rate per unit area across the flow, Q / (L_x L_y) for a
 * flow along z.  NaN without a force along that component. */
double obstacle_mean_velocity(const struct march_state *st)
{
    double f[3];
    body_force_vector(st->cs, f);
    int a = march_driven_component(st);
    if (f[a] == 0.0)
        return NAN;
    return copysign(1.0, f[a]) * march_component_mean(st, a, st->field.velocity[a]);
}

/* The flow's direction: an inflow face's (into the box), else the
 * component the body force drives; *sense is +1 or -1 along it.  -1 when
 * neither drives a flow. */
static int flow_direction(const struct march_state *st, double *sense)
{
    const struct boundary *bc = &st->bc;
    for (int d = 0; d < 3; d++)
        for (int side = 0; side < 2; side++)
            if (bc->face[d][side] == BC_INFLOW) {
                *sense = (side ? -1.0 : 1.0) * (bc->inflow_velocity < 0.0 ? -1.0 : 1.0);
                return d;
            }
    double f[3];
    body_force_vector(st->cs, f);
    int a = march_driven_component(st);
    *sense = f[a] < 0.0 ? -1.0 : 1.0;
    return f[a] != 0.0 ? a : -1;
}

/* How the forces are named: drag along the flow (positive downstream), lift
 * across it in the plane (positive along the grid's axis), for a flow along
 * the plane's a (k = 0) or b (k = 1); k = -1 for a flow along the extrusion,
 * or none, whose forces are named by their axes.  q: the coefficients'
 * dynamic pressure per unit length (0 without a velocity scale). */
struct force_frame {
    int k, along, across;
    double sense, q;
    int axis[2]; /* the plane's directions */
};
static void force_frame(const struct march_state *st, const struct obstacle_forces *f,
                        struct force_frame *fr)
{
    struct shape_set set;
    case_obstacle_shapes(st->cs, &set);
    int dir = flow_direction(st, &fr->sense);
    fr->k = dir == set.plane_a ? 0 : dir == set.plane_b ? 1 : -1;
    fr->along = fr->k;
    fr->across = 1 - fr->k;
    fr->q = 0.5 * st->cs->density * f->u_ref * f->u_ref * f->d_ref;
    fr->axis[0] = set.plane_a;
    fr->axis[1] = set.plane_b;
}

void obstacle_results(const struct march_state *st, struct result_values *res)
{
    /* a wall around the fluid (obstacle.invert: a duct) is no body in a
     * flow: no drag or lift, front, back or box around it (its forces in
     * the plane of a flow along the duct are zeros, not measurements); the
     * scene measures the flow inside */
    if (st->cs->obstacle.invert)
        return;
    struct obstacle_forces f;
    int rc = obstacle_forces(st, &f);
    struct force_frame fr;
    force_frame(st, &f, &fr);
    if (fr.k >= 0) {
        int along = fr.along, across = fr.across;
        double sense = fr.sense, q = fr.q;
        result_values_add(res, "drag_force", "%.10g", sense * f.surface[along]);
        result_values_add(res, "lift_force", "%.10g", f.surface[across]);
        result_values_add(res, "drag_force_pressure", "%.10g", sense * f.pressure_part[along]);
        result_values_add(res, "drag_force_reconstructed", "%.10g", sense * f.reconstructed[along]);
        result_values_add(res, "lift_force_reconstructed", "%.10g", f.reconstructed[across]);
        result_values_add(res, "drag_force_pressure_reconstructed", "%.10g",
                       sense * f.reconstructed_pressure[along]);
        result_values_add(res, "drag_force_control_volume", "%.10g", sense * f.control_volume[along]);
        result_values_add(res, "lift_force_control_volume", "%.10g", f.control_volume[across]);
        if (q > 0.0) {
            result_values_add(res, "drag_coefficient", "%.10g", sense * f.surface[along] / q);
            result_values_add(res, "lift_coefficient", "%.10g", f.surface[across] / q);
            result_values_add(res, "drag_coefficient_control_volume", "%.10g",
                           sense * f.control_volume[along] / q);
            result_values_add(res, "lift_coefficient_control_volume", "%.10g",
                           f.control_volume[across] / q);
            result_values_add(res, "drag_coefficient_reconstructed", "%.10g",
                           sense * f.reconstructed[along] / q);
            result_values_add(res, "lift_coefficient_reconstructed", "%.10g",
                           f.reconstructed[across] / q);
        }
        /* the front and back points lie along a */
        if (fr.k == 0 && !f.mirror[0])
            result_values_add(res, "pressure_drop", "%.10g", sense * f.front_back);
    } else {
        const int *axis = fr.axis;
        for (int c = 0; c < 2; c++) {
            char key[40];
            snprintf(key, sizeof key, "force_%c", "xyz"[axis[c]]);
            result_values_add(res, key, "%.10g", f.surface[c]);
            snprintf(key, sizeof key, "force_%c_control_volume", "xyz"[axis[c]]);
            result_values_add(res, key, "%.10g", f.control_volume[c]);
        }
    }
    double u_mean = obstacle_mean_velocity(st);
    if (isfinite(u_mean))
        result_values_add(res, "mean_velocity", "%.10g", u_mean);
    if (rc == -2)
        result_values_add(res, "obstacle_warning", "%s",
                       "no memory for the discrete force: drag and lift are 0");
    else if (rc != 0)
        result_values_add(res, "obstacle_warning", "%s",
                       "samples reached into the body (too few cells across): reconstructed forces incomplete");
}

void obstacle_force_lines(const struct march_state *st, const struct obstacle_forces *f,
                          struct obstacle_force_lines *l)
{
    static const char *const axis_names[3] = {"force_x", "force_y", "force_z"};
    l->n = 0;
    if (!case_obstacle_active(st->cs) || st->cs->obstacle.invert)
        return;
    struct force_frame fr; /* obstacle_results' names and numbers */
    force_frame(st, f, &fr);
#define LINE(nm, v) (l->name[l->n] = (nm), l->value[l->n++] = (v))
    if (fr.k >= 0) {
        int along = fr.along, across = fr.across;
        double sense = fr.sense, q = fr.q;
        LINE("drag_force", sense * f->surface[along]);
        LINE("lift_force", f->surface[across]);
        if (q > 0.0) {
            LINE("drag_coefficient", sense * f->surface[along] / q);
            LINE("lift_coefficient", f->surface[across] / q);
        }
        if (fr.k == 0 && !f->mirror[0])
            LINE("pressure_drop", sense * f->front_back);
    } else {
        LINE(axis_names[fr.axis[0]], f->surface[0]);
        LINE(axis_names[fr.axis[1]], f->surface[1]);
    }
#undef LINE
}

struct csv_ctx {
    FILE *f;
    double eta;
};

static void write_sample(void *ctx, const struct sample *s, double ds, double angle)
{
    (void)ds;
    struct csv_ctx *c = ctx;
    fprintf(c->f, "%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n", angle * 180.0 / PI,
            s->x[0], s->x[1], s->x[2], s->p, -s->p, s->tau_t);
}

int obstacle_write(const char *dir, const struct march_state *st, char *err, size_t errlen)
{
    struct plane pl;
    plane_init(&pl, st); /* every rank's part (collective), rank 0 writes */
    int rc = 0;
    if (!st->ranks || comm_rank() == 0) {
        struct output_file o;
        rc = output_open(&o, dir, "obstacle_surface.csv", err, errlen);
        if (rc == 0) {
            fprintf(o.f, "angle_deg,x,y,z,pressure,normal_stress,tangential_stress\n");
            struct csv_ctx c = {o.f, 0.0};
            (void)outline(&pl, write_sample, &c);
            rc = output_commit(&o, err, errlen);
        }
    }
    plane_free(&pl);
    return rc;
}
