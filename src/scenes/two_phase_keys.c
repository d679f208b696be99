/* The two-phase scenes' shared key values (scenes/two_phase_keys.h). */
#include <stddef.h>
#include "scenes/two_phase_keys.h"

const struct choice two_phase_mixture_choices[] = {
    {"weighted", MIXTURE_WEIGHTED}, {"harmonic", MIXTURE_HARMONIC}, {NULL, 0}};
