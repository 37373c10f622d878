/* Parameter units: see parameter_units.h. */
#include "fit/engine/parameter_units.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "measurements/units.h"

double phc_parameter_to_user(const phc_parameter *p, double slot_value)
{
    return (slot_value - p->unit_offset) / p->unit_scale;
}

double phc_parameter_to_slot(const phc_parameter *p, double user_value)
{
    return p->unit_scale * user_value + p->unit_offset;
}

/* "cfg.yaml:4: parameter 'delta'" (or the problem's name without a config). */
static void place(const phc_problem *pb, const phc_parameter *p, char *buf, size_t size)
{
    if (pb->source && p->config_line)
        snprintf(buf, size, "%s:%zu: parameter '%s'", pb->source, p->config_line, p->name);
    else
        snprintf(buf, size, "%s: parameter '%s'", pb->name ? pb->name : "problem", p->name);
}

/* The unit every slot bound to parameter i declares (NULL when none does);
 * two different ones are an error. */
static int slot_unit_of(const phc_problem *pb, size_t i, const char **unit, phc_error *err)
{
    const phc_dataset *first_ds = NULL;
    const char *first_slot = NULL;
    *unit = NULL;
    for (size_t d = 0; d < pb->n_datasets; ++d) {
        const phc_dataset *ds = pb->datasets[d];
        for (size_t j = 0; j < ds->k; ++j) {
            if (ds->param_index[j] != i || !ds->slot_units || !ds->slot_units[j])
                continue;
            if (!*unit) {
                *unit = ds->slot_units[j];
                first_ds = ds;
                first_slot = ds->slot_names[j];
            } else if (strcmp(*unit, ds->slot_units[j]) != 0) {
                char where[4400];
                place(pb, &pb->params[i], where, sizeof where);
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%s is bound to slots of different units: '%s' (slot '%s' of data set "
                                     "'%s') and '%s' (slot '%s' of data set '%s'); use one parameter for each",
                                     where, *unit, first_slot, first_ds->name ? first_ds->name : "?",
                                     ds->slot_units[j], ds->slot_names[j], ds->name ? ds->name : "?");
            }
        }
    }
    return PHC_OK;
}

int phc_problem_convert_units(phc_problem *pb, phc_error *err)
{
    phc_units *units = NULL;
    int rc = PHC_OK;
    for (size_t i = 0; i < pb->n_params && !rc; ++i) {
        phc_parameter *p = &pb->params[i];
        const char *slot_unit = NULL;
        if ((rc = slot_unit_of(pb, i, &slot_unit, err)) || !slot_unit)
            continue;
        if (!(p->slot_unit = strdup(slot_unit))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            break;
        }
        if (!p->unit) { /* the model's unit, shown in the report */
            if (!(p->unit = strdup(slot_unit)))
                rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            continue;
        }
        if (strcmp(p->unit, slot_unit) == 0)
            continue;
        if (!units && !(units = phc_units_new(err))) {
            rc = err && err->status ? err->status : PHC_ERR_IO;
            break;
        }
        char where[4400];
        place(pb, p, where, sizeof where);
        strncat(where, ": unit", sizeof where - strlen(where) - 1);
        phc_unit_conversion c;
        if ((rc = phc_units_conversion(units, p->unit, slot_unit, where, &c, err)))
            break;
        p->unit_scale = c.scale;
        p->unit_offset = c.offset;
        p->value = phc_parameter_to_slot(p, p->value);
        p->lower = phc_parameter_to_slot(p, p->lower); /* +-infinity stay */
        p->upper = phc_parameter_to_slot(p, p->upper);
        p->range_lo = phc_parameter_to_slot(p, p->range_lo); /* NAN stays */
        p->range_hi = phc_parameter_to_slot(p, p->range_hi);
        if (c.scale < 0) { /* an inverted unit turns intervals round */
            double t = p->lower;
            p->lower = p->upper;
            p->upper = t;
            t = p->range_lo;
            p->range_lo = p->range_hi;
            p->range_hi = t;
        }
        p->scale *= fabs(c.scale); /* 0 (automatic) stays */
    }
    phc_units_free(units);
    return rc;
}

void phc_parameter_user_bounds(const phc_parameter *p, double *lower, double *upper)
{
    double lo = phc_parameter_to_user(p, p->lower), hi = phc_parameter_to_user(p, p->upper);
    if (lo > hi) {
        const double t = lo;
        lo = hi;
        hi = t;
    }
    *lower = lo;
    *upper = hi;
}
