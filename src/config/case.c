/* The core key table: every key of a case but its scene's own section,
 * with its range, help and doc (keys.h), in the order case_write_ini
 * writes them; what each core section is for (docs/case_keys.md); and the
 * defaults of every key (what a case file may leave out). */
#include "config/case.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include "case_internal.h"
#include "config/keys.h"

#define HALF_PI 1.57079632679489661923

const struct choice case_bc_choices[] = {
    {"periodic", BC_PERIODIC}, {"wall", BC_WALL}, {"slip", BC_SLIP},
    {"surface", BC_SURFACE}, {"lid", BC_LID}, {"open", BC_OPEN}, {"inflow", BC_INFLOW}, {NULL, 0}};
static const struct choice profile_choices[] = {
    {"uniform", INFLOW_UNIFORM}, {"parabolic", INFLOW_PARABOLIC}, {NULL, 0}};
const struct choice case_plane_choices[] = {
    {"xz", OBSTACLE_XZ}, {"xy", OBSTACLE_XY}, {"yz", OBSTACLE_YZ}, {NULL, 0}};
static const struct choice obstacle_boundary_choices[] = {
    {"sharp", OBSTACLE_SHARP}, {"staircase", OBSTACLE_STAIRCASE}, {"cells", OBSTACLE_CELLS},
    {NULL, 0}};
static const struct choice law_choices[] = {
    {"mui", LAW_MUI}, {"bingham", LAW_BINGHAM}, {"newtonian", LAW_NEWTONIAN},
    {"ngf", LAW_NGF}, {NULL, 0}};
static const struct choice reg_choices[] = {
    {"simple", REG_SIMPLE}, {"bercovier", REG_BERCOVIER},
    {"papanastasiou", REG_PAPANASTASIOU}, {"mc", REG_MC}, {NULL, 0}};
static const struct choice curve_choices[] = {
    {"jop", CURVE_JOP}, {"barker_gray", CURVE_BARKER_GRAY}, {NULL, 0}};
static const struct choice fluidity_solver_choices[] = {
    {"auto", FLUIDITY_AUTO}, {"lines", FLUIDITY_LINES}, {"multigrid", FLUIDITY_MULTIGRID},
    {NULL, 0}};
static const struct choice mode_choices[] = {
    {"steady", MODE_STEADY}, {"transient", MODE_TRANSIENT}, {NULL, 0}};
static const struct choice dir_choices[] = {
    {"auto", -1}, {"x", 0}, {"y", 1}, {"z", 2}, {NULL, 0}};
static const struct choice axis_choices[] = {{"x", 0}, {"y", 1}, {"z", 2}, {NULL, 0}};
static const struct choice advection_choices[] = {
    {"centred", ADVECTION_CENTRED}, {"upwind", ADVECTION_UPWIND},
    {"vanleer", ADVECTION_VANLEER}, {"quick", ADVECTION_QUICK}, {NULL, 0}};
static const struct choice time_scheme_choices[] = {
    {"euler", TIME_EULER}, {"bdf2", TIME_BDF2}, {NULL, 0}};
static const struct choice precond_choices[] = {
    {"auto", PRECOND_AUTO}, {"line", PRECOND_LINE}, {"cholesky", PRECOND_CHOLESKY},
    {"lu", PRECOND_LU}, {"amg", PRECOND_AMG}, {"fourier", PRECOND_FOURIER},
    {"gmg", PRECOND_GMG}, {"multigrid", PRECOND_MULTIGRID}, {NULL, 0}};

/* Enum fields are written and read as int through memcpy. */
_Static_assert(sizeof(enum bc_kind) == sizeof(int), "enum size");
_Static_assert(sizeof(enum inflow_profile) == sizeof(int), "enum size");
_Static_assert(sizeof(enum rheology_law) == sizeof(int), "enum size");
_Static_assert(sizeof(enum regularisation) == sizeof(int), "enum size");
_Static_assert(sizeof(enum rheology_curve) == sizeof(int), "enum size");
_Static_assert(sizeof(enum solver_mode) == sizeof(int), "enum size");
_Static_assert(sizeof(enum preconditioner) == sizeof(int), "enum size");

#define T struct muflow_case
#define GT0 KEY_GT0
#define GE0 KEY_GE0
#define RANGE KEY_RANGE
#define NONE_LO KEY_NONE_LO
#define NONE_HI KEY_NONE_HI
#define DBL(s, n, m, r, h) KEY_DBL(T, s, n, m, h, r)
#define DBLT(s, n, m, r, t, h) KEY_DBLT(T, s, n, m, t, h, r)
#define INT(s, n, m, r, h) KEY_INT(T, s, n, m, h, r)
#define LNG(s, n, m, r, h) KEY_LNG(T, s, n, m, h, r)
#define BOOL(s, n, m, h) KEY_BOOL(T, s, n, m, h)
#define CHO(s, n, m, ch, h) KEY_CHO(T, s, n, m, ch, h)
#define STR(s, n, m, h) KEY_STR(T, s, n, m, h)
#define FACE_HELP(f) f " face: wall (no slip), slip (free slip), surface (flat stress-free free " \
                     "surface, p = 0), lid (moving no-slip wall), open (outflow / open top, "   \
                     "p = 0), inflow (prescribed velocity), periodic (on both faces)"
