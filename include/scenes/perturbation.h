/* A divergence-free pseudo-random velocity perturbation for the layer
 * scenes (bagnold2's 2D cross-sections, bagnold's 3D layer): the discrete
 * curl of a vector potential on the grid's edges, so that the MAC
 * divergence of the added velocity vanishes cell by cell to round-off. */
#ifndef MUFLOW_SCENES_PERTURBATION_H
#define MUFLOW_SCENES_PERTURBATION_H

#include "march/march.h"

enum perturbation_shape {
    /* the potential's y component only: a stream function of each x-z plane
     * (u and w; every y plane its own) */
    PERTURB_XZ = 0,
    /* all three components: u, v and w vary in x, y and z */
    PERTURB_3D,
};

/* Adds to st's velocity the curl of a potential whose components are a
 * pseudo-random deviate in [-1, 1] per edge (the same on any number of
 * threads, periodic along x and y) times sin^2(pi z / height) below height
 * and 0 above, scaled so that the largest added face velocity is amplitude.
 * The potential vanishes on the nodes of z = 0 and z = height, so the
 * normal velocity w does there: the base's no-penetration holds, and so does
 * that of a flat top at height.  Needs periodic x (and y for PERTURB_3D):
 * the deviates wrap there.  Allocates nothing. */
void perturbation_add(struct march_state *st, enum perturbation_shape shape, double height,
                      double amplitude);

#endif
