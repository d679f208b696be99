/* Two-phase mixture properties (two_phase.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "march/module_record.h"
#include "march/step.h"
#include "kernels/kernels.h"
#include "kernels/rheology.h"
#include "kernels/vof.h"
#include "physics/two_phase.h"
#include "physics/vof_transport.h"
#include "platform/comm.h"

/* Sub-steps of the transport keep each sweep's CFL number below this
 * (VOF_CFL_MAX with a margin for the rounding of the ratio). */
#define TRANSPORT_CFL 0.45
/* A change of T below this in every cell leaves the density as it was (its
 * relative effect on the mixture density is below 1e-12 / 1500). */
#define TRACER_UNCHANGED 1e-12

struct two_phase {
    struct two_phase_params p;
    double *T;
    int configured;
    /* a module replaces the grains' viscosity after the properties stage
     * and mixes it (two_phase_defer_mixing): the module's words for it */
    const char *mixing_deferred;
    int transported;        /* T moves with the flow (else it is held) */
    struct vof_transport vt;
    int vt_ready;
    double *before;         /* T at the start of the transport stage */
    /* the grains' share of each edge's control volume, cut from the
     * reconstructed interface (edge_fractions) */
    double *edge_t[3];
    double *normal[3], *alpha; /* the reconstruction behind them (work) */
    int edges_stale;        /* T changed since they were computed */
};

static int create(struct march_state *st, void **state, char *err, size_t errlen)
{
    struct two_phase *tp = calloc(1, sizeof *tp);
    if (!tp) {
        snprintf(err, errlen, "two phases: out of memory");
        return -1;
    }
    *state = tp;
    tp->edges_stale = 1;
    if (fields_add_written(&st->fields, "tracer", FIELD_CHECKPOINT | FIELD_SAVED, &tp->T) != 0) {
        snprintf(err, errlen, "two phases: out of memory for the tracer");
        return -1;
    }
    return 0;
}

static void destroy(void *state)
{
    struct two_phase *tp = state;
    if (tp && tp->vt_ready)
        vof_transport_free(&tp->vt);
    if (tp) {
        field_free(tp->before);
        for (int c = 0; c < 3; c++) {
            field_free(tp->edge_t[c]);
            field_free(tp->normal[c]);
        }
        field_free(tp->alpha);
    }
    free(state);
}

double *two_phase_configure(struct march_state *st, const struct two_phase_params *p, char *err,
                            size_t errlen)
{
    struct two_phase *tp = march_module_state(st, &two_phase_module);
    if (!tp) {
        snprintf(err, errlen, "two phases: the module is not switched on");
        return NULL;
    }
    /* the cut and bed edges evaluate mu(I) themselves: a deferred mixture
     * is the replacing module's viscosity mixed at the cells' and edges'
     * mean fractions only */
    if (tp->mixing_deferred && (p->edges == EDGES_SERIES || p->bed_pressure)) {
        snprintf(err, errlen, "two phases with %s: this scene's series or bed edges take mu(I) "
                              "(rheology.law = mui)",
                 tp->mixing_deferred);
        return NULL;
    }
    tp->p = *p;
    tp->configured = 1;
    int ok = 1;
    for (int c = 0; c < 3; c++) {
        if (!tp->edge_t[c])
            ok &= (tp->edge_t[c] = field_alloc(&st->g)) != NULL;
        if (!tp->normal[c])
            ok &= (tp->normal[c] = field_alloc(&st->g)) != NULL;
    }
    if (!tp->alpha)
        ok &= (tp->alpha = field_alloc(&st->g)) != NULL;
    if (!ok) {
        snprintf(err, errlen, "two phases: out of memory for the edge fractions");
        return NULL;
    }
    tp->edges_stale = 1;
    tp->transported = p->transported;
    /* the reconstruction's and the sweeps' directions are those of more
     * than one cell: a rank's block of one cell along a split direction
     * would drop one that the whole grid has */
    for (int d = 0; d < 3; d++)
        if (bc_split(&st->bc, d) && st->g.n[d] < 2) {
            snprintf(err, errlen, "two phases on %d MPI ranks: a block of %d cell along %c "
                                  "(domain.n%c over the ranks along it: at least 2 cells each)",
                     comm_size(), st->g.n[d], "xyz"[d], "xyz"[d]);
            return NULL;
        }
    if (tp->transported && !tp->vt_ready) {
        if (vof_transport_init(&tp->vt, &st->g, &st->bc) != 0 ||
            !(tp->before = field_alloc(&st->g))) {
            snprintf(err, errlen, "two phases: out of memory for the transport");
            return NULL;
        }
        tp->vt_ready = 1;
    }
    return tp->T;
}

