/* The nonlocal granular fluidity (physics/ngf.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "physics/ngf.h"
#include "physics/fluidity_anderson.h"
#include "physics/two_phase.h"
#include "grid/boundary.h"
#include "kernels/rheology.h"
#include "solvers/line_screened.h"
#include "solvers/multigrid.h"
#include "march/step.h"
#include "march/module_record.h"

/* the largest coefficient mu_s + b I taken: beyond it g is 0 to round-off,
 * and the elimination keeps finite numbers */
#define NGF_COEF_MAX 1e300
/* the multigrid's cap on it: its residuals' squares (PCG's dot products)
 * must stay finite; g = |D| / 1e100 is 0 to round-off as well */
#define NGF_MG_COEF_MAX 1e100
/* A steady step is a Picard step (the momentum solved with the step's
 * viscosity, its mass term a small perturbation) when rho h^2 / (dt eta)
 * is below this in every cell */
#define NGF_PICARD_MASS 1e-2
/* the Picard steps in a row that must reduce |G(x) - x| before the
 * acceleration acts */
#define NGF_CONTRACTING 5
/* A creeping layer whose fluidity grows (NGF_GROWING Picard steps in a
 * row that raised |G(x) - x|) while it is below NGF_AMPLIFY_BELOW of the
 * inertial rate sqrt(p / rho_s) / d is amplified to NGF_AMPLIFY_TO of it */
#define NGF_GROWING 3
#define NGF_AMPLIFY_BELOW 1e-2
#define NGF_AMPLIFY_TO 1e-2
/* the multigrid's relative residual (of |D|'s 2-norm): below the steady
 * criterion's effect (docs/numerics/rheology.md) */
#define NGF_MG_RTOL 1e-12
/* Under a light phase (physics/two_phase.h) a cell takes part in the
 * grains' fluidity equation when at least this fraction of it is grains;
 * the others take the local fluidity (no lap(g) term) and no flux of g
 * crosses a face between the two kinds: the free surface's condition,
 * g' = 0, on the reconstructed surface to a cell (docs/numerics/rheology.md) */
#define NGF_GRAINS_CELL 0.5

struct ngf {
    double *fluidity;      /* the registered cell field */
    double *line;          /* 5 arrays of nz: coefficient, |D|, g, work, hc */
    double *hf;            /* nz + 1 centre distances along z */
    struct line_screened L;
    /* the multigrid's solve of the box (NULL: lines along z): the face
     * coefficient A^2 d^2, the screening mu_s + b I and the right-hand
     * side -|D| per cell */
    struct multigrid *mg;
    double *face, *screen, *rhs;
    double *face3[3]; /* under a light phase: each direction's, set per solve */
    long unconverged; /* its solves that stopped above NGF_MG_RTOL */
    /* the steady iteration's acceleration (NULL: Picard, and in transient
     * mode); over the cells in the module's order: the iterate x the last
     * step took, the map's value G(x) and the next iterate; the lambda its
     * history is of */
    struct fluidity_anderson *accel;
    double *x, *gx, *next;
    /* the checkpoint's copy of the history and of x (cell fields, three a
     * registry entry): mirror[2 j] the residuals of ring slot j, mirror[2 j
     * + 1] its map values, mirror[2 (depth + 1)] x */
    double **mirror;
    double *seen;    /* the fluidity G(u) the last step started from */
    int seen_valid;
    int x_valid;     /* the last step was a Picard step from x */
    int contracting, contracting_before; /* the Picard steps in a row that
                                          * reduced |G(x) - x| */
    double last_fx;  /* the last |G(x) - x| */
    int growing;     /* the Picard steps in a row that raised it */
    double accel_lambda;
};

/* The four-cell mean of an edge, as the viscosity kernels take it
 * (kernels/stencil.h: mean4). */
static double edge_mean(const double *f, ptrdiff_t e, ptrdiff_t s1, ptrdiff_t s2)
{
    return 0.25 * (f[e] + f[e - s1] + f[e - s2] + f[e - s1 - s2]);
}

