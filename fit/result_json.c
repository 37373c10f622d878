/* result.json writer and reader (jansson): see result_json.h. */
#include "fit/result_json.h"
#include "fit/engine/provenance.h"
#include "fit/json_file_internal.h"
#include "measurements/atomic_file.h"

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <errno.h>
#include <sys/stat.h>
#include <unistd.h>

static json_t *num(double v)
{
    return isfinite(v) ? json_real(v) : json_null();
}

static json_t *num_array(const double *v, size_t n)
{
    json_t *a = json_array();
    for (size_t i = 0; a && v && i < n; ++i)
        json_array_append_new(a, num(v[i]));
    return a;
}

static json_t *goodness_json(const phc_goodness *g)
{
    return json_pack("{s:I, s:I, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o}",
                     "n", (json_int_t)g->n, "k", (json_int_t)g->k, "rss", num(g->rss), "wrss", num(g->wrss),
                     "rmse", num(g->rmse), "mae", num(g->mae), "bias", num(g->bias), "r2", num(g->r2),
                     "nse", num(g->nse), "reduced_chi2", num(g->reduced_chi2), "log_likelihood",
                     num(g->log_likelihood), "aic", num(g->aic), "aicc", num(g->aicc), "bic", num(g->bic));
}

/* {"ids": [n series ids], "names": [...] or null, "title": "..." or null} */
static json_t *series_json(const phc_dataset_result *d)
{
    json_t *ids = json_array(), *names = d->series_names ? json_array() : json_null();
    for (size_t i = 0; ids && i < d->n; ++i)
        json_array_append_new(ids, json_integer((json_int_t)d->series[i]));
    for (size_t g = 0; names && d->series_names && g < d->n_series; ++g)
        json_array_append_new(names, json_string(d->series_names[g]));
    return json_pack("{s:o, s:o, s:o}", "ids", ids, "names", names, "title",
                     d->series_title ? json_string(d->series_title) : json_null());
}

static json_t *dataset_json(const phc_dataset_result *d)
{
    json_t *checks = json_object();
    for (size_t c = 0; c < PHC_CHECK_COUNT; ++c) {
        const phc_check_result *ck = &d->checks[c];
        json_object_set_new(checks, ck->name,
                            json_pack("{s:o, s:o, s:b, s:b, s:s}", "value", num(ck->statistic), "p_value",
                                      num(ck->p_value), "pass", ck->pass, "applicable", ck->applicable,
                                      "tests", ck->what));
    }
    json_t *o = json_pack("{s:s, s:s, s:I, s:o, s:o, s:o, s:o, s:o, s:s, s:s}", "name", d->name, "kind", d->kind,
                          "n", (json_int_t)d->n, "rss", num(d->goodness.rss), "rmse", num(d->goodness.rmse),
                          "r2", num(d->goodness.r2), "checks", checks, "goodness", goodness_json(&d->goodness),
                          "x_label", d->x_label, "y_label", d->y_label);
    json_object_set_new(o, "x", num_array(d->x, d->n));
    json_object_set_new(o, "y", num_array(d->y, d->n));
    json_object_set_new(o, "fitted", num_array(d->yhat, d->n));
    json_object_set_new(o, "residuals", num_array(d->residual, d->n));
    json_object_set_new(o, "standardised_residuals", num_array(d->std_residual, d->n));
    json_object_set_new(o, "sigma", d->sigma ? num_array(d->sigma, d->n) : json_null());
    json_object_set_new(o, "acf", num_array(d->acf, d->acf_lags ? d->acf_lags + 1 : 0));
    /* time series: what phc_fit_recheck needs (x_seconds, time_of_day) and
     * what the checks of time series found (recomputed on reading) */
    json_object_set_new(o, "x_seconds", num(d->x_seconds));
    json_object_set_new(o, "time_of_day", d->time_of_day ? num_array(d->time_of_day, d->n) : json_null());
    if (d->acf_time)
        json_object_set_new(o, "acf_time", json_pack("{s:o, s:o}", "bin_h", num(d->acf_time_bin_h), "acf",
                                                     num_array(d->acf_time, d->acf_time_bins)));
    if (d->checks[PHC_CHECK_DAILY_CYCLE].applicable)
        json_object_set_new(o, "periodogram",
                            json_pack("{s:o, s:o, s:o, s:o, s:o}", "daily_period_h", num(d->cycle_period_h),
                                      "daily_peak_clock_hour", num(d->cycle_peak_hour), "peak_period_h",
                                      num(d->peak_period_h), "peak_power", num(d->peak_power), "peak_fap",
                                      num(d->peak_fap)));
    if (d->extra_markdown)
        json_object_set_new(o, "extra_markdown", json_string(d->extra_markdown));
    if (d->values_json) { /* the kind's numbers: stored as JSON, not as a string */
        json_t *v = json_loads(d->values_json, JSON_DECODE_ANY, NULL);
        json_object_set_new(o, "values", v ? v : json_string(d->values_json));
    }
    if (d->series)
        json_object_set_new(o, "series", series_json(d));
    json_t *bl = json_array();
    for (size_t b = 0; b < d->n_baselines; ++b)
        json_array_append_new(bl, json_pack("{s:s, s:s, s:o}", "name", d->baselines[b].name, "description",
                                            d->baselines[b].what, "goodness", goodness_json(&d->baselines[b].goodness)));
    json_object_set_new(o, "baselines", bl);
    return o;
}