static void edge_fractions(struct two_phase *tp, const struct grid *g, const struct boundary *bc);
static double face_fraction(const struct two_phase *tp, const struct grid *g,
                            const struct boundary *bc, const int idx[3], int c);

int two_phase_tracer_changed(struct march_state *st, char *err, size_t errlen)
{
    struct two_phase *tp = march_module_state(st, &two_phase_module);
    const struct grid *g = &st->g;
    const double rg = st->cs->density, rf = tp->p.fluid_density;
    bc_fill_scalar(g, &st->bc, tp->T);
    tp->edges_stale = 1;
    int series = tp->p.edges == EDGES_SERIES;
    if (series) /* the reconstruction the faces' shares are cut from */
        edge_fractions(tp, g, &st->bc);
    const ptrdiff_t *o = g->stride;
    /* the face between cells p - o_c and p: series, the grains' share of its
     * box (face_fraction); mean, the mean of its two cells' (ghost cells
     * mirror the boundary cells, so a wall face gets its cell's) */
    for (int c = 0; c < 3; c++)
        for (int i = 0; i <= grid_slot_hi(g, 0); i++)
            for (int j = 0; j <= grid_slot_hi(g, 1); j++)
                for (int k = 0; k <= g->n[2]; k++) {
                    ptrdiff_t q = grid_idx(g, i, j, k);
                    const int idx[3] = {i, j, k};
                    double t = series ? face_fraction(tp, g, &st->bc, idx, c)
                                      : 0.5 * (tp->T[q] + tp->T[q - o[c]]);
                    st->field.density_faces[c][q] = t * rg + (1.0 - t) * rf;
                }
    return march_density_changed(st, 0, err, errlen);
}

double two_phase_volume(const struct march_state *st)
{
    const struct two_phase *tp = march_module_state(st, &two_phase_module);
    return march_sum(st, kernel_sum(&st->g, tp->T));
}

/* The grains' share of the box lo <= xi <= lo + width of cell idx (which
 * may be a ghost: a rank border's is the neighbour's cell, its interface
 * exchanged; a periodic one is its image's; any other counts as uniformly
 * filled with its T). */
static double box_fraction(const struct two_phase *tp, const struct grid *g,
                           const struct boundary *bc, const int idx[3], const double lo[3],
                           const double width[3])
{
    int w[3] = {idx[0], idx[1], idx[2]};
    for (int d = 0; d < 3; d++)
        if (w[d] < 0 || w[d] >= g->n[d]) {
            if (bc_border(bc, d, w[d] < 0 ? 0 : 1))
                continue;
            if (bc->face[d][0] != BC_PERIODIC)
                return tp->T[grid_idx(g, idx[0], idx[1], idx[2])];
            w[d] = (w[d] + g->n[d]) % g->n[d];
        }
    ptrdiff_t p = grid_idx(g, w[0], w[1], w[2]);
    double m[3] = {tp->normal[0][p], tp->normal[1][p], tp->normal[2][p]};
    return vof_box_fraction(m, tp->alpha[p], tp->T[p], lo, width);
}

/* The quarter lo_a <= xi_a <= lo_a + 1/2, lo_b <= xi_b <= lo_b + 1/2. */
static double quarter_fraction(const struct two_phase *tp, const struct grid *g,
                               const struct boundary *bc, const int idx[3], int a, double lo_a,
                               int b, double lo_b)
{
    double lo[3] = {0.0, 0.0, 0.0}, width[3] = {1.0, 1.0, 1.0};
    lo[a] = lo_a;
    lo[b] = lo_b;
    width[a] = width[b] = 0.5;
    return box_fraction(tp, g, bc, idx, lo, width);
}

/* The grains' share of the face between cells q - o_c and q (q = idx): its
 * momentum node's box, the upper half of the one and the lower half of the
 * other.  The mean of the two cells' T put, on a flat interface a third of
 * a cell above a face, a sixth of a cell's grains too many into the box
 * below it and as many too few into the one above: the hydrostatic
 * pressure at the cells next to the interface was off by a twelfth of a
 * cell's weight of grains. */
