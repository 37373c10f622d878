/* `kind: soil_probe` in a config: its keys and their help, and the
 * translation of its mapping (and the probe table and readings it names)
 * into phc_soil_probe_new's inputs (fit/costs/soil_probe.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/config/kind.h"
#include "fit/config/kinds.h"
#include "fit/config/soil_setup_yaml.h"
#include "fit/config/yaml_keys.h"
#include "fit/costs/soil_probe.h"
#include "fit/costs/source_file.h"
#include "measurements/soil_probes.h"
#include "measurements/units.h"

static const char *const soil_probe_keys[] = {"file",   "time",  "probe", "value",   "quantity", "start",
                                              "probes", "sigma", "soil",  "x_label", "y_label",  NULL};
static const phc_key_help soil_probe_help[] = {
    {"file", "CSV table of readings (time, probe, value; in time order), relative to the "
             "config file. Required."},
    {"time", "{column: NAME, unit: UNIT} or a column name: reading times; any UDUNITS-2 time "
             "unit, or a timestamp unit such as \"hours since 2024-05-01\" (then start is "
             "required); default h. Required."},
    {"probe", "Column of probe ids, each in the probe table. Required."},
    {"value", "Column of readings, in the quantity's unit. Required."},
    {"quantity", "What the readings are: water (w, m³/m³) or fill (w/c). Default: water."},
    {"start", "The reading time of the model's t = 0, in the time unit; no reading may be "
              "earlier. Default: 0; required with a timestamp unit."},
    {"probes", "The probe table, one row per probe: {file, id, x, y, depth, sigma}, its CSV "
               "file (required, relative to the config file) and the names of its columns "
               "(defaults id, x, y, depth; sigma optional: per-probe standard deviations); lat "
               "and lon instead of x and y place probes by latitude and longitude (needs the "
               "soil's geo_origin). x, y in m from the grid's west-south corner, depth in m "
               "below the surface. Required."},
    {"sigma", "Standard deviation of a reading, > 0, in the readings' unit, for probes without "
              "a sigma column. Required unless every probe has one."},
    {"soil", "The soil set-up (the soil: keys below). Required."},
    {"x_label", "Axis label of time. Default: \"time since start (h)\"."},
    {"y_label", "Axis label of the readings. Default: \"water content w (m³/m³)\" or "
                "\"fill level w/c\"."},
    {NULL, NULL}};

/* probes: {file, id, x, y | lat, lon, depth, sigma}: the probe table, placed
 * by latitude and longitude through the soil's geo_origin. */
static int read_probes(const phc_yaml_doc *doc, const phc_yaml_node *pn, const char *base_dir,
                       const phc_geo_frame *geo, char **ppath, phc_probe_table **out, phc_error *err)
{
    static const char *const probe_keys[] = {"file", "id", "x", "y", "lat", "lon", "depth", "sigma", NULL};
    phc_probe_columns pc = {0};
    const char *pfile = NULL;
    int rc;
    if (pn->kind != PHC_YAML_MAPPING)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'probes': expected {file, id, x, y | lat, lon, depth}",
                             doc->path, pn->line);
    pc.id = "id";
    pc.depth = "depth";
    if ((rc = phc_yaml_check_keys(doc, pn, probe_keys, "probes", err)) ||
        (rc = phc_yaml_map_string(doc, pn, "file", 1, "probes", &pfile, err)) ||
        (rc = phc_yaml_map_string(doc, pn, "id", 0, "probes", &pc.id, err)) ||
        (rc = phc_yaml_map_string(doc, pn, "x", 0, "probes", &pc.x, err)) ||
        (rc = phc_yaml_map_string(doc, pn, "y", 0, "probes", &pc.y, err)) ||
        (rc = phc_yaml_map_string(doc, pn, "lat", 0, "probes", &pc.lat, err)) ||
        (rc = phc_yaml_map_string(doc, pn, "lon", 0, "probes", &pc.lon, err)) ||
        (rc = phc_yaml_map_string(doc, pn, "depth", 0, "probes", &pc.depth, err)) ||
        (rc = phc_yaml_map_string(doc, pn, "sigma", 0, "probes", &pc.sigma, err)))
        return rc;
    if (!pc.lat && !pc.lon && !pc.x && !pc.y) {
        pc.x = "x";
        pc.y = "y";
    }
    if (!(*ppath = phc_join_path(base_dir, pfile)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if ((rc = phc_probe_table_read(*ppath, &pc, geo, out, err)) && rc == PHC_ERR_IO)
        phc_error_prefix(err, rc, "%s:%zu: probes: key 'file'", doc->path, phc_key_line(pn, "file"));
    return rc;
}

/* The readings, in hours, and the start (`start:` in the time unit). */
static int read_readings(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *path, const char *tcol,
                         const char *tunit, const char *pcol, const char *vcol, const phc_probe_table *probes,
                         phc_probe_series **ser, double *start, phc_error *err)
{
    phc_units *units = phc_units_new(err);
    phc_unit_conversion tconv;
    char where[256];
    int rc;
    if (!units)
        return err->status;
    snprintf(where, sizeof where, "%s:%zu: time unit", doc->path, phc_key_line(node, "time"));
    if ((rc = phc_units_conversion(units, tunit, "h", where, &tconv, err)))
        goto done;
    if ((rc = phc_probe_series_read(path, tcol, tconv, pcol, vcol, probes, ser, err))) {
        if (rc == PHC_ERR_IO) /* a file that cannot be read: which key named it */
            phc_error_prefix(err, rc, "%s:%zu: key 'file'", doc->path, phc_key_line(node, "file"));
        goto done;
    }
    if (strstr(tunit, "since") && !phc_yaml_get(node, "start")) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: the time unit '%s' is a timestamp: give `start:` (the "
                           "reading time of the model's t = 0, in that unit)", doc->path, phc_key_line(node, "time"),
                           tunit);
        goto done;
    }
    if (phc_yaml_get(node, "start")) {
        double st;
        if ((rc = phc_yaml_map_number(doc, node, "start", 0, "soil_probe data set", &st, err)))
            goto done;
        *start = phc_unit_apply(tconv, st);
    }
done:
    phc_units_free(units);
    return rc;
}

