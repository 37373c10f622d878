/* Tracked plant motion over time (issue 19, `shape_series` data sets): points
 * or organ angles read from a CSV as a tracker writes it.
 *
 * The table is read by measurements/table.h (header line, ',' ';' or tab,
 * quotes, CRLF, '#' comments), so column names are used exactly as written,
 * spaces and parentheses included: "Time (s)", "Point 3 (x)",
 * "Flower 1 Angle (deg)".  Other columns ("Frame") are ignored.
 *
 * The caller names the columns and their units (phc_shape_spec):
 *  - a time column and its unit, any UDUNITS-2 time unit ("s", "min", "h",
 *    "d"); times are converted to seconds and must increase strictly;
 *  - one or more series, each with an id and either
 *    * a point: x, y and optionally z columns, in a UDUNITS-2 length unit
 *      ("mm", "cm", "m") or in pixels ("px", "pixel", "pixels") with a scale
 *      in m/px; with y_down (image rows: y grows downwards) y is negated so
 *      that the output's y points up; output in metres;
 *    * an angle: one column in "deg" ("degree", "degrees", "arc_degree",
 *      "arcdeg", "°") or "rad" ("radian", "radians"); not through UDUNITS-2,
 *      where the radian is dimensionless and "percent" would pass as an
 *      angle; output in radians, unwrapped: each sample is moved by a multiple of
 *      2 pi so that it differs from the previous one by at most pi, so a
 *      track that passes 360 deg -> 0 deg continues to 361, 362 ...; with
 *      y_down (an angle measured in image axes, clockwise on screen) the
 *      angle is negated before unwrapping, so the output turns
 *      counter-clockwise with y up.  `unwrap = 0` keeps the values as read.
 *
 * Errors (PHC_ERR_INPUT unless said otherwise) say what and where:
 *  - the spec's own mistakes name the spec location `where` given by the
 *    caller (e.g. "config.yaml:14: shape_series 'flower4'"): an unknown
 *    column, with the table's "did you mean" (measurements/suggest.h) and
 *    the list of columns; an unknown or unconvertible unit; a pixel unit
 *    without a positive scale; a duplicate or empty series id;
 *  - the data's name the file and line: a missing, non-numeric or NaN cell
 *    ("points.csv:17: column 'Point 3 (x)': expected a finite number, found
 *    'nan'"); a time not after the previous row's ("angles.csv:9: column
 *    'Time (s)': time 70 s is not after the previous row's 80 s (line 8);
 *    times must increase strictly"); a table with no data rows. */
#ifndef PHC_SHAPE_SERIES_H
#define PHC_SHAPE_SERIES_H

#include <stddef.h>

#include "measurements/units.h"
#include "model/status.h"

typedef enum phc_shape_kind {
    PHC_SHAPE_POINT = 0, /* x, y[, z] in m */
    PHC_SHAPE_ANGLE      /* one angle in rad */
} phc_shape_kind;

/* One tracked series: a point or an angle. */
typedef struct phc_shape_series_spec {
    const char *id;               /* series id (unique, non-empty): "flower4", "point 3" */
    phc_shape_kind kind;
    const char *x, *y, *z;        /* POINT: column names; z NULL for 2-D tracks */
    const char *length_unit;      /* POINT: UDUNITS-2 length unit, or "px"/"pixel"/"pixels" */
    double metres_per_pixel;      /* POINT in pixels: scale, m/px, > 0 */
    const char *angle;            /* ANGLE: column name */
    const char *angle_unit;       /* ANGLE: "deg" or "rad" (aliases above) */
    int y_down;                   /* 1: image axes (y down): y (or the angle) is negated */
    int keep_wrapped;             /* ANGLE: 1 keeps the angle as read (no unwrapping) */
    const char *where;            /* for messages about this spec, e.g. "cfg.yaml:14"; may be NULL */
} phc_shape_series_spec;

typedef struct phc_shape_spec {
    const char *time;             /* column name */
    const char *time_unit;        /* UDUNITS-2 time unit */
    const char *where;            /* for messages about the time column; may be NULL */
    size_t n_series;
    const phc_shape_series_spec *series;
} phc_shape_spec;

typedef struct phc_shape_track {
    char *id;
    phc_shape_kind kind;
    size_t dim;                   /* 1 (angle), 2 or 3 (point) */
    double *value;                /* n_times x dim row-major: m or rad */
} phc_shape_track;

typedef struct phc_shape_series {
    char *source;                 /* the path read */
    size_t n_times;
    double *t;                    /* s, strictly increasing, as converted (not shifted) */
    size_t *line;                 /* 1-based file line of each sample */
    size_t n_tracks;
    phc_shape_track *tracks;      /* in the spec's order */
} phc_shape_series;

/* Reads `path` as described above.  `units` is a loaded UDUNITS-2 database
 * (measurements/units.h), or NULL to load one for this call.  On success
 * *out owns everything (free with phc_shape_series_free); on failure *out is
 * NULL and nothing is left allocated. */
int phc_shape_series_read(const char *path, const phc_shape_spec *spec, phc_units *units,
                          phc_shape_series **out, phc_error *err);

/* The same from text in memory; `name` stands for the path in messages. */
int phc_shape_series_parse(const char *text, size_t length, const char *name,
                           const phc_shape_spec *spec, phc_units *units,
                           phc_shape_series **out, phc_error *err);

void phc_shape_series_free(phc_shape_series *s); /* accepts NULL */

/* Index of the track with this id, or -1. */
long phc_shape_series_find(const phc_shape_series *s, const char *id);

/* Unwraps n angles (rad) in place: a[i] += 2 pi k_i so that
 * |a[i] - a[i-1]| <= pi.  Exposed for tests and for callers with angles
 * from elsewhere. */
void phc_angle_unwrap(double *a, size_t n);

#endif /* PHC_SHAPE_SERIES_H */
