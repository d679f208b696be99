/* Shared helpers of the benchmark programs in bench/: timing statistics,
 * case loading and CSV output into the output folder. */
#ifndef MUFLOW_BENCH_H
#define MUFLOW_BENCH_H

#include <stdio.h>
#include "config/case.h"
#include "grid/decomp.h"

/* Median, minimum and maximum of n samples (x is not modified). */
double bench_median(const double *x, int n);
double bench_min(const double *x, int n);
double bench_max(const double *x, int n);

/* Loads a case file with overrides (printf-style list built by the caller);
 * exits with status 2 and the loader's message on failure. */
void bench_load(struct muflow_case *cs, const char *file, int n, char *const ov[]);

/* The unit cube of N^3 cells (gg) and this rank's block of it (dc, local
 * grid g) over dims (0: MPI's choice), periodic and split as given; exits
 * with status 2 and the cause, named after the program, on failure. */
void bench_blocks(const char *program, int N, const int dims[3], const int periodic[3],
                  const int split[3], struct grid *gg, struct grid *g, struct comm_cart *cart,
                  struct decomp *dc);

/* Opens dir/name for writing; exits on failure. */
FILE *bench_open(const char *dir, const char *name);

/* Creates dir (and parents); exits on failure. */
void bench_mkdir(const char *dir);

/* Seconds of the wall clock (omp_get_wtime). */
double bench_now(void);

/* What other processes take of the machine while a section runs: the busy
 * time of all processors (/proc/stat) less this process's own CPU time and
 * that of the children it has waited for (getrusage: RUSAGE_SELF and
 * RUSAGE_CHILDREN), divided by the wall time, in cores.  Under a load of other
 * processes the 2-thread timings suffer first (an OpenMP barrier waits for
 * the thread that was preempted), so every section reports it. */
struct bench_cpu {
    double wall, busy, own;
};
void bench_cpu_start(struct bench_cpu *c);
double bench_cpu_foreign(const struct bench_cpu *c); /* cores; NAN when unknown */
/* The same as CPU seconds since bench_cpu_start, not clipped at 0 (the
 * /proc/stat ticks are 10 ms: sum it over short intervals, then divide), and
 * the wall seconds in *wall; NAN when unknown. */
double bench_cpu_foreign_seconds(const struct bench_cpu *c, double *wall);

/* How many cores the process really gets: the time of a fixed compute-bound
 * workload (no memory traffic) on 1 thread over its time split across
 * `threads` threads, best of 3.  Ideal: `threads`.  Less means that the
 * virtual machine's processors were not all there (another process, or the
 * host running both on one core: /proc/stat does not always show the latter). */
double bench_parallel_capacity(int threads);

/* Waits (at most max_seconds) until other processes use less than 0.2 cores
 * over half a second; says so on stderr when it waited or gave up. */
void bench_wait_quiet(double max_seconds);

#endif
