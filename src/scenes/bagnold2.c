/* Scene "bagnold2": a granular layer of height h0 under a Newtonian fluid
 * (air) in a square domain L x L, periodic along the flow, no slip at the
 * base, inclined by zeta (Barker & Rauter 2018, "Two-fluid
 * regularised mu(I)-rheology with OpenFOAM", sec. 2-3; cases/bagnold2.ini).  The two
 * phases are the two_phase module's mixture (physics/two_phase.h); the
 * interface is flat and held, so the steady state is the exact solution.
 *
 * Exact solution (Barker & Rauter 2018, eqs. 6-11, written from their derivation; the
 * printed constants have sign slips).  A flow uniform along x has the
 * weight of what lies above as its stresses, the top carrying none:
 *   tau(z) = g sin(zeta) q(z),  P(z) = g cos(zeta) q(z),
 *   q(z) = rho_g (h0 - z) + rho_f (L - h0)   (z < h0),  rho_f (L - z)  (z > h0),
 * rho_g = phi rho_s the grains' bulk density.  In the grains |tau| / P =
 * |tan(zeta)| = mu(I), so I = I_zeta = mu^-1(|tan(zeta)|) is uniform, and
 *   du/dz = sign(zeta) (I_zeta / d) sqrt(P / rho_s), u(0) = 0:
 *   u(z) = sign(zeta) (2 I_zeta / (3 d rho_g)) sqrt(g cos(zeta) / rho_s)
 *          [q(0)^(3/2) - q(z)^(3/2)]                               (z < h0);
 * the fluid, eta_f du/dz = tau = rho_f g sin(zeta) (L - z), continuous at h0:
 *   u(z) = u(h0) + (rho_f g sin(zeta) / (2 eta_f)) [(L - h0)^2 - (L - z)^2].
 * Below the yield angle (|tan(zeta)| <= mu_s with the jop curve) the grains
 * carry their load at rest, I_zeta = 0: u = 0 in the grains and the fluid is
 * a film driven by gravity over a static no-slip bed.  A negative tilt is
 * the mirror image (u -> -u).  None exists (NaN, exact_missing says why)
 * where the friction cannot balance the weight (|tan(zeta)| >= mu_s +
 * delta_mu with the jop curve: the layer accelerates), where a confining
 * pressure makes the friction vary with depth in flowing grains, where
 * walls across y or an obstacle make the flow non-uniform.  The top is the
 * paper's open top (`open`: p = 0, du/dz = 0, flow through it allowed) or
 * the flat stress-free `surface` (p = 0, du/dz = 0, w = 0), which for this
 * flat, unidirectional state is the same. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "diagnostics/growth.h"
#include "diagnostics/profile.h"
#include "march/module_record.h"
#include "io/output.h"
#include "physics/obstacle.h"
#include "physics/two_phase.h"
#include "scenes/bagnold2.h"
#include "scenes/perturbation.h"
#include "scenes/scene.h"
#include "scenes/recorded_drive.h"
#include "scene_common.h"
#include "scenes/two_phase_keys.h"

struct bagnold2_params {
    double interface_height;   /* h0 */
    double fluid_density;      /* rho_f */
    double fluid_viscosity;    /* eta_f */
    int mixture;               /* enum mixture_law */
    int interface_edges;       /* enum edge_mixing */
    int start;                 /* enum start_state */
    double perturbation;       /* of the initial velocity, relative to u_top */
};

enum start_state { START_REST = 0, START_EXACT };

/* `mean` (the mixture law at the mean T of an edge's four cells) is the
 * collapse's; here it smeared the interface over two edges and, with the
 * interface 0.3 of a cell above a face, did not settle (u_top 0.46 m/s,
 * exact 0.045) */
static const struct choice edge_choices[] = {{"series", EDGES_SERIES}, {NULL, 0}};
static const struct choice start_choices[] = {
    {"rest", START_REST}, {"exact", START_EXACT}, {NULL, 0}};

