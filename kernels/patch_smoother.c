/* The edge-patch smoother of the grad-div augmented operator
 * (kernels/patch_smoother.h). */
#include "kernels/patch_smoother.h"
#include "kernels/kernels.h"

#include <math.h>

/* idx wrapped along the periodic directions; 1 when it is then an unknown of
 * the box act_c (its slot in *p). */
static inline int face_at(const struct grid *g, const int periodic[3], const struct box *act_c,
                          int idx[3], ptrdiff_t *p)
{
    for (int d = 0; d < 3; d++) {
        if (periodic[d]) {
            const int n = g->n[d];
            idx[d] = idx[d] < 0 ? idx[d] + n : idx[d] >= n ? idx[d] - n : idx[d];
        }
        if (idx[d] < act_c->lo[d] || idx[d] >= act_c->hi[d])
            return 0;
    }
    *p = grid_idx(g, idx[0], idx[1], idx[2]);
    return 1;
}

/* One coupling of a row: the face (component, wrapped index) and its
 * coefficient in (A x)_row. */
struct coupling {
    int c;
    int idx[3];
    ptrdiff_t p;
    double coef;
};

/* The couplings of face idx (slot p) of component c to the other faces:
 * the own stencil's neighbours (-cp, -cm) and, for each other component b,
 * the four b-faces of the shear's transpose part and the augmentation,
 *   (A x)_c += sum_{b != c} [-(Ae[p+ob] + r[p]) x_b(idx+e_b)
 *                           + (Ae[p+ob] + r[p-oc]) x_b(idx+e_b-e_c)
 *                           + (Ae[p] + r[p]) x_b(idx) - (Ae[p] + r[p-oc]) x_b(idx-e_c)]
 *                         / (h_c h_b),
 * Ae the edge coefficients of the plane (c, b) (kernels/stress.c's
 * differences, and -grad(r div x)).  Faces that are not unknowns (0 on the
 * closed faces) are left out.  Returns the count (at most 14). */
static int row_couplings(const struct grid *g, const int periodic[3], const struct box act[3],
                         const struct patch_operator *op, int c, const int idx[3], ptrdiff_t p,
                         struct coupling out[14])
{
    int m = 0;
    const struct own_stencil *s = &op->st[c];
    for (int d = 0; d < 3; d++)
        for (int side = 0; side < 2; side++) {
            double k = side ? s->cp[d][p] : s->cm[d][p];
            if (k == 0.0)
                continue;
            struct coupling *q = &out[m];
            for (int e = 0; e < 3; e++)
                q->idx[e] = idx[e];
            q->idx[d] += side ? 1 : -1;
            if (!face_at(g, periodic, &act[c], q->idx, &q->p))
                continue;
            q->c = c;
            q->coef = -k;
            m++;
        }
    const ptrdiff_t oc = g->stride[c];
    const double *r = op->aug;
    for (int b = 0; b < 3; b++) {
        if (b == c)
            continue;
        const ptrdiff_t ob = g->stride[b];
        const double *Ae = op->A_edge[3 - c - b];
        const double k = 1.0 / (g->h[c] * g->h[b]);
        const double up = Ae[p + ob], dn = Ae[p];
        const double rp = r ? r[p] : 0.0, rm = r ? r[p - oc] : 0.0;
        const int db[4] = {1, 1, 0, 0}, dc[4] = {0, -1, 0, -1};
        const double coef[4] = {-(up + rp) * k, (up + rm) * k, (dn + rp) * k, -(dn + rm) * k};
        for (int t = 0; t < 4; t++) {
            struct coupling *q = &out[m];
            for (int e = 0; e < 3; e++)
                q->idx[e] = idx[e];
            q->idx[b] += db[t];
            q->idx[c] += dc[t];
            if (!face_at(g, periodic, &act[b], q->idx, &q->p))
                continue;
            q->c = b;
            q->coef = coef[t];
            m++;
        }
    }
    return m;
}

/* (A x) at a face whose couplings wrap no periodic seam: every neighbour
 * read at its plain slot (a coupling to a face that is not an unknown is 0
 * in the own stencil; the cross couplings' faces that are not unknowns are
 * closed faces, which hold 0). */
