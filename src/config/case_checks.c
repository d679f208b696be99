/* The checks of a case that need every key, run once after the file and
 * all overrides are read (case_load): one function per topic, each 0 or 1
 * after case_refuse(), the first refusal ending the load. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "case_internal.h"
#include "config/case.h"
#include "config/keys.h"
#include "grid/grid.h"
#include "grid/shapes.h"

#define MAX_CELLS 500000000.0 /* cap on nx*ny*nz */

/* ------------------------------------------------------------------------ */
/* Helpers and the checks of the geometry */

/* The first inflow face as 2 d + side, or -1. */
static int inflow_face(const struct boundary *bc)
{
    for (int d = 0; d < 3; d++)
        for (int side = 0; side < 2; side++)
            if (bc->face[d][side] == BC_INFLOW)
                return 2 * d + side;
    return -1;
}

/* The smallest cell of direction d: its band's, or l / n. */
static double finest_cell(const struct muflow_case *c, int d)
{
    struct grid_axis ax;
    char why[300];
    double h = c->len[d] / c->n[d];
    if (case_axis(c, d, &ax, why, sizeof why) > 0) {
        for (int i = 0; i < ax.n; i++)
            h = fmin(h, ax.hc[i + 1]);
        grid_axis_free(&ax);
    }
    return h;
}

/* " (obstacle.invert = off: the fluid outside the shapes)" */
static const char *invert_text(const struct muflow_case *c)
{
    return c->obstacle.invert ? "obstacle.invert = on (the fluid inside the shapes)"
                              : "obstacle.invert = off (the fluid outside the shapes)";
}

/* The fluid the shapes leave on the grid: one region, or regions that each
 * reach a surface or open face, where the pressure is fixed.  The pressure
 * solves take one free level for the whole fluid; regions closed off from
 * those faces each have their own, and one whose edge is partly the box's
 * walls has a hydrostatic problem without a solution under a body force
 * (docs/numerics/obstacles.md).  The rule is the regions, not the forces;
 * one region alone is solved up to its level. */
static int check_regions(struct case_ctx *x, const struct shape_set *set)
{
    const struct muflow_case *c = x->c;
    static const char axis[3] = {'x', 'y', 'z'};
    int periodic[3], fixed[3][2], nfixed = 0;
    char faces[160] = "";
    size_t used = 0;
    for (int d = 0; d < 3; d++) {
        periodic[d] = c->bc.face[d][0] == BC_PERIODIC;
        for (int side = 0; side < 2; side++) {
            enum bc_kind k = c->bc.face[d][side];
            fixed[d][side] = k == BC_SURFACE || k == BC_OPEN;
            if (fixed[d][side] && used < sizeof faces)
                used += (size_t)snprintf(faces + used, sizeof faces - used, "%sboundary.%c%s = %s",
                                         nfixed++ ? ", " : "", axis[d], side ? "hi" : "lo",
                                         case_bc_choices[k].name);
        }
    }
    int regions, floating;
    if (shapes_regions(set, c->n, c->len, periodic, fixed, &regions, &floating) != 0) {
        case_refuse(x, "obstacle.shapes: out of memory checking the shapes against the box");
        return 1;
    }
    if (regions < 2 || floating == 0)
        return 0;
    case_refuse(x,
                "obstacle.shapes = '%.200s' with %s: the body splits the fluid into %d regions on "
                "this grid, %d of them closed off from every surface or open face of the box, "
                "where the pressure is fixed%s%s%s: their pressures have no common level, which "
                "the pressure solves cannot take; the fluid must be one region, or each region "
                "must reach a surface or open face",
                c->obstacle.shapes, invert_text(c), regions, floating, nfixed ? " (" : "", faces,
                nfixed ? ")" : "");
    return 1;
}

/* The shapes against the box: each reaches into it and spans a cell of
 * the plane at least, some fluid is left, a flow through the box (an
 * inflow face, or open faces at both ends of a direction) finds a path of
 * fluid cells from one end to the other, and the fluid's pressure is fixed
 * (check_regions).  Geometry on the plane's grid: after every size check. */
