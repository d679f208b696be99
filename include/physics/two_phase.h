/* Two phases, grains and a Newtonian fluid, told apart by a volume fraction
 * T (1 grains, 0 fluid): a physics module (march/module.h) for the scenes of
 * Barker & Rauter 2018 (a granular layer under air) and the column collapse.
 *
 * It registers T (checkpointed, restored on a rejected step, written to the
 * field files as "tracer") and, in the properties stage, makes the mixture:
 *   density    rho = T rho_g + (1 - T) rho_f  (Barker & Rauter 2018, eq. 13), rho_g the
 *              bulk density of the grains (physics.density); on a face the
 *              mean of its two cells (EDGES_MEAN) or the grains' share of
 *              the face's box cut from the reconstructed interface
 *              (EDGES_SERIES); the mass term and the projection take it
 *              through march_density_changed;
 *   viscosity  from the granular viscosity eta_g the core properties stage
 *              computed (mu(I) with the regularised total pressure) and the
 *              fluid's eta_f: density-weighted (eq. 14) or harmonic (eq. 15)
 *              at cells and on edges, an edge the interface cuts by the
 *              edge rule below; the tangent coefficients of the Newton step
 *              follow the mixing rule's derivative.
 * A scene's setup configures it (two_phase_configure) and sets T; T is held
 * or, in the transport stage, carried by the projected velocity with the
 * geometric VOF of physics/vof_transport.h (conservative and bounded to
 * round-off while the velocity is solenoidal), in sub-steps that keep each
 * sweep within its CFL limit. */
#ifndef MUFLOW_PHYSICS_TWO_PHASE_H
#define MUFLOW_PHYSICS_TWO_PHASE_H

#include <stddef.h>
#include "march/march.h"

enum mixture_law { MIXTURE_WEIGHTED = 0, MIXTURE_HARMONIC };

/* The viscosity of an edge (a shear-stress location) holding both phases:
 * EDGES_MEAN the mixture law at the mean T of its four cells (the
 * collapse); EDGES_SERIES the two in series over their parts of the edge's
 * link, t and 1 - t cut from the reconstructed interface, each at its own
 * shear rate (and, layered, its own stress and pressure): the exact flux of
 * a profile linear in each phase (docs/numerics/two-phase-and-vof.md). */
enum edge_mixing { EDGES_MEAN = 0, EDGES_SERIES };

struct two_phase_params {
    double fluid_density;    /* rho_f */
    double fluid_viscosity;  /* eta_f */
    enum mixture_law mixture;
    enum edge_mixing edges;
    int transported;         /* 1: T moves with the flow (geometric VOF, sub-stepped
                                within each step); 0: T is held */
    /* the granular viscosity eta_g clipped to [eta_min, eta_max] before it is
     * mixed (the published runs' bounds); 0 and 0: no clip */
    double eta_min, eta_max;
    /* > 0: the time step is limited to this sweep CFL number of the VOF
     * transport at the step's start velocity (at most VOF_CFL_MAX; the
     * sub-steps still guard the velocity the step ends with); 0: no limit,
     * the sub-steps alone */
    double step_cfl;
    /* 1: the phases lie in flat layers along z, the grains below, and the
     * flow carries their weight (bagnold2): a cut edge's phases carry the
     * stress and pressure of their own part of its link (series edges) */
    int layered;
    /* 1: the grains' viscosity on the edges of a no-slip bed at z = 0 at the
     * bed's hydrostatic pressure (each of the two cells above it: its
     * pressure plus its mixture's weight over half a cell), not the core's
     * from a ghost pressure extrapolated linearly from the two cells above
     * the bed, which across the grains' surface of a layer one or two cells
     * deep takes the air's pressure slope for the grains' */
    int bed_pressure;
};

extern const struct module two_phase_module;

/* Sets the fluid and the mixture law, and returns T to initialise (a cell
 * field of the march's grid), or NULL with the cause in err when the module
 * is not switched on. */
double *two_phase_configure(struct march_state *st, const struct two_phase_params *p, char *err,
                            size_t errlen);

/* After T was set or moved: the face density and the projection's
 * coefficient from it.  Returns 0, or -1 with the cause. */
int two_phase_tracer_changed(struct march_state *st, char *err, size_t errlen);

/* T when a scene configured the module, else NULL. */
const double *two_phase_fraction(const struct march_state *st);

/* The mixture of the viscosities (and tangents) the properties stage holds
 * as the grains': the module's properties hook does it after the core's
 * mu(I), unless a module deferred it (below), which calls this after
 * replacing the grains' viscosities. */
void two_phase_mix_viscosities(struct march_state *st);

/* Called by a module that replaces the grains' viscosities after the
 * properties stage (the nonlocal fluidity, physics/ngf.h) when it is
 * created, after this one: the properties hook then leaves the mixture to
 * it, and a scene whose series or bed edges evaluate mu(I) themselves is
 * refused at two_phase_configure, the message naming the module by `by`
 * (its key and value).  Nothing without the two phases. */
void two_phase_defer_mixing(struct march_state *st, const char *by);

/* Sum of T over the interior cells (the grains' volume in cells). */
double two_phase_volume(const struct march_state *st);

#endif
