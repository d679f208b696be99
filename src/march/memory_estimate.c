/* The memory a run will need, from the case alone or before the march
 * allocates, and the machine's (march.h, march_internal.h;
 * docs/numerics/memory-estimate.md). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>
#include "march_internal.h"

#include "solvers/amg_hypre.h"
#include "solvers/saddle_krylov.h"
#include "solvers/saddle_point.h"
#include "solvers/sparse_direct.h"

/* The kinds that factorise no sparse matrix of the operator (the line
 * blocks' bands and the multigrid's coarsest level aside). */
static int without_factors(enum viscous_precond kind)
{
    return kind == VISCOUS_LINE || kind == VISCOUS_FOURIER || kind == VISCOUS_GMG ||
           kind == VISCOUS_MG;
}

/* What the process holds before the march allocates (libraries, FFTW):
 * the smallest run's peak RSS (docs/numerics/memory-estimate.md). */
#define BASE_BYTES 20e6

/* Bytes the march will allocate on g with the preconditioner kind, from
 * the case alone: the registry's fields (saved copies included) and the
 * optional ones of this case, the pressure solver's two arrays, the viscous
 * solver's work, the sparse factorisation when chosen, and the modules'
 * memory_bound (a body's share bounded from above).  Other modules' own
 * fields are not known before they are created.  Against the peak RSS:
 * docs/numerics/memory-estimate.md. */
double march_memory_estimate(const struct muflow_case *cs, const struct march_setup *su,
                             const struct grid *g, enum viscous_precond kind)
{
    double arrays = 2.0; /* pressure: right-hand side and FFT buffer */
    for (size_t m = 0; m < march_nspecs; m++)
        if (march_spec_wanted(cs, &march_specs[m]))
            arrays += field_arrays(march_specs[m].where) *
                      ((march_specs[m].flags & FIELD_SAVED) ? 2 : 1);
    if (cs->augmentation > 0.0)
        arrays += 1.0;
    if ((kind == VISCOUS_LU || kind == VISCOUS_AMG || kind == VISCOUS_CHOLESKY) && cs->newton)
        arrays += 4.0; /* the full tangent's b terms */
    double bytes = BASE_BYTES + arrays * (double)g->size * sizeof(double) +
                   viscous_memory_estimate(g, &cs->bc, kind);
    for (int l = 0; l < 3; l++)
        for (const struct module *const *m = su->modules[l]; m && *m; m++)
            if ((*m)->memory_bound)
                bytes += (*m)->memory_bound(cs, g);
    int dims = 0;
    for (int d = 0; d < 3; d++)
        dims += g->n[d] > 1;
    if (cs->coupled) {
        /* the coupled step's own solver (the viscous one never solves):
           velocities and pressures, or the AMGs of the velocity block and
           of the pressure's commutator with GMRES's basis */
        long unknowns = 4L * (long)grid_cells(g);
        if (kind == VISCOUS_AMG)
            bytes += amg_hypre_memory_estimate(unknowns) + saddle_krylov_memory_estimate(unknowns);
        else if (kind == VISCOUS_MG) /* the velocity multigrid is viscous_memory_estimate's */
            bytes += saddle_krylov_memory_estimate_mg(unknowns) +
                     saddle_point_matrix_estimate(unknowns, dims);
        else
            bytes += saddle_point_memory_estimate(unknowns, dims);
        return bytes;
    }
    if (kind == VISCOUS_AMG) {
        bytes += amg_hypre_memory_estimate(3L * (long)grid_cells(g));
    } else if (!without_factors(kind)) {
        bytes += sparse_direct_memory_estimate(3L * (long)grid_cells(g), dims);
    }
    return bytes;
}

double march_coupled_gathered_estimate(const struct grid *gg)
{
    int dims = 0;
    for (int d = 0; d < 3; d++)
        dims += gg->n[d] > 1;
    /* probes, responses, the gathered residual and increments, shares,
     * pressures and the pressure columns' copies: 17 arrays of gg */
    return saddle_point_memory_estimate(4L * (long)grid_cells(gg), dims) +
           17.0 * (double)gg->size * sizeof(double);
}

