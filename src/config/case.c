/* The case keys: the core key table, the scene's own section, defaults,
 * checks that need every key, loading and writing back (case.h).
 *
 * Loading is two passes over the events of the INI engine (ini.h): the file,
 * then the overrides in order.  The first finds the scene (the last valid
 * case.scene), whose own section is then known; the second applies every
 * event in order and stops at the first error, so that the message names
 * the first bad line or override.  Every key is described once, in the
 * tables below or in its scene's key_block; parsing, range checks, writing
 * back and the checkpoint all use them (keys.h). */
#define _XOPEN_SOURCE 700 /* realpath */
#include "config/case.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include "config/ini.h"
#include "config/keys.h"
#include "solvers/viscous_gmg.h"
#include "grid/grid.h"
#include "grid/shapes.h"
#include "march/march.h"
#include "scenes/scene.h"

#define HALF_PI 1.57079632679489661923
#define MAX_CELLS 500000000.0 /* cap on nx*ny*nz */
#define SHOWN_MAX INI_SHOWN_MAX
#define shown ini_shown

extern const struct choice scene_choice_table[];
static const struct choice bc_choices[] = {
    {"periodic", BC_PERIODIC}, {"wall", BC_WALL}, {"slip", BC_SLIP},
    {"surface", BC_SURFACE}, {"lid", BC_LID}, {"open", BC_OPEN}, {"inflow", BC_INFLOW}, {NULL, 0}};
static const struct choice profile_choices[] = {
    {"uniform", INFLOW_UNIFORM}, {"parabolic", INFLOW_PARABOLIC}, {NULL, 0}};
static const struct choice plane_choices[] = {
    {"xz", OBSTACLE_XZ}, {"xy", OBSTACLE_XY}, {"yz", OBSTACLE_YZ}, {NULL, 0}};
static const struct choice obstacle_boundary_choices[] = {
    {"sharp", OBSTACLE_SHARP}, {"staircase", OBSTACLE_STAIRCASE}, {NULL, 0}};
static const struct choice law_choices[] = {
    {"mui", LAW_MUI}, {"bingham", LAW_BINGHAM}, {"newtonian", LAW_NEWTONIAN}, {NULL, 0}};
static const struct choice reg_choices[] = {
    {"simple", REG_SIMPLE}, {"bercovier", REG_BERCOVIER},
    {"papanastasiou", REG_PAPANASTASIOU}, {"mc", REG_MC}, {NULL, 0}};
static const struct choice curve_choices[] = {
    {"jop", CURVE_JOP}, {"barker_gray", CURVE_BARKER_GRAY}, {NULL, 0}};
static const struct choice mode_choices[] = {
    {"steady", MODE_STEADY}, {"transient", MODE_TRANSIENT}, {NULL, 0}};
static const struct choice dir_choices[] = {
    {"auto", -1}, {"x", 0}, {"y", 1}, {"z", 2}, {NULL, 0}};
static const struct choice axis_choices[] = {{"x", 0}, {"y", 1}, {"z", 2}, {NULL, 0}};
static const struct choice advection_choices[] = {
    {"centred", ADVECTION_CENTRED}, {"upwind", ADVECTION_UPWIND},
    {"vanleer", ADVECTION_VANLEER}, {NULL, 0}};
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
#define FACE(n, m, f) CHO("boundary", n, m, bc_choices, KEY_HELP(FACE_HELP(f), NULL, FACE_DOC))
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
    "components, operator-dependent transfers, rediscretised coarse operators, only the coarsest " \
    "level factorised) preconditioning CG, or GMRES(30) for the full Newton tangent; no probing "   \
    "and no factorisation of a grid-sized matrix; not on stretched grids nor with `coupled` "       \
    "(docs/numerics/velocity-multigrid.md). `auto`, for grids varying in two "                      \
    "or more directions: `gmg` for the steady Newton solves of a scene whose flow runs along its "  \
    "cross-section's periodic direction (the heap, the square duct's mixed model) without "        \
    "augmentation, body or band; else `amg` on a steady 2D cross-section with Newton, no "          \
    "augmentation and more than 1e4 unknowns (5e4 where `cholesky` would serve, or with a body); " \
    "else `cholesky` on a 2D cross-section without open or inflow faces or a body up to 1e6 "       \
    "unknowns; else `lu` (`cholesky` without Newton) up to 4e5 unknowns; beyond them `amg` on a "   \
    "2D cross-section without augmentation; `line` otherwise, and for grids varying in one "        \
    "direction. Without hypre's library, as if there were no `amg`. With `coupled`: `lu`, or "      \
    "`amg` where only its GMRES fits in memory"

/* The core keys, in the order case_write_ini writes them; the scene's own
 * section goes between [solver] and [output].  muflow --list prints their
 * help lines, muflow --list=markdown (docs/case_keys.md) their docs. */
