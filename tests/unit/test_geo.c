/* measurements/geo: coordinate strings, local ENU frames and geodesic
 * distances through the GeographicLib bridge. */
#include "check.h"
#include "measurements/geo.h"

/* WGS84 ellipsoid: semi-major axis a (m) and flattening f. */
static const double WGS84_A = 6378137.0;
static const double WGS84_F = 1.0 / 298.257223563;

static double deg2rad(double d) { return d * 3.14159265358979323846 / 180.0; }

/* Meridian radius of curvature M(phi) (m per radian of latitude) and prime
 * vertical radius N(phi) (m per radian); the parallel circle has radius
 * N cos(phi).  Standard formulas with e^2 = f (2 - f). */
static double meridian_radius(double lat_deg)
{
    double e2 = WGS84_F * (2 - WGS84_F), s = sin(deg2rad(lat_deg));
    return WGS84_A * (1 - e2) / pow(1 - e2 * s * s, 1.5);
}
static double prime_vertical_radius(double lat_deg)
{
    double e2 = WGS84_F * (2 - WGS84_F), s = sin(deg2rad(lat_deg));
    return WGS84_A / sqrt(1 - e2 * s * s);
}

static void test_parse(void)
{
    phc_error err;
    phc_error_clear(&err);
    double d = 0;
    const double dms = 43 + 38 / 60.0 + 53.2 / 3600.0; /* 43°38'53.2" */

    CHECK(phc_geo_parse_angle("43.6481 N", PHC_GEO_LATITUDE, NULL, &d, &err) == PHC_OK);
    CHECK_NEAR(d, 43.6481, 1e-12, 0);
    CHECK(phc_geo_parse_angle("79.3832 W", PHC_GEO_LONGITUDE, NULL, &d, &err) == PHC_OK);
    CHECK_NEAR(d, -79.3832, 1e-12, 0);
    CHECK(phc_geo_parse_angle("N 43.6481", PHC_GEO_LATITUDE, NULL, &d, &err) == PHC_OK);
    CHECK_NEAR(d, 43.6481, 1e-12, 0);
    CHECK(phc_geo_parse_angle("43.6481s", PHC_GEO_LATITUDE, NULL, &d, &err) == PHC_OK);
    CHECK_NEAR(d, -43.6481, 1e-12, 0);
    CHECK(phc_geo_parse_angle("-79.3832", PHC_GEO_LONGITUDE, NULL, &d, &err) == PHC_OK);
    CHECK_NEAR(d, -79.3832, 1e-12, 0);
    CHECK(phc_geo_parse_angle("  43.6481  ", PHC_GEO_LATITUDE, NULL, &d, &err) == PHC_OK);
    CHECK_NEAR(d, 43.6481, 1e-12, 0);
    CHECK(phc_geo_parse_angle("43°38'53.2\"N", PHC_GEO_LATITUDE, NULL, &d, &err) == PHC_OK);
    CHECK_NEAR(d, dms, 1e-12, 0);
    CHECK(phc_geo_parse_angle("43d38'53.2\"", PHC_GEO_LATITUDE, NULL, &d, &err) == PHC_OK);
    CHECK_NEAR(d, dms, 1e-12, 0);
    CHECK(phc_geo_parse_angle("43° 38' 53.2\" N", PHC_GEO_LATITUDE, NULL, &d, &err) == PHC_OK);
    CHECK_NEAR(d, dms, 1e-12, 0);
    CHECK(phc_geo_parse_angle("43:38:53.2N", PHC_GEO_LATITUDE, NULL, &d, &err) == PHC_OK);
    CHECK_NEAR(d, dms, 1e-12, 0);
    CHECK(phc_geo_parse_angle("43:38:53.2S", PHC_GEO_LATITUDE, NULL, &d, &err) == PHC_OK);
    CHECK_NEAR(d, -dms, 1e-12, 0);
    CHECK(phc_geo_parse_angle("79°22'59.5\"W", PHC_GEO_LONGITUDE, NULL, &d, &err) == PHC_OK);
    CHECK_NEAR(d, -(79 + 22 / 60.0 + 59.5 / 3600.0), 1e-12, 0);
    /* Limits are inclusive. */
    CHECK(phc_geo_parse_angle("90S", PHC_GEO_LATITUDE, NULL, &d, &err) == PHC_OK);
    CHECK_NEAR(d, -90, 0, 0);
    CHECK(phc_geo_parse_angle("180E", PHC_GEO_LONGITUDE, NULL, &d, &err) == PHC_OK);
    CHECK_NEAR(d, 180, 0, 0);

    /* Errors: PHC_ERR_INPUT, the place, the text and the axis in the message;
     * the output is left untouched. */
    d = 1234;
    CHECK(phc_geo_parse_angle("43.6481 E", PHC_GEO_LATITUDE, "probes.csv:4: column 'lat'", &d,
                              &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message,
                       "probes.csv:4: column 'lat': cannot read '43.6481 E' as a latitude: ");
    CHECK_STR_CONTAINS(err.message, "E/W");
    CHECK(d == 1234);
    CHECK(phc_geo_parse_angle("43.6481 N", PHC_GEO_LONGITUDE, "probes.csv:4: column 'lon'", &d,
                              &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cannot read '43.6481 N' as a longitude");
    CHECK(phc_geo_parse_angle("95 N", PHC_GEO_LATITUDE, "probes.csv:5: column 'lat'", &d,
                              &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "probes.csv:5: column 'lat': cannot read '95 N' as a latitude");
    CHECK_STR_CONTAINS(err.message, "outside [-90, 90]");
    CHECK(phc_geo_parse_angle("-180.5", PHC_GEO_LONGITUDE, "x", &d, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "outside [-180, 180]");
    CHECK(phc_geo_parse_angle("abc", PHC_GEO_LATITUDE, "probes.csv:6: column 'lat'", &d,
                              &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "probes.csv:6: column 'lat': cannot read 'abc' as a latitude: ");
    CHECK(phc_geo_parse_angle("", PHC_GEO_LATITUDE, "probes.csv:7: column 'lat'", &d, &err) ==
          PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "probes.csv:7: column 'lat': cannot read '' as a latitude: ");
    CHECK(phc_geo_parse_angle("   ", PHC_GEO_LATITUDE, NULL, &d, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cannot read '   ' as a latitude: the field is empty");
    CHECK(phc_geo_parse_angle("nan", PHC_GEO_LATITUDE, NULL, &d, &err) == PHC_ERR_INPUT);
    CHECK(phc_geo_parse_angle("inf", PHC_GEO_LONGITUDE, NULL, &d, &err) == PHC_ERR_INPUT);
    CHECK(phc_geo_parse_angle("4:60", PHC_GEO_LATITUDE, NULL, &d, &err) == PHC_ERR_INPUT);
    CHECK(phc_geo_parse_angle("43.6 N 12", PHC_GEO_LATITUDE, NULL, &d, &err) == PHC_ERR_INPUT);
    CHECK(phc_geo_parse_angle("43.6 12", PHC_GEO_LATITUDE, NULL, &d, &err) == PHC_ERR_INPUT);
    CHECK(phc_geo_parse_angle("43 38 53", PHC_GEO_LATITUDE, NULL, &d, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "blanks separate two numbers");
    CHECK(d == 1234);
    CHECK(phc_geo_parse_angle(NULL, PHC_GEO_LATITUDE, NULL, &d, &err) == PHC_ERR_INVALID);
    CHECK(phc_geo_parse_angle("1", PHC_GEO_LATITUDE, NULL, NULL, &err) == PHC_ERR_INVALID);
    /* err may be NULL. */
    CHECK(phc_geo_parse_angle("abc", PHC_GEO_LATITUDE, NULL, &d, NULL) == PHC_ERR_INPUT);
}

static void test_enu(void)
{
    phc_error err;
    phc_error_clear(&err);
    const phc_geo_frame f = {43.6481, -79.3832, 76.0};
    double enu[3], s;

    /* The origin itself. */
    CHECK(phc_geo_to_enu(&f, f.lat0, f.lon0, f.h0, enu, &err) == PHC_OK);
    CHECK_NEAR(enu[0], 0, 1e-9, 0);
    CHECK_NEAR(enu[1], 0, 1e-9, 0);
    CHECK_NEAR(enu[2], 0, 1e-9, 0);

    /* 0.001 degree north: ~111.1 m, the meridian arc M(phi) dphi (M varies by
     * ~1e-8 relative over the step), and the geodesic distance. */
    CHECK(phc_geo_to_enu(&f, f.lat0 + 0.001, f.lon0, f.h0, enu, &err) == PHC_OK);
    CHECK_NEAR(enu[0], 0, 1e-9, 0);
    CHECK_NEAR(enu[1], meridian_radius(f.lat0 + 0.0005) * deg2rad(0.001), 0.5, 0);
    CHECK_NEAR(enu[1], 111.1, 0.1, 0);
    /* The geodesic lies on the ellipsoid, the two points h0 = 76 m above it:
     * their separation is longer by (M + h0) / M (1.2e-5 relative here). */
    CHECK(phc_geo_distance(f.lat0, f.lon0, f.lat0 + 0.001, f.lon0, &s, &err) == PHC_OK);
    CHECK_NEAR(enu[1], s * (meridian_radius(f.lat0) + f.h0) / meridian_radius(f.lat0), 0, 1e-6);
    CHECK_NEAR(enu[2], 0, 2e-3, 0); /* the Earth curves away: ~ -d^2 / 2R ≈ -1 mm */

    /* 0.001 degree east: N(phi) cos(phi) dlambda ≈ 80.6 m at 43.6 N. */
    CHECK(phc_geo_to_enu(&f, f.lat0, f.lon0 + 0.001, f.h0, enu, &err) == PHC_OK);
    CHECK_NEAR(enu[0], prime_vertical_radius(f.lat0) * cos(deg2rad(f.lat0)) * deg2rad(0.001), 0,
               1e-3);
    CHECK_NEAR(enu[0], 80.6, 0.15, 0);
    CHECK_NEAR(enu[1], 0, 1e-3, 0);
    CHECK(phc_geo_distance(f.lat0, f.lon0, f.lat0, f.lon0 + 0.001, &s, &err) == PHC_OK);
    CHECK_NEAR(enu[0],
               s * (prime_vertical_radius(f.lat0) + f.h0) / prime_vertical_radius(f.lat0), 0,
               1e-6);

    /* 10 m higher is 10 m up. */
    CHECK(phc_geo_to_enu(&f, f.lat0, f.lon0, f.h0 + 10, enu, &err) == PHC_OK);
    CHECK_NEAR(enu[0], 0, 1e-9, 0);
    CHECK_NEAR(enu[1], 0, 1e-9, 0);
    CHECK_NEAR(enu[2], 10, 1e-9, 0);

    /* Round trips, near and far (20 km, 500 m up), and across the antimeridian. */
    const double pts[][3] = {
        {43.6481, -79.3832, 76.0},       {43.6491, -79.3822, 86.0},
        {43.4, -79.6, 576.0},            {43.0, -80.0, -30.0},
    };
    for (size_t i = 0; i < sizeof pts / sizeof pts[0]; ++i) {
        double lat, lon, h;
        CHECK(phc_geo_to_enu(&f, pts[i][0], pts[i][1], pts[i][2], enu, &err) == PHC_OK);
        CHECK(phc_geo_from_enu(&f, enu, &lat, &lon, &h, &err) == PHC_OK);
        CHECK_NEAR(lat, pts[i][0], 1e-9, 0);
        CHECK_NEAR(lon, pts[i][1], 1e-9, 0);
        CHECK_NEAR(h, pts[i][2], 1e-6, 0);
    }
    {
        const phc_geo_frame g = {-16.5, 179.9995, 0.0}; /* Fiji */
        double lat, lon, h;
        CHECK(phc_geo_to_enu(&g, -16.5, -179.9995, 0.0, enu, &err) == PHC_OK);
        CHECK(enu[0] > 100 && enu[0] < 110); /* ~106.7 m east, not 40000 km west */
        CHECK(phc_geo_from_enu(&g, enu, &lat, &lon, &h, &err) == PHC_OK);
        CHECK_NEAR(lat, -16.5, 1e-9, 0);
        CHECK_NEAR(lon, -179.9995, 1e-9, 0);
        CHECK_NEAR(h, 0, 1e-6, 0);
    }

    /* Bad positions are input errors, never clamped. */
    CHECK(phc_geo_to_enu(&f, 95, 0, 0, enu, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "latitude 95 degrees is outside [-90, 90]");
    CHECK(phc_geo_to_enu(&f, 43, NAN, 0, enu, &err) == PHC_ERR_INPUT);
    CHECK(phc_geo_to_enu(&f, 43, -79, INFINITY, enu, &err) == PHC_ERR_INPUT);
    const phc_geo_frame bad = {-91, 0, 0};
    CHECK(phc_geo_to_enu(&bad, 0, 0, 0, enu, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "frame origin latitude");
    const double nan_enu[3] = {0, NAN, 0};
    double lat, lon, h;
    CHECK(phc_geo_from_enu(&f, nan_enu, &lat, &lon, &h, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "north coordinate");
    CHECK(phc_geo_to_enu(NULL, 0, 0, 0, enu, &err) == PHC_ERR_INVALID);
    CHECK(phc_geo_from_enu(&f, enu, NULL, &lon, &h, &err) == PHC_ERR_INVALID);
}

static void test_distance(void)
{
    phc_error err;
    phc_error_clear(&err);
    double s;
    /* GeographicLib's example-Geodesic.cpp: JFK (40.6 N, 73.8 W) to LHR
     * (51.6 N, 0.5 W) is 5551.76 km on WGS84. */
    CHECK(phc_geo_distance(40.6, -73.8, 51.6, -0.5, &s, &err) == PHC_OK);
    CHECK_NEAR(s, 5551.76e3, 10, 0);
    /* A quarter meridian: 10001965.729 m on WGS84. */
    CHECK(phc_geo_distance(0, 0, 90, 0, &s, &err) == PHC_OK);
    CHECK_NEAR(s, 10001965.729, 1e-3, 0);
    CHECK(phc_geo_distance(10, 20, 10, 20, &s, &err) == PHC_OK);
    CHECK_NEAR(s, 0, 0, 0);
    CHECK(phc_geo_distance(91, 0, 0, 0, &s, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "first point latitude 91");
    CHECK(phc_geo_distance(0, 0, 0, NAN, &s, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "second point longitude");
    CHECK(phc_geo_distance(0, 0, 0, 0, NULL, &err) == PHC_ERR_INVALID);
}

int main(void)
{
    test_parse();
    test_enu();
    test_distance();
    return check_finish("test_geo");
}