static int check_shapes_fit(struct case_ctx *x, struct shape_set *set)
{
    struct muflow_case *c = x->c;
    static const char axis[3] = {'x', 'y', 'z'};
    static const char *const len_key[3] = {"lx", "ly", "lz"}, *const n_key[3] = {"nx", "ny", "nz"};
    shapes_set_plane(set, c->obstacle.plane, c->obstacle.invert);
    const char *plane = case_plane_choices[c->obstacle.plane].name;
    int a = set->plane_a, b = set->plane_b;
    int out = shapes_outside_box(set, c->len);
    if (out >= 0) {
        case_refuse(x,
                    "obstacle.shapes = '%.200s': shape %d lies wholly outside the box, whose "
                    "plane %s spans [0, %s] x [0, %s] (a body must reach into the box)",
                    c->obstacle.shapes, out + 1, plane, num_text(c->len[a]).s,
                    num_text(c->len[b]).s);
        return 1;
    }
    /* a body thinner than a cell is not seen, or seen as a cell's staircase */
    for (int i = 0; i < set->n; i++) {
        const struct shape *sh = &set->s[i];
        const int dir[2] = {a, b};
        for (int k = 0; k < 2; k++) {
            int d = dir[k];
            double span = sh->kind == SHAPE_CIRCLE  ? 2.0 * sh->v[2]
                          : sh->kind == SHAPE_SLOPE ? INFINITY /* the ground: unbounded */
                                                    : sh->v[2 + k] - sh->v[k];
            double h = finest_cell(c, d);
            if (span < h) {
                case_refuse(x,
                            "obstacle.shapes = '%.200s': shape %d spans %s along %c, thinner "
                            "than a cell (domain.%s / domain.%s = %s): a body must span at least "
                            "one cell along each direction of its plane (raise domain.%s)",
                            c->obstacle.shapes, i + 1, num_text(span).s, axis[d], len_key[d],
                            n_key[d], num_text(h).s, n_key[d]);
                return 1;
            }
        }
    }
    int flow = -1;
    for (int d = 0; d < 3 && flow < 0; d++)
        if (c->bc.face[d][0] == BC_INFLOW || c->bc.face[d][1] == BC_INFLOW ||
            (c->bc.face[d][0] == BC_OPEN && c->bc.face[d][1] == BC_OPEN))
            flow = d;
    int extrusion = 3 - a - b;
    int fluid = shapes_connect(set, c->n, c->len, extrusion);
    int joined = flow >= 0 ? shapes_connect(set, c->n, c->len, flow) : 1;
    if (fluid < 0 || joined < 0) {
        case_refuse(x, "obstacle.shapes: out of memory checking the shapes against the box");
        return 1;
    }
    if (!fluid) {
        case_refuse(x,
                    "obstacle.shapes = '%.200s' with %s: no cell centre of the grid lies in the "
                    "fluid",
                    c->obstacle.shapes, invert_text(c));
        return 1;
    }
    if (!joined) {
        case_refuse(x,
                    "obstacle.shapes = '%.200s' with %s: the body closes the channel between "
                    "boundary.%clo = %s and boundary.%chi = %s (no path of fluid cells joins "
                    "them on this grid)",
                    c->obstacle.shapes, invert_text(c), axis[flow],
                    case_bc_choices[c->bc.face[flow][0]].name, axis[flow],
                    case_bc_choices[c->bc.face[flow][1]].name);
        return 1;
    }
    return check_regions(x, set);
}

int case_axis(const struct muflow_case *c, int d, struct grid_axis *ax, char *msg,
              size_t msglen)
{
    struct grid_band b[GRID_BANDS_MAX];
    int nb = grid_bands_parse(c->band[d], b, GRID_BANDS_MAX);
    msg[0] = '\0';
    if (nb <= 0)
        return nb;
    return grid_axis_build_bands(ax, c->len[d], c->len[d] / c->n[d], b, nb, c->growth,
                                 c->bc.face[d][0] == BC_PERIODIC, msg, msglen) == 0
               ? 1
               : -1;
}

int case_obstacle_active(const struct muflow_case *c)
{
    for (const char *s = c->obstacle.shapes; *s; s++)
        if (*s != ' ' && *s != '\t' && *s != ';')
            return 1;
    return 0;
}

