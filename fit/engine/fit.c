/* Running a calibration: see fit.h. */
#include "fit/engine/fit.h"
#include "fit/engine/parameter_units.h"
#include "fit/engine/provenance.h"

#include <gsl/gsl_cdf.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/engine/cross_validation.h"
#include "fit/engine/multistart.h"
#include "fit/engine/qr_lstsq.h"
#include "fit/engine/residual_checks.h"
#include "fit/engine/uncertainty.h"
#include "model/jacobi_svd.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define CURVE_POINTS 400
#define MAX_COLLIN_SETS 200000

const char *phc_fit_status_name(phc_nls_outcome outcome)
{
    switch (outcome) {
    case PHC_NLS_CONVERGED: return "converged";
    case PHC_NLS_NOT_CONVERGED: return "not_converged";
    default: return "failed";
    }
}

static void dataset_result_clear(phc_dataset_result *d)
{
    free(d->name);
    free(d->kind);
    free(d->x_label);
    free(d->y_label);
    free(d->x);
    free(d->y);
    free(d->yhat);
    free(d->residual);
    free(d->std_residual);
    free(d->sigma);
    free(d->curve_x);
    free(d->curve_y);
    free(d->extra_markdown);
    free(d->values_json);
    free(d->series);
    for (size_t g = 0; d->series_names && g < d->n_series; ++g)
        free(d->series_names[g]);
    free(d->series_names);
    free(d->series_title);
    free(d->time_of_day);
    free(d->acf_time);
}

/* The data set's series (ids, names, title) into its result; PHC_OK or
 * PHC_ERR_NOMEM. */
static int copy_series(const phc_dataset *ds, phc_dataset_result *d)
{
    if (!ds->series || !ds->n)
        return PHC_OK;
    if (!(d->series = malloc(ds->n * sizeof *d->series)))
        return PHC_ERR_NOMEM;
    memcpy(d->series, ds->series, ds->n * sizeof *d->series);
    d->n_series = ds->n_series;
    for (size_t i = 0; i < ds->n; ++i) /* a data set not added to a problem has no count yet */
        if (d->series[i] >= d->n_series)
            d->n_series = d->series[i] + 1;
    if (ds->series_title && !(d->series_title = strdup(ds->series_title)))
        return PHC_ERR_NOMEM;
    if (!ds->series_names || ds->n_series != d->n_series)
        return PHC_OK;
    if (!(d->series_names = calloc(ds->n_series, sizeof *d->series_names)))
        return PHC_ERR_NOMEM;
    for (size_t g = 0; g < ds->n_series; ++g)
        if (!(d->series_names[g] = strdup(ds->series_names[g])))
            return PHC_ERR_NOMEM;
    return PHC_OK;
}

void phc_fit_result_free(phc_fit_result *res)
{
    if (!res)
        return;
    phc_provenance_free(res->provenance);
    for (size_t i = 0; i < res->n_params; ++i) {
        free(res->params[i].name);
        free(res->params[i].unit);
    }
    free(res->params);
    free(res->free_index);
    free(res->correlation);
    for (size_t i = 0; i < res->n_undetermined; ++i)
        free(res->undetermined[i]);
    free(res->undetermined);
    phc_sensitivity_clear(&res->sensitivity);
    for (size_t i = 0; i < res->n_datasets; ++i)
        dataset_result_clear(&res->datasets[i]);
    free(res->datasets);
    for (size_t i = 0; i < res->n_warnings; ++i)
        free(res->warnings[i]);
    free(res->warnings);
    free(res->name);
    free(res);
}

