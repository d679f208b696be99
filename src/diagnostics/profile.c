/* Layer-averaged profiles, errors and headline values (profile.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "scenes/analytic.h"
#include "diagnostics/profile.h"
#include "diagnostics/reference.h"

/* Largest |psi| with u = d psi / dz, w = -d psi / dx and psi = 0 on the base:
 * integrated up every x-face column (mean over y). */
static double stream_function_max(const struct march_state *st)
{
    const struct grid *g = &st->g;
    double m = 0.0;
    for (int i = 0; i <= g->n[0]; i++) {
        double psi = 0.0;
        for (int k = 0; k < g->n[2]; k++) {
            double u = 0.0;
            for (int j = 0; j < g->n[1]; j++)
                u += st->vel[0][grid_idx(g, i, j, k)];
            psi += u / g->n[1] * g->h[2];
            m = fmax(m, fabs(psi));
        }
    }
    return m;
}

void profile_free(struct profile *pr)
{
    double *arrays[] = {pr->coord, pr->velocity, pr->pressure, pr->shear_rate,
                        pr->inertial, pr->viscosity, pr->exact};
    for (size_t m = 0; m < sizeof arrays / sizeof arrays[0]; m++)
        free(arrays[m]);
    memset(pr, 0, sizeof *pr);
}

int profile_extract(struct profile *pr, const struct march_state *st)
{
    memset(pr, 0, sizeof *pr);
    const struct muflow_case *cs = st->cs;
    if (scene_profile_axes(cs->scene, &pr->axis, &pr->component) != 0)
        return -1;
    const struct grid *g = &st->g;
    int n = pr->n = g->n[pr->axis];
    double **arrays[] = {&pr->coord, &pr->velocity, &pr->pressure, &pr->shear_rate,
                         &pr->inertial, &pr->viscosity, &pr->exact};
    for (size_t m = 0; m < sizeof arrays / sizeof arrays[0]; m++)
        if (!(*arrays[m] = calloc((size_t)n, sizeof(double)))) {
            profile_free(pr);
            return -1;
        }
    const struct box *b = &st->act[pr->component];
    long *nodes = calloc((size_t)n, sizeof(long)), *cells = calloc((size_t)n, sizeof(long));
    if (!nodes || !cells) {
        free(nodes);
        free(cells);
        profile_free(pr);
        return -1;
    }
    /* the cavity's profile is its vertical mid-line: the x-faces (and the
     * cells beside them) nearest to x = lx/2 */
    int cavity = cs->scene == SCENE_BINGHAM_CAVITY;
    int even = g->n[0] % 2 == 0;
    int face_lo = even ? g->n[0] / 2 : (g->n[0] - 1) / 2, face_hi = even ? face_lo : face_lo + 1;
    int cell_lo = even ? g->n[0] / 2 - 1 : face_lo, cell_hi = even ? cell_lo + 1 : face_lo;
    for (int i = b->lo[0]; i < b->hi[0]; i++)
        for (int j = b->lo[1]; j < b->hi[1]; j++)
            for (int k = b->lo[2]; k < b->hi[2]; k++) {
                if (cavity && (i < face_lo || i > face_hi))
                    continue;
                int idx[3] = {i, j, k};
                int l = idx[pr->axis];
                pr->velocity[l] += st->vel[pr->component][grid_idx(g, i, j, k)];
                nodes[l]++;
            }
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                if (cavity && (i < cell_lo || i > cell_hi))
                    continue;
                int idx[3] = {i, j, k};
                int l = idx[pr->axis];
                ptrdiff_t p = grid_idx(g, i, j, k);
                double shear = sqrt(st->shear2[p]);
                pr->pressure[l] += st->pressure[p];
                pr->shear_rate[l] += shear;
                pr->inertial[l] += rheology_inertial_number(&cs->rheo, shear, st->preg[p]);
                pr->viscosity[l] += st->eta[p];
                cells[l]++;
            }
    pr->psi_max = cavity ? stream_function_max(st) : NAN;
    struct curve ref = {0};
    if (cavity && cs->reference[0]) {
        char err[256];
        if (reference_curve(cs->reference, "midline", cavity_reference_bn(cs), &ref, err,
                            sizeof err) != 0)
            memset(&ref, 0, sizeof ref);
    }
    for (int l = 0; l < n; l++) {
        pr->coord[l] = (l + 0.5) * g->h[pr->axis];
        pr->velocity[l] /= nodes[l] > 0 ? (double)nodes[l] : 1.0;
        double nc = cells[l] > 0 ? (double)cells[l] : 1.0;
        pr->pressure[l] /= nc;
        pr->shear_rate[l] /= nc;
        pr->inertial[l] /= nc;
        pr->viscosity[l] /= nc;
        pr->exact[l] = cavity ? (ref.n > 1 ? curve_at(&ref, pr->coord[l]) : NAN)
                              : analytic_velocity(cs, pr->coord[l]);
    }
    curve_free(&ref);
    free(nodes);
    free(cells);
    return 0;
}

