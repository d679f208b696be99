/* muflow CASE [section.key=value ...]
 * muflow --restart DIR [section.key=value ...]
 * muflow --version
 * muflow --list [=markdown]
 * Runs a case file (an INI file under cases/) with command-line overrides of
 * any key, or continues the run whose checkpoint is DIR/checkpoint.h5.
 * Exit status: 0 steady or finished, 1 diverged, 2 bad input or setup
 * failure, 3 unsteady or stopped (max_steps, SIGINT / SIGTERM), 4 an output or
 * checkpoint could not be written. */
#define _POSIX_C_SOURCE 200809L /* setenv, execv */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <omp.h>
#include "kernels/kernels.h"
#include "scenes/scene.h"
#include "config/case.h"
#include "io/checkpoint.h"
#include "app/interrupt.h"
#include "app/run.h"
#include "platform/comm.h"

#define EXIT_OUTPUT_FAILED 4

static int several_ranks(void);

#ifndef MUFLOW_VERSION /* the Makefile's VERSION: git describe, else the VERSION file */
#error "MUFLOW_VERSION is defined by the Makefile"
#endif

/* Two run-time settings that libraries read before main, unless the user
 * chose them (docs/numerics/threads-and-platform.md holds the measurements;
 * bench/analysis.md the profiles).
 *
 * Short spinning for OpenMP threads.  libgomp's default lets a thread that
 * reaches a barrier spin for up to 300,000 iterations before it sleeps.  On a
 * machine whose cores other processes also use, the thread being waited for
 * is often preempted while its partner spins on the core it needs: a thin
 * profile scene, which opens thousands of parallel regions, ran many times
 * slower at 2 threads than at 1.  Sleeping at once (OMP_WAIT_POLICY=passive)
 * costs a futex wake-up at every barrier instead, several microseconds in a
 * virtual machine.  A spin count of SPIN_COUNT bounds what a waiting thread
 * can take from a busy core to a few tens of microseconds and catches the
 * short waits.  One thread needs no policy.
 *
 * Huge pages for the field arrays.  A field of a mid-sized grid is below
 * glibc's threshold for a mapping of its own, which it gets anyway (the
 * threshold grows only after a free), and every 4 kB page of it is a fault
 * on first touch, several microseconds each in a virtual machine.
 * MALLOC_TUNABLES keeps blocks below 32 MB in malloc's heap and lets malloc
 * ask for transparent huge pages there (glibc 2.35 and later; where the
 * kernel gives none, or an older glibc does not know the tunable, nothing
 * changes): a tenth of the faults.
 *
 * libgomp and malloc read the environment before main, so setting a variable
 * in main is too late; setting it in the executable's .preinit_array does
 * not work either (glibc resets environ to the original block between the
 * two).  So main sets them and executes /proc/self/exe again, with the same
 * arguments, first thing: the new image's libraries read them.  The second
 * image finds the variables set and goes on, so there is no loop.  A user's
 * OMP_WAIT_POLICY or GOMP_SPINCOUNT, or GLIBC_TUNABLES (even an empty one),
 * is left alone; under valgrind (its preload library in LD_PRELOAD) there is
 * no re-exec.  When the exec fails (no /proc) the run continues with the
 * libraries' defaults.  The re-exec costs one more program start (loading
 * the shared libraries again).
 * `OMP_DISPLAY_ENV=verbose build/muflow CASE` (a case whose grid opens
 * parallel regions) shows the spin count: the last GOMP_SPINCOUNT printed is
 * SPIN_COUNT's (the tests check it).
 *
 * When other processes already keep the cores busy at start (the 1-minute
 * load average within half a core of the core count), even short spinning
 * takes time the thread being waited for needs: the threads sleep at once
 * (OMP_WAIT_POLICY=passive) instead, and a steady march on a grid below the
 * kernels' parallel threshold runs on one thread unless the user set
 * OMP_NUM_THREADS (its threads would mostly wait for each other:
 * docs/numerics/threads-and-platform.md).
 * MUFLOW_MACHINE_LOAD replaces the load average read (tests). */
