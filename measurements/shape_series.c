/* Tracked plant motion from a CSV (shape_series.h). */
#include "measurements/shape_series.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "measurements/table.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

void phc_angle_unwrap(double *a, size_t n)
{
    const double two_pi = 2.0 * M_PI;
    double shift = 0.0;
    for (size_t i = 1; i < n; ++i) {
        /* the raw step, and the multiple of 2 pi that brings it into [-pi, pi] */
        const double raw = a[i] + shift - a[i - 1];
        shift -= two_pi * floor(raw / two_pi + 0.5);
        a[i] += shift;
    }
}

void phc_shape_series_free(phc_shape_series *s)
{
    if (!s)
        return;
    for (size_t k = 0; k < s->n_tracks; ++k) {
        free(s->tracks[k].id);
        free(s->tracks[k].value);
    }
    free(s->tracks);
    free(s->t);
    free(s->line);
    free(s->source);
    free(s);
}

long phc_shape_series_find(const phc_shape_series *s, const char *id)
{
    for (size_t k = 0; s && id && k < s->n_tracks; ++k)
        if (strcmp(s->tracks[k].id, id) == 0)
            return (long)k;
    return -1;
}

static char *dup_string(const char *s)
{
    const size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

/* "cfg.yaml:14: " or "" */
static void where_prefix(const char *where, char *buf, size_t size)
{
    if (where && *where)
        snprintf(buf, size, "%s: ", where);
    else
        buf[0] = '\0';
}

static int is_one_of(const char *s, const char *const *names)
{
    for (; *names; ++names)
        if (strcmp(s, *names) == 0)
            return 1;
    return 0;
}

static const char *const pixel_names[] = {"px", "pixel", "pixels", NULL};
static const char *const degree_names[] = {"deg",    "degree", "degrees",
                                           "arc_degree", "arcdeg", "\xc2\xb0", NULL};
static const char *const radian_names[] = {"rad", "radian", "radians", NULL};

/* Checks the spec before any file is read. */
static int check_spec(const phc_shape_spec *spec, phc_error *err)
{
    char w[512];
    if (!spec)
        return phc_error_set(err, PHC_ERR_INVALID, "shape series: no column spec given");
    where_prefix(spec->where, w, sizeof w);
    if (!spec->time || !*spec->time)
        return phc_error_set(err, PHC_ERR_INPUT, "%sshape series: no time column named", w);
    if (!spec->time_unit || !*spec->time_unit)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%sshape series: time column '%s' has no unit (give one such as "
                             "s, min or h)",
                             w, spec->time);
    if (spec->n_series == 0 || !spec->series)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%sshape series: no series named (give at least one point or angle)",
                             w);
    for (size_t k = 0; k < spec->n_series; ++k) {
        const phc_shape_series_spec *s = &spec->series[k];
        where_prefix(s->where ? s->where : spec->where, w, sizeof w);
        if (!s->id || !*s->id)
            return phc_error_set(err, PHC_ERR_INPUT, "%sshape series: series %zu has no id", w,
                                 k + 1);
        for (size_t j = 0; j < k; ++j)
            if (strcmp(spec->series[j].id, s->id) == 0)
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%sshape series: series id '%s' is used twice (series %zu "
                                     "and %zu)",
                                     w, s->id, j + 1, k + 1);
        if (s->kind == PHC_SHAPE_POINT) {
            if (!s->x || !*s->x || !s->y || !*s->y)
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%sseries '%s': a point needs x and y columns", w, s->id);
            if (s->z && !*s->z)
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%sseries '%s': empty z column name", w, s->id);
            if (!s->length_unit || !*s->length_unit)
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%sseries '%s': no length unit (give mm, cm, m, or px with "
                                     "a scale in m/px)",
                                     w, s->id);
            if (is_one_of(s->length_unit, pixel_names) &&
                (!(s->metres_per_pixel > 0) || !isfinite(s->metres_per_pixel)))
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%sseries '%s': coordinates in pixels need a scale in m/px "
                                     "(positive and finite), found %g",
                                     w, s->id, s->metres_per_pixel);
        } else if (s->kind == PHC_SHAPE_ANGLE) {
            if (!s->angle || !*s->angle)
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%sseries '%s': an angle series needs an angle column", w,
                                     s->id);
            if (!s->angle_unit || !*s->angle_unit)
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%sseries '%s': no angle unit (give deg or rad)", w, s->id);
        } else {
            return phc_error_set(err, PHC_ERR_INVALID, "%sseries '%s': unknown kind %d", w,
                                 s->id, (int)s->kind);
        }
    }
    return PHC_OK;
}