#define T struct bagnold2_params
static const struct key bagnold2_keys[] = {
    KEY_DBL(T, "bagnold2", "interface_height", interface_height,
            KEY_HELP("height h0 of the flat grains/fluid interface above the base: the grains "
                     "and the fluid above them each at least a cell, domain.lz / domain.nz",
                     "length", NULL),
            KEY_GT0),
    TWO_PHASE_KEY_FLUID_DENSITY(T, "bagnold2"),
    TWO_PHASE_KEY_FLUID_VISCOSITY(T, "bagnold2"),
    TWO_PHASE_KEY_MIXTURE(T, "bagnold2", ""),
    KEY_CHO(T, "bagnold2", "interface_edges", interface_edges, edge_choices,
            "viscosity of an edge the interface cuts: series (the two phases in series over "
            "their parts of its link, cut from the reconstructed interface, each at its own "
            "shear rate, stress and pressure; the only choice)"),
    KEY_CHO(T, "bagnold2", "start", start, start_choices,
            "initial velocity: rest, or exact (the steady solution of eqs. 6-11 on the faces)"),
    KEY_DBL(T, "bagnold2", "perturbation", perturbation,
            KEY_HELP("largest velocity of a divergence-free perturbation (a pseudo-random stream "
                     "function in the grains) added to the initial state, relative to the exact "
                     "top velocity; 0: none",
                     NULL,
                     "Largest velocity of a divergence-free perturbation added to the initial "
                     "state, relative to the exact top velocity: a pseudo-random stream function "
                     "on the x-z nodes (the same on any number of threads) times sin^2(pi z / h0) "
                     "in the grains, 0 in the air, so every wavelength of the grid is seeded; a "
                     "transient run records its amplitude (`growth.csv`) and growth rate "
                     "(`growth_rate`); `0`: none"),
            KEY_GE0),
};
#undef T

/* Table 1 of Barker & Rauter (2018) */
static void defaults(void *block)
{
    struct bagnold2_params *b = block;
    b->interface_height = 5e-4;
    b->fluid_density = 1.0;
    b->fluid_viscosity = 1.48e-5;
    b->mixture = MIXTURE_WEIGHTED;
    b->interface_edges = EDGES_SERIES;
    b->start = START_REST;
    b->perturbation = 0.0;
}

SCENE_PARAMS(bagnold2_block, "bagnold2",
             "A granular layer under a Newtonian fluid (Barker & Rauter 2018, sec. 2-3; "
             "`cases/bagnold2.ini`).  The grains are the case's `[rheology]` (mu(I)) with "
             "`physics.density` their bulk density phi rho_s.  A transient run writes "
             "`growth.csv` (every step: t, the largest departure of the grains' velocity and of "
             "their pressure from the mean along x) and adds `growth_rate` (1/s, the "
             "least-squares slope of ln A over the second half of the record before A reaches 1% "
             "of the exact top velocity), `growth_rate_pressure`, `growth_fit_r2`, "
             "`growth_window`, `amplitude_start` and `amplitude_end` to the summary (its record "
             "is in the checkpoint: a growth study continues with `--restart`).  Where the scene "
             "has no exact solution the summary's `no_exact_solution` says why.",
             struct bagnold2_params, bagnold2_keys, defaults)

static double bagnold2_u(const struct muflow_case *cs, double z);
static const char *exact_missing(const struct muflow_case *cs, char *why, size_t len);

