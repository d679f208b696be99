/* Transfers between the velocity multigrid's levels (kernels/mac_transfer.h). */
#include "kernels/mac_transfer.h"
#include "kernels/kernels.h"

/* A coarse node of one direction and its weight. */
struct tap {
    int at;
    double w;
};

/* The coarse nodes fine index i of direction d draws on, folded by the
 * boundary rules: at most two taps, their count returned. */
static int taps_1d(const struct grid *coarse, const struct boundary *bc, int coarsened, int a,
                   int d, int i, double w2, struct tap t[2])
{
    if (!coarsened) {
        t[0] = (struct tap){i, 1.0};
        return 1;
    }
    struct tap raw[2];
    int nraw;
    if (d == a) { /* faces */
        if (!(i & 1)) {
            raw[0] = (struct tap){i / 2, 1.0};
            nraw = 1;
        } else {
            raw[0] = (struct tap){(i - 1) / 2, 1.0 - w2};
            raw[1] = (struct tap){(i + 1) / 2, w2};
            nraw = 2;
        }
    } else { /* cells */
        int I = i >> 1;
        raw[0] = (struct tap){I, 1.0 - w2};
        raw[1] = (struct tap){(i & 1) ? I + 1 : I - 1, w2};
        nraw = 2;
    }
    const int n = coarse->n[d];
    const int periodic = bc_wraps(bc, d);
    int m = 0;
    for (int r = 0; r < nraw; r++) {
        int I = raw[r].at;
        double w = raw[r].w;
        /* past a rank border: the neighbour's node in the ghost slot (a
         * face along a on the low border, face 0, is this rank's) */
        const int side = d == a ? (I >= n ? 1 : I <= 0 ? 0 : -1) : (I >= n ? 1 : I < 0 ? 0 : -1);
        if (side >= 0 && bc_border(bc, d, side)) {
            t[m++] = (struct tap){I, w};
            continue;
        }
        if (periodic) {
            I = I < 0 ? I + n : I >= n ? I - n : I;
        } else if (d == a) {
            if (I <= 0 || I >= n) { /* a boundary face: closed, or an open one's inner face */
                int side = I <= 0 ? 0 : 1;
                if (bc->face[d][side] != BC_OPEN || n < 2)
                    continue;
                I = side ? n - 1 : 1;
            }
        } else if (I < 0 || I >= n) { /* a ghost cell: the mirror, signed */
            int side = I < 0 ? 0 : 1;
            enum bc_kind k = bc->face[d][side];
            if (k == BC_WALL || k == BC_LID || k == BC_INFLOW)
                w = -w;
            I = side ? n - 1 : 0;
        }
        t[m++] = (struct tap){I, w};
    }
    return m;
}

void kernel_prolong_velocity(const struct grid *fine, const struct grid *coarse,
                             const struct boundary *bc, const int f[3], int a,
                             const struct box *act_f, const struct box *act_c,
                             double *const w[3], const double *y, double *x)
{
    (void)act_c;
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(fine))
    for (int i = act_f->lo[0]; i < act_f->hi[0]; i++)
        for (int j = act_f->lo[1]; j < act_f->hi[1]; j++) {
            struct tap ti[2], tj[2], tk[2];
            for (int k = act_f->lo[2]; k < act_f->hi[2]; k++) {
                const ptrdiff_t p = grid_idx(fine, i, j, k);
                int ni = taps_1d(coarse, bc, f[0] == 2, a, 0, i, w[0][p], ti);
                int nj = taps_1d(coarse, bc, f[1] == 2, a, 1, j, w[1][p], tj);
                int nk = taps_1d(coarse, bc, f[2] == 2, a, 2, k, w[2][p], tk);
                double s = 0.0;
                for (int u = 0; u < ni; u++)
                    for (int v = 0; v < nj; v++) {
                        double wuv = ti[u].w * tj[v].w;
                        for (int w = 0; w < nk; w++)
                            s += wuv * tk[w].w * y[grid_idx(coarse, ti[u].at, tj[v].at, tk[w].at)];
                    }
                x[p] += s;
            }
        }
}

/* The contributions of the fine nodes of x-index i to the coarse nodes
 * they draw on, scattered into y. */
static void restrict_row(const struct grid *fine, const struct grid *coarse,
                         const struct boundary *bc, const int f[3], int a, const struct box *act_f,
                         double *const w[3], const double *x, double *y, int i)
{
    for (int j = act_f->lo[1]; j < act_f->hi[1]; j++)
        for (int k = act_f->lo[2]; k < act_f->hi[2]; k++) {
            const ptrdiff_t p = grid_idx(fine, i, j, k);
            struct tap ti[2], tj[2], tk[2];
            int ni = taps_1d(coarse, bc, f[0] == 2, a, 0, i, w[0][p], ti);
            int nj = taps_1d(coarse, bc, f[1] == 2, a, 1, j, w[1][p], tj);
            int nk = taps_1d(coarse, bc, f[2] == 2, a, 2, k, w[2][p], tk);
            const double xp = x[p];
            for (int u = 0; u < ni; u++)
                for (int v = 0; v < nj; v++) {
                    double wuv = ti[u].w * tj[v].w * xp;
                    for (int t = 0; t < nk; t++)
                        y[grid_idx(coarse, ti[u].at, tj[v].at, tk[t].at)] += wuv * tk[t].w;
                }
        }
}

