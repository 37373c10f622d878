/* `curve` data sets: y = f(columns; parameters) for a user expression, the
 * NIST StRD problems and any closed-form model of a table.
 *
 * Built in C with phc_curve_new from a table (measurements/table.h: read
 * from a CSV file, or phc_table_from_columns for arrays) and options; the
 * config's `kind: curve` mapping is translated into the same options by
 * fit/config/curve_yaml.c.
 *
 * A name in the expression is a parameter slot when options.is_parameter
 * says so (NULL: every name that is not a column); otherwise it must be a
 * column of the table.  A name that is both is an error (ambiguous). */
#ifndef PHC_COSTS_CURVE_H
#define PHC_COSTS_CURVE_H

#include "fit/costs/origin.h"
#include "fit/engine/dataset.h"
#include "measurements/table.h"
#include "model/status.h"

typedef struct phc_curve_options {
    const char *x;          /* column used as abscissa for plots and ordering (required) */
    const char *y;          /* observed column (required) */
    const char *expression; /* the model, muparser syntax: numbers, parameter and column
                               names, + - * / ^, parentheses, exp log sqrt sin cos tan atan
                               abs (and muparser's other functions), pi (required) */
    double sigma;           /* > 0: one standard deviation for every point, in y units */
    const char *sigma_column; /* or a column of per-point standard deviations; neither =
                                 unweighted */
    const char *x_label, *y_label; /* axis labels with units; NULL = the column names */
    phc_is_parameter_fn is_parameter; /* NULL: every name that is not a column */
    void *user_data;                  /* passed to is_parameter */
    const phc_origin *origin;         /* where the options came from, for messages; NULL */
} phc_curve_options;

/* Everything unset: no sigma, no labels, no origin. */
phc_curve_options phc_curve_options_default(void);

/* Builds a curve data set over the rows of `table` (copied; the table may
 * be freed afterwards).  Slot names are the expression's parameters (in
 * the order muparser lists them); parameter indices are left to phc_problem binding.
 * Errors name the option (and the config line when options.origin is set),
 * the table's source, line and column, or the expression position. */
int phc_curve_new(const phc_table *table, const phc_curve_options *options,
                  phc_dataset **out, phc_error *err);

/* The operations of curve data sets (ops->kind is "curve"). */
extern const phc_dataset_ops phc_curve_ops;

#endif /* PHC_COSTS_CURVE_H */