static int check(const struct muflow_case *c, char *msg, size_t msglen)
{
    const struct bagnold2_params *b = params(c);
    if (c->rheo.law != LAW_MUI) {
        snprintf(msg, msglen, "case.scene = bagnold2 needs rheology.law = mui");
        return 1;
    }
    if (c->bc.face[0][0] != BC_PERIODIC || c->bc.face[2][0] != BC_WALL ||
        (c->bc.face[2][1] != BC_SURFACE && c->bc.face[2][1] != BC_OPEN)) {
        snprintf(msg, msglen, "case.scene = bagnold2 needs boundary.xlo = boundary.xhi = periodic, "
                              "boundary.zlo = wall and boundary.zhi = surface or open");
        return 1;
    }
    /* the grains and the fluid above them each at least a cell thick (a
     * ninth of a cell was accepted and ran as a cell of mixture) */
    double lz = c->len[2], dz = lz / c->n[2];
    if (!scene_layer_fits(b->interface_height, lz, dz)) {
        snprintf(msg, msglen, "bagnold2.interface_height = %s: the grains and the fluid above "
                              "them must each be at least a cell thick (domain.lz / domain.nz = "
                              "%s / %d = %.6g): bagnold2.interface_height must be in [%.6g, %.6g]",
                 num_text(b->interface_height).s, num_text(lz).s, c->n[2], dz, dz, lz - dz);
        return 1;
    }
    double rg = c->rheo.phi * c->rheo.grain_density;
    if (fabs(c->density - rg) > 1e-12 * rg) {
        snprintf(msg, msglen, "physics.density = %s: the grains' bulk density must be "
                              "rheology.phi * rheology.grain_density = %s * %s = %.10g",
                 num_text(c->density).s, num_text(c->rheo.phi).s,
                 num_text(c->rheo.grain_density).s, rg);
        return 1;
    }
    char why[256];
    if ((b->start == START_EXACT || b->perturbation > 0.0) && exact_missing(c, why, sizeof why)) {
        snprintf(msg, msglen,
                 "bagnold2.start = exact or bagnold2.perturbation > 0 needs the exact steady "
                 "solution of eqs. (6)-(11), which this case does not have: %s", why);
        return 1;
    }
    if (b->perturbation > 0.0 && !(bagnold2_u(c, c->len[2]) != 0.0)) {
        snprintf(msg, msglen,
                 "bagnold2.perturbation > 0 is relative to the exact top velocity, which is 0 at "
                 "physics.tilt = %s and physics.gravity = %s (nothing moves)",
                 num_text(c->tilt).s, num_text(c->gravity).s);
        return 1;
    }
    return 0;
}

/* Why the case has no exact steady solution, or NULL when it has one: a
 * short reason returned (the summary's), the full one into why (the
 * terminal's). */
static const char *exact_missing(const struct muflow_case *cs, char *why, size_t len)
{
    const struct rheology *r = &cs->rheo;
    double ta = fabs(tan(cs->tilt));
    for (int s = 0; s < 2; s++) {
        enum bc_kind k = cs->bc.face[1][s];
        if (k != BC_PERIODIC && k != BC_SLIP && k != BC_SURFACE) {
            snprintf(why, len, "boundary.%s = %s holds the flow across y: it is not uniform",
                     s ? "yhi" : "ylo", bc_kind_name(k));
            return "the flow varies across y (boundary.ylo, yhi)";
        }
    }
    if (case_obstacle_active(cs)) {
        snprintf(why, len, "obstacle.shapes puts a body in the flow: it is not uniform");
        return "a body in the flow (obstacle.shapes)";
    }
    double iz = rheology_i_of_mu(r, ta);
    if (!isfinite(iz)) {
        snprintf(why, len,
                 "|tan(physics.tilt)| = %.6g is at or above rheology.mu_s + delta_mu = %.6g: "
                 "the friction cannot hold the weight, the layer accelerates without end",
                 ta, r->mu_s + r->delta_mu);
        return "|tan(physics.tilt)| >= mu_s + delta_mu: the layer accelerates";
    }
    if (iz > 0.0 && cs->confining_pressure > 0.0) {
        snprintf(why, len,
                 "physics.confining_pressure = %.6g > 0 in flowing grains: the friction "
                 "varies with depth",
                 cs->confining_pressure);
        return "physics.confining_pressure > 0 in flowing grains";
    }
    return NULL;
}