static enum line_end end_condition(enum bc_kind k)
{
    return k == BC_WALL || k == BC_LID ? LINE_ZERO : LINE_NO_FLUX;
}

/* Ghosts: periodic copies, then on walls and lids the mirror of a zero
 * value (-g), or under a light phase the zero itself; a zero gradient
 * elsewhere.  The ghosts enter only the edges' fluidity (edge_mean): with
 * the mirror a wall's edge has g = 0, eta = p / lambda, a rigid half cell
 * at the wall; with the zero it has the mean of g over the link from the
 * wall to the cell's centre (g rising from 0 to g_0 over it: g_0 / 2 for
 * one cell), the slip over that half cell that the fluidity gives.  The
 * collapse's base needs the latter: the rigid edge turned the first cells'
 * slip after a step (3e-5 to 1e-4) into a wall stress up to 20 times the
 * grains' weight, a transient residual past 1e3 times its start at t =
 * 0.07 (docs/numerics/rheology.md); the layered flows keep the mirror,
 * their validated rule. */
static void fill_ghosts(const struct march_state *st, double *f)
{
    const double wall = two_phase_fraction(st) ? 0.0 : -1.0;
    const struct grid *g = &st->g;
    bc_fill_scalar(g, &st->bc, f);
    for (int d = 0; d < 3; d++)
        for (int side = 0; side < 2; side++) {
            if (st->bc.face[d][side] == BC_PERIODIC ||
                end_condition(st->bc.face[d][side]) != LINE_ZERO)
                continue;
            const int a = (d + 1) % 3, b = (d + 2) % 3;
            for (int u = grid_slot_lo(g, a); u <= grid_slot_hi(g, a); u++)
                for (int v = grid_slot_lo(g, b); v <= grid_slot_hi(g, b); v++) {
                    int in[3], gh[3];
                    in[a] = gh[a] = u;
                    in[b] = gh[b] = v;
                    in[d] = side ? g->n[d] - 1 : 0;
                    gh[d] = side ? g->n[d] : -1;
                    f[grid_idx(g, gh[0], gh[1], gh[2])] =
                        wall * f[grid_idx(g, in[0], in[1], in[2])];
                }
        }
}

/* The multigrid solves the box unless the flow is layered (x and y
 * periodic, z bounded: config/case_checks.c) and the case did not ask for
 * it. */
static int box_solve(const struct muflow_case *cs)
{
    const struct boundary *bc = &cs->bc;
    const int layered = bc->face[0][0] == BC_PERIODIC && bc->face[1][0] == BC_PERIODIC &&
                        bc->face[2][0] != BC_PERIODIC;
    return cs->rheo.fluidity_solver == FLUIDITY_MULTIGRID ||
           (cs->rheo.fluidity_solver == FLUIDITY_AUTO && !layered);
}

/* The box's multigrid: g = 0 on walls and lids, no flux through the other
 * faces, periodic images. */
static int create_box_solver(struct march_state *st, struct ngf *m, double a2, char *err,
                             size_t errlen)
{
    const struct grid *g = &st->g;
    if (st->ranks) {
        snprintf(err, errlen, "ngf: rheology.fluidity_solver = multigrid (auto's choice unless "
                              "the flow is layered: x and y periodic) runs on one process; run "
                              "the case without mpirun");
        return -1;
    }
    enum poisson_bc pbc[3][2];
    for (int d = 0; d < 3; d++)
        for (int side = 0; side < 2; side++) {
            enum bc_kind k = st->bc.face[d][side];
            pbc[d][side] = k == BC_PERIODIC                   ? POISSON_PERIODIC
                           : end_condition(k) == LINE_ZERO ? POISSON_DIRICHLET
                                                            : POISSON_NEUMANN;
        }
    char mg_err[256] = "";
    if (multigrid_create(&m->mg, g, pbc, NULL, mg_err, sizeof mg_err) != 0) {
        snprintf(err, errlen, "ngf: the fluidity's multigrid: %s", mg_err);
        return -1;
    }
    m->face = field_alloc(g);
    m->screen = field_alloc(g);
    m->rhs = field_alloc(g);
    if (!m->face || !m->screen || !m->rhs) {
        snprintf(err, errlen, "ngf: out of memory");
        return -1;
    }
    for (size_t q = 0; q < g->size; q++)
        m->face[q] = a2;
    return 0;
}

