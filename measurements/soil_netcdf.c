/* CF-1.8 NetCDF writer for the soil model: see soil_netcdf.h.
 *
 * Every netCDF call goes through NC_TRY, which turns a failure into
 * PHC_ERR_IO with the final path, what was being done and nc_strerror's
 * text, and jumps to the one cleanup path. */
#include "measurements/soil_netcdf.h"
#include "measurements/soil_netcdf_module_internal.h"

#include <ctype.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <netcdf.h>

#include "measurements/atomic_file.h"

/* Largest chunk of a time-dependent variable (bytes).  One frame per chunk
 * when it fits: appending then writes whole chunks, and readers that take
 * one time step read one chunk.  4 MiB stays inside HDF5's default chunk
 * cache. */
#define CHUNK_BYTES ((size_t)4 << 20)
/* Deflate level: 1 gets most of the gain on smooth fields at a fraction of
 * the cost of higher levels. */
#define DEFLATE_LEVEL 1

struct phc_soil_nc {
    int ncid;          /* -1 once closed */
    char *path;        /* final name */
    phc_atomic_file *af; /* the file until close (atomic_file.h) */
    size_t nx, ny, nz;
    int with_nutrient;
    int var_time, var_water, var_nutrient;
    size_t frames;
    double last_t;
};

/* Runs a netCDF call; on failure records the error and goes to fail. */
#define NC_TRY(call, what)                                                   \
    do {                                                                     \
        int nc_rc_ = (call);                                                 \
        if (nc_rc_ != NC_NOERR) {                                            \
            status = phc_error_set(err, PHC_ERR_IO, "%s: NetCDF: %s: %s",    \
                                   path, (what), nc_strerror(nc_rc_));       \
            goto fail;                                                       \
        }                                                                    \
    } while (0)

