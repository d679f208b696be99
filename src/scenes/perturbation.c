/* The divergence-free perturbation of the layer scenes (scenes/perturbation.h).
 *
 * The potential (a, b, c) lives on the edges: a on the x edges
 * ((i + 1/2) hx, j hy, k hz), psi = -b on the y edges (i hx, (j + 1/2) hy,
 * k hz), c on the z edges (i hx, j hy, (k + 1/2) hz), and the velocity on
 * the faces is its discrete curl,
 *   u = dc/dy + dpsi/dz,   v = da/dz - dc/dx,   w = -dpsi/dx - da/dy,
 * each derivative a difference of the two edges beside the face.  The
 * cell's divergence is then a sum of mixed second differences that cancel
 * in pairs (Dx Dz psi - Dz Dx psi, and likewise for a and c), to round-off
 * whatever the values.  psi alone is bagnold2's stream function of the x-z
 * plane (PERTURB_XZ); its values, and so bagnold2's runs, are those it
 * always had. */
#include <math.h>
#include <stdint.h>
#include "scenes/perturbation.h"

enum { POT_PSI = 0, POT_A, POT_C };

/* A uniform deviate in [-1, 1] of the edge (i, j, k) of the potential's
 * component comp (splitmix64 of its number, one increment per component):
 * the same perturbation on any number of threads. */
static double edge_deviate(int comp, int i, int j, int k)
{
    uint64_t x = ((uint64_t)(uint32_t)i << 42) ^ ((uint64_t)(uint32_t)j << 21) ^ (uint32_t)k;
    x += 0x9e3779b97f4a7c15ULL * (uint64_t)(comp + 1);
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    x ^= x >> 31;
    return (double)(x >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

/* The potential's component comp at its edge (i, j, k), z its height:
 * the deviate times sin^2(pi z / height) below height, 0 above; the
 * periodic directions wrap (j only for the components indexed by a y
 * node: a and c). */
static double potential(const struct grid *g, int comp, int i, int j, int k, double z,
                        double height)
{
    const double pi = 3.14159265358979323846;
    double s = z < height ? sin(pi * z / height) : 0.0;
    int jj = comp == POT_PSI ? j : j % g->n[1];
    int ii = comp == POT_A ? i : i % g->n[0];
    return edge_deviate(comp, ii, jj, k) * s * s;
}

/* The added velocity of the faces (i, j, k): out[0] on the x face, out[1]
 * on the y face, out[2] on the z face. */
static void curl(const struct grid *g, enum perturbation_shape shape, double height, int i, int j,
                 int k, double out[3])
{
    double hx = g->h[0], hy = g->h[1], hz = g->h[2];
    double zn = k * hz, zn1 = (k + 1) * hz, zc = (k + 0.5) * hz;
    double p0 = potential(g, POT_PSI, i, j, k, zn, height);
    out[0] = (potential(g, POT_PSI, i, j, k + 1, zn1, height) - p0) / hz;
    out[1] = 0.0;
    out[2] = -(potential(g, POT_PSI, i + 1, j, k, zn, height) - p0) / hx;
    if (shape != PERTURB_3D)
        return;
    double c0 = potential(g, POT_C, i, j, k, zc, height);
    double a0 = potential(g, POT_A, i, j, k, zn, height);
    out[0] += (potential(g, POT_C, i, j + 1, k, zc, height) - c0) / hy;
    out[1] = (potential(g, POT_A, i, j, k + 1, zn1, height) - a0) / hz -
             (potential(g, POT_C, i + 1, j, k, zc, height) - c0) / hx;
    out[2] -= (potential(g, POT_A, i, j + 1, k, zn, height) - a0) / hy;
}

/* Over the ranks of a decomposed march each rank draws its block's faces
 * by their global index on the whole grid, and the largest face velocity
 * is every rank's: the perturbation of one process. */
void perturbation_add(struct march_state *st, enum perturbation_shape shape, double height,
                      double amplitude)
{
    const struct grid *g = &st->g, *whole = march_global_grid(st);
    const int *lo = st->ranks ? st->ranks->dc.lo : (const int[3]){0, 0, 0};
    double umax = 0.0;
    for (int pass = 0; pass < 2; pass++) {
        double scale = 0.0;
        if (pass == 1) {
            umax = march_max(st, umax);
            if (!(umax > 0.0))
                return;
            scale = amplitude / umax;
        }
        for (int j = 0; j < g->n[1]; j++)
            for (int i = 0; i < g->n[0]; i++)
                for (int k = 0; k < g->n[2]; k++) {
                    double v[3];
                    curl(whole, shape, height, lo[0] + i, lo[1] + j, lo[2] + k, v);
                    if (pass == 0) {
                        umax = fmax(umax, fmax(fabs(v[0]), fmax(fabs(v[1]), fabs(v[2]))));
                    } else {
                        ptrdiff_t p = grid_idx(g, i, j, k);
                        st->field.velocity[0][p] += scale * v[0];
                        if (shape == PERTURB_3D)
                            st->field.velocity[1][p] += scale * v[1];
                        st->field.velocity[2][p] += scale * v[2];
                    }
                }
    }
}