static json_t *result_json(const phc_fit_result *res)
{
    json_t *root = json_object();
    json_object_set_new(root, "name", json_string(res->name));
    if (res->provenance)
        json_object_set_new(root, "provenance", phc_provenance_to_json(res->provenance));
    json_object_set_new(root, "status", json_string(phc_fit_status_name(res->summary.outcome)));
    json_object_set_new(root, "identifiable", json_boolean(res->rank >= res->n_free));
    json_object_set_new(root, "termination", json_string(res->summary.termination));
    json_object_set_new(root, "iterations", json_integer(res->summary.iterations));
    json_object_set_new(root, "initial_cost", num(res->summary.initial_cost));
    json_object_set_new(root, "cost", num(res->cost));
    json_object_set_new(root, "rss", num(res->rss));
    json_object_set_new(root, "weighted_rss", num(res->wrss));
    json_object_set_new(root, "dof", json_integer(res->dof));
    json_object_set_new(root, "n_observations", json_integer((json_int_t)res->n_obs));
    json_object_set_new(root, "variance_factor", num(res->s2));
    json_object_set_new(root, "absolute_sigma", json_boolean(res->absolute_sigma));
    json_object_set_new(root, "level", num(res->level));
    json_object_set_new(root, "collinearity_threshold", num(res->collinearity_threshold));
    json_object_set_new(root, "correlation_threshold", num(res->correlation_threshold));
    json_object_set_new(root, "solver",
                        json_pack("{s:I, s:I, s:I, s:o, s:o, s:I, s:I, s:I}", "residual_evaluations",
                                  (json_int_t)res->summary.residual_evaluations, "jacobian_evaluations",
                                  (json_int_t)res->summary.jacobian_evaluations, "iterations",
                                  (json_int_t)res->summary.iterations, "wall_time_best_start",
                                  num(res->summary.wall_time), "wall_time_total", num(res->total_time),
                                  "starts", (json_int_t)res->starts, "starts_at_best",
                                  (json_int_t)res->starts_at_best, "rescue_starts", (json_int_t)res->rescue_starts));
    json_object_set_new(json_object_get(root, "solver"), "rescue_stopped", json_boolean(res->rescue_stopped));
    json_t *params = json_object();
    for (size_t i = 0; i < res->n_params; ++i) {
        const phc_param_result *p = &res->params[i];
        json_t *ci = json_pack("[o, o]", num(p->ci_lo), num(p->ci_hi));
        json_object_set_new(params, p->name,
                            json_pack("{s:o, s:o, s:o, s:b, s:b, s:i, s:o, s:o, s:o, s:o}", "value", num(p->value),
                                      "stderr", num(p->stderr_), "ci95", ci, "fixed", p->fixed, "at_bound",
                                      p->at_bound != 0, "bound_side", p->at_bound, "unit",
                                      p->unit ? json_string(p->unit) : json_null(), "start", num(p->start),
                                      "sensitivity_l1", num(p->sens_l1), "sensitivity_l2", num(p->sens_l2)));
        json_object_set_new(json_object_get(params, p->name), "bounds",
                            json_pack("[o, o]", isfinite(p->lower) ? num(p->lower) : json_null(),
                                      isfinite(p->upper) ? num(p->upper) : json_null()));
        if (p->unit_scale != 1.0 || p->unit_offset != 0.0) /* value is in the user's unit */
            json_object_set_new(json_object_get(params, p->name), "to_model_unit",
                                json_pack("{s:o, s:o}", "scale", num(p->unit_scale), "offset",
                                          num(p->unit_offset)));
    }
    json_object_set_new(root, "parameters", params);
    json_t *names = json_array(), *matrix = json_array();
    for (size_t a = 0; a < res->n_free; ++a) {
        json_array_append_new(names, json_string(res->params[res->free_index[a]].name));
        json_array_append_new(matrix, num_array(res->correlation + a * res->n_free, res->n_free));
    }
    json_object_set_new(root, "correlation", json_pack("{s:o, s:o}", "names", names, "matrix", matrix));
    json_t *und = json_array();
    for (size_t i = 0; i < res->n_undetermined; ++i)
        json_array_append_new(und, json_string(res->undetermined[i]));
    json_object_set_new(root, "identifiability",
                        json_pack("{s:I, s:o, s:o}", "rank", (json_int_t)res->rank, "condition_number",
                                  num(res->condition), "undetermined", und));
    json_t *sets = json_array();
    const phc_sensitivity *s = &res->sensitivity;
    for (size_t i = 0; i < s->n_sets && i < 200; ++i) {
        json_t *members = json_array();
        for (size_t a = 0; a < s->sets[i].size; ++a)
            json_array_append_new(members, json_string(res->params[res->free_index[s->sets[i].index[a]]].name));
        json_array_append_new(sets, json_pack("{s:o, s:o}", "parameters", members, "index", num(s->sets[i].gamma)));
    }
    json_t *maxg = json_object();
    for (size_t k = 2; k <= s->max_size; ++k) {
        char key[8];
        snprintf(key, sizeof key, "%zu", k);
        json_object_set_new(maxg, key, num(s->max_gamma[k]));
    }
    json_object_set_new(root, "collinearity",
                        json_pack("{s:I, s:o, s:o}", "subsets_evaluated", (json_int_t)s->n_sets, "max_by_size", maxg,
                                  "largest", sets));
    json_t *ds = json_array();
    for (size_t d = 0; d < res->n_datasets; ++d)
        json_array_append_new(ds, dataset_json(&res->datasets[d]));
    json_object_set_new(root, "datasets", ds);
    json_t *warn = json_array();
    for (size_t i = 0; i < res->n_warnings; ++i)
        json_array_append_new(warn, json_string(res->warnings[i]));
    json_object_set_new(root, "verdict",
                        json_pack("{s:s, s:o}", "summary", res->n_warnings ? "check the warnings" : "no problems found",
                                  "warnings", warn));
    return root;
}

