/* Scene "cylinder": granular flow past a cylinder (Chauchat &
 * Medale 2014, sec. 4.2; cases/cylinder.ini), driven by the dimensionless body
 * force F = rho phi g L_x / p_ext and continued in F over steady solves.
 *
 * The case holds the obstacle (one circle in the x-z plane), the confining
 * pressure p_ext (physics.confining_pressure) and the bulk density rho phi
 * (physics.density); the scene sets the gravity from F before each solve
 * (the summary writes back the last one), with L_x the whole box across:
 * twice domain.lx when x = 0 is a slip face through the circle's centre (the
 * half box by symmetry), else lx.  Each F after the first starts from the
 * secant through the two steady states before it (the first continued one:
 * from the last), keeps the final lambda, and a failed F is retried at half
 * the step down to cylinder.min_step; below it the continuation ends on the
 * last steady state.  cylinder.csv has a row per solve. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "config/case.h"
#include "io/output.h"
#include "march/step.h"
#include "physics/flow_rate.h"
#include "physics/obstacle.h"
#include "physics/obstacle_forces.h"
#include "scenes/scene.h"
#include "scene_common.h"

struct cylinder_params {
    double forcing;      /* F of the first solve */
    double forcing_end;  /* the last F (<= forcing: one solve) */
    double forcing_step; /* the continuation's step in F */
    double min_step;     /* a failed step is halved down to this */
    double velocity_end; /* > 0: then continue in the mean velocity U up to this */
    double velocity_ratio; /* the continuation's factor in U */
    double velocity_stages; /* a failed U is retried by stages in lambda from this times it */
};

#define T struct cylinder_params
static const struct key cylinder_keys[] = {
    KEY_DBL(T, "cylinder", "forcing", forcing,
            "F = rho phi g L_x / p_ext of the first steady solve (L_x the whole box across); "
            "sets physics.gravity",
            KEY_GT0),
    KEY_DBL(T, "cylinder", "forcing_end", forcing_end,
            "continue in F up to this over steady solves (0, or not above cylinder.forcing: "
            "one solve)",
            KEY_GE0),
    KEY_DBL(T, "cylinder", "forcing_step", forcing_step, "the continuation's step in F",
            KEY_GT0),
    KEY_DBL(T, "cylinder", "min_step", min_step,
            "a failed F is retried at half the step down to this; below it the continuation "
            "ends on the last steady state",
            KEY_GT0),
    KEY_DBL(T, "cylinder", "velocity_end", velocity_end,
            KEY_HELP("after the continuation in F, continue in the mean velocity U up to this, F "
                     "solved for (0: none); needs cylinder.forcing_end > cylinder.forcing and a "
                     "periodic box",
                     "velocity", NULL),
            KEY_GE0),
    KEY_DBL(T, "cylinder", "velocity_ratio", velocity_ratio,
            "the continuation's factor in U (a failed U is retried at the factor's square root, "
            "down to 1 + (the factor - 1) / 8; a steady one squares it back)",
            KEY_GT0),
    KEY_DBL(T, "cylinder", "velocity_stages", velocity_stages,
            "a failed U is first retried from the same start by the stages in lambda (tenfold, "
            "as solver.continuation) from this times rheology.lambda (1: no such retry)",
            KEY_RANGE(1.0, KEY_NONE_HI, 1, 0)),
};
#undef T

static void cylinder_defaults(void *block)
{
    struct cylinder_params *c = block;
    c->forcing = 1.0;
    c->forcing_end = 0.0;
    c->forcing_step = 0.05;
    c->min_step = 0.0125;
    c->velocity_end = 0.0;
    c->velocity_ratio = 1.25;
    c->velocity_stages = 100.0;
}

