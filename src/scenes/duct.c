/* Scene "duct": the bed-load flow of the bedload scene in a square duct
 * (Chauchat & Medale 2010, sec. 4.1, figs. 10-11; cases/duct_square.ini): a Newtonian
 * fluid driven by a pressure gradient along the periodic x over a flat
 * granular bed, the mixed-fluid model (physics/bed.h) or the two-fluid
 * model (physics/bed_two_fluid.h, its Newton step of the pair solved on the
 * whole cross-section), solved on half the
 * cross-section u(y, z): side wall at y = 0 (no slip), symmetry plane at
 * y = ly = W/2 (slip), walls at z = 0 and z = D = lz, the bed filling
 * z < h_p.  Parameters and their checks, the plane solution the duct is
 * compared with, and the measured bed top are the bedload scene's
 * (scenes/bedload.h), in the section [duct].
 *
 * No exact solution: the profile is the mid-plane's (the last column of
 * cells, y = W/2 - dy/2) against the plane channel's exact profile at the
 * same pressure gradient (solution "plane", difference diff_plane); the
 * headline is the largest velocity of the cross-section against the plane
 * channel's.  The summary adds the flow rate of the full duct (twice the
 * half's), the mean velocity against the plane channel's (the friction of
 * the side walls), and the mid-plane's bed top.
 *
 * The circular duct (Chauchat & Medale 2010, sec. 4.2; cases/duct_circular.ini) is the
 * same box with the wall an embedded circle of the obstacle module
 * ([obstacle], plane yz, invert): the faces weigh in the flow rate by
 * their open share, and the area is the circle's, sampled. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "diagnostics/profile.h"
#include "io/output.h"
#include "physics/bed.h"
#include "physics/bed_two_fluid.h"
#include "physics/obstacle.h"
#include "scenes/bedload.h"
#include "scenes/scene.h"
#include "scene_common.h"

#define T struct bedload_params
static const struct key duct_keys[] = {
    BEDLOAD_KEYS(T, "duct"),
    KEY_CHO(T, "duct", "model", model, bedload_model_choices,
            KEY_HELP("mixed: one mixture velocity (eq. 13); two_fluid: fluid and particle "
                     "velocities coupled by Darcy drag (eq. 12)",
                     NULL,
                     "`mixed`: one mixture velocity, the bed's viscosity plus the Coulomb "
                     "friction (Chauchat & Medale 2010, eq. 13; `src/physics/bed.c`); "
                     "`two_fluid`: the mixture velocity u^m and the particle velocity u^p, "
                     "coupled by the Darcy drag (eq. 12; `src/physics/bed_two_fluid.c`; "
                     "the pair's Newton step solved on the whole cross-section; `s"
                     "olver.mode = steady`, `domain.nz` >= 3)")),
    KEY_DBL(T, "duct", "grain_diameter", grain_diameter,
            KEY_HELP("grain diameter d in the bed's permeability K (two_fluid)", "length", NULL),
            KEY_GT0),
    KEY_DBL(T, "duct", "kozeny", kozeny,
            "Carman-Kozeny constant k_CK of K = eps^3 d^2 / (k_CK (1 - eps)^2) (two_fluid)",
            KEY_GT0),
};
#undef T

static void defaults(void *block) { bedload_defaults(block); }

SCENE_PARAMS(duct_block, "duct",
             "The bed load of `[bedload]` in a duct (Chauchat & Medale 2010, sec. 4; "
             "`cases/duct_square.ini`, `cases/duct_circular.ini`), with the same keys, defaults "
             "and checks.  Half the cross-section is solved: the flow u(y, z) along the periodic "
             "x (`domain.nx = 1`), a side wall at y = 0 (`boundary.ylo = wall`), the symmetry "
             "plane at y = `domain.ly` (`yhi = slip`), walls at z = 0 and z = `domain.lz` = D; "
             "other boundaries are refused.  The circular duct is the same box with the wall an "
             "`[obstacle]` circle (`shapes = circle D/2 D/2 D/2`, `plane = yz`, `invert = on`), "
             "its flow rate weighting each face by its open share.  `profile.csv` is the last "
             "column of cells with the plane channel's exact profile at the same pressure "
             "gradient (`u_plane`); `midplane.csv` adds u extrapolated to the symmetry plane.  "
             "The summary has the mid-plane's difference from the plane profile (`diff_plane`, "
             "`err_max`), `u_max`, `flow_rate` (the whole duct), `mean_velocity` and its ratio "
             "to the plane channel's (`velocity_ratio`), the mobile layer on the mid-plane, "
             "`secondary_velocity`, and for the circular duct its open `area`.",
             struct bedload_params, duct_keys, defaults)

static double plane_u(const struct muflow_case *cs, double z)
{
    struct bedload_exact x = bedload_exact_of(cs, params(cs));
    return bedload_exact_u(&x, z);
}

POINTWISE_PROFILE(plane_profile, plane_u)

static int check(const struct muflow_case *c, char *msg, size_t msglen)
{
    static const enum bc_kind want[3][2] = {
        {BC_PERIODIC, BC_PERIODIC}, {BC_WALL, BC_SLIP}, {BC_WALL, BC_WALL}};
    static const char axis[3] = {'x', 'y', 'z'};
    for (int d = 0; d < 3; d++)
        for (int side = 0; side < 2; side++)
            if (c->bc.face[d][side] != want[d][side]) {
                snprintf(msg, msglen,
                         "case.scene = duct needs boundary.%c%s = %s (periodic along the flow, "
                         "side wall at y = 0, symmetry plane at y = ly, walls at z = 0 and "
                         "z = lz), not %s",
                         axis[d], side ? "hi" : "lo", bc_kind_name(want[d][side]),
                         bc_kind_name(c->bc.face[d][side]));
                return 1;
            }
    if (c->rheo.law != LAW_NEWTONIAN) {
        snprintf(msg, msglen, "case.scene = duct needs rheology.law = newtonian (the bed module "
                              "sets every viscosity; rheology.regularisation and lambda are its "
                              "friction's)");
        return 1;
    }
    if (c->n[1] < 2 || c->n[2] < 2) {
        snprintf(msg, msglen, "case.scene = duct needs domain.ny >= 2 and domain.nz >= 2 (got %d, %d)",
                 c->n[1], c->n[2]);
        return 1;
    }
    if (case_obstacle_active(c) && c->obstacle.plane != OBSTACLE_YZ) {
        snprintf(msg, msglen, "case.scene = duct needs obstacle.plane = yz (the shapes draw "
                              "the duct's wall in its cross-section)");
        return 1;
    }
    const struct bedload_params *b = params(c);
    return bedload_check_params(c, b, "duct", msg, msglen);
}

/* From rest: a start from the plane profile shaped across by
 * 1 - (1 - y / ly)^2 stalled (residual 2e2 after 201 steps at 20 x 40). */
