/* `kind: root_shoot` in a config: its keys and their help, and the
 * translation of its mapping (and of the harvest table or BAAD study it
 * names) into phc_root_shoot_new's inputs (fit/costs/root_shoot.h,
 * fit/costs/harvest.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "fit/config/kind.h"
#include "fit/config/kinds.h"
#include "fit/config/soil_setup_yaml.h"
#include "fit/config/yaml_keys.h"
#include "fit/costs/harvest.h"
#include "fit/costs/root_shoot.h"
#include "fit/costs/source_file.h"

static const char *const root_shoot_keys[] = {
    "file", "diameter", "root_mass", "shoot_mass", "leaf_mass", "stem_mass", "age", "baad",
    "species", "suspicious", "select", "sigma", "preset", "growth", "mode", "seed", "uptake",
    "days", "step", "plant", "soil", "x_label", "y_label", NULL};
static const phc_key_help root_shoot_help[] = {
    {"file", "CSV table of harvested plants, relative to the config file. Give exactly one of "
             "file and baad."},
    {"diameter", "With file: {column: NAME, unit: UNIT} or a column name: basal diameters, "
                 "> 0; default unit mm. Required with file."},
    {"root_mass", "With file: {column, unit} or a column: root masses, > 0; default unit g. "
                  "Required with file."},
    {"shoot_mass", "With file: {column, unit} or a column: shoot masses (stem and leaves), > 0; "
                   "default unit g. Required with file unless leaf_mass and stem_mass are "
                   "given."},
    {"leaf_mass", "With file, instead of shoot_mass: {column, unit} or a column of leaf masses, "
                  "default unit g, added to stem_mass. Optional."},
    {"stem_mass", "With file, instead of shoot_mass: {column, unit} or a column of stem masses, "
                  "default unit g, added to leaf_mass. Optional."},
    {"age", "With file: {column, unit} or a column of plant ages, default unit d, compared "
            "with the simulated ages in the report. Optional."},
    {"baad", "A BAAD study folder (its data.csv), relative to the config file. Give exactly one "
             "of file and baad."},
    {"species", "With baad: the species whose plants are used; the report says whether the "
                "growth preset describes it (by genus). Required with baad."},
    {"suspicious", "With baad: exclude or keep the rows BAAD flags as suspicious (listed in the "
                   "report). Default: exclude."},
    {"select", "{column: NAME, equals: VALUE}: keep only the rows whose column (of the table, "
               "or a raw BAAD column) equals VALUE. Default: every row."},
    {"sigma", "Standard deviation of ln(root mass / shoot mass), > 0. Required."},
    {"preset", "Growth preset: oak, cherry, apple, poplar or maple. Default: oak."},
    {"growth", "{NAME: value, ...}: growth parameters (model/growth.h names, e.g. phi_rg) "
               "overriding the preset's. Default: none."},
    {"mode", "expected (smooth) or stochastic (branching drawn with seed). "
             "Default: expected."},
    {"seed", "Random seed of stochastic mode, a whole number >= 0. Default: 1."},
    {"uptake", "Root water uptake: physical or none (the authors' code). Default: physical."},
    {"days", "Longest simulated age, d, > 0. Default: 365."},
    {"step", "Growth step, d, 0 < step <= days. Default: 1."},
    {"plant", "{x, y, depth}: where the seed is planted in the soil grid, m. Default: the "
              "centre of the surface."},
    {"soil", "The soil the plant grows in, e.g. a pot (the soil: keys below). Default: none "
             "(the roots see the growth parameter soil_fill as fill level)."},
    {"x_label", "Axis label of the diameter. Default: \"basal diameter (mm)\"."},
    {"y_label", "Axis label of the ratio. Default: \"ln(root mass / shoot mass)\"."},
    {NULL, NULL}};

/* The lines the data set's messages have always named: the growth: and
 * plant: mappings' own lines, the other keys' lines. */
static size_t rs_key_line(const void *map, const char *key)
{
    const phc_yaml_node *node = map;
    if (!strcmp(key, "growth") || !strcmp(key, "plant")) {
        const phc_yaml_node *v = phc_yaml_get(node, key);
        return v ? v->line : node->line;
    }
    return phc_key_line(node, key);
}

/* The optional `select: {column: C, equals: V}` filter. */
static int read_select(const phc_yaml_doc *doc, const phc_yaml_node *node, const char **col,
                       const char **val, phc_error *err)
{
    *col = *val = NULL;
    const phc_yaml_node *sel = phc_yaml_get(node, "select");
    if (!sel) return PHC_OK;
    static const char *const keys[] = {"column", "equals", NULL};
    int rc = phc_yaml_check_keys(doc, sel, keys, "select", err);
    if (!rc) rc = phc_yaml_map_string(doc, sel, "column", 1, "select", col, err);
    if (!rc) rc = phc_yaml_map_string(doc, sel, "equals", 1, "select", val, err);
    return rc;
}

