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
    return rheology_inertial_number(&st->cs->rheo, sqrt(shear2), st->field.pressure_regularised[p]);
}

/* The registry's entries of the march's own fields (march.h:
 * MARCH_CORE_FIELDS), and their indices there. */
#define SPEC(name, where, flags, what) {#name, where, flags},
const struct field_spec march_specs[] = {MARCH_CORE_FIELDS(SPEC)};
#define NSPECS (sizeof march_specs / sizeof march_specs[0])
const size_t march_nspecs = NSPECS;
#define INDEX(name, where, flags, what) CORE_##name,
enum { MARCH_CORE_FIELDS(INDEX) CORE_COUNT };
_Static_assert(CORE_COUNT == NSPECS, "one index each");

/* Whether the run needs the array: not the advection term's without
 * advection (its pointers stay NULL; only stage_residual reads it, when
 * physics.advection is on), nor the previous step's fields but for BDF2
 * (stage_time_scheme.c). */
int march_spec_wanted(const struct muflow_case *cs, const struct field_spec *spec)
{
    int bdf2 = cs->time_scheme == TIME_BDF2;
    if (strcmp(spec->name, "velocity_previous") == 0)
        return bdf2;
    if (strcmp(spec->name, "advection_previous") == 0)
        return bdf2 && cs->advection;
    return cs->advection || strcmp(spec->name, "advection") != 0;
}

int march_register_fields(struct march_state *st)
{
    struct field_registry *r = &st->fields;
    const struct field_spec *specs = march_specs;
    /* where each one's arrays go: &member for a cell field, the member (an
     * array of three) for the others */
#define INTO_FIELD_CELLS(m) &(m)
#define INTO_FIELD_FACES(m) (m)
#define INTO_FIELD_EDGES(m) (m)
#define INTO_FIELD_CELLS3(m) (m)
#define INTO(name, where, flags, what) INTO_##where(st->field.name),
    double **into[] = {MARCH_CORE_FIELDS(INTO)};
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
        {"velocity", {"u", "v", "w"}, idx[CORE_velocity], NULL, NULL},
        {"pressure", {NULL}, idx[CORE_pressure], NULL, NULL},
        {"pressure_regularised", {NULL}, idx[CORE_pressure_regularised], NULL, NULL},
        {"shear_rate", {NULL}, idx[CORE_shear2], output_shear_rate, st},
        {"inertial_number", {NULL}, idx[CORE_shear2], output_inertial_number, st},
        {"viscosity", {NULL}, idx[CORE_viscosity], NULL, NULL},
    };
    for (size_t m = 0; m < sizeof outs / sizeof outs[0]; m++)
        if (fields_output(r, &outs[m]) != 0)
            return -1;
    return 0;
}
