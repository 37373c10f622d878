/* Weighings from a table: see weight_table.h. */
#include "fit/costs/weight_table.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/costs/source_file.h"
#include "measurements/c_number.h"
#include "measurements/logger_time.h"

/* The place of a message about option `key` (fit/costs/origin.h). */
#define WHERE(key) phc_origin_key(opt->origin, "weight_curve", key).text

/* What phc_weight_curve_read_table allocates for its weighings. */
typedef struct storage {
    double *t, *mass, *sigma, *cov, *gap_s;
    unsigned char *skip;
    size_t *lines, *rows, *gap_line;
    char *time_unit, *mass_unit, *timezone, *source, *time_name, *mass_name;
    char **cov_names;
    size_t n_cov;
} storage;

static void storage_free(storage *s)
{
    if (!s)
        return;
    free(s->t);
    free(s->mass);
    free(s->sigma);
    free(s->cov);
    free(s->gap_s);
    free(s->skip);
    free(s->lines);
    free(s->rows);
    free(s->gap_line);
    free(s->time_unit);
    free(s->mass_unit);
    free(s->timezone);
    free(s->source);
    free(s->time_name);
    free(s->mass_name);
    for (size_t j = 0; s->cov_names && j < s->n_cov; ++j)
        free(s->cov_names[j]);
    free(s->cov_names);
    free(s);
}

void phc_weighings_release(phc_weighings *w)
{
    if (!w || !w->storage)
        return;
    storage_free(w->storage);
    memset(w, 0, sizeof *w);
}

phc_weight_curve_read_options phc_weight_curve_read_options_default(void)
{
    phc_weight_curve_read_options o = {0};
    o.max_gap = NAN;
    return o;
}

/* A copy of s (NULL stays NULL); 0 when out of memory. */
static int dup_string(const char *s, char **out)
{
    *out = s ? strdup(s) : NULL;
    return !s || *out;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* ---- the options -------------------------------------------------------- */

/* The time options make sense together: a time zone needs stamps or an
 * absolute unit; a unit is for numbers. */
static int check_time_options(const phc_weight_curve_read_options *opt, phc_error *err)
{
    int rc;
    if (!opt->time_column || !opt->time_column[0] || !opt->mass_column || !opt->mass_column[0])
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key '%s' is required", WHERE(NULL),
                             !opt->time_column || !opt->time_column[0] ? "time" : "mass");
    if (opt->timestamps && opt->time_unit)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'time': 'unit' is for numeric times; timestamps (format, columns) become hours since the first weighing",
                             WHERE("time.unit"));
    if (!opt->timestamps && opt->time_column_2)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'time': a second time column is for timestamps (date and time)",
                             WHERE("time"));
    if ((rc = phc_time_zone_check(opt->timezone, err)))
        return phc_error_prefix(err, rc, "%s: key 'timezone'", WHERE("time.timezone"));
    if (opt->timezone && !opt->timestamps && !(opt->time_unit && strstr(opt->time_unit, "since")))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'timezone': needs timestamps (format or columns) or an absolute time unit such as \"seconds since 1970-01-01\"",
                             WHERE("time.timezone"));
    return PHC_OK;
}

/* The time unit in s and the mass unit in g. */
static int unit_scales(const phc_weight_curve_read_options *opt, phc_units *units, double *seconds,
                       double *grams, phc_error *err)
{
    phc_unit_conversion tconv, mconv;
    char where[4300];
    int rc;
    snprintf(where, sizeof where, "%s: time unit", WHERE("time"));
    if ((rc = phc_units_conversion(units, opt->timestamps ? "h" : opt->time_unit ? opt->time_unit : "s", "s",
                                   where, &tconv, err)))
        return rc;
    snprintf(where, sizeof where, "%s: mass unit", WHERE("mass"));
    if ((rc = phc_units_conversion(units, opt->mass_unit ? opt->mass_unit : "g", "g", where, &mconv, err)))
        return rc;
    *seconds = tconv.scale;
    *grams = mconv.scale; /* mass units have no offset */
    return PHC_OK;
}

/* ---- the rows of this plant -------------------------------------------- */

/* Does row r match every select pair?  Text equality, or numeric equality
 * when both sides are numbers ("1" matches "1.0"). */