/* Whether cell (i, j, k) (an image across a periodic face: its cell; any
 * other outside the grid: the inner cell's) takes part in the grains'
 * fluidity equation under a light phase. */
static int grains_cell(const struct grid *g, const struct boundary *bc, const double *T,
                       int idx[3])
{
    for (int d = 0; d < 3; d++)
        if (idx[d] < 0 || idx[d] >= g->n[d])
            idx[d] = bc->face[d][0] == BC_PERIODIC ? (idx[d] + g->n[d]) % g->n[d]
                                                    : (idx[d] < 0 ? 0 : g->n[d] - 1);
    return T[grid_idx(g, idx[0], idx[1], idx[2])] >= NGF_GRAINS_CELL;
}

/* The face coefficients under a light phase: A^2 d^2 between two cells of
 * grains, on a wall below one (g = 0 there), 0 on every face of a cell that
 * takes no part (no flux through the grains' surface, and that cell's own
 * equation the local one).  The arrays are made at the first call. */
static int grains_faces(const struct march_state *st, struct ngf *m, const double *T)
{
    const struct grid *g = &st->g;
    const double a2 = m->face[0];
    for (int d = 0; d < 3; d++)
        if (!m->face3[d] && !(m->face3[d] = field_alloc(g)))
            return -1;
    for (int d = 0; d < 3; d++)
        for (int i = 0; i <= g->n[0]; i++)
            for (int j = 0; j <= g->n[1]; j++)
                for (int k = 0; k <= g->n[2]; k++) {
                    int here[3] = {i, j, k}, below[3] = {i, j, k};
                    int n_other = (d != 0 && i == g->n[0]) || (d != 1 && j == g->n[1]) ||
                                  (d != 2 && k == g->n[2]);
                    if (n_other) /* no face of the grid */
                        continue;
                    below[d]--;
                    m->face3[d][grid_idx(g, i, j, k)] =
                        grains_cell(g, &st->bc, T, here) && grains_cell(g, &st->bc, T, below)
                            ? a2
                            : 0.0;
                }
    return 0;
}

/* The cells of f into the compact array c (back 0), or back (1). */
static void cells_copy(const struct grid *g, double *f, double *c, int back)
{
    size_t n = 0;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++, n++) {
                ptrdiff_t q = grid_idx(g, i, j, k);
                if (back)
                    f[q] = c[n];
                else
                    c[n] = f[q];
            }
}

/* The history's cell fields in the checkpoint (a continued run goes on as
 * the uninterrupted one; a start without them begins with no history). */
static int register_mirrors(struct march_state *st, struct ngf *m, int depth)
{
    static const char *const names[] = {"ngf_history_0", "ngf_history_1", "ngf_history_2",
                                         "ngf_history_3", "ngf_history_4", "ngf_history_5",
                                         "ngf_history_6"};
    const int arrays = 2 * (depth + 1) + 1, entries = (arrays + 2) / 3;
    if (entries > (int)(sizeof names / sizeof names[0]))
        return -1;
    m->mirror = calloc(3 * (size_t)entries, sizeof *m->mirror);
    if (!m->mirror)
        return -1;
    for (int e = 0; e < entries; e++) {
        const struct field_spec spec = {names[e], FIELD_CELLS3,
                                        FIELD_CHECKPOINT | FIELD_START_OPTIONAL};
        if (fields_add(&st->fields, &spec, m->mirror + 3 * e) < 0)
            return -1;
    }
    return 0;
}

