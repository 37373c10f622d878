/* `kind: elasticity_curve` in a config: its keys and their help, and the
 * translation of its mapping into phc_elasticity_curve_options
 * (fit/costs/elasticity_curve.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/config/kind.h"
#include "fit/config/kinds.h"
#include "fit/config/yaml_keys.h"
#include "fit/costs/elasticity_curve.h"
#include "fit/costs/source_file.h"

static const char *const elasticity_curve_keys[] = {"file", "water", "water_content", "modulus", "sigma",
                                                    "x_label", "y_label", NULL};
static const phc_key_help elasticity_curve_help[] = {
    {"file", "CSV table of the measurements, relative to the config file. Required."},
    {"water", "Column of water contents. Required."},
    {"water_content", "What the water column holds: rwc (relative water content as a fraction "
                      "0 to 1; values above 1.5 are refused as probably percent) or absolute "
                      "(water in any unit, >= 0; chi0 then has that unit and kappa its "
                      "inverse). Required."},
    {"modulus", "Column of bulk moduli of elasticity, MPa. Required."},
    {"sigma", "A positive number (MPa) or the name of a column of per-point sigmas. "
              "Default: unweighted."},
    {"x_label", "Axis label of the water content. Default: \"relative water content (RWC)\" "
                "or \"water content (COLUMN)\"."},
    {"y_label", "Axis label of the modulus. Default: \"bulk modulus of elasticity (MPa)\"."},
    {NULL, NULL}};

/* The mapping's strings into the options (file into *file). */
static int read_keys(const phc_yaml_doc *doc, const phc_yaml_node *node, const char **file,
                     phc_elasticity_curve_options *o, phc_error *err)
{
    const char *ctx = "elasticity_curve data set", *content = NULL;
    int rc;
    if ((rc = phc_yaml_map_string(doc, node, "file", 1, ctx, file, err)) ||
        (rc = phc_yaml_map_string(doc, node, "water", 1, ctx, &o->water, err)) ||
        (rc = phc_yaml_map_string(doc, node, "water_content", 1, ctx, &content, err)) ||
        (rc = phc_yaml_map_string(doc, node, "modulus", 1, ctx, &o->modulus, err)) ||
        (rc = phc_yaml_map_string(doc, node, "x_label", 0, ctx, &o->x_label, err)) ||
        (rc = phc_yaml_map_string(doc, node, "y_label", 0, ctx, &o->y_label, err)))
        return rc;
    if (strcmp(content, "rwc") == 0)
        o->water_content = PHC_WATER_CONTENT_RWC;
    else if (strcmp(content, "absolute") == 0)
        o->water_content = PHC_WATER_CONTENT_ABSOLUTE;
    else
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'water_content': expected rwc or absolute, found '%s'",
                             doc->path, phc_key_line(node, "water_content"), content);
    return PHC_OK;
}

/* sigma: a column of the table, else a positive number (MPa). */
static int read_sigma(const phc_yaml_doc *doc, const phc_yaml_node *node, const phc_table *table,
                      phc_elasticity_curve_options *o, phc_error *err)
{
    const phc_yaml_node *sig = phc_yaml_get(node, "sigma");
    if (!sig)
        return PHC_OK;
    if (sig->kind == PHC_YAML_SCALAR && phc_table_find(table, sig->scalar) >= 0) {
        o->sigma_column = sig->scalar;
        return PHC_OK;
    }
    double s = 0;
    if (phc_yaml_number(doc, sig, "sigma", &s, err) || !(s > 0))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: key 'sigma': expected a positive number (MPa) or a column of %s, found '%s'",
                             doc->path, sig->line, phc_table_source(table),
                             sig->kind == PHC_YAML_SCALAR ? sig->scalar : "(not a scalar)");
    o->sigma = s;
    return PHC_OK;
}

static int elasticity_curve_yaml(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                                 phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out,
                                 phc_error *err)
{
    (void)is_parameter; /* the slots are fixed: kappa, chi0, e_min, e_max */
    (void)user_data;
    const char *file = NULL;
    phc_elasticity_curve_options o = phc_elasticity_curve_options_default();
    const phc_origin origin = phc_yaml_origin(doc, node);
    phc_table *table = NULL;
    char *path = NULL;
    int rc;

    *out = NULL;
    if ((rc = read_keys(doc, node, &file, &o, err)))
        return rc;
    if (!(path = phc_join_path(base_dir, file)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if ((rc = phc_table_read(path, &table, err))) {
        if (rc == PHC_ERR_IO) /* a file that cannot be read: which key named it */
            phc_error_prefix(err, rc, "%s:%zu: key 'file'", doc->path, phc_key_line(node, "file"));
        goto done;
    }
    /* A sigma that is neither a column nor a positive number is reported
     * after what the data themselves show, as it always was. */
    phc_error sigma_err;
    phc_error_clear(&sigma_err);
    const int sigma_rc = read_sigma(doc, node, table, &o, &sigma_err);
    o.origin = &origin;
    if ((rc = phc_elasticity_curve_new(table, &o, out, err)))
        goto done;
    if (sigma_rc) {
        phc_dataset_free(*out);
        *out = NULL;
        if (err)
            *err = sigma_err;
        rc = sigma_rc;
    } else if (phc_dataset_add_input(*out, path)) {
        phc_dataset_free(*out);
        *out = NULL;
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
done:
    phc_table_free(table);
    free(path);
    return rc;
}

const phc_kind phc_elasticity_curve_kind = {
    .config = {.name = "elasticity_curve",
               .summary = "bulk moduli against water content -> the logistic elasticity "
                          "kappa, chi0, e_min, e_max (wilting eq. 9)",
               .keys = elasticity_curve_keys,
               .help = elasticity_curve_help},
    .ops = &phc_elasticity_curve_ops,
    .load_yaml = elasticity_curve_yaml,
};