static char *dup_string(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

static int put_text(int ncid, int varid, const char *name, const char *value)
{
    return nc_put_att_text(ncid, varid, name, strlen(value), value);
}

static int put_double(int ncid, int varid, const char *name, double value)
{
    return nc_put_att_double(ncid, varid, name, NC_DOUBLE, 1, &value);
}

/* Matches exactly `n` decimal digits at *s and advances past them. */
static int digits(const char **s, int n)
{
    for (int i = 0; i < n; ++i)
        if (!isdigit((unsigned char)(*s)[i]))
            return 0;
    *s += n;
    return 1;
}

/* ISO 8601 as promised in the header: YYYY-MM-DD[(T| )hh:mm[:ss[.f+]]]
 * [Z|(+|-)hh[:]mm].  Also checks the month, day, hour and minute ranges,
 * because UDUNITS and cftime reject out-of-range fields only when the file
 * is read. */
static int iso_valid(const char *s)
{
    const char *p = s;
    if (!digits(&p, 4) || *p++ != '-' || !digits(&p, 2) || *p++ != '-' ||
        !digits(&p, 2))
        return 0;
    int mon = atoi(s + 5), day = atoi(s + 8);
    if (mon < 1 || mon > 12 || day < 1 || day > 31)
        return 0;
    if (*p == '\0')
        return 1;
    if (*p != 'T' && *p != ' ')
        return 0;
    const char *tp = ++p;
    if (!digits(&p, 2) || *p++ != ':' || !digits(&p, 2))
        return 0;
    if (atoi(tp) > 23 || atoi(tp + 3) > 59)
        return 0;
    if (*p == ':') {
        ++p;
        const char *sp = p;
        if (!digits(&p, 2) || atoi(sp) > 60)
            return 0;
        if (*p == '.') {
            ++p;
            if (!isdigit((unsigned char)*p))
                return 0;
            while (isdigit((unsigned char)*p))
                ++p;
        }
    }
    if (*p == 'Z')
        ++p;
    else if (*p == '+' || *p == '-') {
        ++p;
        if (!digits(&p, 2))
            return 0;
        if (*p == ':')
            ++p;
        if (!digits(&p, 2))
            return 0;
    }
    return *p == '\0';
}

/* Coordinate variable along one axis: voxel centres origin + (i + 1/2) dx. */
static int put_axis(int ncid, int varid, size_t n, double origin, double dx)
{
    double *v = malloc(n * sizeof *v);
    if (!v)
        return NC_ENOMEM;
    for (size_t i = 0; i < n; ++i)
        v[i] = origin + ((double)i + 0.5) * dx;
    int rc = nc_put_var_double(ncid, varid, v);
    free(v);
    return rc;
}

/* Chunk shape (1, cz, cy, nx) of a (time, z, y, x) variable: whole frames
 * when they fit in CHUNK_BYTES, else whole x rows over as many y and z as
 * fit (at least one row). */
static void chunk_shape(size_t nx, size_t ny, size_t nz, size_t chunk[4])
{
    size_t row = nx * sizeof(double);
    size_t rows = row >= CHUNK_BYTES ? 1 : CHUNK_BYTES / row;
    chunk[0] = 1;
    chunk[3] = nx;
    if (rows >= ny) {
        chunk[2] = ny;
        size_t planes = rows / ny;
        chunk[1] = planes < nz ? planes : nz;
    } else {
        chunk[2] = rows;
        chunk[1] = 1;
    }
}

/* Defines a (time, z, y, x) double variable, chunked and compressed. */
static int def_frame_var(int ncid, const char *name, const int dims[4],
                         const size_t chunk[4], int *varid)
{
    int rc = nc_def_var(ncid, name, NC_DOUBLE, 4, dims, varid);
    if (rc == NC_NOERR)
        rc = nc_def_var_chunking(ncid, *varid, NC_CHUNKED, chunk);
    if (rc == NC_NOERR)
        rc = nc_def_var_deflate(ncid, *varid, 1, 1, DEFLATE_LEVEL);
    return rc;
}

/* "2026-05-01T12:00:00Z" (UTC now) into buf, or "" if the clock fails. */
static void utc_now(char *buf, size_t size)
{
    time_t now = time(NULL);
    struct tm tm;
    buf[0] = '\0';
    if (now != (time_t)-1 && gmtime_r(&now, &tm))
        strftime(buf, size, "%Y-%m-%dT%H:%M:%SZ", &tm);
}

static int check_grid(const char *path, const phc_soil_nc_grid *g,
                      phc_error *err)
{
    if (g->nx == 0 || g->ny == 0 || g->nz == 0)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: soil grid: expected nx, ny, nz >= 1, found "
                             "%zu x %zu x %zu", path, g->nx, g->ny, g->nz);
    if (g->ny > SIZE_MAX / g->nx || g->nz > SIZE_MAX / (g->nx * g->ny) ||
        g->nx * g->ny * g->nz > SIZE_MAX / sizeof(double))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: soil grid: %zu x %zu x %zu voxels overflow "
                             "the address space", path, g->nx, g->ny, g->nz);
    if (!(g->dx > 0.0) || !isfinite(g->dx))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: soil grid: expected a voxel size dx > 0 m, "
                             "found %g", path, g->dx);
    for (int d = 0; d < 3; ++d)
        if (!isfinite(g->origin[d]))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "%s: soil grid: origin[%d]: expected a "
                                 "finite value (m), found %g", path, d,
                                 g->origin[d]);
    if (g->has_geo) {
        if (!(g->lat0 >= -90.0 && g->lat0 <= 90.0))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "%s: soil grid: lat0: expected degrees in "
                                 "[-90, 90], found %g", path, g->lat0);
        if (!(g->lon0 >= -180.0 && g->lon0 <= 360.0))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "%s: soil grid: lon0: expected degrees in "
                                 "[-180, 360], found %g", path, g->lon0);
        if (!isfinite(g->h0))
            return phc_error_set(err, PHC_ERR_INVALID,
                                 "%s: soil grid: h0: expected a finite "
                                 "height (m), found %g", path, g->h0);
    }
    return PHC_OK;
}

