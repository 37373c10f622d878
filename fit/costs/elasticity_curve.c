/* `elasticity_curve` data sets: see elasticity_curve.h. */
#include "fit/costs/elasticity_curve.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/costs/source_file.h"
#include "measurements/table.h"
#include "model/elasticity.h"

static const char *const slot_base[PHC_ELASTICITY_NPARAMS] = {"kappa", "chi0", "e_min", "e_max"};

void phc_elasticity_impl_free(void *p)
{
    phc_elasticity_impl *e = p;
    if (!e)
        return;
    if (e->free_extra)
        e->free_extra(e->extra);
    free(e->block);
    free(e);
}

int phc_elasticity_predict(phc_dataset *ds, const double *p, double *yhat, double *jac)
{
    const phc_elasticity_impl *e = ds->impl;
    if (jac)
        memset(jac, 0, ds->n * ds->k * sizeof *jac);
    for (size_t i = 0; i < ds->n; ++i) {
        const size_t b = e->block[i];
        const double *q = p + PHC_ELASTICITY_NPARAMS * b;
        const phc_elasticity_params par = {q[0], q[1], q[2], q[3]};
        double g[PHC_ELASTICITY_NPARAMS];
        yhat[i] = phc_elasticity_eval(&par, ds->x[i], jac ? g : NULL, NULL);
        if (!isfinite(yhat[i]))
            return 1;
        if (jac)
            memcpy(jac + i * ds->k + PHC_ELASTICITY_NPARAMS * b, g, sizeof g);
    }
    return 0;
}

int phc_elasticity_predict_at(phc_dataset *ds, const double *p, const double *x, size_t m, double *y)
{
    const phc_elasticity_impl *e = ds->impl;
    if (e->n_blocks != 1)
        return 1; /* one curve per leaf: no single curve to draw */
    const phc_elasticity_params par = {p[0], p[1], p[2], p[3]};
    for (size_t i = 0; i < m; ++i)
        y[i] = phc_elasticity_eval(&par, x[i], NULL, NULL);
    return 0;
}

int phc_elasticity_dataset_new(const phc_dataset_ops *ops, size_t n, size_t n_blocks,
                               const char *const *suffixes, int rwc, phc_dataset **out, phc_error *err)
{
    /* units of kappa, chi0, e_min, e_max (model/elasticity.h) */
    const char *const unit[PHC_ELASTICITY_NPARAMS] = {rwc ? "1" : NULL, rwc ? "1" : NULL, "MPa", "MPa"};
    *out = NULL;
    phc_dataset *ds = phc_dataset_new(ops, PHC_ELASTICITY_NPARAMS * n_blocks);
    phc_elasticity_impl *e = calloc(1, sizeof *e);
    if (!ds || !e)
        goto nomem;
    ds->impl = e;
    e->n_blocks = n_blocks;
    ds->n = n;
    ds->derivatives = PHC_DERIV_ANALYTIC;
    if (!(e->block = calloc(n ? n : 1, sizeof *e->block)) || !(ds->x = calloc(n ? n : 1, sizeof *ds->x)) ||
        !(ds->y = calloc(n ? n : 1, sizeof *ds->y)) ||
        !(ds->data_lines = calloc(n ? n : 1, sizeof *ds->data_lines)))
        goto nomem;
    for (size_t b = 0; b < n_blocks; ++b)
        for (size_t j = 0; j < PHC_ELASTICITY_NPARAMS; ++j) {
            char name[256];
            if (suffixes)
                snprintf(name, sizeof name, "%s_%s", slot_base[j], suffixes[b]);
            else
                snprintf(name, sizeof name, "%s", slot_base[j]);
            if (!(ds->slot_names[PHC_ELASTICITY_NPARAMS * b + j] = strdup(name)) ||
                (unit[j] && phc_dataset_declare_unit(ds, name, unit[j])))
                goto nomem;
        }
    *out = ds;
    return PHC_OK;
nomem:
    if (!ds || ds->impl != e)
        phc_elasticity_impl_free(e);
    phc_dataset_free(ds);
    return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
}

const phc_dataset_ops phc_elasticity_curve_ops = {.kind = "elasticity_curve",
                                                  .predict = phc_elasticity_predict,
                                                  .predict_at = phc_elasticity_predict_at,
                                                  .free_impl = phc_elasticity_impl_free};

phc_elasticity_curve_options phc_elasticity_curve_options_default(void)
{
    phc_elasticity_curve_options o = {0};
    return o;
}

#define WHERE(key) phc_origin_key(opt->origin, "elasticity_curve", key).text

/* The options alone, before any data: what is required, and sigma. */
static int check_options(const phc_elasticity_curve_options *opt, phc_error *err)
{
    static const char *const names[] = {"water", "modulus"};
    const char *const given[] = {opt->water, opt->modulus};
    for (int i = 0; i < 2; ++i)
        if (!given[i] || !given[i][0])
            return phc_error_set(err, PHC_ERR_INPUT, "%s: key '%s' is required", WHERE(NULL), names[i]);
    if (opt->water_content != PHC_WATER_CONTENT_RWC && opt->water_content != PHC_WATER_CONTENT_ABSOLUTE)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'water_content': expected rwc or absolute%s",
                             WHERE("water_content"), opt->water_content ? "" : " (it is required)");
    if (opt->sigma_column && opt->sigma != 0)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'sigma': give a number or a column, not both",
                             WHERE("sigma"));
    if (!opt->sigma_column && !(opt->sigma >= 0 && isfinite(opt->sigma)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'sigma': expected a positive number (MPa), found %g",
                             WHERE("sigma"), opt->sigma);
    return PHC_OK;
}