static const struct key keys[] = {
    CHO("case", "scene", scene, scene_choice_table,
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
                 "along the third direction: 'circle A B R' and 'rectangle A0 B0 A1 B1' joined by "
                 "';' (empty: none); each must reach into the box and span a cell each way, a "
                 "channel's inflow and outlet stay joined by fluid, and the fluid is one region "
                 "or regions that each reach a surface or open face",
                 "length",
                 "Solid bodies inside the box, a union of shapes in the plane's coordinates (A, "
                 "B), extruded along the third direction: `circle A B R` (centre, radius) and "
                 "`rectangle A0 B0 A1 B1` (two opposite corners), joined by `;`; empty: none. "
                 "Refused: a shape that does not reach into the box or spans less than a cell "
                 "along either direction of its plane, shapes that leave no cell centre in the "
                 "fluid, a body that closes the channel (no path of fluid cells between an "
                 "inflow face and the opposite face, or between two open faces of one "
                 "direction), and a body that splits the fluid into regions one of which "
                 "reaches no `surface` or `open` face (its pressure would be undetermined)")),
    CHO("obstacle", "plane", obstacle.plane, plane_choices,
        "the grid directions of the shapes' coordinates A and B"),
    BOOL("obstacle", "invert", obstacle.invert,
         "the fluid is inside the shapes and the solid outside (a duct)"),
    CHO("obstacle", "boundary", obstacle.boundary, obstacle_boundary_choices,
        "no slip on the body: sharp (each grid link the surface cuts ends on the surface, "
        "second order) or staircase (velocity nodes inside the body held at 0, first order)"),

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
                 "(first order, donor cell) or vanleer (upwind, second order with van Leer's "
                 "limiter)",
                 NULL,
                 "Form of the advection term: `centred` (conservative, second order, "
                 "energy-neutral), `upwind` (conservative donor cell, first order) or `vanleer` "
                 "(upwind, second order with van Leer's limiter). Under the forward-Euler step the "
                 "centred form adds energy where no viscosity damps it, such as a granular free "
                 "surface, where the pressure and so the mu(I) viscosity vanish")),

    CHO("rheology", "law", rheo.law, law_choices, "viscosity law: mu(I), Bingham or Newtonian"),
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
    DBL("rheology", "mu_s", rheo.mu_s, GE0, "static friction coefficient mu_s (mu(I))"),
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
                  "the pressure, which falls back to the LU if it fails) instead of the implicit "
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
                  "rest of the run if it fails (refused on mu(I) and with open faces). For flows "
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
                 "(every component's geometric multigrid, matrix-free) (auto, for grids "
                 "varying in two or more directions: gmg for the steady newton solves of the heap "
                 "and the square duct's mixed model without augmentation, a body or a band, else "
                 "amg on a steady 2D cross-section with newton, no augmentation and over 1e4 "
                 "unknowns (5e4 where cholesky would serve or with a body), else cholesky on a 2D "
                 "cross-section without open or inflow faces up to 1e6 unknowns, lu up to 4e5 "
                 "unknowns, beyond them amg on a 2D cross-section without augmentation; line "
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
         KEY_HELP("steady Newton steps solved with amg, cholesky or gmg: the linear tolerance "
                  "follows the residual's last decrease (Eisenstat-Walker), down to "
                  "linear_tolerance",
                  NULL,
                  "Steady Newton steps solved with `amg`, `cholesky` or `gmg`: the linear "
                  "tolerance follows the residual's last decrease (Eisenstat and Walker's forcing "
                  "term, gamma 0.9, exponent 2), at most 0.1 (0.01 with `gmg`) and the relative "
                  "residual, at least `linear_tolerance`; the LU solves exactly whatever the "
                  "tolerance; `off`: every solve to `linear_tolerance`")),
    INT("solver", "max_linear_iterations", max_linear_iterations, RANGE(1, 1e6, 1, 1),
        "iteration cap of the implicit viscous solve"),
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
};
#undef FACE
#define NKEYS ((int)(sizeof(keys) / sizeof(keys[0])))

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
     "(with the control-volume cross-check) to the summary, and `obstacle_surface.csv` (the "
     "stresses around the body against the angle). A case whose scene transports a tracer (the "
     "collapse) cannot have shapes."},
    {"physics", "Gravity, the density and the terms of the momentum equation."},
    {"rheology",
     "The viscosity law. `law = bingham` needs `plastic_viscosity > 0` or `yield_stress > 0`; "
     "`law = newtonian` needs `viscosity > 0`. With `law = mui` and `curve = barker_gray`, I_1^N "
     "(the lower root of the well-posedness function C(I) of the `jop` curve with these `mu_s`, "
     "`delta_mu`, `i0`) and A_minus = I_1^N exp(alpha / mu(I_1^N)^2) are computed when the case "
     "is loaded; parameters whose `jop` curve is ill posed throughout the bracket are refused, "
     "naming `rheology.mu_s`, `rheology.delta_mu` and `rheology.i0`."},
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

static const char *const sections[] = {"case", "domain", "boundary", "obstacle", "physics",
                                       "rheology", "solver", "output"};
#define NSECTIONS ((int)(sizeof(sections) / sizeof(sections[0])))
#define SCENE_KEYS_MAX 64 /* a scene's keys beyond this are not checked for duplicates */

/* ------------------------------------------------------------------------ */

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
}

/* ------------------------------------------------------------------------ */
/* The scene and its parameter block */

const struct scene *case_scene(const struct muflow_case *c)
{
    const struct scene *s = scene_at(c->scene);
    return s ? s : scene_at(0);
}

const void *case_scene_params(const struct muflow_case *c)
{
    return c->scene_params.bytes;
}

void *case_scene_params_mut(struct muflow_case *c)
{
    return c->scene_params.bytes;
}

void case_set_scene(struct muflow_case *c, int scene)
{
    c->scene = scene;
    memset(&c->scene_params, 0, sizeof c->scene_params);
    const struct key_block *kb = case_scene(c)->keys;
    if (kb && kb->defaults)
        kb->defaults(c->scene_params.bytes);
}

static const struct key_block *scene_keys(const struct muflow_case *c)
{
    return case_scene(c)->keys;
}

/* ------------------------------------------------------------------------ */
/* Key look-up */

static int known_section(const struct muflow_case *c, const char *s)
{
    for (int i = 0; i < NSECTIONS; i++)
        if (strcmp(s, sections[i]) == 0)
            return 1;
    const struct key_block *kb = scene_keys(c);
    return kb && strcmp(s, kb->section) == 0;
}

/* The key section.name and the struct it describes a member of. */
static const struct key *find_key(const struct muflow_case *c, const char *section,
                                  const char *name, void **base)
{
    for (int i = 0; i < NKEYS; i++)
        if (strcmp(keys[i].section, section) == 0 && strcmp(keys[i].name, name) == 0) {
            if (base)
                *base = (void *)c;
            return &keys[i];
        }
    const struct key_block *kb = scene_keys(c);
    if (kb && strcmp(kb->section, section) == 0)
        for (int i = 0; i < kb->nkeys; i++)
            if (strcmp(kb->keys[i].name, name) == 0) {
                if (base)
                    *base = (void *)c->scene_params.bytes;
                return &kb->keys[i];
            }
    return NULL;
}

