/* Day and night, covariates and a pot for weight curves: see weight_drivers.h. */
#include "fit/costs/weight_drivers.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "measurements/logger_time.h"

#define DAY_S 86400.0

/* The place of a message about option `key` (fit/costs/origin.h). */
#define WHERE(key) phc_origin_key(origin, "weight_curve", key).text

void phc_weight_drivers_free(phc_weight_drivers *d)
{
    if (!d)
        return;
    free(d->start);
    free(d->night);
    for (size_t j = 0; j < d->n_cov; ++j)
        free(d->cov_names[j]);
    free(d->cov_names);
    free(d->cov_x);
    free(d->g);
    free(d->dg);
    memset(d, 0, sizeof *d);
}

static int grow(phc_weight_drivers *d, size_t cap)
{
    double *s = realloc(d->start, cap * sizeof *s);
    if (!s)
        return PHC_ERR_NOMEM;
    d->start = s;
    unsigned char *nt = realloc(d->night, cap * sizeof *nt);
    if (!nt)
        return PHC_ERR_NOMEM;
    d->night = nt;
    return PHC_OK;
}

/* The day's starts and ends (s since the first weighing) from a day start
 * at or before 0 to beyond t_max: through the time zone on a calendar, else
 * from the clock time of the first weighing.  *starts, *ends malloc'd. */
static int day_changes(const phc_weight_day *day, double t_max, double t0_posix, const char *timezone,
                       double **starts, size_t *ns, double **ends, size_t *ne, phc_error *err)
{
    int rc;
    *starts = *ends = NULL;
    if (!isnan(t0_posix)) {
        const double lo = t0_posix, hi = t0_posix + t_max;
        if ((rc = phc_local_daily_times(timezone, lo, hi, day->start, starts, ns, err)) ||
            (rc = phc_local_daily_times(timezone, lo, hi, day->end, ends, ne, err))) {
            free(*starts);
            *starts = NULL;
            return rc;
        }
        for (size_t i = 0; i < *ns; ++i)
            (*starts)[i] -= t0_posix;
        for (size_t i = 0; i < *ne; ++i)
            (*ends)[i] -= t0_posix;
        return PHC_OK;
    }
    const size_t days = (size_t)ceil(t_max / DAY_S) + 3;
    *starts = malloc(days * sizeof **starts);
    *ends = malloc(days * sizeof **ends);
    if (!*starts || !*ends)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t k = 0; k < days; ++k) {
        (*starts)[k] = ((double)k - 1) * DAY_S + day->start - day->clock;
        (*ends)[k] = ((double)k - 1) * DAY_S + day->end - day->clock;
    }
    *ns = *ne = days;
    return PHC_OK;
}

/* The schedule's values: start before end, a night factor >= 0, and the
 * clock of the first weighing exactly when there is no calendar. */
