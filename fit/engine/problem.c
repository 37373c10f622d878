/* Calibration problems: see problem.h. */
#include "fit/engine/problem.h"
#include "fit/engine/parameter_units.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

phc_fit_options phc_fit_options_default(void)
{
    phc_fit_options o;
    o.nls = phc_nls_options_default();
    o.starts = 1;
    o.rescue_starts = 16;
    o.absolute_sigma = 0;
    o.level = 0.05;
    o.collinearity_threshold = 20.0;
    o.correlation_threshold = 0.95;
    return o;
}

static char *dup_or_null(const char *s)
{
    return s ? strdup(s) : NULL;
}

phc_problem *phc_problem_new(const char *name)
{
    phc_problem *pb = calloc(1, sizeof *pb);
    if (!pb)
        return NULL;
    pb->name = dup_or_null(name ? name : "fit");
    if (!pb->name) {
        free(pb);
        return NULL;
    }
    pb->options = phc_fit_options_default();
    pb->series_points = PHC_SERIES_POINTS_DEFAULT;
    return pb;
}

void phc_problem_free(phc_problem *pb)
{
    if (!pb)
        return;
    for (size_t i = 0; i < pb->n_params; ++i) {
        free(pb->params[i].name);
        free(pb->params[i].unit);
        free(pb->params[i].slot_unit);
    }
    free(pb->params);
    for (size_t i = 0; i < pb->n_datasets; ++i)
        phc_dataset_free(pb->datasets[i]);
    free(pb->datasets);
    free(pb->name);
    free(pb->source);
    for (size_t i = 0; i < pb->n_seeds; ++i)
        free(pb->seeds[i]);
    free(pb->seeds);
    for (size_t i = 0; i < pb->n_groups; ++i) {
        free(pb->groups[i].name);
        free(pb->groups[i].members);
    }
    free(pb->groups);
    for (size_t i = 0; i < pb->n_outputs; ++i)
        free(pb->outputs[i].name);
    free(pb->outputs);
    free(pb);
}

/* A data set's name as studies print it: its own, or dataset-N. */
static void dataset_label(const phc_problem *pb, size_t d, char *buf, size_t size)
{
    if (pb->datasets[d]->name)
        snprintf(buf, size, "%s", pb->datasets[d]->name);
    else
        snprintf(buf, size, "dataset-%zu", d + 1);
}