static int row_selected(const phc_table *t, size_t r, const phc_weight_curve_read_options *opt,
                        const long *cols)
{
    for (size_t i = 0; i < opt->n_select; ++i) {
        const char *cell = phc_table_cell(t, r, (size_t)cols[i]);
        const char *want = opt->select_values[i];
        if (strcmp(cell, want) == 0)
            continue;
        char *e1 = NULL, *e2 = NULL;
        double a = phc_strtod_c(cell, &e1), b = phc_strtod_c(want, &e2);
        if (e1 && e2 && e1 != cell && e2 != want && !*e1 && !*e2 && a == b)
            continue;
        return 0;
    }
    return 1;
}

int phc_weight_curve_select_rows(const phc_table *table, const phc_weight_curve_read_options *opt,
                                 size_t **rows, size_t *n, phc_error *err)
{
    const size_t n_rows = phc_table_rows(table);
    long *cols = malloc((opt->n_select ? opt->n_select : 1) * sizeof *cols);
    int rc = PHC_OK;
    *rows = NULL;
    *n = 0;
    if (!cols)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < opt->n_select && !rc; ++i) {
        char key[64];
        snprintf(key, sizeof key, "select.%zu", i);
        if (!opt->select_columns[i] || !opt->select_values[i])
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s: select %zu: expected a column and a value", WHERE(key), i + 1);
        else if ((cols[i] = phc_table_find(table, opt->select_columns[i])) < 0)
            rc = phc_unknown_column_at(WHERE(key), "select column", opt->select_columns[i], table, err);
    }
    if (!rc && !(*rows = malloc((n_rows ? n_rows : 1) * sizeof **rows)))
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t r = 0; !rc && r < n_rows; ++r)
        if (row_selected(table, r, opt, cols))
            (*rows)[(*n)++] = r;
    if (!rc && *n == 0)
        rc = opt->n_select ? phc_error_set(err, PHC_ERR_INPUT, "%s: key 'select': no row of %s matches",
                                           WHERE("select"), phc_table_source(table))
                           : phc_error_set(err, PHC_ERR_INPUT, "%s:1: no data rows below the header; expected at least one",
                                           phc_table_source(table));
    free(cols);
    if (rc) {
        free(*rows);
        *rows = NULL;
        *n = 0;
    }
    return rc;
}

/* ---- times --------------------------------------------------------------- */

/* Numeric times of the selected rows, in their unit; *origin is the POSIX
 * time at 0 for an absolute unit ("hours since 2024-10-24"), else NAN. */
static int numeric_times(const phc_table *t, const phc_weight_curve_read_options *opt, const size_t *keep,
                         size_t n, phc_units *units, double **tv, double *origin, phc_error *err)
{
    phc_unit_conversion ac;
    phc_error ignore;
    int rc;
    if ((rc = phc_table_column_numbers_rows(t, opt->time_column, keep, n, tv, err))) {
        const char *found = err ? strstr(err->message, "found '") : NULL;
        if (found && strpbrk(found + 8, ":/")) /* a date or a clock time */
            snprintf(err->message + strlen(err->message), sizeof err->message - strlen(err->message),
                     "; for date and time text give time: {column: NAME, format: ..., timezone: ...}");
        return rc;
    }
    if (opt->time_unit && strstr(opt->time_unit, "since") &&
        !phc_units_conversion(units, opt->time_unit, "seconds since 1970-01-01 00:00:00 UTC", "", &ac, &ignore))
        *origin = ac.offset;
    return PHC_OK;
}

/* Logger stamps of the selected rows (one column, or a date and a time
 * column joined by a space) as hours since the first; *origin is its POSIX
 * time. */