/* Calls visit on every key the case has: the core keys in order, the
 * scene's section before [output]. */
static int each_key(const struct muflow_case *c, int (*visit)(void *ctx, const struct key *k),
                    void *ctx)
{
    const struct key_block *kb = scene_keys(c);
    for (int i = 0; i < NKEYS; i++) {
        if (kb && strcmp(keys[i].section, "output") == 0 &&
            (i == 0 || strcmp(keys[i - 1].section, "output") != 0))
            for (int j = 0; j < kb->nkeys; j++) {
                int rc = visit(ctx, &kb->keys[j]);
                if (rc)
                    return rc;
            }
        int rc = visit(ctx, &keys[i]);
        if (rc)
            return rc;
    }
    return 0;
}

static const void *key_base(const struct muflow_case *c, const struct key *k)
{
    return (k >= keys && k < keys + NKEYS) ? (const void *)c : (const void *)c->scene_params.bytes;
}

struct nearest {
    const char *full;
    int best;
    const struct key *hit;
};

static int nearer(void *vctx, const struct key *k)
{
    struct nearest *n = vctx;
    char cand[96];
    snprintf(cand, sizeof(cand), "%s.%s", k->section, k->name);
    int dist = ini_edit_distance(n->full, cand);
    if (dist < n->best) {
        n->best = dist;
        n->hit = k;
    }
    return 0;
}

struct same_name {
    const char *name;
    const struct key *hit;
};

static int named(void *vctx, const struct key *k)
{
    struct same_name *n = vctx;
    if (strcmp(k->name, n->name) == 0) {
        n->hit = k;
        return 1;
    }
    return 0;
}

/* " (did you mean section.key?)" for a near miss of section.name, or "". */
static void suggest_key(const struct muflow_case *c, const char *section, const char *name,
                        char *out, size_t outlen)
{
    char full[160];
    out[0] = '\0';
    if (snprintf(full, sizeof(full), "%s.%s", section, name) >= (int)sizeof(full))
        return;
    struct nearest n = {full, INT_MAX, NULL};
    each_key(c, nearer, &n);
    const struct key *hit = n.hit;
    if (n.best > 2) { /* right key name, wrong (or no) section? */
        struct same_name s = {name, NULL};
        each_key(c, named, &s);
        hit = s.hit;
    }
    if (hit)
        snprintf(out, outlen, " (did you mean %s.%s?)", hit->section, hit->name);
}

/* Nearest known section within distance 2, or NULL. */
static const char *near_section(const struct muflow_case *c, const char *s)
{
    int best = 3;
    const char *hit = NULL;
    for (int i = 0; i < NSECTIONS; i++) {
        int dist = ini_edit_distance(s, sections[i]);
        if (dist < best) {
            best = dist;
            hit = sections[i];
        }
    }
    const struct key_block *kb = scene_keys(c);
    if (kb && ini_edit_distance(s, kb->section) < best)
        hit = kb->section;
    return hit;
}

/* " (a section of case.scene = NAME)" when s is another scene's section. */
static void owner_hint(const char *s, char *out, size_t outlen)
{
    for (int i = 0; i < scene_count(); i++) {
        const struct key_block *kb = scene_at(i)->keys;
        if (kb && strcmp(kb->section, s) == 0) {
            snprintf(out, outlen, " (a section of case.scene = %s)", scene_at(i)->name);
            return;
        }
    }
}

/* ------------------------------------------------------------------------ */
/* Loading context and errors */

struct ctx {
    struct muflow_case *c;
    const char *where;      /* file name for messages ("case" without file) */
    int failed;
    char *err;
    size_t errlen;
    unsigned char set[NKEYS]; /* core key given explicitly */
    case_warn_fn warn;      /* warnings (duplicates in the file), or NULL */
    void *warn_ctx;
    int keys_given;         /* key lines of the file and overrides */
    /* the file's last line and value of each key (core, then the scene's),
     * and the first line of each section header, for the duplicate warnings */
    int key_line[NKEYS + SCENE_KEYS_MAX];
    const char *key_value[NKEYS + SCENE_KEYS_MAX];
    int section_line[NSECTIONS + 1];
    /* the override that set each key last (its "section.key=value"), NULL
     * for the file's keys and the defaults: a check's message blames it */
    const char *origin[NKEYS + SCENE_KEYS_MAX];
};

/* One warning line (control characters replaced), when a callback is set. */
static void warn(struct ctx *x, const char *fmt, ...)
{
    if (!x->warn)
        return;
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    ini_format_line(msg, sizeof msg, fmt, ap);
    va_end(ap);
    x->warn(x->warn_ctx, msg);
}

