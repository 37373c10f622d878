/* Units of measure (UDUNITS-2): converting a column or a config value from the
 * unit the user declared to the unit a model works in.
 *
 * Only affine conversions exist between the units phytocal uses
 * (y = scale*x + offset), so a conversion is returned as two numbers rather
 * than a converter object: it can be stored and applied without UDUNITS.
 * Timestamps ("seconds since 1970-01-01") convert to durations with an
 * offset; callers that measure time from an origin subtract it anyway. */
#ifndef PHC_UNITS_H
#define PHC_UNITS_H

#include "model/status.h"

typedef struct phc_units phc_units;

/* Loads UDUNITS-2's default unit database (the XML of libudunits2-data, or
 * the file named by $UDUNITS2_XML_PATH).  NULL with err set on failure. */
phc_units *phc_units_new(phc_error *err);
void phc_units_free(phc_units *u); /* accepts NULL */

typedef struct phc_unit_conversion {
    double scale;  /* y = scale * x + offset */
    double offset;
} phc_unit_conversion;

/* The conversion from unit `from` to unit `to` (UDUNITS-2 syntax: "h",
 * "min", "g", "mg", "bar", "MPa", "cm2", "seconds since 1970-01-01" ...).
 * `where` prefixes messages (e.g. "config.yaml:12: time unit"):
 *     "config.yaml:12: time unit: 'hour s' is not a unit UDUNITS-2 knows"
 *     "config.yaml:12: time unit: 'g' cannot be converted to 's'"
 * Returns PHC_OK or PHC_ERR_INPUT. */
int phc_units_conversion(phc_units *u, const char *from, const char *to, const char *where,
                         phc_unit_conversion *out, phc_error *err);

/* 1 when `unit` parses and converts to `dimension_unit`, else 0. */
int phc_units_convertible(phc_units *u, const char *unit, const char *dimension_unit);

static inline double phc_unit_apply(phc_unit_conversion c, double x)
{
    return c.scale * x + c.offset;
}

#endif /* PHC_UNITS_H */
