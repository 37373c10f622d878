/* Day and night, covariates and a pot for weight curves: see weight_drivers.h. */
#include "fit/costs/weight_drivers.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/costs/source_file.h"
#include "fit/config/yaml_keys.h" /* until this kind is YAML-free */
#include "measurements/c_number.h"
#include "measurements/logger_time.h"

#define DAY_S 86400.0

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

/* "HH:MM" or "HH:MM:SS" -> s since midnight, or -1. */
static double clock_seconds(const char *s)
{
    int h = -1, m = -1, sec = 0, used = 0;
    if (sscanf(s, "%2d:%2d%n", &h, &m, &used) != 2)
        return -1;
    if (s[used] == ':') {
        int more = 0;
        if (sscanf(s + used + 1, "%2d%n", &sec, &more) != 1)
            return -1;
        used += 1 + more;
    }
    if (s[used] || h < 0 || h > 24 || m < 0 || m > 59 || sec < 0 || sec > 59 || (h == 24 && (m || sec)))
        return -1;
    return h * 3600.0 + m * 60.0 + sec;
}

static int clock_key(const phc_yaml_doc *doc, const phc_yaml_node *map, const char *key, int required,
                     double *out, phc_error *err)
{
    const char *s = NULL;
    int rc = phc_yaml_map_string(doc, map, key, required, "key 'day'", &s, err);
    if (rc || !s)
        return rc;
    *out = clock_seconds(s);
    if (*out < 0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: day: %s '%s' is not a clock time; expected \"HH:MM\" (24 h)",
                             doc->path, phc_yaml_get(map, key)->line, key, s);
    return PHC_OK;
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

/* Light schedule: intervals alternating day / night over the curve, from a
 * day start at or before 0 to beyond t_max.  The starts and ends are local
 * clock times: with a time zone they are placed day by day through it. */
static int load_schedule(const phc_yaml_doc *doc, const phc_yaml_node *day, double t_max,
                         double t0_posix, const char *timezone, phc_weight_drivers *d,
                         phc_error *err)
{
    static const char *const keys[] = {"start", "end", "night_factor", "clock", NULL};
    int rc;
    if (day->kind != PHC_YAML_MAPPING)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: key 'day': expected {start: \"HH:MM\", end: \"HH:MM\", "
                             "night_factor: F}", doc->path, day->line);
    double clock0 = NAN;
    d->night_factor = NAN;
    if ((rc = phc_yaml_check_keys(doc, day, keys, "key 'day'", err)) ||
        (rc = clock_key(doc, day, "start", 1, &d->day_start, err)) ||
        (rc = clock_key(doc, day, "end", 1, &d->day_end, err)) ||
        (rc = clock_key(doc, day, "clock", 0, &clock0, err)) ||
        (rc = phc_yaml_map_number(doc, day, "night_factor", 0, "key 'day'", &d->night_factor, err)))
        return rc;
    if (!(d->day_start < d->day_end))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: day: start (%02d:%02d) must be before end (%02d:%02d) on the "
                             "same day", doc->path, phc_yaml_get(day, "start")->line,
                             (int)(d->day_start / 3600), (int)fmod(d->day_start / 60, 60),
                             (int)(d->day_end / 3600), (int)fmod(d->day_end / 60, 60));
    const phc_yaml_node *nf = phc_yaml_get(day, "night_factor");
    if (nf && !(d->night_factor >= 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: day: night_factor must be >= 0, found %g",
                             doc->path, nf->line, d->night_factor);
    const int stamped = !isnan(t0_posix);
    if (stamped == !isnan(clock0))
        return phc_error_set(err, PHC_ERR_INPUT,
                             stamped ? "%s:%zu: day: the weighings have dates and times, so 'clock' is "
                                       "not needed; remove it"
                                     : "%s:%zu: day: the time column is a plain number, so give "
                                       "`clock: \"HH:MM\"`, the local time of the first weighing",
                             doc->path, stamped ? phc_yaml_get(day, "clock")->line : day->line);
    d->schedule = 1;
    /* day starts and ends (s since the first weighing) */
    double *starts = NULL, *ends = NULL;
    size_t ns = 0, ne = 0;
    if (stamped) {
        const double lo = t0_posix, hi = t0_posix + t_max;
        if ((rc = phc_local_daily_times(timezone, lo, hi, d->day_start, &starts, &ns, err)) ||
            (rc = phc_local_daily_times(timezone, lo, hi, d->day_end, &ends, &ne, err))) {
            free(starts);
            return rc;
        }
        for (size_t i = 0; i < ns; ++i)
            starts[i] -= t0_posix;
        for (size_t i = 0; i < ne; ++i)
            ends[i] -= t0_posix;
    } else {
        const size_t days = (size_t)ceil(t_max / DAY_S) + 3;
        starts = malloc(days * sizeof *starts);
        ends = malloc(days * sizeof *ends);
        if (!starts || !ends) {
            free(starts);
            free(ends);
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        }
        for (size_t k = 0; k < days; ++k) {
            starts[k] = ((double)k - 1) * DAY_S + d->day_start - clock0;
            ends[k] = ((double)k - 1) * DAY_S + d->day_end - clock0;
        }
        ns = ne = days;
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
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: day: the schedule does not cover the first "
                             "weighing", doc->path, day->line);
    return PHC_OK;
}

static int load_covariates(const phc_yaml_doc *doc, const phc_yaml_node *cov, const phc_table *table,
                           const size_t *rows, const double *t, size_t n_rows, phc_weight_drivers *d,
                           phc_error *err)
{
    static const char *const keys[] = {"columns", "law", NULL};
    const char *law = "linear";
    int rc;
    if (cov->kind != PHC_YAML_MAPPING)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: key 'covariates': expected {columns: [NAME, ...], law: linear}",
                             doc->path, cov->line);
    if ((rc = phc_yaml_check_keys(doc, cov, keys, "key 'covariates'", err)) ||
        (rc = phc_yaml_map_string(doc, cov, "law", 0, "key 'covariates'", &law, err)))
        return rc;
    if (strcmp(law, "linear") != 0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: covariates: law '%s' is not known; the one law is linear "
                             "(g = 1 + sum of loss_<column> x column)",
                             doc->path, phc_yaml_get(cov, "law")->line, law);
    const phc_yaml_node *cols = phc_yaml_get(cov, "columns");
    if (!cols || cols->kind != PHC_YAML_SEQUENCE || cols->count == 0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: covariates: 'columns' must be a non-empty list of column names",
                             doc->path, cols ? cols->line : cov->line);
    const size_t J = cols->count;
    d->n_cov = J;
    d->cov_names = calloc(J, sizeof *d->cov_names);
    d->cov_x = malloc(n_rows * J * sizeof *d->cov_x);
    double *v = malloc(n_rows * sizeof *v);
    if (!d->cov_names || !d->cov_x || !v || grow(d, n_rows)) {
        free(v);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    for (size_t j = 0; j < J; ++j) {
        const phc_yaml_node *c = cols->items[j];
        if (c->kind != PHC_YAML_SCALAR) {
            free(v);
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: covariates: expected a column name",
                                 doc->path, c->line);
        }
        long col = phc_table_find(table, c->scalar);
        if (col < 0) {
            free(v);
            return phc_unknown_column(doc, c->line, "covariate column", c->scalar, table, err);
        }
        if (!(d->cov_names[j] = strdup(c->scalar))) {
            free(v);
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        }
        for (size_t i = 0; i < n_rows; ++i) {
            const char *cell = phc_table_cell(table, rows[i], (size_t)col);
            char *end = NULL;
            v[i] = phc_strtod_c(cell, &end);
            if (!end || end == cell || *end || !isfinite(v[i])) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: column '%s': a covariate needs a number at every kept "
                                   "weighing, found '%s'", phc_table_source(table),
                                   phc_table_row_line(table, rows[i]), c->scalar, cell);
                free(v);
                return rc;
            }
        }
        /* interval i = [t_i, t_{i+1}): the mean of its two readings */
        for (size_t i = 0; i < n_rows; ++i)
            d->cov_x[i * J + j] = i + 1 < n_rows ? 0.5 * (v[i] + v[i + 1]) : v[i];
    }
    free(v);
    d->n = n_rows;
    for (size_t i = 0; i < n_rows; ++i)
        d->start[i] = t[i];
    return PHC_OK;
}

