/* Coordinates of measurement sites: latitude/longitude strings, local
 * east-north-up (ENU) frames and geodesic distances on the WGS84 ellipsoid.
 *
 * A plain C interface to GeographicLib (C. F. F. Karney, "Algorithms for
 * geodesics", J. Geodesy 87:43-55, 2013).  Only measurements/geo_bridge.cc
 * touches GeographicLib; no C++ type appears here.  Classes used:
 *   GeographicLib::DMS             parsing "43°38'53.2\"N", "79.3832 W" ...
 *   GeographicLib::LocalCartesian  geodetic <-> local east-north-up
 *   GeographicLib::Geodesic        WGS84 geodesic distance (Inverse)
 *
 * Units: angles in degrees (latitude positive north, longitude positive
 * east), heights in metres above the WGS84 ellipsoid (not above the geoid or
 * mean sea level: GPS heights usually are ellipsoidal, survey heights often
 * are not), distances and ENU coordinates in metres.
 *
 * Errors: every function returns PHC_OK (0) or a positive enum phc_status
 * and fills `err` (which may be NULL).  PHC_ERR_INVALID: a NULL pointer;
 * PHC_ERR_INPUT: a value that cannot be a coordinate (bad string, latitude
 * outside [-90, 90], non-finite number); PHC_ERR_NOMEM / PHC_ERR_INTERNAL:
 * failures inside GeographicLib.  Nothing here keeps global state: all
 * functions are safe to call from several threads. */
#ifndef PHC_GEO_H
#define PHC_GEO_H

#include "model/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Which coordinate a string is expected to hold. */
typedef enum { PHC_GEO_LATITUDE, PHC_GEO_LONGITUDE } phc_geo_axis;

/* Parses one coordinate (GeographicLib::DMS::Decode) into degrees.
 * Accepted forms: decimal degrees with an optional sign ("-79.3832"), a
 * hemisphere letter before or after ("43.6481 N", "W79.3832"), degrees,
 * minutes and seconds with d/°/'/" markers or colons ("43°38'53.2\"N",
 * "43d38'53.2\"", "43:38:53.2N").  S and W make the value negative.
 * Blanks after a marker or sign and around the hemisphere letter are
 * allowed ("43° 38' 53.2\" N"); blanks between two numbers ("43 38 53") are
 * an error, not glued together.
 * Checks, each an error rather than a silent fix:
 *   - the hemisphere letter matches the axis (N/S for a latitude, E/W for a
 *     longitude); no letter is fine;
 *   - the value is finite and in range: |latitude| <= 90, |longitude| <= 180.
 * On failure returns PHC_ERR_INPUT with a message such as
 *     probes.csv:4: column 'lat': cannot read '43.6 E' as a latitude: ...
 * `where` names the place (file, line, column or key) and may be NULL.
 * *degrees is written only on success. */
int phc_geo_parse_angle(const char *text, phc_geo_axis axis, const char *where, double *degrees,
                        phc_error *err);

/* A local east-north-up frame: x east, y north, z up (along the ellipsoid
 * normal at the origin), metres, with the origin on the WGS84 ellipsoid at
 * geodetic (lat0, lon0, h0) (GeographicLib::LocalCartesian).  A plain value:
 * fill the three fields and pass it by pointer. */
typedef struct phc_geo_frame {
    double lat0; /* origin latitude, degrees, in [-90, 90] */
    double lon0; /* origin longitude, degrees, finite (any value; wrapped) */
    double h0;   /* origin height above the WGS84 ellipsoid, metres */
} phc_geo_frame;

/* Geodetic (lat, lon degrees; h metres above the ellipsoid) -> east, north,
 * up (metres) in frame f: enu[0] = east, enu[1] = north, enu[2] = up.
 * The transformation is exact (through geocentric coordinates), not a flat
 * Earth approximation.  Requires |lat| <= 90 and finite lon, h. */
int phc_geo_to_enu(const phc_geo_frame *f, double lat, double lon, double h, double enu[3],
                   phc_error *err);

/* The inverse: east, north, up (metres) in frame f -> geodetic latitude
 * (degrees, [-90, 90]), longitude (degrees, [-180, 180]) and height
 * (metres above the ellipsoid).  Exact to round-off for any finite enu. */
int phc_geo_from_enu(const phc_geo_frame *f, const double enu[3], double *lat, double *lon,
                     double *h, phc_error *err);

/* Length (metres) of the shortest geodesic between two points on the WGS84
 * ellipsoid (GeographicLib::Geodesic::Inverse, accurate to ~15 nm), for
 * checks and messages ("the probe lies 2.3 km from the plot").  Heights are
 * ignored.  Requires |lat1|, |lat2| <= 90 and finite longitudes. */
int phc_geo_distance(double lat1, double lon1, double lat2, double lon2, double *metres,
                     phc_error *err);

#ifdef __cplusplus
}
#endif

#endif /* PHC_GEO_H */
