/* `infiltration` data sets: see infiltration.h. */
#include "fit/costs/infiltration.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/costs/soil_fields.h"
#include "fit/costs/soil_setup.h"
#include "fit/costs/source_file.h"
#include "fit/config/yaml_keys.h" /* until this kind is YAML-free */
#include "fit/config/soil_setup_yaml.h" /* until this kind is YAML-free */
#include "measurements/c_number.h"
#include "measurements/table.h"
#include "measurements/units.h"

const char *const phc_infiltration_keys[] = {"file", "time", "depth", "fraction", "sigma", "soil",
                                             "x_label", "y_label", NULL};
const phc_key_help phc_infiltration_help[] = {
    {"file", "CSV table of the infiltration front, relative to the config file. Required."},
    {"time", "{column: NAME, unit: UNIT} or a column name: time since the start of the run, "
             "> 0 and increasing; any UDUNITS-2 time unit, default h. Required."},
    {"depth", "{column: NAME, unit: UNIT} or a column name: the depth above which `fraction` "
              "of the water applied so far lies, >= 0; any length unit, default m. Required."},
    {"fraction", "The fraction of the applied water above the depth, in (0, 1]. "
                 "Default: 0.8 (Rhizomorph Fig. 7)."},
    {"sigma", "Standard deviation of the depth, > 0: a number or the name of a column, both in "
              "the depth column's unit. Required."},
    {"soil", "The soil set-up (the soil: keys below); it must have rain or a source. "
             "Required."},
    {"x_label", "Axis label of time. Default: \"time since the start (h)\"."},
    {"y_label", "Axis label of depth. Default: \"depth of 80% of the applied water (m)\" "
                "(with the fraction given)."},
    {NULL, NULL}};

typedef struct inf_impl {
    phc_soil_setup *su;
    double fraction;
    double *t;           /* n model times (h, sorted, > 0) */
    /* during a run */
    double *w_ref, **sw_ref, *tmp;
    const double *times; /* the run's times: 0 first, then the outputs */
    double *y, *jac;
    size_t k, n_out;
} inf_impl;

static void inf_free(void *p)
{
    inf_impl *im = p;
    if (!im)
        return;
    phc_soil_setup_free(im->su);
    free(im->t);
    free(im);
}

static int visit(void *user, const phc_soil *s, size_t i, const phc_soil_tangent *tan)
{
    inf_impl *im = user;
    double *const *sw = tan ? tan->sw : NULL;
    if (i == 0) { /* t = 0: the reference state */
        memcpy(im->w_ref, s->w, s->n * sizeof *s->w);
        for (size_t q = 0; sw && q < im->k; ++q)
            memcpy(im->sw_ref[q], sw[q], s->n * sizeof(double));
        return 0;
    }
    const size_t r = i - 1;
    const double total = s->budget.water_in;
    im->y[r] = phc_soil_infiltration_depth(s, im->w_ref, im->fraction, total, NULL, NULL);
    if (!isfinite(im->y[r]))
        return 0; /* reported as a non-finite prediction */
    for (size_t q = 0; sw && im->jac && q < im->k; ++q) {
        for (size_t v = 0; v < s->n; ++v)
            im->tmp[v] = sw[q][v] - im->sw_ref[q][v];
        double dd = 0;
        phc_soil_infiltration_depth(s, im->w_ref, im->fraction, total, im->tmp, &dd);
        im->jac[r * im->k + q] = dd;
    }
    return 0;
}

/* Depths at the sorted times t[0..m-1] (h), with the Jacobian when jac. */
static int depths(inf_impl *im, size_t k, const double *p, const double *t, size_t m, double *y, double *jac)
{
    const size_t n = im->su->nx * im->su->ny * im->su->nz;
    double *times = malloc((m + 1) * sizeof *times);
    im->w_ref = malloc(n * sizeof(double));
    im->tmp = malloc(n * sizeof(double));
    im->sw_ref = calloc(k ? k : 1, sizeof *im->sw_ref);
    int rc = 0;
    if (!times || !im->w_ref || !im->tmp || !im->sw_ref)
        rc = -1;
    for (size_t q = 0; !rc && jac && q < k; ++q)
        if (!(im->sw_ref[q] = malloc(n * sizeof(double))))
            rc = -1;
    if (!rc) {
        times[0] = 0;
        memcpy(times + 1, t, m * sizeof *t);
        im->y = y;
        im->jac = jac;
        im->k = k;
        phc_error err;
        phc_error_clear(&err);
        int r = phc_soil_setup_run(im->su, p, times, m + 1, jac != NULL, visit, im, NULL, &err);
        rc = r == PHC_ERR_NOMEM ? -1 : r ? 1 : 0;
    }
    for (size_t q = 0; im->sw_ref && q < k; ++q)
        free(im->sw_ref[q]);
    free(im->sw_ref);
    free(im->w_ref);
    free(im->tmp);
    free(times);
    im->sw_ref = NULL;
    im->w_ref = im->tmp = NULL;
    return rc;
}

