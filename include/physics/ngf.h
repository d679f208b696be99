/* The nonlocal granular fluidity (rheology.law = ngf; Kamrin & Koval 2012,
 * Henann & Kamrin 2013): a physics module that every case of that law gets
 * (scenes/scene.h: scene_case_module_list).
 *
 * The stress is tau = (p / g) gamma, so |D| = g mu with mu = |tau| / p and
 * |D| = sqrt(gamma:gamma / 2) (the shear rate of a simple shear), and the
 * fluidity g solves the steady form
 *   A^2 d^2 lap(g) = (mu_s - mu) g + b sqrt(rho_s d^2 / p) mu g^2
 * with g = 0 on walls and lids (a rough base: Kamrin & Henann 2015) and no
 * flux through every other face.  With mu = |D| / g, which the stress holds
 * identically, the equation is linear in g:
 *   -A^2 d^2 lap(g) + (mu_s + b I) g = |D|,   I = |D| d sqrt(rho_s / p),
 * so at each evaluation, after the core viscosities, the module solves it
 * for g from the current shear rates (one tridiagonal system per z column,
 * solvers/line_screened.h, or the whole box by the multigrid with its
 * screening term: rheology.fluidity_solver) and replaces the viscosities by
 * eta = p_reg / (g + lambda), their tangents by eta (Picard: the viscosity
 * is a non-local function of the shear rates, with no pointwise tangent).
 * A steady step long beside the viscous time is one Picard iteration g ->
 * G(u(g)); its `implicit` hook (declining the step) gives it the viscosity
 * of the accelerated fluidity (physics/fluidity_anderson.h,
 * rheology.fluidity_anderson), while the state's own fluidity stays G(u),
 * so that the residual the march judges is the steady equations'.
 * lambda keeps eta finite where g = 0: a layer that cannot flow creeps at
 * a speed proportional to lambda.  Solving with mu from the last stress
 * instead (lagged, Newton on g^2) froze the layer: a stress out of
 * equilibrium gives mu < mu_s and g = 0 (docs/numerics/rheology.md).
 * g is the cell field "fluidity" (checkpointed, restored on a rejected
 * step, written to the field files).  The lines (layered flows: periodic x
 * and y) leave the lateral part of lap(g) out (zero for a flow uniform along
 * x and y); the multigrid (uniform grids, one process) keeps it, and the
 * free surface's edge rule (physics/ngf.c: cell_shear2) is along z only.
 * Under a light phase (physics/two_phase.h: the collapse) the cells at
 * least half grains solve the equation with no flux of g to the others
 * (the grains' free surface, g' = 0, to a cell), which take the local
 * fluidity; the base's edges take the mean of g over their link (the
 * first cell's half), and the two_phase module mixes the viscosities
 * after the fluidity replaced the grains' (two_phase_mix_viscosities). */
#ifndef MUFLOW_PHYSICS_NGF_H
#define MUFLOW_PHYSICS_NGF_H

#include "march/march.h"

extern const struct module ngf_module;

#endif
