/* Scene "none": a case without an exact solution or diagnostics of its
 * own; the run reports its status, residual and fields only. */
#include "scenes/scene.h"
#include "scene_common.h"

const struct scene scene_none = {
    .name = "none",
    .stretched_grid = 1,
    .title = "no scene: status, residual and fields only",
    .profile_axis = -1,
    .profile_component = -1,
    .decomposed = scene_decomposed_always, /* nothing of its own: the march's */
};