static int inf_predict(phc_dataset *ds, const double *p, double *yhat, double *jac)
{
    inf_impl *im = ds->impl;
    for (size_t q = 0; q < ds->k; ++q)
        if (!(p[q] > 0) && strcmp(ds->slot_names[q], "f_diff") && strcmp(ds->slot_names[q], "f_grav"))
            return 1;
    if (jac)
        memset(jac, 0, ds->n * ds->k * sizeof *jac);
    return depths(im, ds->k, p, im->t, ds->n, yhat, jac);
}

static int inf_predict_at(phc_dataset *ds, const double *p, const double *x, size_t m, double *y)
{
    inf_impl *im = ds->impl;
    /* the plot's grid may start at 0: depths need t > 0 */
    double *t = malloc((m ? m : 1) * sizeof *t);
    if (!t)
        return -1;
    for (size_t i = 0; i < m; ++i)
        t[i] = x[i] > 1e-9 ? x[i] : 1e-9;
    int rc = depths(im, ds->k, p, t, m, y, NULL);
    free(t);
    return rc;
}

static int inf_report_section(phc_dataset *ds, const double *p, char **markdown, phc_error *err)
{
    inf_impl *im = ds->impl;
    char *md = NULL;
    int rc = phc_soil_setup_report(im->su, p, im->t[ds->n - 1], &md, err);
    if (rc)
        return rc;
    char *out = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&out, &len);
    if (f)
        fprintf(f, "%s\nObserved: the depth above which %.0f%% of the water applied so far lies.\n", md,
                100 * im->fraction);
    free(md);
    if (!f || (ferror(f) | (fclose(f) != 0))) {
        free(out);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    *markdown = out;
    return PHC_OK;
}

static int inf_simulate_outputs(phc_dataset *ds, const double *p, const char *dir, const char *base, phc_error *err)
{
    inf_impl *im = ds->impl;
    return phc_soil_write_fields(im->su, p, im->t[ds->n - 1], 24, dir, base, ds->name, err);
}

static const phc_dataset_ops infiltration_ops = {"infiltration", inf_predict, inf_predict_at, inf_free,
                                                 inf_report_section, inf_simulate_outputs, NULL, NULL};


/* The soil: block (until this kind is YAML-free). */
static int soil_from_yaml(const phc_yaml_doc *doc, const phc_yaml_node *soil, phc_is_parameter_fn is_parameter,
                          void *user_data, phc_soil_setup **out, phc_error *err)
{
    phc_soil_setup_yaml sy;
    int rc = phc_soil_setup_yaml_read(doc, soil, &sy, err);
    if (!rc)
        rc = phc_soil_setup_new(&sy.options, "infiltration", is_parameter, user_data, out, err);
    phc_soil_setup_yaml_free(&sy);
    return rc;
}

