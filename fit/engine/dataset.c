/* Data sets: see dataset.h. */
#include "fit/engine/dataset.h"

#include <math.h>
#include <string.h>
#include <stdlib.h>

/* 1 + the largest series id (0 without series). */
static size_t series_count(const phc_dataset *ds)
{
    size_t count = 0;
    for (size_t i = 0; ds->series && i < ds->n; ++i)
        if (ds->series[i] >= count)
            count = ds->series[i] + 1;
    return count;
}

static void free_series_names(phc_dataset *ds)
{
    for (size_t g = 0; ds->series_names && g < ds->n_series; ++g)
        free(ds->series_names[g]);
    free(ds->series_names);
    free(ds->series_title);
    ds->series_names = NULL;
    ds->series_title = NULL;
}

phc_dataset *phc_dataset_new(const phc_dataset_ops *ops, size_t k)
{
    phc_dataset *ds = calloc(1, sizeof *ds);
    if (!ds)
        return NULL;
    ds->ops = ops;
    ds->k = k;
    ds->derivatives = PHC_DERIV_CENTRAL;
    ds->loss = PHC_LOSS_NONE;
    ds->loss_scale = 1.0;
    if (k > 0) {
        ds->slot_names = calloc(k, sizeof *ds->slot_names);
        ds->slot_units = calloc(k, sizeof *ds->slot_units);
        ds->param_index = calloc(k, sizeof *ds->param_index);
        if (!ds->slot_names || !ds->slot_units || !ds->param_index) {
            phc_dataset_free(ds);
            return NULL;
        }
    }
    return ds;
}

void phc_dataset_free(phc_dataset *ds)
{
    if (!ds)
        return;
    if (ds->ops && ds->ops->free_impl)
        ds->ops->free_impl(ds->impl);
    if (ds->slot_names)
        for (size_t j = 0; j < ds->k; ++j)
            free(ds->slot_names[j]);
    free(ds->slot_names);
    if (ds->slot_units)
        for (size_t j = 0; j < ds->k; ++j)
            free(ds->slot_units[j]);
    free(ds->slot_units);
    free_series_names(ds);
    free(ds->series);
    free(ds->param_index);
    free(ds->name);
    free(ds->x);
    free(ds->y);
    free(ds->sigma);
    free(ds->data_file);
    free(ds->data_lines);
    free(ds->time_of_day);
    free(ds->x_label);
    free(ds->y_label);
    for (size_t i = 0; i < ds->n_inputs; ++i)
        free(ds->inputs[i]);
    free(ds->inputs);
    free(ds);
}

int phc_dataset_declare_unit(phc_dataset *ds, const char *slot, const char *unit)
{
    for (size_t j = 0; j < ds->k; ++j)
        if (ds->slot_names[j] && strcmp(ds->slot_names[j], slot) == 0) {
            char *copy = strdup(unit);
            if (!copy)
                return PHC_ERR_NOMEM;
            free(ds->slot_units[j]);
            ds->slot_units[j] = copy;
            return PHC_OK;
        }
    return PHC_ERR_INVALID;
}

int phc_dataset_add_input(phc_dataset *ds, const char *path)
{
    for (size_t i = 0; i < ds->n_inputs; ++i)
        if (strcmp(ds->inputs[i], path) == 0)
            return PHC_OK;
    char **grown = realloc(ds->inputs, (ds->n_inputs + 1) * sizeof *grown);
    if (!grown)
        return PHC_ERR_NOMEM;
    ds->inputs = grown;
    if (!(ds->inputs[ds->n_inputs] = strdup(path)))
        return PHC_ERR_NOMEM;
    ds->n_inputs++;
    return PHC_OK;
}

int phc_dataset_name_series(phc_dataset *ds, const char *title, size_t count, phc_series_name_fn name,
                            phc_error *err)
{
    const size_t need = series_count(ds);
    if (!ds->series || count < need)
        return phc_error_set(err, PHC_ERR_INVALID, "data set '%s': %zu series names for series ids up to %zu",
                             ds->name ? ds->name : "?", count, need ? need - 1 : 0);
    free_series_names(ds);
    ds->n_series = count;
    if (!(ds->series_names = calloc(count ? count : 1, sizeof *ds->series_names)) ||
        (title && !(ds->series_title = strdup(title))))
        goto nomem;
    for (size_t g = 0; g < count; ++g) {
        char buf[128];
        buf[0] = '\0';
        name(ds, g, buf, sizeof buf);
        if (!(ds->series_names[g] = strdup(buf)))
            goto nomem;
    }
    return PHC_OK;
nomem:
    free_series_names(ds);
    ds->n_series = need;
    return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
}

int phc_dataset_describe_series(phc_dataset *ds, phc_error *err)
{
    if (ds->ops && ds->ops->name_series) {
        const int rc = ds->ops->name_series(ds, err);
        if (rc)
            return rc;
    }
    if (!ds->series_names)
        ds->n_series = series_count(ds);
    return PHC_OK;
}

int phc_dataset_residuals(const double *p, double *r, double *jac, void *user_data)
{
    phc_dataset *ds = user_data;
    /* r holds yhat first, then is turned into residuals in place. */
    int rc = ds->ops->predict(ds, p, r, jac);
    if (rc)
        return rc;
    if (!ds->sigma) { /* weight 1: the same numbers as the loop below with w = 1 */
        for (size_t i = 0; i < ds->n; ++i)
            r[i] = ds->y[i] - r[i];
        if (jac)
            for (size_t t = 0; t < ds->n * ds->k; ++t)
                jac[t] = -jac[t];
        return 0;
    }
    for (size_t i = 0; i < ds->n; ++i) {
        const double w = 1.0 / ds->sigma[i];
        r[i] = (ds->y[i] - r[i]) * w;
        if (jac)
            for (size_t j = 0; j < ds->k; ++j)
                jac[i * ds->k + j] *= -w;
    }
    return 0;
}

int phc_dataset_check_start(phc_dataset *ds, const double *x, phc_error *err)
{
    double *p = calloc(ds->k ? ds->k : 1, sizeof *p), *yhat = calloc(ds->n ? ds->n : 1, sizeof *yhat);
    if (!p || !yhat) {
        free(p);
        free(yhat);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    for (size_t j = 0; j < ds->k; ++j)
        p[j] = x[ds->param_index[j]];
    const int rc = ds->ops->predict(ds, p, yhat, NULL);
    int status = PHC_OK;
    size_t bad = ds->n;
    for (size_t i = 0; i < ds->n && bad == ds->n; ++i)
        if (!isfinite(yhat[i]))
            bad = i;
    if (rc != 0 || bad < ds->n) {
        if (bad == ds->n) /* the model failed without saying where */
            bad = 0;
        const char *file = ds->data_file ? ds->data_file : "(data)";
        const size_t line = ds->data_lines ? ds->data_lines[bad] : bad + 1;
        status = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: data set '%s': the model is not finite at the start values "
                               "(%s = %g); change the start values or the data",
                               file, line, ds->name, ds->x_label ? ds->x_label : "x", ds->x ? ds->x[bad] : NAN);
    }
    free(p);
    free(yhat);
    return status;
}