SCENE_PARAMS(cylinder_block, "cylinder",
             "Granular flow past a cylinder (Chauchat & Medale 2014, sec. 4.2; "
             "`cases/cylinder.ini`).  The case needs one circle in `obstacle.shapes` (plane "
             "x-z), `rheology.law = mui`, `solver.mode = steady`, `physics.confining_pressure` "
             "p_ext > 0, `physics.tilt = 0` (the flow along -z) and `boundary.zlo = zhi` periodic "
             "or open.  The scene sets `physics.gravity` from F = rho phi g L_x / p_ext (rho phi "
             "= `physics.density`; L_x the whole box across: twice `domain.lx` when x = 0 is a "
             "slip face through the circle's centre).  With `forcing_end > forcing` the run is a "
             "continuation in F over steady solves, each F after the first starting from the "
             "secant through the two steady states before it; a failed F is retried at half the "
             "step down to `min_step`, below which the run ends on the last steady state "
             "(`forcing_failed` in the summary).  With `velocity_end > 0` it goes on in the mean "
             "velocity U, F an unknown of the coupled step.  `cylinder.csv` has a row per solve; "
             "the summary has `forcing`, `flow_rate`, `froude`, `drag` (control volume), "
             "`drag_surface`, `drag_over_pressure` and `drag_coefficient_mean_velocity` of the "
             "final state.  A continuation cannot be combined with `output.checkpoint_every` or "
             "`--restart`.",
             struct cylinder_params, cylinder_keys, cylinder_defaults)

/* ---- geometry and forcing ------------------------------------------------- */

/* The circle's diameter D and the whole box across L_x (twice lx for the
 * half box: a slip face at x = 0 through the centre); both NaN when the
 * case has not one circle in the x-z plane. */
struct box_geometry {
    double diameter, width;
};

static struct box_geometry geometry(const struct muflow_case *cs)
{
    struct box_geometry b = {NAN, NAN};
    struct shape_set set;
    case_obstacle_shapes(cs, &set);
    if (set.n != 1 || set.s[0].kind != SHAPE_CIRCLE || set.invert || set.plane_a != 0 ||
        set.plane_b != 2)
        return b;
    double lx = cs->len[0];
    int half = cs->bc.face[0][0] == BC_SLIP && fabs(set.s[0].v[0]) <= 1e-9 * lx;
    b.diameter = 2.0 * set.s[0].v[2];
    b.width = half ? 2.0 * lx : lx;
    return b;
}

static double gravity_of(const struct muflow_case *cs, double forcing)
{
    return forcing * cs->confining_pressure / (cs->density * geometry(cs).width);
}

static double forcing_of(const struct muflow_case *cs)
{
    return cs->density * cs->gravity * geometry(cs).width / cs->confining_pressure;
}

static int check(const struct muflow_case *c, char *msg, size_t msglen)
{
    if (!isfinite(geometry(c).width)) {
        snprintf(msg, msglen, "case.scene = cylinder needs obstacle.shapes = one circle in the "
                              "x-z plane (obstacle.plane = xz, obstacle.invert = off)");
        return 1;
    }
    if (c->rheo.law != LAW_MUI) {
        snprintf(msg, msglen, "case.scene = cylinder needs rheology.law = mui");
        return 1;
    }
    if (c->mode != MODE_STEADY) {
        snprintf(msg, msglen, "case.scene = cylinder needs solver.mode = steady");
        return 1;
    }
    if (!(c->confining_pressure > 0.0)) {
        snprintf(msg, msglen, "physics.confining_pressure = %s: case.scene = cylinder needs a "
                              "confining pressure p_ext > 0 (F = rho phi g L_x / p_ext)",
                 num_text(c->confining_pressure).s);
        return 1;
    }
    if (c->tilt != 0.0) {
        snprintf(msg, msglen, "physics.tilt = %s: case.scene = cylinder drives the flow along -z "
                              "(physics.tilt = 0)",
                 num_text(c->tilt).s);
        return 1;
    }
    /* the flow along z: periodic, or in at the top and out at the bottom
     * through open faces, where the pressure is p_ext */
    enum bc_kind zlo = c->bc.face[2][0], zhi = c->bc.face[2][1];
    if (!bc_through_flow(&c->bc, 2)) {
        snprintf(msg, msglen, "boundary.zlo = %s, boundary.zhi = %s: case.scene = cylinder "
                              "needs boundary.zlo = boundary.zhi = periodic or open (the flow "
                              "along z)",
                 bc_kind_name(zlo), bc_kind_name(zhi));
        return 1;
    }
    const struct cylinder_params *p = params(c);
    if (p->velocity_end > 0.0 && !(p->forcing_end > p->forcing)) {
        snprintf(msg, msglen, "cylinder.velocity_end = %s needs cylinder.forcing_end > "
                              "cylinder.forcing: the continuation in U starts from the last two "
                              "steady states in F",
                 num_text(p->velocity_end).s);
        return 1;
    }
    if (p->velocity_end > 0.0 && !(p->velocity_ratio > 1.0)) {
        snprintf(msg, msglen, "cylinder.velocity_ratio = %s must be > 1",
                 num_text(p->velocity_ratio).s);
        return 1;
    }
    const char *why = p->velocity_end > 0.0 ? flow_rate_refusal(c) : NULL;
    if (why) {
        snprintf(msg, msglen, "cylinder.velocity_end = %s (U held, F solved for) %s",
                 num_text(p->velocity_end).s, why);
        return 1;
    }
    if (p->forcing_end > p->forcing && c->checkpoint_every > 0) {
        snprintf(msg, msglen, "cylinder.forcing_end > cylinder.forcing (a continuation over "
                              "steady solves) needs output.checkpoint_every = 0");
        return 1;
    }
    return 0;
}