/* The harvest table `file` and its columns. */
static int harvest_table(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *path,
                         const phc_origin *origin, phc_harvest **out, phc_error *err)
{
    const char *ctx = "root_shoot data set";
    phc_harvest_columns c = {.origin = origin};
    phc_table *t = NULL;
    int rc;
    if ((rc = phc_column_spec(doc, node, "diameter", ctx, "mm", &c.diameter, &c.diameter_unit, err)) ||
        (rc = phc_column_spec(doc, node, "root_mass", ctx, "g", &c.root_mass, &c.root_mass_unit, err)))
        return rc;
    if (phc_yaml_get(node, "shoot_mass")) {
        if ((rc = phc_column_spec(doc, node, "shoot_mass", ctx, "g", &c.shoot_mass, &c.shoot_mass_unit, err)))
            return rc;
    } else if ((phc_yaml_get(node, "leaf_mass") &&
                (rc = phc_column_spec(doc, node, "leaf_mass", ctx, "g", &c.leaf_mass, &c.leaf_mass_unit, err))) ||
               (phc_yaml_get(node, "stem_mass") &&
                (rc = phc_column_spec(doc, node, "stem_mass", ctx, "g", &c.stem_mass, &c.stem_mass_unit, err)))) {
        return rc;
    }
    if (phc_yaml_get(node, "age") &&
        (rc = phc_column_spec(doc, node, "age", ctx, "d", &c.age, &c.age_unit, err)))
        return rc;
    if ((rc = read_select(doc, node, &c.select_column, &c.select_value, err)))
        return rc;
    if ((rc = phc_table_read(path, &t, err))) {
        if (rc == PHC_ERR_IO) /* a file that cannot be read: which key named it */
            phc_error_prefix(err, rc, "%s:%zu: key 'file'", doc->path, phc_key_line(node, "file"));
        return rc;
    }
    rc = phc_harvest_from_table(t, &c, out, err);
    phc_table_free(t);
    return rc;
}

/* The BAAD study folder `path`: species, suspicious rows, select. */
static int harvest_baad(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *path,
                        const phc_origin *origin, phc_harvest **out, phc_error *err)
{
    const char *ctx = "root_shoot data set", *susp = "exclude";
    phc_harvest_baad_options b = {.origin = origin};
    int rc;
    if ((rc = phc_yaml_map_string(doc, node, "species", 1, ctx, &b.species, err)) ||
        (rc = phc_yaml_map_string(doc, node, "suspicious", 0, ctx, &susp, err)) ||
        (rc = read_select(doc, node, &b.select_column, &b.select_value, err)))
        return rc;
    if (!strcmp(susp, "keep")) b.keep_suspicious = 1;
    else if (strcmp(susp, "exclude"))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: key 'suspicious': expected 'exclude' or 'keep', found '%s'",
                             doc->path, phc_key_line(node, "suspicious"), susp);
    return phc_harvest_read_baad(path, &b, out, err);
}

/* The growth model's options: preset and overrides, mode, seed, uptake. */
static int growth_options(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *mode, double seed,
                          const char *uptake, phc_root_shoot_options *o, phc_growth_params *gp, phc_error *err)
{
    int rc;
    if ((rc = phc_growth_preset(o->preset, gp, err)))
        return phc_error_prefix(err, rc, "%s:%zu: key 'preset'", doc->path, phc_key_line(node, "preset"));
    if (!strcasecmp(mode, "stochastic")) o->mode = PHC_GROWTH_STOCHASTIC;
    else if (strcasecmp(mode, "expected"))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: key 'mode': expected 'expected' or 'stochastic', found '%s'",
                             doc->path, phc_key_line(node, "mode"), mode);
    if (!(seed >= 0) || seed != floor(seed))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'seed': expected a whole number >= 0, found %g",
                             doc->path, phc_key_line(node, "seed"), seed);
    o->seed = (uint64_t)seed;
    if (!strcasecmp(uptake, "none")) o->uptake = PHC_GROWTH_UPTAKE_NONE;
    else if (strcasecmp(uptake, "physical"))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: key 'uptake': expected 'physical' or 'none', found '%s'",
                             doc->path, phc_key_line(node, "uptake"), uptake);
    /* growth: {name: value} overrides */
    const phc_yaml_node *gr = phc_yaml_get(node, "growth");
    if (gr && gr->kind != PHC_YAML_MAPPING)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'growth': expected a mapping of growth "
                             "parameters to values", doc->path, gr->line);
    for (size_t q = 0; gr && q < gr->count; ++q) {
        long k = phc_growth_param_find(gr->keys[q]);
        if (k < 0)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: growth: unknown growth parameter '%s' (see model/growth.h "
                                 "or the README's list)",
                                 doc->path, gr->key_lines[q], gr->keys[q]);
        if ((rc = phc_yaml_number(doc, gr->values[q], gr->keys[q], phc_growth_param_ref(gp, (size_t)k), err)))
            return rc;
    }
    o->growth = gp;
    return PHC_OK;
}

