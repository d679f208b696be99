/* The own-component stencil of the implicit viscous operator and line
 * Gauss-Seidel on it (kernels/viscous_stencil.h). */
#include "kernels/viscous_stencil.h"
#include "kernels/kernels.h"


/* What the ghost beyond face or cell index j (j = -1 or n) of direction d
 * holds for component a, as a multiple of node P's value: the sign s of
 * the mirror for a tangential component (wall, lid, inflow -1; slip,
 * surface, open +1), 1 for the inner face an open face copies, 0 for a
 * closed face's prescribed zero.  A periodic direction never asks. */
static double ghost_share(const struct boundary *bc, int a, int d, int side)
{
    enum bc_kind kind = bc->face[d][side];
    if (a == d)
        return kind == BC_OPEN ? 1.0 : 0.0;
    return kind == BC_WALL || kind == BC_LID || kind == BC_INFLOW ? -1.0 : 1.0;
}

/* The index of the neighbour of j along d at step +1 or -1, wrapped on a
 * periodic direction; -1 when it is not an unknown (a boundary face or a
 * ghost: the caller folds it). */
static inline int neighbour(const struct grid *g, const struct box *act, int periodic, int d,
                            int j, int step)
{
    int q = j + step;
    if (periodic) {
        int n = g->n[d];
        return q < 0 ? q + n : q >= n ? q - n : q;
    }
    return q >= act->lo[d] && q < act->hi[d] ? q : -1;
}

void kernel_own_stencil(const struct grid *g, const struct boundary *bc, const struct box *act_a,
                        int a, const struct stencil_coefficients *k, struct own_stencil *out)
{
    int periodic[3]; /* wrapping here: a direction split over ranks wraps through them */
    for (int d = 0; d < 3; d++)
        periodic[d] = bc_wraps(bc, d);
    const ptrdiff_t *o = g->stride;
    const double *cut = k->e ? k->e->cut : NULL;
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
    for (int i = act_a->lo[0]; i < act_a->hi[0]; i++)
        for (int j = act_a->lo[1]; j < act_a->hi[1]; j++)
            for (int kk = act_a->lo[2]; kk < act_a->hi[2]; kk++) {
                const int idx[3] = {i, j, kk};
                const ptrdiff_t p = grid_idx(g, i, j, kk);
                double m = k->mass_face ? k->mass_face[p] : k->mass;
                if (k->held && k->held[p]) {
                    out->diag[p] = m;
                    for (int d = 0; d < 3; d++)
                        out->cp[d][p] = out->cm[d][p] = 0.0;
                    continue;
                }
                double diag = m;
                for (int d = 0; d < 3; d++) {
                    const int jd = idx[d];
                    double up, down;
                    if (d == a) {
                        /* normal stress (and the augmentation, and a body's
                         * cut-cell grad-div) between the cells above and below */
                        double hf = grid_hf(g, d, jd), hp = grid_hc(g, d, jd),
                               hm = grid_hc(g, d, jd - 1);
                        double cu = 2.0 * k->A_cell[a][p], cd = 2.0 * k->A_cell[a][p - o[d]];
                        if (k->aug) {
                            cu += k->aug[p];
                            cd += k->aug[p - o[d]];
                        }
                        if (cut) {
                            cu -= k->A_cell[0][p] * cut[p];
                            cd -= k->A_cell[0][p - o[d]] * cut[p - o[d]];
                        }
                        up = cu / (hp * hf);
                        down = cd / (hm * hf);
                    } else {
                        /* shear stress on the edges above and below */
                        const double *Ae = k->A_edge[3 - a - d];
                        double hc = grid_hc(g, d, jd);
                        up = Ae[p + o[d]] / (grid_hf(g, d, jd + 1) * hc);
                        down = Ae[p] / (grid_hf(g, d, jd) * hc);
                    }
                    diag += up + down;
                    for (int side = 0; side < 2; side++) {
                        double c = side ? up : down;
                        int q = neighbour(g, act_a, periodic[d], d, jd, side ? 1 : -1);
                        double *cout = side ? &out->cp[d][p] : &out->cm[d][p];
                        *cout = 0.0;
                        if (q < 0 && bc_border(bc, d, side)) {
                            /* a rank border's ghost: the neighbour's unknown
                             * (a held one read as 0) */
                            const ptrdiff_t pg = p + (side ? o[d] : -o[d]);
                            *cout = k->held && k->held[pg] ? 0.0 : c;
                            continue;
                        }
                        if (q < 0) {
                            /* a boundary face or a ghost: its value is a share
                             * of v_P, so c (v_P - v_Q) moves into diag */
                            diag -= c * ghost_share(bc, a, d, side);
                            continue;
                        }
                        if (q == jd) { /* one node around a periodic direction */
                            diag -= c;
                            continue;
                        }
                        ptrdiff_t pq = p + (ptrdiff_t)(q - jd) * o[d];
                        if (k->held && k->held[pq])
                            continue; /* held at 0 */
                        *cout = c;
                    }
                }
                out->diag[p] = diag;
            }
    if (!k->e)
        return;
    /* cut links: diagonal (kernels/embedded.h); serial, a node may have several */
    for (long l = 0; l < k->e->nlinks; l++) {
        const struct embedded_link *ln = &k->e->links[l];
        if (ln->c != a)
            continue;
        double A = ln->coef < 3 ? k->A_cell[ln->coef][ln->at] : k->A_edge[ln->coef - 3][ln->at];
        out->diag[ln->p] += A * ln->w;
    }
}