void kernel_restrict_velocity(const struct grid *fine, const struct grid *coarse,
                              const struct boundary *bc, const int f[3], int a,
                              const struct box *act_f, const struct box *act_c,
                              double *const w[3], const double *x, double *y)
{
    double scale = 1.0;
    for (int d = 0; d < 3; d++)
        if (f[d] == 2)
            scale *= 0.5;
    /* the box and, past a rank border, its ghost slots (the neighbour's
     * nodes this rank's fine nodes scatter to: decomp_exchange_add) */
    struct box out = *act_c;
    for (int d = 0; d < 3; d++) {
        out.lo[d] -= bc_border(bc, d, 0);
        out.hi[d] += bc_border(bc, d, 1);
    }
    for (int I = out.lo[0]; I < out.hi[0]; I++)
        for (int J = out.lo[1]; J < out.hi[1]; J++)
            for (int K = out.lo[2]; K < out.hi[2]; K++)
                y[grid_idx(coarse, I, J, K)] = 0.0;
    /* a scatter (the transpose of the gather P): the fine rows of x-index i
     * write the coarse rows of x-index I - 1 .. I + 1 around their home I,
     * so the rows of one home run in one thread and homes three apart in
     * parallel; the two homes at either end, which a periodic wrap joins,
     * run serially after them */
    const int step = f[0] == 2 ? 2 : 1, homes = coarse->n[0] + 1;
    for (int colour = 0; colour < 3; colour++) {
#pragma omp parallel for schedule(static) if (kernel_parallel(fine))
        for (int home = 2 + colour; home < homes - 2; home += 3)
            for (int t = 0; t < step; t++) {
                int i = home * step + t;
                if (i >= act_f->lo[0] && i < act_f->hi[0])
                    restrict_row(fine, coarse, bc, f, a, act_f, w, x, y, i);
            }
    }
    for (int home = 0; home < homes; home++) {
        if (home >= 2 && home < homes - 2)
            continue;
        for (int t = 0; t < step; t++) {
            int i = home * step + t;
            if (i >= act_f->lo[0] && i < act_f->hi[0])
                restrict_row(fine, coarse, bc, f, a, act_f, w, x, y, i);
        }
    }
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(coarse))
    for (int I = out.lo[0]; I < out.hi[0]; I++)
        for (int J = out.lo[1]; J < out.hi[1]; J++)
            for (int K = out.lo[2]; K < out.hi[2]; K++)
                y[grid_idx(coarse, I, J, K)] *= scale;
}

/* The conductance of the coupling of component a between the node at p and
 * its neighbour at +e_d: what the own stencil's coupling is before the
 * grid spacing (kernels/viscous_stencil.c). */
static inline double conductance(const struct grid *g, int a, int d, ptrdiff_t p,
                                 const double *const A_cell[3], const double *const A_edge[3],
                                 const double *aug)
{
    if (d == a)
        return 2.0 * A_cell[a][p] + (aug ? aug[p] : 0.0);
    return A_edge[3 - a - d][p + g->stride[d]];
}