static int create(struct march_state *st, void **state, char *err, size_t errlen)
{
    const struct grid *g = &st->g;
    if (st->ranks && st->ranks->dc.n[2] != st->ranks->dc.n_global[2]) {
        snprintf(err, errlen, "ngf: the fluidity's z lines split over MPI ranks (a periodic z)");
        return -1;
    }
    struct ngf *m = calloc(1, sizeof *m);
    if (!m) {
        snprintf(err, errlen, "ngf: out of memory");
        return -1;
    }
    *state = m;
    /* the grains' viscosity is this module's, mixed under a light phase here */
    two_phase_defer_mixing(st, "rheology.law = ngf");
    const int nz = g->n[2];
    m->line = calloc(5 * (size_t)nz, sizeof(double));
    m->hf = calloc((size_t)nz + 1, sizeof(double));
    if (!m->line || !m->hf) {
        snprintf(err, errlen, "ngf: out of memory");
        return -1;
    }
    if (fields_add_written(&st->fields, "fluidity", FIELD_CHECKPOINT | FIELD_SAVED,
                           &m->fluidity) != 0) {
        snprintf(err, errlen, "ngf: cannot register the fluidity field");
        return -1;
    }
    double *hc = m->line + 4 * (size_t)nz;
    for (int k = 0; k < nz; k++)
        hc[k] = grid_hc(g, 2, k);
    for (int k = 0; k <= nz; k++)
        m->hf[k] = grid_hf(g, 2, k);
    const struct rheology *r = &st->rheo;
    const double a2 = r->nonlocal_a * r->nonlocal_a * r->grain_diameter * r->grain_diameter;
    if (box_solve(st->cs) && create_box_solver(st, m, a2, err, errlen) != 0)
        return -1;
    if (st->cs->mode == MODE_STEADY && st->cs->rheo.fluidity_anderson > 0) {
        const size_t cells = (size_t)g->n[0] * g->n[1] * nz;
        m->accel = fluidity_anderson_create(cells, st->cs->rheo.fluidity_anderson);
        m->x = malloc(4 * cells * sizeof(double));
        if (!m->accel || !m->x) {
            snprintf(err, errlen, "ngf: out of memory");
            return -1;
        }
        m->gx = m->x + cells;
        m->next = m->gx + cells;
        m->seen = m->next + cells;
        if (register_mirrors(st, m, st->cs->rheo.fluidity_anderson) != 0) {
            snprintf(err, errlen, "ngf: cannot register the acceleration's history");
            return -1;
        }
    }
    m->L = (struct line_screened){
        .n = nz,
        .a2 = a2,
        .hc = hc,
        .hf = m->hf,
        .lo = end_condition(st->bc.face[2][0]),
        .hi = end_condition(st->bc.face[2][1]),
    };
    return 0;
}

/* eta = p_reg / (g + lambda) on the cells and the edges, their tangents the
 * same (Picard), the Newton coefficients of the full tangent zero. */
static void replace_viscosities(struct march_state *st, const double *f)
{
    const struct grid *g = &st->g;
    const ptrdiff_t *o = g->stride;
    const double lam = st->rheo.lambda;
    const int newton = st->cs->newton;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t q = grid_idx(g, i, j, k);
                double eta = st->field.pressure_regularised[q] / (f[q] + lam);
                st->field.viscosity[q] = eta;
                if (newton)
                    for (int a = 0; a < 3; a++)
                        st->field.tangent_cells[a][q] = eta;
                if (st->b_c)
                    st->b_c[q] = 0.0;
            }
    for (int c = 0; c < 3; c++) {
        int a = (c + 1) % 3, b = (c + 2) % 3;
        int hi[3];
        hi[a] = g->n[a];
        hi[b] = g->n[b];
        hi[c] = g->n[c] - 1;
        for (int i = 0; i <= hi[0]; i++)
            for (int j = 0; j <= hi[1]; j++)
                for (int k = 0; k <= hi[2]; k++) {
                    ptrdiff_t e = grid_idx(g, i, j, k);
                    double pe = rheology_pressure(
                        &st->rheo, edge_mean(st->field.pressure, e, o[a], o[b]), NULL);
                    double eta = pe / (edge_mean(f, e, o[a], o[b]) + lam);
                    st->field.viscosity_edges[c][e] = eta;
                    if (newton)
                        st->field.tangent_edges[c][e] = eta;
                    if (st->full_tangent && st->b_e[c])
                        st->b_e[c][e] = 0.0;
                }
    }
    bc_fill_scalar(g, &st->bc, st->field.viscosity);
    if (newton)
        for (int a = 0; a < 3; a++)
            bc_fill_scalar(g, &st->bc, st->field.tangent_cells[a]);
}

