/* Calibration problems: see problem.h. */
#include "fit/problem.h"

#include <math.h>
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
    return pb;
}

void phc_problem_free(phc_problem *pb)
{
    if (!pb)
        return;
    for (size_t i = 0; i < pb->n_params; ++i) {
        free(pb->params[i].name);
        free(pb->params[i].unit);
    }
    free(pb->params);
    for (size_t i = 0; i < pb->n_datasets; ++i)
        phc_dataset_free(pb->datasets[i]);
    free(pb->datasets);
    free(pb->name);
    free(pb->source);
    free(pb);
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

double phc_problem_scale(const phc_problem *pb, size_t i)
{
    const phc_parameter *p = &pb->params[i];
    if (p->scale > 0)
        return p->scale;
    if (p->value != 0 && isfinite(p->value))
        return fabs(p->value);
    return 1.0;
}

int phc_problem_validate(const phc_problem *pb, phc_error *err)
{
    const char *src = pb->source ? pb->source : pb->name;
    if (pb->n_datasets == 0)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: no data sets to fit", src);
    size_t n_free = 0, n_obs = 0;
    for (size_t i = 0; i < pb->n_params; ++i) {
        const phc_parameter *p = &pb->params[i];
        if (!isfinite(p->value))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: parameter '%s': value is not finite", src, p->name);
        if (!(p->lower < p->upper) && !(p->fixed && p->lower <= p->upper))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s: parameter '%s': lower bound %g is not below upper bound %g",
                                 src, p->name, p->lower, p->upper);
        if (p->value < p->lower || p->value > p->upper)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s: parameter '%s': start value %g is outside its bounds [%g, %g]",
                                 src, p->name, p->value, p->lower, p->upper);
        if (p->scale < 0 || !isfinite(p->scale))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: parameter '%s': scale must be positive", src, p->name);
        int used = 0;
        for (size_t d = 0; d < pb->n_datasets && !used; ++d)
            for (size_t j = 0; j < pb->datasets[d]->k; ++j)
                if (pb->datasets[d]->param_index[j] == i)
                    used = 1;
        if (!used)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s: parameter '%s' is not used by any data set (remove it or bind it)",
                                 src, p->name);
        if (!p->fixed)
            ++n_free;
    }
    for (size_t d = 0; d < pb->n_datasets; ++d) {
        const phc_dataset *ds = pb->datasets[d];
        if (ds->n == 0)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: data set '%s' has no observations", src, ds->name);
        for (size_t i = 0; ds->sigma && i < ds->n; ++i)
            if (!(ds->sigma[i] > 0) || !isfinite(ds->sigma[i]))
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%s: data set '%s': sigma of observation %zu is %g; sigmas must be positive and finite",
                                     src, ds->name, i + 1, ds->sigma[i]);
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
