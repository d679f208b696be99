/* A solid body embedded in the grid, as the implicit operator and the
 * residual see it (built by physics/obstacle.c, applied by these pure loops).
 *
 * Velocity nodes inside the body are not unknowns: they are held at 0 while
 * the stencils read them, and their rows are the mass term alone, so they
 * are decoupled both ways and the operator stays symmetric.
 *
 * A grid link from a fluid node P to a held node S that the surface cuts at
 * theta h from P (0 < theta <= 1) should end on the surface, where the
 * velocity is 0, not at S.  With the linear extrapolation through the
 * surface value, the ghost at S is v_G = -(1 - theta) / theta v_P
 * (Gibou et al., J. Comput. Phys. 176 (2002) 205): the link's term
 * c (v_S - v_P) with v_S = 0 misses c v_G, which is a multiple of v_P alone.
 * So the correction is diagonal (the operator stays symmetric, and the line
 * blocks and probed factorisations capture it without a wider reach):
 *   div tau_P += -c (1 - theta) / theta v_P.
 * c is the Laplacian's part of the link: A / h^2 for the links of the shear
 * stresses and of the normal stress alike.  The stress kernel's normal
 * stress carries 2 A: for a constant viscosity its second half,
 * d_a(d_a v_a) beside the shear stresses' d_b(d_a v_b), is d_a(div v), the
 * plain divergence, which the cut cells' flux form does not make 0 next
 * to the body; the caller takes it out there (the operator adds
 * grad(A div v), the residual subtracts it: physics/obstacle.c,
 * solvers/viscous.c), so what the links correct is the Laplacian.  Only in
 * the cut cells (a face's open share below 1): elsewhere the plain
 * divergence is the projected one, and taking grad(A div v) out of the
 * operator there drops the stiffness that holds a split step's velocity
 * near solenoidal; with a viscosity contrast of 1e7 (a granular bed) the
 * steady Newton march then stalled at a residual of 2e2 (the square duct
 * with a body covering nothing: 117 steps without it).
 */
#ifndef MUFLOW_KERNELS_EMBEDDED_H
#define MUFLOW_KERNELS_EMBEDDED_H

#include <stddef.h>
#include "grid/grid.h"

/* One cut link of fluid node p of component c. */
struct embedded_link {
    ptrdiff_t p;   /* the fluid node */
    ptrdiff_t at;  /* where the link's coefficient lives: a cell or an edge */
    int c;         /* velocity component */
    int coef;      /* 0..2: A_cell[coef] (normal stress), 3..5: A_edge[coef - 3] */
    double w;      /* (1 - theta) / theta / h^2 */
};

struct embedded {
    /* the open share a_f of each face (1 away from the body, 0 on held
     * faces): the cut cells' mass balance sum_f a_f u_f = 0 */
    const double *share[3];
    const double *cut;  /* per cell: 1 where a face's open share is below 1, else 0 */
    double *work;       /* a cell field of work space (the operator's grad-div), 0
                           outside the cut cells whenever the lists below are set */
    /* the interior cut cells and, per component, the faces whose gradient
     * reads one (or its ghost image): the grad-div term of the cut cells
     * computed there only (NULL: on every cell and face) */
    long ncut, ncut_faces[3];
    ptrdiff_t *cut_cells, *cut_faces[3];
    long nheld[3];
    ptrdiff_t *held[3]; /* nodes inside the body, per component */
    double *saved[3];   /* their values while held at 0 (work space) */
    long nlinks;
    struct embedded_link *links;
};

/* Saves v at the held nodes and sets them to 0 (before a stencil reads v). */
void embedded_hold(const struct embedded *e, double *v[3]);

/* After the operator's stencils: the held rows become the mass term alone,
 * out = mass v (mass_face[c] per face, or the scalar mass when mass_face[0]
 * is NULL), and v gets its saved values back. */
void embedded_release(const struct embedded *e, double mass, const double *const mass_face[3],
                      double *v[3], double *out[3]);

/* out_P += scale * c (1 - theta) / theta v_P over the cut links, c the
 * link's coefficient from A_cell / A_edge (scale 1: the operator
 * mass - div tau; -1: the residual's + div tau). */
void embedded_links(const struct embedded *e, const double *const A_cell[3],
                    const double *const A_edge[3], double scale, double *const v[3],
                    double *out[3]);

/* out = sum_d (a u)(face above) - (a u)(face below)) / h_d per cell: the
 * divergence of the cut cells' flux form, with the faces' open shares. */
void embedded_divergence(const struct grid *g, const struct embedded *e, double *const v[3],
                         double *out);

/* f = 0 at the held nodes. */
void embedded_zero(const struct embedded *e, double *f[3]);

#endif