/* Records the first error only; the message is one line. */
static void fail(struct ctx *x, const char *fmt, ...)
{
    if (x->failed)
        return;
    x->failed = 1;
    if (!x->err || x->errlen == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    ini_format_line(x->err, x->errlen, fmt, ap);
    va_end(ap);
}

static int key_slot(const struct muflow_case *c, const struct key *k);

/* 1 when text names the key section.name as a whole word ("domain.nx", not
 * "domain.nx_band" nor "xdomain.nx"). */
static int names_key(const char *text, const char *section, const char *name)
{
    char full[160];
    if (snprintf(full, sizeof full, "%s.%s", section, name) >= (int)sizeof full)
        return 0;
    size_t n = strlen(full);
    for (const char *p = strstr(text, full); p; p = strstr(p + 1, full)) {
        unsigned char before = p == text ? ' ' : (unsigned char)p[-1], after = (unsigned char)p[n];
        if (!(isalnum(before) || before == '_' || before == '.') &&
            !(isalnum(after) || after == '_'))
            return 1;
    }
    return 0;
}

struct blame {
    const struct ctx *x;
    const char *text;       /* the check's message */
    char *out;              /* "override a=1, override b=2" */
    size_t len, used;
};

static int blame_key(void *vctx, const struct key *k)
{
    struct blame *b = vctx;
    int slot = key_slot(b->x->c, k);
    const char *arg = slot >= 0 ? b->x->origin[slot] : NULL;
    if (!arg || !names_key(b->text, k->section, k->name) || b->used >= b->len)
        return 0;
    char sh[SHOWN_MAX + 4];
    b->used += (size_t)snprintf(b->out + b->used, b->len - b->used, "%soverride %s",
                                b->used ? ", " : "", shown(arg, sh));
    return 0;
}

/* A check of the loaded case failed: one line, the message after what set
 * the keys it names: the overrides among them ("override a=1, override
 * b=2: ..."), else the file (its keys or the defaults). */
static void refuse(struct ctx *x, const char *fmt, ...)
{
    if (x->failed)
        return;
    char text[1024], who[1024], b[SHOWN_MAX + 4];
    va_list ap;
    va_start(ap, fmt);
    ini_format_line(text, sizeof text, fmt, ap);
    va_end(ap);
    struct blame bl = {x, text, who, sizeof who, 0};
    who[0] = '\0';
    each_key(x->c, blame_key, &bl);
    fail(x, "%s: %s", bl.used ? who : shown(x->where, b), text);
}

/* One assignment section.name = value, from the file (arg == NULL) or from
 * the override arg.  Returns 1 on success. */
static int assign(struct ctx *x, const char *section, const char *name, const char *value,
                  const char *arg)
{
    char b1[SHOWN_MAX + 4], b2[SHOWN_MAX + 4], b3[SHOWN_MAX + 4], prefix[SHOWN_MAX + 40];
    char hint[160], msg[160];
    if (arg)
        snprintf(prefix, sizeof(prefix), "override %s", shown(arg, b1));
    else
        snprintf(prefix, sizeof(prefix), "%s", shown(x->where, b1));

    void *base;
    const struct key *k = find_key(x->c, section, name, &base);
    if (!k) {
        if (!known_section(x->c, section)) {
            if (!arg && section[0] == '\0') {
                suggest_key(x->c, section, name, hint, sizeof(hint));
                fail(x, "%s: key %s before any [section]%s", prefix, shown(name, b2), hint);
                return 0;
            }
            suggest_key(x->c, section, name, hint, sizeof(hint));
            if (!hint[0])
                owner_hint(section, hint, sizeof(hint));
            if (!hint[0]) {
                const char *near = near_section(x->c, section);
                if (near)
                    snprintf(hint, sizeof(hint), " (did you mean %s?)", near);
            }
            fail(x, "%s: unknown section %s%s", prefix, shown(section, b2), hint);
            return 0;
        }
        suggest_key(x->c, section, name, hint, sizeof(hint));
        fail(x, "%s: unknown key %s.%s%s", prefix, section, shown(name, b2), hint);
        return 0;
    }
    const char *why = key_parse(base, k, value, msg, sizeof(msg));
    if (why) {
        if (arg)
            fail(x, "%s: %s", prefix, why);
        else
            fail(x, "%s: %s.%s = %s: %s", prefix, section, name, shown(value, b3), why);
        return 0;
    }
    if (base == (void *)x->c)
        x->set[k - keys] = 1;
    int slot = key_slot(x->c, k);
    if (slot >= 0)
        x->origin[slot] = arg;
    return 1;
}

/* Slot of key k in ctx's duplicate tables. */
static int key_slot(const struct muflow_case *c, const struct key *k)
{
    if (k >= keys && k < keys + NKEYS)
        return (int)(k - keys);
    const struct key_block *kb = scene_keys(c);
    int j = kb ? (int)(k - kb->keys) : -1;
    return j >= 0 && j < SCENE_KEYS_MAX ? NKEYS + j : -1;
}

/* A key line of the file that was applied: warns when the same key was
 * given on an earlier line of the file (the later value is used).
 * Overrides replace file values by design and never warn. */
static void note_file_key(struct ctx *x, const struct ini_event *v)
{
    char b1[SHOWN_MAX + 4], b2[SHOWN_MAX + 4], b3[SHOWN_MAX + 4];
    const struct key *k = find_key(x->c, v->section, v->key, NULL);
    int slot = k ? key_slot(x->c, k) : -1;
    if (slot < 0)
        return;
    if (x->key_line[slot] > 0)
        warn(x, "%s: %s.%s given twice: line %d (%s) and line %d (%s); the later replaces the "
                "earlier",
             shown(x->where, b1), k->section, k->name, x->key_line[slot],
             shown(x->key_value[slot], b2), v->line, shown(v->value, b3));
    x->key_line[slot] = v->line;
    x->key_value[slot] = v->value;
}

/* A [section] header of the file that was accepted: warns when the section
 * was opened before (its keys are then read as one section). */
static void note_file_section(struct ctx *x, const struct ini_event *v)
{
    char b[SHOWN_MAX + 4];
    int slot = -1;
    for (int i = 0; i < NSECTIONS; i++)
        if (strcmp(v->section, sections[i]) == 0)
            slot = i;
    const struct key_block *kb = scene_keys(x->c);
    if (slot < 0 && kb && strcmp(v->section, kb->section) == 0)
        slot = NSECTIONS;
    if (slot < 0)
        return;
    if (x->section_line[slot] > 0)
        warn(x, "%s: section [%s] given twice: line %d and line %d (their keys are read as one "
                "section)",
             shown(x->where, b), v->section, x->section_line[slot], v->line);
    else
        x->section_line[slot] = v->line;
}

/* A [section] header of the file. */
static int header(struct ctx *x, const char *name)
{
    if (strlen(name) <= SHOWN_MAX && known_section(x->c, name))
        return 1;
    char b[SHOWN_MAX + 4], b2[SHOWN_MAX + 4], hint[96] = "";
    if (strlen(name) <= SHOWN_MAX) {
        owner_hint(name, hint, sizeof(hint));
        const char *near = hint[0] ? NULL : near_section(x->c, name);
        if (near)
            snprintf(hint, sizeof(hint), " (did you mean [%s]?)", near);
    }
    fail(x, "%s: unknown section [%s]%s", shown(x->where, b), shown(name, b2), hint);
    return 0;
}

/* ------------------------------------------------------------------------ */
/* Checks that need every key */

static int key_index(const char *section, const char *name)
{
    for (int i = 0; i < NKEYS; i++)
        if (strcmp(keys[i].section, section) == 0 && strcmp(keys[i].name, name) == 0)
            return i;
    return -1;
}

/* "bagnold|chute|..." : the scenes other than none. */
static const char *scene_names(char *names, size_t len)
{
    size_t used = 0;
    names[0] = '\0';
    for (int i = 1; i < scene_count() && used < len; i++)
        used += (size_t)snprintf(names + used, len - used, "%s%s", i > 1 ? "|" : "",
                                 scene_at(i)->name);
    return names;
}

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
 * those faces each have their own, and a region whose edge is partly the
 * box's walls gets a hydrostatic problem without a solution under a body
 * force (the circular duct outside its circle: two corners closed off by
 * walls, the hydrostatic solve stopped at a relative residual of 4).  Two
 * discs of fluid inside the body, away from the walls, ran (their problems
 * each have one); they are refused with the rest, the rule being the
 * regions, not the forces.  One region alone is solved up to its level.
 * Returns 0, or 1 after refuse(). */
static int check_regions(struct ctx *x, const struct shape_set *set)
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
                                         bc_choices[k].name);
        }
    }
    int regions, floating;
    if (shapes_regions(set, c->n, c->len, periodic, fixed, &regions, &floating) != 0) {
        refuse(x, "obstacle.shapes: out of memory checking the shapes against the box");
        return 1;
    }
    if (regions < 2 || floating == 0)
        return 0;
    refuse(x, "obstacle.shapes = '%.200s' with %s: the body splits the fluid into %d regions on "
              "this grid, %d of them closed off from every surface or open face of the box, "
              "where the pressure is fixed%s%s%s: their pressures have no common level, which the "
              "pressure solves cannot take; the fluid must be one region, or each region must "
              "reach a surface or open face",
           c->obstacle.shapes, invert_text(c), regions, floating, nfixed ? " (" : "", faces,
           nfixed ? ")" : "");
    return 1;
}

