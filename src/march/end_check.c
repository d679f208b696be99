/* The end of a run (march_internal.h: march_check_end): steady, at its end
 * time, at max_steps, unsteady (a stall, a sustained acceleration) or
 * diverged (non-finite values, a blow-up, a collapsed time step); the
 * criteria and their measurements: docs/numerics/steady-criterion.md. */
#include <math.h>
#include <stdio.h>
#include "march_internal.h"

#include "march/step.h"

/* A net acceleration ends the run only when it is sustained: at the last
 * three doublings of the pseudo-time it lost less than ACC_DECAY over the
 * last doubling and no more than over the one before.  A start-up transient
 * loses more at each doubling (friction engages), a layer above
 * atan(mu_s + dmu) less, towards a positive limit. */
#define ACC_DECAY 0.1
/* A steady march is done at the round-off of its velocities when it makes
 * no progress for ROUNDOFF_STALL_STEPS steps (as stalled() judges it) and
 * its residual is within what velocities carrying the field's round-off,
 * eps max |u| each, leave (stage_residual_velocity_roundoff).  The solves
 * leave that much in a stiff region: a plug of viscosity mu p / lambda turns
 * it into a residual the plain measure (its terms at their own velocities)
 * calls real, and which no step removes.  The stagnation guards against a
 * Newton iteration still converging inside that bound. */
#define ROUNDOFF_STALL_STEPS 20
/* Transient mode has no rejections: a state whose residual (relative to
 * rho g, or without gravity to the first residual) exceeds BLOWUP times its
 * start is blowing up.  In either mode a state blows up when its residual
 * is beyond SANE_RESIDUAL times max(1, its start) and its largest velocity
 * beyond BLOWUP times the largest of the sane states, those whose residual
 * stayed within that bound (sane_velocity).  A steady march's rejections
 * bound the growth of one step (REJECT_GROWTH, march.c), not of many, and
 * its residual may climb far and recover, so the residual alone judges
 * transient runs only; a physical acceleration (a layer above
 * atan(mu_s + dmu)) keeps its residual within the weight: its velocity is
 * the scale.  A CFL step below DT_COLLAPSE times the case's dt (or end
 * time, if smaller) has stopped the clock. */
#define BLOWUP 1e3
#define DT_COLLAPSE 1e-8
/* A march from rest has no velocity scale of its own: its first sane states
 * may only creep (the nonlocal fluidity's layer starts at g = 0, eta = p /
 * lambda: 3.6e-6 against the 0.94 it reaches, 160 cells), and the growth to
 * the flow, with a residual a little past the bound, is not a blow-up.  So
 * the scale is at least VELOCITY_FLOOR sqrt(g L), L the box's largest
 * length: small enough that a film's blow-up (bagnold2: 0.0105 m/s to 20
 * m/s, sqrt(g L) = 0.094 m/s) is judged as before. */
#define VELOCITY_FLOOR 1e-2

/* The velocity a blow-up is measured against: the sane states' largest, or
 * the gravity's floor above. */
static double blowup_scale(const struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    double L = fmax(cs->len[0], fmax(cs->len[1], cs->len[2]));
    double floor = cs->gravity > 0.0 ? VELOCITY_FLOOR * sqrt(cs->gravity * L) : 0.0;
    return fmax(st->sane_velocity, floor);
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
    return st->step - st->best_step > steps &&
           st->time - st->best_time >= steps * march_choose_dt(st) &&
           march_fell_over(st, steps) != 1;
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
                    double r = fabs(st->field.residual[c][grid_idx(g, i, j, k)]);
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
void march_check_end(struct march_state *st)
{
    const struct muflow_case *cs = st->cs;
    double excess;
    if (cs->mode == MODE_STEADY && isfinite(st->residual))
        mark_doubling(st);
    if (!isfinite(st->residual) || !isfinite(st->divergence)) {
        long bad = st->step;
        double t = st->time;
        march_restore_good(st);
        st->status = STATUS_DIVERGED;
        snprintf(st->message, sizeof st->message,
                 "non-finite values at step %ld, t = %.6g; the state of step %ld is kept", bad, t,
                 st->step);
    } else if (cs->mode == MODE_TRANSIENT && st->step > 0 &&
               st->residual > BLOWUP * fmax(1.0, st->residual0)) {
        long bad = st->step;
        double t = st->time, r = st->residual;
        march_restore_good(st);
        st->status = STATUS_DIVERGED;
        snprintf(st->message, sizeof st->message,
                 "the state blows up at step %ld, t = %.6g: residual %.3e, over %g times its "
                 "start (an unstable time step? solver.cfl, solver.dt); the state of step %ld "
                 "is kept", bad, t, r, BLOWUP, st->step);
    } else if (st->step > 0 && st->sane_velocity > 0.0 &&
               st->velocity_max > BLOWUP * blowup_scale(st) && !march_sane(st)) {
        long bad = st->step;
        double t = st->time, u = st->velocity_max, r = st->residual, scale = blowup_scale(st);
        long kept;
        march_restore_good(st);
        kept = st->step;
        st->status = STATUS_DIVERGED;
        if (scale > st->sane_velocity)
            snprintf(st->message, sizeof st->message,
                     "the state blows up at step %ld, t = %.6g: max |u| %.3e, over %g times "
                     "%.3e, 1e-2 sqrt(g L) (residual %.3e); the state of step %ld is kept",
                     bad, t, u, BLOWUP, scale, r, kept);
        else
            snprintf(st->message, sizeof st->message,
                     "the state blows up at step %ld, t = %.6g: max |u| %.3e, over %g times "
                     "%.3e, the largest while the residual stayed within %g max(1, its start) "
                     "(now %.3e); the state of step %ld is kept",
                     bad, t, u, BLOWUP, scale, SANE_RESIDUAL, r, kept);
    } else if (cs->mode == MODE_TRANSIENT && st->step > 0 &&
               march_cfl_dt(st) < DT_COLLAPSE * fmin(cs->dt, cs->end_time)) {
        /* the CFL limit, not the last step to end_time, which may be short */
        long bad = st->step;
        double t = st->time, dt = march_cfl_dt(st),
               umax = march_max(st, kernel_max_abs(&st->g, st->act, st->field.velocity));
        march_restore_good(st);
        st->status = STATUS_DIVERGED;
        snprintf(st->message, sizeof st->message,
                 "the time step collapses at step %ld, t = %.6g: CFL step %.3e (max |u| %.3e) "
                 "below %g of min(solver.dt, end_time); the state of step %ld is kept",
                 bad, t, dt, umax, DT_COLLAPSE, st->step);
    } else if (cs->mode == MODE_STEADY && !march_continuing(st) &&
               st->residual_excess <= cs->tolerance &&
               st->divergence <= cs->tolerance) {
        st->status = STATUS_STEADY;
        if (st->residual > cs->tolerance)
            snprintf(st->message, sizeof st->message,
                     "residual %.3e is round-off of its terms: beyond it %.1e <= tolerance %.1e",
                     st->residual, st->residual_excess, cs->tolerance);
        else
            snprintf(st->message, sizeof st->message, "residual %.3e <= tolerance %.1e",
                     st->residual, cs->tolerance);
    } else if (cs->mode == MODE_STEADY && !march_continuing(st) &&
               st->divergence <= cs->tolerance &&
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
