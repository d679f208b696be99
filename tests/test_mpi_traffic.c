/* One bagnold3d step's traffic over the ranks against its model
 * (march/traffic_model.h), in the group mpi (test_mpi.c).  Skipped on one
 * rank.
 *
 * muflow's own tallies (decomp_traffic_read, decomp_collectives_read)
 * count the halo planes, the sums and the all-to-alls it sends.  FFTW's
 * MPI library sends its transposes itself: this executable defines the
 * MPI calls that library makes (MPI_Alltoall, MPI_Alltoallv, MPI_Sendrecv,
 * MPI_Send), exported (the Makefile's --export-dynamic-symbol), so that
 * its calls bind here first; each counts what goes to another rank and
 * hands the call to libmpi's PMPI_ entry.  muflow's own calls go to libmpi
 * by dlsym on its handle (platform/comm.c) and are not seen here. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "app/run.h"
#include "grid/decomp.h"
#include "march/traffic_model.h"
#include "platform/comm.h"
#include "solvers/viscous.h"
#include "test_main.h"
#include "test_util.h"

/* the Makefile passes libmpi's soname (as to platform/comm.c) */
#ifndef MUFLOW_MPI_LIB
#define MUFLOW_MPI_LIB "libmpi.so.40"
#endif

/* ---- the third parties' MPI calls, counted ------------------------------------------- */

static struct {
    int on;
    long messages, bytes;
} seen;

/* libmpi's entry `name`: in the global scope under mpirun (platform/comm.c
 * opens it so), else where a library that needs it (hypre) loaded it. */
static void *real(const char *name)
{
    void *f = dlsym(RTLD_DEFAULT, name);
    if (!f) {
        void *lib = dlopen(MUFLOW_MPI_LIB, RTLD_LAZY | RTLD_NOLOAD);
        f = lib ? dlsym(lib, name) : NULL;
    }
    if (!f) {
        fprintf(stderr, "test_mpi_traffic: no %s in libmpi\n", name);
        abort();
    }
    return f;
}
#define REAL(f) ((__typeof__(&P##f))real("P" #f))

static long type_bytes(MPI_Datatype t)
{
    int s = 0;
    REAL(MPI_Type_size)(t, &s);
    return s;
}

static int rank_in(MPI_Comm c)
{
    int r = 0;
    REAL(MPI_Comm_rank)(c, &r);
    return r;
}

static void count(long bytes)
{
    if (seen.on && bytes > 0) {
        seen.messages++;
        seen.bytes += bytes;
    }
}

int MPI_Alltoall(const void *sb, int sc, MPI_Datatype st, void *rb, int rc, MPI_Datatype rt,
                 MPI_Comm comm)
{
    int P = 1;
    REAL(MPI_Comm_size)(comm, &P);
    for (int r = 0; r < P; r++)
        if (r != rank_in(comm))
            count((long)sc * type_bytes(st));
    return REAL(MPI_Alltoall)(sb, sc, st, rb, rc, rt, comm);
}

int MPI_Alltoallv(const void *sb, const int sc[], const int sd[], MPI_Datatype st, void *rb,
                  const int rc[], const int rd[], MPI_Datatype rt, MPI_Comm comm)
{
    int P = 1;
    REAL(MPI_Comm_size)(comm, &P);
    for (int r = 0; r < P; r++)
        if (r != rank_in(comm))
            count((long)sc[r] * type_bytes(st));
    return REAL(MPI_Alltoallv)(sb, sc, sd, st, rb, rc, rd, rt, comm);
}

int MPI_Sendrecv(const void *sb, int sc, MPI_Datatype st, int dest, int stag, void *rb, int rc,
                 MPI_Datatype rt, int src, int rtag, MPI_Comm comm, MPI_Status *status)
{
    if (dest != rank_in(comm) && dest != MPI_PROC_NULL)
        count((long)sc * type_bytes(st));
    return REAL(MPI_Sendrecv)(sb, sc, st, dest, stag, rb, rc, rt, src, rtag, comm, status);
}

int MPI_Send(const void *b, int c, MPI_Datatype t, int dest, int tag, MPI_Comm comm)
{
    if (dest != rank_in(comm) && dest != MPI_PROC_NULL)
        count((long)c * type_bytes(t));
    return REAL(MPI_Send)(b, c, t, dest, tag, comm);
}

/* ---- a run's steps against the model ------------------------------------------------ */

struct watch {
    long steps, misses, solves, last_step;
    struct step_traffic worst_measured, worst_model; /* the first step that missed */
    long setups, iterations;
};