static int soil_probe_yaml(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                           phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out, phc_error *err)
{
    const char *ctx = "soil_probe data set";
    const char *file = NULL, *tcol = NULL, *tunit = NULL, *pcol = NULL, *vcol = NULL, *quantity = "water";
    phc_soil_probe_options o = phc_soil_probe_options_default();
    const phc_origin origin = phc_yaml_origin(doc, node);
    phc_soil_setup_yaml soil_yaml = {0};
    phc_probe_table *probes = NULL;
    phc_probe_series *ser = NULL;
    char *path = NULL, *ppath = NULL;
    int rc;
    *out = NULL;
    const phc_yaml_node *soil = phc_yaml_get(node, "soil"), *pn = phc_yaml_get(node, "probes");
    if ((rc = phc_yaml_map_string(doc, node, "file", 1, ctx, &file, err)) ||
        (rc = phc_column_spec(doc, node, "time", "soil_probe data set", "h", &tcol, &tunit, err)) ||
        (rc = phc_yaml_map_string(doc, node, "probe", 1, ctx, &pcol, err)) ||
        (rc = phc_yaml_map_string(doc, node, "value", 1, ctx, &vcol, err)) ||
        (rc = phc_yaml_map_string(doc, node, "quantity", 0, ctx, &quantity, err)) ||
        (rc = phc_yaml_map_string(doc, node, "x_label", 0, ctx, &o.x_label, err)) ||
        (rc = phc_yaml_map_string(doc, node, "y_label", 0, ctx, &o.y_label, err)))
        goto done;
    if (strcmp(quantity, "water") && strcmp(quantity, "fill")) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'quantity': '%s' is not one of water, fill", doc->path,
                           phc_key_line(node, "quantity"), quantity);
        goto done;
    }
    o.quantity = strcmp(quantity, "fill") ? PHC_SOIL_PROBE_WATER : PHC_SOIL_PROBE_FILL;
    if (!soil || !pn) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil_probe data set: missing key '%s'", doc->path, node->line,
                           soil ? "probes" : "soil");
        goto done;
    }
    if ((rc = phc_soil_setup_yaml_read(doc, soil, &soil_yaml, err)) ||
        (rc = read_probes(doc, pn, base_dir, soil_yaml.options.geo_origin, &ppath, &probes, err)))
        goto done;
    if (!(path = phc_join_path(base_dir, file))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    if ((rc = read_readings(doc, node, path, tcol, tunit, pcol, vcol, probes, &ser, &o.start, err)))
        goto done;
    if (phc_yaml_get(node, "sigma") && (rc = phc_yaml_number(doc, phc_yaml_get(node, "sigma"), "sigma", &o.sigma, err)))
        goto done;
    o.soil = &soil_yaml.options;
    o.is_parameter = is_parameter;
    o.user_data = user_data;
    o.origin = &origin;
    if ((rc = phc_soil_probe_new(probes, ser, &o, out, err)))
        goto done;
    if (phc_dataset_add_input(*out, path) || phc_dataset_add_input(*out, ppath)) {
        phc_dataset_free(*out);
        *out = NULL;
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
done:
    phc_soil_setup_yaml_free(&soil_yaml);
    phc_probe_table_free(probes);
    phc_probe_series_free(ser);
    free(path);
    free(ppath);
    return rc;
}

const phc_kind phc_soil_probe_kind = {
    .config = {.name = "soil_probe",
               .summary = "soil-moisture probe readings over time -> soil permeability p and "
                          "capacity c, globally or per layer (Rhizomorph §6)",
               .keys = soil_probe_keys,
               .help = soil_probe_help},
    .ops = &phc_soil_probe_ops,
    .load_yaml = soil_probe_yaml,
};
