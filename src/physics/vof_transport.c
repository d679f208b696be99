/* Whole VOF steps over the sweeps of kernels/vof.c (see vof_transport.h). */
#include "physics/vof_transport.h"
#include "grid/decomp.h"
#include "kernels/vof.h"

int vof_transport_init(struct vof_transport *vt, const struct grid *g, const struct boundary *bc)
{
    *vt = (struct vof_transport){.g = g, .bc = bc};
    int ok = 1;
    for (int d = 0; d < 3; d++) {
        ok &= (vt->normal[d] = field_alloc(g)) != NULL;
        ok &= (vt->flux[d] = field_alloc(g)) != NULL;
    }
    ok &= (vt->alpha = field_alloc(g)) != NULL;
    ok &= (vt->indicator = field_alloc(g)) != NULL;
    /* field_alloc zeroes: the flux of a direction of one cell stays 0 */
    if (!ok) {
        vof_transport_free(vt);
        return -1;
    }
    return 0;
}

void vof_transport_free(struct vof_transport *vt)
{
    for (int d = 0; d < 3; d++) {
        field_free(vt->normal[d]);
        field_free(vt->flux[d]);
    }
    field_free(vt->alpha);
    field_free(vt->indicator);
    *vt = (struct vof_transport){0};
}

/* Ghost interfaces.  Periodic faces: the copy bc_fill_scalar makes, so that
 * the flux through face 0 is computed from exactly the data (and by exactly
 * the operations) of the flux through face n: they are the same double and
 * the domain's total is conserved.  Other faces: the mirror image of the
 * interior cell, like the mirrored T (zero-gradient), i.e. xi_e -> 1 - xi_e:
 * m_e changes sign and alpha loses m_e.  Closed boundary faces carry no
 * flux, so this only matters to the faces that let fluid through (open,
 * inflow), whose ghost cells hold the light phase: see open_ghosts.  A rank
 * border's ghosts are the neighbour's cells, their interface exchanged as
 * the neighbour reconstructed it: the flux through a border face is then
 * computed by both ranks from the same upwind data by the same operations,
 * the same double on both (volume conserved over the ranks, the result the
 * one process's). */

/* On an open or inflow face the fluid that enters is the light phase
 * (T = 0): the ghost cells there are empty, with no interface (zero normal:
 * the slab fraction is then the ghost's uniform T = 0).  Fluid leaving takes
 * the interior cell's slab as at any face.  which: 0 sets T's ghosts, 1 the
 * interface's. */
static void open_ghosts(struct vof_transport *vt, double *T, int which)
{
    const struct grid *g = vt->g;
    for (int e = 0; e < 3; e++) {
        int a = (e + 1) % 3, b = (e + 2) % 3;
        for (int side = 0; side < 2; side++) {
            if (!bc_kind_passes_flow(vt->bc->face[e][side]) || bc_border(vt->bc, e, side))
                continue;
            int idx[3];
            idx[e] = side == 0 ? -1 : g->n[e];
            for (idx[a] = grid_slot_lo(g, a); idx[a] <= grid_slot_hi(g, a); idx[a]++)
                for (idx[b] = grid_slot_lo(g, b); idx[b] <= grid_slot_hi(g, b); idx[b]++) {
                    ptrdiff_t p = grid_idx(g, idx[0], idx[1], idx[2]);
                    if (which == 0) {
                        T[p] = 0.0;
                    } else {
                        for (int c = 0; c < 3; c++)
                            vt->normal[c][p] = 0.0;
                        vt->alpha[p] = 0.0;
                    }
                }
        }
    }
}

static void fill_interface_ghosts(struct vof_transport *vt)
{
    const struct grid *g = vt->g;
    for (int d = 0; d < 3; d++)
        bc_fill_scalar(g, vt->bc, vt->normal[d]);
    bc_fill_scalar(g, vt->bc, vt->alpha);
    for (int e = 0; e < 3; e++) {
        if (vt->bc->face[e][0] == BC_PERIODIC || g->n[e] == 1)
            continue;
        int a = (e + 1) % 3, b = (e + 2) % 3;
        for (int side = 0; side < 2; side++)
            for (int ia = 0; ia < g->n[a] && !bc_border(vt->bc, e, side); ia++)
                for (int ib = 0; ib < g->n[b]; ib++) {
                    int idx[3];
                    idx[e] = side == 0 ? -1 : g->n[e];
                    idx[a] = ia;
                    idx[b] = ib;
                    ptrdiff_t p = grid_idx(g, idx[0], idx[1], idx[2]);
                    double m = vt->normal[e][p];
                    vt->alpha[p] -= m;
                    vt->normal[e][p] = -m;
                }
    }
}

int vof_transport_step(struct vof_transport *vt, double *T, double *const vel[3], double dt,
                       double *max_cfl)
{
    const struct grid *g = vt->g;
    /* every rank takes the step or refuses it alike */
    double largest = decomp_max(vt->bc->dc, vof_cfl(g, vel, dt, vt->cfl));
    if (max_cfl)
        *max_cfl = largest;
    if (largest > VOF_CFL_MAX)
        return -1;

    int open = bc_passes_flow(vt->bc);
    static const int forward[3] = {0, 1, 2}, backward[3] = {2, 1, 0};
    const int *seq = vt->steps % 2 == 0 ? forward : backward;
    vt->nsweeps = 0;
    for (int s = 0; s < 3; s++)
        if (g->n[seq[s]] > 1)
            vt->order[vt->nsweeps++] = seq[s];

    /* c_c from the state at the start of the step, kept for every sweep */
    vof_indicator(g, T, vt->indicator);
    for (int s = 0; s < vt->nsweeps; s++) {
        int d = vt->order[s];
        bc_fill_scalar(g, vt->bc, T);
        if (open)
            open_ghosts(vt, T, 0);
        vof_reconstruct(g, T, vt->normal, vt->alpha);
        fill_interface_ghosts(vt);
        if (open)
            open_ghosts(vt, T, 1);
        vof_sweep(g, d, vel[d], dt, vt->indicator, vt->normal, vt->alpha, T, vt->flux[d]);
    }
    bc_fill_scalar(g, vt->bc, T);
    vt->steps++;
    return 0;
}
