/* Run output: summary.ini, history.csv in the output folder (profile.csv:
 * diagnostics/profile.h; field files and checkpoints: fields_h5.h,
 * checkpoint.h).
 * Every file is written under a temporary name and renamed when complete, so
 * a file that exists is whole. */
#ifndef MUFLOW_OUTPUT_H
#define MUFLOW_OUTPUT_H

#include <stdio.h>
#include "march/march.h"
#include "march/results.h"
#include "platform/output_file.h"

/* A run's comparison with the exact (or reference) solution of its scene,
 * which the profile's diagnostics compute (diagnostics/profile.h). */
struct scene_errors {
    int valid;             /* the scene has an analytic solution here */
    double err_rms;        /* sqrt(mean (u - u_ex)^2) over layers; for the cavity the
                              RMS difference from the reference curve at its points
                              (err_midline) */
    double err_max;        /* max |u - u_ex| */
    double err_rms_paper;  /* sqrt(sum (u - u_ex)^2) / N, the papers' form */
    double headline, headline_exact;
};

/* The names of the comparison's lines in [result], the scene's
 * (scenes/scene.h: scene_result_names); headline NULL: no such lines. */
struct result_names {
    const char *headline;  /* the headline value's key (u_surface, psi_max) */
    const char *error;     /* err_rms, or err_midline */
    const char *solution;  /* "exact" or "reference": the headline's counterpart */
    int no_err_rms_paper;  /* no err_rms_paper line */
};

/* What a run returns (run_case_opts, app/run.h): a plain value, nothing to
 * free; its texts are arrays inside it. */
struct run_result {
    struct result_names names; /* the scene's names of the comparison's lines */
    enum run_status status;
    long steps;
    long rejected_steps; /* steady mode: steps retried with a smaller pseudo-time step */
    long pressure_iterations;  /* the projection's multigrid-CG iterations (FFT: 0) */
    long pressure_unconverged; /* its solves that ended above their tolerance */
    long linear_unconverged;   /* implicit solves stopped at solver.max_linear_iterations */
    long grid_matrices;        /* matrices of the grid's unknowns probed (march.h) */
    long pressure_matrices;    /* the projection's whole-grid factorisations in this
                                  process's run (pressure.h: pressure_direct) */
    long preconditioner_fallbacks; /* implicit steps whose factorisation or AMG setup
                                      failed, in this process (the line blocks served),
                                      and coupled steps whose GMRES failed (the LU
                                      served) */
    double time, wall_seconds, residual, divergence;
    struct scene_errors errors;
    char message[256];
    int signal;            /* SIGINT / SIGTERM that stopped the run, or 0 */
    int checkpointed;      /* a checkpoint of the final state was written */
    int restartable;       /* --restart continues from it (else solver.initial_state only) */
    /* what the scene and the modules add: summary lines in order, one
     * terminal line, and the note printed when the run was interrupted and
     * cannot continue */
    struct result_values values;
    char scene_line[320];
    char stop_note[256];
};

/* Adds the summary line key = printf(fmt, ...) (dropped beyond
 * RESULT_VALUES_MAX). */
void run_result_add(struct run_result *r, const char *key, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* A measured value beside its reference: the lines name = value, name_exact
 * = reference (%.10g) and name_error = value / reference - 1 (%.6e). */
void run_result_add_compared(struct run_result *r, const char *name, double value,
                             double reference);
/* The lines of summary.ini's [result] section, in its order: calls
 * line(ctx, key, text, value) with the text the summary writes and the value
 * as a number (exact for the run's own numbers: steps, time, err_rms, the
 * headline, ...; a scene line's text read as a number; NaN for a text:
 * status, message). */
typedef void (*result_line_fn)(void *ctx, const char *key, const char *text, double value);
void run_result_lines(const struct run_result *r, result_line_fn line, void *ctx);
/* The value of the [result] line key (any of run_result_lines': err_rms,
 * err_max, the headline and its exact value, steps, time, a scene's line),
 * NaN when there is none or it is a text. */
double run_result_value(const struct run_result *r, const char *key);

/* Creates dir and its parents; returns 0, or -1 with the cause in err. */
int output_make_dir(const char *dir, char *err, size_t errlen);

/* For a fresh run (not a restart) into a folder that may hold an earlier
 * run's output: removes the files a run writes there -- fields_<step>.h5
 * (six digits or more), fields.xdmf, history.csv, profile.csv, summary.ini,
 * checkpoint.h5, the names in extra (NULL-terminated, or NULL: a run
 * passes every scene's and module's own files, scene_output_files in
 * scenes/scene.h), and each of these names with .tmp
 * appended -- and nothing else (other files, folders of those names).
 * Returns the number of files removed (0 when dir does not exist), or -1
 * with the cause in err. */
int output_remove_run_files(const char *dir, const char *const *extra, char *err, size_t errlen);

/* history.csv, row by row. */
struct history {
    struct output_file file;
};
/* error_name: the scene's name of its error column (err_rms, err_midline). */
int history_open(struct history *h, const char *dir, const char *error_name, char *err,
                 size_t errlen);
/* Like history_open for a run that continues from a checkpoint of step upto:
 * the new file starts with the rows of steps <= upto of the previous one
 * (history.csv.tmp when a run died before renaming it, else history.csv). */
int history_resume(struct history *h, const char *dir, const char *error_name, long upto,
                   char *err, size_t errlen);
/* Pushes the rows so far to the .tmp file (before a checkpoint, so that a
 * restart after a crash finds them). */
void history_flush(struct history *h);
void history_row(struct history *h, const struct march_state *st, const struct scene_errors *e);
int history_close(struct history *h, char *err, size_t errlen);

int output_summary(const char *dir, const struct muflow_case *cs, const struct run_result *r,
                   char *err, size_t errlen);

#endif
