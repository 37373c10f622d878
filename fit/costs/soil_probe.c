/* `soil_probe` data sets: see soil_probe.h. */
#include "fit/costs/soil_probe.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/costs/soil_fields.h"
#include "fit/costs/soil_setup.h"
#include "fit/costs/source_file.h"
#include "fit/config/yaml_keys.h" /* until this kind is YAML-free */
#include "fit/config/soil_setup_yaml.h" /* until this kind is YAML-free */
#include "fit/costs/unique_times.h"
#include "measurements/soil_probes.h"
#include "measurements/units.h"

const char *const phc_soil_probe_keys[] = {"file", "time", "probe", "value", "quantity", "start", "probes",
                                           "sigma", "soil", "x_label", "y_label", NULL};
const phc_key_help phc_soil_probe_help[] = {
    {"file", "CSV table of readings (time, probe, value; in time order), relative to the "
             "config file. Required."},
    {"time", "{column: NAME, unit: UNIT} or a column name: reading times; any UDUNITS-2 time "
             "unit, or a timestamp unit such as \"hours since 2024-05-01\" (then start is "
             "required); default h. Required."},
    {"probe", "Column of probe ids, each in the probe table. Required."},
    {"value", "Column of readings, in the quantity's unit. Required."},
    {"quantity", "What the readings are: water (w, m³/m³) or fill (w/c). Default: water."},
    {"start", "The reading time of the model's t = 0, in the time unit; no reading may be "
              "earlier. Default: 0; required with a timestamp unit."},
    {"probes", "The probe table, one row per probe: {file, id, x, y, depth, sigma}, its CSV "
               "file (required, relative to the config file) and the names of its columns "
               "(defaults id, x, y, depth; sigma optional: per-probe standard deviations); lat "
               "and lon instead of x and y place probes by latitude and longitude (needs the "
               "soil's geo_origin). x, y in m from the grid's west-south corner, depth in m "
               "below the surface. Required."},
    {"sigma", "Standard deviation of a reading, > 0, in the readings' unit, for probes without "
              "a sigma column. Required unless every probe has one."},
    {"soil", "The soil set-up (the soil: keys below). Required."},
    {"x_label", "Axis label of time. Default: \"time since start (h)\"."},
    {"y_label", "Axis label of the readings. Default: \"water content w (m³/m³)\" or "
                "\"fill level w/c\"."},
    {NULL, NULL}};

typedef struct sp_impl {
    phc_soil_setup *su;
    phc_probe_table *probes;
    double *pz;              /* probe heights in the grid frame, m */
    size_t *probe_of;        /* n: probe index of each reading */
    double *t_unique;        /* sorted distinct model times, h */
    size_t m_unique;
    size_t *t_at;            /* n: index into t_unique */
    int fill;                /* compare w/c instead of w */
    /* during predict */
    double *yhat, *jac;
    size_t k;
} sp_impl;

static void sp_free(void *p)
{
    sp_impl *s = p;
    if (!s)
        return;
    phc_soil_setup_free(s->su);
    phc_probe_table_free(s->probes);
    free(s->pz);
    free(s->probe_of);
    free(s->t_unique);
    free(s->t_at);
    free(s);
}

/* The model value (w or w/c) of probe pi and its derivatives. */
static int probe_value(const sp_impl *im, const phc_soil *s, size_t pi, const phc_soil_tangent *tan, double *y,
                       double *row)
{
    const phc_probe *pr = &im->probes->probes[pi];
    double wts[8], val;
    size_t idx[8];
    if (phc_soil_sample(s, s->w, pr->x, pr->y, im->pz[pi], &val, wts, idx))
        return 1;
    if (im->fill) {
        val = 0;
        for (int c = 0; c < 8; ++c)
            val += wts[c] * s->w[idx[c]] / s->c[idx[c]];
    }
    *y = val;
    if (!row || !tan)
        return 0;
    for (size_t q = 0; q < im->k; ++q) {
        const double *sw = tan->sw[q], *dic = tan->dinv_c[q];
        double d = 0;
        for (int c = 0; c < 8; ++c) {
            size_t v = idx[c];
            /* w: d w = sw; w/c: d(w/c) = sw / c + w d(1/c) */
            d += wts[c] * (im->fill ? sw[v] / s->c[v] + s->w[v] * dic[v] : sw[v]);
        }
        row[q] = d;
    }
    return 0;
}