/* The offset from a node of the line at index u of direction d to its
 * neighbour at step, wrapped around a periodic direction.  Non-periodic
 * neighbours outside the box have coupling 0 and their slots (ghosts or
 * boundary faces) hold finite values, so the product is read as it is. */
static inline ptrdiff_t across_offset(const struct grid *g, const int periodic[3], int d, int u,
                                      int step)
{
    const int n = g->n[d];
    if (periodic[d] && ((step > 0 && u == n - 1) || (step < 0 && u == 0)))
        return -(ptrdiff_t)step * (n - 1) * g->stride[d];
    return (ptrdiff_t)step * g->stride[d];
}

void kernel_line_factor(const struct grid *g, const struct box *act_a, int L,
                        const struct own_stencil *s, struct line_factors *f)
{
    const int du = (L + 1) % 3, dw = (L + 2) % 3, n = act_a->hi[L] - act_a->lo[L];
    const ptrdiff_t oL = g->stride[L];
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
    for (int u = act_a->lo[du]; u < act_a->hi[du]; u++)
        for (int w = act_a->lo[dw]; w < act_a->hi[dw]; w++) {
            int idx[3];
            idx[du] = u;
            idx[dw] = w;
            idx[L] = act_a->lo[L];
            ptrdiff_t p = grid_idx(g, idx[0], idx[1], idx[2]);
            double prev_c = 0.0;
            for (int m = 0; m < n; m++, p += oL) {
                /* row m: -cm v_{m-1} + diag v_m - cp v_{m+1} */
                double a = m > 0 ? -s->cm[L][p] : 0.0;
                double b = s->diag[p] - a * prev_c;
                double c = m + 1 < n ? -s->cp[L][p] : 0.0;
                f->inv_b[p] = 1.0 / b;
                f->cprime[p] = prev_c = c / b;
            }
        }
}

/* Solves the line of nodes (idx with idx[L] over the box) for d: its
 * right-hand side r plus the couplings to the neighbouring lines' d. */
static void solve_line(const struct grid *g, const int periodic[3], const struct box *act, int L,
                       const struct own_stencil *s, const struct line_factors *f,
                       const double *r, double *d, int u, int w, int du, int dw)
{
    const int lo = act->lo[L], n = act->hi[L] - lo;
    int idx[3];
    idx[du] = u;
    idx[dw] = w;
    idx[L] = lo;
    const ptrdiff_t p0 = grid_idx(g, idx[0], idx[1], idx[2]), oL = g->stride[L];
    const ptrdiff_t uu = across_offset(g, periodic, du, u, 1),
                    um = across_offset(g, periodic, du, u, -1),
                    wu = across_offset(g, periodic, dw, w, 1),
                    wm = across_offset(g, periodic, dw, w, -1);
    const double *restrict inv_b = f->inv_b, *restrict cprime = f->cprime,
                           *restrict cmL = s->cm[L];
    const double *restrict cpu = s->cp[du], *restrict cmu = s->cm[du];
    const double *restrict cpw = s->cp[dw], *restrict cmw = s->cm[dw];
    /* a periodic direction of one cell across: no coupling (folded in diag) */
    const int has_w = !(periodic[dw] && g->n[dw] == 1);
    double prev = 0.0;
    ptrdiff_t p = p0;
    for (int m = 0; m < n; m++, p += oL) {
        double rhs = r[p] + cpu[p] * d[p + uu] + cmu[p] * d[p + um];
        if (has_w)
            rhs += cpw[p] * d[p + wu] + cmw[p] * d[p + wm];
        /* forward elimination, in place: row m's lower coupling is -cm */
        prev = (rhs + (m > 0 ? cmL[p] * prev : 0.0)) * inv_b[p];
        d[p] = prev;
    }
    p -= oL;
    double x = d[p];
    for (int m = n - 2; m >= 0; m--) {
        p -= oL;
        x = d[p] - cprime[p] * x;
        d[p] = x;
    }
}

/* 1 when line (u, w) borders the seam of a periodic direction of odd
 * length across the lines (its colour would meet its own at the seam). */
static inline int on_seam(const struct grid *g, const int periodic[3], int du, int dw, int u, int w)
{
    return (periodic[du] && g->n[du] > 1 && (g->n[du] & 1) && u == g->n[du] - 1) ||
           (periodic[dw] && g->n[dw] > 1 && (g->n[dw] & 1) && w == g->n[dw] - 1);
}