static int setup(struct march_state *st, char *err, size_t errlen)
{
    return bedload_configure(st, params(st->cs), err, errlen);
}

/* The profile: the last column of cells, beside the symmetry plane. */
static void midplane(const struct grid *g, int faces[2], int cells[2])
{
    faces[0] = faces[1] = cells[0] = cells[1] = g->n[1] - 1;
}

/* u of column j, layer k: the mean over the x-faces of the periodic x. */
static double column_u(const struct march_state *st, int j, int k)
{
    const struct grid *g = &st->g;
    double s = 0.0;
    for (int i = 0; i < g->n[0]; i++)
        s += st->field.velocity[0][grid_idx(g, i, j, k)];
    return s / g->n[0];
}

/* The largest u of the cross-section, over the ranks.  Collective. */
static double largest_u(const struct march_state *st)
{
    double m = 0.0;
    for (int j = 0; j < st->g.n[1]; j++)
        for (int k = 0; k < st->g.n[2]; k++)
            m = fmax(m, column_u(st, j, k));
    return march_max(st, m);
}

/* The mid-plane's columns of the last measure, every rank's alike, for
 * rank 0's midplane.csv: per layer of the domain, u of the last column
 * (y = W/2 - dy/2) and on the symmetry plane itself (zero slope in y
 * there, from the last two columns). */
