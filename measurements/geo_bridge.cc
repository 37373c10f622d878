// GeographicLib bridge: the only file in phytocal that touches GeographicLib.
//
// Every extern "C" function checks its arguments, calls GeographicLib inside
// a try block, catches every exception and returns an enum phc_status; no
// exception ever crosses into C.  See measurements/geo.h for units and
// preconditions.

#include "measurements/geo.h"

#include <GeographicLib/Constants.hpp>
#include <GeographicLib/DMS.hpp>
#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/LocalCartesian.hpp>

#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <exception>
#include <new>
#include <string>

namespace {

// "latitude" / "longitude", for messages.
const char *axis_name(phc_geo_axis axis)
{
    return axis == PHC_GEO_LATITUDE ? "latitude" : "longitude";
}

// Largest allowed |value| in degrees for an axis.
double axis_limit(phc_geo_axis axis)
{
    return axis == PHC_GEO_LATITUDE ? 90.0 : 180.0;
}

// The one message shape of phc_geo_parse_angle:
//   "<where>: cannot read '<text>' as a latitude: <reason>"
int parse_error(phc_error *err, const char *where, const char *text, phc_geo_axis axis,
                const char *reason)
{
    if (where && *where)
        return phc_error_set(err, PHC_ERR_INPUT, "%s: cannot read '%s' as a %s: %s", where, text,
                             axis_name(axis), reason);
    return phc_error_set(err, PHC_ERR_INPUT, "cannot read '%s' as a %s: %s", text,
                         axis_name(axis), reason);
}

// Checks a geodetic position given to `fn`: latitude in [-90, 90] degrees,
// finite longitude (degrees) and height (metres).  Values outside the
// domain are errors, never clamped: GeographicLib would return NaN or fold
// the latitude silently.
int check_position(const char *fn, const char *what, double lat, double lon, double h,
                   phc_error *err)
{
    if (!std::isfinite(lat) || std::fabs(lat) > 90.0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s: %s latitude %.10g degrees is outside [-90, 90]", fn, what, lat);
    if (!std::isfinite(lon))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: %s longitude %.10g degrees is not finite",
                             fn, what, lon);
    if (!std::isfinite(h))
        return phc_error_set(err, PHC_ERR_INPUT, "%s: %s height %.10g m is not finite", fn, what,
                             h);
    return PHC_OK;
}

int check_frame(const char *fn, const phc_geo_frame *f, phc_error *err)
{
    return check_position(fn, "frame origin", f->lat0, f->lon0, f->h0, err);
}

// The frame as a GeographicLib object.  Built per call (a few trigonometric
// evaluations) so that phc_geo_frame stays a plain C value and no state is
// shared between threads.
GeographicLib::LocalCartesian make_local(const phc_geo_frame *f)
{
    return GeographicLib::LocalCartesian(f->lat0, f->lon0, f->h0,
                                         GeographicLib::Geocentric::WGS84());
}

// DMS::Decode strips leading and trailing blanks only, so the common
// "43.6481 N" and "43° 38' 53.2\" N" fail with "Illegal character".  Remove a
// run of ASCII blanks where it cannot change the number: after a component
// marker, a sign or a hemisphere letter (any character other than a digit or
// '.'), or before a hemisphere letter.  Blanks between two digits ("43 38",
// "43.6 12") are kept, so DMS::Decode rejects them instead of silently reading
// 4338 or 43.612.
bool is_hemisphere(char c)
{
    switch (c) {
    case 'N': case 'S': case 'E': case 'W':
    case 'n': case 's': case 'e': case 'w':
        return true;
    default:
        return false;
    }
}

std::string join_blanks(const std::string &in)
{
    std::string out;
    out.reserve(in.size());
    for (std::size_t i = 0; i < in.size();) {
        if (in[i] != ' ' && in[i] != '\t') {
            out += in[i++];
            continue;
        }
        std::size_t j = i;
        while (j < in.size() && (in[j] == ' ' || in[j] == '\t'))
            ++j;
        const bool at_edge = out.empty() || j == in.size();
        const char before = at_edge ? '\0' : out.back();
        const char after = j < in.size() ? in[j] : '\0';
        const bool keep = !at_edge && (std::isdigit(static_cast<unsigned char>(before)) ||
                                       before == '.') &&
                          !is_hemisphere(after);
        if (keep)
            out += ' ';
        i = j;
    }
    return out;
}

// Turns an exception escaping GeographicLib into a status and message.
int exception_status(const char *fn, phc_error *err)
{
    try {
        throw;
    } catch (const std::bad_alloc &) {
        return phc_error_set(err, PHC_ERR_NOMEM, "%s: out of memory", fn);
    } catch (const std::exception &e) {
        return phc_error_set(err, PHC_ERR_INTERNAL, "%s: GeographicLib: %s", fn, e.what());
    } catch (...) {
        return phc_error_set(err, PHC_ERR_INTERNAL, "%s: unknown exception", fn);
    }
}

} // namespace