#define FACE_DOC                                                                                   \
    "Condition on the low / high face of each direction: `wall` no slip; `slip` free slip (zero "   \
    "normal velocity and shear stress); `surface` a flat stress-free free surface (as `slip`, and " \
    "the hydrostatic pressure is 0 on it); `lid` a no-slip wall moving in its own plane; `open` "   \
    "an open boundary, outflow or open top (p = 0, zero normal gradient of every velocity "         \
    "component, mass leaves or enters); `inflow` a prescribed velocity (`inflow_velocity` times "   \
    "`inflow_profile` along the normal, 0 across; needs an `open` face for the volume to leave "    \
    "by); `periodic` on both faces of a direction or on neither"
#define FACE(n, m, f) CHO("boundary", n, m, case_bc_choices, KEY_HELP(FACE_HELP(f), NULL, FACE_DOC))
#define BOX_DOC "Box size along x, y, z; the box is [0, lx] x [0, ly] x [0, lz]"
#define CELLS_DOC "Number of cells along x, y, z; their product at most 500000000"
#define BAND_DOC                                                                                   \
    "`lo hi h`: the direction stretched, with cells of about h in [lo, hi], growing by `growth` "   \
    "from cell to cell outside up to l/n, then l/n to the ends; several bands `lo hi h; lo hi h` " \
    "(at most 8, increasing, not overlapping) have the cells between two of them grow from both; " \
    "the number of cells follows (printed in the run's header); empty: uniform. Only with "        \
    "`solver.mode = steady`, `solver.coupled = on`, `physics.advection = off`, no open or inflow "  \
    "face, `solver.preconditioner` auto or lu, and the scenes `none` and `cylinder`"
#define PRECOND_DOC                                                                                \
    "Preconditioner of the implicit viscous solve. `line`: probed line blocks, exact for flows "   \
    "uniform across the lines. `cholesky`: probed sparse Cholesky of the symmetric operator (for " \
    "a steady Newton solve, of the diagonal tangent, preconditioning BiCGStab on the full "          \
    "tangent). `lu`: probed sparse LU of the full Newton tangent. `fourier`: for grids periodic in " \
    "the two directions across the lines, the line blocks of every plane Fourier mode, the three "  \
    "components coupled, from the operator averaged over the periodic planes; exact for a flow "   \
    "that varies only along the lines, whatever its viscosity contrast. `amg`: hypre's BoomerAMG " \
    "on the probed full tangent inside GMRES(20), one hierarchy per run of velocity components "     \
    "the matrix does not couple; fails with the augmentation; a GMRES that fails on a fresh "        \
    "hierarchy gives way to `lu` for the rest of the run where that fits (4e5 unknowns), with a "   \
    "warning. `gmg`: matrix-free geometric multigrid (zebra line Gauss-Seidel, W(1,1)) of each "   \
    "velocity component along a periodic direction, inside GMRES(20); needs a periodic direction " \
    "and every periodic direction one cell across (a cross-section: the heap, the ducts); not "     \
    "with `coupled`; a failed GMRES gives way to `lu` as above. `multigrid`: matrix-free "          \
    "geometric multigrid of every velocity component together (line Gauss-Seidel over the "        \
    "components, operator-dependent transfers; with the grad-div augmentation, the four faces "    \
    "around each edge solved together and divergence-keeping transfers; rediscretised coarse "     \
    "operators, only the coarsest "                                                                  \
    "level factorised) preconditioning CG, or GMRES(30) for the full Newton tangent; no probing "   \
    "and no factorisation of a grid-sized matrix; not on stretched grids; with `coupled`, GMRES(300) " \
    "on the saddle-point system preconditioned by its cycle and the viscosity-scaled pressure "    \
    "mass, no open face (docs/numerics/velocity-multigrid.md, coupled-step.md). `auto`, for grids varying in two "                      \
    "or more directions: `gmg` for the steady Newton solves of a scene whose flow runs along its "  \
    "cross-section's periodic direction (the heap, the ducts' mixed model, a body included) "      \
    "without augmentation or band; `multigrid` for the time-accurate (Picard) steps of a 2D flow " \
    "without augmentation or band, a body included (not that of a cross-section's flow with "     \
    "Newton named); else `amg` on a steady 2D cross-section with Newton, no "                       \
    "augmentation and more than 1e4 unknowns (5e4 where `cholesky` would serve, or with a body); " \
    "else `cholesky` on a 2D cross-section without open or inflow faces or a body up to 1e6 "       \
    "unknowns; else `lu` (`cholesky` without Newton) up to 4e5 unknowns; beyond them `amg` on a "   \
    "2D cross-section without augmentation, `multigrid` with it (no body, open or inflow face); "  \
    "`line` otherwise, and for grids varying in one "                                               \
    "direction. Without hypre's library, as if there were no `amg`. With `coupled`: `lu`, or "      \
    "`amg` where only its GMRES fits in memory"

/* The core keys, in the order case_write_ini writes them; the scene's own
 * section goes between [solver] and [output].  muflow --list prints their
 * help lines, muflow --list=markdown (docs/case_keys.md) their docs. */