void case_obstacle_shapes(const struct muflow_case *c, struct shape_set *set)
{
    char msg[300];
    memset(set, 0, sizeof *set);
    if (shapes_parse(set, c->obstacle.shapes, msg, sizeof msg) != 0)
        set->n = 0; /* not reached: the case's check parsed them */
    shapes_set_plane(set, c->obstacle.plane, c->obstacle.invert);
}

/* The stretched directions: 'lo hi h' triples, bands the grid can hold,
 * and only the paths built for varying spacing (the coupled steady step:
 * the FFT and geometric-multigrid pressures, the Fourier and Cholesky
 * preconditioners, advection and the volume of fluid assume one size per
 * direction). */
static int check_bands(struct case_ctx *x)
{
    struct muflow_case *c = x->c;
    static const char axis[3] = {'x', 'y', 'z'};
    static const char *const len_key[3] = {"lx", "ly", "lz"}, *const n_key[3] = {"nx", "ny", "nz"};
    for (int d = 0; d < 3; d++) {
        struct grid_axis ax;
        char why[300];
        int r = case_axis(c, d, &ax, why, sizeof why);
        if (r == 0)
            continue;
        if (r < 0 && !why[0]) {
            case_refuse(x,
                        "domain.%c_band = '%.100s': must be one to %d triples 'lo hi h' "
                        "separated by ';' (empty: a uniform direction)",
                        axis[d], c->band[d], GRID_BANDS_MAX);
            return 1;
        }
        if (r > 0)
            grid_axis_free(&ax);
        if (c->n[d] < 2) {
            case_refuse(x,
                        "domain.%c_band needs domain.%s >= 2 (a direction of one cell is not "
                        "stretched)",
                        axis[d], n_key[d]);
            return 1;
        }
        if (r < 0) {
            case_refuse(x, "domain.%c_band = '%.100s' with domain.%s = %s, domain.%s = %d: %s",
                        axis[d], c->band[d], len_key[d], num_text(c->len[d]).s, n_key[d], c->n[d],
                        why);
            return 1;
        }
        const char *need = NULL;
        if (!case_scene_of(c)->stretched_grid)
            need = "a scene built for varying cell sizes (case.scene = none or cylinder)";
        else if (!c->coupled || c->mode != MODE_STEADY)
            need = "solver.mode = steady with solver.coupled = on (the only pressure built for "
                   "varying cell sizes)";
        else if (bc_has_open(&c->bc) || inflow_face(&c->bc) >= 0)
            need = "no open or inflow face (their rows assume one cell size per direction)";
        else if (c->advection)
            need = "physics.advection = off (advection assumes one cell size per direction)";
        else if (c->preconditioner != PRECOND_AUTO && c->preconditioner != PRECOND_LU)
            need = "solver.preconditioner = auto or lu (the others assume one cell size per "
                   "direction)";
        if (need) {
            case_refuse(x, "domain.%c_band = '%.100s' needs %s", axis[d], c->band[d], need);
            return 1;
        }
    }
    return 0;
}

/* ------------------------------------------------------------------------ */
/* The checks, one topic each */

/* The cell count: every array of the run is as large. */
static int check_size(struct case_ctx *x)
{
    const struct muflow_case *c = x->c;
    double cells = (double)c->n[0] * (double)c->n[1] * (double)c->n[2];
    if (cells > MAX_CELLS) {
        case_refuse(x,
                    "domain.nx * domain.ny * domain.nz = %d * %d * %d = %.0f cells: must be "
                    "<= %.0f",
                    c->n[0], c->n[1], c->n[2], cells, MAX_CELLS);
        return 1;
    }
    return 0;
}

