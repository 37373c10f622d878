/* A data set: observations, the model that predicts them, and how its
 * parameter slots are bound to the problem's global parameters.
 *
 * Every kind (curve, weight_curve, ...) implements phc_dataset_ops.  The fit
 * engine sees only weighted residuals r_i = (y_i - yhat_i) / sigma_i and
 * their Jacobian; the report sees observations, predictions and x. */
#ifndef PHC_DATASET_H
#define PHC_DATASET_H

#include <stddef.h>

#include "fit/engine/ceres_bridge.h"
#include "fit/engine/progress.h"
#include "model/status.h"

typedef struct phc_dataset phc_dataset;
struct phc_cv_plan; /* fit/engine/cross_validation.h */

/* Decides whether a name a data set's options use (an expression name, a
 * model slot) is bound to a parameter of the problem (1) or not (0). */
typedef int (*phc_is_parameter_fn)(const char *name, void *user_data);
struct phc_problem;

struct phc_baseline;

typedef struct phc_dataset_ops {
    const char *kind; /* "curve", ... */
    /* Model values yhat[0..n-1] at the slot values p[0..k-1]; jac (n x k
     * row-major d yhat / d p) when non-NULL and the kind has analytic
     * derivatives.  Same return convention as phc_residual_fn (0 / >0 / <0). */
    int (*predict)(phc_dataset *ds, const double *p, double *yhat, double *jac);
    /* Model values at arbitrary x (for the fitted-curve plot); NULL when the
     * kind has no single x axis.  Returns 0 on success. */
    int (*predict_at)(phc_dataset *ds, const double *p, const double *x,
                      size_t m, double *y);
    void (*free_impl)(void *impl);
    /* Optional (NULL = none): a markdown section the kind adds to the report
     * after the data set's checks (for example the classic pressure–volume
     * parameters of every leaf, or the model set-up), at the fitted slot
     * values p.  *markdown is malloc'd; return PHC_OK or an error. */
    int (*report_section)(phc_dataset *ds, const double *p, char **markdown, phc_error *err);
    /* Optional (NULL = none): extra outputs of `phytocal simulate` at slot
     * values p, written into directory dir with file names starting with
     * `base` (for example gridded fields as NetCDF and slice plots). */
    int (*simulate_outputs)(phc_dataset *ds, const double *p, const char *dir, const char *base,
                            phc_error *err);
    /* Optional (NULL = none): extra files of `phytocal fit` at the fitted
     * slot values p (for example observed beside simulated images), written
     * into the run's directory dir with names starting with `base`. */
    int (*fit_outputs)(phc_dataset *ds, const double *p, const char *dir, const char *base,
                       phc_error *err);
    /* Optional (NULL = none): names the series of the observations (the
     * probes of soil readings, the leaves of PV curves, the quantiles of
     * colour histograms) so that plots can draw one colour per series with a
     * key.  Sets ds->series when the loader did not, then calls
     * phc_dataset_name_series.  phc_problem_add_dataset calls it once. */
    int (*name_series)(phc_dataset *ds, phc_error *err);
    /* Optional (NULL = none): cross-validation by the engine
     * (fit/engine/cross_validation.h).  Fills *plan (zeroed by the caller): the
     * groups of observations left out in turn, what is measured of each and
     * how to predict it from the data set refitted without it; leaves
     * plan->n_groups 0 when the data set asks for none.  The engine runs
     * the refits after the fit and adds the predictions to the report. */
    int (*cross_validation)(phc_dataset *ds, struct phc_cv_plan *plan, phc_error *err);
    /* Optional (NULL = none): the simpler model a kind's data are usually
     * described by, fitted to the data set's observations and weights
     * (fit/engine/baseline.h: the straight line for curves, the allometric
     * line for root:shoot).  Returns 0 with *out filled, 1 when the kind has
     * none for these data, or an error code. */
    int (*baseline)(const phc_dataset *ds, struct phc_baseline *out);
    /* Optional (NULL = none): the kind's own results as numbers at full
     * precision, a JSON object in text (for example every pressure–volume
     * parameter and its standard error per leaf), at the fitted slot values
     * p; result.json stores it under the data set's "values".  *json is
     * malloc'd. */
    int (*report_values)(phc_dataset *ds, const double *p, char **json, phc_error *err);
    /* Optional (NULL = none): weights that depend on the parameters (the
     * shoot_traces kind's synthetic-likelihood covariance, first computed at
     * the start values).  phc_fit_run calls it after each solve with the
     * fitted slot values p: the kind either recomputes its weights (ds->y,
     * ds->sigma) there and sets *again = 1, and the fit is solved again
     * from p with them, or leaves them and sets *again = 0 (by its own
     * tolerance and maximum of rounds).  PHC_OK or an error. */
    int (*reweight)(phc_dataset *ds, const double *p, int *again, phc_error *err);
} phc_dataset_ops;