#define SPIN_COUNT "1000"
/* Huge pages for the field arrays; freed memory kept in the process (no trim
 * of the heaps' tops): FFTW's threaded transforms free and allocate their
 * buffers at every execution, and each heap trim that returned them cost page
 * faults and, with two threads, a TLB shootdown on the other core (bagnold3d,
 * 3 steps on 2 threads: 22.5 s -> 9.6 s; docs/numerics/threads-and-platform.md) */
#define MALLOC_TUNABLES                                                                        \
    "glibc.malloc.hugetlb=1:glibc.malloc.mmap_threshold=33554432:"                           \
    "glibc.malloc.trim_threshold=4294967296"

/* Whether other processes keep the cores busy: the 1-minute load average
 * (or MUFLOW_MACHINE_LOAD) within half a core of the online cores. */
static int machine_busy(void)
{
    double load = -1.0;
    const char *given = getenv("MUFLOW_MACHINE_LOAD");
    if (given) {
        load = strtod(given, NULL);
    } else {
        FILE *f = fopen("/proc/loadavg", "r");
        if (f) {
            if (fscanf(f, "%lf", &load) != 1)
                load = -1.0;
            fclose(f);
        }
    }
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    return cores > 0 && load >= (double)cores - 0.5;
}

static void runtime_defaults(char **argv, double slots, int steady)
{
    const int spin =
        !getenv("OMP_WAIT_POLICY") && !getenv("GOMP_SPINCOUNT") && omp_get_max_threads() >= 2;
    const int tunables = !getenv("GLIBC_TUNABLES");
    const int busy = spin && machine_busy();
    /* busy, a steady march on a grid whose loops are too short to share
     * (below the kernels' threshold: its Krylov solves' many small regions)
     * and the thread count the user left to OpenMP: one thread, no barrier
     * to wait at.  A transient step keeps its threads, asleep (the collapse:
     * 0.62 s against one thread's 0.84 s; the heap, steady: 1.29 against
     * 2.07 s; docs/numerics/threads-and-platform.md) */
    const int one =
        busy && steady && !getenv("OMP_NUM_THREADS") && slots < KERNEL_PARALLEL_MIN;
    if (!spin && !tunables)
        return;
    /* Under valgrind the process is the tool's: /proc/self/exe is the tool,
     * and an exec of the program itself would leave the tool behind. */
    const char *preload = getenv("LD_PRELOAD");
    if (preload && strstr(preload, "vgpreload"))
        return;
    char self[4096];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0 || (size_t)n >= sizeof self - 1)
        return;
    self[n] = '\0';
    const int passive = busy;
    if ((one && setenv("OMP_NUM_THREADS", "1", 1) != 0) ||
        (passive && setenv("OMP_WAIT_POLICY", "passive", 1) != 0) ||
        (spin && !passive && setenv("GOMP_SPINCOUNT", SPIN_COUNT, 1) != 0) ||
        (tunables && setenv("GLIBC_TUNABLES", MALLOC_TUNABLES, 1) != 0))
        return;
    execv(self, argv);
    /* the exec failed: this image keeps the defaults */
    if (one)
        unsetenv("OMP_NUM_THREADS");
    if (passive)
        unsetenv("OMP_WAIT_POLICY");
    else if (spin)
        unsetenv("GOMP_SPINCOUNT");
    if (tunables)
        unsetenv("GLIBC_TUNABLES");
}

