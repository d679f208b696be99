/* The helpers the test groups share (test_util.h). */
#define _GNU_SOURCE /* F_SETPIPE_SZ; mkdtemp, popen, readlink, kill */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include "app/run.h"
#include "config/case.h"
#include "io/fields_h5.h"
#include "march/march.h"
#include "march/module.h"
#include "platform/comm.h"
#include "scenes/scene.h"
#include "test_main.h"
#include "test_poisson_kinds.h"

/* ---- cases and runs ------------------------------------------------------ */

void test_load_case(struct muflow_case *cs, const char *file, int n, char *ov[])
{
    char err[1024];
    int rc = case_load(cs, file, n, ov, err, sizeof err);
    if (rc != 0)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
}

void test_run_loaded(const struct muflow_case *cs, int write_output, struct run_result *r)
{
    char err[1024];
    int rc = run_case(cs, write_output, r, err, sizeof err);
    if (rc != RUN_OK)
        print_error("%s\n", err);
    assert_int_equal(rc, RUN_OK);
}

void test_run_case(const char *file, int n, char *ov[], struct muflow_case *cs,
                   struct run_result *r)
{
    test_load_case(cs, file, n, ov);
    test_run_loaded(cs, 0, r);
}

void test_march_create(struct march_state *st, const struct muflow_case *cs,
                       const struct module *const *extra)
{
    char err[1024];
    int rc = scene_march_create(st, cs, extra, err, sizeof err);
    if (rc != 0)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
}

void test_case_refused(const char *file, int n, char *ov[], const char *named)
{
    struct muflow_case cs;
    char err[1024];
    assert_int_equal(case_load(&cs, file, n, ov, err, sizeof err), 2);
    print_message("%s\n", err);
    assert_non_null(strstr(err, named));
    assert_null(strchr(err, '\n'));
}

void test_bad_overrides(const char *case_path, const char *const bad[][2], size_t n)
{
    for (size_t i = 0; i < n; i++) {
        char *ov[] = {(char *)bad[i][0]};
        test_case_refused(case_path, 1, ov, bad[i][1]);
    }
}

/* ---- linear solves -------------------------------------------------------- */

int test_viscous_solve(const struct grid *g, const struct boundary *bc, const struct box act[3],
                       enum viscous_precond kind, const struct viscous_problem *pb, double *const rhs[3],
                       double *x[3], double rtol)
{
    struct viscous_solver *vs = NULL;
    char err[256] = "";
    int rc = viscous_create(&vs, g, bc, act, -1, kind, err, sizeof err);
    if (rc != 0)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
    assert_int_equal(viscous_precondition(vs, pb), 0);
    struct viscous_stats st;
    rc = viscous_solve(vs, pb, rhs, x, rtol, 300, &st);
    if (rc != 0)
        print_error("%s stopped at %d iterations, relative residual %.2e\n",
                    viscous_precond_name(kind), st.iterations,
                    st.relative_residual);
    assert_int_equal(rc, 0);
    viscous_destroy(vs);
    return st.iterations;
}

/* ---- temporary folders --------------------------------------------------- */

#define TMP_PREFIX "/tmp/muflow_"

void test_tmp_make(char *dir, size_t len, const char *tag)
{
    int n = snprintf(dir, len, TMP_PREFIX "%s_XXXXXX", tag);
    assert_true(n > 0 && (size_t)n < len);
    assert_non_null(mkdtemp(dir));
}

