/* `kind: infiltration` in a config: its keys and their help, and the
 * translation of its mapping (and the table it names) into
 * phc_infiltration_options (fit/costs/infiltration.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/config/kind.h"
#include "fit/config/kinds.h"
#include "fit/config/soil_setup_yaml.h"
#include "fit/config/yaml_keys.h"
#include "fit/costs/infiltration.h"
#include "fit/costs/source_file.h"

static const char *const infiltration_keys[] = {"file", "time", "depth", "fraction", "sigma", "soil",
                                                "x_label", "y_label", NULL};
static const phc_key_help infiltration_help[] = {
    {"file", "CSV table of the infiltration front, relative to the config file. Required."},
    {"time", "{column: NAME, unit: UNIT} or a column name: time since the start of the run, "
             "> 0 and increasing; any UDUNITS-2 time unit, default h. Required."},
    {"depth", "{column: NAME, unit: UNIT} or a column name: the depth above which `fraction` "
              "of the water applied so far lies, >= 0; any length unit, default m. Required."},
    {"fraction", "The fraction of the applied water above the depth, in (0, 1]. "
                 "Default: 0.8 (Rhizomorph Fig. 7)."},
    {"sigma", "Standard deviation of the depth, > 0: a number or the name of a column, both in "
              "the depth column's unit. Required."},
    {"soil", "The soil set-up (the soil: keys below); it must have rain or a source. "
             "Required."},
    {"x_label", "Axis label of time. Default: \"time since the start (h)\"."},
    {"y_label", "Axis label of depth. Default: \"depth of 80% of the applied water (m)\" "
                "(with the fraction given)."},
    {NULL, NULL}};

static int infiltration_yaml(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                             phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out, phc_error *err)
{
    const char *ctx = "infiltration data set", *file = NULL;
    phc_infiltration_options o = phc_infiltration_options_default();
    const phc_origin origin = phc_yaml_origin(doc, node);
    phc_soil_setup_yaml soil_yaml = {0};
    phc_table *table = NULL;
    char *path = NULL;
    int rc;
    *out = NULL;
    const phc_yaml_node *soil = phc_yaml_get(node, "soil");
    if ((rc = phc_yaml_map_string(doc, node, "file", 1, ctx, &file, err)) ||
        (rc = phc_column_spec(doc, node, "time", "infiltration data set", "h", &o.time, &o.time_unit, err)) ||
        (rc = phc_column_spec(doc, node, "depth", "infiltration data set", "m", &o.depth, &o.depth_unit, err)) ||
        (rc = phc_yaml_map_number(doc, node, "fraction", 0, ctx, &o.fraction, err)) ||
        (rc = phc_yaml_map_string(doc, node, "x_label", 0, ctx, &o.x_label, err)) ||
        (rc = phc_yaml_map_string(doc, node, "y_label", 0, ctx, &o.y_label, err)))
        goto done;
    if (soil && (rc = phc_soil_setup_yaml_read(doc, soil, &soil_yaml, err)))
        goto done;
    if (!(path = phc_join_path(base_dir, file))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    if ((rc = phc_table_read(path, &table, err))) {
        if (rc == PHC_ERR_IO) /* a file that cannot be read: which key named it */
            phc_error_prefix(err, rc, "%s:%zu: key 'file'", doc->path, phc_key_line(node, "file"));
        goto done;
    }
    /* sigma: a column of the table, else a number */
    const phc_yaml_node *sg = phc_yaml_get(node, "sigma");
    if (sg && sg->kind == PHC_YAML_SCALAR && phc_table_find(table, sg->scalar) >= 0)
        o.sigma_column = sg->scalar;
    else if (sg && (rc = phc_yaml_number(doc, sg, "sigma", &o.sigma, err)))
        goto done;
    o.soil = soil ? &soil_yaml.options : NULL;
    o.is_parameter = is_parameter;
    o.user_data = user_data;
    o.origin = &origin;
    if ((rc = phc_infiltration_new(table, &o, out, err)))
        goto done;
    if (phc_dataset_add_input(*out, path)) {
        phc_dataset_free(*out);
        *out = NULL;
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
done:
    phc_soil_setup_yaml_free(&soil_yaml);
    phc_table_free(table);
    free(path);
    return rc;
}

const phc_kind phc_infiltration_kind = {
    .config = {.name = "infiltration",
               .summary = "the depth reached by a fraction of the applied rain over time -> soil "
                          "permeability p and capacity c (Rhizomorph §6, Fig. 7)",
               .keys = infiltration_keys,
               .help = infiltration_help},
    .ops = &phc_infiltration_ops,
    .load_yaml = infiltration_yaml,
};