static int stamp_times(const phc_table *t, const phc_weight_curve_read_options *opt, const size_t *keep,
                       size_t n, double **tv, double *origin, phc_error *err)
{
    const char *col2 = opt->time_column_2;
    long c[2] = {phc_table_find(t, opt->time_column), col2 ? phc_table_find(t, col2) : -1};
    if (col2 && c[1] < 0)
        return phc_unknown_column_at(WHERE("time"), "time column", col2, t, err);
    char what[160];
    if (col2)
        snprintf(what, sizeof what, "columns '%s' and '%s'", opt->time_column, col2);
    else
        snprintf(what, sizeof what, "column '%s'", opt->time_column);
    char **text = calloc(n ? n : 1, sizeof *text);
    size_t *lines = malloc((n ? n : 1) * sizeof *lines);
    int rc = PHC_OK;
    *tv = malloc((n ? n : 1) * sizeof **tv);
    if (!text || !lines || !*tv)
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < n && !rc; ++i) {
        const char *a = phc_table_cell(t, keep[i], (size_t)c[0]);
        const char *b = col2 ? phc_table_cell(t, keep[i], (size_t)c[1]) : NULL;
        lines[i] = phc_table_row_line(t, keep[i]);
        if (!(text[i] = malloc(strlen(a) + (b ? strlen(b) + 2 : 1))))
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        else
            sprintf(text[i], b ? "%s %s" : "%s", a, b);
    }
    phc_logger_clock clock = {opt->time_format, opt->timezone, phc_table_source(t), what};
    if (!rc && !(rc = phc_logger_times(&clock, (const char *const *)text, lines, n, *tv, err)) && n) {
        *origin = (*tv)[0];
        for (size_t i = n; i-- > 0;)
            (*tv)[i] = ((*tv)[i] - *origin) / 3600.0;
    }
    for (size_t i = 0; text && i < n; ++i)
        free(text[i]);
    free(text);
    free(lines);
    return rc;
}

/* ---- tare and gaps ---------------------------------------------------------- */

/* The longest expected pause, s (NAN: the default, decided by find_gaps). */
static int gap_limit(const phc_weight_curve_read_options *opt, phc_units *units, double seconds_per_unit,
                     double *max_gap, phc_error *err)
{
    *max_gap = NAN;
    if (isnan(opt->max_gap))
        return PHC_OK;
    if (opt->max_gap_unit) {
        phc_unit_conversion c;
        char where[4300];
        int rc;
        snprintf(where, sizeof where, "%s: max_gap unit", WHERE("max_gap"));
        if ((rc = phc_units_conversion(units, opt->max_gap_unit, "s", where, &c, err)))
            return rc;
        *max_gap = phc_unit_apply(c, opt->max_gap);
    } else {
        *max_gap = opt->max_gap * seconds_per_unit;
    }
    if (!(*max_gap > 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'max_gap': must be positive", WHERE("max_gap"));
    return PHC_OK;
}

/* Drops the tare readings at the start of the selected rows: each below 50%
 * of the median of the 10 readings after it; at least 2 rows stay. */
static void drop_tare(const phc_table *t, size_t *keep, double *tv, double *mv, size_t *n_sel,
                      phc_weighings *w)
{
    size_t k = 0, n = *n_sel;
    while (k + 2 < n) {
        double next[10];
        size_t m = 0;
        for (size_t j = k + 1; j < n && m < 10; ++j)
            next[m++] = mv[j];
        qsort(next, m, sizeof *next, cmp_double);
        const double median = m % 2 ? next[m / 2] : 0.5 * (next[m / 2 - 1] + next[m / 2]);
        if (!(mv[k] < 0.5 * median))
            break;
        ++k;
    }
    if (k == 0)
        return;
    w->tare_n = k;
    w->tare_line[0] = phc_table_row_line(t, keep[0]);
    w->tare_line[1] = phc_table_row_line(t, keep[k - 1]);
    memmove(keep, keep + k, (n - k) * sizeof *keep);
    memmove(tv, tv + k, (n - k) * sizeof *tv);
    memmove(mv, mv + k, (n - k) * sizeof *mv);
    *n_sel = n - k;
}

/* Lists the pauses longer than max_gap (s; NAN: 6 h, or 3 median steps, so
 * that daily weighings are not all gaps). */
static int find_gaps(const phc_table *t, const size_t *keep, const double *tv, size_t n, double seconds_per_unit,
                     double max_gap, storage *s, phc_weighings *w, phc_error *err)
{
    const int given = !isnan(max_gap);
    double *step = given || n < 2 ? NULL : malloc((n - 1) * sizeof *step);
    if (!given)
        max_gap = 6 * 3600.0;
    if (step) {
        for (size_t i = 1; i < n; ++i)
            step[i - 1] = tv[i] - tv[i - 1];
        qsort(step, n - 1, sizeof *step, cmp_double);
        max_gap = fmax(max_gap, 3 * step[(n - 1) / 2] * seconds_per_unit);
        free(step);
    }
    w->max_gap = max_gap;
    for (size_t i = 1; i < n; ++i)
        if ((tv[i] - tv[i - 1]) * seconds_per_unit > max_gap) {
            double *g = realloc(s->gap_s, (w->n_gaps + 1) * sizeof *g);
            size_t *l = g ? realloc(s->gap_line, (w->n_gaps + 1) * sizeof *l) : NULL;
            if (g)
                s->gap_s = g;
            if (!l)
                return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            s->gap_line = l;
            s->gap_s[w->n_gaps] = (tv[i] - tv[i - 1]) * seconds_per_unit;
            s->gap_line[w->n_gaps++] = phc_table_row_line(t, keep[i - 1]);
        }
    return PHC_OK;
}

/* ---- sigma, windows left out, covariates ----------------------------------- */

static int sigma_values(const phc_table *t, const phc_weight_curve_read_options *opt, const size_t *keep,
                        size_t n, double **sv, phc_error *err)
{
    int rc;
    if (!opt->sigma_column)
        return PHC_OK;
    if (phc_table_find(t, opt->sigma_column) < 0)
        return phc_unknown_column_at(WHERE("sigma"), "sigma", opt->sigma_column, t, err);
    if ((rc = phc_table_column_numbers_rows(t, opt->sigma_column, keep, n, sv, err)))
        return rc;
    for (size_t i = 0; i < n; ++i)
        if (!((*sv)[i] > 0))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': sigma must be positive, found %g",
                                 phc_table_source(t), phc_table_row_line(t, keep[i]), opt->sigma_column, (*sv)[i]);
    return PHC_OK;
}

/* skip[i] = 1 for the weighings inside an excluded window (time unit, from
 * the first weighing). */
static int exclusion(const phc_weight_curve_read_options *opt, const double *tv, size_t n, unsigned char *skip,
                     phc_error *err)
{
    for (size_t e = 0; e < opt->n_exclude; ++e)
        if (!(opt->exclude[2 * e] < opt->exclude[2 * e + 1])) {
            char key[64];
            snprintf(key, sizeof key, "exclude.%zu", e);
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s: key 'exclude': each window is [from, to] with from < to (time unit, from the first row)",
                                 WHERE(key));
        }
    for (size_t i = 0; i < n; ++i) {
        const double rel = tv[i] - tv[0];
        skip[i] = 0;
        for (size_t e = 0; e < opt->n_exclude && !skip[i]; ++e)
            skip[i] = rel >= opt->exclude[2 * e] && rel <= opt->exclude[2 * e + 1];
    }
    return PHC_OK;
}

