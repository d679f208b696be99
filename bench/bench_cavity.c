/* bench_cavity -- Bingham cavity study: runs cases/bingham_cavity.ini at several Bingham
 * numbers and writes, per run, the cell fields (velocity at centres, |tau|
 * and whether the material yields, |tau| >= tau_0) and the mid-line profile,
 * plus a table of psi_max, err_midline, steps and wall time (cavity_table.csv,
 * and a copy per resolution, cavity_table_nN.csv, for bench/report.py).
 * usage: bench_cavity OUTDIR N [SECTION.KEY=VALUE...] BN... (BN in muflow's
 * convention; the key=value arguments override the case file for every run) */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "scenes/bingham_cavity.h"
#include "app/run.h"
#include "scenes/scene.h"
#include "march/march.h"
#include "diagnostics/profile.h"

static int write_fields(const char *dir, double bn, const struct march_state *st)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/cavity_fields_bn%g.csv", dir, bn);
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    const struct grid *g = &st->g;
    fprintf(f, "x,z,u,w,stress,yielded\n");
    for (int k = 0; k < g->n[2]; k++)
        for (int i = 0; i < g->n[0]; i++) {
            ptrdiff_t p = grid_idx(g, i, 0, k);
            double u = 0.5 * (st->field.velocity[0][p] + st->field.velocity[0][p + g->stride[0]]);
            double w = 0.5 * (st->field.velocity[2][p] + st->field.velocity[2][p + g->stride[2]]);
            /* |tau| = sqrt(tau:tau / 2) = eta |D| in muflow's convention */
            double tau = st->field.viscosity[p] * sqrt(st->field.shear2[p]);
            fprintf(f, "%.6g,%.6g,%.8g,%.8g,%.8g,%d\n", (i + 0.5) * g->h[0], (k + 0.5) * g->h[2],
                    u, w, tau, tau >= st->cs->rheo.yield_stress);
        }
    return fclose(f);
}

int main(int argc, char **argv)
{
    run_init();
    if (argc < 4) {
        fprintf(stderr, "usage: bench_cavity OUTDIR N [SECTION.KEY=VALUE...] BN...\n");
        return 2;
    }
    const char *dir = argv[1];
    int n = atoi(argv[2]);
    char table[1024], table_n[1024];
    snprintf(table, sizeof table, "%s/cavity_table.csv", dir);
    snprintf(table_n, sizeof table_n, "%s/cavity_table_n%d.csv", dir, n);
    FILE *tfs[2] = {fopen(table, "w"), fopen(table_n, "w")};
    if (!tfs[0] || !tfs[1])
        return 1;
    char *ov[16] = {NULL, NULL, NULL, "output.quiet=on"};
    int nov = 4;
    for (int a = 3; a < argc && nov < 16; a++)
        if (strchr(argv[a], '='))
            ov[nov++] = argv[a];
    for (int t = 0; t < 2; t++)
        fprintf(tfs[t], "n,bn,bn_vola,status,steps,wall_seconds,psi_max,psi_max_vola,"
                        "err_midline,rejected\n");
    for (int a = 3; a < argc; a++) {
        if (strchr(argv[a], '='))
            continue;
        double bn = atof(argv[a]);
        char o1[64], o2[64], o3[64];
        snprintf(o1, sizeof o1, "domain.nx=%d", n);
        snprintf(o2, sizeof o2, "domain.nz=%d", n);
        snprintf(o3, sizeof o3, "rheology.yield_stress=%.17g", bn);
        ov[0] = o1, ov[1] = o2, ov[2] = o3;
        static struct muflow_case cs;
        char err[512];
        if (case_load(&cs, "cases/bingham_cavity.ini", nov, ov, err, sizeof err) != 0) {
            fprintf(stderr, "%s\n", err);
            return 2;
        }
        struct march_state st;
        if (scene_march_create(&st, &cs, NULL, err, sizeof err) != 0) {
            fprintf(stderr, "%s\n", err);
            return 1;
        }
        double t0 = omp_get_wtime();
        march_run(&st, NULL, NULL);
        double wall = omp_get_wtime() - t0;
        struct profile pr;
        struct scene_errors e;
        if (scene_profile(&pr, &st) != 0)
            return 1;
        scene_profile_errors(&pr, &st, &e);
        char path[1024];
        snprintf(path, sizeof path, "%s/cavity_midline_bn%g.csv", dir, bn);
        FILE *f = fopen(path, "w");
        if (!f)
            return 1;
        fprintf(f, "z,u\n");
        for (int l = 0; l < pr.n; l++)
            fprintf(f, "%.8g,%.10g\n", pr.coord[l], pr.velocity[l]);
        fclose(f);
        write_fields(dir, bn, &st);
        for (int t = 0; t < 2; t++) {
            fprintf(tfs[t], "%d,%g,%g,%s,%ld,%.3f,%.6g,%.6g,%.6g,%ld\n", n, bn,
                    cavity_reference_bn(&cs), run_status_name(st.status), st.step, wall,
                    e.headline, e.headline_exact, e.err_rms, st.rejected);
            fflush(tfs[t]);
        }
        printf("cavity %dx%d Bn %-8g (Vola %-8g): %s in %ld steps (%ld rejected), %.2f s, "
               "psi_max %.5f (Vola %.5f), err_midline %.4f\n",
               n, n, bn, cavity_reference_bn(&cs), run_status_name(st.status), st.step,
               st.rejected, wall, e.headline, e.headline_exact, e.err_rms);
        fflush(stdout);
        profile_free(&pr);
        march_destroy(&st);
    }
    int bad = fclose(tfs[0]) != 0;
    return fclose(tfs[1]) != 0 || bad;
}
