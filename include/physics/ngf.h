/* The nonlocal granular fluidity (rheology.law = ngf; Kamrin & Koval 2012,
 * Henann & Kamrin 2013): a physics module that every case of that law gets
 * (scenes/scene.h: scene_march_setup adds it).
 *
 * The stress is tau = (p / g) gamma, so |D| = g mu with mu = |tau| / p and
 * |D| = sqrt(gamma:gamma / 2) (the shear rate of a simple shear), and the
 * fluidity g solves the steady form
 *   A^2 d^2 lap(g) = (mu_s - mu) g + b sqrt(rho_s d^2 / p) mu g^2
 * with g = 0 on walls and lids (a rough base: Kamrin & Henann 2015) and a
 * zero normal gradient on every other face.  The module holds g as the cell
 * field "fluidity" (checkpointed, restored on a rejected step, written to the
 * field files).  At each evaluation, after the core viscosities: mu from the
 * stress of the last fluidity and the current shear rates, g by Newton's
 * method along each column (solvers/line_screened.h), and the viscosities
 * replaced by eta = p_reg / (g + lambda), their tangents by eta (Picard:
 * the viscosity is not a pointwise function of the shear rate).
 * Layered flows only so far: periodic x and y, the lateral part of lap(g)
 * left out (zero for a flow uniform along x and y). */
#ifndef MUFLOW_PHYSICS_NGF_H
#define MUFLOW_PHYSICS_NGF_H

#include "march/march.h"

extern const struct module ngf_module;

#endif