const struct key case_core_keys[] = {
    CHO("case", "scene", scene, case_scene_choices,
        KEY_HELP("the flow problem: its exact or reference solution, profile and headline value "
                 "(the scenes above)",
                 NULL,
                 "The flow problem: its set-up, its exact or reference solution, its profile "
                 "and headline value, and its own section of keys (the scenes above)")),
    STR("case", "reference",
        reference,
        KEY_HELP("published data to compare with (CSV rows dataset,parameter,coord,value), a path "
                 "relative to the case file's folder",
                 NULL,
                 "Published data to compare with (CSV rows `dataset,parameter,coord,value`), a "
                 "path relative to the case file's folder; the file must exist; stored as an "
                 "absolute path")),

    DBL("domain", "lx", len[0], GT0, KEY_HELP("box size along x", "length", BOX_DOC)),
    DBL("domain", "ly", len[1], GT0, KEY_HELP("box size along y", "length", BOX_DOC)),
    DBL("domain", "lz", len[2], GT0, KEY_HELP("box size along z", "length", BOX_DOC)),
    INT("domain", "nx", n[0], RANGE(1, 100000000, 1, 1),
        KEY_HELP("cells along x (nx*ny*nz at most 500000000)", NULL, CELLS_DOC)),
    INT("domain", "ny", n[1], RANGE(1, 100000000, 1, 1),
        KEY_HELP("cells along y (nx*ny*nz at most 500000000)", NULL, CELLS_DOC)),
    INT("domain", "nz", n[2], RANGE(1, 100000000, 1, 1),
        KEY_HELP("cells along z (nx*ny*nz at most 500000000)", NULL, CELLS_DOC)),
    STR("domain", "x_band", band[0],
        KEY_HELP("'lo hi h': x refined to cells of about h in [lo, hi], growing by domain.growth "
                 "from cell to cell outside up to lx / nx (empty: uniform lx / nx); the count "
                 "follows; several bands 'lo hi h; lo hi h' (at most 8, increasing)",
                 "length", BAND_DOC)),
    STR("domain", "y_band", band[1],
        KEY_HELP("'lo hi h': y refined in [lo, hi], as domain.x_band", "length", BAND_DOC)),
    STR("domain", "z_band", band[2],
        KEY_HELP("'lo hi h': z refined in [lo, hi], as domain.x_band", "length", BAND_DOC)),
    DBL("domain", "growth", growth, RANGE(1, 1.5, 0, 1),
        "size ratio of neighbouring cells outside a band"),

    FACE("xlo", bc.face[0][0], "low x"),
    FACE("xhi", bc.face[0][1], "high x"),
    FACE("ylo", bc.face[1][0], "low y"),
    FACE("yhi", bc.face[1][1], "high y"),
    FACE("zlo", bc.face[2][0], "low z"),
    FACE("zhi", bc.face[2][1], "high z"),
    DBL("boundary", "lid_velocity", bc.lid_velocity, RANGE(NONE_LO, NONE_HI, 0, 0),
        KEY_HELP("speed of every lid face", "velocity", NULL)),
    CHO("boundary", "lid_direction", bc.lid_direction, axis_choices,
        "velocity component a lid drives (in the lid's plane)"),
    DBL("boundary", "inflow_velocity", bc.inflow_velocity, RANGE(NONE_LO, NONE_HI, 0, 0),
        KEY_HELP("normal speed into the domain on every inflow face (the peak of a parabola)",
                 "velocity", NULL)),
    CHO("boundary", "inflow_profile", bc.inflow_profile, profile_choices,
        KEY_HELP("inflow profile across the face: uniform, or parabolic 4 s (L - s) / L^2 in each "
                 "non-periodic direction of the face",
                 NULL,
                 "Profile across an `inflow` face: `uniform`, or `parabolic` 4 s (L - s) / L^2 "
                 "across each non-periodic direction of the face (their product in 3D), 0 on the "
                 "edges and 1 in the middle")),

    STR("obstacle", "shapes", obstacle.shapes,
        KEY_HELP("solid bodies as a union of shapes in the plane's coordinates (A, B), extruded "
                 "along the third direction: 'circle A B R', 'rectangle A0 B0 A1 B1' and 'slope AC BR "
                 "THETA R' joined by ';' (empty: none); each must reach into the box and span a cell each way, a "
                 "channel's inflow and outlet stay joined by fluid, and the fluid is one region "
                 "or regions that each reach a surface or open face",
                 "length",
                 "Solid bodies inside the box, a union of shapes in the plane's coordinates (A, "
                 "B), extruded along the third direction: `circle A B R` (centre, radius) and "
                 "`rectangle A0 B0 A1 B1` (two opposite corners) and `slope AC BR THETA R` (the ground "
                 "below a bed descending at THETA radians towards +A, bent by an arc of radius "
                 "R into the level floor B = BR, which it meets at A = AC), joined by `;`; "
                 "empty: none. "
                 "Refused: a shape that does not reach into the box or spans less than a cell "
                 "along either direction of its plane, shapes that leave no cell centre in the "
                 "fluid, a body that closes the channel (no path of fluid cells between an "
                 "inflow face and the opposite face, or between two open faces of one "
                 "direction), and a body that splits the fluid into regions one of which "
                 "reaches no `surface` or `open` face (its pressure would be undetermined)")),
    CHO("obstacle", "plane", obstacle.plane, case_plane_choices,
        "the grid directions of the shapes' coordinates A and B"),
    BOOL("obstacle", "invert", obstacle.invert,
         "the fluid is inside the shapes and the solid outside (a duct)"),
    CHO("obstacle", "boundary", obstacle.boundary, obstacle_boundary_choices,
        "no slip on the body: sharp (each grid link the surface cuts ends on the surface, "
        "second order), staircase (velocity nodes inside the body held at 0, first order) or "
        "cells (a cell whose centre is in the body is solid, its faces closed, no slip on "
        "them: no cell is cut, so a VOF tracer combines with it; first order)"),

    DBLT("physics", "tilt", tilt, RANGE(-HALF_PI, HALF_PI, 1, 1),
         "must be in [-pi/2, pi/2] (radians)",
         KEY_HELP("tilt alpha of gravity: g = gravity (sin alpha, 0, -cos alpha)", "rad", NULL)),
    DBL("physics", "gravity", gravity, GE0,
        KEY_HELP("magnitude g of gravity", "length/time^2", NULL)),
    DBL("physics", "density", density, GT0,
        KEY_HELP("bulk density (phi rho_s) in the momentum equation", "mass/length^3", NULL)),
    DBL("physics", "confining_pressure", confining_pressure, GE0,
        KEY_HELP("pressure added to the pressure that enters the rheology", "pressure", NULL)),
    BOOL("physics", "advection", advection, "explicit advection of momentum (off: Stokes-like)"),
    CHO("physics", "advection_scheme", advection_scheme, advection_choices,
        KEY_HELP("form of the advection term: centred (second order, energy-neutral), upwind "
                 "(first order, donor cell), vanleer (upwind, second order with van Leer's "
                 "limiter) or quick (upwind-biased, unlimited)",
                 NULL,
                 "Form of the advection term: `centred` (conservative, second order, "
                 "energy-neutral), `upwind` (conservative donor cell, first order), `vanleer` "
                 "(upwind, second order with van Leer's limiter) or `quick` (Leonard's QUICK, "
                 "the face value 3/4 of the upwind node, 3/8 of the downwind, -1/8 of the second "
                 "upwind: unlimited, its error dissipative where the centred form's disperses; "
                 "the Schaefer-Turek 2D-2 in the benchmark's bands on D/40, "
                 "docs/validation/cylinder_benchmark.md). Under the forward-Euler step the "
                 "centred form adds energy where no viscosity damps it, such as a granular free "
                 "surface, where the pressure and so the mu(I) viscosity vanish")),

    CHO("rheology", "law", rheo.law, law_choices,
        "viscosity law: mu(I), Bingham, Newtonian or ngf (nonlocal granular fluidity)"),
    CHO("rheology", "regularisation", rheo.reg, reg_choices,
        KEY_HELP("form of the regularised yield term (include/kernels/rheology.h)", NULL,
                 "Form of the regularised viscosity (Chauchat & Medale 2014, eqs. 9-12), with "
                 "D0 = I_0 sqrt(p / rho_s) / d: `simple` mu_s p / (|D| + lambda) + delta_mu p / "
                 "(D0 + |D| + lambda); `bercovier` mu_s p / sqrt(|D|^2 + lambda^2) + the same "
                 "second term; `papanastasiou` mu_s p (1 - exp(-|D| / lambda)) / |D| + the same; "
                 "`mc` (mu_s + delta_mu |D| / (D0 + |D|)) p / sqrt(|D|^2 + lambda^2). Bingham: "
                 "the same forms of the yield term with tau_0 for mu_s p, plus the plastic "
                 "viscosity (`include/kernels/rheology.h`)")),
    DBL("rheology", "lambda", rheo.lambda, RANGE(0, 1, 0, 1),
        KEY_HELP("regularisation parameter, a shear rate (also of the pressure regularisation)",
                 "1/time", NULL)),
    DBL("rheology", "mu_s", rheo.mu_s, GE0,
        "static friction coefficient mu_s (mu(I), ngf; glass beads for ngf: 0.3819)"),
    DBL("rheology", "delta_mu", rheo.delta_mu, GE0, "friction increase mu_2 - mu_s (mu(I))"),
    DBL("rheology", "i0", rheo.i0, GT0, "reference inertial number I_0 (mu(I))"),
    CHO("rheology", "curve", rheo.curve, curve_choices,
        KEY_HELP("friction curve of mu(I): jop (mu_s + delta_mu I/(I0 + I)) or barker_gray "
                 "(partially regularised, well posed below I_1^N; include/kernels/rheology.h)",
                 NULL,
                 "Friction curve of mu(I): `jop` (Jop, Forterre & Pouliquen 2006, mu_s + delta_mu "
                 "I / (I_0 + I)) or `barker_gray` (the partially regularised curve of Barker & "
                 "Gray 2017: sqrt(alpha / ln(A_minus / I)) for I <= I_1^N, (mu_s I_0 + mu_2 I + "
                 "mu_inf I^2) / (I_0 + I) above, mu_2 = mu_s + delta_mu; "
                 "`include/kernels/rheology.h`)")),
    DBLT("rheology", "alpha", rheo.alpha, RANGE(0, 2, 0, 0),
         "must be in (0, 2): the barker_gray low-I branch is well posed only for alpha < 2",
         "barker_gray: alpha of the low-I branch mu = sqrt(alpha / ln(A_minus / I)), well posed "
         "only for alpha < 2"),
    DBL("rheology", "mu_inf", rheo.mu_inf, GE0,
        "barker_gray: mu_inf of the high-I branch (mu_s I0 + mu_2 I + mu_inf I^2) / (I0 + I)"),
    DBL("rheology", "phi", rheo.phi, RANGE(0, 1, 0, 1), "solid volume fraction phi"),
    DBL("rheology", "grain_diameter", rheo.grain_diameter, GT0,
        KEY_HELP("grain diameter d", "length", NULL)),
    {.section = "rheology",
     .name = "grain_density",
     .type = K_DOUBLE,
     .off = offsetof(T, rheo.grain_density),
     GT0,
     .help = "grain density rho_s; 1/phi after the file and all overrides unless given",
     .default_text = "1/phi",
     .units = "mass/length^3",
     .doc = "Grain density rho_s; unless given, 1/phi, computed after the file and all "
            "overrides (so changing `phi` changes it)"},
    BOOL("rheology", "pressure_regularisation", rheo.pressure_regularisation,
         "the pressure in mu(I) is (p + sqrt(p^2 + lambda^2)) / 2 (off: max(p, 0))"),
    DBL("rheology", "yield_stress", rheo.yield_stress, GE0,
        KEY_HELP("Bingham yield stress tau_0, in simple shear", "pressure",
                 "Bingham yield stress tau_0 in simple shear: the material yields where "
                 "sqrt(tau:tau / 2) >= tau_0 (sqrt(2) times smaller than a tau_0 written "
                 "with sqrt(D:D), as by Vola et al. 2003)")),
    DBL("rheology", "plastic_viscosity", rheo.plastic_viscosity, GE0,
        KEY_HELP("Bingham plastic viscosity", "pressure time", NULL)),
    DBL("rheology", "viscosity", rheo.viscosity, GT0,
        KEY_HELP("Newtonian viscosity", "pressure time", NULL)),
    DBL("rheology", "nonlocal_a", rheo.nonlocal_a, GT0,
        KEY_HELP("ngf: nonlocal amplitude A, the cooperative length A d / sqrt|mu - mu_s|", NULL,
                 "ngf: the nonlocal amplitude A of A^2 d^2 lap(g) in the fluidity equation; "
                 "the cooperative length is A d / sqrt|mu - mu_s|. Glass beads: 0.48 (Henann & "
                 "Kamrin 2013)")),
    DBL("rheology", "nonlocal_b", rheo.nonlocal_b, GT0,
        KEY_HELP("ngf: rate sensitivity b of the local law mu = mu_s + b I", NULL,
                 "ngf: the rate sensitivity b of the fluidity equation's b sqrt(rho_s d^2 / p) mu "
                 "g^2 term; the local law it gives is mu = mu_s + b I. Glass beads: 0.9377 "
                 "(Henann & Kamrin 2013)")),
    CHO("rheology", "fluidity_solver", rheo.fluidity_solver, fluidity_solver_choices,
        KEY_HELP("ngf: the fluidity equation's solver: auto, lines (along z) or multigrid",
                 NULL,
                 "ngf: how the fluidity equation is solved. `lines`: one tridiagonal solve "
                 "along z per column, the lateral part of lap(g) left out (layered flows: x "
                 "and y periodic); `multigrid`: the whole box by the cell-centred multigrid "
                 "with its screening term (uniform grids); `auto`: lines when x and y are "
                 "periodic, else multigrid")),
    INT("rheology", "fluidity_anderson", rheo.fluidity_anderson, RANGE(0, 8, 1, 1),
        KEY_HELP("ngf: the steady iteration's Anderson depth (0: plain Picard)", NULL,
                 "ngf, steady mode: a step with dt large beside rho h^2 / eta is one Picard "
                 "iteration of the fluidity (the momentum with eta = p / (g + lambda), then g "
                 "from the new shear rates); once these contract, the next fluidity is the "
                 "combination of the last depth + 1 iterations' values whose residual is least "
                 "(Anderson acceleration), cut at 0, and a creeping layer's growing fluidity is "
                 "scaled up to 1e-2 of the inertial rate sqrt(p / rho_s) / d. 0: plain Picard. "
                 "Transient steps are never accelerated")),

    CHO("solver", "mode", mode, mode_choices,
        "steady: pseudo-time march to a steady state; transient: march to solver.end_time"),
    DBL("solver", "tolerance", tolerance, RANGE(0, 1, 0, 0),
        "steady: stop when the relative residual falls below this"),
    LNG("solver", "max_steps", max_steps, RANGE(1, 1e9, 1, 1), "largest number of time steps"),
    DBL("solver", "end_time", end_time, GT0, KEY_HELP("transient: time to reach", "time", NULL)),
    DBL("solver", "steady_tolerance", steady_tolerance, RANGE(0, 1, 1, 0),
        "transient: stop at a steady state once the relative residual and divergence fall "
        "below this, as the steady mode's tolerance (0: run to end_time)"),
    DBL("solver", "dt", dt, GT0,
        KEY_HELP("steady: initial pseudo-time step; transient: upper bound of the step", "time",
                 NULL)),
    DBL("solver", "dt_max", dt_max, GT0,
        KEY_HELP("steady: cap of the growing pseudo-time step (>= dt)", "time", NULL)),
    DBL("solver", "cfl", cfl, RANGE(0, 2, 0, 1), "advective CFL number (with physics.advection)"),
    CHO("solver", "time_scheme", time_scheme, time_scheme_choices,
        KEY_HELP("transient: euler (first order: backward-Euler viscous step, explicit "
                 "advection) or bdf2 (second order: BDF2 with the advection extrapolated)",
                 NULL,
                 "Transient steps: `euler`, first order (backward-Euler viscous step, "
                 "forward-Euler advection, incremental projection); `bdf2`, second order "
                 "(the viscous step by BDF2 with variable-step coefficients, the advection "
                 "extrapolated from the last two steps, the projection with the BDF2 mass; the "
                 "first step by Euler). Only with `solver.mode = transient` and no module that "
                 "solves the step itself (the bed's second velocity). "
                 "The body force, the modules' terms and a non-Newtonian viscosity stay first "
                 "order (docs/numerics/time-step.md)")),
    BOOL("solver", "newton", newton,
         KEY_HELP("consistent tangent viscosity in steady mode (off: Picard, lagged viscosity; a "
                  "transient step always lags it)",
                  NULL,
                  "Steady mode: the consistent tangent of the viscosity (Newton); `off`: Picard, "
                  "the viscosity lagged. A transient (time-accurate) step always lags the "
                  "viscosity: the tangent's linearly implicit step overshoots on the friction "
                  "plateau")),
    DBL("solver", "continuation", continuation, RANGE(1, 1e12, 1, 1),
        "steady: solve with rheology.lambda times this first, then lower lambda 10-fold each "
        "time the residual has fallen 1000-fold, to rheology.lambda (1: off)"),
    DBL("solver", "newton_below", newton_below, RANGE(0, 1, 0, 1),
        KEY_HELP("the tangent is used once the residual has fallen below this times the first "
                 "residual or the largest since, if larger (Picard before; 1: from the start)",
                 NULL,
                 "Use the tangent only once the residual has fallen below this times the first "
                 "residual, or the largest residual since if that is larger; Picard steps before, "
                 "and Picard steps that stall hand over below its square root; `1`: the tangent "
                 "from the start")),
    BOOL("solver", "coupled", coupled,
         KEY_HELP("steady: each step solves velocity and pressure together (the saddle-point "
                  "system of the step by the sparse LU, or with solver.preconditioner = amg by "
                  "GMRES with the AMG of the velocity block and a least-squares commutator for "
                  "the pressure, with multigrid by GMRES with the velocity multigrid and the "
                  "viscosity-scaled pressure mass, either falling back to the LU if it fails) "
                  "instead of the implicit "
                  "step and the projection; for flows whose pressure the projection's pseudo-time "
                  "march does not converge (around a body, the cavity without augmentation, "
                  "through open faces)",
                  NULL,
                  "Steady mode: each step solves the velocity and pressure increments from one "
                  "saddle-point system (the step's probed operator with the pressure gradient and "
                  "the divergence) by UMFPACK's sparse LU (`src/march/stage_coupled.c`), instead "
                  "of the implicit step and the projection; with `preconditioner = amg` by GMRES "
                  "with BoomerAMG on the velocity block and a least-squares commutator for the "
                  "pressure (`src/solvers/saddle_krylov.c`), which gives way to the LU for the "
                  "rest of the run if it fails (refused on mu(I) and with open faces); with "
                  "`preconditioner = multigrid` by GMRES(300) with the velocity multigrid's cycle "
                  "on the velocity block and the viscosity-scaled pressure mass for the pressure "
                  "(`src/march/coupled_mg.c`; the same fallback; refused with open faces). For flows "
                  "whose pressure the projection's pseudo-time march does not converge: a flow "
                  "around a body, the Bingham cavity without `augmentation`, a flow through open "
                  "faces (each open face's balance is a row of the system). Needs `mode = "
                  "steady`, `augmentation = 0` and a scene without physics modules (bodies "
                  "allowed)")),
    STR("solver", "initial_state", initial_state,
        KEY_HELP("a checkpoint (a run folder or its checkpoint.h5) of the same box on any grid: "
                 "its velocity, pressure and modules' fields, interpolated to this grid, start "
                 "the run instead of the scene's state (a steady solve from a coarser mesh's "
                 "solution); empty: the scene's",
                 NULL,
                 "A checkpoint (a run folder or its `checkpoint.h5`) of the same box on any "
                 "uniform grid: its velocity, dynamic pressure and modules' fields, interpolated "
                 "trilinearly to this grid, start the run at step 0 instead of the scene's "
                 "initial state (grid sequencing); another box is refused; empty: the scene's "
                 "start")),
    CHO("solver", "preconditioner", preconditioner, precond_choices,
        KEY_HELP("of the implicit solve: line blocks, sparse Cholesky (of the symmetric operator; "
                 "with newton, of the diagonal tangent, preconditioning BiCGStab on the full "
                 "tangent) or LU, AMG, or fourier (the line blocks of every plane Fourier mode, "
                 "for periodic directions across the lines), or gmg (geometric multigrid of the "
                 "velocity components along periodic directions inside GMRES, matrix-free: flows "
                 "along a periodic direction such as the heap and the ducts), or multigrid "
                 "(every component's geometric multigrid, matrix-free; with solver.coupled, GMRES on "
                 "the saddle-point system with its cycle and the viscosity-scaled pressure mass) "
                 "(auto, for grids "
                 "varying in two or more directions: gmg for the steady newton solves of the heap "
                 "and the ducts' mixed model without augmentation or a band, multigrid for the "
                 "transient steps of a 2D flow without augmentation or a band, else "
                 "amg on a steady 2D cross-section with newton, no augmentation and over 1e4 "
                 "unknowns (5e4 where cholesky would serve or with a body), else cholesky on a 2D "
                 "cross-section without open or inflow faces up to 1e6 unknowns, lu up to 4e5 "
                 "unknowns, beyond them amg on a 2D cross-section without augmentation, "
                 "multigrid with it; line "
                 "otherwise; with solver.coupled lu, or amg where only its GMRES fits in memory)",
                 NULL, PRECOND_DOC)),
    DBL("solver", "augmentation", augmentation, GE0,
        KEY_HELP("kappa of the augmented-Lagrangian term -grad(r div u), r = kappa max(eta) (0: "
                 "off)",
                 NULL,
                 "kappa of the augmented-Lagrangian term -grad(r div u), r = kappa max(eta) (one "
                 "value over the grid, so that a stiff plug beside a yielded layer cannot stall "
                 "the pressure), with the matching Uzawa pressure update; the steady residual is "
                 "that of the unaugmented problem; lets the pressure converge at large "
                 "pseudo-time steps in 2D flows; `0`: off")),
    DBL("solver", "linear_tolerance", linear_tolerance, RANGE(0, 1, 0, 0),
        "relative tolerance of the implicit viscous solve"),
    BOOL("solver", "inexact_newton", inexact_newton,
         KEY_HELP("steady Newton steps solved with amg, cholesky, gmg or multigrid: the linear "
                  "tolerance follows the residual's last decrease (Eisenstat-Walker), down to "
                  "linear_tolerance",
                  NULL,
                  "Steady Newton steps solved with `amg`, `cholesky`, `gmg` or `multigrid` (not "
                  "the coupled step's multigrid: 51 steps against 34 on the cavity): the "
                  "linear tolerance follows the residual's last decrease (Eisenstat and Walker's "
                  "forcing term, gamma 0.9, exponent 2), at most 0.1 (0.01 with `gmg`) and the "
                  "relative residual, at least `linear_tolerance`; the LU solves exactly whatever "
                  "the tolerance; `off`: every solve to `linear_tolerance`")),
    INT("solver", "max_linear_iterations", max_linear_iterations, RANGE(1, 1e6, 1, 1),
        "iteration cap of the implicit viscous solve"),
    BOOL("solver", "pressure_factorisation", pressure_factorisation,
         KEY_HELP("the projection factorises the whole grid on 2D grids of at most 32,768 cells "
                  "with a variable density or a body; off: the multigrid's cycles",
                  NULL,
                  "The projection's variable-coefficient Poisson solve (a varying density, or a "
                  "body) on a 2D grid of at most 32,768 cells: the whole grid factorised by "
                  "CHOLMOD at each new coefficient, beside the implicit step, which is faster "
                  "there (measured in docs/numerics/pressure.md), counted as "
                  "`pressure_matrices` in summary.ini; "
                  "`off`: the multigrid's cycles under CG, only its coarsest level factorised. "
                  "Larger and 3D grids always take the cycles")),
    INT("solver", "preconditioner_reuse", preconditioner_reuse, RANGE(0, 1e6, 1, 1),
        KEY_HELP("a cholesky, lu, fourier or amg preconditioner serves up to this many further "
                 "steps while the Krylov iterations stay within twice its first solve's plus 2 (0: "
                 "one every step)",
                 NULL,
                 "A `cholesky`, `lu`, `fourier` or `amg` preconditioner (its factors, probes or "
                 "hierarchy) serves up to this many further steps while the Krylov iterations stay "
                 "within twice those of its first solve plus 2 (a failed solve builds a new one); "
                 "the solution is the same to `linear_tolerance`, only the iterations change. "
                 "Pays where the operator changes little from step to step; `0`: a new one every "
                 "step")),
    CHO("solver", "line_direction", line_direction, dir_choices,
        "direction of the preconditioner lines, a non-periodic one (auto: chosen by the solver)"),
    DBL("solver", "progress_interval", progress_interval, GE0,
        KEY_HELP("wall-clock seconds between progress lines (0: every step)", "s", NULL)),

    {.section = "output",
     .name = "dir",
     .type = K_STRING,
     .off = offsetof(T, output_dir),
     .size = sizeof(((T *)0)->output_dir),
     .help = "output folder",
     .default_text = "out/<case name>",
     .doc = "Output folder; without control characters, and without `;` at the start or after "
            "a blank (it would start a comment)"},
    BOOL("output", "quiet", quiet, "no progress lines"),
    BOOL("output", "fields", fields,
         KEY_HELP("write HDF5 field files (fields_<step>.h5) and fields.xdmf", NULL,
                  "Write HDF5 field files (`fields_NNNNNN.h5`) and `fields.xdmf`")),
    LNG("output", "fields_every", fields_every, RANGE(0, 1e9, 1, 1),
        KEY_HELP("a field file every this many steps, also step 0 (0: none by step count)",
                 "steps", NULL)),
    DBL("output", "fields_interval", fields_interval, GE0,
        KEY_HELP("a field file each time t passes a multiple of this, also t = 0 (0: none by time)",
                 "time", NULL)),
    LNG("output", "checkpoint_every", checkpoint_every, RANGE(0, 1e9, 1, 1),
        KEY_HELP("a checkpoint every this many steps (0: only when the run is stopped)", "steps",
                 "A checkpoint (`checkpoint.h5`, replacing the previous one) every this many "
                 "steps; `0`: only at the end of the run")),
    LNG("output", "forces_every", forces_every, RANGE(0, 1e9, 1, 1),
        KEY_HELP("a row of forces.csv (the forces on the bodies) every this many steps, and "
                 "the final state's (0: no file)",
                 "steps",
                 "A case with `[obstacle]` shapes (a body in the flow, not `invert`) writes "
                 "`forces.csv`: a row every this many steps and one of the final state (the "
                 "summary's numbers), with `step`, `time`, `drag_force`, `lift_force` and, "
                 "where the summary has them, `drag_coefficient`, `lift_coefficient`, "
                 "`pressure_drop`; `0`: no file")),
};
#undef FACE
#define NKEYS ((int)(sizeof(case_core_keys) / sizeof(case_core_keys[0])))
const int case_core_nkeys = NKEYS;
_Static_assert(NKEYS <= CORE_KEYS_MAX, "CORE_KEYS_MAX: room for every core key");