int phc_result_write_json(const phc_fit_result *res, const char *path, phc_error *err)
{
    json_t *root = result_json(res);
    if (!root)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory building result.json");
    int rc = phc_json_file_write(root, path, err);
    json_decref(root);
    return rc;
}

/* ---- reading --------------------------------------------------------------- */

typedef struct reader {
    const char *path;
    phc_error *err;
} reader;

static int fail_field(reader *rd, const char *field, const char *expected)
{
    return phc_error_set(rd->err, PHC_ERR_INPUT, "%s: %s: expected %s", rd->path, field, expected);
}

static int get_number(reader *rd, json_t *obj, const char *key, const char *where, double *out)
{
    json_t *v = json_object_get(obj, key);
    char field[128];
    snprintf(field, sizeof field, "%s%s", where, key);
    if (v && json_is_null(v)) {
        *out = NAN;
        return PHC_OK;
    }
    if (!v || !json_is_number(v))
        return fail_field(rd, field, "a number");
    *out = json_number_value(v);
    return PHC_OK;
}

static int get_array(reader *rd, json_t *obj, const char *key, const char *where, size_t n, double **out)
{
    json_t *a = json_object_get(obj, key);
    char field[128], expected[64];
    snprintf(field, sizeof field, "%s%s", where, key);
    snprintf(expected, sizeof expected, "an array of %zu numbers", n);
    if (!a || !json_is_array(a) || json_array_size(a) != n)
        return fail_field(rd, field, expected);
    *out = calloc(n ? n : 1, sizeof **out);
    if (!*out)
        return phc_error_set(rd->err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < n; ++i) {
        json_t *v = json_array_get(a, i);
        if (json_is_null(v))
            (*out)[i] = NAN;
        else if (json_is_number(v))
            (*out)[i] = json_number_value(v);
        else
            return fail_field(rd, field, expected);
    }
    return PHC_OK;
}