/* The shapes against the box: each reaches into it and spans a cell of
 * the plane at least, some fluid is left, a flow through the box (an
 * inflow face, or open faces at both ends of a direction) finds a path of
 * fluid cells from one end to the other, and the fluid's pressure is fixed
 * (check_regions).  Geometry on the plane's grid: after every size check.
 * Returns 0, or 1 after refuse(). */
static int check_shapes_fit(struct ctx *x, struct shape_set *set)
{
    struct muflow_case *c = x->c;
    static const char axis[3] = {'x', 'y', 'z'};
    static const char *const len_key[3] = {"lx", "ly", "lz"}, *const n_key[3] = {"nx", "ny", "nz"};
    shapes_set_plane(set, c->obstacle.plane, c->obstacle.invert);
    const char *plane = plane_choices[c->obstacle.plane].name;
    int a = set->plane_a, b = set->plane_b;
    int out = shapes_outside_box(set, c->len);
    if (out >= 0) {
        refuse(x, "obstacle.shapes = '%.200s': shape %d lies wholly outside the box, whose "
                  "plane %s spans [0, %s] x [0, %s] (a body must reach into the box)",
               c->obstacle.shapes, out + 1, plane, num_text(c->len[a]).s, num_text(c->len[b]).s);
        return 1;
    }
    /* a body thinner than a cell is not seen, or seen as a cell's staircase */
    for (int i = 0; i < set->n; i++) {
        const struct shape *sh = &set->s[i];
        const int dir[2] = {a, b};
        for (int k = 0; k < 2; k++) {
            int d = dir[k];
            double span = sh->kind == SHAPE_CIRCLE ? 2.0 * sh->v[2] : sh->v[2 + k] - sh->v[k];
            double h = finest_cell(c, d);
            if (span < h) {
                refuse(x, "obstacle.shapes = '%.200s': shape %d spans %s along %c, thinner than a "
                          "cell (domain.%s / domain.%s = %s): a body must span at least one cell "
                          "along each direction of its plane (raise domain.%s)",
                       c->obstacle.shapes, i + 1, num_text(span).s, axis[d], len_key[d], n_key[d],
                       num_text(h).s, n_key[d]);
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
        refuse(x, "obstacle.shapes: out of memory checking the shapes against the box");
        return 1;
    }
    if (!fluid) {
        refuse(x, "obstacle.shapes = '%.200s' with %s: no cell centre of the grid lies in the "
                  "fluid",
               c->obstacle.shapes, invert_text(c));
        return 1;
    }
    if (!joined) {
        refuse(x, "obstacle.shapes = '%.200s' with %s: the body closes the channel between "
                  "boundary.%clo = %s and boundary.%chi = %s (no path of fluid cells joins them on "
                  "this grid)",
               c->obstacle.shapes, invert_text(c), axis[flow], bc_choices[c->bc.face[flow][0]].name,
               axis[flow], bc_choices[c->bc.face[flow][1]].name);
        return 1;
    }
    return check_regions(x, set);
}

const char *case_coupled_gmres_refusal(const struct muflow_case *c)
{
    /* its GMRES (saddle_krylov.h) is measured on the Bingham cavity only: on
     * the granular cylinder (mu(I), whose matrix has the viscosity's
     * pressure columns) the residual grew to 7e7 in 34 steps and GMRES
     * then stopped at its cap */
    if (c->rheo.law == LAW_MUI)
        return "needs a law without the pressure's dependence (rheology.law = bingham or "
               "newtonian) with solver.preconditioner = amg: on mu(I) its GMRES steps diverged "
               "(the granular cylinder); set solver.preconditioner = lu";
    if (bc_has_open(&c->bc))
        return "with solver.preconditioner = amg needs no open face (its GMRES is not measured "
               "there); set solver.preconditioner = lu";
    return NULL;
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

/* The stretched directions: 'lo hi h' triples, bands the grid can hold,
 * and only the paths built for varying spacing (the coupled steady step:
 * the FFT and geometric-multigrid pressures, the Fourier and Cholesky
 * preconditioners, advection and the volume of fluid assume one size per
 * direction).  Returns 0, or 1 after fail(). */
static int check_bands(struct ctx *x)
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
            refuse(x, "domain.%c_band = '%.100s': must be one to %d triples 'lo hi h' "
                    "separated by ';' (empty: a uniform direction)",
                 axis[d], c->band[d], GRID_BANDS_MAX);
            return 1;
        }
        if (r > 0)
            grid_axis_free(&ax);
        if (c->n[d] < 2) {
            refuse(x, "domain.%c_band needs domain.%s >= 2 (a direction of one cell is not "
                    "stretched)",
                 axis[d], n_key[d]);
            return 1;
        }
        if (r < 0) {
            refuse(x, "domain.%c_band = '%.100s' with domain.%s = %s, domain.%s = %d: %s",
                 axis[d], c->band[d], len_key[d], num_text(c->len[d]).s, n_key[d], c->n[d], why);
            return 1;
        }
        const char *need = NULL;
        if (!case_scene(c)->stretched_grid)
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
            refuse(x, "domain.%c_band = '%.100s' needs %s", axis[d], c->band[d], need);
            return 1;
        }
    }
    return 0;
}