/* Surface velocity of a free-surface layer from its two top nodes.  Near a
 * free surface p grows linearly with depth and, at fixed friction, the shear
 * rate as sqrt(depth): u = U - C depth^(3/2) is the local form, so the two
 * nodes at depths h/2 and 3h/2 give U. */
static double surface_velocity(const struct profile *pr, double H)
{
    if (pr->n < 2)
        return pr->velocity[pr->n - 1];
    double d1 = H - pr->coord[pr->n - 1], d2 = H - pr->coord[pr->n - 2];
    double u1 = pr->velocity[pr->n - 1], u2 = pr->velocity[pr->n - 2];
    double c = (u1 - u2) / (d2 * sqrt(d2) - d1 * sqrt(d1));
    return u1 + c * d1 * sqrt(d1);
}

/* Plug velocity: the centre layer, or the mean of the two centre layers. */
static double plug_velocity(const struct profile *pr)
{
    int n = pr->n;
    if (n % 2 == 1)
        return pr->velocity[n / 2];
    return 0.5 * (pr->velocity[n / 2 - 1] + pr->velocity[n / 2]);
}

/* The cavity against the reference: the mid-line profile, completed by the
 * wall (u = 0) and the lid, interpolated at the reference points; psi_max
 * against the reference's psi_max curve. */
static void cavity_errors(const struct profile *pr, const struct muflow_case *cs,
                          struct scene_errors *e)
{
    e->headline = pr->psi_max;
    e->headline_exact = NAN;
    e->err_rms = e->err_max = e->err_rms_paper = NAN;
    if (!cs->reference[0])
        return;
    char err[256];
    double bn = cavity_reference_bn(cs);
    struct curve psi = {0}, mid = {0};
    if (reference_curve(cs->reference, "psi_max", NAN, &psi, err, sizeof err) == 0 && psi.n > 1)
        e->headline_exact = curve_at(&psi, bn);
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

void profile_errors(const struct profile *pr, const struct muflow_case *cs, struct scene_errors *e)
{
    memset(e, 0, sizeof *e);
    if (cs->scene == SCENE_BINGHAM_CAVITY) {
        cavity_errors(pr, cs, e);
        return;
    }
    double sum2 = 0.0, emax = 0.0;
    e->valid = pr->n > 0;
    for (int l = 0; l < pr->n; l++) {
        double d = pr->velocity[l] - pr->exact[l];
        if (!isfinite(pr->exact[l]))
            e->valid = 0;
        sum2 += d * d;
        if (fabs(d) > emax)
            emax = fabs(d);
    }
    /* bagnold: the free-surface velocity; chute and Bingham channel: the plug */
    e->headline = cs->scene == SCENE_BAGNOLD ? surface_velocity(pr, cs->len[2])
                                             : plug_velocity(pr);
    e->headline_exact = analytic_headline(cs);
    if (!e->valid) {
        e->err_rms = e->err_max = e->err_rms_paper = NAN;
        return;
    }
    e->err_rms = sqrt(sum2 / pr->n);
    e->err_max = emax;
    e->err_rms_paper = sqrt(sum2) / pr->n;
}

void scene_errors_of(const struct march_state *st, struct scene_errors *e)
{
    struct profile pr;
    memset(e, 0, sizeof *e);
    if (profile_extract(&pr, st) != 0) {
        e->err_rms = e->err_max = e->err_rms_paper = e->headline = e->headline_exact = NAN;
        return;
    }
    profile_errors(&pr, st->cs, e);
    profile_free(&pr);
}