typedef struct visit_ctx {
    phc_dataset *ds;
    sp_impl *im;
    int bad;
} visit_ctx;

static int visit(void *user, const phc_soil *s, size_t i, const phc_soil_tangent *tan)
{
    visit_ctx *c = user;
    phc_dataset *ds = c->ds;
    sp_impl *im = c->im;
    for (size_t r = 0; r < ds->n; ++r) {
        if (im->t_at[r] != i)
            continue;
        double *row = im->jac ? im->jac + r * ds->k : NULL;
        if (probe_value(im, s, im->probe_of[r], tan, &im->yhat[r], row)) {
            c->bad = 1;
            return 1;
        }
    }
    return 0;
}

static int sp_predict(phc_dataset *ds, const double *p, double *yhat, double *jac)
{
    sp_impl *im = ds->impl;
    im->yhat = yhat;
    im->jac = jac;
    im->k = ds->k;
    for (size_t q = 0; q < ds->k; ++q)
        if (!(p[q] > 0) && strcmp(ds->slot_names[q], "f_diff") && strcmp(ds->slot_names[q], "f_grav"))
            return 1; /* p and c must stay positive: reject the trial step */
    visit_ctx c = {ds, im, 0};
    phc_error err;
    phc_error_clear(&err);
    int rc = phc_soil_setup_run(im->su, p, im->t_unique, im->m_unique, jac != NULL, visit, &c, NULL, &err);
    if (rc == PHC_ERR_NOMEM)
        return -1;
    return rc ? 1 : 0;
}

