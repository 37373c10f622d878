/* measurements/units: UDUNITS-2 conversions used for data columns. */
#include "check.h"
#include "measurements/units.h"

int main(void)
{
    phc_error err;
    phc_error_clear(&err);
    phc_units *u = phc_units_new(&err);
    CHECK(u != NULL);
    if (!u)
        return check_finish("test_units");
    phc_unit_conversion c;
    CHECK(phc_units_conversion(u, "h", "s", "t", &c, &err) == PHC_OK);
    CHECK_NEAR(c.scale, 3600, 0, 0);
    CHECK_NEAR(c.offset, 0, 0, 0);
    CHECK(phc_units_conversion(u, "min", "s", "t", &c, &err) == PHC_OK);
    CHECK_NEAR(phc_unit_apply(c, 2.5), 150, 0, 1e-15);
    CHECK(phc_units_conversion(u, "mg", "g", "m", &c, &err) == PHC_OK);
    CHECK_NEAR(phc_unit_apply(c, 250), 0.25, 0, 1e-15);
    CHECK(phc_units_conversion(u, "bar", "MPa", "p", &c, &err) == PHC_OK);
    CHECK_NEAR(phc_unit_apply(c, -7.2), -0.72, 0, 1e-14);
    CHECK(phc_units_conversion(u, "cm2", "m2", "a", &c, &err) == PHC_OK);
    CHECK_NEAR(phc_unit_apply(c, 115), 0.0115, 0, 1e-14);
    /* Affine: temperature. */
    CHECK(phc_units_conversion(u, "degC", "K", "T", &c, &err) == PHC_OK);
    CHECK_NEAR(phc_unit_apply(c, 25), 298.15, 0, 1e-12);
    /* POSIX timestamps convert to durations up to an offset: differences
     * are exact seconds. */
    CHECK(phc_units_conversion(u, "seconds since 1970-01-01", "s", "t", &c, &err) == PHC_OK);
    CHECK_NEAR(phc_unit_apply(c, 1553590080.0 + 3600) - phc_unit_apply(c, 1553590080.0), 3600, 0, 1e-12);
    /* Errors name the place and the unit. */
    CHECK(phc_units_conversion(u, "hourz", "s", "cfg.yaml:7: time unit", &c, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:7: time unit: 'hourz' is not a unit UDUNITS-2 knows");
    CHECK(phc_units_conversion(u, "g", "s", "cfg.yaml:8: time unit", &c, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "'g' cannot be converted to 's'");
    CHECK(phc_units_conversion(u, "", "s", "x", &c, &err) == PHC_ERR_INPUT);
    /* A line break is not part of a unit (a fuzzing find: UDUNITS-2 echoed
     * it to stdout and accepted "h"); the message shows it escaped. */
    CHECK(phc_units_conversion(u, "h\n", "s", "t", &c, &err) == PHC_ERR_INPUT);
    CHECK(strcmp(err.message, "t: 'h\\n' is not a unit UDUNITS-2 knows") == 0);
    CHECK(phc_units_convertible(u, "h\r", "s") == 0);
    CHECK(phc_units_convertible(u, "kg\tm", "kg m") == 1); /* tabs separate factors */
    CHECK(phc_units_convertible(u, "d", "s") == 1);
    CHECK(phc_units_convertible(u, "kg", "s") == 0);
    phc_units_free(u);
    phc_units_free(NULL);
    return check_finish("test_units");
}
