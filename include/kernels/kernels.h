/* The hot loops: pure functions over field arrays in the layout of grid.h.
 * No I/O, no allocation, no globals; OpenMP inside.  Velocity is vel[c], the
 * component c on the faces normal to direction c.  A box gives, per velocity
 * component, the face/cell index range [lo, hi) that carries unknowns; faces
 * outside it keep their prescribed values.
 *
 * Strain rates: gamma = grad u + grad u^T, |D|^2 = 0.5 gamma:gamma.  The
 * normal components live at cell centres, the shear components on the edges,
 * and each stress is evaluated where it lives: the viscosity of a normal
 * stress from |D| and p at the cell centre, that of a shear stress from |D|
 * and p on its edge, the missing components being mean squares of their four
 * nearest nodes.  In a unidirectional shear flow the constitutive law then
 * holds exactly on every edge, and the discrete profile is only as wrong as
 * the midpoint rule that integrates the shear rate.
 *
 * Edge arrays: E[c] holds the edges of the plane normal to direction c, i.e.
 * of the shear component (a, b) = the two other directions; edge e sits at
 * face index along a and b and cell index along c, in the layout of grid.h. */
#ifndef MUFLOW_KERNELS_H
#define MUFLOW_KERNELS_H

#include "grid/grid.h"
#include "kernels/rheology.h"

/* Fewer array slots than this (ghosts included, as the full layout holds
 * them: grid.padded; 32^3) and a kernel runs on the
 * calling thread alone: every OpenMP loop of kernels/ (and of the Poisson
 * solver) carries `if (kernel_parallel(g))`.  A parallel region costs a wake-up
 * and a barrier (microseconds when the other core is free, a time slice when it
 * is not), more than the whole loop on the thin profile grids (1 x 160 x 2,
 * 2 x 1 x 40: under 2,000 slots); bench/analysis.md, section 7. */
#define KERNEL_PARALLEL_MIN 32768

/* Fewer array slots than this and no parallel region of muflow runs on more
 * than one thread: the kernels' KERNEL_PARALLEL_MIN, the multigrid's levels
 * (a level of fewer cells runs on one thread), FFTW's threads (65,536 cells).
 * Above it some solver does (the projection's multigrid on a 2D grid well
 * below KERNEL_PARALLEL_MIN), and the waiting policy matters (app/main.c). */
#define PARALLEL_REGION_MIN 4096

static inline int kernel_parallel(const struct grid *g)
{
    return g->padded >= KERNEL_PARALLEL_MIN;
}

/* cn2 = 0.5 sum_i gamma_ii^2 on interior cells; e2[c] = gamma_ab^2 on the
 * edges of plane c, face indices 0..n along a and b, cells -1..n along c
 * (velocity ghosts filled). */
void kernel_strain(const struct grid *g, double *const vel[3], double *cn2, double *e2[3]);

/* Cell viscosity and the tangent coefficient of each normal stress,
 * tan_c[a] = eta + (d eta/d|D|) gamma_aa^2 / (2 |D|): the derivative of
 * tau_aa = eta gamma_aa with respect to gamma_aa.  Also |D|^2 and the
 * regularised pressure of the cell.  e2 as from kernel_strain; p is the total
 * pressure.  tan_c may be NULL (Picard).  b_c, if not NULL, receives
 * (d eta/d|D|) / (2|D|), the coefficient of the full tangent (0 at rest). */
void kernel_viscosity_cells(const struct grid *g, const struct rheology *r, double *const vel[3],
                            const double *cn2, double *const e2[3], const double *p,
                            double *eta, double *tan_c[3], double *shear2, double *preg,
                            double *b_c);

/* |D|^2 on edge e of plane c (the edge's own shear component plus the mean
 * squares of the other components around it), exactly as
 * kernel_viscosity_edges evaluates it: for a module that sets edge
 * viscosities of its own law (physics/bed.h) and must see the same |D|. */
double kernel_edge_shear2(const struct grid *g, const double *cn2, double *const e2[3], int c,
                          ptrdiff_t e);

/* Edge viscosity of each shear component and its tangent coefficient
 * eta + (d eta/d|D|) gamma_ab^2 / |D| (derivative of tau_ab = eta gamma_ab
 * with respect to gamma_ab), on face indices 0..n along a and b, cells
 * 0..n-1 along c.  p (total pressure) and cn2 need filled ghosts.  tan_e may
 * be NULL.  wraps: a bit per direction whose face n is the periodic image of
 * face 0 on this grid (periodic, and the grid holds the whole direction: a
 * decomposed direction's bit is 0); face n is then copied from face 0, not
 * evaluated again (half of the edges of a cross-section's planes along its
 * one-cell direction).  0: every face evaluated. */