static int get_string(reader *rd, json_t *obj, const char *key, const char *where, char **out)
{
    json_t *v = json_object_get(obj, key);
    char field[128];
    snprintf(field, sizeof field, "%s%s", where, key);
    if (!v || !json_is_string(v))
        return fail_field(rd, field, "a string");
    *out = strdup(json_string_value(v));
    return *out ? PHC_OK : phc_error_set(rd->err, PHC_ERR_NOMEM, "out of memory");
}

/* The optional "series" object of a data set (written by series_json). */
static int read_series(reader *rd, json_t *o, const char *where, phc_dataset_result *d)
{
    char field[128];
    json_t *ids = json_object_get(o, "ids"), *names = json_object_get(o, "names"),
           *title = json_object_get(o, "title");
    snprintf(field, sizeof field, "%sseries", where);
    if (!json_is_object(o) || !json_is_array(ids) || json_array_size(ids) != d->n ||
        (names && !json_is_null(names) && !json_is_array(names)) || (title && !json_is_null(title) && !json_is_string(title)))
        return fail_field(rd, field, "{ids: [one integer per observation], names: [strings] or null, title: a string "
                          "or null}");
    if (!(d->series = malloc(d->n * sizeof *d->series)))
        return phc_error_set(rd->err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < d->n; ++i) {
        json_t *v = json_array_get(ids, i);
        if (!json_is_integer(v) || json_integer_value(v) < 0 || json_integer_value(v) >= (json_int_t)1 << 40)
            return fail_field(rd, field, "ids that are integers >= 0");
        d->series[i] = (size_t)json_integer_value(v);
        if (d->series[i] >= d->n_series)
            d->n_series = d->series[i] + 1;
    }
    if (json_is_array(names)) {
        if (json_array_size(names) < d->n_series)
            return fail_field(rd, field, "a name for every series id");
        d->n_series = json_array_size(names);
        if (!(d->series_names = calloc(d->n_series, sizeof *d->series_names)))
            return phc_error_set(rd->err, PHC_ERR_NOMEM, "out of memory");
        for (size_t g = 0; g < d->n_series; ++g) {
            const char *nm = json_string_value(json_array_get(names, g));
            if (!nm)
                return fail_field(rd, field, "names that are strings");
            if (!(d->series_names[g] = strdup(nm)))
                return phc_error_set(rd->err, PHC_ERR_NOMEM, "out of memory");
        }
    }
    if (json_is_string(title) && !(d->series_title = strdup(json_string_value(title))))
        return phc_error_set(rd->err, PHC_ERR_NOMEM, "out of memory");
    return PHC_OK;
}

