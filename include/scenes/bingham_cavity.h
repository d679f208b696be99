/* The Bingham lid-driven cavity scene (src/scenes/bingham_cavity.c). */
#ifndef MUFLOW_SCENES_BINGHAM_CAVITY_H
#define MUFLOW_SCENES_BINGHAM_CAVITY_H

#include "config/case.h"

/* Yield-stress number of the cavity in the convention of its reference data
 * (Vola et al.: sqrt(2) times muflow's simple-shear yield stress). */
double cavity_reference_bn(const struct muflow_case *cs);

#endif