void test_tmp_remove(const char *dir)
{
    char cmd[1100];
    /* never anything else, and no quote that would end the shell's string */
    assert_true(strncmp(dir, TMP_PREFIX, strlen(TMP_PREFIX)) == 0);
    assert_null(strchr(dir, '\''));
    assert_true(strlen(dir) < 1000);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

void test_ranks_dir(char *dir, size_t len, const char *tag)
{
    long pid = comm_rank() == 0 ? (long)getpid() : 0;
    comm_sum_long(&pid, 1);
    snprintf(dir, len, "/tmp/muflow_mpi_%s_%ld", tag, pid);
    if (comm_rank() == 0)
        mkdir(dir, 0700);
    comm_barrier();
}

void test_ranks_dir_remove(const char *dir)
{
    comm_barrier();
    if (comm_rank() == 0)
        test_tmp_remove(dir);
}

void test_poisson_periodic(const enum poisson_bc bc[3][2], int periodic[3])
{
    for (int d = 0; d < 3; d++)
        periodic[d] = bc[d][0] == POISSON_PERIODIC;
}

void test_blocks_open(struct test_blocks *b, const int dims[3], const int periodic[3],
                      const int n[3], const double len[3])
{
    /* every direction free: a test that keeps one whole asks 1 there */
    const int split[3] = {1, 1, 1};
    char err[256] = "";
    assert_int_equal(grid_init(&b->whole, n, len), 0);
    int rc = comm_cart_create(&b->cart, dims, periodic, split, err, sizeof err);
    rc = rc ? rc : decomp_create(&b->dc, &b->cart, n, err, sizeof err);
    if (rc != 0)
        print_error("%s\n", err);
    assert_int_equal(rc, 0);
    assert_int_equal(decomp_local_grid(&b->dc, &b->whole, &b->g), 0);
}

void test_blocks_close(struct test_blocks *b)
{
    decomp_free(&b->dc);
    comm_cart_free(&b->cart);
}

void test_run_dir_make(struct test_run_dir *d, const char *name)
{
    char tag[24];
    snprintf(tag, sizeof tag, "%.20s", name);
    test_tmp_make(d->dir, sizeof d->dir, tag);
    snprintf(d->output, sizeof d->output, "output.dir=%s", d->dir);
    snprintf(d->initial_state, sizeof d->initial_state, "solver.initial_state=%s", d->dir);
}

void test_run_dir_remove(const struct test_run_dir *d)
{
    test_tmp_remove(d->dir);
}

/* ---- files a run writes -------------------------------------------------- */

int test_file_exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

char *test_read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        print_error("cannot open %s: %s\n", path, strerror(errno));
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    assert_non_null(s);
    assert_int_equal(fread(s, 1, (size_t)n, f), (size_t)n);
    s[n] = '\0';
    fclose(f);
    if (len)
        *len = (size_t)n;
    return s;
}

char *test_read_in(const char *dir, const char *name)
{
    char path[1100];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return test_read_file(path, NULL);
}

char *test_summary_result(const char *dir)
{
    char *s = test_read_in(dir, "summary.ini");
    char *start = strstr(s, "[result]\n");
    if (!start)
        print_error("%s/summary.ini has no [result] section\n", dir);
    assert_non_null(start);
    char *end = strstr(start, "\n\n");
    assert_non_null(end);
    end[1] = '\0';
    /* the wall time, and the matrices probed or factorised: a continued run
     * factorises anew what the interrupted one kept */
    const char *drop[] = {"\nwall_seconds = ", "\ngrid_matrices = ", "\npressure_matrices = "};
    for (size_t k = 0; k < sizeof drop / sizeof drop[0]; k++) {
        char *w = strstr(start, drop[k]);
        assert_non_null(w);
        char *eol = strchr(w + 1, '\n');
        memmove(w, eol, strlen(eol) + 1);
    }
    char *out = strdup(start);
    assert_non_null(out);
    free(s);
    return out;
}

static char *csv_without_wall(const char *csv)
{
    int wall[64] = {0}, col = 0, row0 = 1;
    char *out = malloc(strlen(csv) + 1), *o = out;
    assert_non_null(out);
    for (const char *p = csv; *p;) {
        size_t len = strcspn(p, ",\n");
        if (row0 && col < 64)
            wall[col] = strncmp(p, "wall", 4) == 0;
        if (row0 || col >= 64 || !wall[col]) {
            memcpy(o, p, len);
            o += len;
        }
        p += len;
        if (*p == ',') {
            *o++ = *p++;
            col++;
        } else if (*p == '\n') {
            *o++ = *p++;
            col = 0;
            row0 = 0;
        }
    }
    *o = '\0';
    return out;
}

char *test_read_csv_without_wall(const char *dir, const char *name)
{
    char *text = test_read_in(dir, name);
    char *out = csv_without_wall(text);
    free(text);
    return out;
}

double *test_read_csv_numbers(const char *dir, const char *name, char *header, size_t hlen,
                              int *rows, int *cols)
{
    char *text = test_read_in(dir, name);
    char *eol = strchr(text, '\n');
    assert_non_null(eol);
    *eol = '\0';
    snprintf(header, hlen, "%s", text);
    int nc = 1;
    for (const char *c = text; *c; c++)
        nc += *c == ',';
    int nr = 0;
    for (const char *c = eol + 1; *c; c++)
        nr += *c == '\n';
    double *v = malloc((size_t)(nr > 0 ? nr : 1) * (size_t)nc * sizeof *v);
    assert_non_null(v);
    char *p = eol + 1;
    for (int r = 0; r < nr; r++)
        for (int c = 0; c < nc; c++) {
            char *end;
            v[(size_t)r * nc + c] = strtod(p, &end);
            assert_true(end != p && *end == (c + 1 < nc ? ',' : '\n'));
            p = end + 1;
        }
    free(text);
    *rows = nr;
    *cols = nc;
    return v;
}

