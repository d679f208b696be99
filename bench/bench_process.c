/* Whole-process speed of the command a user runs: `build/muflow CASE.ini`
 * forked and executed, timed from before fork to the return of wait4
 * (clock_gettime, CLOCK_MONOTONIC), with the child's CPU time from wait4's
 * rusage.  Outputs are written as a user's run writes them (the same
 * output.dir for every run of a case, under OUTDIR/proc/).
 *
 *   bench_process OUTDIR [repeats [muflow]]        (default 21, build/muflow)
 *
 * Two sections, each after one warm-up run per case and configuration:
 *   load:    bagnold H/40 (cases/bagnold.ini as shipped) and chute b/160
 *            (cases/chute.ini domain.ny=160), 2 threads, idle and with one
 *            spinning process (a forked child in a busy loop, this program's
 *            own: SIGCONT before a loaded run, SIGSTOP after it);
 *   threads: every profile scene (bagnold; chute as shipped with each of the
 *            four regularisations; bingham_channel; couette) at 1 and at 2
 *            threads (OMP_NUM_THREADS in the child's environment), the
 *            spinning process stopped.
 * The configurations alternate run by run (their order reversed every other
 * repeat), so a drift of the machine's load hits them alike.  Each run
 * records the CPU seconds other processes used during it (bench.h: /proc/stat
 * less this process and its waited-for children; the spinning process, not
 * yet waited for, counts as another process and is also given on its own from
 * /proc/PID/stat).  Writes OUTDIR/process_runs.csv (one row a run) and
 * OUTDIR/process_meta.csv; bench/report.py computes the medians, spreads and
 * ratios. */
#define _GNU_SOURCE /* prctl's PR_SET_PDEATHSIG, wait4 */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include "bench.h"

extern char **environ;

#define RUN_TIMEOUT 60 /* seconds: a run still going is killed (exit "timeout") */

struct pcase {
    const char *label, *ini;
    const char *ov[2];
    int nov;
};

static const struct pcase load_cases[] = {
    {"bagnold", "cases/bagnold.ini", {NULL}, 0},
    {"chute_b160", "cases/chute.ini", {"domain.ny=160"}, 1},
};
#define NLOAD (int)(sizeof load_cases / sizeof load_cases[0])

static const struct pcase thread_cases[] = {
    {"bagnold", "cases/bagnold.ini", {NULL}, 0},
    {"chute_simple", "cases/chute.ini", {"rheology.regularisation=simple"}, 1},
    {"chute_bercovier", "cases/chute.ini", {"rheology.regularisation=bercovier"}, 1},
    {"chute_papanastasiou", "cases/chute.ini", {"rheology.regularisation=papanastasiou"}, 1},
    {"chute_mc", "cases/chute.ini", {"rheology.regularisation=mc"}, 1},
    {"bingham_channel", "cases/bingham_channel.ini", {NULL}, 0},
    {"couette", "cases/couette.ini", {NULL}, 0},
};
#define NTHREAD (int)(sizeof thread_cases / sizeof thread_cases[0])

static const char *muflow = "build/muflow";
static const char *outdir;
static char **env_threads[3]; /* [1], [2]: the environment with OMP_NUM_THREADS set */
static pid_t spinner = -1;
static volatile sig_atomic_t running_child = 0;

struct sample {
    double wall, user, sys, foreign, spinner;
    long nivcsw, maxrss;
    int exit_code; /* exit status, 128 + signal, -1 timeout/fork failure */
};

static double mono_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void on_alarm(int sig)
{
    (void)sig;
    if (running_child > 0)
        kill((pid_t)running_child, SIGKILL);
}

/* environ with OMP_NUM_THREADS=n (replaced or added), built before any fork */
static char **env_with_threads(int n)
{
    size_t k = 0;
    while (environ[k])
        k++;
    char **e = calloc(k + 2, sizeof *e);
    char *var = malloc(32);
    if (!e || !var) {
        fprintf(stderr, "bench: out of memory\n");
        exit(1);
    }
    snprintf(var, 32, "OMP_NUM_THREADS=%d", n);
    size_t j = 0;
    for (size_t i = 0; i < k; i++)
        if (strncmp(environ[i], "OMP_NUM_THREADS=", 16) != 0)
            e[j++] = environ[i];
    e[j++] = var;
    e[j] = NULL;
    return e;
}

/* CPU seconds of the spinning process so far (/proc/PID/stat), or NAN */
static double spinner_seconds(void)
{
    if (spinner <= 0)
        return NAN;
    char path[64], buf[1024];
    snprintf(path, sizeof path, "/proc/%d/stat", (int)spinner);
    FILE *f = fopen(path, "r");
    if (!f)
        return NAN;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    char *p = strrchr(buf, ')'); /* after the command name */
    unsigned long long ut, st;
    if (!p || sscanf(p + 2, "%*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %llu %llu", &ut,
                     &st) != 2)
        return NAN;
    long hz = sysconf(_SC_CLK_TCK);
    return hz > 0 ? (double)(ut + st) / (double)hz : NAN;
}