/* 1 where the velocity's condition on z's face (0 low, 1 high) holds the
 * shear rate at 0: a free surface or a slip wall. */
static int shear_held(const struct march_state *st, int side)
{
    enum bc_kind k = st->bc.face[2][side];
    return k == BC_SURFACE || k == BC_SLIP;
}

/* |D|^2 of cell (i, j, k) as the viscosity kernels sum it (kernels/viscosity.c:
 * cell_edges_sum), but on a face whose condition holds the shear rate at 0
 * the edges there take their inner neighbours' values.  A free surface has
 * tau = 0 through p = 0, and the fluidity's shear rate g mu is finite there
 * (g' = 0): the condition's zero, averaged into the top cell's |D| (a source
 * of 1/sqrt(2) of its value), raised the stopping height by 78% on 10 cells
 * per layer at 22 degrees and converged at first order (the discrete
 * linear stability; docs/numerics/rheology.md). */
static double cell_shear2(const struct march_state *st, int i, int j, int k)
{
    const struct grid *g = &st->g;
    const int nz = g->n[2];
    const ptrdiff_t q = grid_idx(g, i, j, k);
    double s2 = st->field.strain_normal2[q];
    for (int c = 0; c < 3; c++) {
        int a = (c + 1) % 3, b = (c + 2) % 3;
        const double *e2 = st->field.strain_shear2[c];
        double sum = 0.0;
        for (int da = 0; da <= 1; da++)
            for (int db = 0; db <= 1; db++) {
                int face[3] = {i, j, k};
                face[a] += da;
                face[b] += db;
                /* along z (a or b is 2) an edge on a held face: its neighbour */
                if (c != 2 && face[2] == nz && shear_held(st, 1))
                    face[2] = nz - 1;
                if (c != 2 && face[2] == 0 && shear_held(st, 0))
                    face[2] = 1;
                sum += e2[grid_idx(g, face[0], face[1], face[2])];
            }
        s2 += 0.25 * sum;
    }
    return s2;
}

/* b I of cell (i, j, k) and its |D| (*shear); p = 0 (a free surface
 * without the pressure regularisation) has I infinite and g = 0. */
static double screening(const struct march_state *st, int i, int j, int k, double *shear)
{
    const struct rheology *r = &st->rheo;
    const double rate = r->nonlocal_b * r->grain_diameter * sqrt(r->grain_density);
    double p = st->field.pressure_regularised[grid_idx(&st->g, i, j, k)];
    *shear = sqrt(cell_shear2(st, i, j, k));
    double bi = p > 0.0 ? rate * *shear / sqrt(p) : (*shear > 0.0 ? INFINITY : 0.0);
    return fmin(r->mu_s + bi, NGF_COEF_MAX);
}

/* The box's fluidity by the multigrid, (L - c) g = -|D| with L = div(A^2 d^2
 * grad), from the last fluidity.  The exact g is >= 0 (an M-matrix and a
 * source >= 0): the solve's round-off below 0 is cut. */