static const char *not_restartable(const struct muflow_case *cs)
{
    const struct cylinder_params *p = params(cs);
    return p->forcing_end > p->forcing
               ? "a continuation in F (cylinder.forcing_end > cylinder.forcing) cannot continue "
                 "from a checkpoint: start a new one from the last steady state "
                 "(solver.initial_state)"
               : NULL;
}

/* ---- one steady state's numbers ------------------------------------------- */

struct cylinder_values {
    double U, Fr, Fr_eff, drag, drag_surface, cd;
};

static void values_of(const struct march_state *st, struct cylinder_values *v)
{
    const struct muflow_case *cs = st->cs;
    double d = geometry(cs).diameter;
    struct obstacle_forces f;
    obstacle_forces(st, &f);
    v->U = obstacle_mean_velocity(st);
    v->Fr = v->U / sqrt(cs->gravity * d);
    v->Fr_eff = v->U / sqrt(cs->gravity * (d + cs->rheo.grain_diameter));
    v->drag = -f.control_volume[1]; /* along the flow, -z */
    v->drag_surface = -f.surface[1];
    v->cd = v->U != 0.0 ? v->drag / (0.5 * cs->density * v->U * v->U) : NAN;
}

/* ---- the continuation ----------------------------------------------------- */

#define MAX_ROWS 200 /* solves of one continuation, failed ones included */

struct row {
    double F, g, wall;
    enum run_status status;
    long steps;
    struct cylinder_values v;
};

/* What results() needs of the drive (in scene_drive.data). */
struct cylinder_run {
    int continued;        /* forcing_end > forcing */
    int solves;
    long steps;
    double failed_F;      /* the F the continuation ended at, or NaN */
    int in_velocity;      /* it went on in U (cylinder.velocity_end) */
    double failed_U;      /* the U it ended at, or NaN */
};

/* cylinder.csv, replaced whole after every solve; a failure to write it is
 * reported on stderr and the continuation goes on (its states are in
 * memory, its record only in that file). */
static void write_rows(const char *dir, const struct muflow_case *cs, const struct row *rows,
                       int n)
{
    struct output_file f;
    char err[256];
    if (output_open(&f, dir, "cylinder.csv", err, sizeof err) != 0) {
        fprintf(stderr, "muflow: warning: %s\n", err);
        return;
    }
    double p = cs->confining_pressure;
    fprintf(f.f, "p_ext,F,g,status,steps,wall_s,Q,U,Fr,Fr_eff,F_D,F_D_surface,F_D_over_p,C_D,"
                 "C_D_over_p\n");
    double width = geometry(cs).width;
    for (int i = 0; i < n; i++) {
        const struct row *r = &rows[i];
        fprintf(f.f, "%.10g,%.10g,%.10g,%s,%ld,%.4g", p, r->F, r->g,
                run_status_name(r->status), r->steps, r->wall);
        if (r->status == STATUS_STEADY)
            fprintf(f.f, ",%.10g,%.10g,%.8g,%.8g,%.10g,%.10g,%.10g,%.8g,%.8g\n",
                    r->v.U * width, r->v.U, r->v.Fr, r->v.Fr_eff, r->v.drag, r->v.drag_surface,
                    r->v.drag / p, r->v.cd, r->v.cd / p);
        else
            fprintf(f.f, ",,,,,,,,,\n");
    }
    if (output_commit(&f, err, sizeof err) != 0)
        fprintf(stderr, "muflow: warning: %s\n", err);
}