/* The lines of one colour along a direction L that is not the layout's
 * fastest, all at once: the elimination runs along L in the outer loop and
 * across the lines of the fastest direction in the inner one, so that each
 * step reads memory in order (one line at a time would touch a cache line
 * per node).  Lines on a seam are left to the serial pass. */
static void solve_plane(const struct grid *g, const int periodic[3], const struct box *act, int L,
                        const struct own_stencil *s, const struct line_factors *f,
                        const double *r, double *d, int colour, int inner, int outer)
{
    const int lo = act->lo[L], n = act->hi[L] - lo;
    const ptrdiff_t oL = g->stride[L];
    const int i0 = act->lo[inner], i1 = act->hi[inner];
    const double *restrict inv_b = f->inv_b, *restrict cprime = f->cprime,
                           *restrict cmL = s->cm[L];
    const double *restrict cpi = s->cp[inner], *restrict cmi = s->cm[inner];
    const double *restrict cpo = s->cp[outer], *restrict cmo = s->cm[outer];
    const int has_o = !(periodic[outer] && g->n[outer] == 1);
    const int has_i = !(periodic[inner] && g->n[inner] == 1);
#pragma omp parallel for schedule(static) if (kernel_parallel(g))
    for (int o = act->lo[outer]; o < act->hi[outer]; o++) {
        const ptrdiff_t ou = across_offset(g, periodic, outer, o, 1),
                        om = across_offset(g, periodic, outer, o, -1);
        int start = i0 + (((i0 + o) & 1) != colour);
        int idx[3];
        idx[outer] = o;
        idx[inner] = 0;
        idx[L] = lo;
        const ptrdiff_t base = grid_idx(g, idx[0], idx[1], idx[2]);
        for (int m = 0; m < n; m++) {
            const ptrdiff_t row = base + (ptrdiff_t)m * oL;
            for (int u = start; u < i1; u += 2) {
                int seam = (periodic[inner] && g->n[inner] > 1 && (g->n[inner] & 1) &&
                            u == g->n[inner] - 1) ||
                           (periodic[outer] && g->n[outer] > 1 && (g->n[outer] & 1) &&
                            o == g->n[outer] - 1);
                if (seam)
                    continue;
                const ptrdiff_t p = row + u; /* the inner direction has stride 1 */
                double rhs = r[p];
                if (has_i)
                    rhs += cpi[p] * d[p + across_offset(g, periodic, inner, u, 1)] +
                           cmi[p] * d[p + across_offset(g, periodic, inner, u, -1)];
                if (has_o)
                    rhs += cpo[p] * d[p + ou] + cmo[p] * d[p + om];
                d[p] = (rhs + (m > 0 ? cmL[p] * d[p - oL] : 0.0)) * inv_b[p];
            }
        }
        for (int m = n - 2; m >= 0; m--) {
            const ptrdiff_t row = base + (ptrdiff_t)m * oL;
            for (int u = start; u < i1; u += 2) {
                int seam = (periodic[inner] && g->n[inner] > 1 && (g->n[inner] & 1) &&
                            u == g->n[inner] - 1) ||
                           (periodic[outer] && g->n[outer] > 1 && (g->n[outer] & 1) &&
                            o == g->n[outer] - 1);
                if (seam)
                    continue;
                const ptrdiff_t p = row + u;
                d[p] -= cprime[p] * d[p + oL];
            }
        }
    }
}

void kernel_line_gauss_seidel(const struct grid *g, const int periodic[3], const struct box *act_a,
                              int L, const struct own_stencil *s, const struct line_factors *f,
                              const double *r, double *d, int reverse)
{
    const int du = (L + 1) % 3, dw = (L + 2) % 3;
    const int u0 = act_a->lo[du], u1 = act_a->hi[du], w0 = act_a->lo[dw], w1 = act_a->hi[dw];
    const int len = act_a->hi[L] - act_a->lo[L];
    if (len <= 0 || u1 <= u0 || w1 <= w0)
        return;
    /* lines along a direction other than the fastest (z): by planes */
    const int by_planes = L != 2 && g->stride[2] == 1;
    for (int pass = 0; pass < 3; pass++) {
        const int colour = reverse ? 2 - pass : pass;
        if (colour == 2) {
            for (int u = u0; u < u1; u++)
                for (int w = w0; w < w1; w++)
                    if (on_seam(g, periodic, du, dw, u, w))
                        solve_line(g, periodic, act_a, L, s, f, r, d, u, w, du, dw);
            continue;
        }
        if (by_planes) {
            solve_plane(g, periodic, act_a, L, s, f, r, d, colour, 2, L == 0 ? 1 : 0);
            continue;
        }
#pragma omp parallel for collapse(2) schedule(static) if (kernel_parallel(g))
        for (int u = u0; u < u1; u++)
            for (int w = w0; w < w1; w++) {
                if (((u + w) & 1) != colour || on_seam(g, periodic, du, dw, u, w))
                    continue;
                solve_line(g, periodic, act_a, L, s, f, r, d, u, w, du, dw);
            }
    }
}