static int load_pot(const phc_yaml_doc *doc, const phc_yaml_node *pot, phc_weight_drivers *d,
                    phc_error *err)
{
    static const char *const keys[] = {"capacity", "conductance", NULL};
    int rc;
    if (pot->kind != PHC_YAML_MAPPING)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: key 'pot': expected {capacity: GRAMS, conductance: G_PER_S} "
                             "(either may be left out to fit it)", doc->path, pot->line);
    d->pot = 1;
    d->capacity = d->conductance = NAN;
    if ((rc = phc_yaml_check_keys(doc, pot, keys, "key 'pot'", err)) ||
        (rc = phc_yaml_map_number(doc, pot, "capacity", 0, "key 'pot'", &d->capacity, err)) ||
        (rc = phc_yaml_map_number(doc, pot, "conductance", 0, "key 'pot'", &d->conductance, err)))
        return rc;
    const phc_yaml_node *c = phc_yaml_get(pot, "capacity"), *k = phc_yaml_get(pot, "conductance");
    if (c && !(d->capacity > 0 && isfinite(d->capacity)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: pot: capacity must be > 0 g, found %g",
                             doc->path, c->line, d->capacity);
    if (k && !(d->conductance >= 0 && isfinite(d->conductance)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: pot: conductance must be >= 0 g/s, found %g",
                             doc->path, k->line, d->conductance);
    return PHC_OK;
}

int phc_weight_drivers_load(const phc_yaml_doc *doc, const phc_yaml_node *node,
                            const phc_table *table, const size_t *rows, const double *t,
                            size_t n_rows, double t0_posix, const char *timezone,
                            phc_weight_drivers *d, phc_error *err)
{
    memset(d, 0, sizeof *d);
    d->night_factor = d->capacity = d->conductance = NAN;
    const phc_yaml_node *day = phc_yaml_get(node, "day"), *cov = phc_yaml_get(node, "covariates"),
                        *pot = phc_yaml_get(node, "pot");
    int rc = PHC_OK;
    if (day && cov)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: give either 'day' (a light schedule) or 'covariates', not both",
                             doc->path, cov->line);
    if (day)
        rc = load_schedule(doc, day, n_rows ? t[n_rows - 1] : 0, t0_posix, timezone, d, err);
    else if (cov)
        rc = load_covariates(doc, cov, table, rows, t, n_rows, d, err);
    if (!rc && pot)
        rc = load_pot(doc, pot, d, err);
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