/* What each core section is for, before its table in docs/case_keys.md. */
static const struct {
    const char *section, *intro;
} section_intros[] = {
    {"domain", "The box and its grid, uniform unless a band stretches a direction."},
    {"boundary",
     "`periodic` must be on both faces of a direction or on neither, and at least one direction "
     "must not be periodic (the implicit solve works along it). An `inflow` face (with "
     "`inflow_velocity` not 0) needs an `open` face for its volume to leave by; an `open` face "
     "needs at least 2 cells along its direction and `solver.augmentation = 0`."},
    {"obstacle",
     "Solid bodies in the flow. A case with shapes runs the projection through the multigrid "
     "solver (the faces the body closes take the coefficient 0, the cut cells' faces their open "
     "share) and writes `drag_coefficient`, `lift_coefficient`, `pressure_drop` and the forces "
     "(with the control-volume cross-check) to the summary, `obstacle_surface.csv` (the "
     "stresses around the body against the angle) and `forces.csv` (the forces through the "
     "run, `output.forces_every`). A case whose scene transports a tracer (the "
     "collapse) can have shapes only with `boundary = cells` (the slope_release's bed)."},
    {"physics", "Gravity, the density and the terms of the momentum equation."},
    {"rheology",
     "The viscosity law. `law = bingham` needs `plastic_viscosity > 0` or `yield_stress > 0`; "
     "`law = newtonian` needs `viscosity > 0`. With `law = mui` and `curve = barker_gray`, I_1^N "
     "(the lower root of the well-posedness function C(I) of the `jop` curve with these `mu_s`, "
     "`delta_mu`, `i0`) and A_minus = I_1^N exp(alpha / mu(I_1^N)^2) are computed when the case "
     "is loaded; parameters whose `jop` curve is ill posed throughout the bracket are refused, "
     "naming `rheology.mu_s`, `rheology.delta_mu` and `rheology.i0`. `law = ngf` is the "
     "nonlocal granular fluidity (`mu_s`, `nonlocal_a`, `nonlocal_b`; "
     "docs/numerics/rheology.md): along z lines for layered flows (periodic x and y), by its "
     "multigrid on other uniform grids on one process (the column collapse under air); not in "
     "the coupled step."},
    {"solver",
     "The march: steady (a pseudo-time march to the steady state) or transient (to `end_time`), "
     "and the solvers of its steps."},
    {"output",
     "Whatever the schedule, a field file of the final state is written at the end of every run "
     "(unless `fields = off`), and a checkpoint. The run's `summary.ini` repeats every key with "
     "the value used, in the order of these tables; reading it back gives the same case."},
};

