/* Open faces (grid/boundary.h: `open`): the loop over their faces and the
 * momentum balance that the projection (stage_projection.c) and the
 * coupled step (stage_coupled.c) take on them.  On an open face the
 * pressure is 0 (Dirichlet ghost -p) and the normal velocity is state; the
 * face's balance is its inner neighbour's with zero normal gradient for
 * every term but the pressure and the body force. */
#ifndef MUFLOW_OPEN_FACES_H
#define MUFLOW_OPEN_FACES_H

#include "march/step.h"

/* Runs BODY on every face of every open boundary with d its direction, pf
 * the face, pi the inner face beside it (face 1 or n - 1), pc the boundary
 * cell between them and s the sign of the outward normal (-1 low, +1 high);
 * the body is the macro's variadic part, so that it may hold commas.  A
 * rank border's side is not the boundary: its faces are inner ones. */
#define FOR_OPEN_FACES(st, ...)                                                      \
    for (int d = 0; d < 3; d++)                                                       \
        for (int side = 0; side < 2; side++) {                                        \
            if ((st)->bc.face[d][side] != BC_OPEN || bc_border(&(st)->bc, d, side))   \
                continue;                                                             \
            const int a_ = (d + 1) % 3, b_ = (d + 2) % 3;                             \
            const ptrdiff_t od = (st)->g.stride[d];                                   \
            const double s = side ? 1.0 : -1.0;                                       \
            int idx_[3];                                                              \
            idx_[d] = side ? (st)->g.n[d] : 0;                                        \
            for (idx_[a_] = 0; idx_[a_] < (st)->g.n[a_]; idx_[a_]++)                  \
                for (idx_[b_] = 0; idx_[b_] < (st)->g.n[b_]; idx_[b_]++) {            \
                    const ptrdiff_t pf = grid_idx(&(st)->g, idx_[0], idx_[1], idx_[2]); \
                    const ptrdiff_t pi = side ? pf - od : pf + od;                    \
                    const ptrdiff_t pc = side ? pf - od : pf;                         \
                    __VA_ARGS__                                                       \
                }                                                                     \
        }

/* d p / d x_d on an open face beside cell pc (outward sign s), with the
 * Dirichlet ghost -p[pc]: (ghost - p) / h high, (p - ghost) / h low. */
static inline double face_gradient(const double *p, ptrdiff_t pc, double s, double h)
{
    return -2.0 * s * p[pc] / h;
}

/* The pressure and body-force acceleration a = (F - grad p_dyn) / rho on
 * the inner face p = pi (on_face 0) or on the open face p = pf (on_face 1)
 * of direction d beside the boundary cell pc, F = rho g - grad p_hyd. */
double open_acceleration(const struct march_state *st, int d, ptrdiff_t p, int on_face,
                         ptrdiff_t pc, double s);

#endif
