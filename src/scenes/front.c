/* Scene "front": a uniform granular layer fed at the inflow runs down a rough
 * incline ahead of its front, under air (the two_phase module: grains of
 * mu(I), air Newtonian, T carried by the geometric VOF; Barker & Rauter 2018,
 * "Two-fluid regularised mu(I)-rheology with OpenFOAM", sec. 4; cases/front.ini).
 * In the frame of the front the shape becomes steady; it is compared with
 * the depth-averaged travelling front of Pouliquen (1999), "On the shape of
 * granular fronts down rough inclined planes" (diagnostics/
 * depth_averaged_exact.h), whose friction law mu(I) gives for a Bagnold
 * profile: mu_b = mu_s + delta_mu / (1 + beta h / (d Fr)), beta = (2/5)
 * sqrt(phi) I0 (the depth mean of Bagnold's profile, (2/5) I sqrt(phi g
 * cos zeta) h^{3/2} / d, solved for I).
 *
 * The inflow face (x = 0) carries the exact uniform two-layer flow of depth
 * h_inf (Bagnold in the grains, the air's gravity-driven film above it
 * under the open top: the bagnold2 solution, Barker & Rauter eqs. 6-11)
 * through the boundary's inflow_shape hook; the VOF lets only air in
 * through an inflow face, so the first column of cells is the feed: its T
 * is reset to the layer after every step.  A precursor layer (front.
 * precursor h_inf) covers the bed ahead: on a bare bed the nose, moved over
 * the no-slip bed only by the VOF's fluxes, traps the bed's air under the
 * grains, which then slide on it (docs/validation/front.md).  The grains'
 * viscosity on the bed is at the bed's hydrostatic pressure (two_phase's
 * bed_pressure): the precursor, a cell or two deep, otherwise carried three
 * quarters of its weight there and flowed at the viscosity floor's rate,
 * 7.6 times its flux, 2.1 of the front speed's 2.9 % on 250 x 15.  The run
 * starts from the Pouliquen front with its tip at front.tip, over the precursor,
 * the grains moving with Bagnold's profile at the front's speed, the air
 * with its film.
 *
 * Measured at every step: the column heights h(x) = sum T dz, the tip
 * (where h falls to TIP_SHARE of the way from the precursor to h_inf,
 * linear between centres), x_half (where h crosses h_inf / 2, from
 * downstream), h's error over the front; the front speed is the
 * least-squares slope of x_half(t) over the second half of the record,
 * against mass conservation across the front, (q_inf - q_p) / (h_inf -
 * h_p); the shape at the end, in the frame of x_half, against the exact
 * shape over the front's length (from the tip back to where the exact depth
 * is FRONT_SHARE h_inf), and over its body (without the nose); the velocity
 * profile behind the front, the mean over the uniform columns, against
 * Bagnold's; the precursor's flux against its uniform flow's.  At the end
 * the depth-averaged equations with the momentum flux, solved on the same
 * problem (feed, precursor, start: da_reference), give a second reference
 * of the shape, the closed form's omissions included. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "diagnostics/depth_averaged.h"
#include "diagnostics/depth_averaged_exact.h"
#include "march/module_record.h"
#include "io/output.h"
#include "physics/two_phase.h"
#include "scenes/collapse.h"
#include "scenes/layer_feed.h"
#include "scenes/recorded_drive.h"
#include "scenes/scene.h"
#include "scene_common.h"
#include "scenes/two_phase_keys.h"
#include "scenes/da_match.h"

/* the tip: where h falls below this share of h_inf */
#define TIP_SHARE 0.05
/* the front's length: from the tip back to where the exact h reaches this
 * share of h_inf */
#define FRONT_SHARE 0.95
/* the nose: where the exact h is below this share of h_inf (the last 3
 * h_inf), the body above it */
#define NOSE_SHARE 0.25
/* behind the front: columns where the exact h (in the front's frame) is
 * above this share of h_inf, BEHIND_SKIP depths past the feed */
#define BEHIND_SHARE 0.99
#define BEHIND_SKIP 5.0

struct front_params {
    double depth;           /* h_inf */
    double tip;             /* the tip's position at t = 0 */
    double precursor;       /* the grains' layer ahead of the front, in h_inf */
    double fluid_density;
    double fluid_viscosity;
    int mixture;            /* enum mixture_law */
    double viscosity_floor; /* the grains' viscosity floor in rho_g d sqrt(g d) */
    double vof_cfl;
    int da_cells;           /* the depth-averaged reference's cells per h_inf */
};

