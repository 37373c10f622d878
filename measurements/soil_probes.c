/* Soil-moisture probes: see soil_probes.h. */
#include "measurements/soil_probes.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "measurements/c_number.h"
#include "measurements/table.h"

void phc_probe_table_free(phc_probe_table *t)
{
    if (!t)
        return;
    for (size_t i = 0; i < t->n; ++i)
        free(t->probes[i].id);
    free(t->probes);
    free(t->path);
    free(t);
}

long phc_probe_find(const phc_probe_table *t, const char *id)
{
    for (size_t i = 0; i < t->n; ++i)
        if (!strcmp(t->probes[i].id, id))
            return (long)i;
    return -1;
}

/* A numeric cell of column `col` at row r (finite). */
static int cell_number(const phc_table *t, size_t r, long col, const char *name, double *out, phc_error *err)
{
    const char *cell = phc_table_cell(t, r, (size_t)col);
    char *end = NULL;
    double v = phc_strtod_c(cell, &end);
    if (!end || end == cell || *end || !isfinite(v))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': expected a finite number, found '%s'",
                             phc_table_source(t), phc_table_row_line(t, r), name, cell);
    *out = v;
    return PHC_OK;
}

static int need(const phc_table *t, const char *name, const char *role, long *col, phc_error *err)
{
    *col = phc_table_find(t, name);
    if (*col >= 0)
        return PHC_OK;
    char list[512] = "";
    for (size_t c = 0; c < phc_table_columns(t); ++c) {
        size_t used = strlen(list);
        snprintf(list + used, sizeof list - used, "%s'%s'", c ? ", " : "", phc_table_column_name(t, c));
    }
    return phc_error_set(err, PHC_ERR_INPUT, "%s: the %s column '%s' is not in the table (columns: %s)",
                         phc_table_source(t), role, name, list);
}

int phc_probe_table_read(const char *path, const phc_probe_columns *cols, const phc_geo_frame *frame,
                         phc_probe_table **out, phc_error *err)
{
    phc_table *t = NULL;
    phc_probe_table *pt = NULL;
    int rc;
    *out = NULL;
    const int geo = cols->lat || cols->lon;
    if (!cols->id || !cols->depth || (geo ? !(cols->lat && cols->lon) : !(cols->x && cols->y)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: a probe table needs id and depth columns and either x and y "
                             "or lat and lon", path);
    if (geo && !frame)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: the probes are placed by latitude and longitude but the soil "
                             "grid has no geo_origin to place them from", path);
    if ((rc = phc_table_read(path, &t, err)))
        return rc;
    long c_id, c_a, c_b, c_depth, c_sigma = -1;
    if ((rc = need(t, cols->id, "probe id", &c_id, err)) ||
        (rc = need(t, geo ? cols->lat : cols->x, geo ? "latitude" : "x", &c_a, err)) ||
        (rc = need(t, geo ? cols->lon : cols->y, geo ? "longitude" : "y", &c_b, err)) ||
        (rc = need(t, cols->depth, "depth", &c_depth, err)) ||
        (cols->sigma && (rc = need(t, cols->sigma, "sigma", &c_sigma, err))))
        goto fail;
    const size_t rows = phc_table_rows(t);
    if (!rows) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s: the probe table has no rows", path);
        goto fail;
    }
    pt = calloc(1, sizeof *pt);
    if (!pt || !(pt->probes = calloc(rows, sizeof *pt->probes)) || !(pt->path = strdup(path))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    for (size_t r = 0; r < rows; ++r) {
        phc_probe *p = &pt->probes[r];
        const size_t line = phc_table_row_line(t, r);
        const char *id = phc_table_cell(t, r, (size_t)c_id);
        p->line = line;
        p->sigma = NAN;
        if (!*id) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': a probe needs an id", path, line, cols->id);
            goto fail;
        }
        long dup = phc_probe_find(pt, id);
        if (dup >= 0) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: probe '%s' is listed twice (first on line %zu)", path,
                               line, id, pt->probes[dup].line);
            goto fail;
        }
        if (!(p->id = strdup(id))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        pt->n = r + 1;
        if ((rc = cell_number(t, r, c_depth, cols->depth, &p->depth, err)))
            goto fail;
        if (p->depth < 0) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: probe '%s': depth must be >= 0 m below the surface, "
                               "found %g", path, line, id, p->depth);
            goto fail;
        }
        if (c_sigma >= 0) {
            if ((rc = cell_number(t, r, c_sigma, cols->sigma, &p->sigma, err)))
                goto fail;
            if (!(p->sigma > 0)) {
                rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: probe '%s': sigma must be > 0, found %g", path,
                                   line, id, p->sigma);
                goto fail;
            }
        }
        if (!geo) {
            if ((rc = cell_number(t, r, c_a, cols->x, &p->x, err)) ||
                (rc = cell_number(t, r, c_b, cols->y, &p->y, err)))
                goto fail;
            continue;
        }
        char where[512];
        snprintf(where, sizeof where, "%s:%zu: column '%s'", path, line, cols->lat);
        if ((rc = phc_geo_parse_angle(phc_table_cell(t, r, (size_t)c_a), PHC_GEO_LATITUDE, where, &p->lat, err)))
            goto fail;
        snprintf(where, sizeof where, "%s:%zu: column '%s'", path, line, cols->lon);
        if ((rc = phc_geo_parse_angle(phc_table_cell(t, r, (size_t)c_b), PHC_GEO_LONGITUDE, where, &p->lon, err)))
            goto fail;
        double enu[3];
        if ((rc = phc_geo_to_enu(frame, p->lat, p->lon, frame->h0, enu, err)))
            goto fail;
        p->x = enu[0];
        p->y = enu[1];
        p->geographic = 1;
    }
    phc_table_free(t);
    *out = pt;
    return PHC_OK;
