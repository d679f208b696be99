/* The march's own fields, declared once (march_internal.h): the
 * registry's specs, which of them a run needs, their registration and what
 * the field files hold. */
#include <math.h>
#include <string.h>
#include "march_internal.h"

#include "kernels/rheology.h"

/* |D| and I for the field files, from |D|^2 (and the regularised pressure). */
static double output_shear_rate(const void *ctx, double shear2, ptrdiff_t p)
{
    (void)ctx;
    (void)p;
    return sqrt(shear2);
}

static double output_inertial_number(const void *ctx, double shear2, ptrdiff_t p)
{
    const struct march_state *st = ctx;
    return rheology_inertial_number(&st->cs->rheo, sqrt(shear2), st->preg[p]);
}

/* The arrays of the march, declared once (march/fields.h). */
const struct field_spec march_specs[] = {
    {"velocity", FIELD_FACES, FIELD_CHECKPOINT | FIELD_SAVED},
    {"p_dyn", FIELD_CELLS, FIELD_CHECKPOINT | FIELD_SAVED},
    {"p_hyd", FIELD_CELLS, 0},
    {"force", FIELD_FACES, 0},
    {"density_faces", FIELD_FACES, 0},
    {"pressure", FIELD_CELLS, 0},
    {"strain_normal2", FIELD_CELLS, 0},
    {"strain_shear2", FIELD_EDGES, 0},
    {"shear2", FIELD_CELLS, 0},
    {"viscosity", FIELD_CELLS, 0},
    {"pressure_regularised", FIELD_CELLS, 0},
    {"tangent_cells", FIELD_CELLS3, 0},
    {"viscosity_edges", FIELD_EDGES, 0},
    {"tangent_edges", FIELD_EDGES, 0},
    {"residual", FIELD_FACES, 0},
    {"increment", FIELD_FACES, 0},
    {"advection", FIELD_FACES, 0},
    {"divergence", FIELD_CELLS, 0},
    {"phi", FIELD_CELLS, 0},
};
#define NSPECS (sizeof march_specs / sizeof march_specs[0])
const size_t march_nspecs = NSPECS;

/* Whether the run needs the array: the advection term's only without
 * advection (its pointers stay NULL; only stage_residual reads it, when
 * physics.advection is on). */
int march_spec_wanted(const struct muflow_case *cs, const struct field_spec *spec)
{
    return cs->advection || strcmp(spec->name, "advection") != 0;
}

int march_register_fields(struct march_state *st)
{
    struct field_registry *r = &st->fields;
    const struct field_spec *specs = march_specs;
    double **into[] = {st->vel, &st->p_dyn, &st->p_hyd, st->force, st->rho_face, &st->pressure,
                       &st->cn2, st->e2, &st->shear2, &st->eta, &st->preg, st->tan_c, st->eta_e,
                       st->tan_e, st->res, st->delta, st->adv, &st->div, &st->phi};
    _Static_assert(NSPECS == sizeof into / sizeof into[0], "one each");
    int idx[NSPECS];
    for (size_t m = 0; m < NSPECS; m++) {
        idx[m] = -1; /* not wanted: its pointers stay NULL */
        if (march_spec_wanted(st->cs, &specs[m]) && (idx[m] = fields_add(r, &specs[m], into[m])) < 0)
            return -1;
    }
    /* what the field files hold, in this order: the velocity (face values
     * u, v, w and the cell-centred vector), then the cell scalars */
    const struct field_output outs[] = {
        {"velocity", {"u", "v", "w"}, idx[0], NULL, NULL},
        {"pressure", {NULL}, idx[5], NULL, NULL},
        {"pressure_regularised", {NULL}, idx[10], NULL, NULL},
        {"shear_rate", {NULL}, idx[8], output_shear_rate, st},
        {"inertial_number", {NULL}, idx[8], output_inertial_number, st},
        {"viscosity", {NULL}, idx[9], NULL, NULL},
    };
    for (size_t m = 0; m < sizeof outs / sizeof outs[0]; m++)
        if (fields_output(r, &outs[m]) != 0)
            return -1;
    return 0;
}