static double face_fraction(const struct two_phase *tp, const struct grid *g,
                            const struct boundary *bc, const int idx[3], int c)
{
    double lo[3] = {0.0, 0.0, 0.0}, width[3] = {1.0, 1.0, 1.0};
    width[c] = 0.5;
    double t = 0.5 * box_fraction(tp, g, bc, idx, lo, width);
    int below[3] = {idx[0], idx[1], idx[2]};
    below[c] -= 1;
    lo[c] = 0.5;
    return t + 0.5 * box_fraction(tp, g, bc, below, lo, width);
}

/* The grains' share of every edge's control volume (the cell-sized box
 * centred on the edge: a quarter of each of its four cells), cut from the
 * piecewise-linear interface.  The mean of the four cells' T smears a flat
 * interface over two edges: an edge whose box holds 6% grains counted 28%
 * of them, and the air above a layer moved as if it were half a cell
 * thinner. */
static void edge_fractions(struct two_phase *tp, const struct grid *g, const struct boundary *bc)
{
    vof_reconstruct(g, tp->T, tp->normal, tp->alpha);
    if (bc->dc) /* the neighbours' interfaces in the rank borders' ghosts */
        for (int c = 0; c < 4; c++)
            bc_fill_scalar(g, bc, c < 3 ? tp->normal[c] : tp->alpha);
    for (int c = 0; c < 3; c++) {
        int a = (c + 1) % 3, b = (c + 2) % 3;
        int hi[3] = {g->n[0], g->n[1], g->n[2]};
        hi[c] = g->n[c] - 1;
        for (int i = 0; i <= hi[0]; i++)
            for (int j = 0; j <= hi[1]; j++)
                for (int k = 0; k <= hi[2]; k++) {
                    int e[3] = {i, j, k}, q[3];
                    double t = 0.0;
                    for (int sa = 0; sa < 2; sa++)
                        for (int sb = 0; sb < 2; sb++) {
                            /* sa = 1: the cell below along a, whose upper half is in the box */
                            memcpy(q, e, sizeof q);
                            q[a] -= sa;
                            q[b] -= sb;
                            t += 0.25 * quarter_fraction(tp, g, bc, q, a, 0.5 * sa, b, 0.5 * sb);
                        }
                    tp->edge_t[c][grid_idx(g, i, j, k)] = t;
                }
    }
    tp->edges_stale = 0;
}

/* The mixture of the granular viscosity eta_g and the fluid's at fraction
 * t, and its derivative with respect to eta_g (for the tangents).  An edge
 * the interface cuts under the series rule is cut_edge's instead. */
static inline double mix(const struct two_phase *tp, double rg, double t, double eta_g,
                         double *deta)
{
    double ef = tp->p.fluid_viscosity, rf = tp->p.fluid_density;
    if (tp->p.mixture == MIXTURE_HARMONIC) {
        double eta = 1.0 / (t / eta_g + (1.0 - t) / ef);
        *deta = t > 0.0 ? eta * eta * t / (eta_g * eta_g) : 0.0;
        return eta;
    }
    double w = t * rg / (t * rg + (1.0 - t) * rf);
    *deta = w;
    return w * eta_g + (1.0 - w) * ef;
}

/* The granular viscosity within the clip (when there is one); *clipped
 * says whether it was cut (its derivatives then vanish). */
static inline double clip(const struct two_phase *tp, double eta_g, int *clipped)
{
    *clipped = 0;
    if (!(tp->p.eta_max > 0.0))
        return eta_g;
    double e = fmin(fmax(eta_g, tp->p.eta_min), tp->p.eta_max);
    *clipped = e != eta_g;
    return e;
}

/* eta (and the tangent A, the full tangent's b) of one stress location:
 * A = eta + eta_g' x (its derivative part), which scales with d eta / d eta_g. */
static inline void mix_point(const struct two_phase *tp, double rg, double t, double *eta,
                             double *const tan[], int ntan, double *b)
{
    int cut;
    double d, eg = clip(tp, *eta, &cut);
    if (cut) {
        for (int a = 0; a < ntan; a++)
            *tan[a] = eg;
        if (b)
            *b = 0.0;
    }
    double m = mix(tp, rg, t, eg, &d);
    for (int a = 0; a < ntan; a++)
        *tan[a] = m + d * (*tan[a] - eg);
    if (b)
        *b *= d;
    *eta = m;
}