/* The faces against each other and against the grid and the solver. */
static int check_faces(struct case_ctx *x)
{
    const struct muflow_case *c = x->c;
    static const char axis[3] = {'x', 'y', 'z'};
    for (int d = 0; d < 3; d++) {
        int lo = c->bc.face[d][0] == BC_PERIODIC, hi = c->bc.face[d][1] == BC_PERIODIC;
        if (lo != hi) {
            case_refuse(x,
                        "boundary.%clo = %s, boundary.%chi = %s: periodic must be on both faces "
                        "of %c or on neither",
                        axis[d], case_bc_choices[c->bc.face[d][0]].name, axis[d],
                        case_bc_choices[c->bc.face[d][1]].name, axis[d]);
            return 1;
        }
    }

    for (int d = 0; d < 3; d++)
        for (int side = 0; side < 2; side++)
            if (c->bc.face[d][side] == BC_LID && c->bc.lid_direction == d) {
                case_refuse(x,
                            "boundary.%c%s = lid, boundary.lid_direction = %c: a lid moves in "
                            "its own plane, the direction must differ from %c",
                            axis[d], side ? "hi" : "lo", axis[d], axis[d]);
                return 1;
            }

    /* an open face's momentum balance is its inner neighbour's (stage_projection.c) */
    for (int d = 0; d < 3; d++)
        for (int side = 0; side < 2; side++)
            if (c->bc.face[d][side] == BC_OPEN && c->n[d] < 2) {
                case_refuse(x,
                            "boundary.%c%s = open with domain.n%c = %d: an open face needs at "
                            "least 2 cells along %c",
                            axis[d], side ? "hi" : "lo", axis[d], c->n[d], axis[d]);
                return 1;
            }

    /* the grad-div augmentation treats an open face's velocity as fixed in
     * the implicit step while the projection moves it: the Uzawa update then
     * fights the open face's pressure condition (docs/numerics/open-boundaries.md) */
    if (c->augmentation > 0.0 && bc_has_open(&c->bc)) {
        case_refuse(x,
                    "solver.augmentation = %s with an open face: the grad-div augmentation "
                    "is not supported with open boundaries (set solver.augmentation = 0)",
                    num_text(c->augmentation).s);
        return 1;
    }
    return 0;
}

/* The coupled step (stage_coupled.c): a steady Newton step of its own, whose
 * pressure needs no augmentation (its open faces' balance is in its matrix,
 * coupled_open.h); then the preconditioner the keys name against the case,
 * which only the layers that build it know (case_checks.preconditioner). */
static int check_solver(struct case_ctx *x)
{
    const struct muflow_case *c = x->c;
    if (c->coupled) {
        const char *why = c->mode != MODE_STEADY ? "needs solver.mode = steady"
                          : c->augmentation > 0.0 ? "needs solver.augmentation = 0 (its pressure "
                                                    "is solved with the velocity)"
                                                  : NULL;
        if (why) {
            case_refuse(x, "solver.coupled = on %s", why);
            return 1;
        }
    }
    /* (the coupled step needs the steady mode: refused above) */
    if (c->time_scheme == TIME_BDF2 && c->mode != MODE_TRANSIENT) {
        case_refuse(x, "solver.time_scheme = bdf2 needs solver.mode = transient (or set "
                       "solver.time_scheme = euler)");
        return 1;
    }
    const struct case_checks *above = case_registered_checks();
    char msg[512];
    if (above->preconditioner && above->preconditioner(c, msg, sizeof msg) != 0) {
        case_refuse(x, "%s", msg);
        return 1;
    }
    return 0;
}

/* An inflow's volume must leave somewhere: through an open face. */
static int check_inflow(struct case_ctx *x)
{
    const struct muflow_case *c = x->c;
    static const char axis[3] = {'x', 'y', 'z'};
    int inflow = inflow_face(&c->bc);
    if (inflow >= 0 && !bc_has_open(&c->bc) && c->bc.inflow_velocity != 0.0) {
        case_refuse(x,
                    "boundary.%c%s = inflow with boundary.inflow_velocity = %s and no open "
                    "face: the inflowing volume has no way out (set an outlet face to open)",
                    axis[inflow / 2], inflow % 2 ? "hi" : "lo",
                    num_text(c->bc.inflow_velocity).s);
        return 1;
    }
    return 0;
}

/* The shapes are read here so that a bad one stops the case at load; their
 * fit to the grid is checked last (check_shapes_fit). */
static int read_shapes(struct case_ctx *x, struct shape_set *set)
{
    const struct muflow_case *c = x->c;
    char why[300];
    if (shapes_parse(set, c->obstacle.shapes, why, sizeof why) != 0) {
        case_refuse(x, "obstacle.shapes = '%.200s': %s", c->obstacle.shapes, why);
        return 1;
    }
    return 0;
}