static double bagnold2_u(const struct muflow_case *cs, double z)
{
    char why[256];
    if (exact_missing(cs, why, sizeof why))
        return NAN;
    const struct rheology *r = &cs->rheo;
    const struct bagnold2_params *b = params(cs);
    /* the I at which the curve reaches |tan(zeta)| (0 below mu_s: at rest) */
    double iz = rheology_i_of_mu(r, fabs(tan(cs->tilt)));
    double sign = cs->tilt < 0.0 ? -1.0 : 1.0;
    double L = cs->len[2], h0 = b->interface_height, rf = b->fluid_density;
    double rs = r->grain_density, rg = r->phi * rs, d = r->grain_diameter;
    double gc = cs->gravity * cos(cs->tilt), gs = cs->gravity * sin(cs->tilt);
    /* du/dz = (I / d) sqrt(P / rho_s), P = gc (rg (h0 - z) + rf (L - h0)) */
    double k = sign * (iz / d) * sqrt(gc / rs) * 2.0 / (3.0 * rg);
    double zz = fmin(z, h0);
    double P0 = rg * h0 + rf * (L - h0), Pz = rg * (h0 - zz) + rf * (L - h0);
    double u = iz > 0.0 ? k * (P0 * sqrt(P0) - Pz * sqrt(Pz)) : 0.0;
    if (z > h0)
        u += (rf * gs / (2.0 * b->fluid_viscosity)) * ((L - h0) * (L - h0) - (L - z) * (L - z));
    return u;
}

static void exact_profile(const struct muflow_case *cs, int n, const double *x, double *u)
{
    for (int i = 0; i < n; i++)
        u[i] = bagnold2_u(cs, x[i]);
}

/* The share of layer k (cells of height h) below the flat interface at h0. */
static double layer_fraction(double h0, int k, double h)
{
    return fmin(1.0, fmax(0.0, (h0 - k * h) / h));
}

/* The flat interface at h0: each cell's fraction below it. */
static int setup(struct march_state *st, char *err, size_t errlen)
{
    const struct bagnold2_params *b = params(st->cs);
    /* steady mode holds the flat interface; a transient run carries it */
    const struct two_phase_params tp = {.fluid_density = b->fluid_density,
                                        .fluid_viscosity = b->fluid_viscosity,
                                        .mixture = (enum mixture_law)b->mixture,
                                        .edges = (enum edge_mixing)b->interface_edges,
                                        .transported = st->cs->mode == MODE_TRANSIENT,
                                        .layered = 1};
    double *T = two_phase_configure(st, &tp, err, errlen);
    if (!T)
        return -1;
    const struct grid *g = &st->g;
    double h = g->h[2];
    const int k0 = scene_block_lo(st, 2); /* this rank's first layer */
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++)
                T[grid_idx(g, i, j, k)] = layer_fraction(b->interface_height, k0 + k, h);
    if (b->start == START_EXACT)
        for (int i = grid_slot_lo(g, 0); i <= grid_slot_hi(g, 0); i++)
            for (int j = grid_slot_lo(g, 1); j <= grid_slot_hi(g, 1); j++)
                for (int k = 0; k < g->n[2]; k++)
                    st->field.velocity[0][grid_idx(g, i, j, k)] =
                        bagnold2_u(st->cs, (k0 + k + 0.5) * h);
    /* the stream function of each x-z plane, in the grains (sin^2(pi z / h0)
     * below the interface, 0 above: the air starts unperturbed), every
     * wavelength of the grid seeded, so which one grows fastest is measured,
     * not chosen */
    if (b->perturbation > 0.0)
        perturbation_add(st, PERTURB_XZ, b->interface_height,
                         b->perturbation * fabs(bagnold2_u(st->cs, st->cs->len[2])));
    return two_phase_tracer_changed(st, err, errlen);
}

/* ---- the growth record: the perturbation's amplitude at every step ---- */

struct growth_record {
    double *t, *au, *ap;   /* time, velocity and pressure amplitudes */
    long n, cap;
    long last_step;
};

static int record_create(struct march_state *st, void **state, char *err, size_t errlen)
{
    (void)st;
    struct growth_record *r = calloc(1, sizeof *r);
    if (!r) {
        snprintf(err, errlen, "bagnold2: out of memory");
        return -1;
    }
    r->last_step = -1;
    *state = r;
    return 0;
}

