/* Geometric volume of fluid: the volume fraction T (1 = grains, 0 = air) of
 * every cell, transported by direction-split sweeps whose face fluxes are cut
 * geometrically from a piecewise-linear interface (PLIC) in the upwind cell.
 *
 * Interface in a cell: in the cell's own unit coordinates xi in [0,1]^3
 * (x = x_cell_low + h xi, so a plane keeps its shape on anisotropic cells) the
 * fluid is where m . xi <= alpha.  The normal m points out of the fluid and is
 * normalised |m_x| + |m_y| + |m_z| = 1; m = 0 marks a cell treated as
 * uniformly filled (T = 0 or 1, or no direction to be found).  Volume and
 * plane constant are related by the piecewise-polynomial formulas of
 * Scardovelli & Zaleski (2000, J. Comput. Phys. 164); a normal with a zero
 * component reduces them exactly to their 2D form.  Normals come from the
 * mixed Youngs-centred method (MYC) of Aulisa, Manservisi, Scardovelli &
 * Zaleski (2007, J. Comput. Phys. 225).
 *
 * Advection: one sweep along d moves T by the face velocity u_d only,
 *   T += dt/h_d [ c_c (u_{i+1} - u_i) - (F_{i+1} - F_i) ],
 * where F is the flux of T through each face (grain volume per unit area and
 * time, the upwind polygon's share of u dt) and c_c = 1 where T > 1/2 at the
 * start of the whole step, 0 elsewhere (Weymouth & Yue 2010, J. Comput.
 * Phys. 229).  The c_c term cancels over the sweeps of a step when the
 * velocity is discretely divergence-free, because c_c is the same in every
 * sweep: the step conserves grain volume to round-off.  c_c being the 0/1
 * indicator rather than T itself is what keeps 0 <= T <= 1 for a sweep CFL
 * number |u| dt / h_d <= 1/2 (VOF_CFL_MAX).
 *
 * A direction of one cell (thin 2D grids) has a zero normal component and is
 * never swept.  Ghost layers of T are the caller's (bc_fill_scalar). */
#ifndef MUFLOW_VOF_H
#define MUFLOW_VOF_H

#include "grid/grid.h"

/* The largest sweep CFL number |u| dt / h for which a sweep stays bounded. */
#define VOF_CFL_MAX 0.5

/* Fraction of the unit cube [0,1]^3 where m . xi <= alpha (m not zero; any
 * signs and scaling). */
double vof_plane_volume(const double m[3], double alpha);

/* The plane constant alpha with vof_plane_volume(m, alpha) = volume (volume
 * clamped to [0, 1]; m not zero). */
double vof_plane_alpha(const double m[3], double volume);

/* Fraction of the slab lo <= xi_d <= lo + width (0 <= lo, lo + width <= 1) of
 * the unit cube that lies in the fluid m . xi <= alpha, as a fraction of the
 * slab's own volume; with m = 0 the cell's uniform content t_uniform.  This is
 * the face value of T whose product with u is the geometric flux. */
double vof_slab_fraction(const double m[3], double alpha, double t_uniform, int d, double lo,
                         double width);

/* The same for the box lo <= xi <= lo + width (each within [0, 1]): the
 * fluid's share of a part of the cell, as a fraction of the part's volume
 * (the slab above is the box of one direction). */
double vof_box_fraction(const double m[3], double alpha, double t_uniform, const double lo[3],
                        const double width[3]);

/* Interface of every interior cell from T (ghost layer filled): normal[c]
 * receives m_c, alpha the plane constant (see above).  Cells with T <= 0 or
 * T >= 1 get m = 0.  Directions of one cell get m_c = 0. */
void vof_reconstruct(const struct grid *g, const double *T, double *normal[3], double *alpha);

/* c_c of Weymouth & Yue on interior cells: 1 where T > 1/2, else 0. */
void vof_indicator(const struct grid *g, const double *T, double *indicator);

/* One sweep along direction d (n[d] > 1): the flux of T through every face
 * 0..n[d] of d (interior cells across) into flux, in the units of vel_d
 * (flux = face value of T times u), then T of the interior cells updated as
 * above.  The upwind cell of face 0 or n[d] may be a ghost: normal, alpha and
 * T there are the caller's (a periodic copy keeps the two fluxes identical,
 * hence conservation).  vel_d: the face velocity of direction d (faces
 * 0..n[d] set).  Needs |vel_d| dt / h_d <= VOF_CFL_MAX for boundedness. */
void vof_sweep(const struct grid *g, int d, const double *vel_d, double dt,
               const double *indicator, double *const normal[3], const double *alpha, double *T,
               double *flux);

/* Sweep CFL numbers max |u_d| dt / h_d over faces 0..n[d] of the interior
 * cells, per direction into cfl[d] (0 for a direction of one cell, which is
 * never swept); returns the largest. */
double vof_cfl(const struct grid *g, double *const vel[3], double dt, double cfl[3]);

#endif