static inline double row_direct(const struct grid *g, const struct patch_operator *op, int c,
                                ptrdiff_t p, double *const x[3], const double ih[3])
{
    const struct own_stencil *s = &op->st[c];
    const double *xc = x[c];
    double y = s->diag[p] * xc[p];
    for (int d = 0; d < 3; d++) {
        const ptrdiff_t od = g->stride[d];
        y -= s->cp[d][p] * xc[p + od] + s->cm[d][p] * xc[p - od];
    }
    const ptrdiff_t oc = g->stride[c];
    const double *r = op->aug;
    const double rp = r ? r[p] : 0.0, rm = r ? r[p - oc] : 0.0;
    for (int b = 0; b < 3; b++) {
        if (b == c || (op->skip >> b & 1))
            continue;
        const ptrdiff_t ob = g->stride[b];
        const double *Ae = op->A_edge[3 - c - b], *xb = x[b];
        const double up = Ae[p + ob], dn = Ae[p];
        y += ((up + rm) * xb[p + ob - oc] - (up + rp) * xb[p + ob] + (dn + rp) * xb[p] -
              (dn + rm) * xb[p - oc]) *
             (ih[c] * ih[b]);
    }
    return y;
}

/* 1 when face idx may couple across a periodic seam (a direction of more
 * than one slot: a compact one's neighbours are the node itself). */
static inline int near_seam(const struct grid *g, const int periodic[3], const int idx[3])
{
    for (int d = 0; d < 3; d++)
        if (periodic[d] && !grid_compact(g, d) && (idx[d] <= 0 || idx[d] >= g->n[d] - 1))
            return 1;
    return 0;
}

double kernel_patch_row(const struct grid *g, const int periodic[3], const struct box act[3],
                        const struct patch_operator *op, int c, const int idx[3],
                        double *const x[3])
{
    const ptrdiff_t p = grid_idx(g, idx[0], idx[1], idx[2]);
    if (!near_seam(g, periodic, idx)) {
        const double ih[3] = {1.0 / g->h[0], 1.0 / g->h[1], 1.0 / g->h[2]};
        return row_direct(g, op, c, p, x, ih);
    }
    struct coupling q[14];
    int m = row_couplings(g, periodic, act, op, c, idx, p, q);
    double y = op->st[c].diag[p] * x[c][p];
    for (int t = 0; t < m; t++)
        y += q[t].coef * x[q[t].c][q[t].p];
    return y;
}

int kernel_patch_plane_ok(const struct grid *g, const struct boundary *bc, int n)
{
    for (int d = 0; d < 3; d++)
        for (int side = 0; side < 2; side++)
            if (bc->face[d][side] == BC_OPEN)
                return 0;
    for (int d = 0; d < 3; d++) {
        if (d == n)
            continue;
        int periodic = bc->face[d][0] == BC_PERIODIC;
        if (g->n[d] < (periodic ? 3 : 2))
            return 0;
    }
    return 1;
}

/* The plane's in-plane directions a < b. */
static void plane_dirs(int n, int *a, int *b)
{
    *a = n == 0 ? 1 : 0;
    *b = n == 2 ? 1 : 2;
}

/* The four faces of the patch at edge idx: their components, slots and
 * presence (an absent face is an identity row). */
struct patch {
    int c[4];
    int idx[4][3];
    ptrdiff_t p[4];
    int on[4];
};

static void patch_faces(const struct grid *g, const int periodic[3], const struct box act[3],
                        int a, int b, const int idx[3], struct patch *pt)
{
    const int comp[4] = {a, a, b, b};
    for (int f = 0; f < 4; f++) {
        pt->c[f] = comp[f];
        for (int e = 0; e < 3; e++)
            pt->idx[f][e] = idx[e];
    }
    pt->idx[1][b] -= 1;
    pt->idx[3][a] -= 1;
    for (int f = 0; f < 4; f++)
        pt->on[f] = face_at(g, periodic, &act[pt->c[f]], pt->idx[f], &pt->p[f]);
}

static inline int same_face(const struct coupling *q, const struct patch *pt, int f)
{
    return pt->on[f] && q->c == pt->c[f] && q->p == pt->p[f];
}

/* Packed lower triangle: (i, j), j <= i, at i (i + 1) / 2 + j. */
#define LT(i, j) ((i) * ((i) + 1) / 2 + (j))

/* The patch's block factorised into L (packed); returns 1 on a
 * non-positive pivot (replaced by the diagonal's scale). */
