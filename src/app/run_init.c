/* run_init (run.h): the one place that wires the case reader to the layers
 * above it, which it cannot include. */
#include "app/run.h"
#include "config/case_registry.h"
#include "kernels/rheology.h"
#include "march/march.h"
#include "scenes/scene.h"

/* The memory check with the setup of the case's scene (march.h). */
static int memory_check(const struct muflow_case *cs, char *msg, size_t msglen)
{
    struct march_setup su;
    scene_march_setup(cs, NULL, &su);
    return march_memory_check(cs, &su, msg, msglen);
}

void run_init(void)
{
    static const struct case_checks checks = {
        .preconditioner = march_preconditioner_refusal,
        .rheology_curve = rheology_curve_setup,
        .memory = memory_check,
    };
    scenes_register();
    case_register_checks(&checks);
}