static long differs(const struct step_traffic *a, const struct step_traffic *b)
{
    return (memcmp(&a->halo, &b->halo, sizeof a->halo) != 0) +
           (memcmp(&a->coll, &b->coll, sizeof a->coll) != 0) +
           (a->fft_messages != b->fft_messages) + (a->fft_bytes != b->fft_bytes);
}

/* At each observation after a step: that step's tallies and FFTW's calls
 * (seen since the last observation) against the model of its events. */
static void observe(void *vctx, const struct march_state *st)
{
    struct watch *w = vctx;
    if (st->step > w->last_step && st->step > 0) {
        struct viscous_precond_info info;
        viscous_precond_info(st->viscous, &info);
        const struct step_events ev = {st->linear_iterations, !info.reused,
                                       st->pressure_solves - w->solves};
        struct step_traffic model, measured = {st->step_halo, st->step_collectives,
                                               seen.messages, seen.bytes};
        const int covered = march_step_traffic_model(st, &ev, &model) == 0;
        const long miss = !covered || st->rejected > 0 || differs(&measured, &model);
        if (miss && w->misses == 0) {
            w->worst_measured = measured;
            w->worst_model = model;
        }
        w->misses += miss;
        w->steps++;
        w->setups += ev.setups;
        w->iterations += ev.iterations;
    }
    w->last_step = st->step;
    w->solves = st->pressure_solves;
    seen.messages = seen.bytes = 0;
}

static void print_traffic(const char *what, const struct step_traffic *t)
{
    printf("      %s: halo %ld exchanges %ld messages %ld B; %ld sums (%ld values); %ld "
           "all-to-alls %ld messages %ld B; FFTW %ld executions %ld messages %ld B\n",
           what, t->halo.exchanges, t->halo.messages, t->halo.bytes, t->coll.reductions,
           t->coll.reduced_values, t->coll.alltoalls, t->coll.alltoall_messages,
           t->coll.alltoall_bytes, t->coll.fft_executions, t->fft_messages, t->fft_bytes);
}

/* bagnold3d's small grid (8 x 8 x 16) and an uneven one (10 x 6), split as
 * MPI_Dims_create does (2 ranks: along x, the Fourier blocks' lines their
 * slabs, no all-to-all; 4: 2 x 2, FFTW's slabs of 3 rows cutting the blocks
 * of 5) and along x alone (4 ranks: blocks of 3, 3, 2, 2 against FFTW's 3,
 * 3, 3, 1), 4 steps each (set-ups and reuses of the Fourier blocks): every
 * step's tallies equal the model's. */
void test_bagnold3d_traffic(void **state)
{
    (void)state;
    if (comm_size() < 2)
        skip();
    char *grids[2][6] = {
        {"domain.nx=8", "domain.ny=8", "domain.nz=16", "domain.lx=7", "domain.ly=7",
         "solver.max_steps=4"},
        {"domain.nx=10", "domain.ny=6", "domain.nz=16", "domain.lx=8.75", "domain.ly=5.25",
         "solver.max_steps=4"}};
    double misses = 0.0;
    for (int s = 0; s < 3; s++) {
        struct muflow_case cs;
        test_load_case(&cs, "../cases/bagnold3d.ini", 6, grids[s > 0]);
        struct watch w = {.last_step = -1};
        const struct run_options opt = {.hook = observe, .hook_ctx = &w,
                                        .dims = {s == 2 ? comm_size() : 0, s == 2, 1}};
        struct run_result res;
        char err[1024] = "";
        seen.on = 1;
        const int rc = run_case_opts(&cs, &opt, &res, err, sizeof err);
        seen.on = 0;
        if (rc != RUN_OK)
            print_error("%s\n", err);
        const double bad = rc != RUN_OK || w.steps != 4 || w.misses > 0;
        double all[2] = {bad, (double)w.misses};
        comm_sum(all, 2);
        if (comm_rank() == 0) {
            printf("    %s %s on %d ranks%s: %ld steps (%ld CG iterations, %ld set-ups), %.0f "
                   "steps' traffic off the model (all ranks)\n",
                   grids[s > 0][0], grids[s > 0][1], comm_size(), s == 2 ? " along x" : "",
                   w.steps, w.iterations, w.setups, all[1]);
            if (w.misses > 0) {
                print_traffic("measured", &w.worst_measured);
                print_traffic("model", &w.worst_model);
            }
        }
        misses += all[0];
    }
    assert_true(misses == 0.0);
}