/* One steady solve at F from the state st holds (fresh: the case's start,
 * with its continuation in lambda; else a continued solve, measured afresh
 * like a run from solver.initial_state); with U > 0 at the mean velocity U,
 * F its start and then the solve's (physics/flow_rate.h). */
static enum run_status solve(struct scene_drive *d, double F, double U, int fresh,
                             double stages, struct row *row)
{
    struct march_state *st = d->st;
    memset(row, 0, sizeof *row);
    row->F = F;
    row->status = STATUS_DIVERGED; /* until the march says */
    d->cs->gravity = gravity_of(d->cs, F);
    row->g = d->cs->gravity;
    char err[256];
    /* the single solve of a run continued from its checkpoint goes on from
     * the checkpoint's step (its case holds this gravity already) */
    int resume = fresh && d->restarted;
    if (!resume && march_reforce(st, err, sizeof err) != 0) {
        st->status = STATUS_DIVERGED;
        snprintf(st->message, sizeof st->message, "F = %g: %.200s", F, err);
        return st->status;
    }
    if (!resume && flow_rate_restart(st, d->cs->gravity, U, err, sizeof err) != 0) {
        st->status = STATUS_DIVERGED;
        snprintf(st->message, sizeof st->message, "U = %g: %.200s", U, err);
        return st->status;
    }
    if (!fresh) {
        st->residual0 = 0.0; /* the pseudo-time scale of a new start */
        st->stage_residual0 = 0.0;
        st->picard_stalled = 0;
        if (stages > 1.0)
            st->rheo.lambda = d->cs->rheo.lambda * stages;
    }
    enum run_status s = march_run(st, d->observe, d->observe_ctx);
    if (U > 0.0) { /* the force the solve found */
        d->cs->gravity = flow_rate_gravity(st);
        F = forcing_of(d->cs);
    }
    row->F = F; /* the row was cleared above */
    row->g = d->cs->gravity;
    row->status = s;
    row->steps = st->step;
    row->wall = st->wall_seconds;
    if (s == STATUS_STEADY)
        values_of(st, &row->v);
    if (d->verbose) {
        if (U > 0.0)
            printf("cylinder: U %-9.6g %s after %ld steps, F %.6g", U, run_status_name(s),
                   st->step, F);
        else
            printf("cylinder: F %-9.6g %s after %ld steps", F, run_status_name(s), st->step);
        if (s == STATUS_STEADY)
            printf("  U %.5g  Fr %.4g  F_D %.5g  F_D / p_ext %.5g", row->v.U, row->v.Fr,
                   row->v.drag, row->v.drag / d->cs->confining_pressure);
        printf("  [%.1f s]\n", st->wall_seconds);
        if (s != STATUS_STEADY)
            printf("cylinder:   (%s)\n", st->message);
        fflush(stdout);
    }
    return s;
}

/* The run stops: no memory to keep the continuation's states in. */
static void out_of_memory(struct march_state *st)
{
    st->status = STATUS_STOPPED;
    snprintf(st->message, sizeof st->message, "cylinder: out of memory for the continuation");
}

/* One continued solve from the state fields_snapshot_put left, counted and
 * recorded; a steady one becomes the last of the two states the next
 * secant takes (older <- last <- it).  Returns the solve's status, or
 * STATUS_STOPPED when there is no memory for its state. */
static enum run_status continued_solve(struct scene_drive *d, struct cylinder_run *run,
                                       struct row *rows, int *n, double F, double U,
                                       double stages, struct field_snapshot *last,
                                       struct field_snapshot *older)
{
    struct march_state *st = d->st;
    enum run_status s = solve(d, F, U, 0, stages, &rows[(*n)++]);
    run->solves++;
    run->steps += st->step;
    if (d->dir)
        write_rows(d->dir, d->cs, rows, *n);
    if (s == STATUS_STEADY) {
        struct field_snapshot t = *older;
        *older = *last;
        *last = t;
        if (fields_snapshot_take(last, &st->fields) != 0) {
            out_of_memory(st);
            return STATUS_STOPPED;
        }
    }
    return s;
}