/* The grains' stress tau_g(x) = eta_g(x) x at their own shear rate x and
 * pressure p_reg (the clip applied), and its slope d tau_g / dx. */
static double grain_stress(const struct two_phase *tp, const struct rheology *r, double x,
                           double p_reg, double *slope)
{
    struct rheology_point pt;
    rheology_eval(r, x, p_reg, &pt);
    int cut;
    double eta = clip(tp, pt.eta, &cut);
    *slope = cut ? eta : eta + pt.deta_dshear * x;
    return eta * x;
}

/* How the stress and the grains' pressure vary along a cut link: the
 * stress each phase carries over its part of the link, as a multiple of the
 * edge's (m_g, m_f), and the grains' pressure there. */
struct link_load {
    double m_g, m_f, p_g;
};

/* An edge the interface cuts, at the grains' share t of its link: the two
 * phases in series, each at its own shear rate.  The link's mean rate G is
 * t x + (1 - t) m_f tau / eta_f, where the grains carry m_g tau = tau_g(x)
 * at their rate x (the exact flux of a profile linear in each phase); x is
 * solved for (Newton kept inside a bracket: the left side rises with x).
 * The grains' law at the link's mean rate instead, where the air's rate is a
 * hundred times the grains', made them a hundred times too soft: a sliver
 * of air at 0.2 of a cell above a face put 7.5 % of u_top into the air's
 * profile.  Returns eta = tau / G and *dtau_dG, the series of the two
 * slopes. */
static double series_edge(const struct two_phase *tp, const struct rheology *r, double t,
                          double G, const struct link_load *ld, double *dtau_dG)
{
    const double ef = tp->p.fluid_viscosity;
    double slope, p_reg = rheology_pressure(r, ld->p_g, NULL);
    if (!(G > 0.0)) { /* at rest: the viscosities at rest in series */
        grain_stress(tp, r, 0.0, p_reg, &slope);
        *dtau_dG = 1.0 / (t * ld->m_g / slope + (1.0 - t) * ld->m_f / ef);
        return *dtau_dG;
    }
    double lo = 0.0, hi = G / t, x = G;
    for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; it++) {
        double tau = grain_stress(tp, r, x, p_reg, &slope);
        double f = t * x + (1.0 - t) * (ld->m_f / ld->m_g) * tau / ef - G;
        if (f > 0.0)
            hi = x;
        else
            lo = x;
        if (fabs(f) <= 1e-14 * G)
            break;
        double d = t + (1.0 - t) * (ld->m_f / ld->m_g) * slope / ef;
        double xn = d > 0.0 ? x - f / d : 0.5 * (lo + hi);
        x = xn > lo && xn < hi ? xn : 0.5 * (lo + hi);
    }
    double tau = grain_stress(tp, r, x, p_reg, &slope) / ld->m_g;
    *dtau_dG = 1.0 / (t * ld->m_g / fmax(slope, 1e-300) + (1.0 - t) * ld->m_f / ef);
    return tau / G;
}

/* The load along a link of edge e (plane c) that the interface cuts.  A
 * layered flow (tp->p.layered: flat layers along z, the grains below, on
 * a uniform spacing along z) carries the weight above it: stress and
 * pressure both grow with it, so each phase's part of the link carries the
 * edge's stress times the ratio of the pressure at its middle to the
 * edge's, from the pressure of the cells above the interface and the
 * hydrostatic rise through the link.  A third of a cell of grains above an
 * edge loads it with ten times the air's weight, which the air above the
 * interface does not carry.  Otherwise the edge's stress and mean pressure
 * in both phases. */
static struct link_load cut_link_load(const struct two_phase *tp, const struct march_state *st,
                                      int c, ptrdiff_t e, double t)
{
    const struct grid *g = &st->g;
    const ptrdiff_t *o = g->stride;
    int a = (c + 1) % 3, b = (c + 2) % 3;
    const double *p = st->field.pressure;
    struct link_load ld = {1.0, 1.0,
                           0.25 * (p[e] + p[e - o[a]] + p[e - o[b]] + p[e - o[a] - o[b]])};
    if (!tp->p.layered || c == 2 || g->axis[2])
        return ld;
    int h = a == 2 ? b : a; /* the edge's horizontal direction */
    double f[3];
    body_force_vector(st->cs, f);
    double gn = -f[2] / st->cs->density, dz = g->h[2];
    double rg = st->cs->density, rf = tp->p.fluid_density;
    /* the link from the centres below the edge to those above: grains over
     * lg, the interface, fluid over lf; the edge half way */
    double lg = t * dz, lf = (1.0 - t) * dz;
    double p_i = 0.5 * (p[e] + p[e - o[h]]) + rf * gn * lf;
    double p_e = t >= 0.5 ? p_i + rg * gn * (t - 0.5) * dz : p_i - rf * gn * (0.5 - t) * dz;
    double p_g = p_i + 0.5 * rg * gn * lg, p_f = p_i - 0.5 * rf * gn * lf;
    if (!(p_e > 0.0 && p_f > 0.0 && gn > 0.0))
        return ld;
    ld.m_g = p_g / p_e;
    ld.m_f = p_f / p_e;
    ld.p_g = p_g;
    return ld;
}