static void box_fluidity(struct march_state *st, struct ngf *m)
{
    const struct grid *g = &st->g;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t q = grid_idx(g, i, j, k);
                double shear;
                m->screen[q] = fmin(screening(st, i, j, k, &shear), NGF_MG_COEF_MAX);
                m->rhs[q] = -shear;
            }
    double *face[3] = {m->face, m->face, m->face};
    const double *T = two_phase_fraction(st);
    char err[256] = "out of memory for the light phase's faces";
    const int no_faces = T && grains_faces(st, m, T) != 0;
    if (T && !no_faces)
        for (int d = 0; d < 3; d++)
            face[d] = m->face3[d];
    struct multigrid_stats stats = {0};
    if (no_faces || multigrid_set_operator(m->mg, face, m->screen, err, sizeof err) != 0) {
        /* no fluidity: NaN, so that the step is rejected and the run ends
         * diverged with its last good state, the cause said here */
        fprintf(stderr, "muflow: step %ld: the fluidity's multigrid: %s\n", st->step, err);
        for (size_t q = 0; q < g->size; q++)
            m->fluidity[q] = NAN;
        return;
    }
    if (multigrid_pcg(m->mg, m->rhs, m->fluidity, NGF_MG_RTOL, 200, &stats) != 0 &&
        m->unconverged++ == 0)
        /* the iterate is taken, as the pressure's (never silently: once) */
        fprintf(stderr,
                "muflow: warning: step %ld: the fluidity's multigrid stopped at a relative "
                "residual of %.1e (tolerance %.0e) after %d iterations; the step took that "
                "iterate (further ones not reported)\n",
                st->step, stats.rel, NGF_MG_RTOL, stats.cycles);
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t q = grid_idx(g, i, j, k);
                m->fluidity[q] = fmax(m->fluidity[q], 0.0);
            }
}

/* Every column's fluidity from its shear rates: with mu = |D| / g the steady
 * equation is linear in g,
 *   -A^2 d^2 g'' + (mu_s + b I) g = |D|,  I = |D| d sqrt(rho_s / p_reg),
 * one tridiagonal solve per column (physics/ngf.h says why this form), or
 * the box's multigrid. */
static void properties(struct march_state *st, void *state)
{
    struct ngf *m = state;
    const struct grid *g = &st->g;
    const int nz = g->n[2];
    double *coef = m->line, *shear = m->line + nz, *gcol = m->line + 2 * (size_t)nz;
    double *work = m->line + 3 * (size_t)nz;
    double *f = m->fluidity;
    if (m->mg)
        box_fluidity(st, m);
    else
        for (int i = 0; i < g->n[0]; i++)
            for (int j = 0; j < g->n[1]; j++) {
                for (int k = 0; k < nz; k++)
                    coef[k] = screening(st, i, j, k, &shear[k]);
                if (line_screened_solve(&m->L, coef, shear, work, gcol) != 0)
                    for (int k = 0; k < nz; k++)
                        gcol[k] = 0.0; /* not reached: the matrix is diagonally dominant */
                for (int k = 0; k < nz; k++)
                    f[grid_idx(g, i, j, k)] = gcol[k];
            }
    fill_ghosts(st, f);
    replace_viscosities(st, f);
    two_phase_mix_viscosities(st); /* under a light phase: the mixture's */
}

/* Whether the step of length dt is a Picard step: its mass term rho / dt
 * small beside the viscous term eta / h^2 of every cell (the smallest
 * spacing), so that it solves the momentum with the current viscosity and
 * the next state is the Picard map's value. */
static int picard_step(const struct march_state *st, double dt)
{
    const struct grid *g = &st->g;
    double eta_min = INFINITY;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++)
                eta_min = fmin(eta_min, st->field.viscosity[grid_idx(g, i, j, k)]);
    eta_min = -march_max(st, -eta_min);
    double h = march_min_spacing(g);
    return st->cs->density * h * h <= NGF_PICARD_MASS * dt * eta_min;
}

/* The steady step's viscosity from the accelerated fluidity
 * (physics/fluidity_anderson.h).  The state's fluidity is G(u), the plain
 * iteration's (properties: the residual the march judges is the steady
 * equations' own); a Picard step from x that led to it is one pair (x,
 * G(u)) of the map, and the step from here takes eta = p_reg / (w + lambda)
 * of the accelerated w with the momentum residual of that viscosity, so
 * that a Picard step solves the momentum with w.  A step that is not a
 * Picard step (a small pseudo-time step: its state is not the map's value)
 * starts the history again.  Declines the step (1): the viscous solver
 * takes it. */
