/* The time loop (see march.h). */
#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "march/march.h"
#include "march/step.h"
#include "grid/shapes.h"
#include "solvers/saddle_krylov.h"
#include "solvers/saddle_point.h"
#include "solvers/sparse_direct.h"
#include "solvers/viscous_gmg.h"

/* A steady march is judged unable to reach a steady state only when the best
 * residual has not improved by 10% for STALL_STEPS steps AND for a
 * pseudo-time of STALL_STEPS unreduced steps (choose_dt without the cut of
 * rejected steps), AND no residual of those steps is 10% below the one
 * STALL_STEPS steps ago.  The step count alone took the pseudo-time march
 * through a physical start-up for a stall (bagnold from dt 0.001: residual
 * flat at 4.3e-2 for 400 steps while the layer speeds up, steady after
 * 4041), and a crawl of cut steps (dt ~1e-8 after rejections: the
 * papanastasiou chute, 300 steps in which the pseudo-time moves by 1e-6) for
 * no progress.  The best residual alone took a start from rest whose
 * residual first climbs for a stall: the square duct at 80 x 160 climbs from
 * 1 to 27 in six steps and falls back below 1 only at step 390, steadily but
 * with a plateau near 2; it was called unsteady at step 206, and is steady
 * in 549 steps with the window's condition. */
#define STALL_STEPS MARCH_STALL_STEPS
#define STALL_FACTOR 0.9
/* A net acceleration ends the run only when it is sustained: at the last
 * three doublings of the pseudo-time it lost less than ACC_DECAY over the
 * last doubling and no more than over the one before.  A start-up transient
 * has an acceleration whose decay per doubling grows (friction engages: 1e-5,
 * 3e-3, 6%, 24%, 68% for bagnold from dt 0.001), a layer above
 * atan(mu_s + dmu) one whose decay shrinks towards a positive limit (15%,
 * 10%, 6.5%, 4.2%, 2.8% at tilt 0.6). */
#define ACC_DECAY 0.1
/* A steady-mode step that multiplies the residual by more than this is
 * rejected and retried with a ten times smaller pseudo-time step: a linearised
 * step far from the solution can overshoot into spurious states. */
#define REJECT_GROWTH 2.0
/* ... and only when its root mean square grew as much too: the maximum alone
 * sits where the plug forms (or at the lid's corners) and doubles on Newton
 * steps that reduce the residual elsewhere.  Measured on the Bingham cavity
 * 64 x 64 (Vola Bn = 10): 99 steps and 26 rejected with the maximum alone,
 * 61 and 14 with both.  Only in solves that start with Picard steps
 * (solver.newton_below < 1): the chute, tangent from the start, took 42
 * steps instead of 45 with it, and the profile scenes keep their counts. */
/* Picard steps (solver.newton_below < 1) that make no 10% progress of the
 * best residual in PICARD_STALL steps hand over to the tangent before the
 * residual has fallen newton_below-fold: at Vola Bn = 1000 on 64 x 64 the
 * Picard steps sat near 3e-2 for 140 steps (233 steps in all), with the
 * switch at the stall 40. */
#define PICARD_STALL 10
/* but no earlier than at the geometric mean of the start and newton_below
 * (a 10-fold drop for 1e-2): on 128 x 128 at Bn = 1000 the Picard steps
 * stalled at 0.24 and the tangent from there let the residual grow to 33. */
/* In Picard-first solves the maximum may double with the RMS, but not grow
 * beyond this in one step. */
#define REJECT_MAX_GROWTH 10.0
#define MIN_DT_SCALE 1e-12
/* the retries' insensitivity to dt, and the round-off's share of the
 * residual, of the rule that takes a try at a steady state's round-off
 * (march_run) */
#define DT_BLIND 0.1
#define ROUNDOFF_SHARE 10.0
/* A steady march is done at the round-off of its velocities when it makes
 * no progress for ROUNDOFF_STALL_STEPS steps (as stalled() judges it) and
 * its residual is within what velocities carrying the field's round-off,
 * eps max |u| each, leave (stage_residual_velocity_roundoff).  The solves
 * leave that much in a stiff region: a plug of viscosity mu p / lambda turns
 * it into a residual the plain measure (its terms at their own velocities)
 * calls real, and which no step removes.  The stagnation guards against a
 * Newton iteration still converging inside that bound (the heap at 35 x 50
 * is within it at a state 2.5e-7 max |u| off the solution). */
#define ROUNDOFF_STALL_STEPS 20
/* Transient mode has no rejections: a state whose residual (relative to
 * rho g, or without gravity to the first residual) exceeds BLOWUP times its
 * start is blowing up.  In either mode a state blows up when its residual
 * is beyond SANE_RESIDUAL times max(1, its start) and its largest velocity
 * beyond BLOWUP times the largest of the sane states, those whose residual
 * stayed within that bound (sane_velocity).  A steady march's rejections
 * bound the growth of one step (REJECT_GROWTH), not of many, and its
 * residual may climb far and recover (the channel's coupled first step
 * reached 7e13 times its start, steady in 204 steps all the same), so the
 * residual alone judges transient runs only.  It missed a steady march
 * whose velocity grew 7e4-fold: bagnold2 below mu_s (tilt 0.2, 4 x 100,
 * lambda 1e-8 by stages from 1e-6), where the last stage's stiffer plug
 * raised the residual from 0.17 to 14 (step 67, max |u| still the film's
 * 0.0105 m/s) and then the velocity to 23 m/s at step 91 and 700 m/s, the
 * residual never past 80; it ended "unsteady: the residual stalls".  A
 * physical acceleration (a layer above atan(mu_s + dmu)) keeps its residual
 * within the weight: its velocity is the scale.  A CFL step below
 * DT_COLLAPSE times the case's dt (or end time, if smaller) has stopped the
 * clock.  Measured on the Newtonian cavity at cfl 2 (an unstable explicit
 * advection): the residual grows about 8-fold every 10 steps from the start,
 * passes 1e3 at step 33 (t = 11.0, max |u| below the lid speed) and 1e20 at
 * step 260, where dt was 1e-10 and the run went on for 2095 steps (48 s) to
 * a non-finite state, keeping one with psi_max 4.5e74 as "the last finite
 * state". */
#define BLOWUP 1e3
#define SANE_RESIDUAL 10.0
#define DT_COLLAPSE 1e-8

const char *run_status_name(enum run_status s)
{
    switch (s) {
    case STATUS_RUNNING: return "running";
    case STATUS_STEADY: return "steady";
    case STATUS_FINISHED: return "finished";
    case STATUS_UNSTEADY: return "unsteady";
    case STATUS_DIVERGED: return "diverged";
    case STATUS_STOPPED: return "stopped";
    }
    return "?";
}

/* |D| and I for the field files, from |D|^2 (and the regularised pressure). */
static double output_shear_rate(const void *ctx, double shear2, ptrdiff_t p)
{
    (void)ctx;
    (void)p;
    return sqrt(shear2);
}

static double output_inertial_number(const void *ctx, double shear2, ptrdiff_t p)
{
    const struct march_state *st = ctx;
    return rheology_inertial_number(&st->cs->rheo, sqrt(shear2), st->preg[p]);
}

/* Line blocks are exact for flows uniform across lines and cheap; a flow that
 * varies in two or more directions gets a sparse factorisation while it is
 * affordable.  A flow varies only across its bounded (non-periodic)
 * directions and, with a body, the periodic ones of the body's plane: the
 * body force is uniform, so with one such direction the lines along it are
 * exact whatever the periodic extent (measured: bagnold
 * 15 x 5 x 40 took 15.3 s with the LU of 375 probes a step, 0.11 s with the
 * line blocks, same profile; 16 x 8 x 40 needed 960 probes and failed).  The
 * probes are one operator application each per step: beyond the
 * factorisation's limit the line blocks serve instead of failing. */
