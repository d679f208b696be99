/* The screened diffusion equation on a line of cells (line_screened.h).
 * Row k, with the fluxes F_k = a2 (x_k - x_{k-1}) / hf_k across face k:
 *   (F_k - F_{k+1}) / hc_k + c_k x_k = s_k,
 * the end faces' flux a2 x_0 / (hc_0 / 2) for a zero value on the face (the
 * ghost -x_0 of a uniform grid), 0 for no flux. */
#include "solvers/line_screened.h"

/* The face couplings a2 / (hf hc) of row k to k - 1 (lo) and k + 1 (hi), and
 * the end faces' part of the diagonal. */
static void row_coefficients(const struct line_screened *L, int k, double *lo, double *hi,
                             double *end)
{
    const int n = L->n;
    double hc = L->hc[k];
    *lo = k > 0 ? L->a2 / (L->hf[k] * hc) : 0.0;
    *hi = k < n - 1 ? L->a2 / (L->hf[k + 1] * hc) : 0.0;
    *end = 0.0;
    if (k == 0 && L->lo == LINE_ZERO)
        *end += L->a2 / (0.5 * hc * hc);
    if (k == n - 1 && L->hi == LINE_ZERO)
        *end += L->a2 / (0.5 * hc * hc);
}

void line_screened_residual(const struct line_screened *L, const double *c, const double *s,
                            const double *x, double *out)
{
    for (int k = 0; k < L->n; k++) {
        double lo, hi, end;
        row_coefficients(L, k, &lo, &hi, &end);
        double ax = (lo + hi + end + c[k]) * x[k];
        if (k > 0)
            ax -= lo * x[k - 1];
        if (k < L->n - 1)
            ax -= hi * x[k + 1];
        out[k] = (s ? s[k] : 0.0) - ax;
    }
}

int line_screened_solve(const struct line_screened *L, const double *c, const double *s,
                        double *work, double *x)
{
    /* forward elimination: work[k] = -hi_k / pivot_k, x[k] the eliminated
     * right-hand side; then back substitution */
    double prev_upper = 0.0;
    for (int k = 0; k < L->n; k++) {
        double lo, hi, end;
        row_coefficients(L, k, &lo, &hi, &end);
        double pivot = lo + hi + end + c[k] - lo * prev_upper;
        if (!(pivot > 0.0))
            return -1;
        work[k] = -hi / pivot;
        x[k] = ((s ? s[k] : 0.0) + (k > 0 ? lo * x[k - 1] : 0.0)) / pivot;
        prev_upper = hi / pivot;
    }
    for (int k = L->n - 2; k >= 0; k--)
        x[k] -= work[k] * x[k + 1];
    return 0;
}
