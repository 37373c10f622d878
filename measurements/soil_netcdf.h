/* CF-1.8 NetCDF output of the 3-D soil model (model/soil.h).
 *
 * One file holds one run: the static fields capacity c (dimensionless) and
 * permeability p (m/h) on (z, y, x), and one frame per call of
 * phc_soil_nc_append of water w (m^3/m^3) and, optionally, nutrients v
 * (nutrient units per m^3) on (time, z, y, x).
 *
 * Format: NetCDF-4 (HDF5 storage, "classic model" is not imposed).  Why not
 * the classic 64-bit-offset format: the time-dependent fields of a soil run
 * are large and mostly smooth or zero, and only NetCDF-4 can compress them
 * (deflate + shuffle, chunked one frame per chunk, so appending a frame
 * never rewrites earlier ones).  Every current reader opens NetCDF-4:
 * xarray (netCDF4 and h5netcdf engines), Panoply, ParaView's "NetCDF CF"
 * reader, ncview, NCO/CDO, MATLAB, R.  (Only xarray's pure-Python scipy
 * engine is limited to the classic formats.)
 *
 * Layout: voxel (i, j, k) is element i + nx (j + ny k) of every array, which
 * is exactly C order of a (z, y, x) variable: the arrays are written as they
 * are, without copying.  x east, y north, z up; k = nz - 1 is the surface
 * layer.  Coordinates are the voxel centres origin + (index + 1/2) dx (m) in
 * the grid frame.  With a geographic origin (has_geo) the grid frame is the
 * local east-north-up (ENU) frame tangent to the WGS84 ellipsoid at
 * (lat0, lon0, h0) (GeographicLib's LocalCartesian); the file then carries a
 * CF "orthographic" grid mapping centred there, which is the ellipsoidal
 * form of that tangent-plane projection, so GIS-aware readers can place the
 * grid (heights: z is height above the tangent plane through h0, which
 * departs from height above the ellipsoid by x^2/(2 R) ~ 8 mm at 300 m).
 *
 * The file is written under a temporary name next to `path`
 * (path.tmp-XXXXXX, claimed with O_EXCL: measurements/atomic_file.h) and
 * renamed to `path` by phc_soil_nc_close (DESIGN §3):
 * a run that dies leaves no half-written file under the final name.
 * An existing file at `path` is replaced at close.
 *
 * Threads: the netCDF-C library is not thread-safe; use one writer at a
 * time per process.  No globals here; the writer object is caller-owned. */
#ifndef PHC_SOIL_NETCDF_H
#define PHC_SOIL_NETCDF_H

#include <stddef.h>

#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct phc_soil_nc phc_soil_nc;

typedef struct phc_soil_nc_grid {
    size_t nx, ny, nz;  /* voxels along x (east), y (north), z (up); >= 1 */
    double dx;          /* voxel edge (m), > 0 */
    double origin[3];   /* corner of voxel (0,0,0) in the grid frame (m) */
    int has_geo;        /* nonzero: lat0, lon0, h0 locate the grid frame */
    double lat0;        /* latitude of the frame origin (degrees north, WGS84) */
    double lon0;        /* longitude of the frame origin (degrees east) */
    double h0;          /* height of the frame origin above the ellipsoid (m) */
    int with_nutrient;  /* nonzero: define the nutrient variable; every
                           append must then pass nutrients, else none */
} phc_soil_nc_grid;

/* Creates the writer for `path` (see above for the temporary name) and
 * writes dimensions time (unlimited), z, y, x; coordinates x, y, z (m) and
 * time (h); capacity and permeability (nx*ny*nz values each, layout above);
 * and the global attributes (Conventions "CF-1.8", title, source, history,
 * and with has_geo the geospatial_*_origin attributes and a comment on the
 * ENU frame).
 *
 * title: free text (NULL: "phytocal soil model run").
 * start_iso: the calendar time of t = 0, ISO 8601 "YYYY-MM-DD", optionally
 *   followed by "Thh:mm[:ss[.fff]]" (or a space instead of T) and "Z" or a
 *   "+hh:mm" offset, e.g. "2026-05-01T00:00:00Z"; time units become
 *   "hours since <start_iso>", calendar "standard".  NULL: model time
 *   without a date, "hours since 0001-01-01 00:00:00" with calendar
 *   "proleptic_gregorian" (the conventional CF placeholder epoch).
 *
 * Returns PHC_OK and *out, or PHC_ERR_INVALID (bad grid or arguments),
 * PHC_ERR_INPUT (start_iso not ISO 8601), PHC_ERR_IO (netCDF failure: the
 * message names `path` and gives nc_strerror's text), PHC_ERR_NOMEM. */
int phc_soil_nc_create(const char *path, const phc_soil_nc_grid *g,
                       const char *title, const char *start_iso,
                       const double *capacity, const double *permeability,
                       phc_soil_nc **out, phc_error *err);

/* Appends one frame at model time t_hours (h; finite and larger than the
 * previous frame's: CF time coordinates are strictly monotonic).  water and,
 * when the grid had with_nutrient, nutrient hold nx*ny*nz values.  nutrient
 * must be NULL exactly when with_nutrient was 0 (nothing is dropped
 * silently).  The frame is flushed to disk before returning, so a reader (or
 * a crash) sees every completed frame in the temporary file. */
int phc_soil_nc_append(phc_soil_nc *nc, double t_hours, const double *water,
                       const double *nutrient, phc_error *err);

/* Number of frames appended so far (0 for NULL). */
size_t phc_soil_nc_frames(const phc_soil_nc *nc);

/* Closes the file, renames it to its final path and frees the writer, also
 * when it fails.  When netCDF cannot close the file, the temporary file is
 * left in place for inspection and the message names it; when the finished
 * file cannot be flushed or renamed into place, it is removed and an earlier
 * file at `path` stays.  Accepts NULL. */
int phc_soil_nc_close(phc_soil_nc *nc, phc_error *err);

#ifdef __cplusplus
}
#endif

#endif /* PHC_SOIL_NETCDF_H */
