/* The viscosity's dependence on the pressure in the coupled step's Newton
 * matrix: the columns -d(div tau)/d p of the momentum rows.
 *
 * Why: a pressure-dependent law (mu(I): eta ~ mu p / |D|) makes the stress
 * depend on p at first order, and in a plug (|D| below lambda) on p alone:
 * there tau ~ mu p D / lambda.  Without these columns the Newton matrix of
 * the coupled step misses that dependence; the granular cylinder then
 * stalled at a residual that grew tenfold per tenfold decrease of lambda
 * (docs/numerics/coupled-step.md).
 *
 * How: by coloured finite differences of the viscous residual in the
 * cell pressures, as the velocity block is probed.  A cell's pressure
 * reaches the viscosity of the cell and of its surrounding edges (the mean
 * of four cells), so the faces it moves are those of component a with
 * index i_a or i_a + 1 along a and within one cell along every other
 * direction; cells three apart along some direction never share such a
 * face, so one pass perturbs every third cell in each direction (up to five
 * residues along a periodic direction whose length is not a multiple of 3,
 * so that none meet across the seam). */
#ifndef MUFLOW_MARCH_COUPLED_PRESSURE_H
#define MUFLOW_MARCH_COUPLED_PRESSURE_H

#include <stddef.h>

struct coupled_view;
struct march_state;
struct probe_matrix;
struct pressure_columns;

/* The pattern: for each of the nu velocity unknowns (field slot slot[k]),
 * the cells (numbered by cell[] per cell slot, periodic images included,
 * -1 beyond a bounded face: the coupled step's numbering, x fastest) whose
 * pressure can move its row, leaving out the cells whose dp is held
 * (held[q]) and the rows of faces held in a body.  cell and held are kept,
 * not copied.  NULL when out of memory. */
struct pressure_columns *pressure_columns_create(struct coupled_view *view,
                                                 const struct probe_matrix *pm,
                                                 const ptrdiff_t *slot, int nu, const int *cell,
                                                 const unsigned char *held);

/* The entries of row k: n cells and their values -d R_k / d p_cell. */
void pressure_columns_row(const struct pressure_columns *pc, int k, int *n, const int **cells,
                          const double **values);

/* The number of entries (the matrix's extra nonzeros). */
long pressure_columns_count(const struct pressure_columns *pc);

/* Probes the values at st's velocity and pressure.  st's pressure, viscosity
 * and tangents are those of st again on return.  0, or -1 out of memory. */
int pressure_columns_probe(struct pressure_columns *pc, struct march_state *st);

void pressure_columns_destroy(struct pressure_columns *pc);

#endif
