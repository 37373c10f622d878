/* `kind: pv_curve` in a config: its keys and their help, and the translation
 * of its mapping into phc_pv_curve_options (fit/costs/pv_curve.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/config/kind.h"
#include "fit/config/kinds.h"
#include "fit/config/yaml_keys.h"
#include "fit/costs/pv_curve.h"
#include "fit/costs/source_file.h"

static const char *const pv_curve_keys[] = {"file", "psi", "psi_unit", "fresh_mass", "bag_mass", "dry_mass",
                                            "saturated_mass", "group", "leaf", "breakpoint", "sigma",
                                            "convention", "tlp", "modulus_points", "leaf_area", NULL};
static const phc_key_help pv_curve_help[] = {
    {"file", "CSV table of the pressure-volume points, at least 6 per leaf, relative to the "
             "config file. Required."},
    {"psi", "Column of water potentials, every value < 0 (enter pressure-chamber balance "
            "pressures with a minus sign). Required."},
    {"psi_unit", "Unit of psi: MPa, bar or kPa (case ignored). Default: MPa."},
    {"fresh_mass", "Column of weighed masses, g: the leaf, or the leaf in its bag when bag_mass "
                   "is given. Required."},
    {"bag_mass", "A column or a number, g, subtracted from fresh_mass (the bagged-leaf "
                 "protocol). Default: none."},
    {"dry_mass", "A column or a number, g, below every leaf mass. Required."},
    {"saturated_mass", "The turgid leaf mass, g: a column or a number; or extrapolate (the "
                       "saturated water from psi against leaf water at psi = 0 over the wettest "
                       "3 to 5 points). Required."},
    {"group", "Column of leaf ids, for a table of several leaves. Default: one leaf."},
    {"leaf", "With group: one leaf id, each (one logistic per leaf: slots kappa_<id>, "
             "chi0_<id>, e_min_<id>, e_max_<id>) or pooled (one logistic for all leaves). "
             "Required when the group column holds more than one id."},
    {"breakpoint", "How the linear (osmotic) region is chosen: min_rss, max_r2, or a whole "
                   "number >= 3 of driest points. Default: min_rss."},
    {"sigma", "Standard deviation of the moduli, a positive number, MPa. "
              "Default: unweighted."},
    {"convention", "phytocal (the defaults below) or photosynthesis (exactly as the R package "
                   "photosynthesis::fit_PV_curve: breakpoint max_r2 over its candidates, tlp "
                   "measured at its cut row, modulus_points shared_break). The keys below "
                   "override it. Default: phytocal."},
    {"tlp", "fitted (where the turgor line reaches zero) or measured (the measured point at "
            "the break). Default: fitted (measured with convention photosynthesis)."},
    {"modulus_points", "Points of the bulk modulus (turgor line): above_break or shared_break "
                       "(down to and including the break point). Default: above_break "
                       "(shared_break with convention photosynthesis)."},
    {"leaf_area", "A column or a number, cm2 (> 0): gives C*_FT, the capacitance at full turgor "
                  "per leaf area (mol m-2 MPa-1). Default: none."},
    {NULL, NULL}};

/* `breakpoint:` min_rss | max_r2 | a whole number >= 3 of driest points. */
static int read_breakpoint(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *bp,
                           phc_pv_options *analysis, phc_error *err)
{
    char *end = NULL;
    long m = strtol(bp, &end, 10);
    if (strcmp(bp, "min_rss") == 0)
        analysis->rule = PHC_PV_BREAK_MIN_RSS;
    else if (strcmp(bp, "max_r2") == 0)
        analysis->rule = PHC_PV_BREAK_MAX_R2;
    else if (end != bp && *end == '\0' && m >= 3) {
        analysis->rule = PHC_PV_BREAK_FIXED;
        analysis->n_osmotic = (size_t)m;
    } else
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: key 'breakpoint': expected min_rss, max_r2 or a whole number of points >= 3, "
                             "found '%s'", doc->path, phc_key_line(node, "breakpoint"), bp);
    return PHC_OK;
}

/* The mapping's strings into the options (file into *file). */
static int read_keys(const phc_yaml_doc *doc, const phc_yaml_node *node, const char **file,
                     phc_pv_curve_options *o, phc_error *err)
{
    const char *ctx = "pv_curve data set", *bp = NULL;
    static const char *const conventions[] = {"phytocal", "photosynthesis", NULL};
    static const char *const tlps[] = {"fitted", "measured", NULL};
    static const char *const points[] = {"above_break", "shared_break", NULL};
    int rc, convention = 0, tlp = -1, mp = -1;
    if ((rc = phc_yaml_map_string(doc, node, "file", 1, ctx, file, err)) ||
        (rc = phc_yaml_map_string(doc, node, "psi", 1, ctx, &o->psi, err)) ||
        (rc = phc_yaml_map_string(doc, node, "psi_unit", 0, ctx, &o->psi_unit, err)) ||
        (rc = phc_yaml_map_string(doc, node, "fresh_mass", 1, ctx, &o->fresh_mass, err)) ||
        (rc = phc_yaml_map_string(doc, node, "group", 0, ctx, &o->group, err)) ||
        (rc = phc_yaml_map_string(doc, node, "leaf", 0, ctx, &o->leaf, err)) ||
        (rc = phc_yaml_map_string(doc, node, "breakpoint", 0, ctx, &bp, err)) ||
        (rc = phc_yaml_map_choice(doc, node, "convention", ctx, conventions, &convention, err)) ||
        (rc = phc_yaml_map_choice(doc, node, "tlp", ctx, tlps, &tlp, err)) ||
        (rc = phc_yaml_map_choice(doc, node, "modulus_points", ctx, points, &mp, err)))
        return rc;
    if (convention == 1)
        o->analysis = phc_pv_options_photosynthesis();
    if (tlp >= 0)
        o->analysis.tlp = tlp ? PHC_PV_TLP_MEASURED : PHC_PV_TLP_FITTED;
    if (mp >= 0)
        o->analysis.modulus_points = mp ? PHC_PV_MODULUS_SHARED_BREAK : PHC_PV_MODULUS_ABOVE_BREAK;
    return bp ? read_breakpoint(doc, node, bp, &o->analysis, err) : PHC_OK;
}