/* What the scene needs of the core keys, and its own section's check. */
static int check_scene(struct case_ctx *x)
{
    const struct muflow_case *c = x->c;
    const struct case_scene_info *sc = case_scene_of(c);
    const struct key_block *kb = sc->keys;
    char msg[512];
    if ((sc->check && sc->check(c, msg, sizeof msg) != 0) ||
        (kb && kb->check && kb->check(c, c->scene_params.bytes, msg, sizeof msg) != 0)) {
        case_refuse(x, "%s", msg);
        return 1;
    }
    return 0;
}

static int check_time_step(struct case_ctx *x)
{
    const struct muflow_case *c = x->c;
    if (c->dt_max < c->dt) {
        case_refuse(x, "solver.dt_max = %s < solver.dt = %s: dt_max must be >= dt",
                    num_text(c->dt_max).s, num_text(c->dt).s);
        return 1;
    }
    return 0;
}

/* The nonlocal fluidity (physics/ngf.h): along z lines only for layered
 * flows, the multigrid on uniform grids; its viscosity p / (g + lambda)
 * needs lambda > 0 where g = 0. */
static int check_ngf(struct case_ctx *x)
{
    const struct muflow_case *c = x->c;
    const int layered = c->bc.face[0][0] == BC_PERIODIC && c->bc.face[1][0] == BC_PERIODIC &&
                        c->bc.face[2][0] != BC_PERIODIC;
    if (c->rheo.fluidity_solver == FLUIDITY_LINES && !layered) {
        case_refuse(x, "rheology.fluidity_solver = lines solves the fluidity along z (layered "
                       "flows): it needs boundary.xlo, xhi, ylo, yhi = periodic and boundary.zlo, "
                       "zhi not periodic; rheology.fluidity_solver = multigrid solves the box");
        return 1;
    }
    const int box = c->rheo.fluidity_solver == FLUIDITY_MULTIGRID ||
                    (c->rheo.fluidity_solver == FLUIDITY_AUTO && !layered);
    for (int d = 0; d < 3; d++)
        if (box && c->band[d][0]) {
            case_refuse(x, "domain.%c_band: rheology.law = ngf solves the fluidity by the "
                           "multigrid here (rheology.fluidity_solver), on uniform grids only",
                        "xyz"[d]);
            return 1;
        }
    if (!(c->rheo.lambda > 0.0)) {
        case_refuse(x, "rheology.law = ngf needs rheology.lambda > 0 (in (0, 1]): the viscosity "
                       "is p / (g + lambda) and the fluidity g is 0 where the grains rest");
        return 1;
    }
    if (c->coupled) {
        case_refuse(x, "rheology.law = ngf needs solver.coupled = off: the coupled step does not "
                       "take the fluidity's viscosities yet");
        return 1;
    }
    return 0;
}

/* The law's own parameters, then the curve's derived values (I_1^N,
 * A_minus), once, from the final keys (case_checks.rheology_curve: the
 * kernels' root finder). */
static int check_rheology(struct case_ctx *x)
{
    struct muflow_case *c = x->c;
    if (c->rheo.law == LAW_NEWTONIAN && !(c->rheo.viscosity > 0)) {
        case_refuse(x, "rheology.law = newtonian needs rheology.viscosity > 0");
        return 1;
    }
    if (c->rheo.law == LAW_BINGHAM &&
        !(c->rheo.plastic_viscosity > 0 || c->rheo.yield_stress > 0)) {
        case_refuse(x,
                    "rheology.law = bingham needs rheology.plastic_viscosity > 0 or "
                    "rheology.yield_stress > 0");
        return 1;
    }
    if (c->rheo.law == LAW_NGF && check_ngf(x) != 0)
        return 1;
    const struct case_checks *above = case_registered_checks();
    if (c->rheo.law == LAW_MUI) {
        char msg[512];
        if (above->rheology_curve && above->rheology_curve(&c->rheo, msg, sizeof msg) != 0) {
            case_refuse(x, "%s", msg);
            return 1;
        }
    } else {
        c->rheo.i1n = 0.0;
        c->rheo.a_minus = 0.0;
    }
    return 0;
}

