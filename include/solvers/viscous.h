/* The implicit viscous step, matrix-free:
 *   (mass) x - div tau(x) = rhs,   tau_aa = A_cell[a] gamma_aa, tau_ab = A_edge gamma_ab,
 * with mass = rho/dt and the coefficients either the viscosities (Picard, eta
 * lagged) or the tangent coefficients d tau / d gamma of each stress at its own
 * location (kernels.h): the consistent tangent of a unidirectional shear flow,
 * so the step becomes Newton's method as dt grows.  Every coefficient is
 * positive, so the operator is symmetric positive definite and solved by
 * preconditioned conjugate gradients.
 *
 * Preconditioner: one banded block per grid line along a non-periodic
 * direction, per velocity component.  The blocks are found by probing the
 * operator itself with five comb vectors (the stencil reaches two nodes along
 * a line), all lines at once, so each block holds the line's couplings summed
 * over the neighbouring lines: exact for flows uniform across the lines (the
 * profile scenes), a line smoother otherwise.  Blocks are factorised by GSL's
 * banded Cholesky. */
#ifndef MUFLOW_VISCOUS_H
#define MUFLOW_VISCOUS_H

#include <stddef.h>
#include "grid/boundary.h"
#include "grid/grid.h"
#include "kernels/embedded.h"
#include "kernels/kernels.h"
#include "solvers/amg_hypre.h"
#include "solvers/viscous_operator.h"


struct viscous_stats {
    int iterations;
    double relative_residual;
    int failed_blocks;      /* line blocks that were not positive definite */
    int direct;             /* 1 when the sparse factorisation was used */
};

struct viscous_solver;

enum viscous_precond { VISCOUS_LINE = 0, VISCOUS_CHOLESKY, VISCOUS_LU, VISCOUS_AMG, VISCOUS_FOURIER,
                        VISCOUS_GMG, VISCOUS_MG };

/* line_dir: 0, 1, 2, or -1 to pick the non-periodic direction with most cells.
 * kind: line blocks; the probed sparse Cholesky factorisation of the
 * symmetric operator; the probed sparse LU of the full tangent
 * (sparse_direct.h); or algebraic multigrid (BoomerAMG, amg_hypre.h) on the
 * probed matrix inside restarted GMRES, for the symmetric operator and the
 * full tangent alike; each with line blocks as fallback; or the line blocks
 * of every plane Fourier mode (fourier_lines.h: both directions across the
 * lines periodic), for the symmetric operator; or the geometric multigrid
 * of the velocity components along periodic directions (viscous_gmg.h:
 * their blocks of the symmetric operator, or of the diagonal tangent,
 * zebra line smoothing) inside restarted GMRES on those components, the
 * others left out while their right-hand side is negligible (else their
 * line blocks, with BiCGStab), matrix-free.  Returns 0, or -1
 * with a message in err. */
int viscous_create(struct viscous_solver **out, const struct grid *g, const struct boundary *bc,
                   const struct box act[3], int line_dir, enum viscous_precond kind, char *err,
                   size_t errlen);
void viscous_destroy(struct viscous_solver *s);

/* out = operator(v); v's ghosts are overwritten (filled from bc). */
void viscous_apply(struct viscous_solver *s, const struct viscous_problem *pb, double *v[3],
                   double *out[3]);

/* The operator of pb as an operator_fn (probe_matrix.h) with ctx a struct
 * viscous_operator: what the probed matrices, the Fourier blocks and the
 * coupled step probe. */
struct viscous_operator {
    struct viscous_solver *s;
    const struct viscous_problem *pb;
};
void viscous_operator_apply(void *ctx, double *v[3], double *out[3]);

/* Builds the preconditioner for this operator (probes and factorises the
 * line blocks, probes the sparse factorisation's matrix, sets up the AMG
 * hierarchy).  Returns 0, or 1 when the AMG setup or the probing failed and
 * the line blocks serve instead (viscous_precond_info: fallbacks, cause).
 * The sparse factorisation itself runs in viscous_solve, for the blocks of
 * components its right-hand side reaches; if it fails there, the line
 * blocks serve that solve (counted and told the same way). */
int viscous_precondition(struct viscous_solver *s, const struct viscous_problem *pb);

/* Teaches the probed matrix pm (of this solver's unknowns) the pattern of
 * pb's kind of operator (full tangent or not, augmentation or not, open
 * faces given or not), once per kind (*learnt holds the last kind, 0 at
 * first): the operator with generic coefficients, whose pattern holds that
 * of any coefficients, zeros included, through probe_matrix_learn.  Its
 * assemblies then probe once per colour of the pattern, fewer than the
 * structured colouring takes (docs/numerics/linear-solvers.md, "A learnt
 * colouring"). */
struct probe_matrix;
void viscous_learn_pattern(struct viscous_solver *s, struct probe_matrix *pm, int *learnt,
                           const struct viscous_problem *pb);

/* Solves operator(x) = rhs from x = 0 to relative residual rtol: conjugate
 * gradients for the symmetric operator, BiCGStab for the full tangent.
 * Returns 0 when converged, 1 when maxit was reached, -1 on a breakdown. */
int viscous_solve(struct viscous_solver *s, const struct viscous_problem *pb, double *const rhs[3],
                  double *x[3], double rtol, int maxit, struct viscous_stats *st);

