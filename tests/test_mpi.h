/* What the files of the group mpi (tests/test_mpi*.c) share
 * (test_mpi_compare.c): the splits of this run's ranks a check runs on,
 * each once, and a scene split over the ranks against one process.  Every
 * call is collective and reduces its verdict over the ranks before
 * asserting (all pass or fail together). */
#ifndef MUFLOW_TEST_MPI_H
#define MUFLOW_TEST_MPI_H

#include "march/march.h"

/* Of the n splits asked (as run_options.dims: 0, MPI's choice), those
 * that cut this run's ranks into blocks no earlier one did, in order, into
 * dims; their number.  Along x, along z and MPI's choice over both are
 * three splits on four ranks, two on two (the choice is along x), one on
 * one: the others would repeat a computation to the bit. */
#define TEST_SPLITS_MAX 8 /* splits asked at once */
int test_splits(int n, const int ask[][3], int dims[][3]);

/* A scene split as dims asks (0: MPI's choice) ends as the same case run by
 * one process (every rank runs it too: the reference) with the same status
 * (want), steps within 1, the [result] errors and headline within 1e-8
 * relative (the ranks' sums in MPI's order; a NaN where the other has a
 * number fails); the headline within tol of the exact value (the
 * discretisation's error: the reference's own measure), or, tol NaN, a
 * scene without one (exact NaN).  On one rank both runs are one process's. */
void check_scene_on_ranks(const char *file, int n, char *ov[], double tol, enum run_status want);

/* A case and what check_scene_lines compares of its runs. */
struct scene_lines {
    const char *file; /* the case file and its n overrides ov */
    int n;
    char **ov;
    const char *const *keys; /* [result] lines within 1e-8 relative, NULL-ended */
    const char *count;       /* a [result] line counting steps, as steps within 1 (or NULL) */
    enum run_status want;
};

/* A scene without a headline (its measures: s->keys) split as dims asks
 * against one process: the same status (s->want), steps within 1, each of
 * keys within 1e-8 relative (both 0 alike), s->count within 1, mass_error
 * within 1e-13 of one process's (the volume's round-off, summed in another
 * order; a scene without one passes it). */
void check_scene_lines(const struct scene_lines *s, const int dims[3]);

/* check_scene_lines on each of test_splits(n, ask) against one run of one
 * process. */
void check_scene_splits(const struct scene_lines *s, int n, const int ask[][3]);

#endif