/* Global attributes. */
static int put_globals(int ncid, const phc_soil_nc_grid *g, const char *title)
{
    char history[128], buf[1024];
    char now[32];
    int rc;
    utc_now(now, sizeof now);
    snprintf(history, sizeof history, "%s%screated by phytocal "
             "(measurements/soil_netcdf.c)", now, *now ? ": " : "");
    if ((rc = put_text(ncid, NC_GLOBAL, "Conventions", "CF-1.8")) ||
        (rc = put_text(ncid, NC_GLOBAL, "title",
                       title && *title ? title : "phytocal soil model run")) ||
        (rc = put_text(ncid, NC_GLOBAL, "source", "phytocal")) ||
        (rc = put_text(ncid, NC_GLOBAL, "references",
                       "Li et al., Rhizomorph: the coordinated function of "
                       "shoots and roots, ACM TOG 42(4) 2023, section 6 "
                       "(soil water and nutrients)")) ||
        (rc = put_text(ncid, NC_GLOBAL, "history", history)) ||
        (rc = put_double(ncid, NC_GLOBAL, "voxel_size_m", g->dx)))
        return rc;
    if (!g->has_geo) {
        return put_text(ncid, NC_GLOBAL, "comment",
                        "x, y, z are voxel centres (m) in the model's own "
                        "Cartesian grid frame: x east, y north, z up; the "
                        "surface layer is the largest z.  The frame is not "
                        "tied to a geographic position.");
    }
    snprintf(buf, sizeof buf,
             "x, y, z are voxel centres (m) in a local east-north-up (ENU) "
             "Cartesian frame tangent to the WGS84 ellipsoid at latitude "
             "%.9g degrees north, longitude %.9g degrees east, height %.6g m "
             "above the ellipsoid (geospatial_lat_origin, "
             "geospatial_lon_origin, geospatial_vertical_origin): x east, "
             "y north, z up along the ellipsoid normal there.  The surface "
             "layer is the largest z.  The grid mapping 'crs' (orthographic "
             "projection centred on the origin) is the horizontal part of "
             "that frame.", g->lat0, g->lon0, g->h0);
    if ((rc = put_double(ncid, NC_GLOBAL, "geospatial_lat_origin", g->lat0)) ||
        (rc = put_double(ncid, NC_GLOBAL, "geospatial_lon_origin", g->lon0)) ||
        (rc = put_double(ncid, NC_GLOBAL, "geospatial_vertical_origin",
                         g->h0)) ||
        (rc = put_text(ncid, NC_GLOBAL, "geospatial_lat_units",
                       "degrees_north")) ||
        (rc = put_text(ncid, NC_GLOBAL, "geospatial_lon_units",
                       "degrees_east")) ||
        (rc = put_text(ncid, NC_GLOBAL, "geospatial_vertical_units", "m")) ||
        (rc = put_text(ncid, NC_GLOBAL, "geospatial_vertical_positive",
                       "up")) ||
        (rc = put_text(ncid, NC_GLOBAL, "comment", buf)))
        return rc;
    return NC_NOERR;
}

/* Attributes of a coordinate variable. */
static int put_axis_atts(int ncid, int varid, char axis, const char *long_name,
                         int has_geo)
{
    int rc;
    char a[2] = {axis, '\0'};
    if ((rc = put_text(ncid, varid, "units", "m")) ||
        (rc = put_text(ncid, varid, "axis", a)) ||
        (rc = put_text(ncid, varid, "long_name", long_name)))
        return rc;
    if (axis == 'Z')
        return put_text(ncid, varid, "positive", "up");
    if (has_geo)
        return put_text(ncid, varid, "standard_name",
                        axis == 'X' ? "projection_x_coordinate"
                                    : "projection_y_coordinate");
    return NC_NOERR;
}