void kernel_viscosity_edges(const struct grid *g, const struct rheology *r, const double *cn2,
                            double *const e2[3], const double *p, double *eta_e[3],
                            double *tan_e[3], double *b_e[3], int wraps);

/* The full consistent tangent couples every strain component through |D|:
 * d tau = eta d gamma + b gamma d(|D|^2), b = (d eta/d|D|) / (2|D|).  These
 * give d(|D|^2) along a direction v at every stress location, times b:
 * pn = sum_i gamma_ii(u) gamma_ii(v) per cell, pe[c] = gamma_c(u) gamma_c(v)
 * per edge (ranges as kernel_strain); then B = b d(|D|^2)[v] with d(|D|^2)
 * built from pn and pe exactly as |D|^2 is built from cn2 and e2 (pn needs
 * filled ghosts). */
void kernel_strain_products(const struct grid *g, double *const u[3], double *const v[3],
                            double *pn, double *pe[3]);
void kernel_tangent_cells(const struct grid *g, const double *pn, double *const pe[3],
                          const double *b_c, double *B_c);
void kernel_tangent_edges(const struct grid *g, const double *pn, double *const pe[3],
                          double *const b_e[3], double *B_e[3]);

/* The implicit operator, mass v - div tau(v), for a v whose only nonzero
 * component is c, along the grid's periodic direction of one cell (the
 * flow of a cross-section: viscous_krylov.c's solve of that component alone), on
 * uniform cells: what kernel_stress_divergence and the tangent's terms
 * (kernel_strain_products, kernel_tangent_edges, with the base strains gb
 * of kernel_flow_gammas and the edges' b_edge; b_edge NULL: Picard, gb not
 * read) give for such a v, in three
 * passes over the cross-section instead of the general path's dozen over
 * every component and plane; the same sums up to rounding.  v's ghosts
 * filled; A_edge and b_edge as viscous.h; mass_face NULL: the scalar mass.
 * pe and S are work arrays (the two shear planes' strain products and
 * stresses); out is written on the cross-section's cells (index 0 along
 * c). */
void kernel_flow_block(const struct grid *g, int c, const double *const gb[2], const double *v,
                       const double *const A_edge[3], const double *const b_edge[3],
                       const double *mass_face, double mass, double *pe[2], double *S[2],
                       double *out);

/* The base strains kernel_flow_block reads with Newton (its gb): on the
 * edges of the two shear planes of the flow component c (gb[t]: the plane
 * of c and the t-th other direction, ascending), gamma of the base
 * velocity as kernel_strain_products takes it, over face indices 0 .. n of
 * that direction and cells -1 .. n of the third.  They are constant over a
 * Newton step, so its operator applications read them instead of
 * recomputing them (docs/numerics/multigrid.md, `gmg`).  base with filled
 * ghosts. */
void kernel_flow_gammas(const struct grid *g, int c, double *const base[3], double *gb[2]);

/* The full tangent's cross term in the block of that flow component c
 * (multigrid_set_mixed's coefficients, viscous_gmg.c): the edge stress
 * gamma_cd carries b gamma_cd d|D|^2, whose part from the other shear e is
 * 2 mean4(gamma_ce dgamma_ce) over the four edges around it; with the base
 * strain's mean taken out of the sum, k[t] = 2 b gamma_cd mean4(gamma_ce)
 * on the interior faces of d, d the t-th of the two directions other than
 * c (ascending), e the other.  gb: the base strains of kernel_flow_gammas;
 * b_edge per edge plane as viscous.h. */
void kernel_cross_coefficients(const struct grid *g, int c, const double *const gb[2],
                               const double *const b_edge[3], double *k[2]);

/* out_c = [div tau]_c on the faces of act[c] (zero elsewhere), with
 * tau_aa = A_cell[a] gamma_aa(v) at cells and tau_ab = A_edge[c] gamma_ab(v)
 * on the edges of plane c.  With the viscosities and v = u this is the stress
 * term of the momentum residual; with the tangent coefficients it is the
 * linearised operator, symmetric positive definite.  A_cell needs filled ghosts.
 * out must not share memory with the inputs (the loops use restrict). */
