/* A calibration problem: named global parameters, data sets bound to them,
 * and the options of the solve and of the report.  Built from a YAML config
 * by phc_config_load (config.h) or by hand through this API. */
#ifndef PHC_PROBLEM_H
#define PHC_PROBLEM_H

#include <stddef.h>

#include "fit/engine/ceres_bridge.h"
#include "fit/engine/dataset.h"
#include "fit/engine/prior.h"
#include "model/status.h"

typedef struct phc_parameter {
    char *name;
    double value;        /* start value (physical units) */
    double lower, upper; /* bounds; -INFINITY / INFINITY when open */
    int fixed;
    char *unit;          /* the user's unit (reports show values in it), e.g. "g h-1"; may
                            be NULL.  When a bound slot declares its unit (slot_unit),
                            phc_problem_convert_units converts value, bounds, range and
                            scale into slot_unit; otherwise it is a label */
    char *slot_unit;     /* the unit of the slots it is bound to, or NULL */
    double unit_scale, unit_offset; /* unit -> slot_unit: slot = unit_scale * user + unit_offset
                                       (1 and 0 when there is nothing to convert) */
    double scale;        /* typical magnitude; 0 = automatic (|value| or 1) */
    double range_lo, range_hi; /* multi-start box; NAN = automatic */
    size_t config_line;  /* line of its key in the config (problem->source), 0 when
                            built by hand: messages about it name that line */
    int per_piece;       /* the config's `per_piece: true`: a slot NAME_<k> (k >= 2) of a
                            curve split at irrigations gets its own copy of this
                            parameter (same start, bounds, unit and scale) */
    phc_prior prior;     /* the config's `prior:` for sensitivity studies, in the user's unit
                            (kind NONE: the bounds make a uniform one; fit/engine/prior.h) */
    size_t prior_line;   /* line of `prior:` in the config, 0 when none */
} phc_parameter;

/* A group of parameters that a sensitivity study varies as one factor
 * (`groups:` in the config). */
typedef struct phc_parameter_group {
    char *name;
    size_t *members;     /* parameter indices */
    size_t n_members;    /* >= 1 */
    size_t config_line;
} phc_parameter_group;

/* A named output of a sensitivity study (`outputs:` in the config): the
 * prediction of data set `dataset` at x = `at` (in the data set's x unit,
 * the axis of its plots: for a time series the time since its first row)
 * or at its observation `observation` (1-based; 0 when `at` is used). */
typedef struct phc_named_output {
    char *name;          /* letters, digits, '_', '-', '.'; unique; not "cost" */
    size_t dataset;      /* index into the problem's data sets */
    double at;           /* x, when observation is 0 */
    size_t observation;  /* 1-based, or 0 */
    size_t config_line;  /* 0 when built by hand */
} phc_named_output;

/* The largest magnitude of a start value, finite bound or range end.  The
 * fit works on multiples of these (the automatic multi-start box spans 10x
 * the start, and a box's width is upper - lower), which must stay finite. */
#define PHC_PARAMETER_MAX 1e300

typedef struct phc_fit_options {
    phc_nls_options nls;   /* solver settings for every start */
    size_t starts;         /* >= 1; extra starts are Sobol points in the box */
    size_t rescue_starts;  /* with starts = 1: Sobol starts added when the first
                              solve fails to converge or stalls on a plateau
                              (a parameter with no effect); 0 disables (16) */
    int absolute_sigma;    /* 1: sigmas are true standard deviations (s^2 = 1) */
    double level;          /* significance level of residual checks (0.05) */
    double collinearity_threshold; /* FME's rule of thumb: 20 */
    double correlation_threshold;  /* |r| above this is reported (0.95) */
} phc_fit_options;

phc_fit_options phc_fit_options_default(void);

