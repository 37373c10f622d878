/* Soil-moisture probes: where they are, and what they read over time.
 *
 * A probe table (CSV, one row per probe) gives each probe's id and its
 * position, either in the soil grid's frame (x east, y north in metres from
 * the grid's west-south corner, depth in metres below the top of the soil)
 * or geographically (latitude, longitude as decimal degrees or strings such
 * as "43.6481 N", and depth), optionally with a standard deviation per
 * probe.  Geographic positions are placed on the grid through the local
 * east-north-up frame at the grid's georeferenced origin (measurements/geo.h,
 * GeographicLib): x = east, y = north.
 *
 * A reading series (CSV, one row per reading) gives time, probe id and value.
 * Rows must be in time order (equal times are fine: several probes read at
 * once); a probe id not in the table is an error naming the line and the
 * ids that exist. */
#ifndef PHC_SOIL_PROBES_H
#define PHC_SOIL_PROBES_H

#include <stddef.h>

#include "measurements/geo.h"
#include "measurements/units.h"
#include "model/status.h"

typedef struct phc_probe {
    char *id;
    double x, y;    /* m, grid frame (east, north from the grid origin) */
    double depth;   /* m below the top of the soil, >= 0 */
    double sigma;   /* standard deviation of its readings (value unit), or NAN */
    int geographic; /* 1 when placed from latitude and longitude */
    double lat, lon;/* degrees, when geographic */
    size_t line;    /* 1-based line in the probe table */
} phc_probe;

typedef struct phc_probe_table {
    char *path;
    phc_probe *probes;
    size_t n;
} phc_probe_table;

/* Column names of the probe table; NULL = absent.  Give id, depth and
 * either x and y or lat and lon. */
typedef struct phc_probe_columns {
    const char *id, *x, *y, *lat, *lon, *depth, *sigma;
} phc_probe_columns;

/* Reads a probe table.  `frame` is the grid's georeferenced origin, needed
 * (non-NULL) when the table gives latitude and longitude.  Errors
 * (PHC_ERR_INPUT) name the file and line: a duplicate id, a negative depth
 * or sigma, an unparseable coordinate, latitude and longitude without a
 * georeferenced grid. */
int phc_probe_table_read(const char *path, const phc_probe_columns *cols, const phc_geo_frame *frame,
                         phc_probe_table **out, phc_error *err);
void phc_probe_table_free(phc_probe_table *t);
/* Index of the probe with this id, or -1. */
long phc_probe_find(const phc_probe_table *t, const char *id);

typedef struct phc_probe_series {
    char *path;
    size_t n;
    double *t;        /* converted with the caller's time conversion */
    size_t *probe;    /* index into the probe table */
    double *value;
    size_t *line;     /* 1-based line of each reading */
} phc_probe_series;

/* Reads readings (time, probe, value columns); times go through `tconv`
 * (for example to hours).  Errors name file and line: an unknown probe id,
 * a time before the previous row's, a non-finite number. */
int phc_probe_series_read(const char *path, const char *time_col, phc_unit_conversion tconv,
                          const char *probe_col, const char *value_col,
                          const phc_probe_table *probes, phc_probe_series **out, phc_error *err);
void phc_probe_series_free(phc_probe_series *s);

#endif /* PHC_SOIL_PROBES_H */