#define T struct front_params
static const struct key front_keys[] = {
    KEY_DBL(T, "front", "depth", depth,
            KEY_HELP("depth h_inf of the uniform layer fed at the inflow: at least two cells, "
                     "and a cell of air above it",
                     "length", NULL),
            KEY_GT0),
    KEY_DBL(T, "front", "tip", tip,
            KEY_HELP("position of the front's tip at t = 0 (the Pouliquen shape behind it): "
                     "inside (2 domain.lx / domain.nx, domain.lx)",
                     "length", NULL),
            KEY_GT0),
    KEY_DBL(T, "front", "precursor", precursor,
            "depth of a layer of grains on the bed ahead of the front, as a share of "
            "front.depth (0: a bare bed, whose air the nose overruns and traps at the base)",
            KEY_RANGE(0.0, 0.5, 1, 0)),
    TWO_PHASE_KEY_FLUID_DENSITY(T, "front"),
    TWO_PHASE_KEY_FLUID_VISCOSITY(T, "front"),
    TWO_PHASE_KEY_MIXTURE(T, "front", ""),
    TWO_PHASE_KEY_VISCOSITY_FLOOR(T, "front"),
    TWO_PHASE_KEY_VOF_CFL(T, "front"),
    KEY_INT(T, "front", "da_cells", da_cells,
            "cells of the depth-averaged front over the precursor (the nose's reference) per "
            "front.depth",
            KEY_RANGE(4, 1000, 1, 1)),
};
#undef T

/* Table 2 grains at 10 d deep, air of Table 1 (cases/front.ini) */
static void defaults(void *block)
{
    struct front_params *f = block;
    f->depth = 1.43e-3;
    f->tip = 0.06;
    f->precursor = 0.1;
    f->fluid_density = 1.0;
    f->fluid_viscosity = 1.48e-5;
    f->mixture = MIXTURE_WEIGHTED;
    f->viscosity_floor = 1.0;
    f->vof_cfl = 0.4;
    f->da_cells = 20;
}

SCENE_PARAMS(front_block, "front",
             "A uniform granular layer fed at the inflow (x = 0) runs down a rough incline ahead "
             "of its front, under air (Barker & Rauter 2018, sec. 4; `cases/front.ini`); its "
             "steady shape in the front's frame is compared with the depth-averaged front of "
             "Pouliquen (1999).  The grains are the case's `[rheology]` (mu(I)) with "
             "`physics.density` = phi rho_s; the scene needs `solver.mode = transient`, "
             "`boundary.xlo = inflow` (the scene gives its profile: the uniform layer's exact "
             "flow), `xhi = open`, `zlo = wall`, `zhi = open`, periodic y, `domain.ny = 1` and "
             "mu_s < tan(physics.tilt) < mu_s + delta_mu.  It writes `front.csv` (every step: t, "
             "the tip, x_half, the grains' volume, h's rms error), `shape.csv` (h(x) at the end, "
             "in the front's frame, with the exact shape and the depth-averaged front over the "
             "precursor) and `behind.csv` (the velocity profile behind the "
             "front with Bagnold's).",
             struct front_params, front_keys, defaults)

/* ---- the exact uniform layer and the depth-averaged front ---- */

/* The uniform layer of the case (depth, air) */
static struct layer_feed feed_of(const struct muflow_case *cs)
{
    const struct front_params *p = params(cs);
    return (struct layer_feed){cs, p->depth, p->fluid_density, p->fluid_viscosity};
}

/* u(z) of the uniform two-layer flow of depth h, its grains' mean speed */
static double uniform_u(const struct muflow_case *cs, double h, double z)
{
    struct layer_feed lf = feed_of(cs);
    return layer_uniform_u(&lf, h, z);
}

static double uniform_mean(const struct muflow_case *cs, double h)
{
    struct layer_feed lf = feed_of(cs);
    return layer_uniform_mean(&lf, h);
}

/* The speed of a front between the uniform layer of depth h_inf behind it
 * and the precursor's of depth h_p ahead: mass conservation across it,
 * (q_inf - q_p) / (h_inf - h_p), q = h u_mean(h); the uniform layer's mean
 * speed on a bare bed. */
static double front_speed_exact(const struct muflow_case *cs)
{
    double h = params(cs)->depth, hp = params(cs)->precursor * h;
    return (h * uniform_mean(cs, h) - (hp > 0.0 ? hp * uniform_mean(cs, hp) : 0.0)) / (h - hp);
}

static int front_exact(const struct muflow_case *cs, struct da_front *f)
{
    const struct rheology *r = &cs->rheo;
    double beta = 0.4 * sqrt(r->phi) * r->i0;
    return da_front_setup(f, cs->gravity, cs->tilt, 1.0, r->mu_s, r->mu_s + r->delta_mu, beta,
                          r->grain_diameter, params(cs)->depth);
}

/* The exact depth at xi: the front over the precursor layer */
static double exact_depth(const struct muflow_case *cs, const struct da_front *f, double xi)
{
    return fmax(da_front_depth(f, xi), params(cs)->precursor * f->h_inf);
}

/* The level of the tip: TIP_SHARE of the way from the precursor to h_inf */
static double tip_level(const struct muflow_case *cs, double h_inf)
{
    double hp = params(cs)->precursor * h_inf;
    return hp + TIP_SHARE * (h_inf - hp);
}

