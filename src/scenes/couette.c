/* Scene "couette": Newtonian plane Couette-Poiseuille flow between a fixed
 * wall at z = 0 and a lid at z = H moving along x at U, driven also by the
 * body force G = rho g sin(tilt) along x (cases/couette.ini).
 *
 * Exact solution: mu u'' = -G with u(0) = 0, u(H) = U, so
 *   u(z) = U z / H + G z (H - z) / (2 mu).
 * Its parabolic part tests the second-order wall condition; the headline is
 * the mid-height velocity. */
#include <math.h>
#include <stdio.h>
#include "scenes/scene.h"
#include "scene_common.h"

static double couette_u(const struct muflow_case *cs, double z)
{
    double H = cs->len[2], U = cs->bc.lid_velocity;
    double G = cs->density * cs->gravity * sin(cs->tilt);
    return U * z / H + G * z * (H - z) / (2.0 * cs->rheo.viscosity);
}

POINTWISE_PROFILE(exact_profile, couette_u)

static int check(const struct muflow_case *c, char *msg, size_t msglen)
{
    if (c->rheo.law != LAW_NEWTONIAN) {
        snprintf(msg, msglen, "case.scene = couette needs rheology.law = newtonian");
        return 1;
    }
    if (c->bc.face[2][0] != BC_WALL || c->bc.face[2][1] != BC_LID || c->bc.lid_direction != 0 ||
        c->bc.face[0][0] != BC_PERIODIC || c->bc.face[1][0] != BC_PERIODIC) {
        snprintf(msg, msglen, "case.scene = couette needs boundary.zlo = wall, boundary.zhi = lid, "
                              "boundary.lid_direction = x and boundary.xlo, boundary.xhi, "
                              "boundary.ylo, boundary.yhi = periodic");
        return 1;
    }
    return 0;
}

const struct scene scene_couette = {
    .name = "couette",
    .title = "Newtonian plane Couette-Poiseuille flow (linear plus parabolic profile)",
    .check = check,
    /* a profile along z: periodic x and y split over ranks */
    .decomposed = scene_decomposed_always,
    .profile_axis = 2,
    .profile_component = 0,
    .exact_profile = exact_profile,
    .headline_name = "u_mid",
};
