/* Scene "bingham_cavity": the Bingham lid-driven square cavity in Stokes
 * flow (Chauchat & Medale 2010, sec. 3.1.2; cases/bingham_cavity.ini), compared with the
 * published data of Vola et al. (2003) named by case.reference: the
 * vertical mid-line profile (err_midline) and the largest stream function
 * psi_max (the headline). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "diagnostics/profile.h"
#include "diagnostics/reference.h"
#include "io/output.h"
#include "scenes/bingham_cavity.h"
#include "scenes/scene.h"
#include "scene_common.h"

double cavity_reference_bn(const struct muflow_case *cs)
{
    /* Bn = tau_0 L / (mu_p U) with L = lx, U the lid speed */
    double bn = cs->rheo.yield_stress * cs->len[0] /
                (cs->rheo.plastic_viscosity * fabs(cs->bc.lid_velocity));
    return sqrt(2.0) * bn;
}

/* The profile is the vertical mid-line: the x-faces (and the cells beside
 * them) nearest to x = lx/2. */
static void midline(const struct grid *g, int faces[2], int cells[2])
{
    int even = g->n[0] % 2 == 0;
    faces[0] = even ? g->n[0] / 2 : (g->n[0] - 1) / 2;
    faces[1] = even ? faces[0] : faces[0] + 1;
    cells[0] = even ? g->n[0] / 2 - 1 : faces[0];
    cells[1] = even ? cells[0] + 1 : faces[0];
}

/* The reference mid-line at the profile's points: interpolated between the
 * data's points, NaN outside their range (the digitised curve starts and
 * ends a little inside the walls; extrapolating it would invent values)
 * and without data. */
static void reference_profile(const struct muflow_case *cs, int n, const double *x, double *u)
{
    struct curve ref = {0};
    char err[256];
    if (cs->reference[0] && reference_curve(cs->reference, "midline", cavity_reference_bn(cs),
                                            &ref, err, sizeof err) != 0)
        memset(&ref, 0, sizeof ref);
    for (int i = 0; i < n; i++)
        u[i] = ref.n > 1 && x[i] >= ref.x[0] && x[i] <= ref.x[ref.n - 1] ? curve_at(&ref, x[i])
                                                                          : NAN;
    curve_free(&ref);
}

static void reference_parameters(const struct muflow_case *cs, char *out, size_t outlen)
{
    snprintf(out, outlen, "Bn = %.6g in Vola's convention, sqrt(2) tau_0 L / (mu_p U)",
             cavity_reference_bn(cs));
}

/* The reference psi_max at bn: the published curve between its first and
 * last point, NaN outside them (its ends are the data's: extrapolated past
 * Vola's last Bn, 982, the curve turned negative, which a largest |psi|
 * cannot be) and without data. */
static double psi_max_at(const struct curve *psi, double bn)
{
    return psi->n > 1 && bn >= psi->x[0] && bn <= psi->x[psi->n - 1] ? curve_at(psi, bn) : NAN;
}

/* Why the case has no reference where it has none, for the summary (psi,
 * mid: each "" when that reference exists): the data's range of psi_max,
 * and the Bn of its mid-line profiles. */
static void missing_reference(const struct muflow_case *cs, char *psi_note, char *mid_note,
                              size_t len)
{
    psi_note[0] = mid_note[0] = '\0';
    if (!cs->reference[0])
        return;
    char err[256];
    double bn = cavity_reference_bn(cs);
    struct curve psi = {0}, mid = {0}, all = {0};
    if (reference_curve(cs->reference, "psi_max", NAN, &psi, err, sizeof err) == 0 &&
        isnan(psi_max_at(&psi, bn))) {
        if (psi.n > 1)
            snprintf(psi_note, len, "Bn %.6g outside the data's %.6g to %.6g (Vola's convention; "
                                    "not extrapolated)",
                     bn, psi.x[0], psi.x[psi.n - 1]);
        else
            snprintf(psi_note, len, "the data hold no psi_max curve");
    }
    if (reference_curve(cs->reference, "midline", bn, &mid, err, sizeof err) == 0 && mid.n < 2 &&
        reference_curve(cs->reference, "midline", NAN, &all, err, sizeof err) == 0) {
        /* the profiles' Bn, once each (the rows come sorted by Bn) */
        size_t used = (size_t)snprintf(mid_note, len, "Bn %.6g has no profile in the data (Bn", bn);
        for (int i = 0; i < all.n && used < len; i++)
            if (i == 0 || all.x[i] != all.x[i - 1])
                used += (size_t)snprintf(mid_note + used, len - used, "%s %.6g", i ? "," : "",
                                         all.x[i]);
        if (used < len)
            snprintf(mid_note + used, len - used, ")");
    }
    curve_free(&psi);
    curve_free(&mid);
    curve_free(&all);
}

/* Largest |psi| with u = d psi / dz, w = -d psi / dx and psi = 0 on the base:
 * integrated up every x-face column (mean over y).  Over ranks every
 * rank's faces are summed into the whole grid's (each face once, from the
 * rank that owns it), and every rank integrates the columns as one process
 * does: the same sums in the same order, psi_max to the bit of the same
 * velocities. */