/* ---- check ---- */

static int check(const struct muflow_case *c, char *msg, size_t msglen)
{
    const struct front_params *p = params(c);
    if (layer_feed_check(c, "front", BC_OPEN, "open", msg, msglen))
        return 1;
    /* the depth-averaged friction of a Bagnold layer is Pouliquen's form
     * (the closed-form front) only for the jop curve's high-I branch */
    if (c->rheo.curve == CURVE_BARKER_GRAY && c->rheo.mu_inf != 0.0) {
        snprintf(msg, msglen, "rheology.mu_inf = %s: case.scene = front needs 0 with "
                              "rheology.curve = barker_gray (the depth-averaged front's friction "
                              "law is Pouliquen's only for the jop branch above I_1^N)",
                 num_text(c->rheo.mu_inf).s);
        return 1;
    }
    double dz = c->len[2] / c->n[2], dx = c->len[0] / c->n[0];
    if (!(scene_at_least_a_cell(p->depth, 2.0 * dz) && scene_at_least_a_cell(c->len[2] - p->depth, dz))) {
        snprintf(msg, msglen, "front.depth = %s: must be in [%.6g, %.6g]: at least two cells "
                              "(domain.lz / domain.nz = %.6g) and a cell of air above",
                 num_text(p->depth).s, 2.0 * dz, c->len[2] - dz, dz);
        return 1;
    }
    if (!(p->tip > 2.0 * dx && p->tip < c->len[0])) {
        snprintf(msg, msglen, "front.tip = %s: must be in (%.6g, %s): past the feed's column "
                              "and inside domain.lx",
                 num_text(p->tip).s, 2.0 * dx, num_text(c->len[0]).s);
        return 1;
    }
    return 0;
}

/* ---- the record: the front's positions at every step ---- */

enum { S_T, S_TIP, S_HALF, S_VOL, S_RMS, NSERIES };
static const char *const series_names[NSERIES] = {"t", "x_tip", "x_half", "grains_volume",
                                                  "h_err_rms"};

struct record {
    struct layer_record base; /* the columns S_*, the inflow's layer (the hook's context) */
    /* of the last state recorded, every rank's alike (the ranks' parts
     * reduced, so that rank 0 writes them alone): the heights h(x) and the
     * T = 1/2 contour's height of each column of the domain (nx each), the
     * mean u of the columns behind the front at each layer (nz; NaN
     * without such a column) */
    double *h, *contour, *behind;
    struct da_front f;        /* the exact front (setup makes sure there is one) */
    /* the depth-averaged front over the precursor at da_time: da_n depths
     * on cells of da_dx, its x_half (da_reference) */
    double *da_h, da_dx, da_half, da_time;
    int da_n;
};

static int create(struct march_state *st, void **state, char *err, size_t errlen)
{
    struct record *r = calloc(1, sizeof *r);
    const struct grid *G = march_global_grid(st);
    if (r) {
        r->h = malloc(2 * (size_t)G->n[0] * sizeof *r->h);
        r->behind = malloc((size_t)G->n[2] * sizeof *r->behind);
    }
    if (!r || !r->h || !r->behind) {
        if (r) {
            free(r->h);
            free(r->behind);
        }
        free(r);
        snprintf(err, errlen, "front: out of memory");
        return -1;
    }
    layer_series_init(&r->base.s, NSERIES, series_names);
    r->contour = r->h + G->n[0];
    front_exact(st->cs, &r->f);
    r->da_time = NAN;
    r->base.feed = feed_of(st->cs);
    *state = r;
    return 0;
}

static void destroy(void *state)
{
    struct record *r = state;
    if (r) {
        layer_series_free(&r->base.s);
        free(r->h);
        free(r->behind);
        free(r->da_h);
    }
    free(r);
}

static const struct module front_module = {
    .name = "front",
    .create = create,
    .end_step = layer_record_end_step,
    .save = layer_record_save,
    .load = layer_record_load,
    .destroy = destroy,
};

static struct record *record_of(const struct march_state *st)
{
    return march_module_state(st, &front_module);
}

/* xi of the exact front for column centre x, aligned at h_inf / 2 */
static double exact_xi(const struct da_front *f, double x, double x_half)
{
    return x - x_half + da_front_position(f, 0.5 * f->h_inf);
}

/* |h - h_exact| / h_inf over the front's length (from the tip back to where
 * the exact depth is FRONT_SHARE h_inf), the exact front aligned at x_half,
 * over the columns whose exact depth is at least above h_inf (0: all): its
 * root mean square, largest value and the count of columns. */