/* A goodness object (goodness_json) into *g; n observations. */
static int read_goodness(reader *rd, json_t *g, const char *where, size_t n, phc_goodness *out)
{
    if (!json_is_object(g))
        return fail_field(rd, where, "an object");
    char prefix[96];
    snprintf(prefix, sizeof prefix, "%s.", where);
    struct {
        const char *key;
        double *dst;
    } fields[] = {{"rss", &out->rss},   {"wrss", &out->wrss},
                  {"rmse", &out->rmse}, {"mae", &out->mae},
                  {"bias", &out->bias}, {"r2", &out->r2},
                  {"nse", &out->nse},   {"reduced_chi2", &out->reduced_chi2},
                  {"aic", &out->aic},   {"aicc", &out->aicc},
                  {"bic", &out->bic},   {"log_likelihood", &out->log_likelihood}};
    int rc;
    for (size_t i = 0; i < sizeof fields / sizeof fields[0]; ++i)
        if ((rc = get_number(rd, g, fields[i].key, prefix, fields[i].dst)))
            return rc;
    out->n = n;
    json_t *k = json_object_get(g, "k");
    out->k = json_is_integer(k) ? (size_t)json_integer_value(k) : 0;
    return PHC_OK;
}

static int read_dataset(reader *rd, json_t *o, size_t index, phc_dataset_result *d)
{
    char where[64];
    snprintf(where, sizeof where, "datasets[%zu].", index);
    int rc;
    json_t *n = json_object_get(o, "n");
    if (!json_is_integer(n) || json_integer_value(n) < 1)
        return fail_field(rd, "datasets[].n", "a positive integer");
    d->n = (size_t)json_integer_value(n);
    if ((rc = get_string(rd, o, "name", where, &d->name)) || (rc = get_string(rd, o, "kind", where, &d->kind)) ||
        (rc = get_string(rd, o, "x_label", where, &d->x_label)) ||
        (rc = get_string(rd, o, "y_label", where, &d->y_label)) ||
        (rc = get_array(rd, o, "x", where, d->n, &d->x)) || (rc = get_array(rd, o, "y", where, d->n, &d->y)) ||
        (rc = get_array(rd, o, "fitted", where, d->n, &d->yhat)) ||
        (rc = get_array(rd, o, "residuals", where, d->n, &d->residual)) ||
        (rc = get_array(rd, o, "standardised_residuals", where, d->n, &d->std_residual)))
        return rc;
    json_t *sig = json_object_get(o, "sigma");
    if (sig && !json_is_null(sig) && (rc = get_array(rd, o, "sigma", where, d->n, &d->sigma)))
        return rc;
    /* optional (results written before the daily-cycle checks have neither) */
    json_t *xs = json_object_get(o, "x_seconds");
    if (xs && !json_is_null(xs)) {
        if ((rc = get_number(rd, o, "x_seconds", where, &d->x_seconds)))
            return rc;
        if (!(d->x_seconds >= 0))
            return fail_field(rd, "datasets[].x_seconds", "a number >= 0");
    }
    json_t *tod = json_object_get(o, "time_of_day");
    if (tod && !json_is_null(tod) && (rc = get_array(rd, o, "time_of_day", where, d->n, &d->time_of_day)))
        return rc;
    json_t *values = json_object_get(o, "values");
    if (values && !json_is_null(values) &&
        !(d->values_json = json_dumps(values, JSON_COMPACT | JSON_REAL_PRECISION(17) | JSON_ENCODE_ANY)))
        return phc_error_set(rd->err, PHC_ERR_NOMEM, "out of memory");
    json_t *extra = json_object_get(o, "extra_markdown");
    if (extra && (rc = get_string(rd, o, "extra_markdown", where, &d->extra_markdown)))
        return rc;
    json_t *series = json_object_get(o, "series");
    if (series && !json_is_null(series) && (rc = read_series(rd, series, where, d)))
        return rc;
    if ((rc = read_goodness(rd, json_object_get(o, "goodness"), "datasets[].goodness", d->n, &d->goodness)))
        return rc;
    d->k = d->goodness.k;
    /* optional (results written before the baselines have none) */
    json_t *bl = json_object_get(o, "baselines");
    for (size_t b = 0; json_is_array(bl) && b < json_array_size(bl) && b < PHC_MAX_BASELINES; ++b) {
        json_t *e = json_array_get(bl, b);
        const char *nm = json_string_value(json_object_get(e, "name"));
        const char *what = json_string_value(json_object_get(e, "description"));
        if (!nm || !what)
            return fail_field(rd, "datasets[].baselines[]", "{name, description, goodness}");
        phc_baseline *x = &d->baselines[d->n_baselines];
        snprintf(x->name, sizeof x->name, "%s", nm);
        snprintf(x->what, sizeof x->what, "%s", what);
        if ((rc = read_goodness(rd, json_object_get(e, "goodness"), "datasets[].baselines[].goodness", d->n,
                                &x->goodness)))
            return rc;
        d->n_baselines++;
    }
    /* The stored Durbin–Watson p-value is kept (its exact moments need the
     * Jacobian); everything else is recomputed by phc_fit_recheck. */
    json_t *checks = json_object_get(o, "checks");
    json_t *dw = json_object_get(checks, "durbin_watson");
    d->checks[PHC_CHECK_DURBIN_WATSON].applicable = 0;
    if (json_is_object(dw)) {
        double p = NAN;
        if ((rc = get_number(rd, dw, "p_value", "datasets[].checks.durbin_watson.", &p)))
            return rc;
        d->checks[PHC_CHECK_DURBIN_WATSON].p_value = p;
        d->checks[PHC_CHECK_DURBIN_WATSON].applicable = isfinite(p);
    }
    return PHC_OK;
}