static double stream_function_max(const struct march_state *st)
{
    const struct grid *g = &st->g, *gg = march_global_grid(st);
    const int nx = gg->n[0] + 1, nz = gg->n[2];
    double *u = calloc((size_t)nx * (size_t)nz, sizeof(double));
    if (!u)
        return NAN;
    const int *lo = st->ranks ? st->ranks->dc.lo : (const int[3]){0, 0, 0};
    /* the last face is this rank's unless the next rank's face 0 */
    const int ihi = g->n[0] + !bc_border(&st->bc, 0, 1);
    for (int i = 0; i < ihi; i++)
        for (int k = 0; k < g->n[2]; k++) {
            double s = 0.0;
            for (int j = 0; j < g->n[1]; j++)
                s += st->field.velocity[0][grid_idx(g, i, j, k)];
            u[(size_t)(lo[0] + i) * (size_t)nz + (size_t)(lo[2] + k)] = s;
        }
    if (st->ranks)
        march_sum_array(st, u, nx * nz);
    double m = 0.0;
    for (int i = 0; i < nx; i++) {
        double psi = 0.0;
        for (int k = 0; k < nz; k++) {
            psi += u[(size_t)i * (size_t)nz + (size_t)k] / gg->n[1] * gg->h[2];
            m = fmax(m, fabs(psi));
        }
    }
    free(u);
    return m;
}

/* The mid-line profile, completed by the wall (u = 0) and the lid,
 * interpolated at the reference points; psi_max against the reference's
 * psi_max curve. */
static void errors(const struct march_state *st, const struct profile *pr, struct scene_errors *e)
{
    const struct muflow_case *cs = st->cs;
    memset(e, 0, sizeof *e);
    e->headline = stream_function_max(st);
    e->headline_exact = NAN;
    e->err_rms = e->err_max = e->err_rms_paper = NAN;
    if (!cs->reference[0])
        return;
    char err[256];
    double bn = cavity_reference_bn(cs);
    struct curve psi = {0}, mid = {0};
    if (reference_curve(cs->reference, "psi_max", NAN, &psi, err, sizeof err) == 0)
        e->headline_exact = psi_max_at(&psi, bn);
    curve_free(&psi);
    if (reference_curve(cs->reference, "midline", bn, &mid, err, sizeof err) != 0 || mid.n < 2) {
        curve_free(&mid);
        return;
    }
    struct curve ours = {.n = pr->n + 2};
    ours.x = malloc((size_t)ours.n * sizeof(double));
    ours.y = malloc((size_t)ours.n * sizeof(double));
    if (ours.x && ours.y) {
        ours.x[0] = 0.0;
        ours.y[0] = 0.0;
        for (int l = 0; l < pr->n; l++) {
            ours.x[l + 1] = pr->coord[l];
            ours.y[l + 1] = pr->velocity[l];
        }
        ours.x[pr->n + 1] = cs->len[2];
        ours.y[pr->n + 1] = cs->bc.lid_velocity;
        double s2 = 0.0, emax = 0.0;
        for (int q = 0; q < mid.n; q++) {
            double d = curve_at(&ours, mid.x[q]) - mid.y[q];
            s2 += d * d;
            emax = fmax(emax, fabs(d));
        }
        e->valid = 1;
        e->err_rms = sqrt(s2 / mid.n);
        e->err_max = emax;
    }
    curve_free(&ours);
    curve_free(&mid);
}

/* Where the published data do not cover the case: the reason, on the
 * terminal (the scene's line) and in the summary (psi_max_reference_note,
 * midline_reference_note). */
static void results(const struct march_state *st, const struct scene_drive *d,
                    struct run_result *res)
{
    (void)d;
    char psi[256], mid[256]; /* the summary keeps what fits its values */
    missing_reference(st->cs, psi, mid, sizeof psi);
    if (psi[0])
        run_result_add(res, "psi_max_reference_note", "%s", psi);
    if (mid[0])
        run_result_add(res, "midline_reference_note", "%s", mid);
    if (psi[0] || mid[0])
        snprintf(res->scene_line, sizeof res->scene_line, "%s%.130s%s%s%.130s",
                 psi[0] ? "no psi_max reference: " : "", psi, psi[0] && mid[0] ? "; " : "",
                 mid[0] ? "no mid-line reference: " : "", mid);
}

const struct scene scene_bingham_cavity = {
    .name = "bingham_cavity",
    .title = "Bingham lid-driven cavity against Vola et al. (2003)",
    .profile_axis = 2,
    .profile_component = 0,
    .profile_slab = midline,
    .exact_profile = reference_profile,
    .headline_name = "psi_max",
    .error_name = "err_midline",
    .solution_name = "reference",
    .no_err_rms_paper = 1,
    .reference_parameters = reference_parameters,
    .errors = errors,
    .results = results,
    /* the walls and the lid split over ranks under the velocity multigrid
     * (auto's pick there: precond_policy.c), psi_max from every rank's faces */
    .decomposed = scene_decomposed_always,
};