/* The continuation's record and state: its rows, the last two steady
 * states (their fields, F and U), the steps of the last one's solve and the
 * status of the last solve. */
struct continuation {
    struct row *rows;
    int n;
    struct field_snapshot last, older;
    double F_last, F_older, U_last, U_older;
    long last_steps;
    enum run_status status;
};

/* In F up to cylinder.forcing_end, each start the secant through the last
 * two steady states; a failed F is retried at half the step down to
 * cylinder.min_step. */
static void continue_in_forcing(struct scene_drive *d, struct continuation *c)
{
    struct march_state *st = d->st;
    const struct cylinder_params *p = params(d->cs);
    struct cylinder_run *run = (struct cylinder_run *)d->data.bytes;
    double step = p->forcing_step;
    const double eps = 1e-9 * p->forcing_end;
    while (c->F_last < p->forcing_end - eps && c->n < MAX_ROWS) {
        double F = fmin(c->F_last + step, p->forcing_end);
        /* the secant through the last two steady states, at most one of
         * their steps ahead */
        double w = isfinite(c->F_older) ? fmin(1.0, (F - c->F_last) / (c->F_last - c->F_older))
                                        : 0.0;
        fields_snapshot_put(&c->last, isfinite(c->F_older) ? &c->older : NULL, w, &st->fields);
        c->status = continued_solve(d, run, c->rows, &c->n, F, 0.0, 1.0, &c->last, &c->older);
        /* a signal, a failed output or no memory: the run says which */
        if (c->status == STATUS_STOPPED)
            break;
        if (c->status == STATUS_STEADY) {
            c->F_older = c->F_last;
            c->F_last = F;
            c->U_older = c->U_last;
            c->U_last = c->rows[c->n - 1].v.U;
            c->last_steps = st->step;
            continue;
        }
        /* no steady state at F: back to the last one, a shorter step */
        if (step * 0.5 >= p->min_step * (1.0 - 1e-9)) {
            step *= 0.5;
            continue;
        }
        run->failed_F = F;
        break;
    }
}

/* Then in U up to cylinder.velocity_end, from the last two steady states,
 * by their secant, on which U is exact (it is linear in the velocity); a
 * failed U is retried by stages in lambda, then at the factor's square
 * root. */
static void continue_in_velocity(struct scene_drive *d, struct continuation *c)
{
    struct march_state *st = d->st;
    const struct cylinder_params *p = params(d->cs);
    struct cylinder_run *run = (struct cylinder_run *)d->data.bytes;
    double ratio = p->velocity_ratio, min_ratio = 1.0 + (p->velocity_ratio - 1.0) / 8.0;
    int staged = 0; /* this U is being retried by stages */
    run->failed_F = NAN;
    run->in_velocity = 1;
    while (c->U_last < p->velocity_end * (1.0 - 1e-9) && c->n < MAX_ROWS) {
        double U = fmin(c->U_last * ratio, p->velocity_end);
        fields_snapshot_put(&c->last, &c->older, (U - c->U_last) / (c->U_last - c->U_older),
                            &st->fields);
        double g = flow_rate_gravity(st); /* the secant's */
        c->status = continued_solve(d, run, c->rows, &c->n, g / gravity_of(d->cs, 1.0), U,
                                    staged ? p->velocity_stages : 1.0, &c->last, &c->older);
        if (c->status == STATUS_STOPPED)
            break;
        if (c->status == STATUS_STEADY) {
            c->U_older = c->U_last;
            c->U_last = U;
            c->F_last = c->rows[c->n - 1].F;
            c->last_steps = st->step;
            ratio = fmin(p->velocity_ratio, ratio * ratio); /* back after a cut */
            staged = 0;
            continue;
        }
        /* the same U by stages in lambda, which steadies where the plain
         * solve stalls (docs/validation/cylinder.md) */
        if (p->velocity_stages > 1.0 && !staged) {
            staged = 1;
            continue;
        }
        staged = 0;
        if (sqrt(ratio) >= min_ratio * (1.0 - 1e-12)) {
            ratio = sqrt(ratio);
            continue;
        }
        run->failed_U = U;
        break;
    }
}

