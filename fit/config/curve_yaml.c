/* `kind: curve` in a config: its keys and their help, and the translation
 * of its mapping into phc_curve_options (fit/costs/curve.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/config/kind.h"
#include "fit/config/kinds.h"
#include "fit/config/yaml_keys.h"
#include "fit/costs/curve.h"
#include "fit/costs/source_file.h"

static const char *const curve_keys[] = {"file", "x", "y", "expression", "sigma",
                                         "x_label", "y_label", NULL};
static const phc_key_help curve_help[] = {
    {"file", "CSV table of the observations (header line, then rows), relative to the config "
             "file. Required."},
    {"x", "Column used as abscissa in plots and to order the residuals. Required."},
    {"y", "Column of observed values. Required."},
    {"expression", "The model, in muparser syntax: numbers, parameter and column names, "
                   "+ - * / ^, parentheses, exp log sqrt sin cos tan atan abs (and muparser's "
                   "other functions), pi. A name is a parameter slot when it is a global "
                   "parameter or a key of the data set's `parameters:` binding, otherwise a "
                   "column of the file (both is an error). Required."},
    {"sigma", "A positive number (one sigma for every point, in y units) or the name of a "
              "column of per-point sigmas. Default: unweighted."},
    {"x_label", "Axis label of x in plots. Default: the x column's name."},
    {"y_label", "Axis label of y in plots. Default: the y column's name."},
    {NULL, NULL}};

static int curve_yaml(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                      phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out, phc_error *err)
{
    const char *ctx = "curve data set", *file = NULL;
    phc_curve_options o = phc_curve_options_default();
    const phc_origin origin = phc_yaml_origin(doc, node);
    phc_table *table = NULL;
    int rc;

    *out = NULL;
    if ((rc = phc_yaml_map_string(doc, node, "file", 1, ctx, &file, err)) ||
        (rc = phc_yaml_map_string(doc, node, "x", 1, ctx, &o.x, err)) ||
        (rc = phc_yaml_map_string(doc, node, "y", 1, ctx, &o.y, err)) ||
        (rc = phc_yaml_map_string(doc, node, "expression", 1, ctx, &o.expression, err)) ||
        (rc = phc_yaml_map_string(doc, node, "x_label", 0, ctx, &o.x_label, err)) ||
        (rc = phc_yaml_map_string(doc, node, "y_label", 0, ctx, &o.y_label, err)))
        return rc;
    char *path = phc_join_path(base_dir, file);
    if (!path)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if ((rc = phc_kind_read_table(user_data, path, &table, err))) {
        if (rc == PHC_ERR_IO) /* a file that cannot be read: which key named it */
            phc_error_prefix(err, rc, "%s:%zu: key 'file'", doc->path, phc_key_line(node, "file"));
        goto done;
    }
    /* sigma: a column of the file, else a positive number */
    const phc_yaml_node *sig = phc_yaml_get(node, "sigma");
    if (sig && sig->kind == PHC_YAML_SCALAR && phc_table_find(table, sig->scalar) >= 0) {
        o.sigma_column = sig->scalar;
    } else if (sig) {
        if ((rc = phc_yaml_number(doc, sig, "sigma", &o.sigma, err))) {
            phc_error_set(err, rc,
                          "%s:%zu: key 'sigma': expected a positive number or a column of %s, found '%s'",
                          doc->path, sig->line, path, sig->kind == PHC_YAML_SCALAR ? sig->scalar : "(not a scalar)");
            goto done;
        }
        if (!(o.sigma > 0)) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'sigma': must be positive, found %g",
                               doc->path, sig->line, o.sigma);
            goto done;
        }
    }
    o.is_parameter = is_parameter;
    o.user_data = user_data;
    o.origin = &origin;
    if ((rc = phc_curve_new(table, &o, out, err)))
        goto done;
    if (phc_dataset_add_input(*out, path)) {
        phc_dataset_free(*out);
        *out = NULL;
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
done:
    phc_table_free(table);
    free(path);
    return rc;
}

const phc_kind phc_curve_kind = {
    .config = {.name = "curve",
               .summary = "any expression of columns and parameters (muparser) fitted to a column; "
                          "the NIST StRD problems, enzyme kinetics",
               .keys = curve_keys,
               .help = curve_help},
    .ops = &phc_curve_ops,
    .load_yaml = curve_yaml,
    .each = 1,
};