/* Settings of the VISCOUS_AMG kind. */
struct viscous_amg {
    struct amg_options amg;
    int bicgstab;           /* 1: BiCGStab instead of GMRES */
    int restart;            /* GMRES restart length */
    int picard;             /* 1: the multigrid is built on the symmetric Picard
                               operator (viscosities, no b terms) of the same state,
                               and preconditions the full tangent */
    int drop_augmentation;  /* 1: built without the grad-div term */
    int reuse;              /* > 0: a hierarchy serves up to this many further
                               steps while the Krylov iterations stay within twice
                               those of its first solve (a failed solve rebuilds it) */
};

/* amg_options_default, GMRES(20), the operator solved, set up every step. */
void viscous_amg_defaults(struct viscous_amg *c);

/* Overrides from a comma-separated key=value list: amg_options_parse's keys
 * plus krylov=gmres|bicgstab, restart=N, picard=0|1, aug=1|0 (0 drops the
 * augmentation from the multigrid's matrix), reuse=N.  Returns 0 or -1 with a message. */
int viscous_amg_parse(struct viscous_amg *c, const char *spec, char *err, size_t errlen);

/* Sets them for a VISCOUS_AMG solver (before viscous_precondition).  Returns
 * 0, or -1 with a message (another kind, or out of memory). */
int viscous_set_amg(struct viscous_solver *s, const struct viscous_amg *c, char *err,
                    size_t errlen);

/* What the last viscous_precondition built and how long it and the last
 * viscous_solve took (CPU seconds of the process), for measurements. */
struct viscous_precond_info {
    int kind;               /* enum viscous_precond in use (VISCOUS_LINE after a fallback) */
    long unknowns, entries; /* of the probed matrix (AMG) */
    double probe_seconds;   /* probing and assembly (AMG) */
    double setup_seconds;   /* multigrid setup (AMG); probing and factorisation (LU) */
    double solve_seconds;   /* the last viscous_solve */
    int levels;
    double complexity;      /* operator complexity */
    int blocks;             /* AMG: diagonal blocks set up apart (amg_hypre_blocks) */
    int reused;             /* 1: the last viscous_precondition kept the hierarchy */
    long grid_matrices;     /* matrices of the grid's unknowns probed and factorised
                               or set up for the AMG (a multigrid's coarsest level,
                               the line and Fourier blocks not counted) */
    long fallbacks;         /* preconditioners whose factorisation or AMG setup
                               failed (the line blocks served) */
    char cause[200];        /* why the last of them failed */
    int dropped_blocks;     /* blocks of components the last solve left out (a
                               negligible part of its right-hand side) */
    int probed_components;  /* of the matrix in use: the components whose
                               columns its probing took (bit c; 7: all) */
    long lagged_factors;    /* Cholesky with the full tangent: times the diagonal
                               tangent was not positive definite and the lagged
                               viscosity's factors served instead */
};
void viscous_precond_info(const struct viscous_solver *s, struct viscous_precond_info *info);

/* The kind's name as solver.preconditioner spells it ("?" out of range). */
const char *viscous_precond_name(enum viscous_precond kind);

/* on: every solve keeps every block of components (none left out for a
 * negligible part of the right-hand side; for measurements and tests). */
void viscous_keep_blocks(struct viscous_solver *s, int on);

/* Bytes viscous_create allocates on g with the faces bc for kind, without
 * the sparse factorisation (sparse_direct_memory_estimate). */
double viscous_memory_estimate(const struct grid *g, const struct boundary *bc,
                               enum viscous_precond kind);
/* Bytes gmg adds to viscous_memory_estimate of a rank's block g of the
 * split grid gg: its hierarchies on gg, not g, and the gathered arrays
 * (its cross-section whole on every rank: viscous_gmg.h). */
double viscous_gmg_gathered_estimate(const struct grid *gg, const struct grid *g);

/* A sparse factorisation (cholesky, lu), the fourier blocks or an AMG
 * hierarchy then precondition up to steps further viscous_precondition calls
 * while the Krylov iterations stay within twice those of its first solve
 * plus 2; a failed solve rebuilds it (0: one every call, the default).  For
 * the AMG it sets viscous_amg's reuse (a later viscous_set_amg replaces it). */
void viscous_set_reuse(struct viscous_solver *s, int steps);
/* The kept factorisation or hierarchy is built anew at the next
 * viscous_precondition call (the caller changed the operator's mass term). */
void viscous_renew(struct viscous_solver *s);

/* When on, an AMG solver whose GMRES fails on a fresh hierarchy (its
 * iteration cap, or a breakdown) gives way for good to the probed sparse LU
 * of the same full tangent: the solve is done again with it, and
 * viscous_precond_info counts a fallback and says why.  The caller allows
 * it where the LU's factorisation fits (march_create.c).  Off by default. */
void viscous_allow_lu_fallback(struct viscous_solver *s, int on);

/* The velocity multigrid of a VISCOUS_MG solver (NULL for another kind):
 * the coupled step's preconditioner sets it up and cycles it itself
 * (march/coupled_mg.h). */
struct velocity_mg *viscous_velocity_mg(struct viscous_solver *s);

/* The line direction in use. */
int viscous_line_direction(const struct viscous_solver *s);


#endif
