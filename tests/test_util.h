/* The helpers the test groups share (tests/test_util.c): loading and running
 * a case, temporary folders, files and summaries a run writes, the muflow
 * command and shell commands, HDF5 field files, states compared.  Each one
 * that can fail fails the calling test (cmocka), naming what failed. */
#ifndef MUFLOW_TEST_UTIL_H
#define MUFLOW_TEST_UTIL_H

#include <stddef.h>
#include <hdf5.h>
#include "grid/decomp.h"
#include "solvers/poisson.h"
#include "solvers/viscous.h"

struct muflow_case;
struct run_result;
struct march_state;
struct module;

/* Deterministic pseudo-random numbers in [-1, 1) (a linear congruential
 * step; the tests' fields and coefficients). */
static inline double rand_pm1(unsigned long long *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / 4503599627370496.0 - 1.0; /* 2^53 / 2 */
}

/* In [0, 1): the same numbers as (rand_pm1 + 1) / 2, exactly. */
static inline double rand_unit(unsigned long long *s)
{
    return 0.5 * (rand_pm1(s) + 1.0);
}

/* ---- cases and runs ------------------------------------------------------ */

/* Loads the case file with its n overrides (case_load returns 0). */
void test_load_case(struct muflow_case *cs, const char *file, int n, char *ov[]);

/* Runs a loaded case to its end (run_case returns RUN_OK); write_output 0:
 * in memory only, 1: into its output folder. */
void test_run_loaded(const struct muflow_case *cs, int write_output, struct run_result *r);

/* test_load_case, then test_run_loaded without output. */
void test_run_case(const char *file, int n, char *ov[], struct muflow_case *cs,
                   struct run_result *r);

/* scene_march_create of the loaded case and the extra modules (NULL: none)
 * returns 0. */
void test_march_create(struct march_state *st, const struct muflow_case *cs,
                       const struct module *const *extra);

/* The case file with its n overrides is refused: case_load returns 2 with a
 * one-line message containing named (the key it names). */
void test_case_refused(const char *file, int n, char *ov[], const char *named);

/* Each bad[i][0], one override of the case file case_path, is refused:
 * case_load returns 2 with a one-line message containing bad[i][1] (the
 * key it names). */
void test_bad_overrides(const char *case_path, const char *const bad[][2], size_t n);

/* ---- linear solves -------------------------------------------------------- */

/* A viscous solver of kind on g (faces bc, unknowns act) preconditioned for
 * pb solves rhs into x to rtol within 300 iterations (else fails, saying
 * where it stopped); its iterations. */
int test_viscous_solve(const struct grid *g, const struct boundary *bc, const struct box act[3],
                       enum viscous_precond kind, const struct viscous_problem *pb, double *const rhs[3],
                       double *x[3], double rtol);

/* ---- temporary folders --------------------------------------------------- */

/* A fresh folder /tmp/muflow_<tag>_XXXXXX (mkdtemp) in dir[len]. */
void test_tmp_make(char *dir, size_t len, const char *tag);

/* Deletes dir and all it holds; only a folder under /tmp/muflow_. */
void test_tmp_remove(const char *dir);

/* A folder every MPI rank names alike, /tmp/muflow_mpi_<tag>_<rank 0's pid>
 * (made by rank 0; every rank returns once it exists), and its removal once
 * every rank is done with it. */
void test_ranks_dir(char *dir, size_t len, const char *tag);
void test_ranks_dir_remove(const char *dir);

/* The ranks' blocks of a global grid of n cells over len (whole, every
 * rank's reference): the Cartesian communicator over dims ranks (0: MPI's
 * choice, every direction free to split), periodic along d where
 * periodic[d], this rank's block dc and its local grid g.  Collective;
 * test_blocks_close frees what test_blocks_open made (b stays where it
 * was opened: dc points at cart). */
struct test_blocks {
    struct grid whole, g;
    struct comm_cart cart;
    struct decomp dc;
};
void test_blocks_open(struct test_blocks *b, const int dims[3], const int periodic[3],
                      const int n[3], const double len[3]);
void test_blocks_close(struct test_blocks *b);

/* The directions the Poisson solver's conditions bc make periodic. */
void test_poisson_periodic(const enum poisson_bc bc[3][2], int periodic[3]);

