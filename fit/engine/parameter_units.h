/* Units of parameters: a parameter's `unit:` is converted into the unit of
 * the model slots it is bound to (each kind declares its slots' units with
 * phc_dataset_declare_unit), so that a user may give a water-loss rate in
 * g h-1 to a model that works in g s-1, and reads the fitted value back in
 * g h-1.  UDUNITS-2 does the conversion (measurements/units.h).
 *
 * For every parameter bound to at least one slot with a declared unit:
 *   - slots of different units bound to one parameter are an error;
 *   - without `unit:` the parameter takes the slot's unit (shown in reports);
 *   - with `unit:` its start, bounds, multi-start range and scale are
 *     converted into the slot's unit (unit_scale, unit_offset remember the
 *     conversion); a unit UDUNITS-2 does not know, or one of another
 *     dimension, is PHC_ERR_INPUT naming the parameter and its config line.
 * A parameter whose slots declare no unit keeps `unit:` as a label. */
#ifndef PHC_PARAMETER_UNITS_H
#define PHC_PARAMETER_UNITS_H

#include "fit/engine/problem.h"
#include "model/status.h"

/* Converts every parameter of a bound problem as above.  Call once, after
 * all data sets are added and bound (phc_config_load does). */
int phc_problem_convert_units(phc_problem *pb, phc_error *err);

/* A value of parameter p from its slots' unit into the user's (and back). */
double phc_parameter_to_user(const phc_parameter *p, double slot_value);
double phc_parameter_to_slot(const phc_parameter *p, double user_value);
/* p's bounds in the user's unit, lower first (a negative scale swaps them;
 * infinite bounds stay infinite): what a prior in that unit is truncated to. */
void phc_parameter_user_bounds(const phc_parameter *p, double *lower, double *upper);

#endif /* PHC_PARAMETER_UNITS_H */