typedef struct phc_problem {
    char *name;
    char *source;                 /* config path, for messages */
    phc_parameter *params;
    size_t n_params;
    phc_dataset **datasets;
    size_t n_datasets;
    phc_fit_options options;
    char **seeds;                 /* every `seed:` of the config as "datasets[1].soil.rocks.seed: 7",
                                     for provenance */
    size_t n_seeds;
    phc_parameter_group *groups;  /* for sensitivity studies; a parameter is in at most one */
    size_t n_groups;
    phc_named_output *outputs;    /* named outputs of sensitivity studies (phc_problem_add_output) */
    size_t n_outputs;
    size_t series_points;         /* sensitivity studies: per data set, the observations (at most
                                     this many, evenly spaced by index) whose predictions are
                                     outputs with indices per observation; 0 = none
                                     (phc_problem_new sets PHC_SERIES_POINTS_DEFAULT) */
} phc_problem;

#define PHC_SERIES_POINTS_DEFAULT 100

phc_problem *phc_problem_new(const char *name);
void phc_problem_free(phc_problem *pb); /* accepts NULL */

/* Adds a parameter (name copied; unique); returns its index in *index. */
int phc_problem_add_parameter(phc_problem *pb, const char *name, double value,
                              size_t *index, phc_error *err);
/* Adds a named output (copied name): data set `dataset` (by name) at x =
 * `at` (observation 0) or at its 1-based `observation` (then `at` is
 * ignored).  Add the data sets first.  PHC_ERR_INPUT, naming the config
 * line when config_line > 0 ("cfg.yaml:30: outputs: 'W_6h': ..."): a
 * name that is empty, not plain, "cost", "<data set>.mean" or ".cost", or
 * already used; an unknown data
 * set; an observation beyond the data set's; `at` not finite or outside
 * the data set's x range; `at` on a kind that cannot predict at any x
 * (no predict_at) unless its observations form one series with
 * increasing x (then the prediction is interpolated linearly). */
int phc_problem_add_output(phc_problem *pb, const char *name, const char *dataset, double at, size_t observation,
                           size_t config_line, phc_error *err);

/* Index of a parameter by name, or -1. */
long phc_problem_find_parameter(const phc_problem *pb, const char *name);
/* Takes ownership of ds (also on failure); names its series first
 * (phc_dataset_describe_series). */
int phc_problem_add_dataset(phc_problem *pb, phc_dataset *ds, phc_error *err);

/* For data sets built in C (phc_<kind>_new): binds each slot of ds to the
 * problem's parameter of the same name, so that data sets sharing a slot
 * name share the parameter (as a config does without a `parameters:`
 * binding).  A slot without a parameter of its name is PHC_ERR_INPUT naming
 * both; add the parameters first.  Leaves ds unchanged on failure. */
int phc_problem_bind_by_name(const phc_problem *pb, phc_dataset *ds, phc_error *err);

/* Checks the whole problem before a fit: starts, finite bounds and ranges
 * within +-PHC_PARAMETER_MAX, bounds are intervals, starts inside them,
 * every parameter used by some data set, at least as many observations as
 * free parameters, positive sigmas.  Messages name the parameter or data
 * set, and the config line of either when it came from a config
 * ("cfg.yaml:4: parameter 'vmax': ..."). */
int phc_problem_validate(const phc_problem *pb, phc_error *err);

/* Stopping tolerances phc_problem_finish leaves as they are (the caller set
 * them on purpose): bits of PHC_KEEP_*. */
enum {
    PHC_KEEP_FUNCTION_TOLERANCE = 1,
    PHC_KEEP_GRADIENT_TOLERANCE = 2,
    PHC_KEEP_PARAMETER_TOLERANCE = 4
};

/* What a problem needs once its parameters and data sets are in, whether
 * it was built in C or from a config (phc_config_load calls it):
 *   1. every parameter's `unit` converted into its slots' units
 *      (phc_problem_convert_units, fit/engine/parameter_units.h);
 *   2. a model computed to a relative accuracy tol (an ODE solver: the
 *      largest model_tolerance of the data sets) cannot resolve cost
 *      changes below it, so the stopping tolerances not named in `keep`
 *      are raised to at least tol instead of iterating on round-off;
 *   3. phc_problem_validate.
 * Returns the first error. */
int phc_problem_finish(phc_problem *pb, unsigned keep, phc_error *err);

/* The scale used for parameter i (explicit, or |value|, or 1). */
double phc_problem_scale(const phc_problem *pb, size_t i);

#endif /* PHC_PROBLEM_H */