static int shape_error(const struct muflow_case *cs, const struct da_front *f,
                       const struct grid *g, const double *h, double x_half, double above,
                       double *rms, double *max)
{
    double xi_len = da_front_position(f, FRONT_SHARE * f->h_inf), s2 = 0.0;
    int n = 0;
    *max = 0.0;
    for (int i = 0; i < g->n[0]; i++) {
        double xi = exact_xi(f, (i + 0.5) * g->h[0], x_half);
        double he = exact_depth(cs, f, xi);
        if (xi < xi_len || xi > 0.0 || he < above * f->h_inf)
            continue;
        double e = (h[i] - he) / f->h_inf;
        s2 += e * e;
        *max = fmax(*max, fabs(e));
        n++;
    }
    *rms = n ? sqrt(s2 / n) : NAN;
    if (!n)
        *max = NAN;
    return n;
}

/* The largest |h - h_exact| / h_inf over the nose: the front's length
 * where the exact depth is below NOSE_SHARE h_inf */
static double nose_error(const struct muflow_case *cs, const struct da_front *f,
                         const struct grid *g, const double *h, double x_half)
{
    double xi_len = da_front_position(f, FRONT_SHARE * f->h_inf), max = 0.0;
    for (int i = 0; i < g->n[0]; i++) {
        double xi = exact_xi(f, (i + 0.5) * g->h[0], x_half);
        double he = exact_depth(cs, f, xi);
        if (xi >= xi_len && xi <= 0.0 && he < NOSE_SHARE * f->h_inf)
            max = fmax(max, fabs(h[i] - he) / f->h_inf);
    }
    return max;
}

static int column_behind(const struct da_front *f, const struct grid *g, int i, double x_half)
{
    double x = (i + 0.5) * g->h[0];
    return x > BEHIND_SKIP * f->h_inf &&
           da_front_depth(f, exact_xi(f, x, x_half)) >= BEHIND_SHARE * f->h_inf;
}

/* The mean u of the columns behind the front at each layer k (u[nz] of the
 * domain), the columns' count: each rank's columns (global i from 1) at
 * their global layers, summed over the ranks.  Collective. */
static int behind_profile(const struct march_state *st, const struct da_front *f, double x_half,
                          double *u)
{
    const struct grid *g = &st->g, *G = march_global_grid(st);
    const int i0 = scene_block_lo(st, 0), k0 = scene_block_lo(st, 2);
    int count = 0;
    for (int k = 0; k < G->n[2]; k++)
        u[k] = 0.0;
    for (int i = 1; i < G->n[0]; i++)
        count += column_behind(f, G, i, x_half);
    for (int i = i0 ? 0 : 1; i < g->n[0]; i++) {
        if (!column_behind(f, G, i0 + i, x_half))
            continue;
        for (int k = 0; k < g->n[2]; k++)
            u[k0 + k] += 0.5 * (st->field.velocity[0][grid_idx(g, i, 0, k)] +
                                st->field.velocity[0][grid_idx(g, i + 1, 0, k)]);
    }
    if (st->ranks)
        march_sum_array(st, u, G->n[2]);
    for (int k = 0; k < G->n[2]; k++)
        u[k] = count ? u[k] / count : NAN;
    return count;
}

/* The height of each column's T = 1/2 contour (c[nx] of the domain): from
 * the top down, the first cell at T >= 1/2, linear between its centre and
 * the one above (beside the integrated depth, it tells the VOF's smearing
 * from the shape); 0 without one.  A rank's topmost such cell whose
 * neighbour above (a rank border's ghost) is at T >= 1/2 too gives no
 * crossing: it is a rank's above; the ranks' largest.  Collective. */
static void column_contours(const struct march_state *st, const double *T, double *c)
{
    const struct grid *g = &st->g, *G = march_global_grid(st);
    const int i0 = scene_block_lo(st, 0), k0 = scene_block_lo(st, 2);
    for (int i = 0; i < G->n[0]; i++)
        c[i] = 0.0;
    for (int i = 0; i < g->n[0]; i++)
        for (int k = g->n[2] - 1; k >= 0; k--) {
            double t = T[grid_idx(g, i, 0, k)];
            if (t < 0.5)
                continue;
            double above = k0 + k + 1 < G->n[2] ? T[grid_idx(g, i, 0, k + 1)] : 0.0;
            if (above < 0.5)
                c[i0 + i] = (k0 + k + 0.5 + (t - 0.5) / (t - above)) * g->h[2];
            break;
        }
    if (st->ranks)
        march_max_array(st, c, G->n[0]);
}

static int record_step(void *rec, const struct march_state *st)
{
    struct record *r = rec;
    const double *T = collapse_tracer(st);
    if (!T)
        return 0;
    /* the columns of this state, on every rank (the write's, rank 0's) */
    const struct grid *g = march_global_grid(st);
    double hi = r->f.h_inf, vol = 0.0, mx, **v = r->base.s.v;
    layer_columns(st, T, r->h, 0);
    column_contours(st, T, r->contour);
    const double x_half = layer_crossing(r->h, g->n[0], g->h[0], 0.5 * hi);
    behind_profile(st, &r->f, x_half, r->behind);
    int rc = layer_series_row(&r->base.s, st->step);
    if (rc != 0)
        return rc > 0 ? 0 : -1;
    long n = r->base.s.n - 1;
    for (int i = 0; i < g->n[0]; i++)
        vol += r->h[i] * g->h[0];
    v[S_T][n] = st->time;
    v[S_TIP][n] = layer_crossing(r->h, g->n[0], g->h[0], tip_level(st->cs, hi));
    v[S_HALF][n] = x_half;
    v[S_VOL][n] = vol;
    shape_error(st->cs, &r->f, g, r->h, v[S_HALF][n], 0.0, &v[S_RMS][n], &mx);
    return 0;
}