/* The covariate columns at every weighing not skipped (NAN at the others),
 * n x J row-major. */
static int covariate_values(const phc_table *t, const phc_weight_curve_read_options *opt, const size_t *keep,
                            const unsigned char *skip, size_t n, storage *s, phc_error *err)
{
    const size_t J = opt->n_covariates;
    if (J == 0)
        return PHC_OK;
    s->cov = malloc((n ? n : 1) * J * sizeof *s->cov);
    s->cov_names = calloc(J, sizeof *s->cov_names);
    if (!s->cov || !s->cov_names)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    s->n_cov = J;
    for (size_t j = 0; j < J; ++j) {
        const char *name = opt->covariates[j];
        char key[64];
        snprintf(key, sizeof key, "covariates.columns.%zu", j);
        const long col = name ? phc_table_find(t, name) : -1;
        if (col < 0)
            return name ? phc_unknown_column_at(WHERE(key), "covariate column", name, t, err)
                        : phc_error_set(err, PHC_ERR_INPUT, "%s: covariates: expected a column name", WHERE(key));
        if (!(s->cov_names[j] = strdup(name)))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        for (size_t i = 0; i < n; ++i) {
            double *v = &s->cov[i * J + j];
            *v = NAN;
            if (skip[i])
                continue;
            const char *cell = phc_table_cell(t, keep[i], (size_t)col);
            char *end = NULL;
            *v = phc_strtod_c(cell, &end);
            if (!end || end == cell || *end || !isfinite(*v))
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%s:%zu: column '%s': a covariate needs a number at every kept "
                                     "weighing, found '%s'", phc_table_source(t),
                                     phc_table_row_line(t, keep[i]), name, cell);
        }
    }
    return PHC_OK;
}

/* ---- reading ---------------------------------------------------------------- */