int test_csv_column(const char *header, const char *col)
{
    size_t n = strlen(col);
    const char *c = header;
    for (int i = 0;; i++) {
        if (strncmp(c, col, n) == 0 && (c[n] == ',' || c[n] == '\0'))
            return i;
        c = strchr(c, ',');
        if (!c)
            return -1;
        c++;
    }
}

/* ---- commands ------------------------------------------------------------ */

void test_muflow_bin(char *out, size_t len)
{
    ssize_t n = readlink("/proc/self/exe", out, len - sizeof "/muflow");
    assert_true(n > 0);
    out[n] = '\0';
    strcpy(strrchr(out, '/'), "/muflow");
}

int test_sh(const char *cmd, char **out)
{
    fflush(NULL); /* nothing of ours buffered twice into the child */
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    size_t used = 0, cap = 1 << 14, got;
    char *buf = malloc(cap);
    assert_non_null(buf);
    while ((got = fread(buf + used, 1, cap - 1 - used, p)) > 0) {
        used += got;
        if (used + 1 == cap) {
            cap *= 2;
            buf = realloc(buf, cap);
            assert_non_null(buf);
        }
    }
    buf[used] = '\0';
    int st = pclose(p);
    if (out)
        *out = buf;
    else
        free(buf);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

int test_one_line(const char *text)
{
    const char *nl = strchr(text, '\n');
    return nl && nl > text && nl[1] == '\0';
}

char *test_sh_refused(const char *cmd, const char *named)
{
    char *out;
    int rc = test_sh(cmd, &out);
    print_message("%s\n-> exit %d: %s", cmd, rc, out);
    assert_int_equal(rc, 2);
    assert_true(test_one_line(out));
    assert_non_null(strstr(out, named));
    return out;
}

int test_cli(char *const args[], const char *when, int sig, char *out, size_t len)
{
    int fd[2];
    assert_int_equal(pipe(fd), 0);
    /* the child blocks about 40 progress lines ahead of us */
    assert_true(fcntl(fd[0], F_SETPIPE_SZ, 4096) >= 0);
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        dup2(fd[1], 1);
        close(fd[0]);
        close(fd[1]);
        execv(args[0], args);
        _exit(127);
    }
    close(fd[1]);
    FILE *f = fdopen(fd[0], "r");
    assert_non_null(f);
    setvbuf(f, NULL, _IONBF, 0); /* read no further ahead than the lines we look at */
    char line[512];
    size_t used = 0;
    int sent = 0;
    out[0] = '\0';
    while (fgets(line, sizeof line, f)) {
        size_t l = strlen(line);
        if (used + l < len) {
            memcpy(out + used, line, l + 1);
            used += l;
        }
        if (sig && !sent && strstr(line, when)) {
            kill(pid, sig);
            sent = 1;
        }
    }
    fclose(f);
    int status;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    if (sig)
        assert_true(sent);
    return status;
}

/* ---- HDF5 field files ---------------------------------------------------- */

hid_t test_h5_open(const char *path)
{
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        print_error("cannot open %s\n", path);
    assert_true(f >= 0);
    return f;
}