int phc_result_read_json(const char *path, phc_fit_result **out, phc_error *err)
{
    json_error_t jerr;
    struct stat st;
    *out = NULL;
    if (stat(path, &st) != 0)
        return phc_error_set(err, PHC_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    if (S_ISDIR(st.st_mode))
        return phc_error_set(err, PHC_ERR_IO, "%s: is a directory; give the result.json inside it", path);
    json_t *root = json_load_file(path, 0, &jerr);
    if (!root) {
        if (jerr.line < 0)
            return phc_error_set(err, PHC_ERR_IO, "%s: %s", path, jerr.text);
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%d:%d: invalid JSON: %s", path, jerr.line, jerr.column,
                             jerr.text);
    }
    reader rd = {path, err};
    int rc = PHC_OK;
    phc_fit_result *res = calloc(1, sizeof *res);
    if (!res) {
        json_decref(root);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    if (!json_is_object(root)) {
        rc = fail_field(&rd, "(top level)", "an object");
        goto fail;
    }
    char *status = NULL, *termination = NULL;
    if ((rc = get_string(&rd, root, "name", "", &res->name)) ||
        (rc = get_string(&rd, root, "status", "", &status)) ||
        (rc = get_string(&rd, root, "termination", "", &termination)))
        goto fail_strings;
    res->summary.outcome = strcmp(status, "converged") == 0       ? PHC_NLS_CONVERGED
                           : strcmp(status, "not_converged") == 0 ? PHC_NLS_NOT_CONVERGED
                                                                  : PHC_NLS_FAILED;
    snprintf(res->summary.termination, sizeof res->summary.termination, "%s", termination);
    double level = 0.05, dof = 0;
    if ((rc = get_number(&rd, root, "cost", "", &res->cost)) || (rc = get_number(&rd, root, "rss", "", &res->rss)) ||
        (rc = get_number(&rd, root, "weighted_rss", "", &res->wrss)) ||
        (rc = get_number(&rd, root, "variance_factor", "", &res->s2)) ||
        (rc = get_number(&rd, root, "level", "", &level)) || (rc = get_number(&rd, root, "dof", "", &dof)) ||
        (rc = get_number(&rd, root, "collinearity_threshold", "", &res->collinearity_threshold)) ||
        (rc = get_number(&rd, root, "correlation_threshold", "", &res->correlation_threshold)))
        goto fail_strings;
    res->dof = (long)dof;
    res->level = level;
    json_t *it = json_object_get(root, "iterations");
    res->summary.iterations = json_is_integer(it) ? (int)json_integer_value(it) : 0;
    json_t *prov = json_object_get(root, "provenance");
    if (prov && (rc = phc_provenance_from_json(prov, path, &res->provenance, err)))
        goto fail_strings;

    json_t *params = json_object_get(root, "parameters");
    if (!json_is_object(params) || json_object_size(params) == 0) {
        rc = fail_field(&rd, "parameters", "a non-empty object");
        goto fail_strings;
    }
    res->n_params = json_object_size(params);
    res->params = calloc(res->n_params, sizeof *res->params);
    res->free_index = calloc(res->n_params, sizeof *res->free_index);
    if (!res->params || !res->free_index) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail_strings;
    }
    const char *key;
    json_t *pv;
    size_t i = 0;
    json_object_foreach(params, key, pv)
    {
        phc_param_result *p = &res->params[i++];
        char where[160];
        snprintf(where, sizeof where, "parameters.%s.", key);
        if (!(p->name = strdup(key))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail_strings;
        }
        json_t *ci = json_object_get(pv, "ci95");
        if (!json_is_object(pv) || !json_is_array(ci) || json_array_size(ci) != 2) {
            rc = fail_field(&rd, where, "an object with value, stderr, ci95 [lo, hi]");
            goto fail_strings;
        }
        if ((rc = get_number(&rd, pv, "value", where, &p->value)) ||
            (rc = get_number(&rd, pv, "stderr", where, &p->stderr_)) ||
            (rc = get_number(&rd, pv, "start", where, &p->start)) ||
            (rc = get_number(&rd, pv, "sensitivity_l1", where, &p->sens_l1)) ||
            (rc = get_number(&rd, pv, "sensitivity_l2", where, &p->sens_l2)))
            goto fail_strings;
        json_t *lo = json_array_get(ci, 0), *hi = json_array_get(ci, 1);
        p->ci_lo = json_is_number(lo) ? json_number_value(lo) : NAN;
        p->ci_hi = json_is_number(hi) ? json_number_value(hi) : NAN;
        p->fixed = json_is_true(json_object_get(pv, "fixed"));
        json_t *side = json_object_get(pv, "bound_side");
        p->at_bound = json_is_integer(side) ? (int)json_integer_value(side) : 0;
        json_t *bounds = json_object_get(pv, "bounds"); /* optional: older results have none */
        json_t *blo = json_array_get(bounds, 0), *bhi = json_array_get(bounds, 1);
        p->lower = json_is_number(blo) ? json_number_value(blo) : -INFINITY;
        p->upper = json_is_number(bhi) ? json_number_value(bhi) : INFINITY;
        p->unit_scale = 1.0; /* model unit = value's unit, unless stored */
        p->unit_offset = 0.0;
        json_t *to_model = json_object_get(pv, "to_model_unit");
        if (json_is_object(to_model)) {
            json_t *sc = json_object_get(to_model, "scale"), *of = json_object_get(to_model, "offset");
            if (json_is_number(sc) && json_is_number(of) && json_number_value(sc) != 0) {
                p->unit_scale = json_number_value(sc);
                p->unit_offset = json_number_value(of);
            }
        }
        json_t *unit = json_object_get(pv, "unit");
        if (json_is_string(unit) && !(p->unit = strdup(json_string_value(unit)))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail_strings;
        }
    }
    /* correlation over the free parameters, in the stored name order */
    json_t *corr = json_object_get(root, "correlation");
    json_t *names = json_object_get(corr, "names"), *matrix = json_object_get(corr, "matrix");
    if (!json_is_array(names) || !json_is_array(matrix) || json_array_size(names) != json_array_size(matrix)) {
        rc = fail_field(&rd, "correlation", "{names: [...], matrix: [[...]]} of equal sizes");
        goto fail_strings;
    }
    res->n_free = json_array_size(names);
    if (res->n_free > res->n_params) {
        rc = fail_field(&rd, "correlation.names", "at most as many names as parameters");
        goto fail_strings;
    }
    res->correlation = calloc(res->n_free * res->n_free + 1, sizeof *res->correlation);
    if (!res->correlation) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail_strings;
    }
    for (size_t a = 0; a < res->n_free; ++a) {
        const char *nm = json_string_value(json_array_get(names, a));
        size_t found = res->n_params;
        for (size_t j = 0; nm && j < res->n_params; ++j)
            if (strcmp(res->params[j].name, nm) == 0)
                found = j;
        json_t *row = json_array_get(matrix, a);
        if (found == res->n_params || !json_is_array(row) || json_array_size(row) != res->n_free) {
            rc = fail_field(&rd, "correlation", "names of parameters and a square matrix");
            goto fail_strings;
        }
        res->free_index[a] = found;
        for (size_t b = 0; b < res->n_free; ++b) {
            json_t *v = json_array_get(row, b);
            res->correlation[a * res->n_free + b] = json_is_number(v) ? json_number_value(v) : NAN;
        }
    }
    json_t *ident = json_object_get(root, "identifiability");
    json_t *und = json_object_get(ident, "undetermined");
    if (json_is_array(und) && json_array_size(und)) {
        res->undetermined = calloc(json_array_size(und), sizeof *res->undetermined);
        if (!res->undetermined) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail_strings;
        }
        for (size_t u = 0; u < json_array_size(und); ++u) {
            const char *s = json_string_value(json_array_get(und, u));
            res->undetermined[res->n_undetermined++] = strdup(s ? s : "?");
        }
    }
    json_t *rank = json_object_get(ident, "rank");
    res->rank = json_is_integer(rank) ? (size_t)json_integer_value(rank) : res->n_free;
    /* largest collinear subsets, as stored */
    json_t *largest = json_object_get(json_object_get(root, "collinearity"), "largest");
    if (json_is_array(largest) && json_array_size(largest)) {
        phc_sensitivity *s = &res->sensitivity;
        s->sets = calloc(json_array_size(largest), sizeof *s->sets);
        if (!s->sets) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail_strings;
        }
        for (size_t k = 0; k < json_array_size(largest); ++k) {
            json_t *e = json_array_get(largest, k);
            json_t *members = json_object_get(e, "parameters");
            json_t *g = json_object_get(e, "index");
            phc_collinear_set *set = &s->sets[s->n_sets];
            if (!json_is_array(members) || json_array_size(members) > PHC_COLLIN_MAX_SIZE)
                continue;
            set->size = json_array_size(members);
            set->gamma = json_is_number(g) ? json_number_value(g) : INFINITY;
            int ok = 1;
            for (size_t a = 0; a < set->size && ok; ++a) {
                const char *nm = json_string_value(json_array_get(members, a));
                ok = 0;
                for (size_t f = 0; nm && f < res->n_free; ++f)
                    if (strcmp(res->params[res->free_index[f]].name, nm) == 0) {
                        set->index[a] = f;
                        ok = 1;
                    }
            }
            if (ok)
                s->n_sets++;
        }
    }
    json_t *ds = json_object_get(root, "datasets");
    if (!json_is_array(ds) || json_array_size(ds) == 0) {
        rc = fail_field(&rd, "datasets", "a non-empty array");
        goto fail_strings;
    }
    res->n_datasets = json_array_size(ds);
    res->datasets = calloc(res->n_datasets, sizeof *res->datasets);
    if (!res->datasets) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail_strings;
    }
    for (size_t d = 0; d < res->n_datasets; ++d) {
        if (!json_is_object(json_array_get(ds, d))) {
            rc = fail_field(&rd, "datasets[]", "objects");
            goto fail_strings;
        }
        if ((rc = read_dataset(&rd, json_array_get(ds, d), d, &res->datasets[d])))
            goto fail_strings;
        res->n_obs += res->datasets[d].n;
    }
    if ((rc = phc_fit_recheck(res, level, err)))
        goto fail_strings;
    *out = res;
    res = NULL;
fail_strings:
    free(status);
    free(termination);
fail:
    phc_fit_result_free(res);
    json_decref(root);
    return rc;
}