int phc_soil_nc_create(const char *path, const phc_soil_nc_grid *g,
                       const char *title, const char *start_iso,
                       const double *capacity, const double *permeability,
                       phc_soil_nc **out, phc_error *err)
{
    phc_error_clear(err);
    if (out)
        *out = NULL;
    if (!path || !*path)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "soil NetCDF: no output path given");
    if (!g || !out || !capacity || !permeability)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: soil NetCDF: grid, capacity, permeability "
                             "and out must not be NULL", path);
    int status = check_grid(path, g, err);
    if (status)
        return status;
    if (start_iso && !iso_valid(start_iso))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s: start time: expected an ISO 8601 date such "
                             "as '2026-05-01T00:00:00Z', found '%s'", path,
                             start_iso);

    phc_soil_nc *nc = calloc(1, sizeof *nc);
    if (!nc)
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
    nc->ncid = -1;
    nc->nx = g->nx;
    nc->ny = g->ny;
    nc->nz = g->nz;
    nc->with_nutrient = g->with_nutrient != 0;
    nc->var_nutrient = -1;
    nc->path = dup_string(path);
    char *units = malloc((start_iso ? strlen(start_iso) : 0) + 64);
    if (!nc->path || !units) {
        status = phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", path);
        goto fail;
    }
    /* The temporary file is created first (atomic_file.h, with O_EXCL):
     * that gives the system's own reason when the directory is missing or
     * not writable (HDF5's failure maps to a misleading "Permission
     * denied"), and never overwrites a file that is not ours.  nc_create
     * then replaces our empty file. */
    if ((status = phc_atomic_file_open(path, &nc->af, err)))
        goto fail;
    {
        const char *tmp = phc_atomic_file_temp_path(nc->af);
        int rc = nc_create(tmp, NC_NETCDF4 | NC_CLOBBER, &nc->ncid);
        if (rc != NC_NOERR) {
            nc->ncid = -1;
            status = phc_error_set(err, PHC_ERR_IO,
                                   "%s: cannot create the NetCDF file "
                                   "(temporary name %s): %s", path,
                                   tmp, nc_strerror(rc));
            goto fail;
        }
    }
    int ncid = nc->ncid;
    int dim_t, dim_z, dim_y, dim_x;
    NC_TRY(nc_def_dim(ncid, "time", NC_UNLIMITED, &dim_t), "defining time");
    NC_TRY(nc_def_dim(ncid, "z", g->nz, &dim_z), "defining z");
    NC_TRY(nc_def_dim(ncid, "y", g->ny, &dim_y), "defining y");
    NC_TRY(nc_def_dim(ncid, "x", g->nx, &dim_x), "defining x");

    int var_x, var_y, var_z, var_cap, var_perm, var_crs = -1;
    NC_TRY(nc_def_var(ncid, "time", NC_DOUBLE, 1, &dim_t, &nc->var_time),
           "defining variable time");
    NC_TRY(nc_def_var(ncid, "z", NC_DOUBLE, 1, &dim_z, &var_z),
           "defining variable z");
    NC_TRY(nc_def_var(ncid, "y", NC_DOUBLE, 1, &dim_y, &var_y),
           "defining variable y");
    NC_TRY(nc_def_var(ncid, "x", NC_DOUBLE, 1, &dim_x, &var_x),
           "defining variable x");

    /* time */
    if (start_iso)
        sprintf(units, "hours since %s", start_iso);
    else
        strcpy(units, "hours since 0001-01-01 00:00:00");
    NC_TRY(put_text(ncid, nc->var_time, "units", units), "time:units");
    NC_TRY(put_text(ncid, nc->var_time, "calendar",
                    start_iso ? "standard" : "proleptic_gregorian"),
           "time:calendar");
    NC_TRY(put_text(ncid, nc->var_time, "standard_name", "time"),
           "time:standard_name");
    NC_TRY(put_text(ncid, nc->var_time, "long_name",
                    start_iso ? "time" : "model time since the start of the "
                    "run (no calendar date given)"), "time:long_name");
    NC_TRY(put_text(ncid, nc->var_time, "axis", "T"), "time:axis");

    /* space */
    NC_TRY(put_axis_atts(ncid, var_x, 'X', "x (east) of voxel centre",
                         g->has_geo), "x attributes");
    NC_TRY(put_axis_atts(ncid, var_y, 'Y', "y (north) of voxel centre",
                         g->has_geo), "y attributes");
    NC_TRY(put_axis_atts(ncid, var_z, 'Z',
                         g->has_geo ? "height of voxel centre above the "
                         "frame origin (up)" : "z (up) of voxel centre",
                         g->has_geo), "z attributes");

    if (g->has_geo) {
        /* CF §F "orthographic" on WGS84: the ellipsoidal orthographic
         * projection (EPSG method 9840) gives the east and north components
         * of the local tangent-plane (ENU) frame at the origin. */
        NC_TRY(nc_def_var(ncid, "crs", NC_INT, 0, NULL, &var_crs),
               "defining variable crs");
        NC_TRY(put_text(ncid, var_crs, "grid_mapping_name", "orthographic"),
               "crs attributes");
        NC_TRY(put_double(ncid, var_crs, "latitude_of_projection_origin",
                          g->lat0), "crs attributes");
        NC_TRY(put_double(ncid, var_crs, "longitude_of_projection_origin",
                          g->lon0), "crs attributes");
        NC_TRY(put_double(ncid, var_crs, "false_easting", 0.0),
               "crs attributes");
        NC_TRY(put_double(ncid, var_crs, "false_northing", 0.0),
               "crs attributes");
        NC_TRY(put_double(ncid, var_crs, "semi_major_axis", 6378137.0),
               "crs attributes");
        NC_TRY(put_double(ncid, var_crs, "inverse_flattening", 298.257223563),
               "crs attributes");
        NC_TRY(put_text(ncid, var_crs, "long_name", "local east-north-up "
                        "tangent plane at the grid origin (WGS84)"),
               "crs attributes");
    }

    int dims3[3] = {dim_z, dim_y, dim_x};
    int dims4[4] = {dim_t, dim_z, dim_y, dim_x};
    size_t chunk[4];
    chunk_shape(g->nx, g->ny, g->nz, chunk);

    NC_TRY(nc_def_var(ncid, "capacity", NC_DOUBLE, 3, dims3, &var_cap),
           "defining variable capacity");
    NC_TRY(put_text(ncid, var_cap, "units", "1"), "capacity attributes");
    NC_TRY(put_text(ncid, var_cap, "long_name", "soil water capacity "
                    "(w / capacity is the fill level that drives diffusion)"),
           "capacity attributes");
    NC_TRY(nc_def_var(ncid, "permeability", NC_DOUBLE, 3, dims3, &var_perm),
           "defining variable permeability");
    NC_TRY(put_text(ncid, var_perm, "units", "m h-1"),
           "permeability attributes");
    NC_TRY(put_text(ncid, var_perm, "long_name", "soil permeability "
                    "(gravity drainage velocity at unit gravity force; "
                    "0 blocks flow)"), "permeability attributes");

    NC_TRY(def_frame_var(ncid, "water", dims4, chunk, &nc->var_water),
           "defining variable water");
    NC_TRY(put_text(ncid, nc->var_water, "units", "m3 m-3"),
           "water attributes");
    NC_TRY(put_text(ncid, nc->var_water, "long_name",
                    "volumetric water content"), "water attributes");
    NC_TRY(put_text(ncid, nc->var_water, "standard_name",
                    "volume_fraction_of_condensed_water_in_soil"),
           "water attributes");
    if (nc->with_nutrient) {
        NC_TRY(def_frame_var(ncid, "nutrient", dims4, chunk,
                             &nc->var_nutrient), "defining variable nutrient");
        /* Model nutrient units per cubic metre of soil (model/soil.h). */
        NC_TRY(put_text(ncid, nc->var_nutrient, "units", "m-3"),
               "nutrient attributes");
        NC_TRY(put_text(ncid, nc->var_nutrient, "long_name",
                        "nutrient concentration (model nutrient units per "
                        "cubic metre of soil)"), "nutrient attributes");
    }
    if (g->has_geo) {
        int vars[4] = {var_cap, var_perm, nc->var_water, nc->var_nutrient};
        for (int v = 0; v < 4; ++v)
            if (vars[v] >= 0)
                NC_TRY(put_text(ncid, vars[v], "grid_mapping", "crs"),
                       "grid_mapping attributes");
    }
    NC_TRY(put_globals(ncid, g, title), "global attributes");
    NC_TRY(nc_enddef(ncid), "ending define mode");

    NC_TRY(put_axis(ncid, var_x, g->nx, g->origin[0], g->dx), "writing x");
    NC_TRY(put_axis(ncid, var_y, g->ny, g->origin[1], g->dx), "writing y");
    NC_TRY(put_axis(ncid, var_z, g->nz, g->origin[2], g->dx), "writing z");
    if (var_crs >= 0) {
        int zero = 0;
        NC_TRY(nc_put_var_int(ncid, var_crs, &zero), "writing crs");
    }
    NC_TRY(nc_put_var_double(ncid, var_cap, capacity), "writing capacity");
    NC_TRY(nc_put_var_double(ncid, var_perm, permeability),
           "writing permeability");
    NC_TRY(nc_sync(ncid), "flushing");

    free(units);
    *out = nc;
    return PHC_OK;