int phc_infiltration_load(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                          phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out, phc_error *err)
{
    const char *ctx = "infiltration data set";
    const char *file = NULL, *tcol = NULL, *tunit = NULL, *dcol = NULL, *dunit = NULL;
    const char *x_label = NULL, *y_label = NULL;
    phc_units *units = NULL;
    phc_table *table = NULL;
    phc_dataset *ds = NULL;
    double *tv = NULL, *dv = NULL, *sv = NULL;
    char *path = NULL;
    int rc;
    *out = NULL;
    inf_impl *im = calloc(1, sizeof *im);
    if (!im)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    im->fraction = 0.8;
    const phc_yaml_node *soil = phc_yaml_get(node, "soil");
    if ((rc = phc_yaml_map_string(doc, node, "file", 1, ctx, &file, err)) ||
        (rc = phc_column_spec(doc, node, "time", "infiltration data set", "h", &tcol, &tunit, err)) ||
        (rc = phc_column_spec(doc, node, "depth", "infiltration data set", "m", &dcol, &dunit, err)) ||
        (rc = phc_yaml_map_number(doc, node, "fraction", 0, ctx, &im->fraction, err)) ||
        (rc = phc_yaml_map_string(doc, node, "x_label", 0, ctx, &x_label, err)) ||
        (rc = phc_yaml_map_string(doc, node, "y_label", 0, ctx, &y_label, err)))
        goto fail;
    if (!(im->fraction > 0 && im->fraction <= 1)) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'fraction': must be in (0, 1], found %g", doc->path,
                           phc_key_line(node, "fraction"), im->fraction);
        goto fail;
    }
    if (!soil) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: infiltration data set: missing key 'soil'", doc->path,
                           node->line);
        goto fail;
    }
    if ((rc = soil_from_yaml(doc, soil, is_parameter, user_data, &im->su, err)))
        goto fail;
    if (!im->su->n_rain && !im->su->n_sources) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: infiltration data set: the soil has no rain or source, so "
                           "nothing infiltrates", doc->path, soil->line);
        goto fail;
    }
    if (!(units = phc_units_new(err))) {
        rc = err->status;
        goto fail;
    }
    phc_unit_conversion tconv, dconv;
    char where[256];
    snprintf(where, sizeof where, "%s:%zu: time unit", doc->path, phc_key_line(node, "time"));
    if ((rc = phc_units_conversion(units, tunit, "h", where, &tconv, err)))
        goto fail;
    snprintf(where, sizeof where, "%s:%zu: depth unit", doc->path, phc_key_line(node, "depth"));
    if ((rc = phc_units_conversion(units, dunit, "m", where, &dconv, err)))
        goto fail;
    if (!(path = phc_join_path(base_dir, file))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if ((rc = phc_table_read(path, &table, err))) {
        if (rc == PHC_ERR_IO) /* a file that cannot be read: which key named it */
            phc_error_prefix(err, rc, "%s:%zu: key 'file'", doc->path, phc_key_line(node, "file"));
        goto fail;
    }
    if ((rc = phc_need_column(doc, node, "time", tcol, table, err)) ||
        (rc = phc_need_column(doc, node, "depth", dcol, table, err)) ||
        (rc = phc_table_column_numbers(table, tcol, &tv, err)) ||
        (rc = phc_table_column_numbers(table, dcol, &dv, err)))
        goto fail;
    const size_t n = phc_table_rows(table);
    if (n < 1) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:1: no data rows below the header; expected at least one", path);
        goto fail;
    }
    const phc_yaml_node *sg = phc_yaml_get(node, "sigma");
    double sigma = NAN;
    if (!sg) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: infiltration data set: missing key 'sigma' (the depth's "
                           "standard deviation, or a column)", doc->path, node->line);
        goto fail;
    }
    if (sg->kind == PHC_YAML_SCALAR && phc_table_find(table, sg->scalar) >= 0) {
        if ((rc = phc_table_column_numbers(table, sg->scalar, &sv, err)))
            goto fail;
    } else if ((rc = phc_yaml_number(doc, sg, "sigma", &sigma, err))) {
        goto fail;
    }
    ds = phc_soil_setup_dataset(im->su, &infiltration_ops, n, path);
    if (!ds || phc_dataset_add_input(ds, path)) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    im->t = malloc(n * sizeof *im->t);
    if (!im->t) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    for (size_t r = 0; r < n; ++r) {
        const size_t line = phc_table_row_line(table, r);
        double t = phc_unit_apply(tconv, tv[r]), d = phc_unit_apply(dconv, dv[r]);
        double s = sv ? sv[r] * dconv.scale : sigma * dconv.scale;
        if (!(t > 0) || (r > 0 && !(t > im->t[r - 1]))) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': times must be > 0 (after the start of the "
                               "run) and increasing, found %g", path, line, tcol, tv[r]);
            goto fail;
        }
        if (!(d >= 0) || !(s > 0)) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: a depth must be >= 0 and its sigma > 0 (found %g, %g)",
                               path, line, dv[r], s / dconv.scale);
            goto fail;
        }
        im->t[r] = t;
        ds->x[r] = t;
        ds->y[r] = d;
        ds->sigma[r] = s;
        ds->data_lines[r] = line;
    }
    char ylab[96];
    snprintf(ylab, sizeof ylab, "depth of %.0f%% of the applied water (m)", 100 * im->fraction);
    ds->x_label = strdup(x_label ? x_label : "time since the start (h)");
    ds->y_label = strdup(y_label ? y_label : ylab);
    if (!ds->x_label || !ds->y_label) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    ds->derivatives = PHC_DERIV_ANALYTIC;
    ds->config_line = node->line;
    ds->impl = im;
    im = NULL;
    *out = ds;
    ds = NULL;
    rc = PHC_OK;
fail:
    phc_units_free(units);
    phc_table_free(table);
    free(tv);
    free(dv);
    free(sv);
    free(path);
    inf_free(im);
    if (ds)
        ds->impl = NULL;
    phc_dataset_free(ds);
    return rc;
}