static void record_destroy(void *state)
{
    struct growth_record *r = state;
    if (r) {
        free(r->t);
        free(r->au);
        free(r->ap);
    }
    free(r);
}

/* The record in the checkpoint: a continued run's growth.csv and growth
 * fit are the uninterrupted run's. */
static int record_save(const struct march_state *st, void *state, struct module_record *rec)
{
    (void)st;
    const struct growth_record *r = state;
    double last = (double)r->last_step;
    if (module_record_put(rec, "last_step", &last, 1) != 0 ||
        module_record_put(rec, "t", r->t, r->n) != 0 ||
        module_record_put(rec, "amplitude_velocity", r->au, r->n) != 0 ||
        module_record_put(rec, "amplitude_pressure", r->ap, r->n) != 0)
        return -1;
    return 0;
}

static int record_load(struct march_state *st, void *state, struct module_record *rec)
{
    struct growth_record *r = state;
    double last;
    /* an earlier checkpoint: a growth study's record starts at its initial
     * state; any other run's covers the steps it runs */
    if (!rec)
        return st->cs->mode == MODE_TRANSIENT && params(st->cs)->perturbation > 0.0 ? -1 : 0;
    long n = module_record_count(rec, "t");
    if (n < 0 || module_record_get(rec, "last_step", &last, 1) != 0)
        return -1;
    long cap = n > 0 ? n : 1;
    double *t = malloc((size_t)cap * sizeof *t), *au = malloc((size_t)cap * sizeof *au),
           *ap = malloc((size_t)cap * sizeof *ap);
    int rc = t && au && ap ? 0 : module_record_fail(rec, "out of memory for the growth record");
    if (rc == 0 && (module_record_get(rec, "t", t, n) != 0 ||
                    module_record_get(rec, "amplitude_velocity", au, n) != 0 ||
                    module_record_get(rec, "amplitude_pressure", ap, n) != 0))
        rc = -1;
    if (rc != 0) {
        free(t);
        free(au);
        free(ap);
        return -1;
    }
    free(r->t);
    free(r->au);
    free(r->ap);
    r->t = t;
    r->au = au;
    r->ap = ap;
    r->n = n;
    r->cap = cap;
    r->last_step = (long)last;
    return 0;
}

static const struct module growth_module = {
    .name = "bagnold2_growth",
    .create = record_create,
    .save = record_save,
    .load = record_load,
    .destroy = record_destroy,
};

static struct growth_record *record_of(const struct march_state *st)
{
    return march_module_state(st, &growth_module);
}

/* The means along x of u, w and p over each row (j, k) of the domain
 * (rows[3][ny nz], global rows): this rank's part of each, summed over the
 * ranks.  Collective. */
static void row_means(const struct march_state *st, double *rows[3])
{
    const struct grid *g = &st->g, *G = march_global_grid(st);
    const int j0 = scene_block_lo(st, 1), k0 = scene_block_lo(st, 2), nrow = G->n[1] * G->n[2];
    const double *v[3] = {st->field.velocity[0], st->field.velocity[2], st->field.pressure};
    for (int a = 0; a < 3; a++)
        for (int r = 0; r < nrow; r++)
            rows[a][r] = 0.0;
    for (int j = 0; j < g->n[1]; j++)
        for (int k = 0; k < g->n[2]; k++)
            for (int a = 0; a < 3; a++) {
                double *s = &rows[a][(j0 + j) * G->n[2] + k0 + k];
                for (int i = 0; i < g->n[0]; i++)
                    *s += v[a][grid_idx(g, i, j, k)];
            }
    if (st->ranks)
        march_sum_array(st, rows[0], 3 * nrow);
    for (int a = 0; a < 3; a++)
        for (int r = 0; r < nrow; r++)
            rows[a][r] /= G->n[0];
}