static int check_day(const phc_weight_day *day, int stamped, const phc_origin *origin, phc_error *err)
{
    if (!(day->start >= 0 && day->end <= DAY_S) || !(isnan(day->clock) || (day->clock >= 0 && day->clock <= DAY_S)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: day: start, end and clock must be clock times, 0 to "
                             "86400 s since midnight, found %g, %g and %g", WHERE("day"), day->start,
                             day->end, day->clock);
    if (!(day->start < day->end))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s: day: start (%02d:%02d) must be before end (%02d:%02d) on the "
                             "same day", WHERE("day.start"),
                             (int)(day->start / 3600), (int)fmod(day->start / 60, 60),
                             (int)(day->end / 3600), (int)fmod(day->end / 60, 60));
    if (!isnan(day->night_factor) && !(day->night_factor >= 0 && isfinite(day->night_factor)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: day: night_factor must be >= 0, found %g",
                             WHERE("day.night_factor"), day->night_factor);
    if (stamped == !isnan(day->clock))
        return phc_error_set(err, PHC_ERR_INPUT,
                             stamped ? "%s: day: the weighings have dates and times, so 'clock' is "
                                       "not needed; remove it"
                                     : "%s: day: the time column is a plain number, so give "
                                       "`clock: \"HH:MM\"`, the local time of the first weighing",
                             WHERE(stamped ? "day.clock" : "day"));
    return PHC_OK;
}

/* Light schedule: intervals alternating day / night over the curve, from a
 * day start at or before 0 to beyond t_max.  The starts and ends are local
 * clock times: with a time zone they are placed day by day through it. */
static int load_schedule(const phc_weight_day *day, double t_max, double t0_posix, const char *timezone,
                         const phc_origin *origin, phc_weight_drivers *d, phc_error *err)
{
    int rc;
    if ((rc = check_day(day, !isnan(t0_posix), origin, err)))
        return rc;
    d->day_start = day->start;
    d->day_end = day->end;
    d->night_factor = day->night_factor;
    d->schedule = 1;
    double *starts = NULL, *ends = NULL;
    size_t ns = 0, ne = 0;
    if ((rc = day_changes(day, t_max, t0_posix, timezone, &starts, &ns, &ends, &ne, err))) {
        free(starts);
        free(ends);
        return rc;
    }
    /* merge: a start opens a day, an end a night; keep from the last change
     * at or before 0 */
    size_t cap = ns + ne + 1, i = 0, j = 0;
    if (grow(d, cap)) {
        free(starts);
        free(ends);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    d->n = 0;
    while (i < ns || j < ne) {
        int is_start = j >= ne || (i < ns && starts[i] <= ends[j]);
        double t = is_start ? starts[i++] : ends[j++];
        if (t <= 0)
            d->n = 0; /* an earlier change is superseded */
        if (d->n && d->night[d->n - 1] == !is_start)
            continue;
        d->start[d->n] = t;
        d->night[d->n] = (unsigned char)!is_start;
        ++d->n;
    }
    free(starts);
    free(ends);
    if (d->n == 0 || d->start[0] > 0)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: day: the schedule does not cover the first "
                             "weighing", WHERE("day"));
    return PHC_OK;
}

/* Covariates: interval i = [t_i, t_{i+1}) takes the mean of its two
 * readings of each column (the last interval its own reading). */
static int load_covariates(const double *x, const char *const *names, size_t J, const double *t,
                           size_t n_rows, phc_weight_drivers *d, phc_error *err)
{
    if (!(d->cov_names = calloc(J, sizeof *d->cov_names)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    d->n_cov = J;
    d->cov_x = malloc((n_rows ? n_rows : 1) * J * sizeof *d->cov_x);
    if (!d->cov_x || grow(d, n_rows ? n_rows : 1))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t j = 0; j < J; ++j) {
        if (!(d->cov_names[j] = strdup(names && names[j] ? names[j] : "covariate")))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        for (size_t i = 0; i < n_rows; ++i)
            d->cov_x[i * J + j] = i + 1 < n_rows ? 0.5 * (x[i * J + j] + x[(i + 1) * J + j]) : x[i * J + j];
    }
    d->n = n_rows;
    for (size_t i = 0; i < n_rows; ++i)
        d->start[i] = t[i];
    return PHC_OK;
}

static int load_pot(const phc_weight_pot *pot, const phc_origin *origin, phc_weight_drivers *d,
                    phc_error *err)
{
    if (!isnan(pot->capacity) && !(pot->capacity > 0 && isfinite(pot->capacity)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: pot: capacity must be > 0 g, found %g",
                             WHERE("pot.capacity"), pot->capacity);
    if (!isnan(pot->conductance) && !(pot->conductance >= 0 && isfinite(pot->conductance)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: pot: conductance must be >= 0 g/s, found %g",
                             WHERE("pot.conductance"), pot->conductance);
    d->pot = 1;
    d->capacity = pot->capacity;
    d->conductance = pot->conductance;
    return PHC_OK;
}

int phc_weight_drivers_init(const phc_weight_day *day, const phc_weight_pot *pot,
                            const double *covariates, const char *const *names, size_t n_cov,
                            const double *t, size_t n_rows, double t0_posix, const char *timezone,
                            const phc_origin *origin, phc_weight_drivers *d, phc_error *err)
{
    memset(d, 0, sizeof *d);
    d->night_factor = d->capacity = d->conductance = NAN;
    const int schedule = day && day->on;
    int rc = PHC_OK;
    if (schedule && n_cov)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s: give either 'day' (a light schedule) or 'covariates', not both",
                             WHERE("covariates"));
    if (n_cov && !covariates)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: %zu covariates without readings",
                             WHERE("covariates"), n_cov);
    if (schedule)
        rc = load_schedule(day, n_rows ? t[n_rows - 1] : 0, t0_posix, timezone, origin, d, err);
    else if (n_cov)
        rc = load_covariates(covariates, names, n_cov, t, n_rows, d, err);
    if (!rc && pot && pot->on)
        rc = load_pot(pot, origin, d, err);
    const size_t nc = phc_weight_drivers_coef_count(d);
    if (!rc && d->n) {
        d->g = malloc(d->n * sizeof *d->g);
        d->dg = malloc((nc ? d->n * nc : 1) * sizeof *d->dg);
        if (!d->g || !d->dg)
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    if (rc)
        phc_weight_drivers_free(d);
    return rc;
}

int phc_weight_drivers_time_varying(const phc_weight_drivers *d) { return d->n > 0; }

size_t phc_weight_drivers_coef_count(const phc_weight_drivers *d)
{
    return (d->schedule && isnan(d->night_factor) ? 1 : 0) + d->n_cov;
}

size_t phc_weight_drivers_slot_count(const phc_weight_drivers *d)
{
    return phc_weight_drivers_coef_count(d) + (d->pot && isnan(d->capacity)) +
           (d->pot && isnan(d->conductance));
}

int phc_weight_drivers_slot_names(const phc_weight_drivers *d, char **names)
{
    size_t k = 0;
    if (d->schedule && isnan(d->night_factor))
        names[k++] = strdup("night_factor");
    for (size_t j = 0; j < d->n_cov; ++j) {
        size_t len = strlen(d->cov_names[j]);
        char *s = malloc(len + 6);
        if (s) {
            memcpy(s, "loss_", 5);
            for (size_t c = 0; c <= len; ++c) {
                unsigned char ch = (unsigned char)d->cov_names[j][c];
                s[5 + c] = (char)(ch && !isalnum(ch) ? '_' : ch);
            }
        }
        names[k++] = s;
    }
    if (d->pot && isnan(d->capacity))
        names[k++] = strdup("pot_capacity");
    if (d->pot && isnan(d->conductance))
        names[k++] = strdup("pot_conductance");
    for (size_t i = 0; i < k; ++i)
        if (!names[i])
            return PHC_ERR_NOMEM;
    return PHC_OK;
}

void phc_weight_drivers_model(phc_weight_drivers *d, const double *v,
                              const phc_water_loss_pattern **loss, phc_water_loss_pattern *loss_buf,
                              const phc_water_pot **pot, phc_water_pot *pot_buf)
{
    size_t s = 0;
    const size_t nc = phc_weight_drivers_coef_count(d);
    *loss = NULL;
    *pot = NULL;
    if (d->schedule) {
        const int fitted = isnan(d->night_factor);
        const double f = fitted ? v[s++] : d->night_factor;
        for (size_t k = 0; k < d->n; ++k) {
            d->g[k] = d->night[k] ? f : 1.0;
            if (fitted)
                d->dg[k] = d->night[k] ? 1.0 : 0.0;
        }
    } else if (d->n_cov) {
        const size_t J = d->n_cov;
        for (size_t k = 0; k < d->n; ++k) {
            double g = 1.0;
            for (size_t j = 0; j < J; ++j) {
                g += v[s + j] * d->cov_x[k * J + j];
                d->dg[k * J + j] = d->cov_x[k * J + j];
            }
            d->g[k] = g;
        }
        s += J;
    }
    if (d->n) {
        loss_buf->n = d->n;
        loss_buf->start = d->start;
        loss_buf->g = d->g;
        loss_buf->n_coef = nc;
        loss_buf->dg = nc ? d->dg : NULL;
        *loss = loss_buf;
    }
    if (d->pot) {
        pot_buf->capacity = isnan(d->capacity) ? v[s++] : d->capacity;
        pot_buf->conductance = isnan(d->conductance) ? v[s++] : d->conductance;
        *pot = pot_buf;
    }
}
