/* Layer-averaged profiles, errors and headline values (profile.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "diagnostics/profile.h"

void profile_free(struct profile *pr)
{
    double *arrays[] = {pr->coord, pr->velocity, pr->pressure, pr->shear_rate,
                        pr->inertial, pr->viscosity, pr->exact};
    for (size_t m = 0; m < sizeof arrays / sizeof arrays[0]; m++)
        free(arrays[m]);
    memset(pr, 0, sizeof *pr);
}

/* The layers' sums and counts of every rank (each over the global layers,
 * its own block's filled, 0 elsewhere). */
static int sum_over_ranks(const struct march_state *st, struct profile *pr, long *nodes,
                          long *cells)
{
    const int n = pr->n;
    double *sums[] = {pr->velocity, pr->pressure, pr->shear_rate, pr->inertial, pr->viscosity};
    const int m = (int)(sizeof sums / sizeof sums[0]);
    double *buf = malloc((size_t)(m + 2) * (size_t)n * sizeof(double));
    if (!buf)
        return -1;
    for (int l = 0; l < n; l++) {
        for (int a = 0; a < m; a++)
            buf[a * n + l] = sums[a][l];
        buf[m * n + l] = (double)nodes[l];
        buf[(m + 1) * n + l] = (double)cells[l];
    }
    march_sum_array(st, buf, (m + 2) * n);
    for (int l = 0; l < n; l++) {
        for (int a = 0; a < m; a++)
            sums[a][l] = buf[a * n + l];
        nodes[l] = (long)buf[m * n + l];
        cells[l] = (long)buf[(m + 1) * n + l];
    }
    free(buf);
    return 0;
}

int profile_extract(struct profile *pr, const struct march_state *st,
                    const struct profile_spec *spec)
{
    memset(pr, 0, sizeof *pr);
    const struct muflow_case *cs = st->cs;
    if (spec->axis < 0 || spec->component < 0)
        return -1;
    pr->axis = spec->axis;
    pr->component = spec->component;
    pr->exact_name = spec->exact_name;
    const struct grid *g = &st->g;
    /* the layers over the global axis, this rank's from its block's first */
    const int n = pr->n = march_global_grid(st)->n[pr->axis];
    const int l0 = st->ranks ? st->ranks->dc.lo[pr->axis] : 0;
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
    /* a slab along the slab axis (the cavity's mid-line in x, the duct's
     * mid-plane in y), or every node */
    int sa = spec->slab_axis;
    int faces[2] = {-1, g->n[sa] + 1}, cellr[2] = {-1, g->n[sa] + 1};
    if (spec->slab) {
        /* the slab's global indices, this block's from its first (each
         * face and cell of it on the one rank that owns it) */
        spec->slab(march_global_grid(st), faces, cellr);
        const int lo = st->ranks ? st->ranks->dc.lo[sa] : 0;
        for (int s = 0; s < 2; s++) {
            faces[s] -= lo;
            cellr[s] -= lo;
        }
    }
    for (int i = b->lo[0]; i < b->hi[0]; i++)
        for (int j = b->lo[1]; j < b->hi[1]; j++)
            for (int k = b->lo[2]; k < b->hi[2]; k++) {
                int idx[3] = {i, j, k};
                if (idx[sa] < faces[0] || idx[sa] > faces[1])
                    continue;
                int l = l0 + idx[pr->axis];
                pr->velocity[l] += st->field.velocity[pr->component][grid_idx(g, i, j, k)];
                nodes[l]++;
            }
    for (int i = 0; i < g->n[0]; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                int idx[3] = {i, j, k};
                if (idx[sa] < cellr[0] || idx[sa] > cellr[1])
                    continue;
                int l = l0 + idx[pr->axis];
                ptrdiff_t p = grid_idx(g, i, j, k);
                double shear = sqrt(st->field.shear2[p]);
                pr->pressure[l] += st->field.pressure[p];
                pr->shear_rate[l] += shear;
                pr->inertial[l] +=
                    rheology_inertial_number(&cs->rheo, shear, st->field.pressure_regularised[p]);
                pr->viscosity[l] += st->field.viscosity[p];
                cells[l]++;
            }
    if (st->ranks && sum_over_ranks(st, pr, nodes, cells) != 0) {
        free(nodes);
        free(cells);
        profile_free(pr);
        return -1;
    }
    for (int l = 0; l < n; l++) {
        pr->coord[l] = grid_xc(march_global_grid(st), pr->axis, l);
        pr->velocity[l] /= nodes[l] > 0 ? (double)nodes[l] : 1.0;
        double nc = cells[l] > 0 ? (double)cells[l] : 1.0;
        pr->pressure[l] /= nc;
        pr->shear_rate[l] /= nc;
        pr->inertial[l] /= nc;
        pr->viscosity[l] /= nc;
        pr->exact[l] = NAN;
    }
    if (spec->exact)
        spec->exact(cs, n, pr->coord, pr->exact);
    free(nodes);
    free(cells);
    return 0;
}

double profile_centre_value(const struct profile *pr)
{
    int n = pr->n;
    if (n % 2 == 1)
        return pr->velocity[n / 2];
    return 0.5 * (pr->velocity[n / 2 - 1] + pr->velocity[n / 2]);
}

void profile_errors_default(const struct profile *pr, double exact_centre, struct scene_errors *e)
{
    memset(e, 0, sizeof *e);
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
    e->headline = profile_centre_value(pr);
    e->headline_exact = exact_centre;
    if (!e->valid) {
        e->err_rms = e->err_max = e->err_rms_paper = NAN;
        return;
    }
    e->err_rms = sqrt(sum2 / pr->n);
    e->err_max = emax;
    e->err_rms_paper = sqrt(sum2) / pr->n;
}

int profile_write(const char *dir, const struct profile *pr, char *err, size_t errlen)
{
    struct output_file o;
    if (output_open(&o, dir, "profile.csv", err, errlen) != 0)
        return -1;
    FILE *f = o.f;
    const char *ax = pr->axis == 0 ? "x" : pr->axis == 1 ? "y" : "z";
    const char *vc = pr->component == 0 ? "u" : pr->component == 1 ? "v" : "w";
    fprintf(f, "%s,%s,pressure,shear_rate,inertial_number,viscosity,%s_%s\n", ax, vc, vc,
            pr->exact_name ? pr->exact_name : "exact");
    for (int l = 0; l < pr->n; l++)
        fprintf(f, "%.10g,%.12g,%.10g,%.10g,%.10g,%.10g,%.12g\n", pr->coord[l], pr->velocity[l],
                pr->pressure[l], pr->shear_rate[l], pr->inertial[l], pr->viscosity[l],
                pr->exact[l]);
    return output_commit(&o, err, errlen);
}
