/* run_init (run.h): the one place that wires the case reader to the layers
 * above it, which it cannot include. */
#include "app/run.h"
#include "config/case_registry.h"
#include "kernels/rheology.h"
#include "march/march.h"
#include "scenes/scene.h"

void run_init(void)
{
    static const struct case_checks checks = {
        .preconditioner = march_preconditioner_refusal,
        .rheology_curve = rheology_curve_setup,
        .memory = march_memory_check,
    };
    scenes_register();
    case_register_checks(&checks);
}