double march_available_memory(void)
{
    /* MUFLOW_AVAILABLE_MEMORY (bytes) stands in for the machine's, so that
     * the refusal can be tested on any machine */
    const char *env = getenv("MUFLOW_AVAILABLE_MEMORY");
    if (env && *env)
        return strtod(env, NULL);
    FILE *f = fopen("/proc/meminfo", "r");
    if (f) {
        char line[256];
        double kb = -1.0;
        while (fgets(line, sizeof line, f))
            if (sscanf(line, "MemAvailable: %lf kB", &kb) == 1)
                break;
        fclose(f);
        if (kb >= 0.0)
            return kb * 1024.0;
    }
    long pages = sysconf(_SC_AVPHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    return pages > 0 && size > 0 ? (double)pages * (double)size : 0.0;
}

/* "12.3 GB", "353 MB" */
static void format_bytes(char *out, size_t len, double b)
{
    if (b >= 1e9)
        snprintf(out, len, "%.1f GB", b / 1e9);
    else
        snprintf(out, len, "%.0f MB", b / 1e6);
}

/* The preconditioner and the estimate of the case on g (amg: see
 * march_amg_allowed).  Auto's coupled LU that does not fit in avail gives
 * way to the coupled GMRES where that is allowed and fits
 * (docs/numerics/coupled-step.md). */
double march_plan(const struct muflow_case *cs, const struct march_setup *su,
                  const struct grid *g, int amg, double avail, enum viscous_precond *kind)
{
    *kind = march_choose_preconditioner(cs, su, g, amg);
    double bytes = march_memory_estimate(cs, su, g, *kind);
    if (cs->coupled && cs->preconditioner == PRECOND_AUTO && *kind == VISCOUS_LU &&
        avail > 0.0 && bytes > avail && !saddle_krylov_refusal(cs->rheo.law, &cs->bc)) {
        double gmres = march_memory_estimate(cs, su, g, VISCOUS_AMG);
        if (gmres <= avail && march_amg_allowed(amg)) {
            *kind = VISCOUS_AMG;
            bytes = gmres;
        }
    }
    return bytes;
}

/* The refusal of a run that needs more than avail: one line naming the
 * grid keys. */
void march_memory_refusal(char *err, size_t errlen, const struct grid *g,
                          enum viscous_precond kind, double need, double avail)
{
    char needs[32], have[32];
    format_bytes(needs, sizeof needs, need);
    format_bytes(have, sizeof have, avail);
    snprintf(err, errlen,
             "%s = %d x %d x %d: the run needs about %s "
             "(fields, solver work%s), more than the %s of memory available on this machine",
             grid_stretched(g) ? "the cells with the domain's bands (domain.x_band, "
                                 "domain.y_band, domain.z_band)"
                               : "domain.nx x domain.ny x domain.nz",
             g->n[0], g->n[1], g->n[2], needs, without_factors(kind) ? "" : ", sparse factorisation",
             have);
}

int march_memory_check(const struct muflow_case *cs, const struct march_setup *su, char *msg,
                       size_t msglen)
{
    double avail = march_available_memory();
    struct grid g;
    int periodic[3];
    bc_periodic_flags(&cs->bc, periodic);
    if (!(avail > 0.0) || grid_init_compact(&g, cs->n, cs->len, periodic) != 0)
        return 0; /* nothing known, or a grid march_create refuses itself */
    struct grid_axis axes[3];
    int built[3] = {0, 0, 0}, ok = 1;
    for (int d = 0; d < 3; d++) {
        char why[300];
        int r = case_axis(cs, d, &axes[d], why, sizeof why);
        built[d] = r > 0;
        ok &= r >= 0 && (r == 0 || grid_set_axis(&g, d, &axes[d]) == 0);
    }
    int refused = 0;
    if (ok) {
        /* without opening hypre's library: the smaller of the two choices */
        enum viscous_precond with, without;
        double need_with = march_plan(cs, su, &g, 1, avail, &with);
        double need_without = march_plan(cs, su, &g, 0, avail, &without);
        double need = fmin(need_with, need_without);
        if (need > avail) {
            march_memory_refusal(msg, msglen, &g, need_with <= need_without ? with : without,
                                 need, avail);
            refused = 1;
        }
    }
    for (int d = 0; d < 3; d++)
        if (built[d])
            grid_axis_free(&axes[d]);
    return refused;
}