/* A creeping layer that the plain iteration lifts to its flow: at lambda's
 * scale the map is linear in g (eta = p_reg / (g + lambda), the fluidity
 * equation linear in |D|), so its growing mode grows by the same factor a
 * step (1.2 on the shipped incline: some 90 steps from 1e-8 to the flow)
 * whatever its amplitude.  Far below the flowing scale, the inertial rate
 * sqrt(p / rho_s) / d, the iterate is scaled up to NGF_AMPLIFY_TO of it
 * along that mode (the last value G); a layer below its stopping height
 * contracts to the creep instead and is never amplified.  1 when it
 * amplified. */
static int amplify(const struct march_state *st, struct ngf *m)
{
    const struct grid *g = &st->g;
    const struct rheology *r = &st->rheo;
    double gmax = 0.0, pmax = 0.0;
    size_t n = 0;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++, n++) {
                gmax = fmax(gmax, m->next[n]);
                pmax = fmax(pmax, st->field.pressure_regularised[grid_idx(g, i, j, k)]);
            }
    gmax = march_max(st, gmax);
    double rate = sqrt(march_max(st, pmax) / r->grain_density) / r->grain_diameter;
    if (!(gmax > 0.0 && gmax < NGF_AMPLIFY_BELOW * rate))
        return 0;
    const double s = NGF_AMPLIFY_TO * rate / gmax;
    for (size_t q = 0; q < n; q++)
        m->next[q] *= s;
    return 1;
}

static int implicit(struct march_state *st, void *state, double dt)
{
    struct ngf *m = state;
    if (!m->accel)
        return 1;
    const struct grid *g = &st->g;
    cells_copy(g, m->fluidity, m->gx, 0);
    if (st->rheo.lambda != m->accel_lambda || !picard_step(st, dt)) {
        /* a new lambda (a continuation's stage) is a new map */
        fluidity_anderson_reset(m->accel);
        m->accel_lambda = st->rheo.lambda;
        m->x_valid = 0;
        return 1;
    }
    /* the state the last step started from again: a rejected step's retry */
    int differs = !m->seen_valid;
    for (size_t q = 0, n = (size_t)g->n[0] * g->n[1] * g->n[2]; q < n; q++) {
        differs |= m->seen[q] != m->gx[q];
        m->seen[q] = m->gx[q];
    }
    m->seen_valid = 1;
    if (march_sum(st, differs) == 0.0) {
        /* a retried step: the mix was rejected, the plain step is taken */
        fluidity_anderson_keep_newest(m->accel);
        m->contracting = m->contracting_before = 0;
        cells_copy(g, m->fluidity, m->next, 0);
    } else {
        /* a new state */
        m->contracting = 0;
        if (m->x_valid) {
            double fx = fluidity_anderson_push(m->accel, st, m->x, m->gx);
            int slot = fluidity_anderson_newest_slot(m->accel);
            cells_copy(g, m->mirror[2 * slot], fluidity_anderson_slot(m->accel, 0, slot), 1);
            cells_copy(g, m->mirror[2 * slot + 1], fluidity_anderson_slot(m->accel, 1, slot), 1);
            /* only a contraction is accelerated: from a creeping layer the
             * map's growing mode leads to the flow, and the combination of
             * least residual would lead back to the creep (an unstable
             * fixed point) */
            m->contracting = fx < m->last_fx ? m->contracting_before + 1 : 0;
            m->growing = fx > m->last_fx ? m->growing + 1 : 0;
            m->last_fx = fx;
        } else {
            fluidity_anderson_reset(m->accel);
            m->last_fx = INFINITY;
            m->growing = 0;
        }
        m->contracting_before = m->contracting;
        if (m->contracting == 0)
            fluidity_anderson_keep_newest(m->accel);
        if (m->contracting >= NGF_CONTRACTING)
            fluidity_anderson_next(m->accel, st, m->next);
        else
            cells_copy(g, m->fluidity, m->next, 0);
        if (m->growing >= NGF_GROWING && amplify(st, m))
            fluidity_anderson_reset(m->accel);
    }
    size_t n = (size_t)g->n[0] * g->n[1] * g->n[2];
    int same = 1;
    for (size_t q = 0; q < n; q++) {
        m->x[q] = m->next[q];
        same &= m->next[q] == m->gx[q];
    }
    m->x_valid = 1;
    cells_copy(g, m->mirror[2 * (st->cs->rheo.fluidity_anderson + 1)], m->x, 1);
    if (march_sum(st, !same) > 0.0) {
        cells_copy(g, m->fluidity, m->next, 1);
        fill_ghosts(st, m->fluidity);
        replace_viscosities(st, m->fluidity);
        two_phase_mix_viscosities(st);
        stage_residual(st);
    }
    return 1;
}

