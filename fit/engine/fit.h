/* Running a calibration: solve (with multi-start), then everything a user
 * needs to judge the result: covariance, standard errors, 95% intervals,
 * correlations, undetermined parameter combinations, sensitivities and
 * collinearity, goodness of fit and residual checks per data set. */
#ifndef PHC_FIT_H
#define PHC_FIT_H

#include <stddef.h>

#include "fit/engine/ceres_bridge.h"
#include "fit/engine/baseline.h"
#include "fit/engine/goodness.h"
#include "fit/engine/problem.h"
#include "fit/engine/sensitivity.h"
#include "model/status.h"

/* Residual checks reported per data set, in this order. */
typedef enum phc_check_id {
    PHC_CHECK_RUNS,
    PHC_CHECK_DURBIN_WATSON,
    PHC_CHECK_LJUNG_BOX,
    PHC_CHECK_NORMALITY,     /* Shapiro–Wilk (n <= 5000) or Anderson–Darling */
    PHC_CHECK_BREUSCH_PAGAN,
    PHC_CHECK_DAILY_CYCLE,   /* Lomb–Scargle peak at 22-26 h; applicable to time series
                                (x_seconds > 0) spanning >= 36 h (PHC_DAILY_MIN_SPAN_H) */
    PHC_CHECK_COUNT
} phc_check_id;

typedef struct phc_check_result {
    char name[32];       /* "runs", "durbin_watson", "ljung_box", "shapiro_wilk", ... */
    char what[64];       /* the question it answers, e.g. "serial correlation" */
    int applicable;      /* 0 when the sample is too small: statistic/p NAN */
    double statistic;
    double p_value;
    int pass;            /* p >= level (or not applicable) */
} phc_check_result;

#define PHC_ACF_MAX_LAG 20
/* Largest lag of the time-lag autocorrelation of time series, hours (two
 * days: the 24 h lag and the half-day either side of it). */
#define PHC_ACF_TIME_MAX_LAG_H 48.0

typedef struct phc_dataset_result {
    char *name, *kind;
    char *x_label, *y_label;
    size_t n, k;                 /* observations, free parameters it uses */
    phc_goodness goodness;
    phc_check_result checks[PHC_CHECK_COUNT];
    double *x, *y, *yhat;        /* n values, data order */
    double *residual;            /* y - yhat (data units) */
    double *std_residual;        /* (y - yhat) / (sigma s) or / s: for checks and QQ */
    double *sigma;               /* copy of the data set's sigmas or NULL */
    double *curve_x, *curve_y;   /* dense fitted curve (curve_n points) or NULL: one curve
                                    for every observation (not one per series) */
    size_t curve_n;
    size_t *series;              /* n series ids (the probe, leaf, quantile of each
                                    observation) or NULL: plots draw one colour per series */
    size_t n_series;             /* with series: how many (every id is below it) */
    char **series_names;         /* n_series names, or NULL (plots number them) */
    char *series_title;          /* what one series is ("probe", "leaf") or NULL */
    double acf[PHC_ACF_MAX_LAG + 1];
    size_t acf_lags;             /* lags computed (0 when n too small) */
    double x_seconds;            /* seconds per unit of x when x is a time, else 0 (copied
                                    from the data set; saved in result.json) */
    double *time_of_day;         /* n local clock times, hours in [0, 24), or NULL (owned) */
    /* Time series spanning >= 1.5 days (x_seconds > 0, PHC_DAILY_MIN_SPAN_H);
     * recomputed by every check pass, NULL / 0 / NAN otherwise: */
    double *acf_time;            /* acf_time_bins values (owned): autocorrelation of the
                                    standardised residuals at lags k acf_time_bin_h hours
                                    (phc_check_acf_time; NAN where a bin holds no pair) */
    size_t acf_time_bins;
    double acf_time_bin_h;       /* lag bin, hours: max(median sampling interval, 1 h) */
    double cycle_period_h;       /* daily_cycle: period of the periodogram peak in 22-26 h */
    double cycle_peak_hour;      /* with time_of_day: local clock hour at which a 24 h
                                    sinusoid fitted to the standardised residuals peaks */
    double peak_period_h;        /* highest periodogram peak over periods from 2 sampling
                                    bins (>= 2 h) to the span, hours, */
    double peak_power, peak_fap; /* its normalised power and Baluev false-alarm probability */
    char *extra_markdown;        /* the kind's own report section, or NULL */
    char *values_json;           /* the kind's own numbers (a JSON object in text), or NULL */
    size_t n_baselines;          /* baselines[0] is the mean; then the kind's (baseline.h) */
    phc_baseline baselines[PHC_MAX_BASELINES];
} phc_dataset_result;

typedef struct phc_param_result {
    char *name, *unit;
    double start, value;         /* in the user's unit */
    double unit_scale, unit_offset; /* user -> the model slots' unit: slot = unit_scale *
                                       value + unit_offset (parameter_units.h) */
    double stderr_;              /* NAN when not determined or dof = 0 */
    double ci_lo, ci_hi;         /* t-based 95% interval */
    int fixed;
    int at_bound;                /* -1 at lower, +1 at upper, 0 inside */
    double lower, upper;         /* bounds in the user's unit (-inf, +inf when none) */
    double sens_l1, sens_l2;     /* FME summaries (NAN for fixed) */
} phc_param_result;

struct phc_provenance;

typedef struct phc_fit_result {
    char *name;
    struct phc_provenance *provenance; /* what produced it (provenance.h; owned, may be NULL) */
    phc_nls_summary summary;     /* of the best start */
    double total_time;           /* all starts, seconds */
    size_t starts;               /* starts run */
    size_t rescue_starts;        /* of which added because start 0 stalled or failed */
    int rescue_stopped;          /* 1: the rescue starts were stopped early, every one having
                                    stalled on a plateau without a lower cost */
    size_t starts_at_best;       /* starts whose cost is within 1e-8 (relative) of the best */
    size_t n_obs, n_free;
    long dof;                    /* n_obs - n_free */
    double cost;                 /* 1/2 sum rho(r^2), weighted */
    double wrss;                 /* sum of squared weighted residuals */
    double rss;                  /* sum of squared unweighted residuals */
    double s2;                   /* variance factor used for the covariance */
    int absolute_sigma;
    double level;                /* check level */
    double collinearity_threshold, correlation_threshold;
    size_t n_params;
    phc_param_result *params;
    size_t *free_index;          /* n_free indices into params */
    double *correlation;         /* n_free x n_free, NAN where undetermined */
    size_t rank;
    double condition;
    size_t n_undetermined;
    char **undetermined;         /* combinations the data cannot determine */
    phc_sensitivity sensitivity; /* over the free parameters */
    size_t n_datasets;
    phc_dataset_result *datasets;
    size_t n_warnings;
    char **warnings;             /* verdict: empty = nothing to distrust */
} phc_fit_result;


/* Fits pb (validated first) and fills *out.  Returns PHC_OK when a result
 * was produced, even if the solver did not converge (look at
 * out->summary.outcome); an error code otherwise, with a message. */
int phc_fit_run(phc_problem *pb, phc_progress_fn progress, void *user_data,
                phc_fit_result **out, phc_error *err);

/* Recomputes the checks, the verdict and the warnings of a result from its
 * stored residuals at a (possibly new) level.  Used by `phytocal report`. */
int phc_fit_recheck(phc_fit_result *res, double level, phc_error *err);

void phc_fit_result_free(phc_fit_result *res); /* accepts NULL */

/* "converged", "not_converged" or "failed". */
const char *phc_fit_status_name(phc_nls_outcome outcome);

#endif /* PHC_FIT_H */