/* The numbers of column `name`; an unknown column is reported with the
 * spec's location before the table's "unknown column ...; did you mean". */
static int column(const phc_table *t, const char *name, const char *where, const char *id,
                  double **values, phc_error *err)
{
    int rc;
    if (phc_table_find(t, name) < 0) {
        rc = phc_table_column_numbers(t, name, values, err);
        if (rc == PHC_OK) { /* cannot happen: the column is absent */
            free(*values);
            *values = NULL;
            rc = phc_error_set(err, PHC_ERR_INTERNAL, "column '%s' vanished", name);
        }
        char w[512];
        where_prefix(where, w, sizeof w);
        if (id)
            return phc_error_prefix(err, rc, "%sseries '%s'", w, id);
        return phc_error_prefix(err, rc, "%stime column", w);
    }
    return phc_table_column_numbers(t, name, values, err);
}

/* Scale (and offset) taking the series' values to m or rad. */
static int series_conversion(const phc_shape_series_spec *s, const char *where, phc_units *units,
                             phc_unit_conversion *c, phc_error *err)
{
    char w[700];
    const char *wp = where && *where ? where : NULL;
    if (s->kind == PHC_SHAPE_POINT) {
        if (is_one_of(s->length_unit, pixel_names)) {
            c->scale = s->metres_per_pixel;
            c->offset = 0;
            return PHC_OK;
        }
        snprintf(w, sizeof w, "%s%sseries '%s': length unit", wp ? wp : "", wp ? ": " : "",
                 s->id);
        return phc_units_conversion(units, s->length_unit, "m", w, c, err);
    }
    if (is_one_of(s->angle_unit, degree_names)) {
        c->scale = M_PI / 180.0;
        c->offset = 0;
        return PHC_OK;
    }
    if (is_one_of(s->angle_unit, radian_names)) {
        c->scale = 1.0;
        c->offset = 0;
        return PHC_OK;
    }
    /* Not through UDUNITS-2: there the radian is dimensionless, so "percent"
     * or "1" would convert to radians without complaint. */
    return phc_error_set(err, PHC_ERR_INPUT,
                         "%s%sseries '%s': angle unit '%s' is not one phytocal reads (use deg "
                         "or rad; also degree(s), arc_degree, arcdeg, radian(s))",
                         wp ? wp : "", wp ? ": " : "", s->id, s->angle_unit);
}