/* The checks that need every key, in the order of their cost: the keys
 * against each other, then the size of the run (the cell count, the memory
 * the run needs, from the case alone), and only then the body's geometry on
 * the grid, which costs as much as the grid (a case far beyond the machine's
 * memory went through a minute and 1.5 GB of it before being refused). */
static void finish(struct ctx *x)
{
    struct muflow_case *c = x->c;
    static const char axis[3] = {'x', 'y', 'z'};

    if (!x->set[key_index("rheology", "grain_density")])
        c->rheo.grain_density = 1.0 / c->rheo.phi; /* phi in (0, 1]: finite */

    double cells = (double)c->n[0] * (double)c->n[1] * (double)c->n[2];
    if (cells > MAX_CELLS) {
        refuse(x, "domain.nx * domain.ny * domain.nz = %d * %d * %d = %.0f cells: must be <= %.0f",
               c->n[0], c->n[1], c->n[2], cells, MAX_CELLS);
        return;
    }

    for (int d = 0; d < 3; d++) {
        int lo = c->bc.face[d][0] == BC_PERIODIC, hi = c->bc.face[d][1] == BC_PERIODIC;
        if (lo != hi) {
            refuse(x,
                   "boundary.%clo = %s, boundary.%chi = %s: periodic must be on both faces of "
                   "%c or on neither",
                   axis[d], bc_choices[c->bc.face[d][0]].name, axis[d],
                   bc_choices[c->bc.face[d][1]].name, axis[d]);
            return;
        }
    }

    for (int d = 0; d < 3; d++)
        for (int side = 0; side < 2; side++)
            if (c->bc.face[d][side] == BC_LID && c->bc.lid_direction == d) {
                refuse(x, "boundary.%c%s = lid, boundary.lid_direction = %c: a lid moves in its "
                          "own plane, the direction must differ from %c",
                       axis[d], side ? "hi" : "lo", axis[d], axis[d]);
                return;
            }

    /* an open face's momentum balance is its inner neighbour's (stage_projection.c) */
    for (int d = 0; d < 3; d++)
        for (int side = 0; side < 2; side++)
            if (c->bc.face[d][side] == BC_OPEN && c->n[d] < 2) {
                refuse(x, "boundary.%c%s = open with domain.n%c = %d: an open face needs at "
                          "least 2 cells along %c",
                       axis[d], side ? "hi" : "lo", axis[d], c->n[d], axis[d]);
                return;
            }

    /* the grad-div augmentation treats an open face's velocity as fixed in
     * the implicit step while the projection moves it: the Uzawa update then
     * fights the open face's pressure condition (measured: a channel that
     * converges without it stalls at residual 0.4) */
    if (c->augmentation > 0.0 && bc_has_open(&c->bc)) {
        refuse(x, "solver.augmentation = %s with an open face: the grad-div augmentation "
                  "is not supported with open boundaries (set solver.augmentation = 0)",
               num_text(c->augmentation).s);
        return;
    }

    /* the coupled step (stage_coupled.c): a steady Newton step of its own,
     * whose pressure needs no augmentation (its open faces' balance is in
     * its matrix, coupled_open.h) */
    if (c->coupled) {
        const char *why = c->mode != MODE_STEADY ? "needs solver.mode = steady"
                          : c->augmentation > 0.0 ? "needs solver.augmentation = 0 (its pressure "
                                                    "is solved with the velocity)"
                                                  : NULL;
        if (why) {
            refuse(x, "solver.coupled = on %s", why);
            return;
        }
        why = c->preconditioner == PRECOND_AMG ? case_coupled_gmres_refusal(c)
              : c->preconditioner == PRECOND_GMG || c->preconditioner == PRECOND_MULTIGRID
                  ? "with solver.preconditioner = gmg or multigrid: the coupled step solves its "
                    "own matrix; set solver.preconditioner = lu or amg"
                  : NULL;
        if (why) {
            refuse(x, "solver.coupled = on %s", why);
            return;
        }
    }
    /* the implicit step's geometric multigrid covers the velocity components
     * along periodic directions (viscous_gmg.h) */
    if (c->preconditioner == PRECOND_GMG) {
        const char *why = viscous_gmg_refusal(c->n, &c->bc);
        if (why) {
            refuse(x, "%s", why);
            return;
        }
    }

    /* an inflow's volume must leave somewhere: through an open face */
    int inflow = inflow_face(&c->bc);
    if (inflow >= 0 && !bc_has_open(&c->bc) && c->bc.inflow_velocity != 0.0) {
        refuse(x, "boundary.%c%s = inflow with boundary.inflow_velocity = %s and no open "
                  "face: the inflowing volume has no way out (set an outlet face to open)",
               axis[inflow / 2], inflow % 2 ? "hi" : "lo", num_text(c->bc.inflow_velocity).s);
        return;
    }

    if (check_bands(x) != 0)
        return;

    /* the shapes are read here so that a bad one stops the case at load
     * (their fit to the grid is checked last) */
    struct shape_set set;
    {
        char why[300];
        if (shapes_parse(&set, c->obstacle.shapes, why, sizeof why) != 0) {
            refuse(x, "obstacle.shapes = '%.200s': %s", c->obstacle.shapes, why);
            return;
        }
    }

    const struct scene *sc = case_scene(c);
    const struct key_block *kb = sc->keys;
    char msg[512];
    if ((sc->check && sc->check(c, msg, sizeof msg) != 0) ||
        (kb && kb->check && kb->check(c, c->scene_params.bytes, msg, sizeof msg) != 0)) {
        refuse(x, "%s", msg);
        return;
    }

    if (c->dt_max < c->dt) {
        refuse(x, "solver.dt_max = %s < solver.dt = %s: dt_max must be >= dt",
               num_text(c->dt_max).s, num_text(c->dt).s);
        return;
    }

    if (c->rheo.law == LAW_NEWTONIAN && !(c->rheo.viscosity > 0)) {
        refuse(x, "rheology.law = newtonian needs rheology.viscosity > 0");
        return;
    }
    if (c->rheo.law == LAW_BINGHAM &&
        !(c->rheo.plastic_viscosity > 0 || c->rheo.yield_stress > 0)) {
        refuse(x,
               "rheology.law = bingham needs rheology.plastic_viscosity > 0 or "
               "rheology.yield_stress > 0");
        return;
    }

    /* the curve's derived values (I_1^N, A_minus), once, from the final keys */
    if (c->rheo.law == LAW_MUI) {
        if (rheology_curve_setup(&c->rheo, msg, sizeof msg) != 0) {
            refuse(x, "%s", msg);
            return;
        }
    } else {
        c->rheo.i1n = 0.0;
        c->rheo.a_minus = 0.0;
    }

    if (!x->set[key_index("output", "dir")]) {
        /* "out/<name>", checked like an explicit output.dir (name < 128) */
        char dir[sizeof(c->name) + 8], m[160], b2[SHOWN_MAX + 4];
        snprintf(dir, sizeof(dir), "out/%s", c->name);
        const char *why = key_parse(c, &keys[key_index("output", "dir")], dir, m, sizeof(m));
        if (why)
            refuse(x, "default output.dir = %s: %s; set output.dir", shown(dir, b2), why);
    }
    if (x->failed)
        return;

    /* The implicit viscous solve works along a non-periodic direction
     * (solvers/viscous.c): a box periodic on every face cannot be run. */
    if (c->bc.face[0][0] == BC_PERIODIC && c->bc.face[1][0] == BC_PERIODIC &&
        c->bc.face[2][0] == BC_PERIODIC) {
        char names[512];
        if (x->keys_given == 0)
            refuse(x,
                   "the case sets no key: no case.scene and the default %d x %d x %d box, "
                   "periodic on every face, which muflow cannot solve; a case needs at least one "
                   "direction whose faces are wall, slip, surface, lid, open or inflow "
                   "(boundary.*) and, to be compared with a solution, a scene (case.scene = "
                   "%s): the files in cases/ are complete examples, muflow --list lists every "
                   "key",
                   c->n[0], c->n[1], c->n[2], scene_names(names, sizeof names));
        else
            refuse(x,
                   "every boundary face is periodic: muflow needs at least one direction "
                   "whose faces are wall, slip, surface, lid, open or inflow (boundary.xlo and "
                   "boundary.xhi, boundary.ylo and boundary.yhi, or boundary.zlo and "
                   "boundary.zhi); the implicit viscous solve works along it");
        return;
    }
    if (c->line_direction >= 0 && c->bc.face[c->line_direction][0] == BC_PERIODIC) {
        refuse(x,
               "solver.line_direction = %c: %c is periodic; the preconditioner lines need a "
               "non-periodic direction (auto chooses one)",
               axis[c->line_direction], axis[c->line_direction]);
        return;
    }

    /* the size of the run, from the case alone */
    if (march_memory_check(c, msg, sizeof msg) != 0) {
        refuse(x, "%s", msg);
        return;
    }

    if (set.n > 0)
        check_shapes_fit(x, &set);
}