void kernel_prolong_weights(const struct grid *fine, const struct boundary *bc, const int f[3],
                            int a, const struct box *act_f, const double *const A_cell[3],
                            const double *const A_edge[3], const double *aug, int linear,
                            double *w[3])
{
    for (int d = 0; d < 3; d++) {
        if (f[d] != 2)
            continue;
        const int n = fine->n[d], periodic = bc_wraps(bc, d);
        const ptrdiff_t sd = fine->stride[d];
        double *wd = w[d];
        /* past a low rank border, the cells' ghost -1 too: the low
         * neighbour's last cell, whose weight reads a coefficient two cells
         * beyond that rank's block (the solver hands it over) */
        struct box bx = *act_f;
        bx.lo[d] -= d != a && bc_border(bc, d, 0);
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(fine))
        for (int i = bx.lo[0]; i < bx.hi[0]; i++)
            for (int j = bx.lo[1]; j < bx.hi[1]; j++)
                for (int k = bx.lo[2]; k < bx.hi[2]; k++) {
                    const int idx[3] = {i, j, k};
                    const int t = idx[d];
                    const ptrdiff_t p = grid_idx(fine, i, j, k);
                    if (d == a) { /* faces: the odd face between two coarse faces */
                        double val = 0.5;
                        if (!linear && (t & 1)) {
                            double up = conductance(fine, a, d, p, A_cell, A_edge, aug);
                            double dn = conductance(fine, a, d, p - sd, A_cell, A_edge, aug);
                            if (up > 0.0 && dn > 0.0)
                                val = up / (up + dn);
                        }
                        wd[p] = val;
                        continue;
                    }
                    /* cells: the conductances of the own face (to the sibling),
                     * the coarse face and the far face (the neighbour's inner
                     * one), as series resistances (multigrid.c's flux weights) */
                    int own, cross, far, outside;
                    if (t & 1) {
                        own = t, cross = t + 1, far = t + 2;
                        outside = t + 1 >= n;
                    } else {
                        own = t + 1, cross = t, far = t - 1;
                        outside = t == 0;
                    }
                    double val = linear == 2 ? 0.0 : 0.25;
                    if (!linear && !(outside && !periodic)) {
                        /* the face of index q lies between cells q - 1 and q */
                        int q[3] = {own, cross, far};
                        double kf[3];
                        for (int s = 0; s < 3; s++) {
                            int c = q[s] - 1; /* the cell below the face */
                            if (periodic)
                                c = c < 0 ? c + n : c >= n ? c - n : c;
                            kf[s] = conductance(fine, a, d, p + (ptrdiff_t)(c - t) * sd, A_cell,
                                                A_edge, aug);
                        }
                        if (kf[0] > 0.0 && kf[1] > 0.0 && kf[2] > 0.0) {
                            double ra = 0.5 / kf[0], rb = 1.0 / kf[1] + 0.5 / kf[2];
                            val = ra / (ra + rb);
                        }
                    }
                    wd[p] = val;
                }
    }
}


void kernel_coarsen_cells(const struct grid *fine, const struct grid *coarse, const int f[3],
                          int harmonic, const double *x, double *y)
{
    const double share = 1.0 / (f[0] * f[1] * f[2]);
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(coarse))
    for (int I = 0; I < coarse->n[0]; I++)
        for (int J = 0; J < coarse->n[1]; J++)
            for (int K = 0; K < coarse->n[2]; K++) {
                double s = 0.0;
                int zero = 0;
                for (int u = 0; u < f[0]; u++)
                    for (int v = 0; v < f[1]; v++)
                        for (int w = 0; w < f[2]; w++) {
                            double a = x[grid_idx(fine, f[0] * I + u, f[1] * J + v, f[2] * K + w)];
                            zero |= a == 0.0;
                            s += harmonic ? (a != 0.0 ? 1.0 / a : 0.0) : a;
                        }
                y[grid_idx(coarse, I, J, K)] =
                    harmonic ? (zero ? 0.0 : 1.0 / (share * s)) : share * s;
            }
}

void kernel_coarsen_faces(const struct grid *fine, const struct grid *coarse, const int f[3],
                          int a, const double *x, double *y)
{
    int g[3] = {f[0], f[1], f[2]}; /* children per direction: one along a */
    g[a] = 1;
    const double share = 1.0 / (g[0] * g[1] * g[2]);
    int hi[3] = {coarse->n[0], coarse->n[1], coarse->n[2]};
    hi[a] = grid_slot_hi(coarse, a) + 1; /* faces 0..n, one slot when compact */
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(coarse))
    for (int I = 0; I < hi[0]; I++)
        for (int J = 0; J < hi[1]; J++)
            for (int K = 0; K < hi[2]; K++) {
                const int c[3] = {I, J, K};
                int b[3];
                for (int d = 0; d < 3; d++)
                    b[d] = f[d] * c[d];
                double s = 0.0;
                for (int u = 0; u < g[0]; u++)
                    for (int v = 0; v < g[1]; v++)
                        for (int w = 0; w < g[2]; w++)
                            s += x[grid_idx(fine, b[0] + u, b[1] + v, b[2] + w)];
                y[grid_idx(coarse, I, J, K)] = share * s;
            }
}

void kernel_coarsen_edges(const struct grid *fine, const struct grid *coarse, const int f[3],
                          int k, const double *x, double *y)
{
    int hi[3] = {grid_slot_hi(coarse, 0) + 1, grid_slot_hi(coarse, 1) + 1, grid_slot_hi(coarse, 2) + 1};
    hi[k] = coarse->n[k]; /* cells along the edge, faces across (one slot when compact) */
    const double share = 1.0 / f[k];
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(coarse))
    for (int I = 0; I < hi[0]; I++)
        for (int J = 0; J < hi[1]; J++)
            for (int K = 0; K < hi[2]; K++) {
                const int c[3] = {I, J, K};
                int b[3];
                for (int d = 0; d < 3; d++)
                    b[d] = f[d] * c[d];
                double s = 0.0;
                for (int u = 0; u < f[k]; u++) {
                    int q[3] = {b[0], b[1], b[2]};
                    q[k] += u;
                    s += x[grid_idx(fine, q[0], q[1], q[2])];
                }
                y[grid_idx(coarse, I, J, K)] = share * s;
            }
}