static int add_warning(phc_fit_result *res, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
static int add_warning(phc_fit_result *res, const char *fmt, ...)
{
    char buf[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    char **grown = realloc(res->warnings, (res->n_warnings + 1) * sizeof *grown);
    if (!grown)
        return PHC_ERR_NOMEM;
    res->warnings = grown;
    if (!(res->warnings[res->n_warnings] = strdup(buf)))
        return PHC_ERR_NOMEM;
    res->n_warnings++;
    return PHC_OK;
}

static double *dup_array(const double *src, size_t n)
{
    if (!src || n == 0)
        return NULL;
    double *d = malloc(n * sizeof *d);
    if (d)
        memcpy(d, src, n * sizeof *d);
    return d;
}

/* Stable order by x (residual checks look for structure along x). */
typedef struct keyed {
    double x;
    size_t i;
} keyed;
static int by_key(const void *a, const void *b)
{
    const keyed *ka = a, *kb = b;
    if (ka->x < kb->x)
        return -1;
    if (ka->x > kb->x)
        return 1;
    return (ka->i > kb->i) - (ka->i < kb->i);
}

static void set_check(phc_check_result *c, const char *name, const char *what, int rc,
                      double stat, double p, double level)
{
    snprintf(c->name, sizeof c->name, "%s", name);
    snprintf(c->what, sizeof c->what, "%s", what);
    c->applicable = rc == PHC_OK && isfinite(p);
    c->statistic = c->applicable ? stat : NAN;
    c->p_value = c->applicable ? p : NAN;
    c->pass = !c->applicable || p >= level;
}

/* Local clock hour (0-24) at which a + b cos(w h) + c sin(w h), w = 2 pi / 24,
 * fitted by least squares to the standardised residuals against their clock
 * times, is largest; NAN when the fit is degenerate (times at one phase). */
static double cycle_peak_hour(const phc_dataset_result *d)
{
    double A[3][3] = {{0}}, y[3] = {0};
    for (size_t i = 0; i < d->n; ++i) {
        const double h = d->time_of_day[i], r = d->std_residual[i];
        if (!isfinite(h) || !isfinite(r))
            continue;
        const double v[3] = {1.0, cos(2.0 * M_PI * h / 24.0), sin(2.0 * M_PI * h / 24.0)};
        for (int a = 0; a < 3; ++a) {
            y[a] += v[a] * r;
            for (int b = 0; b < 3; ++b)
                A[a][b] += v[a] * v[b];
        }
    }
    /* Cramer's rule on the 3 x 3 normal equations */
#define DET3(M) ((M)[0][0] * ((M)[1][1] * (M)[2][2] - (M)[1][2] * (M)[2][1]) - \
                 (M)[0][1] * ((M)[1][0] * (M)[2][2] - (M)[1][2] * (M)[2][0]) + \
                 (M)[0][2] * ((M)[1][0] * (M)[2][1] - (M)[1][1] * (M)[2][0]))
    const double det = DET3(A);
    if (!(fabs(det) > 1e-9 * A[0][0] * A[0][0] * A[0][0]))
        return NAN;
    double coef[3];
    for (int k = 1; k < 3; ++k) {
        double M[3][3];
        memcpy(M, A, sizeof M);
        for (int a = 0; a < 3; ++a)
            M[a][k] = y[a];
        coef[k] = DET3(M) / det;
    }
#undef DET3
    double h = atan2(coef[2], coef[1]) * 24.0 / (2.0 * M_PI);
    return h < 0 ? h + 24.0 : h;
}

/* The checks of time series (x_seconds > 0) spanning >= 1.5 days: the
 * daily-cycle test, the time-lag autocorrelation and the highest
 * periodogram peak.  r: the standardised residuals in the x order of
 * `order`.  Sets the daily_cycle check (not applicable for other data). */
static int time_series_checks(phc_dataset_result *d, const keyed *order, const double *r, double level)
{
    const size_t n = d->n;
    free(d->acf_time);
    d->acf_time = NULL;
    d->acf_time_bins = 0;
    d->acf_time_bin_h = d->cycle_period_h = d->cycle_peak_hour = NAN;
    d->peak_period_h = d->peak_power = d->peak_fap = NAN;
    int rc = PHC_ERR_INVALID;
    double stat = NAN, p = NAN;
    double *t = NULL;
    int ts = d->x_seconds > 0 && isfinite(d->x_seconds) && n >= 3;
    if (ts) {
        if (!(t = malloc(n * sizeof *t)))
            return PHC_ERR_NOMEM;
        for (size_t i = 0; i < n && ts; ++i) {
            t[i] = order[i].x * d->x_seconds / 3600.0; /* hours */
            ts = isfinite(t[i]);
        }
        ts = ts && t[n - 1] - t[0] >= PHC_DAILY_MIN_SPAN_H; /* sorted by x */
    }
    if (ts) {
        rc = phc_check_daily_cycle(t, r, n, &stat, &p, &d->cycle_period_h);
        if (rc == PHC_ERR_NOMEM)
            goto nomem;
        if (rc == PHC_OK && d->time_of_day)
            d->cycle_peak_hour = cycle_peak_hour(d);
        const double bin = phc_check_acf_time_bin(t, n, 1.0);
        if (isfinite(bin)) {
            const size_t bins = (size_t)floor(PHC_ACF_TIME_MAX_LAG_H / bin + 1e-9) + 1;
            if (!(d->acf_time = malloc(bins * sizeof *d->acf_time)))
                goto nomem;
            int arc = phc_check_acf_time(t, r, n, bin, bins, d->acf_time, NULL);
            if (arc == PHC_ERR_NOMEM)
                goto nomem;
            if (arc == PHC_OK) {
                d->acf_time_bins = bins;
                d->acf_time_bin_h = bin;
            } else {
                free(d->acf_time);
                d->acf_time = NULL;
            }
            /* highest peak from the span down to two lag bins (>= 2 h) */
            const double f_lo = 1.0 / (t[n - 1] - t[0]), f_hi = 1.0 / (2.0 * bin);
            phc_periodogram_peak pk;
            if (f_hi > f_lo) {
                int prc = phc_check_periodogram_peak(t, r, n, f_lo, f_hi, 5.0, &pk);
                if (prc == PHC_ERR_NOMEM)
                    goto nomem;
                if (prc == PHC_OK) {
                    d->peak_period_h = pk.period;
                    d->peak_power = pk.power;
                    d->peak_fap = pk.fap;
                }
            }
        }
    }
    set_check(&d->checks[PHC_CHECK_DAILY_CYCLE], "daily_cycle", "a 24-hour cycle in the residuals (Lomb–Scargle)",
              rc, stat, p, level);
    free(t);
    return PHC_OK;
nomem:
    free(t);
    free(d->acf_time);
    d->acf_time = NULL;
    d->acf_time_bins = 0;
    return PHC_ERR_NOMEM;
}

/* Residual checks of one data set.  X: n x kx rows of the weighted Jacobian
 * in data order (for Durbin–Watson's exact moments), or NULL to keep the
 * stored Durbin–Watson p-value (recheck from a saved result). */
static int compute_checks(phc_dataset_result *d, const double *X, size_t kx, double level)
{
    const size_t n = d->n;
    keyed *order = malloc(n * sizeof *order);
    double *r = malloc(n * sizeof *r);
    double *Xs = X && kx ? malloc(n * kx * sizeof *Xs) : NULL;
    double *fitted = malloc(n * sizeof *fitted);
    if (!order || !r || !fitted || (X && kx && !Xs)) {
        free(order);
        free(r);
        free(Xs);
        free(fitted);
        return PHC_ERR_NOMEM;
    }
    for (size_t i = 0; i < n; ++i) {
        order[i].x = d->x[i];
        order[i].i = i;
    }
    qsort(order, n, sizeof *order, by_key);
    for (size_t i = 0; i < n; ++i) {
        const size_t o = order[i].i;
        r[i] = d->std_residual[o];
        fitted[i] = d->yhat[o];
        if (Xs)
            memcpy(Xs + i * kx, X + o * kx, kx * sizeof *X);
    }
    double stat, p;
    size_t runs;
    int rc = phc_check_runs(r, n, &stat, &p, &runs);
    set_check(&d->checks[PHC_CHECK_RUNS], "runs", "runs of residual signs along x", rc, stat, p, level);
    if (X || !d->checks[PHC_CHECK_DURBIN_WATSON].applicable) {
        rc = phc_check_durbin_watson(r, n, Xs, Xs ? kx : 0, &stat, &p);
    } else {
        /* keep the stored p-value, recompute the statistic */
        double num = 0, den = 0;
        for (size_t i = 0; i < n; ++i) {
            den += r[i] * r[i];
            if (i)
                num += (r[i] - r[i - 1]) * (r[i] - r[i - 1]);
        }
        stat = den > 0 ? num / den : NAN;
        p = d->checks[PHC_CHECK_DURBIN_WATSON].p_value;
        rc = PHC_OK;
    }
    set_check(&d->checks[PHC_CHECK_DURBIN_WATSON], "durbin_watson", "lag-1 serial correlation", rc, stat, p, level);
    rc = phc_check_ljung_box(r, n, 0, 0, &stat, &p);
    set_check(&d->checks[PHC_CHECK_LJUNG_BOX], "ljung_box", "serial correlation up to lag 10", rc, stat, p, level);
    if (n <= 5000) {
        rc = phc_check_shapiro_wilk(r, n, &stat, &p);
        set_check(&d->checks[PHC_CHECK_NORMALITY], "shapiro_wilk", "normality of residuals", rc, stat, p, level);
    } else {
        rc = phc_check_anderson_darling(r, n, &stat, &p);
        set_check(&d->checks[PHC_CHECK_NORMALITY], "anderson_darling", "normality of residuals", rc, stat, p, level);
    }
    rc = phc_check_breusch_pagan(r, fitted, n, 1, &stat, &p);
    set_check(&d->checks[PHC_CHECK_BREUSCH_PAGAN], "breusch_pagan", "variance changing with the fitted value",
              rc, stat, p, level);
    size_t lags = n > 2 ? (n - 1 < PHC_ACF_MAX_LAG ? n - 1 : PHC_ACF_MAX_LAG) : 0;
    if (lags > n / 2)
        lags = n / 2;
    d->acf_lags = (lags > 0 && phc_check_acf(r, n, lags, d->acf) == PHC_OK) ? lags : 0;
    if (time_series_checks(d, order, r, level)) {
        free(order);
        free(r);
        free(Xs);
        free(fitted);
        return PHC_ERR_NOMEM;
    }
    free(order);
    free(r);
    free(Xs);
    free(fitted);
    return PHC_OK;
}

/* The verdict's warnings about identifiability and intervals: a
 * rank-deficient Jacobian, and 95% intervals that cross a parameter's own
 * bound (the Wald interval assumes the model is linear near the optimum; a
 * bound it crosses is where that fails: κ from −26 to 126 with κ >= 0). */
static int interval_warnings(phc_fit_result *res)
{
    int rc = 0;
    if (res->n_free && res->rank < res->n_free)
        rc |= add_warning(res, "the Jacobian has rank %zu of %zu free parameters: they are not identifiable from "
                               "these data (fix or tie parameters, or add data that separate them)",
                          res->rank, res->n_free);
    for (size_t i = 0; i < res->n_params; ++i) {
        const phc_param_result *p = &res->params[i];
        if (p->fixed || p->at_bound || !isfinite(p->ci_lo) || !isfinite(p->ci_hi))
            continue;
        const int below = p->ci_lo < p->lower, above = p->ci_hi > p->upper;
        if (below || above)
            rc |= add_warning(res, "parameter '%s': its 95%% interval [%.6g, %.6g] crosses its %s bound %.6g: the "
                                   "estimate is %.3g standard errors from the bound, where an interval of value "
                                   "± t·stderr is not reliable",
                              p->name, p->ci_lo, p->ci_hi, below ? "lower" : "upper", below ? p->lower : p->upper,
                              fabs(p->value - (below ? p->lower : p->upper)) / p->stderr_);
    }
    return rc;
}

/* The verdict's warnings about baselines (baseline.h): the model must
 * predict the data better than their mean (R² > 0 for unweighted data), and
 * a kind's simpler model must not have a clearly lower AICc (by more than
 * 2, the usual "substantially better" threshold of Burnham & Anderson). */
static int baseline_warnings(phc_fit_result *res)
{
    int rc = 0;
    for (size_t d = 0; d < res->n_datasets; ++d) {
        const phc_dataset_result *ds = &res->datasets[d];
        const phc_goodness *g = &ds->goodness;
        for (size_t b = 0; b < ds->n_baselines; ++b) {
            const phc_baseline *bl = &ds->baselines[b];
            if (b == 0) {
                if (g->wrss > bl->goodness.wrss * (1.0 + 1e-9))
                    rc |= add_warning(res, "data set '%s': the model predicts these data worse than their mean: "
                                           "R² = %.3g (weighted RSS %.4g against %.4g for the mean)",
                                      ds->name, g->r2, g->wrss, bl->goodness.wrss);
            } else if ((isfinite(g->aicc) && isfinite(bl->goodness.aicc) && bl->goodness.aicc < g->aicc - 2.0) ||
                       (bl->goodness.wrss == 0 && g->wrss > 0)) {
                if (bl->goodness.wrss == 0) /* through every point: no likelihood to compare */
                    rc |= add_warning(res, "data set '%s': %s (%zu parameters) fits these data exactly, the model "
                                           "does not (weighted RSS %.4g)",
                                      ds->name, bl->what, bl->goodness.k, g->wrss);
                else
                    rc |= add_warning(res, "data set '%s': %s (%zu parameters) fits these data better than the "
                                           "model: AICc %.4g against %.4g (R² %.3g against %.3g)",
                                      ds->name, bl->what, bl->goodness.k, bl->goodness.aicc, g->aicc,
                                      bl->goodness.r2, g->r2);
            }
        }
    }
    return rc;
}

/* Warnings that make up the verdict. */
static int build_verdict(phc_fit_result *res)
{
    int rc = PHC_OK;
    for (size_t i = 0; i < res->n_warnings; ++i)
        free(res->warnings[i]);
    free(res->warnings);
    res->warnings = NULL;
    res->n_warnings = 0;
    if (res->summary.outcome != PHC_NLS_CONVERGED)
        rc |= add_warning(res, "the solver did not converge: %s", res->summary.termination);
    for (size_t i = 0; i < res->n_params; ++i) {
        const phc_param_result *p = &res->params[i];
        if (p->at_bound)
            rc |= add_warning(res, "parameter '%s' ended at its %s bound (%g): its interval is not reliable",
                              p->name, p->at_bound < 0 ? "lower" : "upper", p->value);
    }
    rc |= interval_warnings(res);
    for (size_t i = 0; i < res->n_undetermined; ++i)
        rc |= add_warning(res, "the data cannot determine the combination %s", res->undetermined[i]);
    const size_t nf = res->n_free;
    for (size_t a = 0; a < nf; ++a)
        for (size_t b = a + 1; b < nf; ++b) {
            const double c = res->correlation[a * nf + b];
            if (fabs(c) > res->correlation_threshold)
                rc |= add_warning(res, "parameters '%s' and '%s' are strongly correlated (r = %.4f)",
                                  res->params[res->free_index[a]].name, res->params[res->free_index[b]].name, c);
        }
    const phc_sensitivity *s = &res->sensitivity;
    size_t shown = 0;
    for (size_t i = 0; i < s->n_sets && shown < 3; ++i) {
        if (!(s->sets[i].gamma > res->collinearity_threshold))
            break;
        char names[256] = "";
        for (size_t a = 0; a < s->sets[i].size; ++a) {
            size_t used = strlen(names);
            snprintf(names + used, sizeof names - used, "%s%s", a ? ", " : "",
                     res->params[res->free_index[s->sets[i].index[a]]].name);
        }
        rc |= add_warning(res, "parameters {%s} are collinear (collinearity index %.3g > %g)", names,
                          s->sets[i].gamma, res->collinearity_threshold);
        ++shown;
    }
    for (size_t d = 0; d < res->n_datasets; ++d)
        for (size_t c = 0; c < PHC_CHECK_COUNT; ++c) {
            const phc_check_result *ck = &res->datasets[d].checks[c];
            const phc_dataset_result *ds = &res->datasets[d];
            if (c == PHC_CHECK_DAILY_CYCLE && ck->applicable && !ck->pass) {
                char when[128] = "";
                if (isfinite(ds->cycle_peak_hour)) {
                    const int minutes = (int)lround(ds->cycle_peak_hour * 60.0) % (24 * 60);
                    snprintf(when, sizeof when, "; the residuals (data minus model) are highest around "
                                                "%02d:%02d local time", minutes / 60, minutes % 60);
                }
                rc |= add_warning(res, "data set '%s': the residuals follow a daily cycle (periodogram peak at "
                                       "%.1f h, p = %.2g): the model misses a difference between day and night, "
                                       "for example faster water loss by day than by night%s",
                                  ds->name, ds->cycle_period_h, ck->p_value, when);
            } else if (ck->applicable && !ck->pass)
                rc |= add_warning(res, "data set '%s': %s check failed (%s, p = %.3g < %g)",
                                  res->datasets[d].name, ck->name, ck->what, ck->p_value, res->level);
        }
    if (res->dof <= 0)
        rc |= add_warning(res, "no degrees of freedom left (%ld): standard errors are not available", res->dof);
    rc |= baseline_warnings(res);
    return rc ? PHC_ERR_NOMEM : PHC_OK;
}

int phc_fit_recheck(phc_fit_result *res, double level, phc_error *err)
{
    if (!(level > 0 && level < 1))
        return phc_error_set(err, PHC_ERR_INVALID, "level must be in (0, 1), found %g", level);
    res->level = level;
    for (size_t d = 0; d < res->n_datasets; ++d)
        if (compute_checks(&res->datasets[d], NULL, 0, level))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if (build_verdict(res))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    return PHC_OK;
}

/* Slot values of a data set from the global parameter vector. */
static void slot_values(const phc_dataset *ds, const double *x, double *p)
{
    for (size_t j = 0; j < ds->k; ++j)
        p[j] = x[ds->param_index[j]];
}

static int fill_dataset_result(phc_dataset *ds, const double *x, const double *r_w,
                               const double *J, size_t n_all, const size_t *free_index,
                               size_t n_free, double s, double level, phc_dataset_result *d,
                               phc_error *err)
{
    const size_t n = ds->n;
    double *p = calloc(ds->k, sizeof *p);
    double *X = NULL;
    size_t *cols = calloc(n_free ? n_free : 1, sizeof *cols);
    size_t kx = 0;
    int rc = PHC_OK;
    d->name = strdup(ds->name);
    d->kind = strdup(ds->ops->kind);
    d->x_label = strdup(ds->x_label ? ds->x_label : "x");
    d->y_label = strdup(ds->y_label ? ds->y_label : "y");
    d->n = n;
    d->x = dup_array(ds->x, n);
    d->y = dup_array(ds->y, n);
    d->sigma = dup_array(ds->sigma, n);
    d->x_seconds = ds->x_seconds;
    d->time_of_day = dup_array(ds->time_of_day, n);
    d->yhat = calloc(n, sizeof *d->yhat);
    d->residual = calloc(n, sizeof *d->residual);
    d->std_residual = calloc(n, sizeof *d->std_residual);
    if (!p || !cols || !d->name || !d->kind || !d->x_label || !d->y_label || !d->x || !d->y ||
        (ds->sigma && !d->sigma) || (ds->time_of_day && !d->time_of_day) || !d->yhat || !d->residual || !d->std_residual || copy_series(ds, d)) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    slot_values(ds, x, p);
    if (ds->ops->predict(ds, p, d->yhat, NULL) != 0) {
        rc = phc_error_set(err, PHC_ERR_DOMAIN, "data set '%s': the model cannot be evaluated at the optimum",
                           ds->name);
        goto fail;
    }
    if (ds->ops->report_section && (rc = ds->ops->report_section(ds, p, &d->extra_markdown, err)))
        goto fail;
    if (ds->ops->report_values && (rc = ds->ops->report_values(ds, p, &d->values_json, err)))
        goto fail;
    for (size_t i = 0; i < n; ++i) {
        d->residual[i] = d->y[i] - d->yhat[i];
        d->std_residual[i] = r_w[i] / (s > 0 ? s : 1.0);
    }
    /* free parameters this data set depends on: columns of J */
    for (size_t f = 0; f < n_free; ++f)
        for (size_t j = 0; j < ds->k; ++j)
            if (ds->param_index[j] == free_index[f]) {
                cols[kx++] = free_index[f];
                break;
            }
    d->k = kx;
    if (phc_goodness_compute(d->y, d->yhat, ds->sigma, n, kx, &d->goodness) != PHC_OK)
        memset(&d->goodness, 0, sizeof d->goodness);
    d->n_baselines = 0;
    if (phc_baseline_mean(d->y, ds->sigma, n, &d->baselines[0]) == PHC_OK)
        d->n_baselines = 1;
    if (d->n_baselines && ds->ops->baseline && ds->ops->baseline(ds, &d->baselines[1]) == 0)
        d->n_baselines = 2;
    if (kx) {
        X = malloc(n * kx * sizeof *X);
        if (!X) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        for (size_t i = 0; i < n; ++i)
            for (size_t c = 0; c < kx; ++c)
                X[i * kx + c] = J[i * n_all + cols[c]];
    }
    for (size_t c = 0; c < PHC_CHECK_COUNT; ++c)
        d->checks[c].applicable = 0;
    if (compute_checks(d, X, kx, level)) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if (ds->ops->predict_at) {
        double lo = INFINITY, hi = -INFINITY;
        for (size_t i = 0; i < n; ++i) {
            lo = fmin(lo, d->x[i]);
            hi = fmax(hi, d->x[i]);
        }
        d->curve_x = malloc(CURVE_POINTS * sizeof *d->curve_x);
        d->curve_y = malloc(CURVE_POINTS * sizeof *d->curve_y);
        if (!d->curve_x || !d->curve_y) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        for (size_t i = 0; i < CURVE_POINTS; ++i)
            d->curve_x[i] = lo + (hi - lo) * (double)i / (CURVE_POINTS - 1);
        if (hi > lo && ds->ops->predict_at(ds, p, d->curve_x, CURVE_POINTS, d->curve_y) == 0) {
            d->curve_n = CURVE_POINTS;
        } else {
            free(d->curve_x);
            free(d->curve_y);
            d->curve_x = d->curve_y = NULL;
        }
    }
fail:
    free(p);
    free(X);
    free(cols);
    return rc;
}

/* Relative effect below which a parameter counts as having none (the
 * covariance's singular-value cut-off too). */
#define NEGLIGIBLE_EFFECT 1e-10

/* The magnitude a relative change of parameter i is measured against: its
 * value, or its scale when the value is 0. */
static double effect_scale(const phc_problem *pb, const double *x, size_t i)
{
    return x[i] != 0 ? fabs(x[i]) : phc_problem_scale(pb, i);
}

/* The last successful evaluation of a fit's problem (residuals, Jacobian,
 * cost at x): the rescue decision, the Gauss–Newton polish and the analysis
 * evaluate at the same point one after the other (the best start, then the
 * polished solution), and each such evaluation runs the model and its
 * Jacobian once.  Only phc_fit_run's own phc_nls, whose data sets do not
 * change during the fit, is remembered. */
typedef struct nls_memo {
    phc_nls *nls;
    size_t m, np;
    int valid;
    double *x, *r, *J, cost;
} nls_memo;

static void nls_memo_clear(nls_memo *c)
{
    free(c->x);
    free(c->r);
    free(c->J);
    memset(c, 0, sizeof *c);
}

/* phc_nls_evaluate(c->nls, x, r, J, cost, err) (r, J, cost may be NULL),
 * from the memo when x is bitwise the last successfully evaluated point. */
static int memo_evaluate(nls_memo *c, const double *x, double *r, double *J, double *cost, phc_error *err)
{
    if (!c->x || !c->r || !c->J) {
        c->m = phc_nls_residual_count(c->nls);
        if (!c->x)
            c->x = malloc(c->np * sizeof *c->x);
        if (!c->r)
            c->r = malloc(c->m * sizeof *c->r);
        if (!c->J)
            c->J = malloc(c->m * c->np * sizeof *c->J);
        if (!c->x || !c->r || !c->J)
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    if (!c->valid || memcmp(c->x, x, c->np * sizeof *x) != 0) {
        c->valid = 0;
        int rc = phc_nls_evaluate(c->nls, x, c->r, c->J, &c->cost, err);
        if (rc)
            return rc;
        memcpy(c->x, x, c->np * sizeof *x);
        c->valid = 1;
    }
    if (r)
        memcpy(r, c->r, c->m * sizeof *r);
    if (J)
        memcpy(J, c->J, c->m * c->np * sizeof *J);
    if (cost)
        *cost = c->cost;
    return PHC_OK;
}

/* 1 when some free parameter has (relatively) no effect on the residuals at
 * x (phc_negligible_columns): a stall on a plateau. */
static int stalled_on_plateau(nls_memo *memo, const phc_problem *pb, const double *x)
{
    const size_t m = phc_nls_residual_count(memo->nls), np = pb->n_params;
    double *J = malloc(m * np * sizeof *J), *scale = malloc(np * sizeof *scale);
    int *fixed = malloc(np * sizeof *fixed), *negligible = malloc(np * sizeof *negligible);
    int stalled = 0;
    if (J && scale && fixed && negligible && memo_evaluate(memo, x, NULL, J, NULL, NULL) == PHC_OK) {
        for (size_t j = 0; j < np; ++j) {
            scale[j] = effect_scale(pb, x, j);
            fixed[j] = pb->params[j].fixed;
        }
        stalled = phc_negligible_columns(J, m, np, np, scale, fixed, NEGLIGIBLE_EFFECT, negligible) > 0;
    }
    free(J);
    free(scale);
    free(fixed);
    free(negligible);
    return stalled;
}

/* Gauss–Newton polish of a converged least-squares optimum.
 *
 * The trust-region solver accepts a step only when the cost decreases, and
 * near the optimum a parameter error e changes the cost by O(e^2): below
 * the round-off of the cost once e ~ 1e-8 relative.  So the solver stops
 * with ~8 correct digits however tight its tolerances.  Gauss–Newton steps
 * (min |J d + r| by SVD, column-scaled) converge on the step size instead,
 * which the cost's round-off does not limit.  A step is kept while the cost
 * does not rise beyond its round-off (residuals y - yhat lose digits to
 * cancellation: Misra1b's cost is only good to ~1e-13, so the allowance is
 * 1e-10 relative) and the steps keep shrinking; it stops after a kept
 * step below 1e-13 relative: the steps shrink at least geometrically (the
 * slowest, NIST ENSO's, by 0.64 per step), so what further steps would add
 * is below ~2e-13 relative, 100 times below the 11 digits NIST certifies
 * (a threshold of 1e-15 took 58 more Gauss–Newton steps on the 44 NIST
 * fits, each a QR and a model run, for changes of at most 3e-14 in the
 * parameters). */
static int polish(nls_memo *memo, const phc_problem *pb, double *x, size_t m, phc_error *err)
{
    const size_t np = pb->n_params;
    size_t nf = 0;
    for (size_t i = 0; i < np; ++i)
        nf += !pb->params[i].fixed;
    for (size_t d = 0; d < pb->n_datasets; ++d)
        if (pb->datasets[d]->loss != PHC_LOSS_NONE)
            return PHC_OK; /* robust losses: Gauss–Newton on plain residuals would ignore them */
    if (nf == 0 || m < nf)
        return PHC_OK;
    double *r = malloc(m * sizeof *r), *J = malloc(m * np * sizeof *J), *A = malloc(m * nf * sizeof *A);
    double *b = malloc(m * sizeof *b), *sv = malloc((nf + phc_qr_lstsq_work(m, nf)) * sizeof *sv),
           *trial = malloc(np * sizeof *trial);
    double *colscale = malloc(nf * sizeof *colscale);
    size_t *fi = malloc(nf * sizeof *fi);
    int rc = PHC_OK;
    if (!r || !J || !A || !b || !sv || !trial || !colscale || !fi) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    /* Parameters on a bound stay there: Gauss–Newton refines the others. */
    size_t f_count = 0;
    for (size_t i = 0; i < np; ++i) {
        const phc_parameter *p = &pb->params[i];
        const double tol = 1e-12 * phc_problem_scale(pb, i);
        if (!p->fixed && !(x[i] - p->lower <= tol) && !(p->upper - x[i] <= tol))
            fi[f_count++] = i;
    }
    nf = f_count;
    if (nf == 0)
        goto done;
    double cost;
    if (memo_evaluate(memo, x, r, J, &cost, NULL) != PHC_OK)
        goto done;
    double last_step = INFINITY;
    for (int it = 0; it < 10; ++it) {
        for (size_t f = 0; f < nf; ++f) {
            double ss = 0;
            for (size_t i = 0; i < m; ++i)
                ss += J[i * np + fi[f]] * J[i * np + fi[f]];
            colscale[f] = ss > 0 ? sqrt(ss) : 1.0;
            for (size_t i = 0; i < m; ++i)
                A[i * nf + f] = J[i * np + fi[f]] / colscale[f];
        }
        for (size_t i = 0; i < m; ++i)
            b[i] = -r[i];
        /* sv: the step (nf), then phc_qr_lstsq's work space */
        double *step_f = sv;
        size_t rank = 0;
        if (phc_qr_lstsq(A, m, nf, b, 1e-13, sv + nf, step_f, &rank) != 0 || rank < nf)
            break; /* rank-deficient: leave it to the covariance analysis */
        double step = 0;
        memcpy(trial, x, np * sizeof *x);
        int inside = 1;
        for (size_t f = 0; f < nf; ++f) {
            const size_t i = fi[f];
            const double d = step_f[f] / colscale[f];
            trial[i] = x[i] + d;
            step = fmax(step, fabs(d) / (fabs(x[i]) + phc_problem_scale(pb, i) * 1e-300 + 1e-300));
            inside &= trial[i] >= pb->params[i].lower && trial[i] <= pb->params[i].upper;
        }
        if (!inside || !(step < 1e-4) || step >= last_step)
            break; /* not in the Gauss–Newton basin, or no longer contracting */
        double trial_cost;
        if (memo_evaluate(memo, trial, r, J, &trial_cost, NULL) != PHC_OK ||
            !(trial_cost <= cost * (1 + 1e-10) + 1e-300)) {
            memo_evaluate(memo, x, r, J, &cost, NULL);
            break;
        }
        memcpy(x, trial, np * sizeof *x);
        cost = trial_cost;
        last_step = step;
        if (step < 1e-13)
            break;
    }
done:
    free(r);
    free(J);
    free(A);
    free(b);
    free(sv);
    free(trial);
    free(colscale);
    free(fi);
    return rc;
}

/* The data set's cross-validation (fit/engine/cross_validation.h), when its kind
 * has the op and the data set asks for it: run at the fitted values x and
 * added to the data set's report section. */
static int add_cross_validation(const phc_problem *pb, phc_dataset *ds, const double *x, phc_progress_fn progress,
                                void *user_data, phc_dataset_result *d, phc_error *err)
{
    if (!ds->ops->cross_validation)
        return PHC_OK;
    double *p = calloc(ds->k ? ds->k : 1, sizeof *p);
    phc_cv_result *cv = NULL;
    char *md = NULL;
    int rc;
    if (!p)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    slot_values(ds, x, p);
    if (!(rc = phc_cross_validate(pb, ds, p, progress, user_data, &cv, err)) && cv &&
        !(rc = phc_cv_result_markdown(cv, &md, err))) {
        const size_t a = d->extra_markdown ? strlen(d->extra_markdown) : 0, b = strlen(md);
        char *joined = realloc(d->extra_markdown, a + b + 1);
        if (joined) {
            memcpy(joined + a, md, b + 1);
            d->extra_markdown = joined;
        } else
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    free(md);
    phc_cv_result_free(cv);
    free(p);
    return rc;
}

/* ---- the solve stage: starts, rescue, polish ---------------------------- */

#define RESCUE_PATIENCE 3 /* rescue starts that all stall on a plateau before the rest are skipped */

/* Declares pb's parameters (bounds, fixed flags, scales) and one residual
 * block per data set to nls, and writes the configured start into x (np
 * values).  Every data set must be able to evaluate its model there
 * (phc_dataset_check_start).  PHC_OK or an error with a message. */
static int solve_setup(phc_nls *nls, const phc_problem *pb, double *x, phc_error *err)
{
    int rc;
    for (size_t i = 0; i < pb->n_params; ++i) {
        const phc_parameter *p = &pb->params[i];
        if ((rc = phc_nls_set_parameter(nls, i, p->lower, p->upper, p->fixed, phc_problem_scale(pb, i), err)))
            return rc;
        x[i] = p->value;
    }
    for (size_t d = 0; d < pb->n_datasets; ++d) {
        phc_dataset *ds = pb->datasets[d];
        if ((rc = phc_dataset_check_start(ds, x, err)))
            return rc;
        if ((rc = phc_nls_add_block(nls, ds->n, ds->param_index, ds->k, phc_dataset_residuals,
                                    ds->derivatives, ds->loss, ds->loss_scale, ds, err)))
            return rc;
    }
    return PHC_OK;
}

/* Runs the starts from x (the configured start, overwritten): start 0 is x
 * itself, the others come from the Sobol box (multistart.h).  With a single
 * configured start, a start 0 that did not converge or that sits where the
 * model no longer depends on a parameter (a stall on a plateau, e.g. NIST
 * BoxBOD from Start 1) adds opt->rescue_starts starts.  On PHC_OK best (np)
 * holds the lowest-cost point, and res->summary (of that start),
 * total_time, starts, rescue_starts and starts_at_best are set.  Reports
 * "start" progress; a cancelled callback is an error. */
static int run_starts(nls_memo *memo, const phc_problem *pb, phc_progress_fn progress, void *user_data,
                      double *x, double *best, phc_fit_result *res, phc_error *err)
{
    const phc_fit_options *opt = &pb->options;
    const size_t np = pb->n_params;
    size_t planned = opt->starts, useless = 0;
    double best_cost = INFINITY;
    double *costs = calloc(opt->starts + opt->rescue_starts, sizeof *costs);
    phc_multistart *ms = NULL;
    int rc = PHC_OK;
    if (!costs)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    phc_progress_relay relay = {progress, user_data, "start", NULL, 0, planned, 0};
    phc_nls_options nls_opt = opt->nls;
    if (progress) {
        nls_opt.on_iteration = phc_progress_relay_iteration;
        nls_opt.on_iteration_data = &relay;
    }
    for (size_t s = 0; s < planned; ++s) {
        relay.step = s + 1;
        relay.steps = planned;
        if (phc_progress_report(progress, user_data, "start", s + 1, planned, -1, NAN, NULL)) {
            rc = phc_error_set(err, PHC_ERR_INTERNAL, "cancelled");
            goto done;
        }
        if (s > 0 && !ms && !(ms = phc_multistart_new(pb))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
        if (s > 0 && (rc = phc_multistart_next(ms, x))) {
            phc_error_set(err, rc, "cannot draw start %zu", s + 1);
            goto done;
        }
        /* a rescue start where some parameter already has no effect before
         * any step (see below) */
        const int flat_start = s > 0 && res->rescue_starts && stalled_on_plateau(memo, pb, x);
        phc_nls_summary sum;
        if ((rc = phc_nls_solve(memo->nls, &nls_opt, x, &sum, err)))
            goto done;
        if (relay.cancelled) {
            rc = phc_error_set(err, PHC_ERR_INTERNAL, "cancelled");
            goto done;
        }
        res->total_time += sum.wall_time;
        costs[s] = sum.outcome == PHC_NLS_FAILED ? INFINITY : sum.final_cost;
        const int improved = costs[s] < best_cost - 1e-9 * fabs(best_cost); /* beyond round-off */
        const int better = costs[s] < best_cost ||
                           (s == 0 && !isfinite(best_cost)) ||
                           (costs[s] == best_cost && res->summary.outcome != PHC_NLS_CONVERGED &&
                            sum.outcome == PHC_NLS_CONVERGED);
        if (better) {
            best_cost = costs[s];
            memcpy(best, x, np * sizeof *x);
            res->summary = sum;
        }
        if (s == 0 && planned == 1 && opt->rescue_starts > 0 &&
            (res->summary.outcome != PHC_NLS_CONVERGED || stalled_on_plateau(memo, pb, best))) {
            planned += opt->rescue_starts;
            res->rescue_starts = opt->rescue_starts;
        } else if (s > 0 && res->rescue_starts) {
            /* A rescue start at which some parameter has no effect already
             * at its starting point, and that ends on a plateau again
             * without a lower cost, did not help.  When the first
             * RESCUE_PATIENCE all are such, the parameter has no effect
             * wherever the box was sampled (a rank-deficient problem, not a
             * bad start): stop, rather than run every rescue start (16 by
             * default, each as slow as the first on a simulation model).
             * A start that only drifts onto a plateau while solving (NIST
             * BoxBOD from Start 1: the exponential saturates) keeps the
             * rescue going. */
            if (flat_start && !improved && stalled_on_plateau(memo, pb, x))
                ++useless;
            if (useless == s && s >= RESCUE_PATIENCE) {
                res->rescue_stopped = 1;
                res->rescue_starts = s;
                planned = s + 1;
            }
        }
    }
    res->starts = planned;
    for (size_t s = 0; s < planned; ++s)
        if (isfinite(costs[s]) && costs[s] <= best_cost + 1e-8 * fabs(best_cost) + 1e-300)
            res->starts_at_best++;
done:
    phc_multistart_free(ms);
    free(costs);
    return rc;
}

/* The solve stage: declares pb to nls (solve_setup), runs the starts
 * (run_starts) and, when the best start converged, polishes it by
 * Gauss-Newton (polish).  On PHC_OK best (np values) is the solution, at
 * which the analyse stage judges everything; res holds the solver's
 * summary and the start counts. */
static int fit_solve(nls_memo *memo, const phc_problem *pb, phc_progress_fn progress, void *user_data,
                     double *best, phc_fit_result *res, phc_error *err)
{
    double *x = calloc(pb->n_params, sizeof *x);
    int rc;
    if (!x)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if (!(rc = solve_setup(memo->nls, pb, x, err)) && !(rc = run_starts(memo, pb, progress, user_data, x, best, res, err)) &&
        res->summary.outcome == PHC_NLS_CONVERGED)
        rc = polish(memo, pb, best, phc_nls_residual_count(memo->nls), err);
    free(x);
    return rc;
}

/* Weights that depend on the parameters (phc_dataset_ops.reweight): after
 * the solve, every such data set may recompute its weights at the fitted
 * values best; while one does, the problem is solved again from best with
 * the new weights (one start, then the polish) and best, res->summary and
 * res->total_time become the new solve's.  The kinds bound the rounds. */
static int reweight_rounds(nls_memo *memo, const phc_problem *pb, phc_progress_fn progress, void *user_data,
                           double *best, phc_fit_result *res, phc_error *err)
{
    const size_t np = pb->n_params;
    int rc = PHC_OK;
    double *p = NULL, *x = malloc(np * sizeof *x);
    size_t kmax = 1;
    for (size_t d = 0; d < pb->n_datasets; ++d)
        kmax = pb->datasets[d]->k > kmax ? pb->datasets[d]->k : kmax;
    if (!x || !(p = malloc(kmax * sizeof *p))) {
        free(x);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    for (size_t round = 1; !rc; ++round) {
        int again = 0;
        for (size_t d = 0; d < pb->n_datasets && !rc; ++d) {
            phc_dataset *ds = pb->datasets[d];
            int a = 0;
            if (!ds->ops->reweight)
                continue;
            slot_values(ds, best, p);
            rc = ds->ops->reweight(ds, p, &a, err);
            again |= a;
        }
        if (rc || !again)
            break;
        memo->valid = 0; /* the residuals changed with the weights */
        if (phc_progress_report(progress, user_data, "reweighted solve", round, 0, -1, NAN, NULL)) {
            rc = phc_error_set(err, PHC_ERR_INTERNAL, "cancelled");
            break;
        }
        memcpy(x, best, np * sizeof *x);
        phc_nls_summary sum;
        if ((rc = phc_nls_solve(memo->nls, &pb->options.nls, x, &sum, err)))
            break;
        res->total_time += sum.wall_time;
        res->summary = sum;
        memcpy(best, x, np * sizeof *x);
        if (sum.outcome != PHC_NLS_CONVERGED)
            break;
        rc = polish(memo, pb, best, phc_nls_residual_count(memo->nls), err);
    }
    free(x);
    free(p);
    return rc;
}

/* ---- the analyse stage: covariance, intervals, sensitivities, data sets -- */

/* The result's frame at the solution: its name, the parameter and data-set
 * arrays (filled later), the free parameters (free_index, n_free), the
 * observation count m, degrees of freedom, the options it reports, the
 * weighted residual sum of squares of the m weighted residuals r and the
 * variance factor s2 (1 with absolute sigmas, else wrss / dof, NAN without
 * degrees of freedom).  PHC_OK or PHC_ERR_NOMEM with a message. */
static int result_frame(const phc_problem *pb, const double *r, size_t m, phc_fit_result *res, phc_error *err)
{
    const size_t np = pb->n_params;
    const phc_fit_options *opt = &pb->options;
    res->name = strdup(pb->name);
    res->n_params = np;
    res->params = calloc(np, sizeof *res->params);
    res->free_index = calloc(np, sizeof *res->free_index);
    res->n_datasets = pb->n_datasets;
    res->datasets = calloc(pb->n_datasets, sizeof *res->datasets);
    if (!res->name || !res->params || !res->free_index || !res->datasets)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    res->n_obs = m;
    for (size_t i = 0; i < np; ++i)
        if (!pb->params[i].fixed)
            res->free_index[res->n_free++] = i;
    res->dof = (long)m - (long)res->n_free;
    res->absolute_sigma = opt->absolute_sigma;
    res->level = opt->level;
    res->collinearity_threshold = opt->collinearity_threshold;
    res->correlation_threshold = opt->correlation_threshold;
    for (size_t i = 0; i < m; ++i)
        res->wrss += r[i] * r[i];
    res->s2 = opt->absolute_sigma ? 1.0 : (res->dof > 0 ? res->wrss / (double)res->dof : NAN);
    return PHC_OK;
}

/* Each parameter's result at the solution best: name, unit, start and value
 * in the user's unit (parameter_units.h), and for free parameters the
 * standard error from cov (NAN without degrees of freedom), the t-based 95%
 * interval and whether it ended on a bound.  PHC_OK or PHC_ERR_NOMEM. */
static int param_results(const phc_problem *pb, const double *best, const phc_covariance *cov,
                         phc_fit_result *res, phc_error *err)
{
    const double t = res->dof > 0 ? gsl_cdf_tdist_Pinv(0.975, (double)res->dof) : NAN;
    for (size_t i = 0, f = 0; i < pb->n_params; ++i) {
        const phc_parameter *p = &pb->params[i];
        phc_param_result *pr = &res->params[i];
        pr->name = strdup(p->name);
        pr->unit = p->unit ? strdup(p->unit) : NULL;
        if (!pr->name || (p->unit && !pr->unit))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        pr->start = phc_parameter_to_user(p, p->value);
        pr->value = phc_parameter_to_user(p, best[i]);
        pr->unit_scale = p->unit_scale;
        pr->unit_offset = p->unit_offset;
        pr->fixed = p->fixed;
        { /* a negative unit scale swaps the bounds */
            const double a = isfinite(p->lower) ? phc_parameter_to_user(p, p->lower) : (p->unit_scale > 0 ? -INFINITY : INFINITY);
            const double b = isfinite(p->upper) ? phc_parameter_to_user(p, p->upper) : (p->unit_scale > 0 ? INFINITY : -INFINITY);
            pr->lower = fmin(a, b);
            pr->upper = fmax(a, b);
        }
        pr->stderr_ = pr->ci_lo = pr->ci_hi = pr->sens_l1 = pr->sens_l2 = NAN;
        if (p->fixed)
            continue;
        pr->stderr_ = res->dof > 0 ? cov->stderr_[f] / fabs(p->unit_scale) : NAN;
        pr->ci_lo = pr->value - t * pr->stderr_;
        pr->ci_hi = pr->value + t * pr->stderr_;
        const double tol = 1e-10 * phc_problem_scale(pb, i);
        if (isfinite(p->lower) && best[i] - p->lower <= tol)
            pr->at_bound = p->unit_scale > 0 ? -1 : 1;
        else if (isfinite(p->upper) && p->upper - best[i] <= tol)
            pr->at_bound = p->unit_scale > 0 ? 1 : -1;
        ++f;
    }
    return PHC_OK;
}

/* The combinations of free parameters the data cannot determine (cov's null
 * space, described with the parameters' names) into res->undetermined. */
static int undetermined_combinations(const phc_problem *pb, const phc_covariance *cov, phc_fit_result *res,
                                     phc_error *err)
{
    const size_t nf = res->n_free;
    if (!cov->n_null)
        return PHC_OK;
    const char **names = malloc(nf * sizeof *names);
    res->undetermined = calloc(cov->n_null, sizeof *res->undetermined);
    if (!names || !res->undetermined) {
        free(names);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    for (size_t f = 0; f < nf; ++f)
        names[f] = pb->params[res->free_index[f]].name;
    for (size_t k = 0; k < cov->n_null; ++k) {
        char buf[512];
        phc_covariance_describe_null(cov, k, names, buf, sizeof buf);
        res->undetermined[res->n_undetermined++] = strdup(buf);
    }
    free(names);
    return PHC_OK;
}

/* Covariance over the free parameters from Jf (m x n_free, the Jacobian's
 * free columns at best), scaled by res->s2 (1 when undefined): rank,
 * condition, correlations, undetermined combinations and every parameter's
 * interval (param_results).  PHC_OK or an error with a message. */
static int analyse_covariance(const phc_problem *pb, const double *best, const double *Jf, size_t m,
                              phc_fit_result *res, phc_error *err)
{
    const size_t nf = res->n_free;
    const double s2 = isfinite(res->s2) ? res->s2 : 1.0;
    phc_covariance cov = {0};
    double *scales = calloc(nf ? nf : 1, sizeof *scales); /* one zero when no parameter is free */
    if (!scales)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t f = 0; f < nf; ++f)
        scales[f] = effect_scale(pb, best, res->free_index[f]);
    int rc = phc_covariance_compute(Jf, m, nf, s2, NEGLIGIBLE_EFFECT, scales, &cov, err);
    free(scales);
    if (rc)
        goto done;
    res->rank = cov.rank;
    res->condition = cov.condition;
    res->correlation = dup_array(cov.correlation, nf * nf);
    if (!res->correlation) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    if (!(rc = undetermined_combinations(pb, &cov, res, err)))
        rc = param_results(pb, best, &cov, res, err);
done:
    phc_covariance_clear(&cov);
    return rc;
}

/* The standard deviation the weighted residuals are measured in: sqrt(s2),
 * or 1 when s2 is not a positive number. */
static double noise_scale(const phc_fit_result *res)
{
    return isfinite(res->s2) && res->s2 > 0 ? sqrt(res->s2) : 1.0;
}

/* Normalised sensitivities S_ij = d yhat_i / d p_j * p_j / sigma_i (FME;
 * Soetaert & Petzoldt 2010) of the free parameters from Jf (m x n_free) at
 * best, their L1/L2 summaries and collinearity indices into
 * res->sensitivity and the parameters' sens_l1, sens_l2. */
static int analyse_sensitivity(const phc_problem *pb, const double *best, const double *Jf, size_t m,
                               phc_fit_result *res, phc_error *err)
{
    const size_t nf = res->n_free;
    double *S = malloc(m * (nf ? nf : 1) * sizeof *S);
    int rc = PHC_OK;
    if (!S)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    const double s_noise = noise_scale(res);
    for (size_t d = 0, row = 0; d < pb->n_datasets; ++d) {
        const phc_dataset *ds = pb->datasets[d];
        /* residuals are already divided by sigma when sigmas are given */
        const double extra = ds->sigma && pb->options.absolute_sigma ? 1.0 : s_noise;
        for (size_t i = 0; i < ds->n; ++i, ++row)
            for (size_t f = 0; f < nf; ++f) {
                const size_t gi = res->free_index[f];
                const double pj = best[gi] != 0 ? best[gi] : phc_problem_scale(pb, gi); /* signed */
                S[row * nf + f] = -Jf[row * nf + f] * pj / extra;
            }
    }
    if (nf && (rc = phc_sensitivity_compute(S, m, nf, MAX_COLLIN_SETS, &res->sensitivity, err)))
        goto done;
    for (size_t f = 0; f < nf; ++f) {
        res->params[res->free_index[f]].sens_l1 = res->sensitivity.l1[f];
        res->params[res->free_index[f]].sens_l2 = res->sensitivity.l2[f];
    }
done:
    free(S);
    return rc;
}

/* Per data set at best, from the weighted residuals r (m) and Jacobian J
 * (m x np): goodness, residual checks, the dense curve, the kind's report
 * section and cross-validation (fill_dataset_result, add_cross_validation);
 * res->rss sums the unweighted residuals' squares. */
static int analyse_datasets(const phc_problem *pb, const double *best, const double *r, const double *J,
                            phc_progress_fn progress, void *user_data, phc_fit_result *res, phc_error *err)
{
    const size_t np = pb->n_params;
    const double s = pb->options.absolute_sigma ? 1.0 : noise_scale(res);
    int rc;
    for (size_t d = 0, row = 0; d < pb->n_datasets; ++d) {
        phc_dataset *ds = pb->datasets[d];
        if ((rc = fill_dataset_result(ds, best, r + row, J + row * np, np, res->free_index, res->n_free, s,
                                      pb->options.level, &res->datasets[d], err)) ||
            (rc = add_cross_validation(pb, ds, best, progress, user_data, &res->datasets[d], err)))
            return rc;
        for (size_t i = 0; i < ds->n; ++i)
            res->rss += res->datasets[d].residual[i] * res->datasets[d].residual[i];
        row += ds->n;
    }
    return PHC_OK;
}

/* The analyse stage: everything judged at the solution best (from the
 * solve stage, nls set up by it): residuals and Jacobian, the result's
 * frame, covariance and intervals, sensitivities, the per-data-set results
 * and the verdict.  Reports "uncertainty" progress first; a cancelled
 * callback is an error. */
static int fit_analyse(nls_memo *memo, phc_problem *pb, const double *best, phc_progress_fn progress,
                       void *user_data, phc_fit_result *res, phc_error *err)
{
    const size_t np = pb->n_params, m = phc_nls_residual_count(memo->nls);
    if (phc_progress_report(progress, user_data, "uncertainty", 0, 0, -1, NAN, NULL))
        return phc_error_set(err, PHC_ERR_INTERNAL, "cancelled");
    double *r = calloc(m, sizeof *r), *J = calloc(m * np, sizeof *J), *Jf = NULL;
    int rc;
    if (!r || !J) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    if ((rc = memo_evaluate(memo, best, r, J, &res->cost, err)) || (rc = result_frame(pb, r, m, res, err)))
        goto done;
    const size_t nf = res->n_free;
    if (!(Jf = malloc(m * nf * sizeof *Jf))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < m; ++i)
        for (size_t f = 0; f < nf; ++f)
            Jf[i * nf + f] = J[i * np + res->free_index[f]];
    if ((rc = analyse_covariance(pb, best, Jf, m, res, err)) || (rc = analyse_sensitivity(pb, best, Jf, m, res, err)) ||
        (rc = analyse_datasets(pb, best, r, J, progress, user_data, res, err)))
        goto done;
    if (build_verdict(res))
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
done:
    free(r);
    free(J);
    free(Jf);
    return rc;
}

int phc_fit_run(phc_problem *pb, phc_progress_fn progress, void *user_data,
                phc_fit_result **out, phc_error *err)
{
    int rc;
    *out = NULL;
    if ((rc = phc_problem_validate(pb, err)))
        return rc;
    /* long work of the kinds while the fit runs reports progress through
     * their data set */
    for (size_t d = 0; d < pb->n_datasets; ++d) {
        pb->datasets[d]->progress = progress;
        pb->datasets[d]->progress_data = user_data;
    }
    phc_nls *nls = phc_nls_new(pb->n_params);
    nls_memo memo = {nls, 0, pb->n_params, 0, NULL, NULL, NULL, 0};
    phc_fit_result *res = calloc(1, sizeof *res);
    double *best = calloc(pb->n_params, sizeof *best);
    if (!nls)
        rc = phc_nls_new_error("fit", err);
    else if (!res || !best)
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    else if (!(rc = fit_solve(&memo, pb, progress, user_data, best, res, err)) &&
             (res->summary.outcome != PHC_NLS_CONVERGED ||
              !(rc = reweight_rounds(&memo, pb, progress, user_data, best, res, err))) &&
             !(rc = fit_analyse(&memo, pb, best, progress, user_data, res, err))) {
        *out = res;
        res = NULL;
    }
    for (size_t d = 0; d < pb->n_datasets; ++d) {
        pb->datasets[d]->progress = NULL;
        pb->datasets[d]->progress_data = NULL;
    }
    nls_memo_clear(&memo);
    phc_nls_free(nls);
    phc_fit_result_free(res);
    free(best);
    return rc;
}