/* "out/<name>" when output.dir is not given, checked like an explicit one
 * (the name has fewer than 128 characters). */
static int check_output_dir(struct case_ctx *x)
{
    struct muflow_case *c = x->c;
    int dir_key = case_core_key_index("output", "dir");
    if (!x->set[dir_key]) {
        char dir[sizeof(c->name) + 8], m[160], b2[SHOWN_MAX + 4];
        snprintf(dir, sizeof(dir), "out/%s", c->name);
        const char *why = key_parse(c, &case_core_keys[dir_key], dir, m, sizeof(m));
        if (why)
            case_refuse(x, "default output.dir = %s: %s; set output.dir", shown(dir, b2), why);
    }
    return x->failed;
}

/* "bagnold|chute|..." : the scenes other than none. */
static const char *scene_names(char *names, size_t len)
{
    size_t used = 0;
    names[0] = '\0';
    for (int i = 1; i < case_scene_count() && used < len; i++)
        used += (size_t)snprintf(names + used, len - used, "%s%s", i > 1 ? "|" : "",
                                 case_scene_info(i)->name);
    return names;
}

/* The implicit viscous solve works along a non-periodic direction
 * (solvers/viscous.c): a box periodic on every face cannot be run. */
static int check_solvable(struct case_ctx *x)
{
    const struct muflow_case *c = x->c;
    static const char axis[3] = {'x', 'y', 'z'};
    if (c->bc.face[0][0] == BC_PERIODIC && c->bc.face[1][0] == BC_PERIODIC &&
        c->bc.face[2][0] == BC_PERIODIC) {
        char names[512];
        if (x->keys_given == 0)
            case_refuse(x,
                        "the case sets no key: no case.scene and the default %d x %d x %d box, "
                        "periodic on every face, which muflow cannot solve; a case needs at "
                        "least one direction whose faces are wall, slip, surface, lid, open or "
                        "inflow (boundary.*) and, to be compared with a solution, a scene "
                        "(case.scene = %s): the files in cases/ are complete examples, muflow "
                        "--list lists every key",
                        c->n[0], c->n[1], c->n[2], scene_names(names, sizeof names));
        else
            case_refuse(x,
                        "every boundary face is periodic: muflow needs at least one direction "
                        "whose faces are wall, slip, surface, lid, open or inflow (boundary.xlo "
                        "and boundary.xhi, boundary.ylo and boundary.yhi, or boundary.zlo and "
                        "boundary.zhi); the implicit viscous solve works along it");
        return 1;
    }
    if (c->line_direction >= 0 && c->bc.face[c->line_direction][0] == BC_PERIODIC) {
        case_refuse(x,
                    "solver.line_direction = %c: %c is periodic; the preconditioner lines need "
                    "a non-periodic direction (auto chooses one)",
                    axis[c->line_direction], axis[c->line_direction]);
        return 1;
    }
    return 0;
}

/* The memory the run needs, from the case alone (case_checks.memory: the
 * march's estimate). */
static int check_memory(struct case_ctx *x)
{
    const struct case_checks *above = case_registered_checks();
    char msg[512];
    if (above->memory && above->memory(x->c, msg, sizeof msg) != 0) {
        case_refuse(x, "%s", msg);
        return 1;
    }
    return 0;
}

/* In the order of their cost: the keys against each other, then the size
 * of the run (the cell count, the memory it needs, from the case alone),
 * and only then the body's geometry on the grid, which costs as much as the
 * grid (docs/numerics/memory-estimate.md). */
void case_check_all(struct case_ctx *x)
{
    struct muflow_case *c = x->c;
    if (!x->set[case_core_key_index("rheology", "grain_density")])
        c->rheo.grain_density = 1.0 / c->rheo.phi; /* phi in (0, 1]: finite */
    struct shape_set set;
    if (check_size(x) || check_faces(x) || check_solver(x) || check_inflow(x) ||
        check_bands(x) || read_shapes(x, &set) || check_scene(x) || check_time_step(x) ||
        check_rheology(x) || check_output_dir(x) || check_solvable(x) || check_memory(x))
        return;
    if (set.n > 0)
        check_shapes_fit(x, &set);
}