int phc_problem_add_output(phc_problem *pb, const char *name, const char *dataset, double at, size_t observation,
                           size_t config_line, phc_error *err)
{
    char place[600];
    if (pb->source && config_line)
        snprintf(place, sizeof place, "%s:%zu: outputs: '%s'", pb->source, config_line, name ? name : "");
    else
        snprintf(place, sizeof place, "outputs: '%s'", name ? name : "");
    if (!name || !*name)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: an output needs a name", place);
    for (const char *c = name; *c; ++c)
        if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') || *c == '_' ||
              *c == '-' || *c == '.'))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: a name holds only letters, digits, '_', '-' and '.'",
                                 place);
    if (strcmp(name, "cost") == 0)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: 'cost' is the name of the study's cost output", place);
    for (size_t i = 0; i < pb->n_outputs; ++i)
        if (strcmp(pb->outputs[i].name, name) == 0)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: the name is used twice", place);
    for (size_t i = 0; i < pb->n_datasets; ++i) {
        char own[600];
        dataset_label(pb, i, own, sizeof own);
        const size_t len = strlen(own);
        if (strncmp(name, own, len) == 0 && (strcmp(name + len, ".mean") == 0 || strcmp(name + len, ".cost") == 0))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: a study names data set '%s''s own output so", place, own);
    }
    long d = -1;
    char label[512];
    for (size_t i = 0; i < pb->n_datasets && d < 0; ++i) {
        dataset_label(pb, i, label, sizeof label);
        if (dataset && strcmp(label, dataset) == 0)
            d = (long)i;
    }
    if (d < 0) {
        char *names = NULL;
        size_t len = 0;
        for (size_t i = 0; i < pb->n_datasets; ++i) {
            dataset_label(pb, i, label, sizeof label);
            len += strlen(label) + 2;
        }
        names = calloc(len + 1, 1);
        for (size_t i = 0; names && i < pb->n_datasets; ++i) {
            dataset_label(pb, i, label, sizeof label);
            strcat(names, i ? ", " : "");
            strcat(names, label);
        }
        const int rc = phc_error_set(err, PHC_ERR_INPUT, "%s: dataset: no data set is called '%s' (the data sets: "
                                     "%s)", place, dataset ? dataset : "", names ? names : "?");
        free(names);
        return rc;
    }
    const phc_dataset *ds = pb->datasets[d];
    if (observation) {
        if (observation > ds->n)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: observation: %zu is beyond the %zu observations of data "
                                 "set '%s'", place, observation, ds->n, dataset);
    } else {
        if (!isfinite(at))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: at: not a finite number", place);
        if (!ds->x || ds->n == 0)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: at: data set '%s' has no x axis; give observation: N",
                                 place, dataset);
        double lo = ds->x[0], hi = ds->x[0];
        int increasing = 1;
        for (size_t i = 1; i < ds->n; ++i) {
            lo = ds->x[i] < lo ? ds->x[i] : lo;
            hi = ds->x[i] > hi ? ds->x[i] : hi;
            increasing &= ds->x[i] >= ds->x[i - 1];
        }
        if (at < lo || at > hi)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: at: %.10g lies outside data set '%s''s x range [%.10g, "
                                 "%.10g]%s%s", place, at, dataset, lo, hi, ds->x_label ? " of " : "",
                                 ds->x_label ? ds->x_label : "");
        if (!ds->ops->predict_at && (!increasing || ds->n_series > 1))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: at: a %s data set cannot predict at any x and its "
                                 "observations are not one series in increasing x to interpolate; give "
                                 "observation: N", place, ds->ops->kind);
    }
    phc_named_output *grown = realloc(pb->outputs, (pb->n_outputs + 1) * sizeof *grown);
    if (!grown)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    pb->outputs = grown;
    phc_named_output *o = &pb->outputs[pb->n_outputs];
    if (!(o->name = strdup(name)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    o->dataset = (size_t)d;
    o->at = observation ? NAN : at;
    o->observation = observation;
    o->config_line = config_line;
    pb->n_outputs++;
    return PHC_OK;
}

long phc_problem_find_parameter(const phc_problem *pb, const char *name)
{
    for (size_t i = 0; i < pb->n_params; ++i)
        if (strcmp(pb->params[i].name, name) == 0)
            return (long)i;
    return -1;
}

int phc_problem_add_parameter(phc_problem *pb, const char *name, double value,
                              size_t *index, phc_error *err)
{
    if (phc_problem_find_parameter(pb, name) >= 0)
        return phc_error_set(err, PHC_ERR_INPUT, "parameter '%s' is defined twice", name);
    phc_parameter *grown = realloc(pb->params, (pb->n_params + 1) * sizeof *grown);
    if (!grown)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory adding parameter '%s'", name);
    pb->params = grown;
    phc_parameter *p = &pb->params[pb->n_params];
    memset(p, 0, sizeof *p);
    p->name = strdup(name);
    if (!p->name)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory adding parameter '%s'", name);
    p->value = value;
    p->lower = -INFINITY;
    p->upper = INFINITY;
    p->range_lo = p->range_hi = NAN;
    p->unit_scale = 1.0;
    if (index)
        *index = pb->n_params;
    pb->n_params++;
    return PHC_OK;
}

int phc_problem_add_dataset(phc_problem *pb, phc_dataset *ds, phc_error *err)
{
    /* the series (probes, leaves, ...) with their names, for the plots */
    const int rc = phc_dataset_describe_series(ds, err);
    if (rc) {
        phc_dataset_free(ds);
        return rc;
    }
    phc_dataset **grown = realloc(pb->datasets, (pb->n_datasets + 1) * sizeof *grown);
    if (!grown) {
        phc_dataset_free(ds);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory adding a data set");
    }
    pb->datasets = grown;
    pb->datasets[pb->n_datasets++] = ds;
    ds->problem = pb;
    return PHC_OK;
}

int phc_problem_bind_by_name(const phc_problem *pb, phc_dataset *ds, phc_error *err)
{
    for (size_t j = 0; j < ds->k; ++j)
        if (phc_problem_find_parameter(pb, ds->slot_names[j]) < 0)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "data set '%s' (%s): slot '%s' has no parameter of that name; "
                                 "add it with phc_problem_add_parameter first",
                                 ds->name ? ds->name : "?", ds->ops->kind, ds->slot_names[j]);
    for (size_t j = 0; j < ds->k; ++j)
        ds->param_index[j] = (size_t)phc_problem_find_parameter(pb, ds->slot_names[j]);
    return PHC_OK;
}

double phc_problem_scale(const phc_problem *pb, size_t i)
{
    const phc_parameter *p = &pb->params[i];
    if (p->scale > 0)
        return p->scale;
    if (p->value != 0 && isfinite(p->value))
        return fabs(p->value);
    return 1.0;
}

/* Where a parameter or data set was given: "cfg.yaml:4" when it came from
 * line 4 of a config, else the config (or the problem's name). */
static const char *place(const phc_problem *pb, size_t line, char *buf, size_t size)
{
    const char *src = pb->source ? pb->source : pb->name;
    if (pb->source && line > 0)
        snprintf(buf, size, "%s:%zu", src, line);
    else
        snprintf(buf, size, "%s", src);
    return buf;
}

/* A finite start value, bound or range end the fit can work with: within
 * +-PHC_PARAMETER_MAX, and so once divided by an explicit scale.  Infinite
 * values (open bounds, automatic ranges) pass. */