static void start_spinner(void)
{
    pid_t parent = getpid();
    spinner = fork();
    if (spinner == 0) {
        prctl(PR_SET_PDEATHSIG, SIGKILL); /* never outlives the benchmark */
        if (getppid() != parent)
            _exit(0);
        volatile unsigned long x = 0;
        for (;;)
            x++;
    }
    if (spinner < 0) {
        fprintf(stderr, "bench: fork of the spinning process failed: %s\n", strerror(errno));
        exit(1);
    }
    kill(spinner, SIGSTOP);
}

static void spin(int on)
{
    kill(spinner, on ? SIGCONT : SIGSTOP);
    if (on) /* let it be running, not just woken, when the run starts */
        nanosleep(&(struct timespec){0, 20000000L}, NULL);
}

static double loadavg1(void)
{
    double l = NAN;
    FILE *f = fopen("/proc/loadavg", "r");
    if (f) {
        if (fscanf(f, "%lf", &l) != 1)
            l = NAN;
        fclose(f);
    }
    return l;
}

static void run_once(const struct pcase *c, int threads, struct sample *s)
{
    char od[1200], errpath[1200];
    snprintf(od, sizeof od, "output.dir=%s/proc/%s", outdir, c->label);
    snprintf(errpath, sizeof errpath, "%s/proc/%s.stderr", outdir, c->label);
    char *argv[8];
    int a = 0;
    argv[a++] = (char *)muflow;
    argv[a++] = (char *)c->ini;
    for (int i = 0; i < c->nov; i++)
        argv[a++] = (char *)c->ov[i];
    argv[a++] = od;
    argv[a] = NULL;
    memset(s, 0, sizeof *s);
    s->exit_code = -1;
    struct bench_cpu cpu;
    double sp0 = spinner_seconds();
    bench_cpu_start(&cpu);
    double t0 = mono_now();
    pid_t pid = fork();
    if (pid == 0) {
        int dn = open("/dev/null", O_WRONLY);
        int de = open(errpath, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (dn >= 0)
            dup2(dn, 1);
        if (de >= 0)
            dup2(de, 2);
        execve(muflow, argv, env_threads[threads]);
        _exit(127);
    }
    if (pid < 0) {
        fprintf(stderr, "bench: fork failed: %s\n", strerror(errno));
        return;
    }
    running_child = pid;
    alarm(RUN_TIMEOUT);
    int status = 0;
    struct rusage ru;
    pid_t w;
    while ((w = wait4(pid, &status, 0, &ru)) < 0 && errno == EINTR)
        ;
    double t1 = mono_now();
    alarm(0);
    running_child = 0;
    double wall;
    s->foreign = bench_cpu_foreign_seconds(&cpu, &wall);
    s->spinner = spinner_seconds() - sp0;
    if (w != pid)
        return;
    s->wall = t1 - t0;
    s->user = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec;
    s->sys = (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
    s->nivcsw = ru.ru_nivcsw;
    s->maxrss = ru.ru_maxrss;
    if (WIFEXITED(status))
        s->exit_code = WEXITSTATUS(status);
    else if (WIFSIGNALED(status))
        s->exit_code = 128 + WTERMSIG(status);
}

static FILE *runs_csv;

static void record(const char *section, const struct pcase *c, const char *cond, int threads,
                   int rep, const struct sample *s)
{
    fprintf(runs_csv, "%s,%s,%s,%d,%d,%.6e,%.6e,%.6e,%ld,%ld,%d,%.4f,%.4f\n", section, c->label,
            cond, threads, rep, s->wall, s->user, s->sys, s->nivcsw, s->maxrss, s->exit_code,
            s->foreign, s->spinner);
    fflush(runs_csv);
    if (s->exit_code != 0)
        fprintf(stderr, "  %s %s %s %d threads: exit %d (see %s/proc/%s.stderr)\n", section,
                c->label, cond, threads, s->exit_code, outdir, c->label);
}

/* per section: at least 3 repeats, then no new repeat after `budget` seconds */
static int keep_going(int rep, double start, double budget)
{
    return rep < 3 || mono_now() - start < budget;
}

static void print_median(const char *what, double *x, int n)
{
    if (n > 0)
        fprintf(stderr, "    %-36s %8.1f ms (median of %d, %.1f-%.1f)\n", what,
                1e3 * bench_median(x, n), n, 1e3 * bench_min(x, n), 1e3 * bench_max(x, n));
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s OUTDIR [repeats [muflow]]\n", argv[0]);
        return 2;
    }
    outdir = argv[1];
    int reps = argc > 2 ? atoi(argv[2]) : 21;
    if (reps < 1)
        reps = 1;
    if (argc > 3)
        muflow = argv[3];
    if (access(muflow, X_OK) != 0) {
        fprintf(stderr, "bench: %s is not an executable (make %s)\n", muflow, muflow);
        return 2;
    }
    char proc[1100];
    snprintf(proc, sizeof proc, "%s/proc", outdir);
    bench_mkdir(proc);
    env_threads[1] = env_with_threads(1);
    env_threads[2] = env_with_threads(2);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_alarm; /* no SA_RESTART: wait4 returns EINTR, then waits again */
    sigaction(SIGALRM, &sa, NULL);
    start_spinner();

    runs_csv = bench_open(outdir, "process_runs.csv");
    fprintf(runs_csv, "section,case,condition,threads,rep,wall_s,user_s,sys_s,nivcsw,maxrss_kb,"
                      "exit,foreign_cpu_s,spinner_cpu_s\n");
    FILE *fm = bench_open(outdir, "process_meta.csv");
    const char *wp = getenv("OMP_WAIT_POLICY"), *sc = getenv("GOMP_SPINCOUNT");
    fprintf(fm, "key,value\nrepeats,%d\nmuflow,%s\nomp_wait_policy,%s\ngomp_spincount,%s\n"
                "run_timeout_s,%d\n",
            reps, muflow, wp ? wp : "(unset)", sc ? sc : "(unset)", RUN_TIMEOUT);
    bench_wait_quiet(30.0);
    double t_all = mono_now();
    fprintf(stderr, "process: %s, %d repeats after a warm-up\n", muflow, reps);

    /* ---- load: idle against one spinning process, 2 threads ---- */
    fprintf(fm, "load_loadavg_start,%.2f\n", loadavg1());
    double start = mono_now();
    double *w[NLOAD][2];
    int n_load = 0;
    for (int c = 0; c < NLOAD; c++)
        for (int m = 0; m < 2; m++)
            w[c][m] = calloc((size_t)reps, sizeof(double));
    for (int rep = -1; rep < reps && keep_going(rep, start, 120.0); rep++) {
        for (int k = 0; k < 2; k++) {
            int loaded = (rep & 1) ? 1 - k : k; /* idle first on even repeats */
            if (loaded)
                spin(1);
            for (int c = 0; c < NLOAD; c++) {
                struct sample s;
                run_once(&load_cases[c], 2, &s);
                record("load", &load_cases[c], loaded ? "loaded" : "idle", 2, rep, &s);
                if (rep >= 0)
                    w[c][loaded][rep] = s.wall;
            }
            if (loaded)
                spin(0);
        }
        if (rep >= 0)
            n_load = rep + 1;
    }
    fprintf(fm, "load_loadavg_end,%.2f\nload_repeats,%d\nload_seconds,%.1f\n", loadavg1(), n_load,
            mono_now() - start);
    fprintf(stderr, "  2 threads, idle and with one spinning process:\n");
    for (int c = 0; c < NLOAD; c++)
        for (int m = 0; m < 2; m++) {
            char what[96];
            snprintf(what, sizeof what, "%s, %s", load_cases[c].label, m ? "loaded" : "idle");
            print_median(what, w[c][m], n_load);
            free(w[c][m]);
        }

    /* ---- threads: 1 against 2, the spinning process stopped ---- */
    fprintf(fm, "threads_loadavg_start,%.2f\n", loadavg1());
    start = mono_now();
    double *wt[NTHREAD][3];
    int n_thr = 0;
    for (int c = 0; c < NTHREAD; c++)
        for (int t = 1; t <= 2; t++)
            wt[c][t] = calloc((size_t)reps, sizeof(double));
    for (int rep = -1; rep < reps && keep_going(rep, start, 180.0); rep++) {
        for (int c = 0; c < NTHREAD; c++)
            for (int k = 0; k < 2; k++) {
                int t = (rep & 1) ? 1 + k : 2 - k; /* 2 threads first on even repeats */
                struct sample s;
                run_once(&thread_cases[c], t, &s);
                record("threads", &thread_cases[c], "idle", t, rep, &s);
                if (rep >= 0)
                    wt[c][t][rep] = s.wall;
            }
        if (rep >= 0)
            n_thr = rep + 1;
    }
    fprintf(fm, "threads_loadavg_end,%.2f\nthreads_repeats,%d\nthreads_seconds,%.1f\n",
            loadavg1(), n_thr, mono_now() - start);
    fprintf(stderr, "  1 and 2 threads:\n");
    for (int c = 0; c < NTHREAD; c++)
        for (int t = 2; t >= 1; t--) {
            char what[96];
            snprintf(what, sizeof what, "%s, %d thread%s", thread_cases[c].label, t,
                     t > 1 ? "s" : "");
            print_median(what, wt[c][t], n_thr);
            free(wt[c][t]);
        }

    kill(spinner, SIGKILL);
    waitpid(spinner, NULL, 0);
    fprintf(fm, "seconds,%.1f\n", mono_now() - t_all);
    fclose(fm);
    fclose(runs_csv);
    fprintf(stderr, "process: done in %.1f s\n", mono_now() - t_all);
    return 0;
}
