/* Shared helpers of the benchmark programs (bench.h). */
#define _POSIX_C_SOURCE 200809L /* sysconf, nanosleep */
#include <errno.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>
#include "bench.h"
#include "app/run.h"
#include "io/output.h"

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double bench_median(const double *x, int n)
{
    if (n <= 0)
        return 0.0;
    double *s = malloc((size_t)n * sizeof *s);
    if (!s) {
        fprintf(stderr, "bench: out of memory\n");
        exit(1);
    }
    memcpy(s, x, (size_t)n * sizeof *s);
    qsort(s, (size_t)n, sizeof *s, cmp_double);
    double m = n % 2 ? s[n / 2] : 0.5 * (s[n / 2 - 1] + s[n / 2]);
    free(s);
    return m;
}

double bench_min(const double *x, int n)
{
    double m = x[0];
    for (int i = 1; i < n; i++)
        if (x[i] < m)
            m = x[i];
    return m;
}

double bench_max(const double *x, int n)
{
    double m = x[0];
    for (int i = 1; i < n; i++)
        if (x[i] > m)
            m = x[i];
    return m;
}

void bench_blocks(const char *program, int N, const int dims[3], const int periodic[3],
                  const int split[3], struct grid *gg, struct grid *g, struct comm_cart *cart,
                  struct decomp *dc)
{
    char err[256] = "";
    const int n[3] = {N, N, N};
    const double len[3] = {1.0, 1.0, 1.0};
    if (grid_init(gg, n, len) != 0 ||
        comm_cart_create(cart, dims, periodic, split, err, sizeof err) ||
        decomp_create(dc, cart, n, err, sizeof err) || decomp_local_grid(dc, gg, g)) {
        fprintf(stderr, "%s: %s\n", program, err);
        exit(2);
    }
}

void bench_load(struct muflow_case *cs, const char *file, int n, char *const ov[])
{
    char err[512];
    run_init(); /* the scenes case_load reads case.scene against */
    if (case_load(cs, file, n, ov, err, sizeof err) != 0) {
        fprintf(stderr, "bench: %s\n", err);
        exit(2);
    }
    cs->quiet = 1;
}

void bench_mkdir(const char *dir)
{
    char err[512];
    if (output_make_dir(dir, err, sizeof err) != 0) {
        fprintf(stderr, "bench: %s\n", err);
        exit(2);
    }
}

FILE *bench_open(const char *dir, const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "bench: cannot write %s: %s\n", path, strerror(errno));
        exit(2);
    }
    return f;
}

double bench_now(void) { return omp_get_wtime(); }

/* Busy seconds of all processors since boot, or NAN. */
static double busy_seconds(void)
{
    FILE *f = fopen("/proc/stat", "r");
    if (!f)
        return NAN;
    unsigned long long v[8] = {0};
    int n = fscanf(f, "cpu %llu %llu %llu %llu %llu %llu %llu %llu", &v[0], &v[1], &v[2], &v[3],
                   &v[4], &v[5], &v[6], &v[7]);
    fclose(f);
    if (n < 7)
        return NAN;
    /* user nice system [idle iowait] irq softirq steal */
    double ticks = (double)(v[0] + v[1] + v[2] + v[5] + v[6] + (n > 7 ? v[7] : 0));
    long hz = sysconf(_SC_CLK_TCK);
    return hz > 0 ? ticks / (double)hz : NAN;
}

static double rusage_seconds(int who)
{
    struct rusage ru;
    getrusage(who, &ru);
    return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
           (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
}

/* this process and the children it has waited for (bench_process's runs) */
static double own_seconds(void)
{
    return rusage_seconds(RUSAGE_SELF) + rusage_seconds(RUSAGE_CHILDREN);
}

void bench_cpu_start(struct bench_cpu *c)
{
    c->wall = bench_now();
    c->busy = busy_seconds();
    c->own = own_seconds();
}

double bench_cpu_foreign_seconds(const struct bench_cpu *c, double *wall)
{
    *wall = bench_now() - c->wall;
    double busy = busy_seconds() - c->busy, own = own_seconds() - c->own;
    return isfinite(busy) ? busy - own : NAN;
}

double bench_cpu_foreign(const struct bench_cpu *c)
{
    double wall, s = bench_cpu_foreign_seconds(c, &wall);
    if (!(wall > 0.0) || !isfinite(s))
        return NAN;
    double f = s / wall;
    return f > 0.0 ? f : 0.0;
}

void bench_wait_quiet(double max_seconds)
{
    double t0 = bench_now(), f = NAN;
    for (;;) {
        struct bench_cpu c;
        bench_cpu_start(&c);
        nanosleep(&(struct timespec){0, 500000000L}, NULL);
        f = bench_cpu_foreign(&c);
        if (!isfinite(f) || f < 0.2)
            break;
        if (bench_now() - t0 > max_seconds) {
            fprintf(stderr, "bench: other processes keep using %.2f cores: timings will be "
                            "noisy\n", f);
            return;
        }
    }
    if (bench_now() - t0 > 0.6)
        fprintf(stderr, "bench: waited %.0f s for other processes to quieten\n", bench_now() - t0);
}

/* A dependent chain of n multiply-adds: about 4 cycles each, no memory. */
static double chain(long n, double x)
{
    for (long i = 0; i < n; i++)
        x = x * 0.999999999 + 1e-9;
    return x;
}

static volatile double capacity_sink;

double bench_parallel_capacity(int threads)
{
    const long n = 20000000L; /* per thread: about 30 ms */
    double best1 = 1e300, bestp = 1e300;
    for (int r = 0; r < 3; r++) {
        double t0 = bench_now();
        double x = 1.0;
        for (int t = 0; t < threads; t++)
            x += chain(n, (double)t);
        capacity_sink = x;
        double t1 = bench_now() - t0;
        if (t1 < best1)
            best1 = t1;
        t0 = bench_now();
        double s = 0.0;
#pragma omp parallel for num_threads(threads) schedule(static, 1) reduction(+ : s)
        for (int t = 0; t < threads; t++)
            s += chain(n, (double)t);
        capacity_sink = s;
        double tp = bench_now() - t0;
        if (tp < bestp)
            bestp = tp;
    }
    return bestp > 0.0 ? best1 / bestp : NAN;
}
