/* `curve` data sets: y = f(columns; parameters) for a user expression.
 *
 * Config keys (besides the common data-set keys of config.h):
 *   file:       CSV file, relative to the config file
 *   x:          column used as abscissa for plots and for ordering residuals
 *   y:          observed column
 *   expression: the model, muparser syntax: numbers, parameter and column
 *               names, + - * / ^, parentheses, exp log sqrt sin cos tan atan
 *               abs (and muparser's other functions), pi
 *   sigma:      a positive number (one sigma for all points, in y units) or
 *               the name of a column of per-point sigmas; absent = unweighted
 *   x_label, y_label: axis labels with units (default: the column names)
 *
 * A name in the expression is a parameter slot when it is a global parameter
 * or a key of the data set's `parameters:` binding; otherwise it must be a
 * column of the file.  A name that is both is an error (ambiguous). */
#ifndef PHC_COSTS_CURVE_H
#define PHC_COSTS_CURVE_H

#include "fit/config_help.h"
#include "fit/dataset.h"
#include "measurements/yaml_doc.h"
#include "model/status.h"

/* Keys specific to `curve` (NULL-terminated). */
extern const char *const phc_curve_keys[];
/* Help on each of those keys (fit/config_help.h). */
extern const phc_key_help phc_curve_help[];

/* Decides whether an expression name is a parameter slot. */
typedef int (*phc_is_parameter_fn)(const char *name, void *user_data);

/* Builds a curve data set from its config mapping.  base_dir is the config
 * file's directory.  Slot names are filled; parameter indices are left to
 * the caller (binding).  Errors name the config file and line or the CSV
 * file, line and column, or the expression position. */
int phc_curve_load(const phc_yaml_doc *doc, const phc_yaml_node *node,
                   const char *base_dir, phc_is_parameter_fn is_parameter,
                   void *user_data, phc_dataset **out, phc_error *err);

#endif /* PHC_COSTS_CURVE_H */