#define FACTOR_MAX_UNKNOWNS 400000L
/* The Cholesky (of a transient step or a Picard solve) of a 2D cross-section
 * further (in 3D its fill grows like n^(4/3): the limit above stays): the column
 * collapse at 204.8 cells per H0 (1024 x 320, 983,040 unknowns, of which
 * the 655,360 of the plane factorised: docs/design.md, "Blocks of
 * components"), 2 threads, its first 5 steps: 3.7 s a step, 1 CG iteration,
 * peak 2.2 GB; the AMG 5.6 s and 17 iterations, 1.6 GB; the line blocks
 * 14 s and their CG at its cap of 500 iterations, the residual 10 times
 * the right-hand side's. */
#define CHOLESKY_2D_MAX_UNKNOWNS 1000000L

/* Above this many unknowns auto takes BoomerAMG (GMRES(20), one V-cycle an
 * iteration, the inexact Newton forcing term) instead of the LU for a
 * steady flow with Newton's full tangent and no grad-div augmentation.
 * Measured on the heap at the tilt 0.4061 (whole steady solves, the same
 * steps and state with either), one process after the other, 1 thread, CPU
 * s of the whole run, two rounds on a machine loaded 5-6: 25 x 36 (2,700
 * unknowns) LU 1.23-1.27, AMG 1.05-1.15 (a tie; the LU's memory is 33 MB
 * against 40, hypre's library); 35 x 50 (5,250) LU 2.28-3.19, AMG
 * 1.48-1.57 (1.5-2x); 50 x 70 (10,500) LU 8.1-8.2, AMG 3.9-4.0 (2.1x).
 * The heap's crossover is thus near 3e3, but the square duct at 40 x 80
 * (9,600 unknowns, many rejected steps) reaches the same state in 298
 * steps with the AMG against 214 with the LU, 1.55x slower: the threshold
 * stays at 1e4, where it was before the forcing term (whose tie on the heap
 * was at 35 x 50 then).  With the augmentation (the cavity) BoomerAMG's
 * GMRES stalls: the LU stays.  Measured again once the factorisations took
 * METIS and the SkylakeX kernels (about 2x faster, suitesparse.c), 1
 * thread, two rounds: LU / AMG in CPU time 1.3-1.4 at 35 x 50, 1.2-1.3 at
 * 50 x 70, 1.4-1.6 at 70 x 100, 1.4 at 100 x 140: the threshold stands. */
#define AMG_MIN_UNKNOWNS 10000L
/* Where the Cholesky of the diagonal tangent serves (no open faces, no
 * body), the AMG only beyond this: once solves left out the blocks of
 * components that carry round-off and the probing their columns ("Blocks
 * left out of a solve"), whole steady solves on 2 threads, one sitting:
 * the heap at 70 x 100 (21,000 unknowns) a tie (1.56 s against the AMG's
 * 1.52 s, 52 MB against 66), at 100 x 140 (42,000) 3.74 s against 2.98 s
 * (66 MB against 94), at 140 x 200 (84,000) 11.2 s against 6.5 s, at
 * 280 x 400 77.3 s against 26.3 s; but the square duct at 80 x 160
 * (38,400) 3.5-3.9 s against 5.6-5.8 s and at 120 x 240 (86,400) 3.2 s
 * against 5.0 s, steady from rest in 59-93 steps.  Between the two: the
 * duct's meshes of the paper (to 80 x 160) keep the Cholesky, the heap's
 * doubled mesh takes the AMG. */
#define AMG_OVER_CHOLESKY_MIN_UNKNOWNS 50000L

/* A new problem (a start, a stage of the continuation, a new forcing): its
 * progress is measured afresh. */
static void forget_progress(struct march_state *st)
{
    st->best_residual = INFINITY;
    st->best_step = st->step;
    st->best_time = st->time;
    for (int k = 0; k < MARCH_RECENT; k++)
        st->recent_residual[k] = NAN;
    st->peak_residual = 0.0;
}

/* Whether a residual of the last `steps` steps (the current one included) is
 * 10% below the one `steps` steps ago; -1 when that one was not recorded. */
static int fell_over(const struct march_state *st, long steps)
{
    if (st->step < steps)
        return -1;
    double start = st->recent_residual[(st->step - steps) % MARCH_RECENT];
    if (!(start > 0.0))
        return -1;
    if (st->residual < STALL_FACTOR * start)
        return 1;
    for (long k = st->step - steps + 1; k < st->step; k++)
        if (st->recent_residual[k % MARCH_RECENT] < STALL_FACTOR * start)
            return 1;
    return 0;
}

/* Whether auto may choose hypre's AMG: amg 1 or 0 as given, -1 the
 * library's answer (it is opened to find out). */
static int amg_allowed(int amg)
{
    char err[160];
    return amg >= 0 ? amg : amg_hypre_available(err, sizeof err);
}

/* The implicit solve's preconditioner for the case on g (amg: see
 * amg_allowed). */