static void usage(FILE *f)
{
    fprintf(f, "usage: muflow CASE.ini [section.key=value ...]\n"
               "       muflow --restart DIR [section.key=value ...]\n"
               "       muflow --version\n"
               "       muflow --list     (the scenes and every case key: default, allowed\n"
               "                          values, meaning)\n"
               "       muflow --list=markdown   (the same in full: docs/case_keys.md)\n"
               "  runs the case to a steady state (solver.mode = steady) or to\n"
               "  solver.end_time (transient); any case key can be overridden, e.g.\n"
               "  muflow cases/bagnold.ini physics.tilt=0.45 domain.nz=80\n"
               "  --restart continues from DIR/checkpoint.h5 (it holds the case; output\n"
               "  goes to DIR unless output.dir is overridden), e.g.\n"
               "  muflow --restart out/bagnold solver.max_steps=20000\n"
               "  output: summary.ini, profile.csv, history.csv, fields_*.h5, fields.xdmf,\n"
               "  checkpoint.h5 (at the end of the run) in output.dir\n"
               "  SIGINT / SIGTERM: the step ends, a checkpoint and the outputs are written\n");
}

/* The case of a restart: the checkpoint's, output to dir, then the overrides. */
static int load_restart(struct muflow_case *cs, const char *dir, int n, char **ov,
                        char *path, size_t plen, char *err, size_t errlen)
{
    if (snprintf(path, plen, "%s/%s", dir, CHECKPOINT_NAME) >= (int)plen) {
        snprintf(err, errlen, "--restart %.100s...: folder name too long", dir);
        return 2;
    }
    size_t len = strlen(dir) + sizeof "output.dir=";
    char *outdir = malloc(len);
    char **all = malloc((size_t)(n + 1) * sizeof *all);
    int rc = 2;
    if (!outdir || !all) {
        snprintf(err, errlen, "out of memory");
    } else {
        snprintf(outdir, len, "output.dir=%s", dir);
        all[0] = outdir;
        for (int i = 0; i < n; i++)
            all[i + 1] = ov[i];
        rc = checkpoint_load_case(path, n + 1, all, cs, err, errlen);
    }
    free(outdir);
    free(all);
    return rc;
}

static void report(const struct muflow_case *cs, const struct run_result *r)
{
    printf("%s: %s after %ld steps, t = %.6g, wall %.3f s, residual %.3e (%s)\n", cs->name,
           run_status_name(r->status), r->steps, r->time, r->wall_seconds, r->residual,
           r->message);
    const struct scene *sc = case_scene(cs);
    const char *hname = sc->headline_name;
    /* the scene's names: err_midline and "reference" for the cavity, whose
     * comparison is published data rather than an exact solution */
    const char *sname = scene_solution_name(sc);
    char compared[96];
    if (isfinite(r->errors.headline_exact))
        snprintf(compared, sizeof compared, " (%s %.6g)", sname, r->errors.headline_exact);
    else
        snprintf(compared, sizeof compared, " (no %s value)", sname);
    if (hname && r->errors.valid) {
        printf("%s: %s %.4e  err_max %.4e", cs->name, scene_error_name(sc), r->errors.err_rms,
               r->errors.err_max);
        if (!sc->no_err_rms_paper)
            printf("  err_rms_paper %.4e", r->errors.err_rms_paper);
        printf("  %s %.6g%s\n", hname, r->errors.headline, compared);
    } else if (hname && scene_has_reference(sc)) {
        char params[160] = "";
        if (sc->reference_parameters)
            sc->reference_parameters(cs, params, sizeof params);
        if (!cs->reference[0])
            printf("%s: no reference data (case.reference is not set); %s %.6g\n", cs->name,
                   hname, r->errors.headline);
        else
            /* the headline may still have a reference value (the cavity's
             * psi_max curve covers Bn continuously, its mid-lines do not) */
            printf("%s: no reference %s for these parameters%s%s%s in %s; %s %.6g%s\n",
                   cs->name, isfinite(r->errors.headline_exact) ? "profile" : "data",
                   params[0] ? " (" : "", params, params[0] ? ")" : "", cs->reference, hname,
                   r->errors.headline, isfinite(r->errors.headline_exact) ? compared : "");
    } else if (hname) {
        printf("%s: no analytic steady solution for these parameters; %s %.6g\n", cs->name,
               hname, r->errors.headline);
    }
    if (r->scene_line[0])
        printf("%s: %s\n", cs->name, r->scene_line);
    printf("output: %s\n", cs->output_dir);
    if (r->signal && !r->restartable) /* stop_note: why not, and what to do instead */
        printf("muflow: interrupted by %s %s\n", interrupt_name(r->signal), r->stop_note);
    else if (r->signal)
        printf("muflow: interrupted by %s at step %ld%s; resume with: muflow --restart %s\n",
               interrupt_name(r->signal), r->steps,
               r->checkpointed ? ", checkpoint written" : ", NO checkpoint written",
               cs->output_dir);
    else if (r->checkpointed && r->restartable)
        printf("checkpoint: %s/%s (muflow --restart %s)\n", cs->output_dir, CHECKPOINT_NAME,
               cs->output_dir);
    else if (r->checkpointed)
        printf("final state: %s/%s (a new run starts from it with solver.initial_state)\n",
               cs->output_dir, CHECKPOINT_NAME);
    fflush(stdout);
}