static int patch_block(const struct grid *g, const int periodic[3], const struct box act[3],
                       const struct patch_operator *op, const struct patch *pt, double *L)
{
    double M[4][4] = {{0.0}};
    for (int f = 0; f < 4; f++) {
        if (!pt->on[f]) {
            M[f][f] = 1.0;
            continue;
        }
        struct coupling q[14];
        int m = row_couplings(g, periodic, act, op, pt->c[f], pt->idx[f], pt->p[f], q);
        M[f][f] = op->st[pt->c[f]].diag[pt->p[f]];
        for (int t = 0; t < m; t++)
            for (int h = 0; h < 4; h++)
                if (h != f && same_face(&q[t], pt, h))
                    M[f][h] += q[t].coef;
    }
    int bad = 0;
    for (int i = 0; i < 4; i++) {
        for (int j = 0; j <= i; j++) {
            double s = 0.5 * (M[i][j] + M[j][i]);
            for (int k = 0; k < j; k++)
                s -= L[LT(i, k)] * L[LT(j, k)];
            if (i == j) {
                if (!(s > 1e-14 * fabs(M[i][i]))) {
                    bad = 1;
                    s = fabs(M[i][i]) > 0.0 ? fabs(M[i][i]) : 1.0;
                }
                L[LT(i, i)] = 1.0 / sqrt(s); /* the reciprocal: no division in the sweeps */
            } else {
                L[LT(i, j)] = s * L[LT(j, j)];
            }
        }
    }
    return bad;
}

/* The colours along one direction: stride s apart; a periodic direction
 * whose length is not a multiple of s gives its last n mod s patches a
 * colour each, so that no colour meets itself across the seam. */
struct colour_run {
    int start, step, count;
};

static int colours_along(int lo, int hi, int s, int periodic)
{
    int len = hi - lo;
    return len <= 0 ? 0 : len < s ? len : s + (periodic ? len % s : 0);
}

static struct colour_run colour_run(int lo, int hi, int s, int periodic, int k)
{
    int len = hi - lo, full = periodic ? s * (len / s) : len;
    struct colour_run r;
    if (len < s) { /* a colour each */
        r.start = lo + k;
        r.step = 1;
        r.count = 1;
    } else if (k < s) {
        r.start = lo + k;
        r.step = s;
        r.count = full > k ? (full - k + s - 1) / s : 0;
    } else {
        r.start = lo + full + (k - s);
        r.step = 1;
        r.count = 1;
    }
    return r;
}

/* The edges' index ranges of the plane normal to n: along a and b the
 * in-plane components' own faces, along n their common cells. */
static void edge_range(const struct box act[3], int n, int a, int b, int lo[3], int hi[3])
{
    lo[a] = act[a].lo[a];
    hi[a] = act[a].hi[a];
    lo[b] = act[b].lo[b];
    hi[b] = act[b].hi[b];
    lo[n] = act[a].lo[n] > act[b].lo[n] ? act[a].lo[n] : act[b].lo[n];
    hi[n] = act[a].hi[n] < act[b].hi[n] ? act[a].hi[n] : act[b].hi[n];
}

long kernel_patch_factor(const struct grid *g, const int periodic[3], const struct box act[3],
                         int n, const struct patch_operator *op, double *fac)
{
    int a, b, lo[3], hi[3];
    plane_dirs(n, &a, &b);
    edge_range(act, n, a, b, lo, hi);
    long bad = 0;
#pragma omp parallel for collapse(2) schedule(static) reduction(+ : bad) if (kernel_parallel(g))
    for (int i = lo[0]; i < hi[0]; i++)
        for (int j = lo[1]; j < hi[1]; j++)
            for (int k = lo[2]; k < hi[2]; k++) {
                const int idx[3] = {i, j, k};
                struct patch pt;
                patch_faces(g, periodic, act, a, b, idx, &pt);
                bad += patch_block(g, periodic, act, op, &pt, &fac[PATCH_FACTOR * grid_idx(g, i, j, k)]);
            }
    return bad;
}

/* The block's solution of y in place (L L^T d = y). */
static inline void block_solve(const double *L, double y[4])
{
    for (int i = 0; i < 4; i++) {
        double s = y[i];
        for (int k = 0; k < i; k++)
            s -= L[LT(i, k)] * y[k];
        y[i] = s * L[LT(i, i)];
    }
    for (int i = 3; i >= 0; i--) {
        double s = y[i];
        for (int k = i + 1; k < 4; k++)
            s -= L[LT(k, i)] * y[k];
        y[i] = s * L[LT(i, i)];
    }
}