static enum viscous_precond choose_preconditioner(const struct muflow_case *cs,
                                                  const struct march_setup *su,
                                                  const struct grid *g, int amg)
{
    switch (cs->preconditioner) {
    case PRECOND_LINE: return VISCOUS_LINE;
    case PRECOND_CHOLESKY: return VISCOUS_CHOLESKY;
    case PRECOND_LU: return VISCOUS_LU;
    case PRECOND_AMG: return VISCOUS_AMG;
    case PRECOND_FOURIER: return VISCOUS_FOURIER;
    case PRECOND_GMG: return VISCOUS_GMG;
    case PRECOND_MULTIGRID: return VISCOUS_MG;
    case PRECOND_AUTO: break;
    }
    /* the coupled step probes and factorises its own matrix: the viscous
     * solver is never asked to solve, and the LU's kind is the cheapest
     * that keeps the full tangent (the AMG would open hypre for nothing) */
    if (cs->coupled)
        return cs->newton ? VISCOUS_LU : VISCOUS_CHOLESKY;
    /* the directions the flow varies in: bounded ones, and periodic ones
     * in a body's plane (a periodic row of bodies: measured, the line
     * blocks took 53-500 CG iterations a step around a cylinder in a flow
     * periodic along z, the LU 1) */
    int varying = 0, periodic[3], in_plane[3] = {0, 0, 0};
    if (case_obstacle_active(cs)) {
        struct shape_set set;
        case_obstacle_shapes(cs, &set);
        in_plane[set.plane_a] = in_plane[set.plane_b] = 1;
    }
    bc_periodic_flags(&cs->bc, periodic);
    for (int d = 0; d < 3; d++)
        varying += g->n[d] > 2 && (!periodic[d] || in_plane[d]);
    long unknowns = 3L * (long)grid_cells(g);
    if (varying < 2)
        return VISCOUS_LINE;
    /* measured on 2D cross-sections only: a grid that varies in three
     * directions keeps the LU (or the line blocks beyond its size) */
    int wide = 0;
    for (int d = 0; d < 3; d++)
        wide += g->n[d] > 2;
    /* a flow along the one-cell periodic direction of a cross-section that
     * the implicit step solves (the scene says so): the geometric multigrid
     * of the implicit step, whose cycle has the tangent's cross term
     * (docs/design.md, "Geometric multigrid for the implicit step"): at
     * least as fast as every other kind at every size measured, whole
     * steady solves on 2 threads, the heap at the tilt 0.4061 at 35 x 50
     * 0.16 s against the Cholesky's 0.20 s, at 70 x 100 0.57 against
     * 1.55 s, at 140 x 200 2.5 s against the AMG's 6.6 s and the LU's
     * 8.2 s; the square duct at 20 x 40 0.10 against 0.12 s, at 80 x 160
     * 1.65 against 3.29 s, at 120 x 240 1.90 s against the AMG's 5.15 s;
     * the same steps and states.  Measured with Newton in steady mode,
     * without the augmentation and without a body (whose cut cells it
     * does not hold) */
    if (su->cross_section_flow && cs->newton &&
        cs->mode == MODE_STEADY && wide == 2 && !(cs->augmentation > 0.0) &&
        !case_obstacle_active(cs) && !grid_stretched(g) &&
        !viscous_gmg_refusal(g->n, &cs->bc))
        return VISCOUS_GMG;
    /* in a flow that varies in two directions the strain components couple
     * through |D|: Newton needs the full tangent, which is not symmetric
     * (and reaches two nodes, the symmetric operator one); the LU and the
     * AMG both take it from the same probes.  On a 2D cross-section the
     * Cholesky of the diagonal tangent (symmetric, one node) preconditions
     * BiCGStab on the full tangent instead of the LU: the same steps and
     * states, measured (1 thread, whole steady solves): the heap at 35 x 50
     * 0.34 s against 0.64 s, the Bingham cavity 0.65 against 1.49 s, the
     * square duct 0.44 against 1.10 s, and less memory in each (docs/design.md, "The Cholesky of the
     * diagonal tangent").  Not with open faces: there the Cholesky path
     * stalls (the Newtonian chute open at both ends, nz 8: no steady state
     * after 231 steps, the LU's in 49).  Nor with a body: the cut cells'
     * grad-div correction (docs/design.md, "The Laplacian form near the
     * body") leaves the operator indefinite where the viscosity varies, and
     * the circular duct at 40 x 80 failed the Cholesky from step 1 (683
     * fallbacks to the line blocks, unsteady after 586 steps; the LU steady
     * in 381) */
    int lu = wide != 2 || bc_passes_flow(&cs->bc) || case_obstacle_active(cs);
    enum viscous_precond kind = cs->newton && lu ? VISCOUS_LU : VISCOUS_CHOLESKY;
    int reach = kind == VISCOUS_LU ? 2 : 1;
    if (sparse_direct_probes_for(g, periodic, reach) > sparse_direct_max_probes())
        return VISCOUS_LINE;
    /* the AMG has no fill: it serves beyond the factorisation's limit too;
     * without hypre's library (opened here, as the AMG would) the LU or the
     * line blocks as before */
    /* a transient step lags the viscosity (the tangent is for steady
     * solves), where the AMG was not measured: the LU as before */
    /* with a body too: the circular duct at 80 x 160 from rest (38,400
     * unknowns) got the AMG, whose GMRES reached its cap from the tangent's
     * first steps on (steady in 122 steps, 31 s on 2 threads, by the LU it
     * then gave way to), where the LU from the start takes 78 steps and
     * 10.8 s; at 120 x 240 (86,400) the AMG serves: 72 steps, 14.2 s
     * against the LU's 17.8 s */
    long amg_min = kind == VISCOUS_CHOLESKY || case_obstacle_active(cs)
                       ? AMG_OVER_CHOLESKY_MIN_UNKNOWNS
                       : AMG_MIN_UNKNOWNS;
    if (cs->newton && wide == 2 && cs->mode == MODE_STEADY && !(cs->augmentation > 0.0) &&
        unknowns > amg_min && amg_allowed(amg))
        return VISCOUS_AMG;
    /* beyond the factorisation's limit a 2D cross-section takes the AMG
     * (measured above: the line blocks do not converge there) */
    if (unknowns > (kind == VISCOUS_CHOLESKY && wide == 2 ? CHOLESKY_2D_MAX_UNKNOWNS
                                                          : FACTOR_MAX_UNKNOWNS))
        return wide == 2 && !(cs->augmentation > 0.0) && amg_allowed(amg)
                   ? VISCOUS_AMG
                   : VISCOUS_LINE;
    return kind;
}

/* The arrays of the march, declared once (march/fields.h). */
static const struct field_spec march_specs[] = {
    {"velocity", FIELD_FACES, FIELD_CHECKPOINT | FIELD_SAVED},
    {"p_dyn", FIELD_CELLS, FIELD_CHECKPOINT | FIELD_SAVED},
    {"p_hyd", FIELD_CELLS, 0},
    {"force", FIELD_FACES, 0},
    {"density_faces", FIELD_FACES, 0},
    {"pressure", FIELD_CELLS, 0},
    {"strain_normal2", FIELD_CELLS, 0},
    {"strain_shear2", FIELD_EDGES, 0},
    {"shear2", FIELD_CELLS, 0},
    {"viscosity", FIELD_CELLS, 0},
    {"pressure_regularised", FIELD_CELLS, 0},
    {"tangent_cells", FIELD_CELLS3, 0},
    {"viscosity_edges", FIELD_EDGES, 0},
    {"tangent_edges", FIELD_EDGES, 0},
    {"residual", FIELD_FACES, 0},
    {"increment", FIELD_FACES, 0},
    {"advection", FIELD_FACES, 0},
    {"divergence", FIELD_CELLS, 0},
    {"phi", FIELD_CELLS, 0},
};
#define NSPECS (sizeof march_specs / sizeof march_specs[0])

/* Whether the run needs the array: the advection term's only without
 * advection (its pointers stay NULL; only stage_residual reads it, when
 * physics.advection is on). */
static int spec_wanted(const struct muflow_case *cs, const struct field_spec *spec)
{
    return cs->advection || strcmp(spec->name, "advection") != 0;
}

static int register_fields(struct march_state *st)
{
    struct field_registry *r = &st->fields;
    const struct field_spec *specs = march_specs;
    double **into[] = {st->vel, &st->p_dyn, &st->p_hyd, st->force, st->rho_face, &st->pressure,
                       &st->cn2, st->e2, &st->shear2, &st->eta, &st->preg, st->tan_c, st->eta_e,
                       st->tan_e, st->res, st->delta, st->adv, &st->div, &st->phi};
    _Static_assert(NSPECS == sizeof into / sizeof into[0], "one each");
    int idx[NSPECS];
    for (size_t m = 0; m < NSPECS; m++) {
        idx[m] = -1; /* not wanted: its pointers stay NULL */
        if (spec_wanted(st->cs, &specs[m]) && (idx[m] = fields_add(r, &specs[m], into[m])) < 0)
            return -1;
    }
    /* what the field files hold, in this order: the velocity (face values
     * u, v, w and the cell-centred vector), then the cell scalars */
    const struct field_output outs[] = {
        {"velocity", {"u", "v", "w"}, idx[0], NULL, NULL},
        {"pressure", {NULL}, idx[5], NULL, NULL},
        {"pressure_regularised", {NULL}, idx[10], NULL, NULL},
        {"shear_rate", {NULL}, idx[8], output_shear_rate, st},
        {"inertial_number", {NULL}, idx[8], output_inertial_number, st},
        {"viscosity", {NULL}, idx[9], NULL, NULL},
    };
    for (size_t m = 0; m < sizeof outs / sizeof outs[0]; m++)
        if (fields_output(r, &outs[m]) != 0)
            return -1;
    return 0;
}

/* The projection's condition on a face: the pressure vanishes on an open
 * face (Dirichlet), its normal gradient on every closed or prescribed one. */
static enum poisson_bc projection_bc(enum bc_kind k)
{
    return k == BC_PERIODIC ? POISSON_PERIODIC : k == BC_OPEN ? POISSON_DIRICHLET : POISSON_NEUMANN;
}

/* What the process holds before the march allocates (libraries, FFTW):
 * the peak RSS of the smallest run, bagnold 2 x 1 x 40, is 20 MB. */
#define BASE_BYTES 20e6

