/* Restarted GMRES (Saad and Schultz) on vectors of n doubles, preconditioned
 * on the right: the residual it monitors is the true one, |b - A x|, and
 * every restart recomputes it from x.  The operator and the preconditioner
 * are callbacks, so that any matrix or matrix-free operator can use it. */
#ifndef MUFLOW_GMRES_H
#define MUFLOW_GMRES_H

/* y = op(x) (the operator, or the preconditioner's approximate inverse). */
typedef void (*gmres_apply_fn)(void *ctx, const double *x, double *y);

struct gmres;

/* For vectors of n entries and a restart after m iterations.  Returns 0, or
 * -1 when memory runs out. */
int gmres_create(struct gmres **out, long n, int m);

/* The same keeping the preconditioned basis M^-1 v_k as well (m more
 * vectors): the update x += M^-1 V y is then Z y, one preconditioner
 * application less per restart cycle, and the preconditioner may change
 * from one iteration to the next (flexible GMRES, Saad 1993). */
int gmres_create_flexible(struct gmres **out, long n, int m);
void gmres_destroy(struct gmres *g);

/* The vectors as one rank's share of vectors split over the ranks of dc
 * (grid/decomp.h): every dot product summed over them (NULL: one process). */
struct decomp;
void gmres_set_decomp(struct gmres *g, const struct decomp *dc);

struct gmres_stats {
    int iterations;           /* operator applications in the Krylov loop */
    double relative_residual; /* |b - A x| / |b| at the end */
};

/* A x = b from the x given (|b| = 0: x = 0 at once).  Returns 0 when
 * |b - A x| <= rtol |b|, 1 at maxit iterations (x the last iterate), -1 on
 * a breakdown or a non-finite residual. */
int gmres_solve(struct gmres *g, gmres_apply_fn op, gmres_apply_fn prec, void *ctx,
                const double *b, double *x, double rtol, int maxit, struct gmres_stats *st);

#endif