fail:
    free(units);
    if (nc->ncid >= 0)
        nc_close(nc->ncid);
    phc_atomic_file_abort(nc->af);
    free(nc->path);
    free(nc);
    return status;
}

int phc_soil_nc_append(phc_soil_nc *nc, double t_hours, const double *water,
                       const double *nutrient, phc_error *err)
{
    phc_error_clear(err);
    if (!nc)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "soil NetCDF: append to a NULL writer");
    const char *path = nc->path;
    if (nc->ncid < 0)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: append after the file was closed", path);
    if (!water)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: frame %zu: water must not be NULL", path,
                             nc->frames);
    if (nc->with_nutrient && !nutrient)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: frame %zu: the file was created with "
                             "nutrients, found nutrient = NULL", path,
                             nc->frames);
    if (!nc->with_nutrient && nutrient)
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: frame %zu: the file was created without "
                             "nutrients (with_nutrient = 0), but nutrient "
                             "values were given", path, nc->frames);
    if (!isfinite(t_hours))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: frame %zu: expected a finite time (h), "
                             "found %g", path, nc->frames, t_hours);
    if (nc->frames > 0 && !(t_hours > nc->last_t))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "%s: frame %zu: time must increase: expected "
                             "t > %.17g h, found %.17g h", path, nc->frames,
                             nc->last_t, t_hours);

    int status = PHC_OK;
    int ncid = nc->ncid;
    size_t start[4] = {nc->frames, 0, 0, 0};
    size_t count[4] = {1, nc->nz, nc->ny, nc->nx};
    char what[64];
    snprintf(what, sizeof what, "writing frame %zu", nc->frames);
    NC_TRY(nc_put_var1_double(ncid, nc->var_time, start, &t_hours), what);
    NC_TRY(nc_put_vara_double(ncid, nc->var_water, start, count, water),
           what);
    if (nc->with_nutrient)
        NC_TRY(nc_put_vara_double(ncid, nc->var_nutrient, start, count,
                                  nutrient), what);
    NC_TRY(nc_sync(ncid), what);
    nc->frames++;
    nc->last_t = t_hours;
    return PHC_OK;