/* A warning of the case loader (a key given twice in the file). */
static void print_warning(void *ctx, const char *line)
{
    (void)ctx;
    fprintf(stderr, "muflow: warning: %s\n", line);
}

/* The waiting policy and the huge pages matter only to a run that opens
 * parallel regions on two threads or more: any grid of PARALLEL_REGION_MIN
 * slots (kernels.h), where a solver may, even if the kernels do not (the
 * column collapse's 2D grid, 24,300 slots: its projection's multigrid).  A
 * thin profile grid opens few and is spared the second program start, but
 * on a busy machine the few (the sparse factorisations' own) still spin at
 * libgomp's default count: there it runs on one thread too. */
static void runtime_defaults_for(const struct muflow_case *cs, char **argv)
{
    if (several_ranks()) /* MPI is open: no second start; the ranks' threads as given */
        return;
    double slots = (double)(cs->n[0] + 2) * (cs->n[1] + 2) * (cs->n[2] + 2);
    if (slots >= PARALLEL_REGION_MIN)
        runtime_defaults(argv, slots, cs->mode == MODE_STEADY);
    else if (!getenv("OMP_NUM_THREADS") && !getenv("OMP_WAIT_POLICY") &&
             omp_get_max_threads() >= 2 && machine_busy())
        omp_set_num_threads(1); /* no second start: it would cost more than the run gains */
}

/* The options without arguments; "-h" is "--help". */
static int is_bare_option(const char *arg)
{
    return strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0 ||
           strcmp(arg, "--version") == 0 || strcmp(arg, "--list") == 0 ||
           strcmp(arg, "--list=markdown") == 0;
}

/* An argument the command line cannot take: 2 after one line and the usage
 * on stderr, or 0.  A first argument that starts with '-' is an option (a
 * case file named so is given as ./-name.ini). */
static int refuse_arguments(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    const char *first = argv[1];
    if (first[0] == '-' && !is_bare_option(first) && strcmp(first, "--restart") != 0) {
        fprintf(stderr, "muflow: unknown option %s\n", first);
        usage(stderr);
        return 2;
    }
    if (is_bare_option(first) && argc > 2) {
        fprintf(stderr, "muflow: %s takes no arguments (got '%s'%s)\n", first, argv[2],
                argc > 3 ? " ..." : "");
        usage(stderr);
        return 2;
    }
    return 0;
}

/* 1 when the run has several MPI ranks (mpirun -np N, N > 1); one rank
 * (mpirun -np 1) is the serial run, MPI left alone. */
static int several_ranks(void)
{
    const char *ranks = getenv("OMPI_COMM_WORLD_SIZE");
    return comm_launched() && ranks && strcmp(ranks, "1") != 0;
}

/* A run that cannot start: the message once (rank 0) and status 2 on
 * every rank of an MPI job, or on stderr. */
static int refuse(const char *msg)
{
    if (several_ranks())
        comm_exit(2, 1, msg);
    fprintf(stderr, "%s\n", msg);
    return 2;
}

/* Under mpirun with several ranks MPI is opened; the scenes that run
 * decomposed say so (scene.h: decomposed), every other one ends with status
 * 2 on every rank (rank 0 says why and what does) rather than N copies of
 * the serial run writing the same files. */
