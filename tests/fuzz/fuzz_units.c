/* libFuzzer harness: unit strings through UDUNITS-2 (measurements/units.h).
 * The first byte picks the unit to convert to (the units phytocal's readers
 * convert into); the rest is the user's unit string, as it would appear in a
 * config's `unit:` or a BAAD unit_in cell.  The unit database is loaded once. */
#include "fuzz_common.h"

#include <math.h>

#include "measurements/units.h"

static const char *const targets[] = {"s",  "h",     "g",     "kg",   "m",  "m2", "MPa",
                                      "kg/m2", "yr", "K",   "degC", "1",  "mm/h", "seconds since 1970-01-01"};

static phc_units *units;

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    phc_error err;
    units = phc_units_new(&err);
    if (!units)
        phc_fuzz_fail("cannot load the unit database", err.message);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    const char *to = targets[data[0] % (sizeof targets / sizeof targets[0])];
    char *from = phc_fuzz_string(data + 1, size - 1);
    phc_error err;
    phc_unit_conversion c;
    int rc = phc_units_conversion(units, from, to, "fuzz: unit", &c, &err);
    phc_fuzz_check_error(rc, &err, "fuzz: unit");
    if (rc == 0 && (!isfinite(c.scale) || !isfinite(c.offset) || c.scale == 0))
        phc_fuzz_fail("a conversion that is accepted is affine and finite", NULL);
    phc_units_convertible(units, from, to);
    free(from);
    return 0;
}