/* ---- the driver: the march, recorded ---- */

static int drive(struct scene_drive *d)
{
    struct recorded_drive rd = {.record_step = record_step,
                                .rec = record_of(d->st),
                                .record_name = "the front's record"};
    recorded_drive_run(d, &rd);
    return 0;
}

/* ---- the depth-averaged front over the precursor ---- */

/* The closed form leaves out the momentum flux and the precursor, which
 * the nose meets near the critical Froude number; the depth-averaged
 * equations (docs/numerics/depth-averaged.md) solved on the scene's
 * problem keep both: chi = 5/4 (Bagnold's profile, the layer's behind the
 * front), K = 1, Pouliquen's friction matched to mu(I) (scenes/da_match.h). */
#define DA_CHI 1.25

struct da_layer {
    double h, u;
};

static void da_layer_state(void *ctx, double x, double t, double *h, double *u)
{
    (void)x;
    (void)t;
    const struct da_layer *l = ctx;
    *h = l->h;
    *u = l->u;
}

/* The model's uniform flow of depth h: mu_b(h, u) = tan zeta */
static double da_uniform_speed(const struct da_params *p, double g, double zeta, double h)
{
    double fr = p->beta * h / (p->L * ((p->mu2 - p->mu1) / (tan(zeta) - p->mu1) - 1.0));
    return fr * sqrt(g * cos(zeta) * h);
}

/* The model on [0, lx] at time t: fed with the uniform layer of h_inf at
 * x = 0, open at lx, from the Pouliquen front with its tip at front.tip
 * over the precursor, each layer at its own uniform speed (as the 2D run
 * starts); front.da_cells cells per h_inf.  Fills r->da_*; -1 if the model
 * cannot be set up or run. */
static int da_reference(const struct muflow_case *cs, struct record *r, double t)
{
    if (r->da_h && r->da_time == t)
        return 0;
    const struct front_params *fp = params(cs);
    struct da_params p = da_params_matched(cs);
    p.chi = DA_CHI;
    double zeta = cs->tilt, hi = fp->depth, hp = fp->precursor * hi;
    struct da_layer feed = {hi, da_uniform_speed(&p, cs->gravity, zeta, hi)};
    double up = hp > 0.0 ? da_uniform_speed(&p, cs->gravity, zeta, hp) : 0.0;
    int n = (int)ceil(fp->da_cells * cs->len[0] / hi);
    double dx = cs->len[0] / n;
    double *h = realloc(r->da_h, (size_t)n * sizeof *h), *buf = malloc(2 * (size_t)n * sizeof *buf);
    if (!h || !buf) {
        free(buf);
        if (h)
            r->da_h = h;
        return -1;
    }
    r->da_h = h;
    double *m = buf, *zetas = buf + n;
    for (int i = 0; i < n; i++) {
        double hf = da_front_depth(&r->f, (i + 0.5) * dx - fp->tip);
        h[i] = fmax(hf, hp);
        m[i] = hf > hp ? hf * feed.u : hp * up;
        zetas[i] = zeta;
    }
    struct da_bc in = {.kind = DA_BC_GIVEN, .ghost = da_layer_state, .ctx = &feed};
    struct da_bc out = {.kind = DA_BC_OPEN};
    struct da_solver *so = da_create(n, 0.0, dx, zetas, &p, in, out, NULL, 0);
    int rc = so && da_advance(so, h, m, 0.0, t) >= 0 ? 0 : -1;
    da_free(so);
    free(buf);
    r->da_n = n;
    r->da_dx = dx;
    r->da_half = layer_crossing(h, n, dx, 0.5 * hi);
    r->da_time = rc == 0 ? t : NAN;
    return rc;
}

/* The model's depth at the 2D column centre x, the two fronts aligned at
 * h_inf / 2 (the 2D's at x_half): linear between its centres */
static double da_depth_at(const struct record *r, double x, double x_half)
{
    double s = (x - x_half + r->da_half) / r->da_dx - 0.5;
    if (s <= 0.0)
        return r->da_h[0];
    int i = (int)s;
    if (i >= r->da_n - 1)
        return r->da_h[r->da_n - 1];
    return r->da_h[i] + (s - i) * (r->da_h[i + 1] - r->da_h[i]);
}