/* The amplitudes of the departure from a flow uniform along x, in the
 * grains (T >= 1/2, a face: the mean of its two cells):
 *   au  the largest |v - <v>_x| over the grains' x and z faces, <v>_x the
 *       mean of the velocity component v over its row of faces (a uniform
 *       flow has au = 0: u depends on z only, w = 0);
 *   ap  the largest |p - <p>_x| over the grains' cells, p the total pressure
 *       (hydrostatic while the layer is uniform, so <p>_x is p_hydrostatic).
 * Over ranks: the rows' means and the maxima over every rank's faces (a
 * face on a rank border reads the cell across it in the ghost).  Collective. */
void bagnold2_amplitudes(const struct march_state *st, double *au, double *ap)
{
    const struct grid *g = &st->g, *G = march_global_grid(st);
    int t = fields_find(&st->fields, "tracer");
    *au = *ap = NAN;
    if (t < 0)
        return;
    const double *T = st->fields.e[t].v[0];
    const int nrow = G->n[1] * G->n[2], j0 = scene_block_lo(st, 1), k0 = scene_block_lo(st, 2);
    double *buf = malloc(3 * (size_t)nrow * sizeof *buf);
    if (!buf)
        return;
    double *rows[3] = {buf, buf + nrow, buf + 2 * (size_t)nrow};
    row_means(st, rows);
    double m[2] = {0.0, 0.0};
    int nx = g->n[0], split = nx != G->n[0];
    for (int j = 0; j < g->n[1]; j++)
        for (int k = 0; k < g->n[2]; k++) {
            const int r = (j0 + j) * G->n[2] + k0 + k;
            const double su = rows[0][r], sw = rows[1][r], sp = rows[2][r];
            for (int i = 0; i < nx; i++) {
                double tc = T[grid_idx(g, i, j, k)];
                /* the cell before along the periodic x: a rank border's ghost */
                int im = i > 0 ? i - 1 : split ? -1 : nx - 1;
                double tx = 0.5 * (tc + T[grid_idx(g, im, j, k)]);
                if (tx >= 0.5)
                    m[0] = fmax(m[0], fabs(st->field.velocity[0][grid_idx(g, i, j, k)] - su));
                if (k0 + k > 0 && 0.5 * (tc + T[grid_idx(g, i, j, k - 1)]) >= 0.5)
                    m[0] = fmax(m[0], fabs(st->field.velocity[2][grid_idx(g, i, j, k)] - sw));
                if (tc >= 0.5)
                    m[1] = fmax(m[1], fabs(st->field.pressure[grid_idx(g, i, j, k)] - sp));
            }
        }
    free(buf);
    if (st->ranks)
        march_max_array(st, m, 2);
    *au = m[0];
    *ap = m[1];
}

static int record_step(void *rec, const struct march_state *st)
{
    struct growth_record *r = rec;
    if (!r || st->cs->mode != MODE_TRANSIENT || st->step == r->last_step)
        return 0;
    if (r->n == r->cap) {
        long c = r->cap ? 2 * r->cap : 1024;
        double *t = realloc(r->t, (size_t)c * sizeof *t);
        if (t)
            r->t = t;
        double *au = t ? realloc(r->au, (size_t)c * sizeof *au) : NULL;
        if (au)
            r->au = au;
        double *ap = au ? realloc(r->ap, (size_t)c * sizeof *ap) : NULL;
        if (!ap)
            return -1;
        r->ap = ap;
        r->cap = c;
    }
    r->t[r->n] = st->time;
    bagnold2_amplitudes(st, &r->au[r->n], &r->ap[r->n]);
    r->n++;
    r->last_step = st->step;
    return 0;
}

static int drive(struct scene_drive *d)
{
    struct recorded_drive rd = {.record_step = record_step,
                                .rec = record_of(d->st),
                                .record_name = "the growth record"};
    recorded_drive_run(d, &rd);
    return 0;
}

