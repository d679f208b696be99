/* The open faces' momentum balance (open_faces.h). */
#include "march/open_faces.h"

double open_acceleration(const struct march_state *st, int d, ptrdiff_t p, int on_face,
                         ptrdiff_t pc, double s)
{
    const struct grid *g = &st->g;
    double rho = st->density_uniform ? st->cs->density : st->field.density_faces[d][p];
    double F, G;
    if (on_face) {
        double f[3];
        body_force_vector(st->cs, f);
        F = (st->density_uniform ? f[d] : f[d] * rho / st->cs->density) -
            face_gradient(st->field.p_hyd, pc, s, g->h[d]);
        G = face_gradient(st->field.p_dyn, pc, s, g->h[d]);
    } else {
        F = st->field.force[d][p];
        G = (st->field.p_dyn[p] - st->field.p_dyn[p - g->stride[d]]) / g->h[d];
    }
    return rho > 0.0 ? (F - G) / rho : 0.0;
}