fail:
    phc_table_free(t);
    phc_probe_table_free(pt);
    return rc;
}

void phc_probe_series_free(phc_probe_series *s)
{
    if (!s)
        return;
    free(s->path);
    free(s->t);
    free(s->probe);
    free(s->value);
    free(s->line);
    free(s);
}

int phc_probe_series_read(const char *path, const char *time_col, phc_unit_conversion tconv,
                          const char *probe_col, const char *value_col, const phc_probe_table *probes,
                          phc_probe_series **out, phc_error *err)
{
    phc_table *t = NULL;
    phc_probe_series *s = NULL;
    int rc;
    *out = NULL;
    if ((rc = phc_table_read(path, &t, err)))
        return rc;
    long c_t, c_p, c_v;
    if ((rc = need(t, time_col, "time", &c_t, err)) || (rc = need(t, probe_col, "probe", &c_p, err)) ||
        (rc = need(t, value_col, "value", &c_v, err)))
        goto fail;
    const size_t rows = phc_table_rows(t);
    if (!rows) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s: no readings", path);
        goto fail;
    }
    s = calloc(1, sizeof *s);
    if (!s || !(s->path = strdup(path)) || !(s->t = malloc(rows * sizeof *s->t)) ||
        !(s->probe = malloc(rows * sizeof *s->probe)) || !(s->value = malloc(rows * sizeof *s->value)) ||
        !(s->line = malloc(rows * sizeof *s->line))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    for (size_t r = 0; r < rows; ++r) {
        const size_t line = phc_table_row_line(t, r);
        const char *id = phc_table_cell(t, r, (size_t)c_p);
        long pi = phc_probe_find(probes, id);
        if (pi < 0) {
            char list[256] = "";
            for (size_t i = 0; i < probes->n && strlen(list) < 200; ++i) {
                size_t used = strlen(list);
                snprintf(list + used, sizeof list - used, "%s'%s'", i ? ", " : "", probes->probes[i].id);
            }
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': probe '%s' is not in %s (probes: %s)", path,
                               line, probe_col, id, probes->path, list);
            goto fail;
        }
        double tv, vv;
        if ((rc = cell_number(t, r, c_t, time_col, &tv, err)) || (rc = cell_number(t, r, c_v, value_col, &vv, err)))
            goto fail;
        tv = phc_unit_apply(tconv, tv);
        if (r > 0 && tv < s->t[r - 1]) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': time %s is before the previous reading's "
                               "(line %zu); readings must be in time order", path, line, time_col,
                               phc_table_cell(t, r, (size_t)c_t), s->line[r - 1]);
            goto fail;
        }
        s->t[r] = tv;
        s->probe[r] = (size_t)pi;
        s->value[r] = vv;
        s->line[r] = line;
        s->n = r + 1;
    }
    phc_table_free(t);
    *out = s;
    return PHC_OK;
fail:
    phc_table_free(t);
    phc_probe_series_free(s);
    return rc;
}