static int build(const phc_table *t, const phc_shape_spec *spec, phc_units *units,
                 phc_shape_series *out, phc_error *err)
{
    const size_t rows = phc_table_rows(t);
    const char *src = phc_table_source(t);
    double *col = NULL;
    int rc;
    char w[700];

    if (rows == 0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s: no data rows (only a header): a shape series needs at least "
                             "one time",
                             src);
    /* time */
    {
        phc_unit_conversion tc;
        snprintf(w, sizeof w, "%s%stime unit", spec->where ? spec->where : "",
                 spec->where ? ": " : "");
        if ((rc = phc_units_conversion(units, spec->time_unit, "s", w, &tc, err)))
            return rc;
        if ((rc = column(t, spec->time, spec->where, NULL, &out->t, err)))
            return rc;
        out->n_times = rows;
        out->line = malloc(rows * sizeof *out->line);
        if (!out->line)
            return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", src);
        for (size_t r = 0; r < rows; ++r) {
            const double raw = out->t[r];
            out->t[r] = phc_unit_apply(tc, raw);
            out->line[r] = phc_table_row_line(t, r);
            if (r > 0 && !(out->t[r] > out->t[r - 1]))
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%s:%zu: column '%s': time %.10g %s is not after the "
                                     "previous row's %.10g %s (line %zu); times must increase "
                                     "strictly",
                                     src, out->line[r], spec->time, raw, spec->time_unit,
                                     (out->t[r - 1] - tc.offset) / tc.scale, spec->time_unit,
                                     out->line[r - 1]);
        }
    }
    /* series */
    out->tracks = calloc(spec->n_series, sizeof *out->tracks);
    if (!out->tracks)
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", src);
    for (size_t k = 0; k < spec->n_series; ++k) {
        const phc_shape_series_spec *s = &spec->series[k];
        const char *where = s->where ? s->where : spec->where;
        phc_shape_track *tr = &out->tracks[k];
        phc_unit_conversion c;
        out->n_tracks = k + 1;
        tr->id = dup_string(s->id);
        tr->kind = s->kind;
        tr->dim = s->kind == PHC_SHAPE_ANGLE ? 1 : (s->z ? 3 : 2);
        tr->value = malloc(rows * tr->dim * sizeof *tr->value);
        if (!tr->id || !tr->value)
            return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", src);
        if ((rc = series_conversion(s, where, units, &c, err)))
            return rc;
        const char *names[3] = {s->kind == PHC_SHAPE_ANGLE ? s->angle : s->x, s->y, s->z};
        for (size_t d = 0; d < tr->dim; ++d) {
            if ((rc = column(t, names[d], where, s->id, &col, err)))
                return rc;
            /* image axes: y (d == 1) or the angle (clockwise on screen) flip sign */
            const double sign = s->y_down && (s->kind == PHC_SHAPE_ANGLE || d == 1) ? -1.0 : 1.0;
            for (size_t r = 0; r < rows; ++r)
                tr->value[r * tr->dim + d] = sign * phc_unit_apply(c, col[r]);
            free(col);
            col = NULL;
        }
        if (s->kind == PHC_SHAPE_ANGLE && !s->keep_wrapped)
            phc_angle_unwrap(tr->value, rows);
    }
    return PHC_OK;
}

static int read_common(const char *path, const char *text, size_t length,
                       const phc_shape_spec *spec, phc_units *units, phc_shape_series **out,
                       phc_error *err)
{
    phc_table *t = NULL;
    phc_units *own = NULL;
    phc_shape_series *s = NULL;
    int rc;

    *out = NULL;
    if ((rc = check_spec(spec, err)))
        return rc;
    rc = text ? phc_table_parse(text, length, path, &t, err) : phc_table_read(path, &t, err);
    if (rc)
        return rc;
    if (!units) {
        own = phc_units_new(err);
        if (!own) {
            phc_table_free(t);
            return err ? err->status : PHC_ERR_IO;
        }
        units = own;
    }
    s = calloc(1, sizeof *s);
    if (!s || !(s->source = dup_string(path))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        goto done;
    }
    rc = build(t, spec, units, s, err);
done:
    phc_table_free(t);
    phc_units_free(own);
    if (rc) {
        phc_shape_series_free(s);
        return rc;
    }
    *out = s;
    return PHC_OK;
}

int phc_shape_series_read(const char *path, const phc_shape_spec *spec, phc_units *units,
                          phc_shape_series **out, phc_error *err)
{
    if (!path || !out)
        return phc_error_set(err, PHC_ERR_INVALID, "shape series: no path or output given");
    return read_common(path, NULL, 0, spec, units, out, err);
}

int phc_shape_series_parse(const char *text, size_t length, const char *name,
                           const phc_shape_spec *spec, phc_units *units,
                           phc_shape_series **out, phc_error *err)
{
    if (!text || !out)
        return phc_error_set(err, PHC_ERR_INVALID, "shape series: no text or output given");
    return read_common(name ? name : "(text)", text, length, spec, units, out, err);
}