void bagnold2_growth_window(const double *t, const double *au, long n, double a_sat,
                            double *t0, double *t1)
{
    *t0 = *t1 = NAN;
    if (n < 1)
        return;
    long m = 0;
    a_sat = fmax(a_sat, au[0]);
    while (m < n - 1 && !(au[m] > a_sat))
        m++;
    *t1 = t[m];
    *t0 = 0.5 * (t[0] + t[m]);
}

struct growth_fit bagnold2_growth(const struct march_state *st, int pressure)
{
    const struct growth_record *r = record_of(st);
    struct growth_fit none = {NAN, NAN, NAN, NAN, NAN, 0};
    if (!r || r->n < 3)
        return none;
    double t0, t1;
    bagnold2_growth_window(r->t, r->au, r->n,
                           BAGNOLD2_SATURATION * fabs(bagnold2_u(st->cs, st->cs->len[2])), &t0,
                           &t1);
    return growth_fit_window(r->t, pressure ? r->ap : r->au, r->n, t0, t1);
}

/* RMS and max of u - u_exact over the layers whose centre is in [lo, hi). */
static void part_errors(const struct profile *pr, double lo, double hi, double *rms,
                        double *emax)
{
    double s2 = 0.0, m = 0.0;
    int n = 0;
    for (int l = 0; l < pr->n; l++)
        if (pr->coord[l] >= lo && pr->coord[l] < hi) {
            double d = pr->velocity[l] - pr->exact[l];
            s2 += d * d;
            m = fmax(m, fabs(d));
            n++;
        }
    *rms = n ? sqrt(s2 / n) : NAN;
    *emax = n ? m : NAN;
}

/* The profile at the interface z: the parabola through its first three
 * nodes above (the fluid's profile is one: exact there up to the nodes'
 * errors).  Interpolating across the interface took a share of the air's
 * shear with it (5.6e-5 m/s, 0.25 %, at 0.06 of a cell above a node, the
 * air's own error 4.4e-6); the grains' two nodes below, their profile's
 * curvature (0.17 % at 28 degrees).  Linear interpolation where the fluid
 * holds fewer than three nodes. */
static double profile_at(const struct profile *pr, double z)
{
    int l = 0;
    while (l < pr->n - 1 && pr->coord[l] <= z)
        l++;
    const double *x = pr->coord, *u = pr->velocity;
    if (l >= 1 && l + 2 < pr->n)
        return u[l] * (z - x[l + 1]) * (z - x[l + 2]) / ((x[l] - x[l + 1]) * (x[l] - x[l + 2])) +
               u[l + 1] * (z - x[l]) * (z - x[l + 2]) /
                   ((x[l + 1] - x[l]) * (x[l + 1] - x[l + 2])) +
               u[l + 2] * (z - x[l]) * (z - x[l + 1]) /
                   ((x[l + 2] - x[l]) * (x[l + 2] - x[l + 1]));
    l = l < 1 ? 1 : l;
    double t = (z - x[l - 1]) / (x[l] - x[l - 1]);
    return u[l - 1] + t * (u[l] - u[l - 1]);
}

static void errors(const struct march_state *st, const struct profile *pr, struct scene_errors *e)
{
    const struct muflow_case *cs = st->cs;
    profile_errors_default(pr, bagnold2_u(cs, cs->len[2]), e);
    /* the headline: the velocity at the top of the domain, from the top two
     * layers (du/dz = 0 there) */
    e->headline = profile_zero_slope_end(pr->velocity[pr->n - 1], pr->velocity[pr->n - 2]);
}