/* A mass given as a column name or a number (g) into *m.  *extrapolate is
 * set instead when allowed and the value is `extrapolate`. */
static int read_mass(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *key, int required,
                     const phc_table *t, int *extrapolate, phc_pv_mass *m, phc_error *err)
{
    const phc_yaml_node *v = phc_yaml_get(node, key);
    if (!v) {
        if (!required)
            return PHC_OK;
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: pv_curve data set: missing key '%s' (a column of %s or a number in g%s)",
                             doc->path, node->line, key, phc_table_source(t),
                             extrapolate ? ", or 'extrapolate'" : "");
    }
    if (v->kind != PHC_YAML_SCALAR || !v->scalar[0])
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key '%s': expected a column name or a number (g)",
                             doc->path, v->line, key);
    if (extrapolate && strcmp(v->scalar, "extrapolate") == 0) {
        *extrapolate = 1;
        return PHC_OK;
    }
    if (phc_table_find(t, v->scalar) >= 0) {
        m->column = v->scalar;
        return PHC_OK;
    }
    phc_error tmp;
    phc_error_clear(&tmp);
    if (phc_yaml_number(doc, v, key, &m->value, &tmp) != PHC_OK) {
        int rc = phc_need_column(doc, node, key, v->scalar, t, err);
        if (rc == PHC_ERR_INPUT)
            strncat(err->message, " (nor a number)", sizeof err->message - strlen(err->message) - 1);
        return rc;
    }
    return PHC_OK; /* a negative number is refused by phc_pv_curve_new, at this key's line */
}

/* sigma: a positive number, MPa. */
static int read_sigma(const phc_yaml_doc *doc, const phc_yaml_node *node, double *sigma, phc_error *err)
{
    const phc_yaml_node *sig = phc_yaml_get(node, "sigma");
    double s = 0;
    if (!sig)
        return PHC_OK;
    if (phc_yaml_number(doc, sig, "sigma", &s, err) || !(s > 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'sigma': expected a positive number (MPa), found '%s'",
                             doc->path, sig->line, sig->kind == PHC_YAML_SCALAR ? sig->scalar : "(not a scalar)");
    *sigma = s;
    return PHC_OK;
}

static int pv_curve_yaml(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                         phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out, phc_error *err)
{
    (void)is_parameter; /* the slots are fixed: kappa, chi0, e_min, e_max (per leaf with `each`) */
    const char *file = NULL;
    phc_pv_curve_options o = phc_pv_curve_options_default();
    const phc_origin origin = phc_yaml_origin(doc, node);
    phc_table *table = NULL;
    char *path = NULL;
    int rc;

    *out = NULL;
    if ((rc = read_keys(doc, node, &file, &o, err)))
        return rc;
    if (!(path = phc_join_path(base_dir, file)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if ((rc = phc_kind_read_table(user_data, path, &table, err))) {
        if (rc == PHC_ERR_IO) /* a file that cannot be read: which key named it */
            phc_error_prefix(err, rc, "%s:%zu: key 'file'", doc->path, phc_key_line(node, "file"));
        goto done;
    }
    if ((rc = read_mass(doc, node, "bag_mass", 0, table, NULL, &o.bag_mass, err)) ||
        (rc = read_mass(doc, node, "dry_mass", 1, table, NULL, &o.dry_mass, err)) ||
        (rc = read_mass(doc, node, "saturated_mass", 1, table, &o.extrapolate_saturation, &o.saturated_mass, err)) ||
        (rc = read_mass(doc, node, "leaf_area", 0, table, NULL, &o.leaf_area, err)))
        goto done;
    /* A sigma that is not a positive number is reported after what the
     * data themselves show, as it always was. */
    phc_error sigma_err;
    phc_error_clear(&sigma_err);
    const int sigma_rc = read_sigma(doc, node, &o.sigma, &sigma_err);
    o.origin = &origin;
    if ((rc = phc_pv_curve_new(table, &o, out, err)))
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

const phc_kind phc_pv_curve_kind = {
    .config = {.name = "pv_curve",
               .summary = "pressure-volume data (water potential and mass along a bench dry-down) -> "
                          "PV traits per leaf and the logistic elasticity (wilting eq. 9)",
               .keys = pv_curve_keys,
               .help = pv_curve_help},
    .ops = &phc_pv_curve_ops,
    .load_yaml = pv_curve_yaml,
    .each = 1,
};
