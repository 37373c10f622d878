/* `soil_probe` data sets: see soil_probe.h. */
#include "fit/costs/soil_probe.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/costs/soil_fields.h"
#include "fit/costs/unique_times.h"

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

const phc_dataset_ops phc_soil_probe_ops = {
    .kind = "soil_probe",
    .predict = sp_predict,
    .free_impl = sp_free,
    .report_section = sp_report_section,
    .simulate_outputs = sp_simulate_outputs,
    .name_series = sp_name_series,
};

phc_soil_probe_options phc_soil_probe_options_default(void)
{
    phc_soil_probe_options o = {.quantity = PHC_SOIL_PROBE_WATER, .start = NAN, .sigma = NAN};
    return o;
}

#define WHERE(key) phc_origin_key(o->origin, "soil_probe", key).text

/* What a program may hand over that a file reader never would. */
static int check_inputs(const phc_probe_table *probes, const phc_probe_series *ser,
                        const phc_soil_probe_options *o, phc_error *err)
{
    if (!probes || !probes->n || !probes->probes)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: the probe table has no probes", WHERE("probes"));
    if (!ser || !ser->n || !ser->t || !ser->probe || !ser->value)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: no readings", WHERE("file"));
    for (size_t i = 0; i < probes->n; ++i)
        if (!probes->probes[i].id)
            return phc_error_set(err, PHC_ERR_INPUT, "%s: probe %zu has no id", WHERE("probes"), i + 1);
    for (size_t r = 0; r < ser->n; ++r)
        if (ser->probe[r] >= probes->n || !isfinite(ser->t[r]) || !isfinite(ser->value[r]))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s: reading %zu: probe %zu of %zu, time %g h, value %g: expected a probe "
                                 "of the table and finite numbers",
                                 WHERE("file"), r + 1, ser->probe[r] + 1, probes->n, ser->t[r], ser->value[r]);
    if (!o->soil)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: soil_probe data set: missing key 'soil'", WHERE(NULL));
    return PHC_OK;
}

/* A copy of the probe table the data set keeps (freed by
 * phc_probe_table_free); NULL when out of memory. */
static phc_probe_table *copy_probes(const phc_probe_table *t)
{
    phc_probe_table *c = calloc(1, sizeof *c);
    if (!c)
        return NULL;
    c->path = strdup(t->path ? t->path : "probes");
    c->probes = calloc(t->n, sizeof *c->probes);
    if (!c->path || !c->probes) {
        phc_probe_table_free(c);
        return NULL;
    }
    for (size_t i = 0; i < t->n; ++i) {
        c->probes[i] = t->probes[i];
        if (!(c->probes[i].id = strdup(t->probes[i].id))) {
            phc_probe_table_free(c);
            return NULL;
        }
        c->n = i + 1;
    }
    return c;
}

/* The probes' heights in the grid frame; a probe outside the grid is an
 * error naming its line in the probe table. */
static int place_probes(sp_impl *im, phc_error *err)
{
    const phc_soil_setup *su = im->su;
    const double top = su->nz * su->dx, ex = su->nx * su->dx, ey = su->ny * su->dx;
    if (!(im->pz = malloc(im->probes->n * sizeof *im->pz)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < im->probes->n; ++i) {
        const phc_probe *pr = &im->probes->probes[i];
        if (!(pr->x >= 0 && pr->x <= ex && pr->y >= 0 && pr->y <= ey && pr->depth <= top)) {
            char config_line[48] = "";
            if (su->line)
                snprintf(config_line, sizeof config_line, "; config line %zu", su->line);
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: probe '%s' at x = %.3f m, y = %.3f m, depth %.3f m%s is outside the soil grid "
                                 "(x 0..%g m, y 0..%g m, depth 0..%g m%s)",
                                 im->probes->path, pr->line, pr->id, pr->x, pr->y, pr->depth,
                                 pr->geographic ? " (east, north of geo_origin)" : "", ex, ey, top, config_line);
        }
        im->pz[i] = top - pr->depth;
    }
    return PHC_OK;
}

/* The observations: model times since start, readings, their sigmas. */
static int fill_readings(phc_dataset *ds, sp_impl *im, const phc_probe_series *ser, const phc_soil_probe_options *o,
                         phc_error *err)
{
    const char *path = ds->data_file;
    const double start = isnan(o->start) ? 0 : o->start;
    for (size_t r = 0; !isnan(o->start) && r < ser->n; ++r)
        if (ser->t[r] < start)
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: the first reading is before `start` (the model's t = 0)",
                                 path, ser->line ? ser->line[r] : r + 2);
    if (!isnan(o->sigma) && !(o->sigma > 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: key 'sigma': must be > 0", WHERE("sigma"));
    if (!(im->probe_of = malloc(ser->n * sizeof *im->probe_of)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t r = 0; r < ser->n; ++r) {
        const phc_probe *pr = &im->probes->probes[ser->probe[r]];
        double s = isnan(pr->sigma) ? o->sigma : pr->sigma;
        if (isnan(s))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: soil_probe data set: give `sigma:` or a sigma column in "
                                 "the probe table (probe '%s' has none)", WHERE(NULL), pr->id);
        ds->x[r] = ser->t[r] - start;
        ds->y[r] = ser->value[r];
        ds->sigma[r] = s;
        ds->data_lines[r] = ser->line ? ser->line[r] : r + 2;
        im->probe_of[r] = ser->probe[r];
    }
    return PHC_OK;
}

int phc_soil_probe_new(const phc_probe_table *probes, const phc_probe_series *ser,
                       const phc_soil_probe_options *o, phc_dataset **out, phc_error *err)
{
    phc_dataset *ds = NULL;
    int rc;
    *out = NULL;
    if ((rc = check_inputs(probes, ser, o, err)))
        return rc;
    sp_impl *im = calloc(1, sizeof *im);
    if (!im)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    im->fill = o->quantity == PHC_SOIL_PROBE_FILL;
    if ((rc = phc_soil_setup_new(o->soil, "soil_probe", o->is_parameter, o->user_data, &im->su, err)))
        goto fail;
    if (!(im->probes = copy_probes(probes))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if ((rc = place_probes(im, err)))
        goto fail;
    const size_t n = ser->n;
    ds = phc_soil_setup_dataset(im->su, &phc_soil_probe_ops, n, ser->path ? ser->path : "readings");
    if (!ds) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if ((rc = fill_readings(ds, im, ser, o, err)) ||
        (rc = phc_unique_times(ds->x, n, &im->t_unique, &im->m_unique, &im->t_at, err)))
        goto fail;
    ds->x_label = strdup(o->x_label ? o->x_label : "time since start (h)");
    ds->y_label = strdup(o->y_label ? o->y_label : im->fill ? "fill level w/c" : "water content w (m³/m³)");
    if (!ds->x_label || !ds->y_label || !(ds->series = malloc(n * sizeof *ds->series))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    memcpy(ds->series, im->probe_of, n * sizeof *ds->series);
    ds->derivatives = PHC_DERIV_ANALYTIC;
    ds->config_line = phc_origin_line(o->origin, NULL);
    ds->impl = im;
    *out = ds;
    return PHC_OK;
fail:
    sp_free(im);
    if (ds)
        ds->impl = NULL;
    phc_dataset_free(ds);
    return rc;
}