static int sp_report_section(phc_dataset *ds, const double *p, char **markdown, phc_error *err)
{
    sp_impl *im = ds->impl;
    char *md = NULL;
    int rc = phc_soil_setup_report(im->su, p, im->t_unique[im->m_unique - 1], &md, err);
    if (rc)
        return rc;
    char *out = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&out, &len);
    if (!f) {
        free(md);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    fprintf(f, "%s\n| probe | x (m) | y (m) | depth (m) | placed from |\n|---|---|---|---|---|\n", md);
    for (size_t i = 0; i < im->probes->n; ++i) {
        const phc_probe *pr = &im->probes->probes[i];
        if (pr->geographic)
            fprintf(f, "| %s | %.3f | %.3f | %.3f | %.6f, %.6f |\n", pr->id, pr->x, pr->y, pr->depth, pr->lat,
                    pr->lon);
        else
            fprintf(f, "| %s | %.3f | %.3f | %.3f | grid metres |\n", pr->id, pr->x, pr->y, pr->depth);
    }
    if (ferror(f) | (fclose(f) != 0)) {
        free(md);
        free(out);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    free(md);
    *markdown = out;
    return PHC_OK;
}

static int sp_simulate_outputs(phc_dataset *ds, const double *p, const char *dir, const char *base, phc_error *err)
{
    sp_impl *im = ds->impl;
    return phc_soil_write_fields(im->su, p, im->t_unique[im->m_unique - 1], 24, dir, base, ds->name, err);
}

/* The probes are the series: the plots name each by its id and depth. */
static void sp_series_name(const phc_dataset *ds, size_t g, char *buf, size_t size)
{
    const phc_probe *pr = &((const sp_impl *)ds->impl)->probes->probes[g];
    snprintf(buf, size, "%s, %.2f m deep", pr->id, pr->depth);
}

static int sp_name_series(phc_dataset *ds, phc_error *err)
{
    const sp_impl *im = ds->impl;
    return phc_dataset_name_series(ds, "probe", im->probes->n, sp_series_name, err);
}

static const phc_dataset_ops soil_probe_ops = {"soil_probe", sp_predict, NULL, sp_free, sp_report_section,
                                               sp_simulate_outputs, NULL, sp_name_series};



/* The soil: block (until this kind is YAML-free). */
static int soil_from_yaml(const phc_yaml_doc *doc, const phc_yaml_node *soil, phc_is_parameter_fn is_parameter,
                          void *user_data, phc_soil_setup **out, phc_error *err)
{
    phc_soil_setup_yaml sy;
    int rc = phc_soil_setup_yaml_read(doc, soil, &sy, err);
    if (!rc)
        rc = phc_soil_setup_new(&sy.options, "soil_probe", is_parameter, user_data, out, err);
    phc_soil_setup_yaml_free(&sy);
    return rc;
}

int phc_soil_probe_load(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                        phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out, phc_error *err)
{
    static const char *const probe_keys[] = {"file", "id", "x", "y", "lat", "lon", "depth", "sigma", NULL};
    const char *ctx = "soil_probe data set";
    const char *file = NULL, *tcol = NULL, *tunit = NULL, *pcol = NULL, *vcol = NULL, *quantity = "water";
    const char *x_label = NULL, *y_label = NULL;
    phc_units *units = NULL;
    phc_probe_series *ser = NULL;
    phc_dataset *ds = NULL;
    char *path = NULL, *ppath = NULL;
    int rc;
    *out = NULL;
    sp_impl *im = calloc(1, sizeof *im);
    if (!im)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    const phc_yaml_node *soil = phc_yaml_get(node, "soil"), *pn = phc_yaml_get(node, "probes");
    if ((rc = phc_yaml_map_string(doc, node, "file", 1, ctx, &file, err)) ||
        (rc = phc_column_spec(doc, node, "time", "soil_probe data set", "h", &tcol, &tunit, err)) ||
        (rc = phc_yaml_map_string(doc, node, "probe", 1, ctx, &pcol, err)) ||
        (rc = phc_yaml_map_string(doc, node, "value", 1, ctx, &vcol, err)) ||
        (rc = phc_yaml_map_string(doc, node, "quantity", 0, ctx, &quantity, err)) ||
        (rc = phc_yaml_map_string(doc, node, "x_label", 0, ctx, &x_label, err)) ||
        (rc = phc_yaml_map_string(doc, node, "y_label", 0, ctx, &y_label, err)))
        goto fail;
    if (strcmp(quantity, "water") && strcmp(quantity, "fill")) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'quantity': '%s' is not one of water, fill", doc->path,
                           phc_key_line(node, "quantity"), quantity);
        goto fail;
    }
    im->fill = !strcmp(quantity, "fill");
    if (!soil || !pn) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil_probe data set: missing key '%s'", doc->path, node->line,
                           soil ? "probes" : "soil");
        goto fail;
    }
    if ((rc = soil_from_yaml(doc, soil, is_parameter, user_data, &im->su, err)))
        goto fail;

    /* Probe table. */
    phc_probe_columns pc = {0};
    const char *pfile = NULL;
    if (pn->kind != PHC_YAML_MAPPING) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'probes': expected {file, id, x, y | lat, lon, depth}",
                           doc->path, pn->line);
        goto fail;
    }
    pc.id = "id";
    pc.depth = "depth";
    if ((rc = phc_yaml_check_keys(doc, pn, probe_keys, "probes", err)) ||
        (rc = phc_yaml_map_string(doc, pn, "file", 1, "probes", &pfile, err)) ||
        (rc = phc_yaml_map_string(doc, pn, "id", 0, "probes", &pc.id, err)) ||
        (rc = phc_yaml_map_string(doc, pn, "x", 0, "probes", &pc.x, err)) ||
        (rc = phc_yaml_map_string(doc, pn, "y", 0, "probes", &pc.y, err)) ||
        (rc = phc_yaml_map_string(doc, pn, "lat", 0, "probes", &pc.lat, err)) ||
        (rc = phc_yaml_map_string(doc, pn, "lon", 0, "probes", &pc.lon, err)) ||
        (rc = phc_yaml_map_string(doc, pn, "depth", 0, "probes", &pc.depth, err)) ||
        (rc = phc_yaml_map_string(doc, pn, "sigma", 0, "probes", &pc.sigma, err)))
        goto fail;
    if (!pc.lat && !pc.lon && !pc.x && !pc.y) {
        pc.x = "x";
        pc.y = "y";
    }
    if (!(ppath = phc_join_path(base_dir, pfile)) || !(path = phc_join_path(base_dir, file))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if ((rc = phc_probe_table_read(ppath, &pc, im->su->has_geo ? &im->su->geo : NULL, &im->probes, err))) {
        if (rc == PHC_ERR_IO) /* a file that cannot be read: which key named it */
            phc_error_prefix(err, rc, "%s:%zu: probes: key 'file'", doc->path, phc_key_line(pn, "file"));
        goto fail;
    }
    const double top = im->su->nz * im->su->dx, ex = im->su->nx * im->su->dx, ey = im->su->ny * im->su->dx;
    if (!(im->pz = malloc(im->probes->n * sizeof *im->pz))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    for (size_t i = 0; i < im->probes->n; ++i) {
        const phc_probe *pr = &im->probes->probes[i];
        if (!(pr->x >= 0 && pr->x <= ex && pr->y >= 0 && pr->y <= ey && pr->depth <= top)) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: probe '%s' at x = %.3f m, y = %.3f m, depth %.3f m%s is outside the soil grid "
                               "(x 0..%g m, y 0..%g m, depth 0..%g m; config line %zu)",
                               ppath, pr->line, pr->id, pr->x, pr->y, pr->depth,
                               pr->geographic ? " (east, north of geo_origin)" : "", ex, ey, top, im->su->line);
            goto fail;
        }
        im->pz[i] = top - pr->depth;
    }

    /* Readings. */
    if (!(units = phc_units_new(err))) {
        rc = err->status;
        goto fail;
    }
    phc_unit_conversion tconv;
    char where[256];
    snprintf(where, sizeof where, "%s:%zu: time unit", doc->path, phc_key_line(node, "time"));
    if ((rc = phc_units_conversion(units, tunit, "h", where, &tconv, err)))
        goto fail;
    if ((rc = phc_probe_series_read(path, tcol, tconv, pcol, vcol, im->probes, &ser, err))) {
        if (rc == PHC_ERR_IO) /* a file that cannot be read: which key named it */
            phc_error_prefix(err, rc, "%s:%zu: key 'file'", doc->path, phc_key_line(node, "file"));
        goto fail;
    }
    double start = phc_unit_apply(tconv, 0.0);
    if (strstr(tunit, "since") && !phc_yaml_get(node, "start")) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: the time unit '%s' is a timestamp: give `start:` (the "
                           "reading time of the model's t = 0, in that unit)", doc->path, phc_key_line(node, "time"),
                           tunit);
        goto fail;
    }
    if (phc_yaml_get(node, "start")) {
        double st;
        if ((rc = phc_yaml_map_number(doc, node, "start", 0, ctx, &st, err)))
            goto fail;
        start = phc_unit_apply(tconv, st);
        if (ser->t[0] < start) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: the first reading is before `start` (the model's t = 0)",
                               path, ser->line[0]);
            goto fail;
        }
    }

    /* Sigma: per probe, or a scalar. */
    double sigma = NAN;
    const phc_yaml_node *sg = phc_yaml_get(node, "sigma");
    if (sg) {
        if ((rc = phc_yaml_number(doc, sg, "sigma", &sigma, err)))
            goto fail;
        if (!(sigma > 0)) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'sigma': must be > 0", doc->path, sg->line);
            goto fail;
        }
    }

    const size_t n = ser->n;
    ds = phc_soil_setup_dataset(im->su, &soil_probe_ops, n, path);
    if (!ds || phc_dataset_add_input(ds, path) || phc_dataset_add_input(ds, ppath)) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    im->probe_of = malloc(n * sizeof *im->probe_of);
    if (!im->probe_of) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    for (size_t r = 0; r < n; ++r) {
        const phc_probe *pr = &im->probes->probes[ser->probe[r]];
        double s = isnan(pr->sigma) ? sigma : pr->sigma;
        if (isnan(s)) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil_probe data set: give `sigma:` or a sigma column in "
                               "the probe table (probe '%s' has none)", doc->path, node->line, pr->id);
            goto fail;
        }
        ds->x[r] = ser->t[r] - start;
        ds->y[r] = ser->value[r];
        ds->sigma[r] = s;
        ds->data_lines[r] = ser->line[r];
        im->probe_of[r] = ser->probe[r];
    }
    if ((rc = phc_unique_times(ds->x, n, &im->t_unique, &im->m_unique, &im->t_at, err)))
        goto fail;
    ds->x_label = strdup(x_label ? x_label : "time since start (h)");
    ds->y_label = strdup(y_label ? y_label : im->fill ? "fill level w/c" : "water content w (m³/m³)");
    if (!ds->x_label || !ds->y_label) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if (!(ds->series = malloc(n * sizeof *ds->series))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    memcpy(ds->series, im->probe_of, n * sizeof *ds->series);
    ds->derivatives = PHC_DERIV_ANALYTIC;
    ds->config_line = node->line;
    ds->impl = im;
    im = NULL;
    phc_units_free(units);
    phc_probe_series_free(ser);
    free(path);
    free(ppath);
    *out = ds;
    return PHC_OK;
fail:
    phc_units_free(units);
    phc_probe_series_free(ser);
    free(path);
    free(ppath);
    sp_free(im);
    if (ds)
        ds->impl = NULL;
    phc_dataset_free(ds);
    return rc;
}