static int line_search(const struct march_state *st, void *state)
{
    (void)st;
    const struct ngf *m = state;
    return m->accel != NULL;
}

/* The acceleration's counters (the same on every rank: global sums) beside
 * its history's fields. */
static int save(const struct march_state *st, void *state, struct module_record *rec)
{
    (void)st;
    const struct ngf *m = state;
    if (!m->accel)
        return 0;
    double v[8] = {m->x_valid, m->contracting, m->contracting_before, m->growing, m->last_fx,
                   m->accel_lambda};
    fluidity_anderson_get_state(m->accel, v + 6);
    return module_record_put(rec, "acceleration", v, 8);
}

static int load(struct march_state *st, void *state, struct module_record *rec)
{
    struct ngf *m = state;
    if (!m->accel || !rec || module_record_count(rec, "acceleration") != 8)
        return 0; /* none: the acceleration starts again from this state */
    double v[8];
    if (module_record_get(rec, "acceleration", v, 8) != 0)
        return -1;
    if (fluidity_anderson_set_state(m->accel, v + 6) != 0)
        return module_record_fail(rec, "acceleration: a history of another depth");
    m->x_valid = v[0] != 0.0;
    m->contracting = (int)v[1];
    m->contracting_before = (int)v[2];
    m->growing = (int)v[3];
    m->last_fx = v[4];
    m->accel_lambda = v[5];
    const struct grid *g = &st->g;
    const int depth = st->cs->rheo.fluidity_anderson;
    for (int slot = 0; slot <= depth; slot++) {
        cells_copy(g, m->mirror[2 * slot], fluidity_anderson_slot(m->accel, 0, slot), 0);
        cells_copy(g, m->mirror[2 * slot + 1], fluidity_anderson_slot(m->accel, 1, slot), 0);
    }
    cells_copy(g, m->mirror[2 * (depth + 1)], m->x, 0);
    return 0;
}

static void destroy(void *state)
{
    struct ngf *m = state;
    if (!m)
        return;
    free(m->line);
    free(m->hf);
    multigrid_destroy(m->mg);
    field_free(m->face);
    for (int d = 0; d < 3; d++)
        field_free(m->face3[d]);
    field_free(m->screen);
    field_free(m->rhs);
    fluidity_anderson_destroy(m->accel);
    free(m->x);
    free(m->mirror);
    free(m);
}

static double memory_bound(const struct muflow_case *cs, const struct grid *g)
{
    double bytes = (double)g->size * sizeof(double) + (6.0 * g->n[2] + 1.0) * sizeof(double);
    if (box_solve(cs))
        /* the light phase's three face arrays counted always */
        bytes += multigrid_memory_estimate(g, NULL) + 6.0 * g->size * sizeof(double);
    if (cs->mode == MODE_STEADY && cs->rheo.fluidity_anderson > 0) {
        const size_t cells = (size_t)g->n[0] * g->n[1] * g->n[2];
        const int mirrors = 3 * ((2 * (cs->rheo.fluidity_anderson + 1) + 3) / 3);
        bytes += fluidity_anderson_bytes(cells, cs->rheo.fluidity_anderson) +
                 4.0 * cells * sizeof(double) + mirrors * (double)g->size * sizeof(double);
    }
    return bytes;
}

const struct module ngf_module = {
    .name = "ngf",
    .create = create,
    .properties = properties,
    .implicit = implicit,
    .line_search = line_search,
    .save = save,
    .load = load,
    .implicit_steady = 1, /* transient steps are the plain Picard's */
    .destroy = destroy,
    .memory_bound = memory_bound,
    .decomposed = 1, /* per z line, z unsplit; ghosts by bc_fill_scalar */
};