void kernel_stress_divergence(const struct grid *g, const struct box act[3],
                              const double *const A_cell[3], const double *const A_edge[3],
                              double *const v[3], double *out[3]);

/* The same sum with every term replaced by its magnitude (differences by the
 * sums of the absolute values): the rounding error of the stress divergence
 * is a few machine epsilons times this. */
/* The divergence's component c alone (out[c]; the others untouched). */
void kernel_stress_component(const struct grid *g, const struct box act[3], int c,
                             const double *const A_cell[3], const double *const A_edge[3],
                             double *const v[3], double *out[3]);

void kernel_stress_magnitude(const struct grid *g, const struct box act[3],
                             const double *const A_cell[3], const double *const A_edge[3],
                             double *const v[3], double *out[3]);
/* The same with every velocity's size taken as at least v_floor: the terms'
 * size when each velocity carries an absolute error of that scale. */
void kernel_stress_magnitude_at(const struct grid *g, const struct box act[3],
                                const double *const A_cell[3], const double *const A_edge[3],
                                double *const v[3], double v_floor, double *out[3]);

/* max over the unknowns of max(|r| - eps_factor * (|m| + |f|), 0): the part
 * of a residual r that its round-off cannot explain. */
double kernel_residual_excess(const struct grid *g, const struct box act[3], double *const r[3],
                              double *const m[3], double *const f[3], double eps_factor);

/* Cell-centred divergence of the face field vel (ghost faces filled). */
void kernel_divergence(const struct grid *g, double *const vel[3], double *div);

/* vel_c -= scale * grad_c(p) on the faces of act[c] (p: cell field, ghosts filled). */
void kernel_gradient_update(const struct grid *g, const struct box act[3], const double *p,
                            double scale, double *vel[3]);

/* vel_c -= scale * beta_c * grad_c(p) on the faces of act[c]: the projection
 * with a face coefficient (beta = rho_ref / rho for a variable density). */
void kernel_gradient_update_coef(const struct grid *g, const struct box act[3], const double *p,
                                 double scale, double *const beta[3], double *vel[3]);

/* out_c = -div(u u_c) (conservative, centred, second order) on act[c], zero
 * elsewhere; out must not share memory with vel (restrict). */
void kernel_advection(const struct grid *g, const struct box act[3], double *const vel[3],
                      double *out[3]);
/* The same in upwind form (kernels/advection_upwind.c), the face value
 * first order (donor cell), second order with van Leer's limiter, or
 * QUICK's unlimited upwind-biased quadratic: damps the free surfaces that
 * the centred form, energy-neutral, leaves to grow under a forward-Euler
 * step. */
enum advection_face { ADVECTION_FACE_DONOR = 0, ADVECTION_FACE_VANLEER, ADVECTION_FACE_QUICK };
void kernel_advection_upwind(const struct grid *g, const struct box act[3],
                             double *const vel[3], enum advection_face face, double *out[3]);

/* Vector operations over the unknowns of act (three components). */
double kernel_dot(const struct grid *g, const struct box act[3], double *const a[3],
                  double *const b[3]);
double kernel_max_abs(const struct grid *g, const struct box act[3], double *const a[3]);
/* y += alpha x */
void kernel_axpy(const struct grid *g, const struct box act[3], double alpha, double *const x[3],
                 double *y[3]);
/* y += a .* x, and y = a .* x - y (a per face: a variable density) */
void kernel_multiply_add(const struct grid *g, const struct box act[3], double *const a[3],
                         double *const x[3], double *y[3]);
void kernel_multiply_minus(const struct grid *g, const struct box act[3], const double *const a[3],
                           double *const x[3], double *y[3]);
/* y = alpha x + beta y */
void kernel_lincomb(const struct grid *g, const struct box act[3], double alpha, double *const x[3],
                    double beta, double *y[3]);
/* Sum, 2-norm and max |f| of a cell field over interior cells,
 * deterministic across runs. */
double kernel_sum(const struct grid *g, const double *f);
double kernel_norm2_cells(const struct grid *g, const double *f);
double kernel_max_abs_cells(const struct grid *g, const double *f);
/* Mean of a field over the indices of box b (a component's active faces),
 * deterministic across runs; 0 for an empty box. */
double kernel_box_mean(const struct grid *g, const struct box *b, const double *f);

/* The mean of component c's field f over box b, each node weighed by its
 * control volume (kernel_box_mean where the grid is uniform). */
double kernel_component_mean(const struct grid *g, const struct box *b, int c, const double *f);

#endif
