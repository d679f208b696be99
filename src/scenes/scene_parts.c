/* What the layers below take of the case's scene (scenes/scene.h): the
 * march's setup, the profile and its errors, the names of the result's
 * lines.  The march, the diagnostics and the outputs never look a scene up
 * themselves. */
#include <math.h>
#include <string.h>
#include "diagnostics/profile.h"
#include "io/output.h"
#include "march/march.h"
#include "scenes/scene.h"

void scene_march_setup(const struct muflow_case *cs, const struct module *const *extra,
                       struct march_setup *su)
{
    const struct scene *sc = case_scene(cs);
    *su = (struct march_setup){
        .modules = {sc->modules, extra, scene_case_module_list(cs)},
        .setup = sc->setup,
        .cross_section_flow = sc->cross_section_flow && sc->cross_section_flow(cs),
    };
}

int scene_march_create(struct march_state *st, const struct muflow_case *cs,
                       const struct module *const *extra, char *err, size_t errlen)
{
    struct march_setup su;
    scene_march_setup(cs, extra, &su);
    return march_create(st, cs, &su, err, errlen);
}

void scene_profile_spec(const struct scene *sc, struct profile_spec *spec)
{
    *spec = (struct profile_spec){
        .axis = sc->profile_axis,
        .component = sc->profile_component,
        .slab = sc->profile_slab,
        .slab_axis = sc->profile_slab_axis,
        .exact = sc->exact_profile,
        .exact_name = scene_solution_name(sc),
    };
}

int scene_profile(struct profile *pr, const struct march_state *st)
{
    struct profile_spec spec;
    scene_profile_spec(case_scene(st->cs), &spec);
    return profile_extract(pr, st, &spec);
}

double scene_exact_at(const struct muflow_case *cs, double x)
{
    const struct scene *sc = case_scene(cs);
    double u = NAN;
    if (sc->exact_profile)
        sc->exact_profile(cs, 1, &x, &u);
    return u;
}

void scene_profile_errors(const struct profile *pr, const struct march_state *st,
                          struct scene_errors *e)
{
    const struct scene *sc = case_scene(st->cs);
    if (sc->errors) {
        sc->errors(st, pr, e);
        return;
    }
    int axis = sc->profile_axis;
    profile_errors_default(pr, scene_exact_at(st->cs, 0.5 * st->cs->len[axis]), e);
}

void scene_errors_of(const struct march_state *st, struct scene_errors *e)
{
    struct profile pr;
    memset(e, 0, sizeof *e);
    if (scene_profile(&pr, st) != 0) {
        e->err_rms = e->err_max = e->err_rms_paper = e->headline = e->headline_exact = NAN;
        return;
    }
    scene_profile_errors(&pr, st, e);
    profile_free(&pr);
}

void scene_result_names(const struct scene *sc, struct result_names *names)
{
    *names = (struct result_names){
        .headline = sc->headline_name,
        .error = scene_error_name(sc),
        .solution = scene_solution_name(sc),
        .no_err_rms_paper = sc->no_err_rms_paper,
    };
}
