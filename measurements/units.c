/* Units of measure through UDUNITS-2 (see units.h). */
#include "measurements/units.h"

#include <math.h>
#include <stdlib.h>
#include <udunits2.h>

struct phc_units {
    ut_system *system;
};

phc_units *phc_units_new(phc_error *err)
{
    /* UDUNITS prints its own diagnostics to stderr by default; the library
     * never prints, so silence it (this handler is process-wide in UDUNITS). */
    ut_set_error_message_handler(ut_ignore);
    phc_units *u = calloc(1, sizeof *u);
    if (!u) {
        phc_error_set(err, PHC_ERR_NOMEM, "out of memory loading the unit database");
        return NULL;
    }
    u->system = ut_read_xml(NULL);
    if (!u->system) {
        free(u);
        phc_error_set(err, PHC_ERR_IO,
                      "cannot read the UDUNITS-2 unit database (is libudunits2-data "
                      "installed, or UDUNITS2_XML_PATH set correctly?)");
        return NULL;
    }
    return u;
}

void phc_units_free(phc_units *u)
{
    if (!u)
        return;
    ut_free_system(u->system);
    free(u);
}

static ut_unit *parse(phc_units *u, const char *text)
{
    if (!text || !*text)
        return NULL;
    /* UDUNITS-2's lexer copies characters no rule matches, a line break
     * ("h\n" from a YAML "\n" or a quoted CSV cell), to stdout and then
     * accepts the unit before it; the library never prints, and a unit has
     * no control characters: refuse them (spaces and tabs separate factors). */
    for (const char *c = text; *c; ++c)
        if (((unsigned char)*c < 0x20 && *c != '\t') || *c == 0x7f)
            return NULL;
    return ut_parse(u->system, text, UT_UTF8);
}

int phc_units_conversion(phc_units *u, const char *from, const char *to, const char *where,
                         phc_unit_conversion *out, phc_error *err)
{
    const char *w = where ? where : "unit";
    ut_unit *a = parse(u, from), *b = NULL;
    cv_converter *c = NULL;
    int rc = PHC_OK;
    if (!a) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s: '%s' is not a unit UDUNITS-2 knows", w,
                           from ? from : "");
        goto done;
    }
    b = parse(u, to);
    if (!b) {
        rc = phc_error_set(err, PHC_ERR_INTERNAL, "%s: internal unit '%s' does not parse", w, to);
        goto done;
    }
    c = ut_get_converter(a, b);
    if (!c) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s: '%s' cannot be converted to '%s'", w, from,
                           to);
        goto done;
    }
    /* All conversions between the units we accept are affine: read the
     * offset at 0 and the scale from 1, and check linearity at a third point
     * so that a non-affine unit (a logarithmic one) is refused, not mangled. */
    double y0 = cv_convert_double(c, 0.0), y1 = cv_convert_double(c, 1.0);
    double y10 = cv_convert_double(c, 10.0);
    double scale = y1 - y0;
    if (!isfinite(y0) || !isfinite(scale) || scale == 0.0 ||
        fabs(y10 - (y0 + 10.0 * scale)) > 1e-9 * (fabs(y10) + fabs(y0) + fabs(scale))) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s: the conversion from '%s' to '%s' is not linear",
                           w, from, to);
        goto done;
    }
    out->scale = scale;
    out->offset = y0;
done:
    cv_free(c);
    ut_free(a);
    ut_free(b);
    return rc;
}

int phc_units_convertible(phc_units *u, const char *unit, const char *dimension_unit)
{
    ut_unit *a = parse(u, unit), *b = parse(u, dimension_unit);
    int ok = a && b && ut_are_convertible(a, b);
    ut_free(a);
    ut_free(b);
    return ok;
}