static void results(const struct march_state *st, const struct scene_drive *d,
                    struct run_result *res)
{
    (void)d;
    const struct muflow_case *cs = st->cs;
    struct profile pr;
    if (scene_profile(&pr, st) != 0)
        return;
    double h0 = params(cs)->interface_height, rg, mg, ra, ma;
    part_errors(&pr, 0.0, h0, &rg, &mg);
    part_errors(&pr, h0, cs->len[2], &ra, &ma);
    double ui = profile_at(&pr, h0), ui_exact = bagnold2_u(cs, h0);
    double top = bagnold2_u(cs, cs->len[2]);
    run_result_add(res, "err_rms_grains", "%.6e", rg);
    run_result_add(res, "err_max_grains", "%.6e", mg);
    run_result_add(res, "err_rms_air", "%.6e", ra);
    run_result_add(res, "err_max_air", "%.6e", ma);
    run_result_add(res, "u_interface", "%.10g", ui);
    run_result_add(res, "u_interface_exact", "%.10g", ui_exact);
    /* the grains' volume against the initial flat layer's */
    const struct grid *G = march_global_grid(st);
    double v0 = 0.0;
    for (int k = 0; k < G->n[2]; k++)
        v0 += layer_fraction(h0, k, G->h[2]);
    v0 *= (double)G->n[0] * G->n[1];
    run_result_add(res, "mass_error", "%.6e", two_phase_volume(st) / v0 - 1.0);
    const struct growth_record *r = record_of(st);
    if (r && r->n >= 3) {
        struct growth_fit fu = bagnold2_growth(st, 0), fp = bagnold2_growth(st, 1);
        run_result_add(res, "growth_rate", "%.6e", fu.rate);
        run_result_add(res, "growth_rate_pressure", "%.6e", fp.rate);
        run_result_add(res, "growth_fit_r2", "%.6f", fu.r2);
        run_result_add(res, "growth_window", "%.6g %.6g", fu.t0, fu.t1);
        run_result_add(res, "amplitude_start", "%.6e", r->au[0]);
        run_result_add(res, "amplitude_end", "%.6e", r->au[r->n - 1]);
    }
    char why[256];
    const char *missing = exact_missing(cs, why, sizeof why);
    if (missing) {
        /* the reason beside the NaN of every error */
        run_result_add(res, "no_exact_solution", "%s", missing);
        snprintf(res->scene_line, sizeof res->scene_line,
                 "no exact solution: %.250s; u_interface %.6g", why, ui);
    } else if (top != 0.0) {
        snprintf(res->scene_line, sizeof res->scene_line,
                 "grains err_rms %.3e (%.3f%% of |u_top|), air err_rms %.3e (%.3f%%), u_interface "
                 "%.6g (exact %.6g)",
                 rg, 100.0 * rg / fabs(top), ra, 100.0 * ra / fabs(top), ui, ui_exact);
    } else {
        snprintf(res->scene_line, sizeof res->scene_line,
                 "grains err_rms %.3e, air err_rms %.3e (exact: at rest), u_interface %.6g", rg,
                 ra, ui);
    }
    profile_free(&pr);
}

/* growth.csv: the amplitudes at every step of a transient run. */
static int write(const char *dir, const struct march_state *st, char *err, size_t errlen)
{
    const struct growth_record *r = record_of(st);
    if (!r || r->n == 0)
        return 0;
    struct output_file f;
    if (output_open(&f, dir, "growth.csv", err, errlen) != 0)
        return -1;
    fprintf(f.f, "t,amplitude_velocity,amplitude_pressure\n");
    for (long m = 0; m < r->n; m++)
        fprintf(f.f, "%.10g,%.10e,%.10e\n", r->t[m], r->au[m], r->ap[m]);
    return output_commit(&f, err, errlen);
}

static const struct module *const bagnold2_modules[] = {&two_phase_module, &growth_module,
                                                        NULL};
static const char *const bagnold2_files[] = {"growth.csv", NULL};

const struct scene scene_bagnold2 = {
    .name = "bagnold2",
    .title = "granular layer under air, two phases (Barker & Rauter 2018, sec. 2-3)",
    .keys = &bagnold2_block,
    .modules = bagnold2_modules,
    .check = check,
    .setup = setup,
    .decomposed = scene_decomposed_always,
    .profile_axis = 2,
    .profile_component = 0,
    .exact_profile = exact_profile,
    .headline_name = "u_top",
    .errors = errors,
    .drive = drive,
    .results = results,
    .write = write,
    .files = bagnold2_files,
};