/* plant: {x, y, depth} */
static int plant_position(const phc_yaml_doc *doc, const phc_yaml_node *node, phc_root_shoot_options *o,
                          phc_error *err)
{
    static const char *const pkeys[] = {"x", "y", "depth", NULL};
    const phc_yaml_node *pl = phc_yaml_get(node, "plant");
    int rc;
    if (pl && ((rc = phc_yaml_check_keys(doc, pl, pkeys, "plant", err)) ||
               (rc = phc_yaml_map_number(doc, pl, "x", 0, "plant", &o->plant_x, err)) ||
               (rc = phc_yaml_map_number(doc, pl, "y", 0, "plant", &o->plant_y, err)) ||
               (rc = phc_yaml_map_number(doc, pl, "depth", 0, "plant", &o->plant_depth, err))))
        return rc;
    return PHC_OK;
}

static int root_shoot_yaml(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                           phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out, phc_error *err)
{
    const char *ctx = "root_shoot data set";
    const char *file = NULL, *baad = NULL, *mode = "expected", *uptake = "physical";
    double seed = 1;
    phc_root_shoot_options o = phc_root_shoot_options_default();
    const phc_origin origin = {.path = doc->path, .map = node, .key_line = rs_key_line, .line = node->line};
    phc_soil_setup_yaml soil_yaml = {0};
    phc_growth_params gp;
    phc_harvest *plants = NULL;
    char *path = NULL;
    int rc;
    *out = NULL;
    if ((rc = phc_yaml_map_string(doc, node, "file", 0, ctx, &file, err)) ||
        (rc = phc_yaml_map_string(doc, node, "baad", 0, ctx, &baad, err)) ||
        (rc = phc_yaml_map_number(doc, node, "sigma", 1, ctx, &o.sigma, err)) ||
        (rc = phc_yaml_map_string(doc, node, "preset", 0, ctx, &o.preset, err)) ||
        (rc = phc_yaml_map_string(doc, node, "mode", 0, ctx, &mode, err)) ||
        (rc = phc_yaml_map_number(doc, node, "seed", 0, ctx, &seed, err)) ||
        (rc = phc_yaml_map_string(doc, node, "uptake", 0, ctx, &uptake, err)) ||
        (rc = phc_yaml_map_number(doc, node, "days", 0, ctx, &o.days, err)) ||
        (rc = phc_yaml_map_number(doc, node, "step", 0, ctx, &o.step, err)) ||
        (rc = phc_yaml_map_string(doc, node, "x_label", 0, ctx, &o.x_label, err)) ||
        (rc = phc_yaml_map_string(doc, node, "y_label", 0, ctx, &o.y_label, err)))
        goto done;
    if (!file == !baad) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: root_shoot data set: give exactly one of 'file' (a table) "
                           "and 'baad' (a BAAD study folder)",
                           doc->path, node->line);
        goto done;
    }
    const phc_yaml_node *soil = phc_yaml_get(node, "soil");
    if ((rc = growth_options(doc, node, mode, seed, uptake, &o, &gp, err)) ||
        (soil && (rc = phc_soil_setup_yaml_read(doc, soil, &soil_yaml, err))) ||
        (rc = plant_position(doc, node, &o, err)))
        goto done;
    if (!(path = phc_join_path(base_dir, file ? file : baad))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    if ((rc = file ? harvest_table(doc, node, path, &origin, &plants, err)
                   : harvest_baad(doc, node, path, &origin, &plants, err)))
        goto done;
    if (baad && (rc = phc_yaml_map_string(doc, node, "species", 1, ctx, &o.species, err)))
        goto done;
    o.soil = soil ? &soil_yaml.options : NULL;
    o.is_parameter = is_parameter;
    o.user_data = user_data;
    o.origin = &origin;
    if ((rc = phc_root_shoot_new(plants, &o, out, err)))
        goto done;
    if (file && phc_dataset_add_input(*out, path)) {
        phc_dataset_free(*out);
        *out = NULL;
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
done:
    phc_soil_setup_yaml_free(&soil_yaml);
    phc_harvest_free(plants);
    free(path);
    return rc;
}

const phc_kind phc_root_shoot_kind = {
    .config = {.name = "root_shoot",
               .summary = "harvested plants' root:shoot against basal diameter -> growth parameters "
                          "(phi_rg, ...) and soil p, c (Rhizomorph §5-6)",
               .keys = root_shoot_keys,
               .help = root_shoot_help},
    .ops = &phc_root_shoot_ops,
    .load_yaml = root_shoot_yaml,
};