/* Over the front's length (the columns shape_error takes), |h - h_da| /
 * h_inf: its rms, its largest over the body (exact h >= NOSE_SHARE h_inf)
 * and over the nose (the rest); and the model's own largest |h_da -
 * h_exact| / h_inf over the nose, on its cells. */
struct da_errors {
    double rms, body_max, nose_max, model_nose_max;
};

static void da_shape_errors(const struct muflow_case *cs, const struct record *r,
                            const struct grid *g, double x_half, struct da_errors *e)
{
    const struct da_front *f = &r->f;
    double xi_len = da_front_position(f, FRONT_SHARE * f->h_inf), s2 = 0.0;
    int n = 0;
    *e = (struct da_errors){0};
    for (int i = 0; i < g->n[0]; i++) {
        double x = (i + 0.5) * g->h[0], xi = exact_xi(f, x, x_half);
        if (xi < xi_len || xi > 0.0)
            continue;
        double he = exact_depth(cs, f, xi);
        double err = fabs(r->h[i] - da_depth_at(r, x, x_half)) / f->h_inf;
        s2 += err * err;
        n++;
        if (he >= NOSE_SHARE * f->h_inf)
            e->body_max = fmax(e->body_max, err);
        else
            e->nose_max = fmax(e->nose_max, err);
    }
    e->rms = n ? sqrt(s2 / n) : NAN;
    /* the model against the closed form on its own cells */
    for (int j = 0; j < r->da_n; j++) {
        double xi = exact_xi(f, (j + 0.5) * r->da_dx, r->da_half), he = exact_depth(cs, f, xi);
        if (xi >= xi_len && xi <= 0.0 && he < NOSE_SHARE * f->h_inf)
            e->model_nose_max = fmax(e->model_nose_max, fabs(r->da_h[j] - he) / f->h_inf);
    }
}

/* ---- the measures at the end ---- */

struct front_measures {
    double speed, speed_exact;  /* the fit of x_half(t); front_speed_exact */
    double h_rms, h_max;        /* |h - h_exact| / h_inf over the front's length */
    double body_rms, body_max;  /* the same without the nose (h_exact < NOSE_SHARE h_inf) */
    double nose_max;            /* the largest over the nose */
    double h_behind;            /* the mean depth behind the front */
    double nose;                /* (tip - x_half) - its exact value, in h_inf */
    double u_rms, u_surface;    /* the profile behind: error / u_surface, the exact top */
    int columns, behind;        /* columns in the front's length, behind it */
};

/* The grains' flux ahead of the front, sum_k T u dz on the x-faces from
 * BEHIND_SKIP depths past the tip to as many before the open end, averaged
 * over those faces (NAN if none): the precursor's, against its uniform
 * flow's h_p u_mean(h_p). */
static double precursor_flux(const struct march_state *st, double x_tip, double h_inf)
{
    const struct grid *g = &st->g, *G = march_global_grid(st);
    const double *T = collapse_tracer(st);
    const double lo = x_tip + BEHIND_SKIP * h_inf, hi = st->cs->len[0] - BEHIND_SKIP * h_inf;
    double q = 0.0;
    int n = 0;
    for (int i = 1; T && i < G->n[0]; i++)
        n += !(i * G->h[0] < lo || i * G->h[0] > hi);
    /* this rank's faces (global index from 1; the cell below a rank
     * border's face 0 is its ghost), summed over the ranks */
    const int i0 = scene_block_lo(st, 0);
    for (int i = i0 ? 0 : 1; T && i < g->n[0]; i++) {
        double x = (i0 + i) * g->h[0];
        if (x < lo || x > hi)
            continue;
        for (int k = 0; k < g->n[2]; k++)
            q += 0.5 * (T[grid_idx(g, i - 1, 0, k)] + T[grid_idx(g, i, 0, k)]) *
                 st->field.velocity[0][grid_idx(g, i, 0, k)] * g->h[2];
    }
    q = march_sum(st, q);
    return n ? q / n : NAN;
}

/* The least-squares slope of x_half(t) over the second half of the record. */
static double speed_fit(const struct record *r)
{
    const struct layer_series *s = &r->base.s;
    if (s->n < 4)
        return NAN;
    return layer_series_slope(s, S_T, S_HALF, 0.5 * (s->v[S_T][0] + s->v[S_T][s->n - 1]));
}