/* A fresh folder for a test's runs (test_tmp_make, named after name), with
 * the overrides that write a run there and start another from it;
 * test_run_dir_remove deletes it and what the runs wrote. */
struct test_run_dir {
    char dir[64];
    char output[96];         /* output.dir=DIR */
    char initial_state[112]; /* solver.initial_state=DIR */
};
void test_run_dir_make(struct test_run_dir *d, const char *name);
void test_run_dir_remove(const struct test_run_dir *d);

/* ---- files a run writes -------------------------------------------------- */

int test_file_exists(const char *path);

/* Whole file, NUL-terminated; its length (without the NUL) in *len when len
 * is not NULL; fails the test when it cannot be read (caller frees). */
char *test_read_file(const char *path, size_t *len);

/* test_read_file of dir/name. */
char *test_read_in(const char *dir, const char *name);

/* The [result] section of dir/summary.ini ("[result]\n" up to the blank
 * line that ends it) without its wall_seconds and grid_matrices lines
 * (caller frees). */
char *test_summary_result(const char *dir);

/* The CSV file dir/name with the values of every column whose header
 * starts with "wall" emptied (the wall time of the process that wrote the
 * row; caller frees). */
char *test_read_csv_without_wall(const char *dir, const char *name);

/* The CSV file dir/name of numbers: its header line (without the newline)
 * in header[hlen], its rows' values row by row (caller frees), their
 * number in *rows and the columns' in *cols; a row of another length, or
 * a value that is no number, fails the test. */
double *test_read_csv_numbers(const char *dir, const char *name, char *header, size_t hlen,
                              int *rows, int *cols);
/* The index of the column named col in a CSV header line, or -1. */
int test_csv_column(const char *header, const char *col);

/* ---- commands ------------------------------------------------------------ */

/* The muflow binary of this build (beside this test executable). */
void test_muflow_bin(char *out, size_t len);

/* Runs cmd with sh; its stdout in *out (malloc'd, the caller frees; NULL:
 * dropped).  Returns its exit status, -1 when it did not exit. */
int test_sh(const char *cmd, char **out);

/* text is one line, ending in its only newline. */
int test_one_line(const char *text);

/* Runs cmd with sh, which must exit with status 2 having printed one line
 * (test_one_line) that contains named: input refused, the cause named.
 * Returns that line (the caller frees). */
char *test_sh_refused(const char *cmd, const char *named);

/* Runs args[0] with args (NULL-terminated), its stdout read through a
 * one-page pipe so that the process cannot run far ahead of the line read;
 * once a line containing `when` has been read, sends sig (0: none) and
 * reads on to the end.  Returns the wait status; stdout in out[len]. */
int test_cli(char *const args[], const char *when, int sig, char *out, size_t len);

/* ---- HDF5 field files ---------------------------------------------------- */

hid_t test_h5_open(const char *path);

/* Dataset name of file, all of it as doubles (caller frees); its number of
 * values in *n, its rank in *rank and its dimensions in dims, each when not
 * NULL. */
double *test_h5_dataset(hid_t file, const char *name, size_t *n, int *rank, hsize_t dims[4]);

/* Attribute name of file, read as type into out; a text attribute into
 * out[len], NUL-terminated. */
void test_h5_attr(hid_t file, const char *name, hid_t type, void *out);
void test_h5_attr_text(hid_t file, const char *name, char *out, size_t len);

/* Dataset name of the HDF5 file at path (test_h5_dataset). */
double *test_h5_file_dataset(const char *path, const char *name, size_t *n);

/* Every dataset of a single-phase field file (fields_h5.h) of step in the
 * folders a and b, and their times: the same bit for bit. */
void test_same_fields(const char *a, const char *b, long step);

/* ---- states -------------------------------------------------------------- */

/* max |u_b - u_a| over every velocity slot of the two states (one grid);
 * the largest |u_a| in *largest when it is not NULL. */
double test_velocity_difference(const struct march_state *a, const struct march_state *b,
                                double *largest);

/* A module that declares the density variable without changing its value
 * (march_density_changed), NULL-terminated: the variable-coefficient path
 * on a flow that must equal the uniform one. */
extern const struct module *const test_variable_density[];

#endif
