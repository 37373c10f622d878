/* `infiltration` data sets: see infiltration.h. */
#include "fit/costs/infiltration.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/costs/soil_fields.h"
#include "fit/costs/source_file.h"
#include "measurements/units.h"

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

const phc_dataset_ops phc_infiltration_ops = {
    .kind = "infiltration",
    .predict = inf_predict,
    .predict_at = inf_predict_at,
    .free_impl = inf_free,
    .report_section = inf_report_section,
    .simulate_outputs = inf_simulate_outputs,
};

phc_infiltration_options phc_infiltration_options_default(void)
{
    phc_infiltration_options o = {.time_unit = "h", .depth_unit = "m", .fraction = 0.8, .sigma = NAN};
    return o;
}

#define WHERE(key) phc_origin_key(o->origin, "infiltration", key).text

/* The fraction, and a soil that gets water. */
static int setup_soil(inf_impl *im, const phc_infiltration_options *o, phc_error *err)
{
    int rc;
    im->fraction = o->fraction;
    if (!(im->fraction > 0 && im->fraction <= 1))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'fraction': must be in (0, 1], found %g", WHERE("fraction"),
                             im->fraction);
    if (!o->soil)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: infiltration data set: missing key 'soil'", WHERE(NULL));
    if ((rc = phc_soil_setup_new(o->soil, "infiltration", o->is_parameter, o->user_data, &im->su, err)))
        return rc;
    if (!im->su->n_rain && !im->su->n_sources)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: infiltration data set: the soil has no rain or source, so "
                             "nothing infiltrates", phc_origin_key(o->soil->origin, "infiltration", NULL).text);
    return PHC_OK;
}

/* The time, depth and sigma columns as numbers (sv NULL for one sigma),
 * and the conversions of their units to h and m. */
static int read_columns(const phc_table *table, const phc_infiltration_options *o, double **tv, double **dv,
                        double **sv, phc_unit_conversion *tconv, phc_unit_conversion *dconv, phc_error *err)
{
    const char *tcol = o->time, *dcol = o->depth;
    phc_units *units = NULL;
    char where[4300];
    int rc;
    if (!tcol || !dcol)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key '%s' is required", WHERE(NULL), tcol ? "depth" : "time");
    if (!(units = phc_units_new(err)))
        return err->status;
    snprintf(where, sizeof where, "%s: time unit", WHERE("time"));
    rc = phc_units_conversion(units, o->time_unit ? o->time_unit : "h", "h", where, tconv, err);
    snprintf(where, sizeof where, "%s: depth unit", WHERE("depth"));
    if (!rc)
        rc = phc_units_conversion(units, o->depth_unit ? o->depth_unit : "m", "m", where, dconv, err);
    phc_units_free(units);
    if (rc)
        return rc;
    if (phc_table_find(table, tcol) < 0)
        return phc_unknown_column_at(WHERE("time"), "key 'time':", tcol, table, err);
    if (phc_table_find(table, dcol) < 0)
        return phc_unknown_column_at(WHERE("depth"), "key 'depth':", dcol, table, err);
    if ((rc = phc_table_column_numbers(table, tcol, tv, err)) || (rc = phc_table_column_numbers(table, dcol, dv, err)))
        return rc;
    if (phc_table_rows(table) < 1)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:1: no data rows below the header; expected at least one",
                             phc_table_source(table));
    if (!o->sigma_column && isnan(o->sigma))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: infiltration data set: missing key 'sigma' (the depth's "
                             "standard deviation, or a column)", WHERE(NULL));
    if (o->sigma_column && !isnan(o->sigma))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'sigma': give a number or a column, not both",
                             WHERE("sigma"));
    if (o->sigma_column && phc_table_find(table, o->sigma_column) < 0)
        return phc_unknown_column_at(WHERE("sigma"), "key 'sigma':", o->sigma_column, table, err);
    if (o->sigma_column)
        return phc_table_column_numbers(table, o->sigma_column, sv, err);
    return PHC_OK;
}

/* The observations in h and m; times > 0 and increasing, depths >= 0. */
static int fill_rows(phc_dataset *ds, inf_impl *im, const phc_table *table, const phc_infiltration_options *o,
                     const double *tv, const double *dv, const double *sv, phc_unit_conversion tconv,
                     phc_unit_conversion dconv, phc_error *err)
{
    const char *path = phc_table_source(table);
    if (!(im->t = malloc(ds->n * sizeof *im->t)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t r = 0; r < ds->n; ++r) {
        const size_t line = phc_table_row_line(table, r);
        double t = phc_unit_apply(tconv, tv[r]), d = phc_unit_apply(dconv, dv[r]);
        double s = sv ? sv[r] * dconv.scale : o->sigma * dconv.scale;
        if (!(t > 0) || (r > 0 && !(t > im->t[r - 1])))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': times must be > 0 (after the start of the "
                                 "run) and increasing, found %g", path, line, o->time, tv[r]);
        if (!(d >= 0) || !(s > 0))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: a depth must be >= 0 and its sigma > 0 (found %g, %g)",
                                 path, line, dv[r], s / dconv.scale);
        im->t[r] = t;
        ds->x[r] = t;
        ds->y[r] = d;
        ds->sigma[r] = s;
        ds->data_lines[r] = line;
    }
    return PHC_OK;
}

int phc_infiltration_new(const phc_table *table, const phc_infiltration_options *o, phc_dataset **out,
                         phc_error *err)
{
    phc_dataset *ds = NULL;
    double *tv = NULL, *dv = NULL, *sv = NULL;
    phc_unit_conversion tconv, dconv;
    int rc;
    *out = NULL;
    inf_impl *im = calloc(1, sizeof *im);
    if (!im)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if ((rc = setup_soil(im, o, err)) || (rc = read_columns(table, o, &tv, &dv, &sv, &tconv, &dconv, err)))
        goto fail;
    ds = phc_soil_setup_dataset(im->su, &phc_infiltration_ops, phc_table_rows(table), phc_table_source(table));
    if (!ds) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if ((rc = fill_rows(ds, im, table, o, tv, dv, sv, tconv, dconv, err)))
        goto fail;
    char ylab[96];
    snprintf(ylab, sizeof ylab, "depth of %.0f%% of the applied water (m)", 100 * im->fraction);
    ds->x_label = strdup(o->x_label ? o->x_label : "time since the start (h)");
    ds->y_label = strdup(o->y_label ? o->y_label : ylab);
    if (!ds->x_label || !ds->y_label) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    ds->derivatives = PHC_DERIV_ANALYTIC;
    ds->config_line = phc_origin_line(o->origin, NULL);
    ds->impl = im;
    im = NULL;
    *out = ds;
    ds = NULL;
    rc = PHC_OK;
fail:
    free(tv);
    free(dv);
    free(sv);
    inf_free(im);
    if (ds)
        ds->impl = NULL;
    phc_dataset_free(ds);
    return rc;
}