/* A cut edge's viscosity, tangent and full-tangent coefficient (as
 * kernel_viscosity_edges defines them) from series_edge at the edge's |D|. */
static void cut_edge(const struct two_phase *tp, struct march_state *st, int c, ptrdiff_t e,
                     double t)
{
    const struct grid *g = &st->g;
    struct link_load ld = cut_link_load(tp, st, c, e, t);
    double G2 = kernel_edge_shear2(g, st->field.strain_normal2, st->field.strain_shear2, c, e);
    double G = sqrt(G2), dtau;
    double eta = series_edge(tp, &st->rheo, t, G, &ld, &dtau);
    st->field.viscosity_edges[c][e] = eta;
    /* d eta / dG = (dtau/dG - eta) / G */
    double deta = G > 0.0 ? (dtau - eta) / G : 0.0;
    if (st->cs->newton)
        st->field.tangent_edges[c][e] =
            G > 0.0 ? eta + deta * st->field.strain_shear2[c][e] / G : eta;
    if (st->b_e[c])
        st->b_e[c][e] = G > 0.0 ? deta / (2.0 * G) : 0.0;
}

/* An edge of the bed (plane c holding z, at face 0 along z, a wall below):
 * the grains' viscosity, its tangent and full-tangent coefficient (as
 * kernel_viscosity_edges defines them) at the bed's hydrostatic pressure,
 * the mean over the edge's two cells of p + rho g_n dz / 2 with each cell's
 * mixture density.  The core's ghost pressure, extrapolated linearly from
 * the two cells above the bed, gives a layer one cell deep under air three
 * quarters of its weight on the bed: less than mu(I) p can carry of its
 * weight's shear, so it flowed at the viscosity floor's Newtonian rate
 * (docs/validation/front.md). */
static void bed_edge(const struct two_phase *tp, struct march_state *st, int c, ptrdiff_t e)
{
    const struct grid *g = &st->g;
    int a = (c + 1) % 3, b = (c + 2) % 3, h = a == 2 ? b : a;
    double f[3];
    body_force_vector(st->cs, f);
    double rg = st->cs->density, rf = tp->p.fluid_density, gn = -f[2] / rg;
    const ptrdiff_t q[2] = {e, e - g->stride[h]};
    double p_bed = 0.0;
    for (int m = 0; m < 2; m++) {
        double t = tp->T[q[m]], rho = t * rg + (1.0 - t) * rf;
        p_bed += 0.5 * (st->field.pressure[q[m]] + 0.5 * rho * gn * g->h[2]);
    }
    double G = sqrt(kernel_edge_shear2(g, st->field.strain_normal2, st->field.strain_shear2, c, e));
    struct rheology_point pt;
    rheology_eval(&st->rheo, G, rheology_pressure(&st->rheo, p_bed, NULL), &pt);
    st->field.viscosity_edges[c][e] = pt.eta;
    if (st->cs->newton)
        st->field.tangent_edges[c][e] =
            G > 0.0 ? pt.eta + pt.deta_dshear * st->field.strain_shear2[c][e] / G : pt.eta;
    if (st->b_e[c])
        st->b_e[c][e] = G > 0.0 ? pt.deta_dshear / (2.0 * G) : 0.0;
}

const double *two_phase_fraction(const struct march_state *st)
{
    const struct two_phase *tp = march_module_state(st, &two_phase_module);
    return tp && tp->configured ? tp->T : NULL;
}

static void mix_viscosities(struct march_state *st, struct two_phase *tp);

/* The mixture of the viscosities the core computed, unless a module
 * replaces the grains' after this hook: it mixes them then
 * (two_phase_defer_mixing). */