/* Bytes the march will allocate on g with the preconditioner kind, from
 * the case alone: the registry's fields (saved copies included) and the
 * optional ones of this case, the pressure solver's two arrays, the viscous
 * solver's work, the sparse factorisation when chosen, and the modules'
 * memory_bound (a body's share bounded from above).  Other modules' own
 * fields are not known before they are created.  Measured against the peak RSS: bagnold
 * 100 x 100 x 50 (line blocks) 353 MB, estimate 367 MB; cavity 128 x 128
 * (LU) 141 MB, estimate 135 MB; 64 x 64 47 MB, estimate 46 MB; with a
 * body, the cylinder benchmark at 1760 x 328 (line blocks) 1,399 MB,
 * estimate 1,680 MB (940 MB before the body counted). */
/* The kinds that factorise no sparse matrix of the operator (the line
 * blocks' bands and the multigrid's coarsest level aside). */
static int without_factors(enum viscous_precond kind)
{
    return kind == VISCOUS_LINE || kind == VISCOUS_FOURIER || kind == VISCOUS_GMG ||
           kind == VISCOUS_MG;
}

static double memory_estimate(const struct muflow_case *cs, const struct march_setup *su,
                              const struct grid *g, enum viscous_precond kind)
{
    double arrays = 2.0; /* pressure: right-hand side and FFT buffer */
    for (size_t m = 0; m < NSPECS; m++)
        if (spec_wanted(cs, &march_specs[m]))
            arrays += field_arrays(march_specs[m].where) *
                      ((march_specs[m].flags & FIELD_SAVED) ? 2 : 1);
    if (cs->augmentation > 0.0)
        arrays += 1.0;
    if ((kind == VISCOUS_LU || kind == VISCOUS_AMG || kind == VISCOUS_CHOLESKY) && cs->newton)
        arrays += 4.0; /* the full tangent's b terms */
    double bytes = BASE_BYTES + arrays * (double)g->size * sizeof(double) +
                   viscous_memory_estimate(g, kind);
    for (int l = 0; l < 3; l++)
        for (const struct module *const *m = su->modules[l]; m && *m; m++)
            if ((*m)->memory_bound)
                bytes += (*m)->memory_bound(cs, g);
    int dims = 0;
    for (int d = 0; d < 3; d++)
        dims += g->n[d] > 1;
    if (cs->coupled) {
        /* the coupled step's own solver (the viscous one never solves):
           velocities and pressures, or the AMGs of the velocity block and
           of the pressure's commutator with GMRES's basis.  Measured, peak
           RSS against the estimate: the cavity's LU at 128 and 256 cells
           across 384 and 1,693 MB against 389 and 1,661 MB (130 and 497 MB
           when the viscous LU's model stood for it); the GMRES 186 and 653
           MB against 239 and 859 MB */
        long unknowns = 4L * (long)grid_cells(g);
        if (kind == VISCOUS_AMG)
            bytes += amg_hypre_memory_estimate(unknowns) + saddle_krylov_memory_estimate(unknowns);
        else
            bytes += saddle_point_memory_estimate(unknowns, dims);
        return bytes;
    }
    if (kind == VISCOUS_AMG) {
        bytes += amg_hypre_memory_estimate(3L * (long)grid_cells(g));
    } else if (!without_factors(kind)) {
        bytes += sparse_direct_memory_estimate(3L * (long)grid_cells(g), dims);
    }
    return bytes;
}