static void measure(const struct march_state *st, const struct record *r,
                    struct front_measures *m)
{
    const struct muflow_case *cs = st->cs;
    const struct grid *g = march_global_grid(st);
    const struct da_front *f = &r->f;
    *m = (struct front_measures){.speed = speed_fit(r), .speed_exact = front_speed_exact(cs)};
    double hi = f->h_inf, x_half = r->base.s.v[S_HALF][r->base.s.n - 1], hb = 0.0;
    m->columns = shape_error(cs, f, g, r->h, x_half, 0.0, &m->h_rms, &m->h_max);
    shape_error(cs, f, g, r->h, x_half, NOSE_SHARE, &m->body_rms, &m->body_max);
    m->nose_max = nose_error(cs, f, g, r->h, x_half);
    for (int i = 0; i < g->n[0]; i++)
        if (column_behind(f, g, i, x_half)) {
            hb += r->h[i];
            m->behind++;
        }
    m->h_behind = m->behind ? hb / m->behind : NAN;
    m->nose = (r->base.s.v[S_TIP][r->base.s.n - 1] - x_half -
               (da_front_position(f, tip_level(cs, hi)) - da_front_position(f, 0.5 * hi))) / hi;
    double *u = malloc((size_t)g->n[2] * sizeof *u);
    m->u_surface = uniform_u(cs, hi, hi);
    m->u_rms = NAN;
    if (u && behind_profile(st, f, x_half, u) > 0) {
        double e2 = 0.0;
        int n = 0;
        for (int k = 0; k < g->n[2] && (k + 1) * g->h[2] <= hi * (1.0 + 1e-12); k++, n++) {
            double e = (u[k] - uniform_u(cs, hi, (k + 0.5) * g->h[2])) / m->u_surface;
            e2 += e * e;
        }
        m->u_rms = n ? sqrt(e2 / n) : NAN;
    }
    free(u);
}

static void results(const struct march_state *st, const struct scene_drive *d,
                    struct run_result *res)
{
    (void)d;
    struct record *r = record_of(st);
    if (!r || r->base.s.n == 0)
        return;
    struct front_measures m;
    measure(st, r, &m);
    double uf = r->f.u_f;
    run_result_add_compared(res, "front_speed", m.speed, m.speed_exact);
    run_result_add(res, "uniform_speed", "%.10g", uniform_mean(st->cs, r->f.h_inf));
    run_result_add(res, "front_speed_depth_averaged", "%.10g", uf);
    run_result_add(res, "x_tip", "%.10g", r->base.s.v[S_TIP][r->base.s.n - 1]);
    run_result_add(res, "x_half", "%.10g", r->base.s.v[S_HALF][r->base.s.n - 1]);
    run_result_add(res, "h_err_rms", "%.6e", m.h_rms);
    run_result_add(res, "h_err_max", "%.6e", m.h_max);
    run_result_add(res, "h_columns", "%d", m.columns);
    run_result_add(res, "h_err_rms_body", "%.6e", m.body_rms);
    run_result_add(res, "h_err_max_body", "%.6e", m.body_max);
    run_result_add(res, "h_behind_error", "%.6e", m.h_behind / params(st->cs)->depth - 1.0);
    run_result_add(res, "nose_offset", "%.6e", m.nose);
    run_result_add(res, "profile_err_rms", "%.6e", m.u_rms);
    double hp = params(st->cs)->precursor * r->f.h_inf;
    run_result_add(res, "precursor_flux", "%.6e",
                   precursor_flux(st, r->base.s.v[S_TIP][r->base.s.n - 1], r->f.h_inf));
    run_result_add(res, "precursor_flux_exact", "%.6e", hp * uniform_mean(st->cs, hp));
    /* the nose against the closed form, and the depth-averaged front over
     * the precursor as the reference of the whole shape */
    run_result_add(res, "h_err_max_nose", "%.6e", m.nose_max);
    struct da_errors e;
    if (da_reference(st->cs, r, st->time) == 0) {
        da_shape_errors(st->cs, r, march_global_grid(st), r->base.s.v[S_HALF][r->base.s.n - 1],
                        &e);
        run_result_add(res, "h_err_rms_depth_averaged", "%.6e", e.rms);
        run_result_add(res, "h_err_max_body_depth_averaged", "%.6e", e.body_max);
        run_result_add(res, "h_err_max_nose_depth_averaged", "%.6e", e.nose_max);
        run_result_add(res, "depth_averaged_nose_err_max", "%.6e", e.model_nose_max);
    }
    snprintf(res->scene_line, sizeof res->scene_line,
             "front speed %.6g (exact %.6g, %+.2f %%)  h(x) rms %.2f %% max %.2f %% of h_inf "
             "over %d columns  profile behind rms %.2f %%",
             m.speed, m.speed_exact, 100.0 * (m.speed / m.speed_exact - 1.0), 100.0 * m.h_rms,
             100.0 * m.h_max, m.columns, 100.0 * m.u_rms);
}

/* front.csv: the record; shape.csv: h(x) (and the T = 1/2 contour's
 * height) in the front's frame with the exact shape; behind.csv: the
 * profile behind the front with Bagnold's. */