/* One patch: its residual, the block's solution, the faces corrected. */
static inline void patch_solve(const struct grid *g, const int periodic[3], const struct box act[3],
                               const struct patch_operator *op, const double *L,
                               double *const b[3], double *x[3], const struct patch *pt)
{
    double y[4];
    for (int f = 0; f < 4; f++)
        y[f] = pt->on[f] ? b[pt->c[f]][pt->p[f]] -
                               kernel_patch_row(g, periodic, act, op, pt->c[f], pt->idx[f], x)
                         : 0.0;
    block_solve(L, y);
    for (int f = 0; f < 4; f++)
        if (pt->on[f])
            x[pt->c[f]][pt->p[f]] += y[f];
}


/* 1 when the patch at edge idx has its four faces and neither they nor
 * their rows' neighbours wrap a periodic seam: its slots are plain offsets
 * and its rows row_direct's. */
static inline int patch_plain(const struct grid *g, const int periodic[3], const struct box act[3],
                              int a, int b, const int idx[3])
{
    for (int d = 0; d < 3; d++)
        if (periodic[d] && !grid_compact(g, d) && (idx[d] < 2 || idx[d] > g->n[d] - 3))
            return 0;
    int lo_a[3] = {idx[0], idx[1], idx[2]}, lo_b[3] = {idx[0], idx[1], idx[2]};
    lo_a[b] -= 1;
    lo_b[a] -= 1;
    return box_holds(&act[a], idx[0], idx[1], idx[2]) &&
           box_holds(&act[a], lo_a[0], lo_a[1], lo_a[2]) &&
           box_holds(&act[b], idx[0], idx[1], idx[2]) &&
           box_holds(&act[b], lo_b[0], lo_b[1], lo_b[2]);
}

static inline void patch_solve_plain(const struct grid *g, const struct patch_operator *op,
                                     const double *L, double *const b[3], double *x[3], int a,
                                     int bb, ptrdiff_t p0, const double ih[3])
{
    const ptrdiff_t pf[4] = {p0, p0 - g->stride[bb], p0, p0 - g->stride[a]};
    const int cf[4] = {a, a, bb, bb};
    double y[4];
    for (int f = 0; f < 4; f++)
        y[f] = b[cf[f]][pf[f]] - row_direct(g, op, cf[f], pf[f], x, ih);
    block_solve(L, y);
    for (int f = 0; f < 4; f++)
        x[cf[f]][pf[f]] += y[f];
}

void kernel_patch_sweep(const struct grid *g, const int periodic[3], const struct box act[3],
                        int n, const struct patch_operator *op, const double *fac,
                        double *const b[3], double *x[3], int reverse)
{
    int a, bb, lo[3], hi[3], stride[3], nc[3];
    plane_dirs(n, &a, &bb);
    edge_range(act, n, a, bb, lo, hi);
    /* patches three apart along a and b, two along n, share no coupling:
     * a patch's faces reach one index beyond its own */
    stride[a] = stride[bb] = 3;
    stride[n] = 2;
    for (int d = 0; d < 3; d++)
        nc[d] = colours_along(lo[d], hi[d], stride[d], periodic[d]);
    const int ncol = nc[0] * nc[1] * nc[2];
    const double ih[3] = {1.0 / g->h[0], 1.0 / g->h[1], 1.0 / g->h[2]};
    for (int t = 0; t < ncol; t++) {
        const int col = reverse ? ncol - 1 - t : t;
        const int k0 = col % nc[0], k1 = col / nc[0] % nc[1], k2 = col / (nc[0] * nc[1]);
        const struct colour_run r0 = colour_run(lo[0], hi[0], stride[0], periodic[0], k0),
                                r1 = colour_run(lo[1], hi[1], stride[1], periodic[1], k1),
                                r2 = colour_run(lo[2], hi[2], stride[2], periodic[2], k2);
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
        for (int u = 0; u < r0.count; u++)
            for (int v = 0; v < r1.count; v++)
                for (int w = 0; w < r2.count; w++) {
                    const int idx[3] = {r0.start + u * r0.step, r1.start + v * r1.step,
                                        r2.start + w * r2.step};
                    const ptrdiff_t p0 = grid_idx(g, idx[0], idx[1], idx[2]);
                    if (patch_plain(g, periodic, act, a, bb, idx)) {
                        patch_solve_plain(g, op, &fac[PATCH_FACTOR * p0], b, x, a, bb, p0, ih);
                        continue;
                    }
                    struct patch pt;
                    patch_faces(g, periodic, act, a, bb, idx, &pt);
                    patch_solve(g, periodic, act, op, &fac[PATCH_FACTOR * p0], b, x, &pt);
                }
    }
}