double *test_h5_dataset(hid_t file, const char *name, size_t *n, int *rank, hsize_t dims[4])
{
    hid_t set = H5Dopen2(file, name, H5P_DEFAULT);
    if (set < 0)
        print_error("dataset %s missing\n", name);
    assert_true(set >= 0);
    hid_t space = H5Dget_space(set);
    int r = H5Sget_simple_extent_ndims(space);
    assert_true(r >= 1 && r <= 4);
    if (rank)
        *rank = r;
    if (dims)
        H5Sget_simple_extent_dims(space, dims, NULL);
    size_t count = (size_t)H5Sget_simple_extent_npoints(space);
    if (n)
        *n = count;
    double *buf = malloc((count ? count : 1) * sizeof(double));
    assert_non_null(buf);
    assert_true(H5Dread(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0);
    H5Sclose(space);
    H5Dclose(set);
    return buf;
}

double *test_h5_file_dataset(const char *path, const char *name, size_t *n)
{
    hid_t f = test_h5_open(path);
    double *a = test_h5_dataset(f, name, n, NULL, NULL);
    H5Fclose(f);
    return a;
}

static hid_t attr_open(hid_t file, const char *name)
{
    hid_t at = H5Aopen(file, name, H5P_DEFAULT);
    if (at < 0)
        print_error("attribute %s missing\n", name);
    assert_true(at >= 0);
    return at;
}

void test_h5_attr(hid_t file, const char *name, hid_t type, void *out)
{
    hid_t at = attr_open(file, name);
    assert_true(H5Aread(at, type, out) >= 0);
    H5Aclose(at);
}

void test_h5_attr_text(hid_t file, const char *name, char *out, size_t len)
{
    hid_t at = attr_open(file, name);
    hid_t type = H5Aget_type(at);
    size_t size = H5Tget_size(type);
    assert_true(size < len);
    hid_t mem = H5Tcopy(H5T_C_S1);
    H5Tset_size(mem, size + 1);
    assert_true(H5Aread(at, mem, out) >= 0);
    out[size] = '\0';
    H5Tclose(mem);
    H5Tclose(type);
    H5Aclose(at);
}

void test_same_fields(const char *a, const char *b, long step)
{
    char name[64], pa[1100], pb[1100];
    fields_h5_name(step, name, sizeof name);
    snprintf(pa, sizeof pa, "%s/%s", a, name);
    snprintf(pb, sizeof pb, "%s/%s", b, name);
    hid_t fa = test_h5_open(pa), fb = test_h5_open(pb);
    /* every dataset of a single-phase field file: the face velocities, five
     * cell scalars and the cell-centred velocity */
    static const char *const sets[] = {"u", "v", "w", "pressure", "pressure_regularised",
                                       "shear_rate", "inertial_number", "viscosity",
                                       "velocity"};
    for (size_t s = 0; s < sizeof sets / sizeof sets[0]; s++) {
        int ra, rb;
        hsize_t da[4], db[4];
        size_t na, nb;
        double *x = test_h5_dataset(fa, sets[s], &na, &ra, da);
        double *y = test_h5_dataset(fb, sets[s], &nb, &rb, db);
        assert_int_equal(ra, rb);
        for (int d = 0; d < ra; d++)
            assert_true(da[d] == db[d]);
        assert_true(na == nb && na > 0);
        if (memcmp(x, y, na * sizeof(double)) != 0)
            print_error("%s: %s differs from %s's\n", pb, sets[s], a);
        assert_memory_equal(x, y, na * sizeof(double));
        free(x);
        free(y);
    }
    double ta, tb;
    test_h5_attr(fa, "time", H5T_NATIVE_DOUBLE, &ta);
    test_h5_attr(fb, "time", H5T_NATIVE_DOUBLE, &tb);
    assert_true(ta == tb);
    H5Fclose(fa);
    H5Fclose(fb);
}

/* ---- states -------------------------------------------------------------- */

double test_velocity_difference(const struct march_state *a, const struct march_state *b,
                                double *largest)
{
    double diff = 0.0, top = 0.0;
    assert_true(a->g.size == b->g.size);
    for (int c = 0; c < 3; c++)
        for (size_t p = 0; p < a->g.size; p++) {
            diff = fmax(diff, fabs(a->field.velocity[c][p] - b->field.velocity[c][p]));
            top = fmax(top, fabs(a->field.velocity[c][p]));
        }
    if (largest)
        *largest = top;
    return diff;
}

static int variable_create(struct march_state *st, void **state, char *err, size_t errlen)
{
    (void)state;
    return march_density_changed(st, 0, err, errlen);
}

static const struct module variable_density = {.name = "variable", .create = variable_create};
const struct module *const test_variable_density[] = {&variable_density, NULL};

/* ---- Poisson condition pairs (test_poisson_kinds.h) ---------------------- */

const enum poisson_bc kind_bc[NKIND][2] = {
    [K_P] = {POISSON_PERIODIC, POISSON_PERIODIC},
    [K_NN] = {POISSON_NEUMANN, POISSON_NEUMANN},
    [K_DD] = {POISSON_DIRICHLET, POISSON_DIRICHLET},
    [K_ND] = {POISSON_NEUMANN, POISSON_DIRICHLET},
    [K_DN] = {POISSON_DIRICHLET, POISSON_NEUMANN},
};
const char *const kind_name[NKIND] = {"P", "NN", "DD", "ND", "DN"};

void kind_triple(int t, enum kind k[3])
{
    k[0] = (enum kind)(t / (NKIND * NKIND));
    k[1] = (enum kind)(t / NKIND % NKIND);
    k[2] = (enum kind)(t % NKIND);
}

void make_bc(const enum kind k[3], enum poisson_bc bc[3][2])
{
    for (int d = 0; d < 3; d++) {
        bc[d][0] = kind_bc[k[d]][0];
        bc[d][1] = kind_bc[k[d]][1];
    }
}

int is_singular(const enum poisson_bc bc[3][2])
{
    for (int d = 0; d < 3; d++)
        if (bc[d][0] == POISSON_DIRICHLET || bc[d][1] == POISSON_DIRICHLET)
            return 0;
    return 1;
}