static int write(const char *dir, const struct march_state *st, char *err, size_t errlen)
{
    struct record *r = record_of(st);
    if (!r || r->base.s.n == 0)
        return 0;
    const struct da_front f = r->f;
    /* the domain's columns as the last record_step left them: rank 0's
     * alone writes (no collective here) */
    const struct grid *g = march_global_grid(st);
    struct output_file o;
    /* the depth-averaged front at the end only (a run of its own each time) */
    int da = st->status != STATUS_RUNNING && da_reference(st->cs, r, st->time) == 0;
    if (output_open(&o, dir, "front.csv", err, errlen) != 0)
        return -1;
    fprintf(o.f, "t,x_tip,x_half,grains_volume,h_err_rms\n");
    const struct layer_series *s = &r->base.s;
    for (long m = 0; m < s->n; m++)
        fprintf(o.f, "%.10g,%.10g,%.10g,%.16e,%.6e\n", s->v[S_T][m], s->v[S_TIP][m],
                s->v[S_HALF][m], s->v[S_VOL][m], s->v[S_RMS][m]);
    if (output_commit(&o, err, errlen) != 0)
        return -1;
    double x_half = r->base.s.v[S_HALF][r->base.s.n - 1];
    if (output_open(&o, dir, "shape.csv", err, errlen) != 0)
        return -1;
    fprintf(o.f, "x,xi,h,h_exact,h_contour,h_depth_averaged\n");
    for (int i = 0; i < g->n[0]; i++) {
        double x = (i + 0.5) * g->h[0], xi = exact_xi(&f, x, x_half);
        fprintf(o.f, "%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n", x, xi, r->h[i],
                exact_depth(st->cs, &f, xi), r->contour[i], da ? da_depth_at(r, x, x_half) : NAN);
    }
    if (output_commit(&o, err, errlen) != 0)
        return -1;
    if (output_open(&o, dir, "behind.csv", err, errlen) != 0)
        return -1;
    fprintf(o.f, "z,u,u_exact\n");
    for (int k = 0; k < g->n[2]; k++)
        fprintf(o.f, "%.10g,%.10g,%.10g\n", (k + 0.5) * g->h[2], r->behind[k],
                uniform_u(st->cs, f.h_inf, (k + 0.5) * g->h[2]));
    return output_commit(&o, err, errlen);
}

/* ---- set-up: the Pouliquen front, moving with Bagnold's profile ---- */

static int setup(struct march_state *st, char *err, size_t errlen)
{
    const struct muflow_case *cs = st->cs;
    const struct front_params *p = params(cs);
    struct record *r = record_of(st);
    double *T = layer_feed_configure(st, &r->base.feed, p->mixture, p->viscosity_floor, 1,
                                     p->vof_cfl, err, errlen);
    if (!T)
        return -1;
    const struct da_front f = r->f;
    const struct grid *g = &st->g;
    double L = cs->len[2], rf = p->fluid_density, gs = cs->gravity * sin(cs->tilt);
    double ubar = uniform_mean(cs, p->depth), film = rf * gs / (2.0 * p->fluid_viscosity);
    double hp = p->precursor * p->depth;
    const int i0 = scene_block_lo(st, 0), k0 = scene_block_lo(st, 2); /* this rank's block */
    for (int i = grid_slot_lo(g, 0); i <= grid_slot_hi(g, 0); i++) {
        /* the column's depth at its centre (T) and at its low face (u);
         * the precursor, thinner than the front's, as its own uniform flow */
        const int gi = i0 + i;
        double hc = gi == 0 ? p->depth : da_front_depth(&f, (gi + 0.5) * g->h[0] - p->tip);
        double hf = gi <= 0 ? p->depth : da_front_depth(&f, gi * g->h[0] - p->tip);
        for (int j = grid_slot_lo(g, 1); j <= grid_slot_hi(g, 1); j++)
            for (int k = 0; k < g->n[2]; k++) {
                double z = (k0 + k + 0.5) * g->h[2], u;
                if (hf > hp) {
                    u = (5.0 / 3.0) * ubar * (1.0 - pow(1.0 - fmin(z / hf, 1.0), 1.5));
                    if (z > hf)
                        u += film * ((L - hf) * (L - hf) - (L - z) * (L - z));
                } else {
                    u = hp > 0.0 ? uniform_u(cs, hp, z) : film * (L * L - (L - z) * (L - z));
                }
                st->field.velocity[0][grid_idx(g, i, j, k)] = u;
                if (i >= 0 && i < g->n[0])
                    T[grid_idx(g, i, j, k)] = layer_fraction(fmax(hc, hp), k0 + k, g->h[2]);
            }
    }
    return two_phase_tracer_changed(st, err, errlen);
}

static const struct module *const front_modules[] = {&two_phase_module, &front_module, NULL};
static const char *const front_files[] = {"front.csv", "shape.csv", "behind.csv", NULL};

const struct scene scene_front = {
    .name = "front",
    .title = "a granular front fed by a uniform layer on an incline under air, two phases "
             "(Pouliquen 1999; Barker & Rauter 2018)",
    .keys = &front_block,
    .modules = front_modules,
    .check = check,
    .setup = setup,
    .decomposed = scene_decomposed_always,
    .profile_axis = -1,
    .profile_component = -1,
    .drive = drive,
    .results = results,
    .write = write,
    .files = front_files,
    .write_running = 1,
};
