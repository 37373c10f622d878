/* Reading a calibration problem from a YAML configuration (DESIGN.md §4).
 *
 * Top-level keys:
 *   name:        run name (default: the config file's stem)
 *   parameters:  mapping name -> {value, lower, upper, fixed, unit, scale,
 *                range: [lo, hi]} or name -> number (the start value)
 *   datasets:    sequence of data sets; each has `kind` and the kind's keys,
 *                plus the common keys:
 *                  name        (default "<kind>-<index>")
 *                  parameters  mapping slot -> global parameter name
 *                              (default: the slot's own name)
 *                  loss        none | huber | cauchy | soft_l1 | arctan
 *                  loss_scale  positive, in units of the weighted residual (1)
 *                  derivatives central | ridders (numerical Jacobians) or
 *                              analytic (kinds that provide it)
 *   solver:      method (levenberg_marquardt | dogleg), max_iterations,
 *                function_tolerance, gradient_tolerance, parameter_tolerance,
 *                threads, starts (multi-start count, Sobol points)
 *   report:      level (0.05), absolute_sigma (false),
 *                collinearity_threshold (20), correlation_threshold (0.95)
 *
 * Every error names the config file and the line, and for unknown keys the
 * nearest valid key. */
#ifndef PHC_CONFIG_H
#define PHC_CONFIG_H

#include "fit/problem.h"
#include "model/status.h"

/* Loads and validates (phc_problem_validate) a configuration file. */
int phc_config_load(const char *path, phc_problem **out, phc_error *err);

#endif /* PHC_CONFIG_H */