struct phc_dataset {
    const phc_dataset_ops *ops;
    void *impl;                  /* owned by the kind */
    char *name;                  /* unique within a problem */
    size_t n;                    /* observations = residuals */
    size_t k;                    /* parameter slots */
    char **slot_names;           /* k names as the model calls them */
    char **slot_units;           /* k units the model works in (UDUNITS-2 syntax, e.g.
                                    "g s-1"), or NULL entries where a slot declares none;
                                    a parameter's `unit:` is converted into it
                                    (fit/engine/parameter_units.h) */
    size_t *param_index;         /* k global parameter indices */
    double *x;                   /* n abscissae for plots and ordering (time, x) */
    double *y;                   /* n observations */
    double *sigma;               /* n standard deviations (all > 0); NULL = 1 */
    char *x_label, *y_label;     /* with units, for plots and tables */
    phc_derivatives derivatives; /* how the Jacobian is obtained */
    phc_loss_kind loss;
    double loss_scale;           /* in units of the weighted residual */
    size_t config_line;          /* where the data set starts in the config */
    double model_tolerance;      /* relative accuracy of the model's numbers (0 = exact to
                                    round-off); solver tolerances the user leaves unset are
                                    raised to it, since the cost cannot be resolved further */
    char *data_file;             /* the file the observations came from (or NULL) */
    size_t *data_lines;          /* n 1-based line numbers in data_file (or NULL) */
    size_t *series;              /* n series ids (e.g. the probe of each reading) when the
                                    observations form several curves over x, or NULL: the
                                    plots then draw one colour and model line per series */
    size_t n_series;             /* with series: 1 + the largest id; else 0 */
    char **series_names;         /* n_series names (probe ids, leaf ids, "L* 4%"...) or NULL */
    char *series_title;          /* what one series is ("probe", "leaf", ...) or NULL */
    const struct phc_problem *problem; /* the problem holding it (set when added): kinds
                                    that refit themselves (cross-validation) read the
                                    bounds and fixed flags of their slots there */
    char **inputs;               /* every file the loader read, as opened (paths relative to
                                    the working directory or absolute), for provenance */
    size_t n_inputs;
    double x_seconds;            /* seconds per unit of x when x is a time (weight curves,
                                    soil readings), else 0: residual checks then look for
                                    serial correlation over time lags out to 1.5 days */
    double *time_of_day;         /* n local clock times of the observations, hours in
                                    [0, 24), or NULL when the clock time is not known:
                                    the report then cannot look for a daily cycle */
    phc_progress_fn progress;    /* set by the caller for the duration of long work (a
                                    kind's own refits in fit_outputs); may be NULL */
    void *progress_data;
};

/* Allocates an empty data set with k slots (names and indices zeroed). */
phc_dataset *phc_dataset_new(const phc_dataset_ops *ops, size_t k);
void phc_dataset_free(phc_dataset *ds); /* accepts NULL; frees impl via ops */

/* Records that the loader read file `path` (kept once; provenance hashes
 * it).  PHC_OK or PHC_ERR_NOMEM. */
/* Declares the unit slot `slot` works in (copied); PHC_ERR_INVALID for an
 * unknown slot, PHC_ERR_NOMEM. */
int phc_dataset_declare_unit(phc_dataset *ds, const char *slot, const char *unit);

int phc_dataset_add_input(phc_dataset *ds, const char *path);

/* Writes the name of series g into buf (size bytes, NUL-terminated). */
typedef void (*phc_series_name_fn)(const phc_dataset *ds, size_t g, char *buf, size_t size);

/* Names the series g = 0 .. count-1 of ds (count >= 1 + the largest id in
 * ds->series) by name(), and says what one series is (`title`, e.g.
 * "probe"; may be NULL), replacing earlier names.  PHC_OK, PHC_ERR_INVALID
 * (no series, or too few names) or PHC_ERR_NOMEM. */
int phc_dataset_name_series(phc_dataset *ds, const char *title, size_t count, phc_series_name_fn name,
                            phc_error *err);

/* Sets ds->n_series from ds->series and lets the kind name its series
 * (ops->name_series).  Called by phc_problem_add_dataset. */
int phc_dataset_describe_series(phc_dataset *ds, phc_error *err);

/* The phc_residual_fn that the fit hands to the bridge, with the data set as
 * user_data: r = (y - yhat)/sigma, d r / d p = -(d yhat / d p)/sigma. */
int phc_dataset_residuals(const double *p, double *r, double *jac, void *ds);

/* Evaluates the model at the slot values of x (global parameters) and checks
 * that every prediction is finite; otherwise PHC_ERR_INPUT naming the data
 * file and line of the first bad observation ("data.csv:4: data set 'd': the
 * model is not finite here at the start values (x = 3)"). */
int phc_dataset_check_start(phc_dataset *ds, const double *x, phc_error *err);

#endif /* PHC_DATASET_H */