static int check_magnitude(const char *at, const phc_parameter *p, const char *what, double v, phc_error *err)
{
    if (!isfinite(v))
        return PHC_OK;
    if (fabs(v) > PHC_PARAMETER_MAX)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s: parameter '%s': %s %g is too large in magnitude: starts, bounds and ranges must be between "
                             "%g and %g, so that the search box built on them (up to 10 times the start, or "
                             "upper - lower) stays finite; express the parameter in a larger unit",
                             at, p->name, what, v, -PHC_PARAMETER_MAX, PHC_PARAMETER_MAX);
    if (p->scale > 0 && fabs(v) / p->scale > PHC_PARAMETER_MAX)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s: parameter '%s': %s %g divided by its scale %g is not below %g (the solver works "
                             "on value / scale); give a larger scale",
                             at, p->name, what, v, p->scale, PHC_PARAMETER_MAX);
    return PHC_OK;
}

int phc_problem_validate(const phc_problem *pb, phc_error *err)
{
    const char *src = pb->source ? pb->source : pb->name;
    char at[1024];
    int rc;
    if (pb->n_datasets == 0)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: no data sets to fit", src);
    size_t n_free = 0, n_obs = 0;
    for (size_t i = 0; i < pb->n_params; ++i) {
        const phc_parameter *p = &pb->params[i];
        place(pb, p->config_line, at, sizeof at);
        if (p->scale < 0 || !isfinite(p->scale))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: parameter '%s': scale must be positive and finite, found %g",
                                 at, p->name, p->scale);
        if (!isfinite(p->value))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: parameter '%s': start value %g is not finite", at, p->name,
                                 p->value);
        if ((rc = check_magnitude(at, p, "start value", p->value, err)) ||
            (rc = check_magnitude(at, p, "lower bound", p->lower, err)) ||
            (rc = check_magnitude(at, p, "upper bound", p->upper, err)) ||
            (rc = check_magnitude(at, p, "range start", p->range_lo, err)) ||
            (rc = check_magnitude(at, p, "range end", p->range_hi, err)))
            return rc;
        if (!(p->lower < p->upper) && !(p->fixed && p->lower <= p->upper))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s: parameter '%s': lower bound %g is not below upper bound %g",
                                 at, p->name, p->lower, p->upper);
        if (p->value < p->lower || p->value > p->upper)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s: parameter '%s': start value %g is outside its bounds [%g, %g]",
                                 at, p->name, p->value, p->lower, p->upper);
        int used = 0;
        for (size_t d = 0; d < pb->n_datasets && !used; ++d)
            for (size_t j = 0; j < pb->datasets[d]->k; ++j)
                if (pb->datasets[d]->param_index[j] == i)
                    used = 1;
        if (!used)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s: parameter '%s' is not used by any data set (remove it or bind it)",
                                 at, p->name);
        if (!p->fixed)
            ++n_free;
    }
    for (size_t d = 0; d < pb->n_datasets; ++d) {
        const phc_dataset *ds = pb->datasets[d];
        if (ds->n == 0)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: data set '%s' has no observations",
                                 place(pb, ds->config_line, at, sizeof at), ds->name);
        for (size_t i = 0; ds->sigma && i < ds->n; ++i)
            if (!(ds->sigma[i] > 0) || !isfinite(ds->sigma[i])) {
                if (ds->data_file && ds->data_lines)
                    snprintf(at, sizeof at, "%s:%zu", ds->data_file, ds->data_lines[i]);
                else
                    place(pb, ds->config_line, at, sizeof at);
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%s: data set '%s': sigma of observation %zu is %g; sigmas must be positive and finite",
                                     at, ds->name, i + 1, ds->sigma[i]);
            }
        n_obs += ds->n;
    }
    if (n_free == 0)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: every parameter is fixed; nothing to fit", src);
    if (n_obs < n_free)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s: %zu observations for %zu free parameters; need at least as many observations",
                             src, n_obs, n_free);
    if (pb->options.starts < 1)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: solver.starts must be at least 1", src);
    return PHC_OK;
}

int phc_problem_finish(phc_problem *pb, unsigned keep, phc_error *err)
{
    double model_tol = 0;
    int rc;
    if (!pb)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_problem_finish: no problem");
    if ((rc = phc_problem_convert_units(pb, err)))
        return rc;
    for (size_t d = 0; d < pb->n_datasets; ++d)
        model_tol = fmax(model_tol, pb->datasets[d]->model_tolerance);
    if (model_tol > 0) {
        if (!(keep & PHC_KEEP_FUNCTION_TOLERANCE))
            pb->options.nls.function_tolerance = fmax(pb->options.nls.function_tolerance, model_tol);
        if (!(keep & PHC_KEEP_GRADIENT_TOLERANCE))
            pb->options.nls.gradient_tolerance = fmax(pb->options.nls.gradient_tolerance, model_tol);
        if (!(keep & PHC_KEEP_PARAMETER_TOLERANCE))
            pb->options.nls.parameter_tolerance = fmax(pb->options.nls.parameter_tolerance, model_tol);
    }
    return phc_problem_validate(pb, err);
}