/* The continuation ends on its last steady state. */
static void end_on_last_steady(struct scene_drive *d, struct continuation *c)
{
    struct march_state *st = d->st;
    struct muflow_case *cs = d->cs;
    const struct cylinder_run *run = (const struct cylinder_run *)d->data.bytes;
    fields_snapshot_put(&c->last, NULL, 0.0, &st->fields);
    cs->gravity = gravity_of(cs, c->F_last);
    char err[200];
    if (march_reforce(st, err, sizeof err) != 0 ||
        flow_rate_restart(st, cs->gravity, run->in_velocity ? c->U_last : 0.0, err,
                          sizeof err) != 0) {
        /* the same forcing gave this state before: only memory can fail */
        st->status = STATUS_DIVERGED;
        snprintf(st->message, sizeof st->message,
                 "the continuation's last steady state could not be set up again: %.150s", err);
    } else {
        step_evaluate(st);
        st->step = c->last_steps; /* the summary's steps: the solve of this state */
        st->status = STATUS_STEADY;
    }
}

/* The message of a continuation that ended steady: where and why it ended. */
static void steady_message(struct march_state *st, const struct cylinder_params *p,
                           const struct cylinder_run *run, const struct continuation *c)
{
    const double eps = 1e-9 * p->forcing_end;
    if (run->in_velocity) {
        if (isfinite(run->failed_U))
            snprintf(st->message, sizeof st->message,
                     "steady at U = %.6g (F = %.6g), the continuation's end: no steady state "
                     "at U = %.6g within a factor of %g of it",
                     c->U_last, c->F_last, run->failed_U,
                     1.0 + (p->velocity_ratio - 1.0) / 8.0);
        else if (c->U_last < p->velocity_end * (1.0 - 1e-9))
            snprintf(st->message, sizeof st->message,
                     "steady at U = %.6g (F = %.6g): the continuation stopped at its limit of "
                     "%d solves short of cylinder.velocity_end = %s",
                     c->U_last, c->F_last, MAX_ROWS, num_text(p->velocity_end).s);
        else
            snprintf(st->message, sizeof st->message,
                     "steady at U = %.6g (F = %.6g) after %d solves from F = %.6g", c->U_last,
                     c->F_last, run->solves, p->forcing);
    } else {
        if (isfinite(run->failed_F))
            snprintf(st->message, sizeof st->message,
                     "steady at F = %.6g, the continuation's end: no steady state at F = %.6g "
                     "within cylinder.min_step = %s of it (the limit of steady flow, or of the "
                     "march)",
                     c->F_last, run->failed_F, num_text(p->min_step).s);
        else if (c->F_last < p->forcing_end - eps)
            snprintf(st->message, sizeof st->message,
                     "steady at F = %.6g: the continuation stopped at its limit of %d solves "
                     "short of cylinder.forcing_end = %s",
                     c->F_last, MAX_ROWS, num_text(p->forcing_end).s);
        else
            snprintf(st->message, sizeof st->message,
                     "steady at F = %.6g after %d solves from F = %.6g", c->F_last,
                     run->solves, p->forcing);
    }
}