/* c->name: base name of path without directory and a trailing ".ini". */
static int set_name(struct ctx *x, const char *path)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    size_t len = strlen(base);
    if (len > 4 && strcmp(base + len - 4, ".ini") == 0)
        len -= 4;
    if (len >= sizeof(x->c->name)) {
        char b[SHOWN_MAX + 4];
        fail(x, "%s: case name longer than %zu characters", shown(path, b),
             sizeof(x->c->name) - 1);
        return 0;
    }
    memcpy(x->c->name, base, len);
    x->c->name[len] = '\0';
    return 1;
}

/* case.reference relative to the case file's folder, made absolute so that a
 * summary or checkpoint that repeats the key finds the same file. */
static void resolve_reference(struct ctx *x, const char *path)
{
    struct muflow_case *c = x->c;
    char joined[2 * sizeof(c->reference)], real[PATH_MAX], b[SHOWN_MAX + 4], b2[SHOWN_MAX + 4];
    const char *slash = path ? strrchr(path, '/') : NULL;
    if (c->reference[0] != '/' && slash)
        snprintf(joined, sizeof joined, "%.*s/%s", (int)(slash - path), path, c->reference);
    else
        snprintf(joined, sizeof joined, "%s", c->reference);
    if (!realpath(joined, real)) {
        refuse(x, "case.reference = %s: %s", shown(joined, b2), strerror(errno));
        return;
    }
    if (strlen(real) >= sizeof(c->reference)) {
        refuse(x, "case.reference = %s: the path is longer than %zu characters", shown(joined, b),
               sizeof(c->reference) - 1);
        return;
    }
    memcpy(c->reference, real, strlen(real) + 1); /* fits: checked above */
}

/* The scene the events choose: the last case.scene whose value names one. */
static int scene_of(const struct ini_events *ev)
{
    int scene = 0;
    for (int i = 0; i < ev->count; i++) {
        const struct ini_event *v = &ev->ev[i];
        if (v->kind == INI_ERROR)
            break;
        if (v->kind != INI_KEY || strcmp(v->section, "case") != 0 || strcmp(v->key, "scene") != 0)
            continue;
        for (const struct choice *ch = scene_choice_table; ch->name; ch++)
            if (ini_equal_nocase(v->value, ch->name))
                scene = ch->value;
    }
    return scene;
}

