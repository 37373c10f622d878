/* `infiltration` data sets: how deep the rain goes.  An infiltration
 * experiment records, over time, the depth above which a fraction f of the
 * water applied so far lies (Rhizomorph Fig. 7 plots f = 80%), and the
 * Rhizomorph soil model (model/soil.h) predicts it:
 *
 *   depth_f(t): the depth d with  sum over planes above d of (w - w(0)) dx^3 = f W_in(t)
 *
 * (linear within a voxel plane; W_in the water that entered through rain and
 * sources up to t).  Fits p and c (globally or per layer) like soil_probe.
 *
 * Built in C with phc_infiltration_new from a table (measurements/table.h:
 * read from a CSV file, or phc_table_from_columns for arrays) and options;
 * the config's `kind: infiltration` mapping is translated into the same by
 * fit/config/infiltration_yaml.c:
 *
 *   - kind: infiltration
 *     file: front.csv
 *     time: {column: t, unit: h}
 *     depth: {column: d80, unit: cm}   # any length unit; converted to m
 *     fraction: 0.8
 *     sigma: 0.01                      # m, or a column name (in the depth unit)
 *     soil: {...}                      # fit/costs/soil_setup.h (with rain)
 *
 * Analytic Jacobians through the soil's forward sensitivities and the
 * implicit-function derivative of the crossing.  A time at which less than
 * f of the applied water is in the box (it drained through an absorbing
 * bottom) has no depth: the model value is then not finite and the data set
 * says so at the start values. */
#ifndef PHC_COSTS_INFILTRATION_H
#define PHC_COSTS_INFILTRATION_H

#include "fit/costs/origin.h"
#include "fit/costs/soil_setup.h"
#include "fit/engine/dataset.h"
#include "measurements/table.h"
#include "model/status.h"

typedef struct phc_infiltration_options {
    const char *time;        /* column of times since the start of the run, > 0 and increasing
                                (required) */
    const char *time_unit;   /* any UDUNITS-2 time unit; NULL: "h" */
    const char *depth;       /* column of the depths above which `fraction` of the water
                                applied so far lies, >= 0 (required) */
    const char *depth_unit;  /* any length unit; NULL: "m" */
    double fraction;         /* in (0, 1]; default 0.8 (Rhizomorph Fig. 7) */
    double sigma;            /* > 0: one standard deviation of the depth, in the depth unit */
    const char *sigma_column; /* or a column of them (same unit); one of the two is required */
    const phc_soil_setup_options *soil; /* the soil, with rain or a source (required) */
    const char *x_label, *y_label; /* NULL: "time since the start (h)", "depth of 80% of the
                                      applied water (m)" (with the fraction given) */
    phc_is_parameter_fn is_parameter; /* which soil slots are fitted; NULL: p and c */
    void *user_data;                  /* passed to is_parameter */
    const phc_origin *origin;         /* where the options came from, for messages; NULL */
} phc_infiltration_options;

/* fraction 0.8, sigma NAN (to be given), units h and m, the rest unset. */
phc_infiltration_options phc_infiltration_options_default(void);

/* Builds an infiltration data set over the rows of `table` (copied; the
 * table may be freed afterwards).  Slot names are the soil's
 * (phc_soil_setup_new); parameter indices are left to the caller.  Errors
 * (PHC_ERR_INPUT) name the option (and the config line when
 * options.origin is set), or the table's source, line and column. */
int phc_infiltration_new(const phc_table *table, const phc_infiltration_options *options, phc_dataset **out,
                         phc_error *err);

/* The operations of infiltration data sets (ops->kind is "infiltration"). */
extern const phc_dataset_ops phc_infiltration_ops;

#endif /* PHC_COSTS_INFILTRATION_H */
