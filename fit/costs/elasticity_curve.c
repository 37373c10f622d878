/* `elasticity_curve` data sets: see elasticity_curve.h. */
#include "fit/costs/elasticity_curve.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/costs/source_file.h"
#include "fit/config/yaml_keys.h" /* until this kind is YAML-free */
#include "measurements/suggest.h"
#include "measurements/table.h"
#include "model/elasticity.h"

const char *const phc_elasticity_curve_keys[] = {"file", "water", "water_content", "modulus", "sigma",
                                                 "x_label", "y_label", NULL};
const phc_key_help phc_elasticity_curve_help[] = {
    {"file", "CSV table of the measurements, relative to the config file. Required."},
    {"water", "Column of water contents. Required."},
    {"water_content", "What the water column holds: rwc (relative water content as a fraction "
                      "0 to 1; values above 1.5 are refused as probably percent) or absolute "
                      "(water in any unit, >= 0; chi0 then has that unit and kappa its "
                      "inverse). Required."},
    {"modulus", "Column of bulk moduli of elasticity, MPa. Required."},
    {"sigma", "A positive number (MPa) or the name of a column of per-point sigmas. "
              "Default: unweighted."},
    {"x_label", "Axis label of the water content. Default: \"relative water content (RWC)\" "
                "or \"water content (COLUMN)\"."},
    {"y_label", "Axis label of the modulus. Default: \"bulk modulus of elasticity (MPa)\"."},
    {NULL, NULL}};

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
                               const char *const *suffixes, phc_dataset **out, phc_error *err)
{
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
            if (!(ds->slot_names[PHC_ELASTICITY_NPARAMS * b + j] = strdup(name)))
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

static const phc_dataset_ops elasticity_ops = {"elasticity_curve", phc_elasticity_predict,
                                               phc_elasticity_predict_at, phc_elasticity_impl_free, NULL, NULL, NULL,
                                               NULL};


int phc_elasticity_curve_load(const phc_yaml_doc *doc, const phc_yaml_node *node,
                              const char *base_dir, phc_is_parameter_fn is_parameter,
                              void *user_data, phc_dataset **out, phc_error *err)
{
    (void)is_parameter;
    (void)user_data;
    const char *ctx = "elasticity_curve data set";
    const char *file = NULL, *water = NULL, *content = NULL, *modulus = NULL;
    const char *x_label = NULL, *y_label = NULL;
    phc_table *table = NULL;
    phc_dataset *ds = NULL;
    double *wx = NULL, *my = NULL;
    char *path = NULL;
    int rc;
    *out = NULL;
    if ((rc = phc_yaml_map_string(doc, node, "file", 1, ctx, &file, err)) ||
        (rc = phc_yaml_map_string(doc, node, "water", 1, ctx, &water, err)) ||
        (rc = phc_yaml_map_string(doc, node, "water_content", 1, ctx, &content, err)) ||
        (rc = phc_yaml_map_string(doc, node, "modulus", 1, ctx, &modulus, err)) ||
        (rc = phc_yaml_map_string(doc, node, "x_label", 0, ctx, &x_label, err)) ||
        (rc = phc_yaml_map_string(doc, node, "y_label", 0, ctx, &y_label, err)))
        return rc;
    int is_rwc;
    if (strcmp(content, "rwc") == 0)
        is_rwc = 1;
    else if (strcmp(content, "absolute") == 0)
        is_rwc = 0;
    else
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'water_content': expected rwc or absolute, found '%s'",
                             doc->path, phc_key_line(node, "water_content"), content);
    if (!(path = phc_join_path(base_dir, file)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if ((rc = phc_table_read(path, &table, err))) {
        if (rc == PHC_ERR_IO) /* a file that cannot be read: which key named it */
            phc_error_prefix(err, rc, "%s:%zu: key 'file'", doc->path, phc_key_line(node, "file"));
        goto fail;
    }
    const size_t n = phc_table_rows(table);
    if (n == 0) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:1: no data rows below the header; expected at least one", path);
        goto fail;
    }
    if ((rc = phc_need_column(doc, node, "water", water, table, err)) ||
        (rc = phc_need_column(doc, node, "modulus", modulus, table, err)) ||
        (rc = phc_table_column_numbers(table, water, &wx, err)) ||
        (rc = phc_table_column_numbers(table, modulus, &my, err)))
        goto fail;
    for (size_t i = 0; i < n; ++i) {
        if (is_rwc && !(wx[i] >= 0 && wx[i] <= 1.5)) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: column '%s': relative water content must be a fraction in [0, 1.5], found %g%s",
                               path, phc_table_row_line(table, i), water, wx[i],
                               wx[i] > 1.5 ? " (percent? divide by 100)" : "");
            goto fail;
        }
        if (!is_rwc && !(wx[i] >= 0)) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': water content must not be negative, found %g",
                               path, phc_table_row_line(table, i), water, wx[i]);
            goto fail;
        }
    }
    if ((rc = phc_elasticity_dataset_new(&elasticity_ops, n, 1, NULL, &ds, err)))
        goto fail;
    memcpy(ds->x, wx, n * sizeof *wx);
    memcpy(ds->y, my, n * sizeof *my);
    for (size_t i = 0; i < n; ++i)
        ds->data_lines[i] = phc_table_row_line(table, i);
    const phc_yaml_node *sig = phc_yaml_get(node, "sigma");
    if (sig) {
        if (sig->kind == PHC_YAML_SCALAR && phc_table_find(table, sig->scalar) >= 0) {
            if ((rc = phc_table_column_numbers(table, sig->scalar, &ds->sigma, err)))
                goto fail;
            for (size_t i = 0; i < n; ++i)
                if (!(ds->sigma[i] > 0)) {
                    rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': sigma must be positive, found %g",
                                       path, phc_table_row_line(table, i), sig->scalar, ds->sigma[i]);
                    goto fail;
                }
        } else {
            double s = 0;
            if ((rc = phc_yaml_number(doc, sig, "sigma", &s, err)) || !(s > 0)) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: key 'sigma': expected a positive number (MPa) or a column of %s, found '%s'",
                                   doc->path, sig->line, path,
                                   sig->kind == PHC_YAML_SCALAR ? sig->scalar : "(not a scalar)");
                goto fail;
            }
            if (!(ds->sigma = malloc(n * sizeof *ds->sigma))) {
                rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
                goto fail;
            }
            for (size_t i = 0; i < n; ++i)
                ds->sigma[i] = s;
        }
    }
    char xl[256];
    if (is_rwc)
        snprintf(xl, sizeof xl, "relative water content (RWC)");
    else
        snprintf(xl, sizeof xl, "water content (%s)", water);
    ds->x_label = strdup(x_label ? x_label : xl);
    ds->y_label = strdup(y_label ? y_label : "bulk modulus of elasticity (MPa)");
    ds->data_file = strdup(path);
    if (!ds->x_label || !ds->y_label || !ds->data_file || phc_dataset_add_input(ds, path)) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    ds->config_line = node->line;
    *out = ds;
    ds = NULL;
    rc = PHC_OK;
fail:
    phc_dataset_free(ds);
    phc_table_free(table);
    free(wx);
    free(my);
    free(path);
    return rc;
}