static int drive(struct scene_drive *d)
{
    struct march_state *st = d->st;
    struct muflow_case *cs = d->cs;
    const struct cylinder_params *p = params(cs);
    struct cylinder_run *run = (struct cylinder_run *)d->data.bytes;
    _Static_assert(sizeof(struct cylinder_run) <= sizeof d->data.bytes, "drive data");
    memset(run, 0, sizeof *run);
    run->failed_F = run->failed_U = NAN;
    run->continued = p->forcing_end > p->forcing;
    struct continuation c = {.rows = malloc(MAX_ROWS * sizeof *c.rows)};
    if (!c.rows) {
        out_of_memory(st);
        return 0;
    }
    double t0 = omp_get_wtime() - st->wall_seconds; /* a restart's: the checkpoint's on */
    c.status = solve(d, p->forcing, 0.0, 1, 1.0, &c.rows[c.n++]);
    run->solves = 1;
    run->steps = st->step;
    if (d->dir)
        write_rows(d->dir, cs, c.rows, c.n);
    if (!run->continued || c.status != STATUS_STEADY) {
        st->wall_seconds = omp_get_wtime() - t0;
        free(c.rows);
        return 0;
    }
    if (fields_snapshot_take(&c.last, &st->fields) != 0) {
        out_of_memory(st);
        free(c.rows);
        return 0;
    }
    c.last_steps = st->step;
    c.F_last = p->forcing;
    c.F_older = NAN;
    c.U_last = c.rows[0].v.U;
    c.U_older = NAN;
    continue_in_forcing(d, &c);
    if (c.status != STATUS_STOPPED && p->velocity_end > 0.0 && isfinite(c.U_older) &&
        c.U_last > c.U_older && c.n < MAX_ROWS)
        continue_in_velocity(d, &c);
    if (c.status != STATUS_STOPPED && c.status != STATUS_STEADY)
        end_on_last_steady(d, &c);
    if (st->status == STATUS_STEADY)
        steady_message(st, p, run, &c);
    st->wall_seconds = omp_get_wtime() - t0; /* the whole continuation */
    fields_snapshot_free(&c.last);
    fields_snapshot_free(&c.older);
    free(c.rows);
    return 0;
}

static void results(const struct march_state *st, const struct scene_drive *d,
                    struct run_result *res)
{
    const struct muflow_case *cs = st->cs;
    const struct cylinder_run *run = (const struct cylinder_run *)d->data.bytes;
    double F = forcing_of(cs), width = geometry(cs).width;
    run_result_add(res, "forcing", "%.15g", F);
    if (run->continued) {
        snprintf(res->stop_note, sizeof res->stop_note,
                 "during the continuation (not restartable): cylinder.csv has the solves "
                 "so far, checkpoint.h5 the last state (solver.initial_state starts a new run "
                 "from it)");
        run_result_add(res, "solves", "%d", run->solves);
        run_result_add(res, "steps_total", "%ld", run->steps);
        if (isfinite(run->failed_F))
            run_result_add(res, "forcing_failed", "%.10g", run->failed_F);
        if (isfinite(run->failed_U))
            run_result_add(res, "velocity_failed", "%.10g", run->failed_U);
    }
    if (st->status != STATUS_STEADY)
        return;
    struct cylinder_values v;
    values_of(st, &v);
    double p = cs->confining_pressure;
    run_result_add(res, "flow_rate", "%.10g", v.U * width);
    run_result_add(res, "froude", "%.10g", v.Fr);
    run_result_add(res, "froude_effective", "%.10g", v.Fr_eff);
    run_result_add(res, "drag", "%.10g", v.drag);
    run_result_add(res, "drag_surface", "%.10g", v.drag_surface);
    run_result_add(res, "drag_over_pressure", "%.10g", v.drag / p);
    run_result_add(res, "drag_coefficient_mean_velocity", "%.10g", v.cd);
    snprintf(res->scene_line, sizeof res->scene_line,
             "F %.6g: U %.5g, Fr %.4g, F_D %.5g (control volume; surface %.5g), F_D / p_ext "
             "%.5g, C_D %.4g",
             F, v.U, v.Fr, v.drag, v.drag_surface, v.drag / p, v.cd);
}

static const char *const cylinder_files[] = {"cylinder.csv", NULL};

/* idle but for a continuation in U (cylinder.velocity_end) */
static const struct module *const cylinder_modules[] = {&flow_rate_module, NULL};

const struct scene scene_cylinder = {
    .name = "cylinder",
    .stretched_grid = 1,
    .title = "granular flow past a cylinder driven by F = rho phi g L_x / p_ext, continued in F",
    .keys = &cylinder_block,
    .check = check,
    .profile_axis = -1,
    .profile_component = -1,
    .drive = drive,
    .not_restartable = not_restartable,
    .results = results,
    .files = cylinder_files,
    .modules = cylinder_modules,
    /* the coupled step gathers its whole plane onto every rank
       (march/coupled_view.h), the forces are summed over the ranks */
    .decomposed = scene_decomposed_always,
};