static int open_ranks(void)
{
    if (!several_ranks())
        return 0;
    char err[512];
    if (comm_init(err, sizeof err) != 0) {
        fprintf(stderr, "muflow: %s\n", err);
        exit(2);
    }
    return 1;
}

static int refuse_scene_on_ranks(const struct muflow_case *cs)
{
    const struct scene *sc = case_scene(cs);
    if (!several_ranks() || (sc->decomposed && sc->decomposed(cs)))
        return 0;
    char names[200] = "";
    for (int i = 0; i < scene_count(); i++) {
        const struct scene *s = scene_at(i);
        if (s->decomposed)
            snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s",
                     names[0] ? ", " : "", s->name);
    }
    char msg[800], keys[120] = "";
    if (sc->decomposed)
        snprintf(keys, sizeof keys, " with %s",
                 sc->not_decomposed ? sc->not_decomposed : "these keys");
    snprintf(msg, sizeof msg,
             "muflow: %s on %d MPI ranks: case.scene = %s%s does not run decomposed (what does: "
             "the scenes %s; see docs/numerics/decomposition.md); run muflow without mpirun",
             cs->name, comm_size(), sc->name, keys, names);
    return refuse(msg);
}

int main(int argc, char **argv)
{
    run_init();
    int refused = refuse_arguments(argc, argv);
    if (refused)
        return refused;
    if (strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0) {
        usage(stdout);
        return 0;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("muflow %s\n", MUFLOW_VERSION);
        return 0;
    }
    if (strcmp(argv[1], "--list") == 0) {
        printf("muflow %s: the scenes and every case key (docs/case_keys.md has more)\n\n",
               MUFLOW_VERSION);
        case_write_key_list(stdout);
        return 0;
    }
    if (strcmp(argv[1], "--list=markdown") == 0) {
        case_write_key_markdown(stdout);
        return 0;
    }
    const int ranks = open_ranks();
    static struct muflow_case cs;
    char err[1024], path[1100];
    struct run_options opt = {.write_output = 1};
    if (strcmp(argv[1], "--restart") == 0) {
        if (argc < 3) {
            usage(stderr);
            return 2;
        }
        /* on any rank count: each rank reads its block of the checkpoint */
        if (load_restart(&cs, argv[2], argc - 3, argv + 3, path, sizeof path, err,
                         sizeof err) != 0) {
            char msg[1100];
            snprintf(msg, sizeof msg, "muflow: %s", err);
            return refuse(msg);
        }
        if (refuse_scene_on_ranks(&cs))
            return 2;
        opt.restart_from = path;
        runtime_defaults_for(&cs, argv);
    } else {
        /* silently first: a re-executed image loads it again and warns once */
        if (case_load(&cs, argv[1], argc - 2, argv + 2, err, sizeof err) == 0)
            runtime_defaults_for(&cs, argv);
        if (case_load_warn(&cs, argv[1], argc - 2, argv + 2,
                           ranks && comm_rank() != 0 ? NULL : print_warning, NULL, err,
                           sizeof err) != 0) {
            snprintf(path, sizeof path, "muflow: %s", err);
            return refuse(path);
        }
        if (refuse_scene_on_ranks(&cs))
            return 2;
    }
    struct run_result r;
    int rc = run_case_opts(&cs, &opt, &r, err, sizeof err);
    if (rc == RUN_ERR_SETUP) {
        snprintf(path, sizeof path, "muflow: %s", err);
        return refuse(path);
    }
    if (ranks && comm_rank() != 0) /* rank 0 reports; the status is every rank's */
        return rc != RUN_OK ? EXIT_OUTPUT_FAILED : run_exit_code(r.status);
    report(&cs, &r);
    if (rc != RUN_OK) {
        fprintf(stderr, "muflow: %s\n", err);
        return EXIT_OUTPUT_FAILED;
    }
    return run_exit_code(r.status);
}