struct midplane {
    double *column, *symmetry; /* nz each */
    int measured;
};

static int midplane_create(struct march_state *st, void **state, char *err, size_t errlen)
{
    struct midplane *m = calloc(1, sizeof *m);
    const int nz = march_global_grid(st)->n[2];
    if (m && !(m->column = malloc(2 * (size_t)nz * sizeof *m->column))) {
        free(m);
        m = NULL;
    }
    if (!m) {
        snprintf(err, errlen, "duct: out of memory");
        return -1;
    }
    m->symmetry = m->column + nz;
    *state = m;
    return 0;
}

static void midplane_destroy(void *state)
{
    struct midplane *m = state;
    if (m)
        free(m->column);
    free(m);
}

static const struct module midplane_module = {
    .name = "duct_midplane",
    .create = midplane_create,
    .destroy = midplane_destroy,
    .decomposed = 1,
};

/* The mid-plane's columns of this state (struct midplane): the last two
 * columns of the domain (global j = ny - 1, ny - 2) from the ranks that
 * hold them, summed over the ranks.  Collective. */
static void midplane_measure(const struct march_state *st, struct midplane *m)
{
    const struct grid *g = &st->g, *G = march_global_grid(st);
    const int nz = G->n[2], j0 = scene_block_lo(st, 1), k0 = scene_block_lo(st, 2);
    double *before = malloc((size_t)nz * sizeof *before);
    if (!before)
        return; /* not measured: midplane.csv says so */
    for (int k = 0; k < nz; k++)
        m->column[k] = before[k] = 0.0;
    for (int j = 0; j < g->n[1]; j++)
        for (int k = 0; k < g->n[2]; k++) {
            if (j0 + j == G->n[1] - 1)
                m->column[k0 + k] = column_u(st, j, k);
            else if (j0 + j == G->n[1] - 2)
                before[k0 + k] = column_u(st, j, k);
        }
    if (st->ranks) {
        march_sum_array(st, m->column, nz);
        march_sum_array(st, before, nz);
    }
    for (int k = 0; k < nz; k++)
        m->symmetry[k] = profile_zero_slope_end(m->column[k], before[k]);
    free(before);
    m->measured = 1;
}

static void errors(const struct march_state *st, const struct profile *pr, struct scene_errors *e)
{
    struct bedload_exact x = bedload_exact_of(st->cs, params(st->cs));
    profile_errors_default(pr, bedload_exact_max(&x), e);
    e->headline = largest_u(st);
}

/* Sub-points per direction of a cell the wall cuts, in the open area. */
#define AREA_SAMPLES 64

/* The open area of the half cross-section inside the body's wall (the
 * circular duct): the cells' fluid shares, exact away from the wall and
 * sampled on AREA_SAMPLES^2 points in the cells it cuts (the faces' open
 * shares of the flux form close a face whose centre is in the wall, so
 * their sum misses O(h) of the area: -1.9% at 10 x 20); each block's
 * cells at their global positions, summed over the ranks.  Collective. */
static double open_area(const struct march_state *st)
{
    const struct grid *g = &st->g;
    struct shape_set set;
    case_obstacle_shapes(st->cs, &set);
    const int lo[3] = {0, scene_block_lo(st, 1), scene_block_lo(st, 2)};
    double reach = hypot(g->h[1], g->h[2]), open = 0.0;
    for (int j = 0; j < g->n[1]; j++)
        for (int k = 0; k < g->n[2]; k++) {
            double x[3];
            obstacle_node_position_at(g, lo, 0, 0, j, k, x);
            double d = shape_distance(&set, x);
            if (fabs(d) > reach) {
                open += d > 0.0;
                continue;
            }
            long in = 0;
            for (int a = 0; a < AREA_SAMPLES; a++)
                for (int b = 0; b < AREA_SAMPLES; b++) {
                    double y[3] = {x[0], (lo[1] + j + (a + 0.5) / AREA_SAMPLES) * g->h[1],
                                   (lo[2] + k + (b + 0.5) / AREA_SAMPLES) * g->h[2]};
                    in += shape_distance(&set, y) > 0.0;
                }
            open += (double)in / (AREA_SAMPLES * AREA_SAMPLES);
        }
    return march_sum(st, open) * g->h[1] * g->h[2];
}