const char *case_section_intro(const char *section)
{
    for (size_t i = 0; i < sizeof section_intros / sizeof section_intros[0]; i++)
        if (strcmp(section_intros[i].section, section) == 0)
            return section_intros[i].intro;
    return NULL;
}

/* ------------------------------------------------------------------------ */
/* The defaults: what a case file may leave out */

void case_defaults(struct muflow_case *c)
{
    memset(c, 0, sizeof(*c));
    snprintf(c->name, sizeof(c->name), "case");
    case_set_scene(c, 0); /* "none" */
    for (int d = 0; d < 3; d++) {
        c->len[d] = 1.0;
        c->n[d] = 1;
        c->band[d][0] = '\0';
        c->bc.face[d][0] = BC_PERIODIC;
        c->bc.face[d][1] = BC_PERIODIC;
    }
    c->growth = 1.1;
    c->bc.lid_velocity = 1.0;
    c->bc.lid_direction = 0;
    c->bc.inflow_velocity = 1.0;
    c->bc.inflow_profile = INFLOW_UNIFORM;
    c->tilt = 0.0;
    c->gravity = 1.0;
    c->density = 1.0;
    c->confining_pressure = 0.0;
    c->advection = 1;

    c->rheo.law = LAW_MUI;
    c->rheo.reg = REG_MC;
    c->rheo.lambda = 1e-4;
    c->rheo.pressure_regularisation = 1;
    c->rheo.mu_s = 0.383;
    c->rheo.delta_mu = 0.26;
    c->rheo.i0 = 0.279;
    c->rheo.curve = CURVE_JOP;
    c->rheo.alpha = 1.9;  /* Barker & Gray (2017), partially regularised mu(I) */
    c->rheo.mu_inf = 0.05;
    c->rheo.phi = 0.6;
    c->rheo.grain_diameter = 1.0;
    c->rheo.grain_density = 1.0 / 0.6;
    c->rheo.yield_stress = 0.0;
    c->rheo.plastic_viscosity = 0.0;
    c->rheo.viscosity = 1.0;
    c->rheo.nonlocal_a = 0.48;  /* glass beads, Henann & Kamrin (2013) */
    c->rheo.nonlocal_b = 0.9377;
    c->rheo.fluidity_anderson = 5;

    c->mode = MODE_STEADY;
    c->tolerance = 1e-10;
    c->max_steps = 10000;
    c->end_time = 1.0;
    c->dt = 1e-2;
    c->dt_max = 1e12;
    c->cfl = 0.5;
    c->newton = 1;
    c->newton_below = 1.0;
    c->continuation = 1.0;
    c->linear_tolerance = 1e-8;
    c->inexact_newton = 1;
    c->pressure_factorisation = 1;
    c->max_linear_iterations = 500;
    c->line_direction = -1;
    c->preconditioner = PRECOND_AUTO;
    c->progress_interval = 1.0;

    snprintf(c->output_dir, sizeof(c->output_dir), "out/%s", c->name);
    c->quiet = 0;
    c->fields = 1;
    c->fields_every = 0;
    c->fields_interval = 0.0;
    c->checkpoint_every = 0;
    c->forces_every = 1;
}

/* ------------------------------------------------------------------------ */
/* The core keys by name and by index */

int case_core_key_index(const char *section, const char *name)
{
    for (int i = 0; i < NKEYS; i++)
        if (strcmp(case_core_keys[i].section, section) == 0 &&
            strcmp(case_core_keys[i].name, name) == 0)
            return i;
    return -1;
}

int case_key_count(void) { return NKEYS; }

const struct key *case_key_at(int i) { return i >= 0 && i < NKEYS ? &case_core_keys[i] : NULL; }