int case_load(struct muflow_case *c, const char *path, int noverrides,
              char *const overrides[], char *err, size_t errlen)
{
    return case_load_warn(c, path, noverrides, overrides, NULL, NULL, err, errlen);
}

int case_load_warn(struct muflow_case *c, const char *path, int noverrides,
                   char *const overrides[], case_warn_fn warn_fn, void *warn_ctx, char *err,
                   size_t errlen)
{
    struct muflow_case work;
    struct ctx x;
    memset(&x, 0, sizeof(x));
    case_defaults(c);
    case_defaults(&work);
    x.c = &work;
    x.where = path ? path : "case";
    x.err = err;
    x.errlen = errlen;
    x.warn = warn_fn;
    x.warn_ctx = warn_ctx;
    if (err && errlen)
        err[0] = '\0';

    struct ini_events ev = {0};
    char b[SHOWN_MAX + 4];
    int oom = 0;
    if (path && set_name(&x, path))
        oom = ini_read_file(&ev, path, x.where, err, errlen) != 0;
    /* overrides up to a missing one (NULL), reported after the events before it */
    for (int i = 0; i < noverrides && !oom && overrides && overrides[i]; i++)
        oom = ini_add_override(&ev, overrides[i]) != 0;
    if (oom && !x.failed)
        fail(&x, "%s: out of memory", shown(x.where, b));
    int scene = scene_of(&ev);
    case_set_scene(&work, scene);
    for (int i = 0; i < ev.count; i++)
        x.keys_given += ev.ev[i].kind == INI_KEY;
    for (int i = 0; i < ev.count && !x.failed; i++) {
        const struct ini_event *v = &ev.ev[i];
        if (v->kind == INI_ERROR) {
            fail(&x, "%s", v->message);
        } else if (v->kind == INI_SECTION) {
            if (header(&x, v->section))
                note_file_section(&x, v);
        } else {
            if (assign(&x, v->section, v->key, v->value, v->arg) && !v->arg)
                note_file_key(&x, v);
            /* an earlier case.scene does not undo the scene of the first
             * pass: the last one is the case's, and its block is set up */
            work.scene = scene;
        }
    }
    for (int i = 0; i < noverrides && !x.failed; i++)
        if (!overrides || !overrides[i])
            fail(&x, "override %d: missing", i + 1);
    ini_events_free(&ev);
    if (!x.failed)
        finish(&x);
    if (!x.failed && work.reference[0])
        resolve_reference(&x, path);
    if (x.failed)
        return 2;
    *c = work;
    return 0;
}

/* ------------------------------------------------------------------------ */
/* The key list (muflow --list) */

int case_key_count(void) { return NKEYS; }

const struct key *case_key_at(int i) { return i >= 0 && i < NKEYS ? &keys[i] : NULL; }

void case_write_key_list(FILE *out)
{
    static struct muflow_case d; /* static: the case is large */
    case_defaults(&d);
    fprintf(out, "Scenes (case.scene):\n");
    for (int i = 0; i < scene_count(); i++)
        fprintf(out, "  %-16s %s\n", scene_at(i)->name, scene_at(i)->title);
    fprintf(out, "\nKeys: section.key = default  (allowed values)\n      meaning\n");
    const char *section = NULL;
    for (int i = 0; i < NKEYS; i++) {
        if (strcmp(keys[i].section, "output") == 0 && strcmp(section, "output") != 0)
            for (int sc = 0; sc < scene_count(); sc++) { /* the scenes' own sections */
                const struct key_block *kb = scene_at(sc)->keys;
                if (!kb)
                    continue;
                static struct muflow_case ds;
                case_defaults(&ds);
                case_set_scene(&ds, sc);
                fprintf(out, "\n[%s]  (only with case.scene = %s)\n", kb->section,
                        scene_at(sc)->name);
                for (int j = 0; j < kb->nkeys; j++)
                    key_write_help(case_scene_params(&ds), &kb->keys[j], out);
            }
        if (!section || strcmp(section, keys[i].section) != 0) {
            section = keys[i].section;
            fprintf(out, "\n[%s]\n", section);
        }
        key_write_help(&d, &keys[i], out);
    }
}

/* ------------------------------------------------------------------------ */
/* Writing */

struct visit_ctx {
    const struct muflow_case *c;
    int (*visit)(void *ctx, const char *section, const char *key, const char *value);
    void *ctx;
};

static int visit_one(void *vctx, const struct key *k)
{
    struct visit_ctx *v = vctx;
    char val[sizeof(v->c->output_dir) + 8];
    key_text(key_base(v->c, k), k, val, sizeof(val));
    return v->visit(v->ctx, k->section, k->name, val);
}

int case_visit_keys(const struct muflow_case *c,
                    int (*visit)(void *ctx, const char *section, const char *key,
                                 const char *value),
                    void *ctx)
{
    struct visit_ctx v = {c, visit, ctx};
    return each_key(c, visit_one, &v);
}

struct write_ctx {
    FILE *out;
    const char *section;
};

static int write_one(void *vctx, const char *section, const char *key, const char *value)
{
    struct write_ctx *w = vctx;
    if (!w->section || strcmp(w->section, section) != 0) {
        fprintf(w->out, "%s[%s]\n", w->section ? "\n" : "", section);
        w->section = section;
    }
    if (value[0] == '\0') /* an unset string key (no reference): its default */
        fprintf(w->out, "; %s is not set\n", key);
    else
        fprintf(w->out, "%s = %s\n", key, value);
    return 0;
}

void case_write_ini(const struct muflow_case *c, FILE *out)
{
    char b[SHOWN_MAX + 4];
    fprintf(out, "; muflow case: %s\n", shown(c->name, b));
    struct write_ctx w = {out, NULL};
    case_visit_keys(c, write_one, &w);
}