static void properties(struct march_state *st, void *state)
{
    struct two_phase *tp = state;
    if (!tp->configured || tp->mixing_deferred)
        return;
    mix_viscosities(st, tp);
}

void two_phase_defer_mixing(struct march_state *st, const char *by)
{
    struct two_phase *tp = march_module_state(st, &two_phase_module);
    if (tp)
        tp->mixing_deferred = by;
}

void two_phase_mix_viscosities(struct march_state *st)
{
    struct two_phase *tp = march_module_state(st, &two_phase_module);
    if (tp && tp->configured)
        mix_viscosities(st, tp);
}

static void mix_viscosities(struct march_state *st, struct two_phase *tp)
{
    const struct grid *g = &st->g;
    const struct muflow_case *cs = st->cs;
    const double rg = cs->density;
    bc_fill_scalar(g, &st->bc, tp->T);
    int series = tp->p.edges == EDGES_SERIES;
    /* the bed's layer: the first of the block at the domain's foot (a rank
     * border below is no bed) */
    int bed = tp->p.bed_pressure && st->bc.face[2][0] == BC_WALL && !g->axis[2] &&
              !bc_border(&st->bc, 2, 0);
    if (series && tp->edges_stale)
        edge_fractions(tp, g, &st->bc);
    const ptrdiff_t *o = g->stride;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t q = grid_idx(g, i, j, k);
                double *tan[3] = {NULL, NULL, NULL};
                if (cs->newton)
                    for (int a = 0; a < 3; a++)
                        tan[a] = &st->field.tangent_cells[a][q];
                mix_point(tp, rg, tp->T[q], &st->field.viscosity[q], tan, cs->newton ? 3 : 0,
                          st->b_c ? &st->b_c[q] : NULL);
            }
    for (int c = 0; c < 3; c++) {
        int a = (c + 1) % 3, b = (c + 2) % 3;
        int hi[3] = {g->n[0], g->n[1], g->n[2]};
        hi[c] = g->n[c] - 1;
        for (int i = 0; i <= hi[0]; i++)
            for (int j = 0; j <= hi[1]; j++)
                for (int k = 0; k <= hi[2]; k++) {
                    ptrdiff_t e = grid_idx(g, i, j, k);
                    const double *T = tp->T;
                    /* series: an edge cut by the interface carries a shear
                     * stress that is continuous across it (its normal lies in
                     * the plane of a and b in a cross-section), so the two
                     * phases act in series whatever the mixture law */
                    double t = series ? tp->edge_t[c][e]
                                      : 0.25 * (T[e] + T[e - o[a]] + T[e - o[b]] +
                                                T[e - o[a] - o[b]]);
                    if (series && t > 0.0 && t < 1.0) {
                        cut_edge(tp, st, c, e, t);
                        continue;
                    }
                    if (bed && c != 2 && k == 0)
                        bed_edge(tp, st, c, e);
                    double *tan[1] = {cs->newton ? &st->field.tangent_edges[c][e] : NULL};
                    mix_point(tp, rg, t, &st->field.viscosity_edges[c][e], tan,
                              cs->newton ? 1 : 0, st->b_e[c] ? &st->b_e[c][e] : NULL);
                }
    }
    bc_fill_scalar(g, &st->bc, st->field.viscosity);
    if (cs->newton)
        for (int a = 0; a < 3; a++)
            bc_fill_scalar(g, &st->bc, st->field.tangent_cells[a]);
}

/* The transport stage: T carried by the projected velocity over the step,
 * geometric VOF (physics/vof_transport.h), in as many equal sub-steps as the
 * sweeps' CFL limit needs, so that the implicit step's dt is not bound by
 * it; then the mixture density follows T. */