struct duct_measures {
    double q_half, q, q_plane, area, mean, mean_plane;
    double mobile, mobile_plane, u_sym_max, secondary;
};

static void measure(const struct march_state *st, struct duct_measures *m)
{
    const struct muflow_case *cs = st->cs;
    const struct grid *g = &st->g, *G = march_global_grid(st);
    struct bedload_exact x = bedload_exact_of(cs, params(cs));
    double W = 2.0 * G->len[1], D = G->len[2];
    /* the flow rate: with a body (the circular duct) each x-face weighted
     * by its open share, the rest of its cell being wall; the area sampled */
    const double *share = st->embedded ? st->embedded->share[0] : NULL;
    m->q_half = 0.0;
    for (int j = 0; j < g->n[1]; j++)
        for (int k = 0; k < g->n[2]; k++)
            m->q_half += (share ? share[grid_idx(g, 0, j, k)] : 1.0) * column_u(st, j, k);
    m->q_half = march_sum(st, m->q_half) * (g->h[1] * g->h[2]);
    m->q = 2.0 * m->q_half;
    m->area = share ? 2.0 * open_area(st) : W * D;
    /* the plane channel of the duct's height D: its flow rate over the
     * duct's width W, and its mean velocity */
    m->q_plane = bedload_exact_flow_rate(&x) * W;
    m->mean = m->q / m->area;
    m->mean_plane = m->q_plane / (W * D);
    int n = G->n[2];
    struct midplane *mp = march_module_state(st, &midplane_module);
    double *z = malloc((size_t)n * sizeof *z);
    m->mobile = m->u_sym_max = NAN;
    if (mp)
        midplane_measure(st, mp);
    if (z && mp && mp->measured) {
        double umax = 0.0;
        for (int k = 0; k < n; k++) {
            z[k] = (k + 0.5) * G->h[2];
            umax = fmax(umax, mp->symmetry[k]);
        }
        m->u_sym_max = umax;
        m->mobile = params(cs)->bed_height - bedload_bed_top(n, z, mp->symmetry, umax);
    }
    free(z);
    m->mobile_plane = x.delta * x.D;
    /* v and w vanish for the unidirectional flow: their largest size
     * relative to the largest u */
    double s = 0.0;
    for (int c = 1; c < 3; c++) {
        const struct box *b = &st->act[c];
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++)
                for (int k = b->lo[2]; k < b->hi[2]; k++)
                    s = fmax(s, fabs(st->field.velocity[c][grid_idx(g, i, j, k)]));
    }
    s = march_max(st, s);
    double um = largest_u(st);
    m->secondary = um > 0.0 ? s / um : s;
}