fail:
    return status;
}

size_t phc_soil_nc_frames(const phc_soil_nc *nc)
{
    return nc ? nc->frames : 0;
}

int phc_soil_nc_close(phc_soil_nc *nc, phc_error *err)
{
    phc_error_clear(err);
    if (!nc)
        return PHC_OK;
    int status = PHC_OK;
    const char *path = nc->path;
    if (nc->ncid >= 0) {
        int rc = nc_close(nc->ncid);
        nc->ncid = -1;
        if (rc != NC_NOERR) {
            status = phc_error_set(err, PHC_ERR_IO,
                                   "%s: NetCDF: closing the temporary file "
                                   "%s (left in place): %s", path,
                                   phc_atomic_file_temp_path(nc->af),
                                   nc_strerror(rc));
            phc_atomic_file_leave(nc->af);
        } else {
            status = phc_atomic_file_commit(nc->af, err);
        }
    } else {
        phc_atomic_file_abort(nc->af);
    }
    free(nc->path);
    free(nc);
    return status;
}

/* ---- the module's entry point (soil_netcdf_module_internal.h) ------------ */

/* This file is compiled into phytocal_netcdf.so, which libphytocal opens on
 * the first soil_netcdf.h call (measurements/soil_netcdf_module.c). */
static const phc_netcdf_module_table netcdf_module = {phc_soil_nc_create, phc_soil_nc_append, phc_soil_nc_frames,
                                                       phc_soil_nc_close};

const void *phc_netcdf_module_entry(int abi)
{
    return abi == PHC_NETCDF_MODULE_ABI ? &netcdf_module : NULL;
}
