/* bagnold3d's steps on MPI ranks (docs/numerics/decomposition.md): each
 * step's traffic of this rank, measured (grid/decomp.h's tallies) and by
 * its model (march/traffic_model.h; FFTW's own transposes by the model
 * alone: tests/test_mpi_traffic.c measures them on small grids), the
 * step's wall seconds and the shares of them rank 0 spent in MPI's calls
 * (halo shifts, sums and maxima, all-to-alls, FFTW's MPI executions, with
 * their transforms), and every rank's peak resident memory and its bytes
 * per local cell.
 *   mpirun -np P bench_step_traffic CASE [key=value ...]
 * `make bench-fourier-ranks` runs bagnold3d 128 x 128 x 64 on 2 ranks. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include "app/run.h"
#include "bench.h"
#include "march/traffic_model.h"
#include "platform/comm.h"
#include "solvers/viscous.h"

struct watch {
    long last_step, solves;
    double t0;
    struct comm_waits w0;
};

static void observe(void *vctx, const struct march_state *st)
{
    struct watch *w = vctx;
    const double now = comm_clock();
    struct comm_waits wt;
    comm_waits_read(&wt);
    if (st->step > w->last_step && st->step > 0 && st->rejected == 0) {
        struct viscous_precond_info info;
        viscous_precond_info(st->viscous, &info);
        const struct step_events ev = {st->linear_iterations, !info.reused,
                                       st->pressure_solves - w->solves};
        struct step_traffic m;
        const int covered = march_step_traffic_model(st, &ev, &m) == 0;
        const struct decomp_traffic *h = &st->step_halo;
        const struct comm_traffic *c = &st->step_collectives;
        const double wall = now - w->t0;
        if (comm_rank() == 0) {
            printf("step %ld: %ld CG iterations, %ld set-up, %ld pressure solves; wall %.3f s, "
                   "in MPI: halo %.1f%%, sums %.1f%%, all-to-alls %.1f%%, FFTW %.1f%%\n",
                   st->step, ev.iterations, ev.setups, ev.pressure_solves, wall,
                   100.0 * (wt.shifts - w->w0.shifts) / wall,
                   100.0 * (wt.reductions - w->w0.reductions) / wall,
                   100.0 * (wt.alltoalls - w->w0.alltoalls) / wall,
                   100.0 * (wt.fft - w->w0.fft) / wall);
            printf("  rank 0 measured: halo %ld exchanges, %ld messages, %.3f MB; %ld sums "
                   "(%ld values); %ld all-to-alls, %ld messages, %.3f MB; %ld FFTW executions\n",
                   h->exchanges, h->messages, 1e-6 * h->bytes, c->reductions, c->reduced_values,
                   c->alltoalls, c->alltoall_messages, 1e-6 * c->alltoall_bytes,
                   c->fft_executions);
            if (covered)
                printf("  rank 0 model:    halo %ld exchanges, %ld messages, %.3f MB; %ld sums "
                       "(%ld values); %ld all-to-alls, %ld messages, %.3f MB; %ld FFTW "
                       "executions, their transposes %ld messages, %.3f MB (%s)\n",
                       m.halo.exchanges, m.halo.messages, 1e-6 * m.halo.bytes, m.coll.reductions,
                       m.coll.reduced_values, m.coll.alltoalls, m.coll.alltoall_messages,
                       1e-6 * m.coll.alltoall_bytes, m.coll.fft_executions, m.fft_messages,
                       1e-6 * m.fft_bytes,
                       memcmp(&m.halo, h, sizeof *h) == 0 && memcmp(&m.coll, c, sizeof *c) == 0
                           ? "= measured" : "OFF the measured");
        }
    }
    w->last_step = st->step;
    w->solves = st->pressure_solves;
    w->t0 = comm_clock();
    comm_waits_read(&w->w0);
}

int main(int argc, char **argv)
{
    char err[1024] = "";
    if (argc < 2 || comm_init(err, sizeof err) != 0) {
        fprintf(stderr, "usage: mpirun -np P bench_step_traffic CASE [key=value ...] %s\n", err);
        return 2;
    }
    struct muflow_case cs;
    bench_load(&cs, argv[1], argc - 2, argv + 2);
    struct watch w = {.last_step = -1};
    const struct run_options opt = {.hook = observe, .hook_ctx = &w};
    struct run_result res;
    if (run_case_opts(&cs, &opt, &res, err, sizeof err) != RUN_OK) {
        fprintf(stderr, "bench_step_traffic: %s\n", err);
        return 1;
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    const long cells = (long)cs.n[0] * cs.n[1] * cs.n[2];
    double rss[2] = {ru.ru_maxrss / 1024.0, 0.0};
    double most = rss[0];
    comm_max(&most, 1);
    rss[1] = rss[0];
    comm_sum(rss + 1, 1);
    if (comm_rank() == 0)
        printf("peak RSS a rank: %.0f MB at most (%.0f on the %d ranks), %.0f B a local cell "
               "(%ld cells, %d ranks)\n", most, rss[1], comm_size(),
               most * 1048576.0 / ((double)cells / comm_size()), cells, comm_size());
    return 0;
}