static int transport(struct march_state *st, void *state, double dt)
{
    struct two_phase *tp = state;
    if (!tp->configured || !tp->transported)
        return 0;
    double cfl[3];
    long n = (long)ceil(march_max(st, vof_cfl(&st->g, st->field.velocity, dt, cfl)) /
                        TRANSPORT_CFL);
    if (n < 1)
        n = 1;
    bc_fill_velocity(&st->g, &st->bc, st->field.velocity);
    memcpy(tp->before, tp->T, st->g.size * sizeof(double));
    for (long m = 0; m < n; m++)
        vof_transport_step(&tp->vt, tp->T, st->field.velocity, dt / (double)n, NULL);
    /* the density (and the multigrid's coefficients, rebuilt with a
     * factorisation of its coarsest level) only when T moved: a flat layer
     * sheared along itself keeps T to round-off */
    double moved = 0.0;
    const struct grid *g = &st->g;
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                ptrdiff_t q = grid_idx(g, i, j, k);
                moved = fmax(moved, fabs(tp->T[q] - tp->before[q]));
            }
    if (march_max(st, moved) > TRACER_UNCHANGED) {
        char err[256];
        if (two_phase_tracer_changed(st, err, sizeof err) != 0) {
            snprintf(st->step_error, sizeof st->step_error, "the transport: %.140s", err);
            return -1;
        }
    }
    return 0;
}

/* The VOF limit of the step: step_cfl h_d / max |u_d| over the swept
 * directions, at the velocity the step starts from. */
static double max_dt(const struct march_state *st, void *state)
{
    struct two_phase *tp = state;
    if (!tp->configured || !tp->transported || !(tp->p.step_cfl > 0.0))
        return INFINITY;
    double cfl[3];
    double c = march_max(st, vof_cfl(&st->g, st->field.velocity, 1.0, cfl));
    return c > 0.0 ? fmin(tp->p.step_cfl, VOF_CFL_MAX) / c : INFINITY;
}

/* What the step takes from earlier steps beyond T: the density of the
 * faces and the edges' shares, both from T as it was when it last moved by
 * more than TRACER_UNCHANGED (so not always today's T), and the parity of
 * the transport's steps, which orders its sweeps.  A continued run takes
 * them from the checkpoint, not from T: it goes on bit for bit (on one
 * process; see load). */
static const char *const rho_names[3] = {"face_density_x", "face_density_y", "face_density_z"};
static const char *const edge_names[3] = {"edge_fraction_x", "edge_fraction_y",
                                          "edge_fraction_z"};

static int save(const struct march_state *st, void *state, struct module_record *rec)
{
    const struct two_phase *tp = state;
    if (!tp->configured)
        return 0;
    const struct grid *g = &st->g;
    double steps = tp->vt_ready ? (double)tp->vt.steps : 0.0, stale = tp->edges_stale;
    if (module_record_put(rec, "transport_steps", &steps, 1) != 0 ||
        module_record_put(rec, "edges_stale", &stale, 1) != 0)
        return -1;
    for (int c = 0; c < 3 && !st->ranks; c++)
        if (module_record_put_field(rec, rho_names[c], g, st->field.density_faces[c]) != 0 ||
            (!tp->edges_stale &&
             module_record_put_field(rec, edge_names[c], g, tp->edge_t[c]) != 0))
            return -1;
    return 0;
}

static int load(struct march_state *st, void *state, struct module_record *rec)
{
    struct two_phase *tp = state;
    if (!tp->configured)
        return 0;
    char err[256];
    if (!rec) /* an earlier checkpoint: the density of today's T */
        return two_phase_tracer_changed(st, err, sizeof err);
    const struct grid *g = &st->g;
    double steps, stale;
    if (module_record_get(rec, "transport_steps", &steps, 1) != 0 ||
        module_record_get(rec, "edges_stale", &stale, 1) != 0)
        return -1;
    if (tp->vt_ready)
        tp->vt.steps = (long)steps;
    /* rank 0 writes the record (io/checkpoint.c): a decomposed run's holds
     * no fields, and one process's are the whole grid's; the ranks' run, or
     * one continuing theirs, takes the density of today's T */
    if (st->ranks || module_record_count(rec, rho_names[0]) < 0)
        return two_phase_tracer_changed(st, err, sizeof err);
    tp->edges_stale = stale != 0.0;
    for (int c = 0; c < 3; c++)
        if (module_record_get_field(rec, rho_names[c], g, st->field.density_faces[c]) != 0 ||
            (!tp->edges_stale &&
             module_record_get_field(rec, edge_names[c], g, tp->edge_t[c]) != 0))
            return -1;
    if (march_density_changed(st, 0, err, sizeof err) != 0)
        return module_record_fail(rec, "%s", err);
    return 0;
}

const struct module two_phase_module = {
    .name = "two_phase",
    .create = create,
    .properties = properties,
    .transport = transport,
    .max_dt = max_dt,
    .save = save,
    .load = load,
    .destroy = destroy,
    .decomposed = 1,
};