/* The strings of the weighings, copied; the arrays' view. */
static int describe(const phc_table *t, const phc_weight_curve_read_options *opt, size_t n, storage *s,
                    phc_weighings *w, phc_error *err)
{
    const char *tunit = opt->timestamps ? "h" : opt->time_unit ? opt->time_unit : "s";
    if (!dup_string(tunit, &s->time_unit) || !dup_string(opt->mass_unit ? opt->mass_unit : "g", &s->mass_unit) ||
        !dup_string(opt->timezone, &s->timezone) || !dup_string(phc_table_source(t), &s->source) ||
        !dup_string(opt->time_column, &s->time_name) || !dup_string(opt->mass_column, &s->mass_name) ||
        !(s->lines = malloc((n ? n : 1) * sizeof *s->lines)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < n; ++i)
        s->lines[i] = phc_table_row_line(t, s->rows[i]);
    w->n = n;
    w->t = s->t;
    w->mass = s->mass;
    w->sigma = s->sigma;
    w->skip = s->skip;
    w->n_covariates = s->n_cov;
    w->covariate_names = (const char *const *)s->cov_names;
    w->covariates = s->cov;
    w->time_unit = s->time_unit;
    w->mass_unit = s->mass_unit;
    w->timezone = s->timezone;
    w->source = s->source;
    w->lines = s->lines;
    w->time_name = s->time_name;
    w->mass_name = s->mass_name;
    w->gap_s = s->gap_s;
    w->gap_line = s->gap_line;
    w->rows = s->rows;
    return PHC_OK;
}

/* Times and masses of the selected rows, without the tare readings; the
 * pauses of the logger. */
static int times_and_masses(const phc_table *table, const phc_weight_curve_read_options *opt, phc_units *units,
                            size_t *n, storage *s, phc_weighings *w, phc_error *err)
{
    double origin = NAN, max_gap;
    int rc;
    if ((rc = opt->timestamps ? stamp_times(table, opt, s->rows, *n, &s->t, &origin, err)
                              : numeric_times(table, opt, s->rows, *n, units, &s->t, &origin, err)) ||
        (rc = phc_table_column_numbers_rows(table, opt->mass_column, s->rows, *n, &s->mass, err)) ||
        (rc = gap_limit(opt, units, w->seconds_per_unit, &max_gap, err)))
        return rc;
    w->calendar = !isnan(origin);
    w->t0_posix = w->calendar ? origin : 0;
    if (opt->tare == PHC_WEIGHT_TARE_AUTO)
        drop_tare(table, s->rows, s->t, s->mass, n, w);
    return find_gaps(table, s->rows, s->t, *n, w->seconds_per_unit, max_gap, s, w, err);
}

int phc_weight_curve_read_table(const phc_table *table, const phc_weight_curve_read_options *opt,
                                phc_weighings *out, phc_error *err)
{
    phc_units *units = opt->units;
    storage *s = calloc(1, sizeof *s);
    size_t n = 0;
    int rc;
    *out = phc_weighings_default();
    if (!s)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if ((rc = check_time_options(opt, err)))
        goto fail;
    if (!units && !(units = phc_units_new(err))) {
        rc = err->status;
        goto fail;
    }
    if ((rc = unit_scales(opt, units, &out->seconds_per_unit, &out->grams_per_unit, err)))
        goto fail;
    if (phc_table_find(table, opt->time_column) < 0) {
        rc = phc_unknown_column_at(WHERE("time"), "time column", opt->time_column, table, err);
        goto fail;
    }
    if (phc_table_find(table, opt->mass_column) < 0) {
        rc = phc_unknown_column_at(WHERE("mass"), "mass column", opt->mass_column, table, err);
        goto fail;
    }
    if ((rc = phc_weight_curve_select_rows(table, opt, &s->rows, &n, err)) ||
        (rc = times_and_masses(table, opt, units, &n, s, out, err)) ||
        (rc = sigma_values(table, opt, s->rows, n, &s->sigma, err)))
        goto fail;
    if (!(s->skip = malloc(n ? n : 1))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if ((rc = exclusion(opt, s->t, n, s->skip, err)) ||
        (rc = covariate_values(table, opt, s->rows, s->skip, n, s, err)) ||
        (rc = describe(table, opt, n, s, out, err)))
        goto fail;
    out->storage = s;
    s = NULL;
fail:
    storage_free(s);
    if (units != opt->units)
        phc_units_free(units);
    if (rc)
        *out = phc_weighings_default();
    return rc;
}