/* A column named by option `key` that the table lacks. */
static int need_column(const phc_elasticity_curve_options *opt, const char *key, const char *name,
                       const phc_table *t, phc_error *err)
{
    if (phc_table_find(t, name) >= 0)
        return PHC_OK;
    char what[64];
    snprintf(what, sizeof what, "key '%s':", key);
    return phc_unknown_column_at(WHERE(key), what, name, t, err);
}

/* The water and modulus columns as numbers, the water contents checked
 * against what they are said to be; *wx and *my are malloc'd. */
static int read_columns(const phc_table *table, const phc_elasticity_curve_options *opt, double **wx,
                        double **my, phc_error *err)
{
    const char *path = phc_table_source(table), *water = opt->water;
    const int is_rwc = opt->water_content == PHC_WATER_CONTENT_RWC;
    int rc;
    if ((rc = need_column(opt, "water", water, table, err)) ||
        (rc = need_column(opt, "modulus", opt->modulus, table, err)) ||
        (rc = phc_table_column_numbers(table, water, wx, err)) ||
        (rc = phc_table_column_numbers(table, opt->modulus, my, err)))
        return rc;
    const double *w = *wx;
    for (size_t i = 0; i < phc_table_rows(table); ++i) {
        if (is_rwc && !(w[i] >= 0 && w[i] <= 1.5))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: column '%s': relative water content must be a fraction in [0, 1.5], found %g%s",
                                 path, phc_table_row_line(table, i), water, w[i],
                                 w[i] > 1.5 ? " (percent? divide by 100)" : "");
        if (!is_rwc && !(w[i] >= 0))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': water content must not be negative, found %g",
                                 path, phc_table_row_line(table, i), water, w[i]);
    }
    return PHC_OK;
}

/* ds->sigma from the options: a column (every value > 0), one number, or
 * none (unweighted). */
static int set_sigma(phc_dataset *ds, const phc_table *table, const phc_elasticity_curve_options *opt,
                     phc_error *err)
{
    const char *col = opt->sigma_column;
    int rc;
    if (col) {
        if (phc_table_find(table, col) < 0)
            return phc_unknown_column_at(WHERE("sigma"), "sigma", col, table, err);
        if ((rc = phc_table_column_numbers(table, col, &ds->sigma, err)))
            return rc;
        for (size_t i = 0; i < ds->n; ++i)
            if (!(ds->sigma[i] > 0))
                return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': sigma must be positive, found %g",
                                     phc_table_source(table), phc_table_row_line(table, i), col, ds->sigma[i]);
    } else if (opt->sigma > 0) {
        if (!(ds->sigma = malloc(ds->n * sizeof *ds->sigma)))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        for (size_t i = 0; i < ds->n; ++i)
            ds->sigma[i] = opt->sigma;
    }
    return PHC_OK;
}

int phc_elasticity_curve_new(const phc_table *table, const phc_elasticity_curve_options *opt,
                             phc_dataset **out, phc_error *err)
{
    phc_dataset *ds = NULL;
    double *wx = NULL, *my = NULL;
    int rc;
    *out = NULL;
    if (!table || !opt)
        return phc_error_set(err, PHC_ERR_INVALID, "elasticity_curve: a table and options are required");
    if ((rc = check_options(opt, err)))
        return rc;
    const char *path = phc_table_source(table);
    const size_t n = phc_table_rows(table);
    if (n == 0)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:1: no data rows below the header; expected at least one", path);
    if ((rc = read_columns(table, opt, &wx, &my, err)) ||
        (rc = phc_elasticity_dataset_new(&phc_elasticity_curve_ops, n, 1, NULL,
                                             opt->water_content == PHC_WATER_CONTENT_RWC, &ds, err)))
        goto fail;
    memcpy(ds->x, wx, n * sizeof *wx);
    memcpy(ds->y, my, n * sizeof *my);
    for (size_t i = 0; i < n; ++i)
        ds->data_lines[i] = phc_table_row_line(table, i);
    if ((rc = set_sigma(ds, table, opt, err)))
        goto fail;
    char xl[256];
    if (opt->water_content == PHC_WATER_CONTENT_RWC)
        snprintf(xl, sizeof xl, "relative water content (RWC)");
    else
        snprintf(xl, sizeof xl, "water content (%s)", opt->water);
    ds->x_label = strdup(opt->x_label ? opt->x_label : xl);
    ds->y_label = strdup(opt->y_label ? opt->y_label : "bulk modulus of elasticity (MPa)");
    ds->data_file = strdup(path);
    if (!ds->x_label || !ds->y_label || !ds->data_file) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    ds->config_line = phc_origin_line(opt->origin, NULL);
    *out = ds;
    ds = NULL;
    rc = PHC_OK;
fail:
    phc_dataset_free(ds);
    free(wx);
    free(my);
    return rc;
}