extern "C" int phc_geo_parse_angle(const char *text, phc_geo_axis axis, const char *where,
                                   double *degrees, phc_error *err)
{
    if (!text || !degrees || (axis != PHC_GEO_LATITUDE && axis != PHC_GEO_LONGITUDE))
        return phc_error_set(err, PHC_ERR_INVALID, "phc_geo_parse_angle: invalid argument");
    try {
        // DMS::Decode's own message for "" is cryptic; say it plainly.
        const char *p = text;
        while (*p && std::isspace(static_cast<unsigned char>(*p)))
            ++p;
        if (!*p)
            return parse_error(err, where, text, axis, "the field is empty");

        // Blanks left between two numbers: say so rather than DMS's
        // "Illegal character   in DMS string".
        const std::string joined = join_blanks(text);
        if (joined.find(' ') != std::string::npos)
            return parse_error(err, where, text, axis,
                               "blanks separate two numbers; mark degrees, minutes and seconds "
                               "with d ' \" (43d38'53.2\") or colons (43:38:53.2)");

        GeographicLib::DMS::flag ind = GeographicLib::DMS::NONE;
        double value;
        try {
            value = GeographicLib::DMS::Decode(joined, ind);
        } catch (const GeographicLib::GeographicErr &e) {
            // Malformed string: DMS explains what is wrong ("Illegal
            // character a in DMS string abc", "Minutes 60 not in range").
            return parse_error(err, where, text, axis, e.what());
        }

        // A hemisphere letter of the other axis means a swapped column or a
        // typo: "43.6481 E" in a latitude column must not become 43.6481.
        if (axis == PHC_GEO_LATITUDE && ind == GeographicLib::DMS::LONGITUDE)
            return parse_error(err, where, text, axis,
                               "it has an E/W hemisphere letter; a latitude takes N or S");
        if (axis == PHC_GEO_LONGITUDE && ind == GeographicLib::DMS::LATITUDE)
            return parse_error(err, where, text, axis,
                               "it has an N/S hemisphere letter; a longitude takes E or W");

        // DMS::Decode reads "nan" and "inf" and performs no range check.
        if (!std::isfinite(value))
            return parse_error(err, where, text, axis, "the value is not finite");
        const double limit = axis_limit(axis);
        if (std::fabs(value) > limit) {
            char reason[128];
            std::snprintf(reason, sizeof reason, "%.10g degrees is outside [%g, %g]", value,
                          -limit, limit);
            return parse_error(err, where, text, axis, reason);
        }
        *degrees = value;
        return PHC_OK;
    } catch (...) {
        return exception_status("phc_geo_parse_angle", err);
    }
}

extern "C" int phc_geo_to_enu(const phc_geo_frame *f, double lat, double lon, double h,
                              double enu[3], phc_error *err)
{
    static const char fn[] = "phc_geo_to_enu";
    if (!f || !enu)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: NULL argument", fn);
    int rc = check_frame(fn, f, err);
    if (rc == PHC_OK)
        rc = check_position(fn, "point", lat, lon, h, err);
    if (rc != PHC_OK)
        return rc;
    try {
        double x, y, z;
        make_local(f).Forward(lat, lon, h, x, y, z);
        if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
            return phc_error_set(err, PHC_ERR_NUMERIC, "%s: non-finite result for (%g, %g, %g)",
                                 fn, lat, lon, h);
        enu[0] = x; // east, m
        enu[1] = y; // north, m
        enu[2] = z; // up, m
        return PHC_OK;
    } catch (...) {
        return exception_status(fn, err);
    }
}

extern "C" int phc_geo_from_enu(const phc_geo_frame *f, const double enu[3], double *lat,
                                double *lon, double *h, phc_error *err)
{
    static const char fn[] = "phc_geo_from_enu";
    if (!f || !enu || !lat || !lon || !h)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: NULL argument", fn);
    int rc = check_frame(fn, f, err);
    if (rc != PHC_OK)
        return rc;
    for (int i = 0; i < 3; ++i)
        if (!std::isfinite(enu[i]))
            return phc_error_set(err, PHC_ERR_INPUT, "%s: %s coordinate %g m is not finite", fn,
                                 i == 0 ? "east" : i == 1 ? "north" : "up", enu[i]);
    try {
        double la, lo, hh;
        make_local(f).Reverse(enu[0], enu[1], enu[2], la, lo, hh);
        if (!std::isfinite(la) || !std::isfinite(lo) || !std::isfinite(hh))
            return phc_error_set(err, PHC_ERR_NUMERIC,
                                 "%s: non-finite result for (%g, %g, %g) m", fn, enu[0], enu[1],
                                 enu[2]);
        *lat = la;
        *lon = lo;
        *h = hh;
        return PHC_OK;
    } catch (...) {
        return exception_status(fn, err);
    }
}

extern "C" int phc_geo_distance(double lat1, double lon1, double lat2, double lon2,
                                double *metres, phc_error *err)
{
    static const char fn[] = "phc_geo_distance";
    if (!metres)
        return phc_error_set(err, PHC_ERR_INVALID, "%s: NULL argument", fn);
    int rc = check_position(fn, "first point", lat1, lon1, 0.0, err);
    if (rc == PHC_OK)
        rc = check_position(fn, "second point", lat2, lon2, 0.0, err);
    if (rc != PHC_OK)
        return rc;
    try {
        // Geodesic::WGS84() is a function-local static built once (C++11
        // guarantees thread-safe initialisation); Inverse is const.
        double s12;
        GeographicLib::Geodesic::WGS84().Inverse(lat1, lon1, lat2, lon2, s12);
        if (!std::isfinite(s12))
            return phc_error_set(err, PHC_ERR_NUMERIC, "%s: non-finite distance", fn);
        *metres = s12;
        return PHC_OK;
    } catch (...) {
        return exception_status(fn, err);
    }
}
