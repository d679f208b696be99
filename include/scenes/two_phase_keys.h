/* The keys every scene of grains under a light fluid declares in its own
 * section (collapse, bagnold2, front, slope_release, wall_shock): one text
 * each, so that the same key means the same in every scene.  S is the
 * section, T the scene's parameter struct, whose members carry the keys'
 * names. */
#ifndef MUFLOW_SCENES_TWO_PHASE_KEYS_H
#define MUFLOW_SCENES_TWO_PHASE_KEYS_H

#include "config/keys.h"
#include "physics/two_phase.h"

/* `mixture`'s values (enum mixture_law). */
extern const struct choice two_phase_mixture_choices[];

#define TWO_PHASE_KEY_FLUID_DENSITY(T, S)                                                    \
    KEY_DBL(T, S, "fluid_density", fluid_density,                                           \
            KEY_HELP("density rho_f of the light phase (the fluid over the grains)",          \
                     "mass/length^3", NULL),                                                 \
            KEY_GT0)
#define TWO_PHASE_KEY_FLUID_VISCOSITY(T, S)                                                  \
    KEY_DBL(T, S, "fluid_viscosity", fluid_viscosity,                                       \
            KEY_HELP("viscosity eta_f of the (Newtonian) light phase", "pressure time", NULL), \
            KEY_GT0)
/* MORE: a scene's own sentence after the common text ("" for none). */
#define TWO_PHASE_KEY_MIXTURE(T, S, MORE)                                                    \
    KEY_CHO(T, S, "mixture", mixture, two_phase_mixture_choices,                             \
            "viscosity of a cell or edge holding both phases: weighted (by density, Barker & " \
            "Rauter 2018, eq. 14) or harmonic (eq. 15)" MORE)
#define TWO_PHASE_KEY_VOF_CFL(T, S)                                                          \
    KEY_DBL(T, S, "vof_cfl", vof_cfl,                                                        \
            "largest sweep CFL number of the VOF transport that the time step allows (0: "   \
            "the VOF does not bound the step, the transport's sub-steps alone keep its "     \
            "sweeps within their limit)",                                                    \
            KEY_RANGE(0.0, 0.5, 1, 1))
#define TWO_PHASE_KEY_VISCOSITY_FLOOR(T, S)                                                  \
    KEY_DBL(T, S, "viscosity_floor", viscosity_floor,                                       \
            "the grains' viscosity is at least this many rho_g d sqrt(g d) before it is "    \
            "mixed (a thin layer, where the pressure vanishes, keeps a viscosity); 0: no "   \
            "floor",                                                                         \
            KEY_GE0)

#endif
