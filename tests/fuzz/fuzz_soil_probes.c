/* libFuzzer harness: soil-moisture probe tables and readings
 * (measurements/soil_probes.h).  The input holds two files split at a
 * "%% NAME" line (fuzz_common.h): the probe table (first part) and the
 * readings (second part, any name).  A probe table whose text mentions "lat"
 * is read as a geographic table (columns id, lat, lon, depth, sigma) on a
 * grid with a georeferenced origin; otherwise as a grid-frame table (id, x,
 * y, depth, sigma).  Readings have columns t (hours), probe, value. */
#include "fuzz_common.h"

#include "measurements/soil_probes.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    phc_fuzz_part parts[PHC_FUZZ_MAX_PARTS];
    char probes_path[4200], readings_path[4200];
    phc_error err;
    phc_probe_table *table = NULL;
    phc_probe_series *series = NULL;
    size_t n = phc_fuzz_split(data, size, parts);
    phc_fuzz_clear();
    phc_fuzz_write("probes.csv", parts[0].data, parts[0].size, probes_path, sizeof probes_path);
    int geo = memmem(parts[0].data, parts[0].size, "lat", 3) != NULL;
    phc_probe_columns cols = {.id = "id", .depth = "depth", .sigma = "sigma"};
    if (geo) {
        cols.lat = "lat";
        cols.lon = "lon";
    } else {
        cols.x = "x";
        cols.y = "y";
    }
    if (!memmem(parts[0].data, parts[0].size, "sigma", 5))
        cols.sigma = NULL; /* the optional column */
    const phc_geo_frame frame = {.lat0 = 43.6481, .lon0 = -79.4042, .h0 = 100};
    int rc = phc_probe_table_read(probes_path, &cols, geo ? &frame : NULL, &table, &err);
    phc_fuzz_check_error(rc, &err, "probes.csv");
    if (rc != 0) {
        if (table)
            phc_fuzz_fail("failure must leave *out NULL", NULL);
        return 0;
    }
    for (size_t i = 0; i < table->n; ++i)
        if (phc_probe_find(table, table->probes[i].id) < 0)
            phc_fuzz_fail("a probe is found by its own id", NULL);
    if (n >= 2) {
        phc_fuzz_write("readings.csv", parts[1].data, parts[1].size, readings_path,
                       sizeof readings_path);
        const phc_unit_conversion hours = {.scale = 1.0 / 3600.0, .offset = 0};
        rc = phc_probe_series_read(readings_path, "t", hours, "probe", "value", table, &series,
                                   &err);
        phc_fuzz_check_error(rc, &err, "readings.csv");
        if (rc == 0) {
            for (size_t i = 0; i < series->n; ++i)
                if (series->probe[i] >= table->n)
                    phc_fuzz_fail("every reading belongs to a probe of the table", NULL);
        }
        phc_probe_series_free(series);
    }
    phc_probe_table_free(table);
    return 0;
}
