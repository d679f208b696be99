/* The screened diffusion equation on a line of cells,
 *   -a2 d/dx (dx / dx) + c(x) x = s,
 * finite volumes on the cells' widths and centre distances, a zero value or
 * a zero flux on each end face.  The nonlocal fluidity's Newton step
 * (physics/ngf.h) on a layered flow is this along z; with the coefficients
 * handed in whole, a 2D/3D solve (the variable-coefficient multigrid) can
 * take the same arguments per cell. */
#ifndef MUFLOW_SOLVERS_LINE_SCREENED_H
#define MUFLOW_SOLVERS_LINE_SCREENED_H

enum line_end { LINE_ZERO = 0, LINE_NO_FLUX };

struct line_screened {
    int n;            /* cells */
    double a2;        /* diffusion coefficient, >= 0 */
    const double *hc; /* cell widths, [n] */
    const double *hf; /* centre distances, hf[k] between cells k - 1 and k, [n + 1] (ends unused) */
    enum line_end lo, hi;
};

/* out = s - (-a2 x'' + c x), the residual of x (s may be NULL: zero). */
void line_screened_residual(const struct line_screened *L, const double *c, const double *s,
                            const double *x, double *out);

/* Solves for x by the Thomas algorithm (no pivoting: the matrix must be
 * positive definite, as the fluidity's Newton matrix is on iterates above
 * the solution; see physics/ngf.c).  work holds n doubles.  0, or -1 when a
 * pivot is not positive (x then undefined). */
int line_screened_solve(const struct line_screened *L, const double *c, const double *s,
                        double *work, double *x);

#endif
