/* Anderson acceleration of the nonlocal fluidity's steady iteration
 * (physics/ngf.h; Anderson 1965, "Iterative procedures for nonlinear
 * integral equations"; Walker & Ni 2011, "Anderson acceleration for
 * fixed-point iterations").
 *
 * A steady step of law = ngf is one application of the Picard map g ->
 * G(u(g)): the momentum solved with eta = p_reg / (g + lambda), then the
 * fluidity's linear equation from the new shear rates.  Its rate is that of
 * the least stable mode of the linearised map, 0.86 a step on the shipped
 * incline.  The acceleration keeps the last `depth` pairs (g_j, G_j), G_j the
 * map's value at the iterate g_j, and takes as the next iterate the
 * combination sum a_j G_j (sum a_j = 1) whose residual sum a_j (G_j - g_j) is
 * least in the 2-norm over the cells (over the ranks too): on the linearised
 * map this is GMRES on (I - G') e = 0 (Walker & Ni), so the slow modes are
 * taken out in a few steps instead of being contracted 0.86 a step.  The
 * next iterate is cut at 0 (g >= 0). */
#ifndef MUFLOW_PHYSICS_FLUIDITY_ANDERSON_H
#define MUFLOW_PHYSICS_FLUIDITY_ANDERSON_H

#include <stddef.h>

struct march_state;
struct fluidity_anderson;

/* depth >= 1 pairs over n cells; NULL when out of memory */
struct fluidity_anderson *fluidity_anderson_create(size_t n, int depth);
void fluidity_anderson_destroy(struct fluidity_anderson *a);
/* forgets the history: the next mix starts again */
void fluidity_anderson_reset(struct fluidity_anderson *a);
/* A continued run's history (the checkpoint): the compact array of ring
 * slot 0 .. depth of the residuals (map_value 0) or the map's values (1);
 * the slot the last push filled; the two counters (pairs held, newest
 * slot) as doubles, and set back (-1: they do not fit this depth). */
double *fluidity_anderson_slot(struct fluidity_anderson *a, int map_value, int slot);
int fluidity_anderson_newest_slot(const struct fluidity_anderson *a);
void fluidity_anderson_get_state(const struct fluidity_anderson *a, double s[2]);
int fluidity_anderson_set_state(struct fluidity_anderson *a, const double s[2]);
/* the bytes it allocates for n cells at that depth */
double fluidity_anderson_bytes(size_t n, int depth);

/* Adds the pair (x, gx): x the iterate a Picard step took (the cells, in
 * the module's order), gx the map's value there; the 2-norm of gx - x over
 * the ranks of st. */
double fluidity_anderson_push(struct fluidity_anderson *a, const struct march_state *st,
                              const double *x, const double *gx);
/* forgets all pairs but the newest */
void fluidity_anderson_keep_newest(struct fluidity_anderson *a);
/* the accelerated iterate from the pairs held */
void fluidity_anderson_next(const struct fluidity_anderson *a, const struct march_state *st,
                            double *next);

#endif