double march_available_memory(void)
{
    /* MUFLOW_AVAILABLE_MEMORY (bytes) stands in for the machine's, so that
     * the refusal can be tested on any machine */
    const char *env = getenv("MUFLOW_AVAILABLE_MEMORY");
    if (env && *env)
        return strtod(env, NULL);
    FILE *f = fopen("/proc/meminfo", "r");
    if (f) {
        char line[256];
        double kb = -1.0;
        while (fgets(line, sizeof line, f))
            if (sscanf(line, "MemAvailable: %lf kB", &kb) == 1)
                break;
        fclose(f);
        if (kb >= 0.0)
            return kb * 1024.0;
    }
    long pages = sysconf(_SC_AVPHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    return pages > 0 && size > 0 ? (double)pages * (double)size : 0.0;
}

/* "12.3 GB", "353 MB" */
static void format_bytes(char *out, size_t len, double b)
{
    if (b >= 1e9)
        snprintf(out, len, "%.1f GB", b / 1e9);
    else
        snprintf(out, len, "%.0f MB", b / 1e6);
}

/* The preconditioner and the estimate of the case on g (amg: see
 * amg_allowed).  Auto's coupled LU that does not fit in avail gives way to
 * the coupled GMRES where that is allowed and fits (the cavity at 256 x 256:
 * 653 MB against the LU's 1,693 MB, 1.3x its time). */
static double plan(const struct muflow_case *cs, const struct march_setup *su,
                   const struct grid *g, int amg, double avail, enum viscous_precond *kind)
{
    *kind = choose_preconditioner(cs, su, g, amg);
    double bytes = memory_estimate(cs, su, g, *kind);
    if (cs->coupled && cs->preconditioner == PRECOND_AUTO && *kind == VISCOUS_LU &&
        avail > 0.0 && bytes > avail && !saddle_krylov_refusal(cs->rheo.law, &cs->bc)) {
        double gmres = memory_estimate(cs, su, g, VISCOUS_AMG);
        if (gmres <= avail && amg_allowed(amg)) {
            *kind = VISCOUS_AMG;
            bytes = gmres;
        }
    }
    return bytes;
}

/* The refusal of a run that needs more than avail: one line naming the
 * grid keys. */
static void refusal(char *err, size_t errlen, const struct grid *g, enum viscous_precond kind,
                    double need, double avail)
{
    char needs[32], have[32];
    format_bytes(needs, sizeof needs, need);
    format_bytes(have, sizeof have, avail);
    snprintf(err, errlen,
             "%s = %d x %d x %d: the run needs about %s "
             "(fields, solver work%s), more than the %s of memory available on this machine",
             grid_stretched(g) ? "the cells with the domain's bands (domain.x_band, "
                                 "domain.y_band, domain.z_band)"
                               : "domain.nx x domain.ny x domain.nz",
             g->n[0], g->n[1], g->n[2], needs, without_factors(kind) ? "" : ", sparse factorisation",
             have);
}

int march_memory_check(const struct muflow_case *cs, const struct march_setup *su, char *msg,
                       size_t msglen)
{
    double avail = march_available_memory();
    struct grid g;
    int periodic[3];
    bc_periodic_flags(&cs->bc, periodic);
    if (!(avail > 0.0) || grid_init_compact(&g, cs->n, cs->len, periodic) != 0)
        return 0; /* nothing known, or a grid march_create refuses itself */
    struct grid_axis axes[3];
    int built[3] = {0, 0, 0}, ok = 1;
    for (int d = 0; d < 3; d++) {
        char why[300];
        int r = case_axis(cs, d, &axes[d], why, sizeof why);
        built[d] = r > 0;
        ok &= r >= 0 && (r == 0 || grid_set_axis(&g, d, &axes[d]) == 0);
    }
    int refused = 0;
    if (ok) {
        /* without opening hypre's library: the smaller of the two choices */
        enum viscous_precond with, without;
        double need_with = plan(cs, su, &g, 1, avail, &with);
        double need_without = plan(cs, su, &g, 0, avail, &without);
        double need = fmin(need_with, need_without);
        if (need > avail) {
            refusal(msg, msglen, &g, need_with <= need_without ? with : without, need, avail);
            refused = 1;
        }
    }
    for (int d = 0; d < 3; d++)
        if (built[d])
            grid_axis_free(&axes[d]);
    return refused;
}

/* The setup's modules, in order. */
static int add_modules(struct march_state *st, const struct march_setup *su, char *err,
                       size_t errlen)
{
    for (int l = 0; l < 3; l++)
        for (const struct module *const *m = su->modules[l]; m && *m; m++) {
            if (st->nmodules == MODULES_MAX) {
                snprintf(err, errlen, "more than %d physics modules", MODULES_MAX);
                return -1;
            }
            /* the coupled step solves the velocity and pressure of one
             * density and one velocity field (module.h: coupled_ok) */
            if (st->cs->coupled && !(*m)->coupled_ok) {
                snprintf(err, errlen, "solver.coupled = on: the physics module '%s' of this "
                                      "scene is not supported by the coupled step yet",
                         (*m)->name);
                return -1;
            }
            int i = st->nmodules++;
            st->modules[i] = *m;
            if ((*m)->create && (*m)->create(st, &st->module_state[i], err, errlen) != 0)
                return -1;
        }
    return 0;
}

int march_create(struct march_state *st, const struct muflow_case *cs,
                 const struct march_setup *su, char *err, size_t errlen)
{
    memset(st, 0, sizeof *st);
    st->cs = cs;
    st->bc = cs->bc;
    st->rheo = cs->rheo;
    if (cs->mode == MODE_STEADY)
        st->rheo.lambda *= cs->continuation;
    int wraps[3];
    bc_periodic_flags(&cs->bc, wraps);
    if (grid_init_compact(&st->g, cs->n, cs->len, wraps) != 0) {
        snprintf(err, errlen, "grid: invalid cell counts or lengths");
        return -1;
    }
    for (int d = 0; d < 3; d++) {
        char why[300];
        int r = case_axis(cs, d, &st->axes[d], why, sizeof why);
        if (r > 0 && grid_set_axis(&st->g, d, &st->axes[d]) != 0) {
            snprintf(why, sizeof why, "the field would not fit in memory");
            r = -1;
        }
        if (r < 0) {
            snprintf(err, errlen, "domain.%c_band: %s", "xyz"[d],
                     why[0] ? why : "not 'lo hi h' triples separated by ';'");
            march_destroy(st);
            return -1;
        }
    }
    const struct grid *g = &st->g;
    fields_init(&st->fields, g);
    bc_unknown_boxes(g, &st->bc, st->act);
    /* refuse before allocating what the machine does not have: a grid inside
     * the key limits (1000 x 1000 x 500) grew past 6.4 GB in a minute
     * without a word (case_load refuses it first, from the case alone) */
    enum viscous_precond kind;
    double avail = march_available_memory();
    st->memory_estimate = plan(cs, su, g, -1, avail, &kind);
    st->precond = kind;
    if (avail > 0.0 && st->memory_estimate > avail) {
        refusal(err, errlen, g, kind, st->memory_estimate, avail);
        march_destroy(st);
        return -1;
    }
    if (register_fields(st) != 0) {
        snprintf(err, errlen, "out of memory for a %d x %d x %d grid", g->n[0], g->n[1], g->n[2]);
        march_destroy(st);
        return -1;
    }
    /* one density everywhere until a module says otherwise */
    st->rho_ref = cs->density;
    st->density_uniform = 1;
    for (int c = 0; c < 3; c++)
        for (size_t p = 0; p < g->size; p++)
            st->rho_face[c][p] = cs->density;
    enum poisson_bc pbc[3][2];
    for (int d = 0; d < 3; d++)
        for (int s = 0; s < 2; s++)
            pbc[d][s] = projection_bc(st->bc.face[d][s]);
    /* the probed LU and the AMG both take the full (non-symmetric) tangent,
     * and so does the coupled step whatever the preconditioner named; the
     * Cholesky factorises the diagonal tangent and BiCGStab solves the full
     * one with it (the heap at 140 x 200: 58 steps instead of the diagonal
     * tangent's 460; docs/design.md, "The Cholesky of the diagonal tangent") */
    st->full_tangent = (kind == VISCOUS_LU || kind == VISCOUS_AMG || kind == VISCOUS_CHOLESKY ||
                        kind == VISCOUS_GMG || kind == VISCOUS_MG ||
                        cs->coupled) && cs->newton;
    int ok = 1;
    if (cs->augmentation > 0.0) {
        const struct field_spec s = {"augmentation", FIELD_CELLS, 0};
        ok &= fields_add(&st->fields, &s, &st->aug) >= 0;
    }
    if (st->full_tangent) {
        const struct field_spec sc = {"tangent_b_cells", FIELD_CELLS, 0},
                                se = {"tangent_b_edges", FIELD_EDGES, 0};
        ok &= fields_add(&st->fields, &sc, &st->b_c) >= 0 &&
              fields_add(&st->fields, &se, st->b_e) >= 0;
    }
    if (!ok) {
        snprintf(err, errlen, "out of memory for the full tangent");
        march_destroy(st);
        return -1;
    }
    /* a stretched grid's steps are the coupled ones (case_checks.c): no projection */
    if ((!grid_stretched(g) && pressure_create(&st->pressure_solver, g,
                                               (const enum poisson_bc(*)[2])pbc, err,
                                               errlen) != 0) ||
        viscous_create(&st->viscous, g, &st->bc, st->act, cs->line_direction, kind, err,
                       errlen) != 0 ||
        add_modules(st, su, err, errlen) != 0 || (su->setup && su->setup(st, err, errlen) != 0) ||
        hydrostatic_split(st, err, errlen) != 0) {
        march_destroy(st);
        return -1;
    }
    viscous_set_reuse(st->viscous, cs->preconditioner_reuse);
    /* an AMG or a geometric multigrid whose GMRES fails gives way to the LU
     * where that fits: the factorisation's limits, and the run with the LU
     * in the memory the machine had at the start */
    int periodic[3];
    bc_periodic_flags(&st->bc, periodic);
    viscous_allow_lu_fallback(st->viscous,
                              (kind == VISCOUS_AMG || kind == VISCOUS_GMG) &&
                                  3L * (long)grid_cells(g) <= FACTOR_MAX_UNKNOWNS &&
                                  sparse_direct_probes_for(g, periodic, 2) <=
                                      sparse_direct_max_probes() &&
                                  !(avail > 0.0 &&
                                    memory_estimate(cs, su, g, VISCOUS_LU) > avail));
    st->dt = cs->dt;
    forget_progress(st);
    st->dt_scale = 1.0;
    return 0;
}

/* The projection's coefficient; none without a projection (a stretched
 * grid's coupled steps solve the pressure with the velocity). */
static int projection_coefficient(struct march_state *st, double *const beta[3], char *err,
                                  size_t errlen)
{
    return st->pressure_solver ? pressure_set_coefficient(st->pressure_solver, beta, err, errlen)
                               : 0;
}

/* With an embedded body the projection's coefficient is the cut cells'
 * flux form: beta = 0 on the held faces (the velocity correction
 * -beta grad phi leaves them at 0), and the pressure operator
 * div_a(beta grad phi) takes a_f beta with the faces' open shares a_f (the
 * multigrid path: the FFT solver takes a uniform coefficient only). */
static int set_cut_coefficient(struct march_state *st, char *err, size_t errlen)
{
    const struct grid *g = &st->g;
    const struct embedded *e = st->embedded;
    for (int c = 0; c < 3; c++)
        for (long i = 0; i < e->nheld[c]; i++)
            st->beta[c][e->held[c][i]] = 0.0;
    double *coef[3] = {field_alloc(g), field_alloc(g), field_alloc(g)};
    int rc = -1;
    if (coef[0] && coef[1] && coef[2]) {
        for (int c = 0; c < 3; c++)
            for (size_t p = 0; p < g->size; p++)
                coef[c][p] = st->beta[c][p] * e->share[c][p];
        rc = projection_coefficient(st, coef, err, errlen);
    } else {
        snprintf(err, errlen, "out of memory for the cut cells' projection coefficient");
    }
    for (int c = 0; c < 3; c++)
        field_free(coef[c]);
    return rc;
}

int march_density_changed(struct march_state *st, int uniform, char *err, size_t errlen)
{
    const struct grid *g = &st->g;
    /* a body closes faces: the coefficient is never uniform then */
    uniform = uniform && !st->embedded;
    st->density_uniform = uniform;
    hydrostatic_force(st); /* gravity acts on the density of now */
    if (uniform)
        return projection_coefficient(st, NULL, err, errlen);
    if (!st->beta[0]) {
        const struct field_spec sb = {"projection_coefficient", FIELD_FACES, 0},
                                sm = {"mass_faces", FIELD_FACES, 0};
        if (fields_add(&st->fields, &sb, st->beta) < 0 ||
            fields_add(&st->fields, &sm, st->mass_face) < 0) {
            snprintf(err, errlen, "out of memory for the variable density");
            return -1;
        }
    }
    for (int c = 0; c < 3; c++)
        for (size_t p = 0; p < g->size; p++)
            st->beta[c][p] = st->rho_face[c][p] > 0.0 ? st->rho_ref / st->rho_face[c][p] : 0.0;
    if (st->embedded)
        return set_cut_coefficient(st, err, errlen);
    return projection_coefficient(st, st->beta, err, errlen);
}

void march_destroy(struct march_state *st)
{
    for (int i = st->nmodules - 1; i >= 0; i--)
        if (st->modules[i]->destroy)
            st->modules[i]->destroy(st->module_state[i]);
    fields_free(&st->fields);
    pressure_destroy(st->pressure_solver);
    viscous_destroy(st->viscous);
    stage_coupled_destroy(st->coupled);
    for (int d = 0; d < 3; d++)
        grid_axis_free(&st->axes[d]);
    memset(st, 0, sizeof *st);
}

int march_reforce(struct march_state *st, char *err, size_t errlen)
{
    if (hydrostatic_split(st, err, errlen) != 0)
        return -1;
    st->force_ref = 0.0; /* rho g may have changed */
    st->step = 0;
    st->time = 0.0;
    st->dt = st->cs->dt;
    /* residual0 is kept: it sets the pseudo-time step dt = dt0 r0 / r, and the
     * first residual of a continued solve is already small, so resetting it
     * would hold dt near dt0 and march through the physical transient (a heap
     * solve from the previous tilt: 150-250 steps instead of 15-40 from rest) */
    st->rejected = 0;
    forget_progress(st);
    st->sane_velocity = 0.0; /* a new forcing: a new velocity scale */
    st->mark_time = 0.0;
    st->marks = 0;
    st->dt_scale = 1.0;
    st->forcing = st->forcing_rms = 0.0; /* the step count starts again */
    st->wall_seconds = 0.0;
    st->status = STATUS_RUNNING;
    st->message[0] = '\0';
    return 0;
}

void march_evaluate(struct march_state *st) { step_evaluate(st); }

void march_apply_tangent(struct march_state *st, double *v[3], double *out[3])
{
    struct viscous_problem pb = implicit_problem(st, 0.0);
    viscous_apply(st->viscous, &pb, v, out);
}

/* The last accepted state: every FIELD_SAVED field of the registry. */

/* The last accepted state as a whole: its fields, step, time and dt. */
static void save_good_state(struct march_state *st)
{
    fields_save(&st->fields);
    st->good_step = st->step;
    st->good_time = st->time;
    st->good_dt = st->dt;
}

static void restore_good(struct march_state *st)
{
    fields_restore(&st->fields);
    st->step = st->good_step;
    st->time = st->good_time;
    st->dt = st->good_dt;
    step_evaluate(st);
}

/* The advective limit of the step (infinite without advection). */
static double cfl_dt(const struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    if (!cs->advection)
        return INFINITY;
    double umax = kernel_max_abs(&st->g, st->act, st->vel);
    return umax > 0.0 ? cs->cfl * march_min_spacing(&st->g) / umax : INFINITY;
}

static double choose_dt(const struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    double dt;
    if (cs->mode == MODE_STEADY) {
        /* switched evolution relaxation: the step grows as the residual falls */
        dt = st->residual > 0.0 ? cs->dt * st->residual0 / st->residual : cs->dt_max;
        if (dt > cs->dt_max)
            dt = cs->dt_max;
        if (dt < cs->dt)
            dt = cs->dt;
    } else {
        dt = cs->dt;
        if (st->time + dt > cs->end_time)
            dt = cs->end_time - st->time;
    }
    double lim = cfl_dt(st);
    /* and the modules' own limits (a tracer's transport) */
    for (int m = 0; m < st->nmodules; m++)
        if (st->modules[m]->max_dt)
            lim = fmin(lim, st->modules[m]->max_dt(st, st->module_state[m]));
    return dt > lim ? lim : dt;
}

/* Records the mean acceleration each time the pseudo-time doubles.  Called
 * on every evaluated state; idempotent for a state already seen (a restart
 * evaluates the checkpoint's state again). */
static void mark_doubling(struct march_state *st)
{
    if (st->time <= 0.0 || (st->marks > 0 && st->time < 2.0 * st->mark_time))
        return;
    st->mark_acc[2] = st->mark_acc[1];
    st->mark_acc[1] = st->mark_acc[0];
    st->mark_acc[0] = march_mean_acceleration(st);
    st->mark_time = st->time;
    st->marks++;
}

/* No 10% progress of the best residual in STALL_STEPS steps and in the
 * pseudo-time of as many unreduced steps, and none over the last STALL_STEPS
 * steps themselves: no residual since 10% below the one STALL_STEPS steps
 * ago (the residual st->residual is the current step's, not yet recorded). */
static int stalled_over(const struct march_state *st, long steps)
{
    return st->step - st->best_step > steps && st->time - st->best_time >= steps * choose_dt(st) &&
           fell_over(st, steps) != 1;
}

static int stalled(const struct march_state *st) { return stalled_over(st, STALL_STEPS); }

/* acc (now) and the marks have one sign, the last doubling lost less than
 * ACC_DECAY and no more than the one before, and acc kept 90% of the last
 * mark. */
static int acceleration_sustained(const struct march_state *st, double acc)
{
    if (st->marks < 3)
        return 0;
    const double *m = st->mark_acc;
    for (int i = 0; i < 3; i++)
        if (m[i] * acc <= 0.0)
            return 0;
    double d0 = 1.0 - m[0] / m[1], d1 = 1.0 - m[1] / m[2];
    return d0 < ACC_DECAY && d0 <= d1 && fabs(acc) >= (1.0 - ACC_DECAY) * fabs(m[0]);
}

/* Continuation in the regularisation (solver.continuation): a stage ends
 * when its residual has fallen STAGE_DROP-fold (or it is steady), and lambda
 * is lowered LAMBDA_STEP-fold, down to the case's. */
#define STAGE_DROP 1e-3
#define LAMBDA_STEP 10.0

static int continuing(const struct march_state *st)
{
    return st->rheo.lambda > st->cs->rheo.lambda;
}

static void next_stages(struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    while (continuing(st) && isfinite(st->residual) &&
           (st->residual <= STAGE_DROP * st->stage_residual0 ||
            (st->residual_excess <= cs->tolerance && st->divergence <= cs->tolerance))) {
        st->rheo.lambda = fmax(cs->rheo.lambda, st->rheo.lambda / LAMBDA_STEP);
        step_evaluate(st);
        st->stage_residual0 = st->residual;
        /* A start already steady at the stages above (solver.initial_state
         * from a solve at a larger lambda) left residual0 at that state's
         * round-off, which would hold the pseudo-time step dt0 r0 / r at dt0
         * for good: nothing marched yet, so the scale is this stage's. */
        if (st->step == 0)
            st->residual0 = st->residual;
        forget_progress(st);
        st->dt_scale = 1.0;
        st->picard_stalled = 0;
    }
}

/* A residual within SANE_RESIDUAL times max(1, the start's): forces at most
 * ten times the weight (or the start's) in every face. */
static int sane(const struct march_state *st)
{
    return st->residual <= SANE_RESIDUAL * fmax(1.0, st->residual0);
}

/* The component and the position of the largest |residual| (where a stall
 * sits). */
static void residual_peak(const struct march_state *st, int *comp, double at[3])
{
    const struct grid *g = &st->g;
    double peak = -1.0;
    *comp = 0;
    at[0] = at[1] = at[2] = 0.0;
    for (int c = 0; c < 3; c++) {
        const struct box *b = &st->act[c];
        for (int i = b->lo[0]; i < b->hi[0]; i++)
            for (int j = b->lo[1]; j < b->hi[1]; j++)
                for (int k = b->lo[2]; k < b->hi[2]; k++) {
                    double r = fabs(st->res[c][grid_idx(g, i, j, k)]);
                    if (!(r > peak))
                        continue;
                    const int idx[3] = {i, j, k};
                    peak = r;
                    *comp = c;
                    for (int d = 0; d < 3; d++)
                        at[d] = d == c ? grid_xf(g, d, idx[d]) : grid_xc(g, d, idx[d]);
                }
    }
}

/* Sets status and message when the run must end with the current state. */
static void check_end(struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    double excess;
    if (cs->mode == MODE_STEADY && isfinite(st->residual))
        mark_doubling(st);
    if (!isfinite(st->residual) || !isfinite(st->divergence)) {
        long bad = st->step;
        double t = st->time;
        restore_good(st);
        st->status = STATUS_DIVERGED;
        snprintf(st->message, sizeof st->message,
                 "non-finite values at step %ld, t = %.6g; the state of step %ld is kept", bad, t,
                 st->step);
    } else if (cs->mode == MODE_TRANSIENT && st->step > 0 &&
               st->residual > BLOWUP * fmax(1.0, st->residual0)) {
        long bad = st->step;
        double t = st->time, r = st->residual;
        restore_good(st);
        st->status = STATUS_DIVERGED;
        snprintf(st->message, sizeof st->message,
                 "the state blows up at step %ld, t = %.6g: residual %.3e, over %g times its "
                 "start (an unstable time step? solver.cfl, solver.dt); the state of step %ld "
                 "is kept", bad, t, r, BLOWUP, st->step);
    } else if (st->step > 0 && st->sane_velocity > 0.0 &&
               st->velocity_max > BLOWUP * st->sane_velocity && !sane(st)) {
        long bad = st->step;
        double t = st->time, u = st->velocity_max, r = st->residual;
        restore_good(st);
        st->status = STATUS_DIVERGED;
        snprintf(st->message, sizeof st->message,
                 "the state blows up at step %ld, t = %.6g: max |u| %.3e, over %g times %.3e, "
                 "the largest while the residual stayed within %g max(1, its start) (now "
                 "%.3e); the state of step %ld is kept", bad, t, u, BLOWUP, st->sane_velocity,
                 SANE_RESIDUAL, r, st->step);
    } else if (cs->mode == MODE_TRANSIENT && st->step > 0 &&
               cfl_dt(st) < DT_COLLAPSE * fmin(cs->dt, cs->end_time)) {
        /* the CFL limit, not the last step to end_time, which may be short */
        long bad = st->step;
        double t = st->time, dt = cfl_dt(st), umax = kernel_max_abs(&st->g, st->act, st->vel);
        restore_good(st);
        st->status = STATUS_DIVERGED;
        snprintf(st->message, sizeof st->message,
                 "the time step collapses at step %ld, t = %.6g: CFL step %.3e (max |u| %.3e) "
                 "below %g of min(solver.dt, end_time); the state of step %ld is kept",
                 bad, t, dt, umax, DT_COLLAPSE, st->step);
    } else if (cs->mode == MODE_STEADY && !continuing(st) && st->residual_excess <= cs->tolerance &&
               st->divergence <= cs->tolerance) {
        st->status = STATUS_STEADY;
        if (st->residual > cs->tolerance)
            snprintf(st->message, sizeof st->message,
                     "residual %.3e is round-off of its terms: beyond it %.1e <= tolerance %.1e",
                     st->residual, st->residual_excess, cs->tolerance);
        else
            snprintf(st->message, sizeof st->message, "residual %.3e <= tolerance %.1e",
                     st->residual, cs->tolerance);
    } else if (cs->mode == MODE_STEADY && !continuing(st) && st->divergence <= cs->tolerance &&
               stalled_over(st, ROUNDOFF_STALL_STEPS) &&
               (excess = stage_residual_velocity_roundoff(st)) <= cs->tolerance) {
        st->status = STATUS_STEADY;
        snprintf(st->message, sizeof st->message,
                 "residual %.3e stalls at the round-off its velocities carry: beyond it %.1e <= "
                 "tolerance %.1e (no 10%% progress in %ld steps)",
                 st->residual, excess, cs->tolerance, st->step - st->best_step);
    } else if (cs->mode == MODE_TRANSIENT && cs->steady_tolerance > 0.0 && st->step > 0 &&
               st->residual_excess <= cs->steady_tolerance &&
               st->divergence <= cs->steady_tolerance) {
        /* a transient run to a steady state: the same criterion as the
         * steady mode's, on the state the time march reached */
        st->status = STATUS_STEADY;
        snprintf(st->message, sizeof st->message,
                 "steady at t = %.6g: residual %.3e <= solver.steady_tolerance %.1e", st->time,
                 st->residual_excess, cs->steady_tolerance);
    } else if (cs->mode == MODE_TRANSIENT && st->time >= cs->end_time * (1.0 - 1e-12)) {
        st->status = STATUS_FINISHED;
        snprintf(st->message, sizeof st->message, "end time %g reached", cs->end_time);
    } else if (st->step >= cs->max_steps) {
        st->status = cs->mode == MODE_STEADY ? STATUS_UNSTEADY : STATUS_STOPPED;
        snprintf(st->message, sizeof st->message, "no %s after max_steps = %ld (residual %.3e)",
                 cs->mode == MODE_STEADY ? "steady state" : "end time", cs->max_steps,
                 st->residual);
    } else if (cs->mode == MODE_STEADY && stalled(st)) {
        double acc = march_mean_acceleration(st);
        if (fabs(acc) <= 0.1 * st->residual * march_force_scale(st) / cs->density) {
            int c;
            double at[3];
            residual_peak(st, &c, at);
            excess = stage_residual_velocity_roundoff(st);
            st->status = STATUS_UNSTEADY;
            snprintf(st->message, sizeof st->message,
                     "no steady state: the residual stalls at %.3e (no 10%% progress in %ld "
                     "steps, pseudo-time %.3g), %.1e beyond the round-off its velocities carry, "
                     "largest in the %c-momentum at (%.3g, %.3g, %.3g)",
                     st->residual, st->step - st->best_step, st->time - st->best_time, excess,
                     "xyz"[c], at[0], at[1], at[2]);
        } else if (acceleration_sustained(st, acc)) {
            st->status = STATUS_UNSTEADY;
            snprintf(st->message, sizeof st->message,
                     "no steady state: the layer accelerates (mean acceleration %.3e, "
                     "%.1f%% and %.1f%% lost over the last two doublings of the pseudo-time; "
                     "residual %.3e, no progress in %ld steps)",
                     acc, 100.0 * (1.0 - st->mark_acc[0] / st->mark_acc[1]),
                     100.0 * (1.0 - st->mark_acc[1] / st->mark_acc[2]), st->residual,
                     st->step - st->best_step);
        }
        /* else a decaying acceleration: a transient the march is following */
    }
}

/* A tangent step of a Picard-first steady solve (solver.newton_below < 1)
 * that raised both the maximum and the root mean square of the residual is
 * shortened: the state moves back along the step, halving it up to
 * LINE_SEARCH_HALVINGS times, until the root mean square has fallen by the
 * Armijo fraction of the step taken.  The pseudo-time step's cut (a
 * rejection) needs a new factorisation per try and left the tangent steps
 * crawling at dt ~ 1e-9 far from the solution; a shorter step along the same
 * direction costs one residual evaluation.  When no length descends, the full
 * step is taken again and judged as before (the tangent direction of the
 * split step is no descent direction there: Vola Bn = 100 on 64 x 64, where
 * a lagged-viscosity step in its place stalled).  Measured on the cavity
 * from rest (docs/design.md, "Globalisation"). */
#define LINE_SEARCH_HALVINGS 5
#define ARMIJO_FRACTION 1e-4

static int line_search(struct march_state *st, double dt, double rms0)
{
    double alpha = 1.0;
    for (int k = 0; k < LINE_SEARCH_HALVINGS; k++) {
        fields_blend(&st->fields, 0.5);
        alpha *= 0.5;
        step_evaluate(st);
        if (st->residual_rms <= (1.0 - ARMIJO_FRACTION * alpha) * rms0)
            return 0;
    }
    restore_good(st);
    if (step_advance(st, dt) != 0)
        return -1;
    step_evaluate(st);
    return 0;
}

/* Whether a module asks for the line search (module.h: line_search). */
static int module_searches(const struct march_state *st)
{
    for (int m = 0; m < st->nmodules; m++)
        if (st->modules[m]->line_search &&
            st->modules[m]->line_search(st, st->module_state[m]))
            return 1;
    return 0;
}

/* The steps that take the line search and the rejection on the maximum and
 * the root mean square together: those of a Picard-first solve, and those of
 * a continuation stage above the case's lambda (solver.continuation), whose
 * state only has to be close enough to start the next stage.  In the stages
 * the plain rejection crawled: after each tenfold lowering the first tangent
 * steps were cut to pseudo-time steps of 1e-5 and the march took 60-100
 * steps per stage (cases/cylinder.ini from rest: 398 steps, 114 with these).
 * The final stage, and solves without continuation, keep the plain rejection:
 * with the search the continuation in F of cases/cylinder.ini stalled at
 * F = 1.15 or 1.2, where the plain march's crawl reaches the steady state
 * (docs/design.md, "The granular cylinder and the steady mode").  But a
 * solve at a held mean velocity (physics/flow_rate.h: its line_search hook), whose plug's speed
 * the border fixes, searches: there the plain rejection crawled at
 * pseudo-time steps of 1e-6 on the maximum at the sliding layers while the
 * root mean square fell (the continuation in U of cases/cylinder.ini to
 * U = 60 at D/4: 3,967 steps and no failed solve with the search, 6,840
 * and two failed without, the same end). */
static int searched_steps(const struct march_state *st)
{
    return st->cs->newton_below < 1.0 || continuing(st) || module_searches(st);
}

enum run_status march_run(struct march_state *st, march_observer obs, void *ctx)
{
    const struct muflow_case *cs = st->cs;
    double t0 = omp_get_wtime() - st->wall_seconds; /* a restart keeps counting */
    st->status = STATUS_RUNNING;
    save_good_state(st);
    step_evaluate(st);
    if (st->step == 0 && st->residual0 == 0.0) /* march_reforce keeps it: below */
        st->residual0 = st->residual;
    if (st->stage_residual0 == 0.0)
        st->stage_residual0 = st->residual0;
    for (;;) {
        st->wall_seconds = omp_get_wtime() - t0;
        if (cs->mode == MODE_STEADY)
            next_stages(st);
        check_end(st);
        if (obs && obs(ctx, st) && st->status == STATUS_RUNNING) {
            st->status = STATUS_STOPPED;
            snprintf(st->message, sizeof st->message, "stopped at step %ld", st->step);
        }
        if (st->status != STATUS_RUNNING)
            break;
        save_good_state(st);
        if (st->residual < STALL_FACTOR * st->best_residual) {
            st->best_residual = st->residual;
            st->best_step = st->step;
            st->best_time = st->time;
        }
        st->recent_residual[st->step % MARCH_RECENT] = st->residual;
        st->peak_residual = fmax(st->peak_residual, st->residual);
        if (sane(st))
            st->sane_velocity = fmax(st->sane_velocity, st->velocity_max);
        /* Picard steps that make no 10% progress in PICARD_STALL steps: the
         * tangent takes over before the residual has fallen newton_below-fold */
        if (cs->mode == MODE_STEADY && cs->newton && cs->newton_below < 1.0 &&
            st->step - st->best_step >= PICARD_STALL && fell_over(st, PICARD_STALL) != 1 &&
            st->residual <= sqrt(cs->newton_below) * march_picard_reference(st))
            st->picard_stalled = 1;
        double accepted_residual = st->residual, accepted_rms = st->residual_rms, dt;
        double last_try = NAN; /* the residual the last rejected try reached */
        /* the accepted state's residual is mostly its own round-off */
        int at_roundoff = cs->mode == MODE_STEADY && !continuing(st) &&
                          st->residual - st->residual_excess >= st->residual / ROUNDOFF_SHARE;
        for (;;) {
            dt = choose_dt(st) * st->dt_scale;
            int newton_step = implicit_uses_tangent(st); /* steady mode only */
            st->step_error[0] = '\0';
            int broke = step_advance(st, dt) != 0;
            if (!broke)
                step_evaluate(st);
            int searched = searched_steps(st);
            if (!broke && newton_step && searched &&
                isfinite(st->residual) && st->residual_rms > accepted_rms &&
                st->residual > accepted_residual)
                broke = line_search(st, dt, accepted_rms) != 0;
            int bad = broke || !isfinite(st->residual) ||
                      (cs->mode == MODE_STEADY && st->residual > REJECT_GROWTH * accepted_residual &&
                        (!searched ||
                         st->residual_rms > REJECT_GROWTH * accepted_rms ||
                         st->residual > REJECT_MAX_GROWTH * accepted_residual));
            /* At the round-off of a steady state, a growth that a tenfold
             * shorter step leaves as it was (within DT_BLIND) does not come
             * from the step's length, and shorter ones do not cure it: the
             * try is taken, and the pseudo-time step comes back in a few
             * doublings instead of some thirty from MIN_DT_SCALE.  Measured
             * on cases/cylinder.ini, lambda 1e-6, F = 1.4, from a state at
             * 5.1e-5: steady in 621 steps, where the plain rejection cycled
             * (each try from 1.3e-6 gave 1e-3 to 9e-3 at every cut, the last
             * accepted at 1e-12 of the step) and ended unsteady after 904;
             * by the stages from lambda 1e-2, steady in 2,817 steps where it
             * stood at 5.1e-5 at the cap of 3,000.  Far from the solution
             * (the stages) the same rule took the residual from 1e-2 to 4
             * in 900 steps: so only at round-off (docs/design.md, "What a
             * cut step leaves"). */
            int dt_blind = at_roundoff && bad && !broke && isfinite(st->residual) &&
                           isfinite(last_try) && fabs(st->residual - last_try) <= DT_BLIND * last_try;
            if (!bad || cs->mode != MODE_STEADY || st->dt_scale < MIN_DT_SCALE || dt_blind) {
                if (broke) { /* nothing usable: end with the last finite state */
                    restore_good(st);
                    st->status = STATUS_DIVERGED;
                    snprintf(st->message, sizeof st->message,
                             "step %ld broke down (%.150s); the last finite state is kept",
                             st->step,
                             st->step_error[0] ? st->step_error : "the implicit viscous solve");
                }
                break;
            }
            last_try = broke ? NAN : st->residual;
            restore_good(st);
            st->dt_scale *= 0.1;
            st->rejected++;
        }
        if (st->status == STATUS_DIVERGED) {
            st->wall_seconds = omp_get_wtime() - t0;
            if (obs)
                obs(ctx, st);
            break;
        }
        st->dt_scale = fmin(1.0, 2.0 * st->dt_scale);
        st->dt = dt;
        st->time += dt;
        st->step++;
    }
    st->wall_seconds = omp_get_wtime() - t0;
    return st->status;
}
