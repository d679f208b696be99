/* The open faces in the coupled step's Newton matrix (stage_coupled.c).
 *
 * An open face's normal velocity is state, not a velocity unknown: the
 * probed operator moves it with its inner face (bc_fill_velocity_homogeneous
 * copies the inner face's increment), and the coupled step gives each open
 * face m one more unknown e_m, its own increment beyond the inner face's:
 * du_f = du_i + e_m.  e_m enters
 *   - the boundary cell's divergence (s share / h, s the outward sign);
 *   - the momentum rows its face's stencil reaches: the columns
 *     d R / d u_f, probed here by applying the operator to the open faces'
 *     own increments (bc_fill_velocity_open_given), one colour at a time;
 * and its row is the open face's balance at a steady state of the
 * projection's march (open_faces.h), a_f = a_i, linear in dp alone:
 *
 *     dG_f - dG_i = (F_f - G_f) - (F_i - G_i),
 *     G_f = -2 s p_c / h (the Dirichlet ghost),  G_i = (p_hi - p_lo) / h,
 *
 * which also fixes the pressure's level (the box needs no pinned cell).
 *
 * Colours: an open face reaches the rows of faces within two indices of it
 * in every direction (the stress divergence of the tangent's strain
 * products), so faces five apart along each tangential direction never
 * share a row; a periodic direction whose length is not a multiple of five
 * gives its remainder colours of its own (none meet across the seam), and
 * each side and direction of the box its own colours. */
#ifndef MUFLOW_MARCH_COUPLED_OPEN_H
#define MUFLOW_MARCH_COUPLED_OPEN_H

#include <stddef.h>

struct march_state;
struct probe_matrix;
struct viscous_problem;
struct coupled_open;

/* An open face pf of direction d beside the boundary cell pc (outward sign
 * s, spacing h, the divergence share of the face), its inner face pi and
 * that face's unknown ki, and the cell numbers of pc (qc) and of the inner
 * face's two cells (qlo, qhi). */
struct open_link {
    ptrdiff_t pf, pi, pc;
    int d, ki, qc, qlo, qhi, colour;
    double s, h, share;
};

/* The open faces of st's box for the coupled step's numbering: nu velocity
 * unknowns at field slots slot[] (components from pm), cell numbers cell[]
 * per cell slot.  *out NULL when the box has no open face.  0; -1 out of
 * memory; -2 when an open face's inner face is not an unknown (held in a
 * body). */
int coupled_open_create(struct coupled_open **out, const struct march_state *st,
                        const struct probe_matrix *pm, const ptrdiff_t *slot, int nu,
                        const int *cell);
void coupled_open_destroy(struct coupled_open *co);

/* The number of open faces (0 for NULL) and face m. */
int coupled_open_count(const struct coupled_open *co);
const struct open_link *coupled_open_link(const struct coupled_open *co, int m);

/* Probes the columns d R / d u_f of the problem pb at st's state (its
 * operator applied with the open faces' increments given); 0, or -1 out of
 * memory. */
int coupled_open_probe(struct coupled_open *co, struct march_state *st,
                       const struct viscous_problem *pb);

/* The probed column of face m: n rows (velocity unknowns) and values. */
void coupled_open_column(const struct coupled_open *co, int m, int *n, const int **rows,
                         const double **values);

/* The number of probed entries (the matrix's extra nonzeros). */
long coupled_open_entries(const struct coupled_open *co);

/* Face m's right-hand side (F_f - G_f) - (F_i - G_i) at st's state. */
double coupled_open_rhs(const struct coupled_open *co, const struct march_state *st, int m);

#endif