static void results(const struct march_state *st, const struct scene_drive *d,
                    struct run_result *res)
{
    (void)d;
    struct duct_measures m;
    measure(st, &m);
    run_result_add(res, "flow_rate", "%.10g", m.q);
    run_result_add(res, "flow_rate_half", "%.10g", m.q_half);
    run_result_add(res, "flow_rate_plane", "%.10g", m.q_plane);
    run_result_add(res, "area", "%.10g", m.area);
    run_result_add(res, "mean_velocity", "%.10g", m.mean);
    run_result_add(res, "mean_velocity_plane", "%.10g", m.mean_plane);
    run_result_add(res, "velocity_ratio", "%.10g", m.mean / m.mean_plane);
    run_result_add(res, "u_max_midplane", "%.10g", m.u_sym_max);
    run_result_add(res, "mobile_layer_midplane", "%.10g", m.mobile);
    run_result_add(res, "mobile_layer_plane", "%.10g", m.mobile_plane);
    run_result_add(res, "secondary_velocity", "%.3e", m.secondary);
    const struct bedload_params *b = params(st->cs);
    if (b->model == BEDLOAD_TWO_FLUID) {
        /* the largest |u^m - u^p| over the bed's faces, the particles'
         * residual, the drag (the mobile layer above is u^m's) */
        double *up = malloc((size_t)st->g.n[2] * sizeof *up), slip = NAN;
        if (up && two_fluid_particle_profile(st, up, &slip) == 0) {
            run_result_add(res, "slip_max", "%.10g", slip);
            run_result_add(res, "particle_residual", "%.10g", two_fluid_particle_residual(st));
            struct two_fluid_params tp = {
                .bed = bedload_bed_params(b), .grain_diameter = b->grain_diameter,
                .kozeny = b->kozeny};
            run_result_add(res, "drag_coefficient", "%.10g", two_fluid_drag(&tp));
        }
        free(up);
    }
    snprintf(res->scene_line, sizeof res->scene_line,
             "flow rate %.6g m^3/s (plane channel of the same width %.6g), mean velocity "
             "ratio %.5f, mid-plane: u_max %.6g m/s, mobile layer %.6g m (plane %.6g)",
             m.q, m.q_plane, m.mean / m.mean_plane, m.u_sym_max, m.mobile, m.mobile_plane);
}

/* midplane.csv: per layer z, u of the last column (y = W/2 - dy/2), u on
 * the symmetry plane (zero slope, from the last two columns) and the plane
 * channel's exact u. */
static int write(const char *dir, const struct march_state *st, char *err, size_t errlen)
{
    /* the columns results measured (rank 0's alone writes: no collective) */
    const struct grid *G = march_global_grid(st);
    const struct midplane *m = march_module_state(st, &midplane_module);
    if (!m || !m->measured) {
        snprintf(err, errlen, "midplane.csv: the mid-plane was not measured (out of memory)");
        return -1;
    }
    struct output_file f;
    int rc = output_open(&f, dir, "midplane.csv", err, errlen);
    if (rc != 0)
        return rc;
    fprintf(f.f, "z,u_column,u_symmetry,u_plane\n");
    for (int k = 0; k < G->n[2]; k++) {
        double z = (k + 0.5) * G->h[2];
        fprintf(f.f, "%.10g,%.12g,%.12g,%.12g\n", z, m->column[k], m->symmetry[k],
                plane_u(st->cs, z));
    }
    return output_commit(&f, err, errlen);
}

static const char *const duct_files[] = {"midplane.csv", NULL};
/* The mixed model's flow along x is the implicit step's to solve; the
 * two-fluid model solves its pair itself (bed_two_fluid.c), where `gmg` was
 * slower than the Cholesky (docs/numerics/bed-models.md) */
static int along_x(const struct muflow_case *cs)
{
    return params(cs)->model == BEDLOAD_MIXED;
}

/* the mixed model over ranks (bedload's: its bed module per cell, the
 * measures reduced over them; the circular duct's body per block, gmg's
 * cross-section gathered with it); the two-fluid model's line solves hold
 * whole planes of one process */
static int decomposed(const struct muflow_case *cs)
{
    return params(cs)->model == BEDLOAD_MIXED;
}

/* both models' modules: setup configures the one of duct.model, the other
 * idles; the mid-plane's measures */
static const struct module *const duct_modules[] = {&bed_module, &two_fluid_module,
                                                    &midplane_module, NULL};

const struct scene scene_duct = {
    .name = "duct",
    .title = "flow over a granular bed in a square or circular duct, half cross-section",
    .keys = &duct_block,
    .modules = duct_modules,
    .check = check,
    .setup = setup,
    .cross_section_flow = along_x,
    .decomposed = decomposed,
    .not_decomposed = "duct.model = two_fluid",
    .profile_axis = 2,
    .profile_component = 0,
    .profile_slab = midplane,
    .profile_slab_axis = 1,
    .exact_profile = plane_profile,
    .headline_name = "u_max",
    .error_name = "diff_plane",
    .solution_name = "plane",
    .no_err_rms_paper = 1,
    .errors = errors,
    .results = results,
    .write = write,
    .files = duct_files,
};
