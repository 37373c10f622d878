/* `kind: leaf_photos` in a config: its keys and their help, and the
 * translation of its mapping (and of the table it names) into the rows and
 * phc_leaf_photos_options of fit/costs/leaf_photos.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/config/kind.h"
#include "fit/config/kinds.h"
#include "fit/config/yaml_keys.h"
#include "fit/costs/leaf_photos.h"
#include "fit/costs/source_file.h"
#include "measurements/table.h"

static const char *const leaf_photos_keys[] = {
    "file", "image", "leaf", "id", "stage", "initial", "reference", "residual", "difference", "grid",
    "quantiles", "sigma", "colour_space", "colour_correction", "register", "model_size", "dt", "veins",
    "vein_floor", "stomata", "inflow", "cross_validate", "x_label", "y_label", NULL};
static const phc_key_help leaf_photos_help[] = {
    {"file", "CSV table with one row per photographed leaf, relative to the config file: the "
             "fresh leaf and at least one more. Required."},
    {"image", "The photo of every row (a file relative to the config file), or {column: NAME}: "
              "a column naming each row's photo. Required."},
    {"leaf", "Column: the leaf's number in its photo, a whole number >= 1 in reading order. "
             "Default: 1 for every row."},
    {"id", "Column naming the rows (for initial and reference). Default: the leaf column, "
           "else the row's line number."},
    {"stage", "{column: NAME, direction: increasing | decreasing} or a column name: each "
              "photo's stage, a time (increasing, the default) or a measured stage such as "
              "SPAD chlorophyll (decreasing); with residual pixels the rows are in stage order. "
              "Required."},
    {"initial", "Id of the row of the fresh leaf the model ages. Default: the row with the "
                "earliest stage."},
    {"reference", "The senescent reference leaf (eq. 8): a row id (not the initial one), or "
                  "{image: FILE, leaf: N} (N default 1). Required."},
    {"residual", "pixels (CIELAB means over grid cells of the photo and the simulated leaf) or "
                 "histogram (quantiles of L*, a*, b* over the leaf; for photos of different "
                 "leaves or that cannot be registered). Default: pixels."},
    {"difference", "pixels: de76 (3 residuals per cell, dL*, da*, db*) or ciede2000 (one per "
                   "cell). Default: de76."},
    {"grid", "pixels: grid cells on the long side of the leaf, 2 to 512. Default: 24."},
    {"quantiles", "histogram: quantiles per CIELAB channel, 2 to 256. Default: 16."},
    {"sigma", "Standard deviation of each residual, delta-E units, > 0. Default: 2."},
    {"colour_space", "Space in which the fresh leaf's colours are matched to the reference's: "
                     "rgb (the paper's) or lab. Default: rgb."},
    {"colour_correction", "Colour correction of every photo: none, gray_world or colorchecker "
                          "(a 24-patch ColorChecker Classic in the frame). Default: none."},
    {"register", "pixels: align each photo to the fresh leaf's (ECC on the silhouettes). "
                 "Default: true."},
    {"model_size", "Simulation grid, px on the long side of the leaf, 16 to 4096. "
                   "Default: 128."},
    {"dt", "Model step, in model time units, > 0. Default: 0.1."},
    {"veins", "Venation map: auto (ridge map of the fresh photo), uniform, or an image file the "
              "size of the fresh leaf's photo. Default: auto."},
    {"vein_floor", "Venation value on the lamina between veins, 0 to 1. Default: 0.05."},
    {"stomata", "Stomata map: uniform or an image file. Default: uniform."},
    {"inflow", "Inflow map: veins (the venation map), uniform, none or an image file. "
               "Default: veins."},
    {"cross_validate", "After the fit, predict each row's stage with that row left out, beside "
                       "a greenness baseline, in the report. Default: false."},
    {"x_label", "Axis label of the stage. Default: the stage column's name."},
    {"y_label", "Axis label of the residuals. Default: names the residual (e.g. \"CIELAB cell "
                "mean (L*, a*, b*)\")."},
    {NULL, NULL}};

static const char *const ctx = "leaf_photos data set";

/* What the translation reads and owns until the data set is built. */
typedef struct lp_yaml {
    const phc_yaml_doc *doc;
    const phc_yaml_node *node;
    const char *base_dir;
    phc_leaf_photos_options o;
    phc_origin origin, reference_origin;
    const char *file, *leaf_col, *id_col, *stage_col, *image_name, *image_col;
    const phc_yaml_node *stage_node, *image_node;
    char *path;                                   /* the table, as opened */
    char *veins_file, *stomata_file, *inflow_file, *reference_path;
    phc_table *t;
    double *stage, *leafno;                       /* per row; leafno NULL without `leaf` */
    phc_leaf_photos_row *rows;
    char **images;                                /* per row, as opened (NULL: none given) */
    size_t n_rows;
} lp_yaml;

static void lp_yaml_free(lp_yaml *y)
{
    for (size_t r = 0; y->images && r < y->n_rows; ++r)
        free(y->images[r]);
    free(y->images);
    free(y->rows);
    free(y->stage);
    free(y->leafno);
    phc_table_free(y->t);
    free(y->path);
    free(y->veins_file);
    free(y->stomata_file);
    free(y->inflow_file);
    free(y->reference_path);
}

/* A map key: the keywords in `names` (their index in *source), or a file. */
static int map_key(const lp_yaml *y, const char *key, const char *const *names, const phc_leaf_map_source *sources,
                   phc_leaf_map_source *source, char **file, phc_error *err)
{
    const char *v = NULL;
    int rc;
    if ((rc = phc_yaml_map_string(y->doc, y->node, key, 0, ctx, &v, err)) || !v)
        return rc;
    for (int i = 0; names[i]; ++i)
        if (!strcmp(v, names[i])) {
            *source = sources[i];
            return PHC_OK;
        }
    *source = PHC_LEAF_MAP_FILE;
    if (!(*file = phc_join_path(y->base_dir, v)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    return PHC_OK;
}

/* The keys that are plain values: names, choices, numbers, map sources. */
static int read_values(lp_yaml *y, phc_error *err)
{
    static const char *const residual_names[] = {"pixels", "histogram", NULL};
    static const char *const difference_names[] = {"de76", "ciede2000", NULL};
    static const char *const space_names[] = {"rgb", "lab", NULL};
    static const char *const correction_names[] = {"none", "gray_world", "colorchecker", NULL};
    static const phc_colour_correction_method corrections[] = {PHC_CC_NONE, PHC_CC_GRAY_WORLD, PHC_CC_COLORCHECKER};
    static const char *const vein_names[] = {"auto", "uniform", NULL};
    static const phc_leaf_map_source vein_sources[] = {PHC_LEAF_MAP_AUTO, PHC_LEAF_MAP_UNIFORM};
    static const char *const stomata_names[] = {"uniform", NULL};
    static const phc_leaf_map_source stomata_sources[] = {PHC_LEAF_MAP_UNIFORM};
    static const char *const inflow_names[] = {"veins", "uniform", "none", NULL};
    static const phc_leaf_map_source inflow_sources[] = {PHC_LEAF_MAP_AUTO, PHC_LEAF_MAP_UNIFORM, PHC_LEAF_MAP_NONE};
    const phc_yaml_doc *doc = y->doc;
    const phc_yaml_node *node = y->node;
    phc_leaf_photos_options *o = &y->o;
    int residual = 0, difference = 0, space = 0, correction = 0;
    long grid = (long)o->grid, nq = (long)o->quantiles, model_size = (long)o->setup.model_size;
    int rc;
    if ((rc = phc_yaml_map_string(doc, node, "file", 1, ctx, &y->file, err)) ||
        (rc = phc_yaml_map_string(doc, node, "leaf", 0, ctx, &y->leaf_col, err)) ||
        (rc = phc_yaml_map_string(doc, node, "id", 0, ctx, &y->id_col, err)) ||
        (rc = phc_yaml_map_string(doc, node, "x_label", 0, ctx, &o->x_label, err)) ||
        (rc = phc_yaml_map_string(doc, node, "y_label", 0, ctx, &o->y_label, err)) ||
        (rc = phc_yaml_map_choice(doc, node, "residual", ctx, residual_names, &residual, err)) ||
        (rc = phc_yaml_map_choice(doc, node, "difference", ctx, difference_names, &difference, err)) ||
        (rc = phc_yaml_map_choice(doc, node, "colour_space", ctx, space_names, &space, err)) ||
        (rc = phc_yaml_map_choice(doc, node, "colour_correction", ctx, correction_names, &correction, err)) ||
        (rc = phc_yaml_map_boolean(doc, node, "register", 0, ctx, &o->register_photos, err)) ||
        (rc = phc_yaml_map_boolean(doc, node, "cross_validate", 0, ctx, &o->cross_validate, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "grid", 0, ctx, &grid, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "quantiles", 0, ctx, &nq, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "model_size", 0, ctx, &model_size, err)) ||
        (rc = phc_yaml_map_number(doc, node, "sigma", 0, ctx, &o->sigma, err)) ||
        (rc = phc_yaml_map_number(doc, node, "dt", 0, ctx, &o->setup.dt, err)) ||
        (rc = phc_yaml_map_number(doc, node, "vein_floor", 0, ctx, &o->setup.vein_floor, err)) ||
        (rc = map_key(y, "veins", vein_names, vein_sources, &o->setup.veins, &y->veins_file, err)) ||
        (rc = map_key(y, "stomata", stomata_names, stomata_sources, &o->setup.stomata, &y->stomata_file, err)) ||
        (rc = map_key(y, "inflow", inflow_names, inflow_sources, &o->setup.inflow, &y->inflow_file, err)))
        return rc;
    /* out of range: a size the kind refuses with the key's line */
    o->grid = grid > 0 ? (size_t)grid : 0;
    o->quantiles = nq > 0 ? (size_t)nq : 0;
    o->setup.model_size = model_size > 0 ? (size_t)model_size : 0;
    o->residual = residual ? PHC_LEAF_RESIDUAL_HISTOGRAM : PHC_LEAF_RESIDUAL_PIXELS;
    o->difference = difference ? PHC_LEAF_CIEDE2000 : PHC_LEAF_DE76;
    o->setup.space = space ? PHC_COLOUR_LAB : PHC_COLOUR_RGB;
    o->colour_correction = corrections[correction];
    o->setup.veins_file = y->veins_file;
    o->setup.stomata_file = y->stomata_file;
    o->setup.inflow_file = y->inflow_file;
    return PHC_OK;
}

/* stage: {column, direction} or a bare column name. */
static int read_stage(lp_yaml *y, phc_error *err)
{
    static const char *const stage_keys[] = {"column", "direction", NULL};
    static const char *const direction_names[] = {"increasing", "decreasing", NULL};
    const phc_yaml_node *sn = y->stage_node = phc_yaml_get(y->node, "stage");
    int direction = 0, rc;
    if (!sn)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: missing key 'stage' ({column: NAME, direction: "
                             "increasing | decreasing})", y->doc->path, y->node->line, ctx);
    if (sn->kind == PHC_YAML_MAPPING) {
        if ((rc = phc_yaml_check_keys(y->doc, sn, stage_keys, "stage", err)) ||
            (rc = phc_yaml_map_string(y->doc, sn, "column", 1, "stage", &y->stage_col, err)) ||
            (rc = phc_yaml_map_choice(y->doc, sn, "direction", ctx, direction_names, &direction, err)))
            return rc;
    } else if ((rc = phc_yaml_string(y->doc, sn, "stage", &y->stage_col, err)))
        return rc;
    y->o.direction = direction ? -1 : 1;
    y->o.stage_name = y->stage_col;
    return PHC_OK;
}

/* image: a file for every row, or {column: NAME}. */
static int read_image(lp_yaml *y, phc_error *err)
{
    static const char *const image_keys[] = {"column", NULL};
    const phc_yaml_node *in = y->image_node = phc_yaml_get(y->node, "image");
    int rc;
    if (!in)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: missing key 'image' (a photo file, or {column: NAME})",
                             y->doc->path, y->node->line, ctx);
    if (in->kind == PHC_YAML_MAPPING) {
        if ((rc = phc_yaml_check_keys(y->doc, in, image_keys, "image", err)) ||
            (rc = phc_yaml_map_string(y->doc, in, "column", 1, "image", &y->image_col, err)))
            return rc;
    } else if ((rc = phc_yaml_string(y->doc, in, "image", &y->image_name, err)))
        return rc;
    y->o.image_column = y->image_col;
    return PHC_OK;
}

/* The table of rows, the columns the keys name, the stages and leaf numbers. */
static int read_table(lp_yaml *y, phc_error *err)
{
    const phc_yaml_doc *doc = y->doc;
    const phc_yaml_node *node = y->node, *sn = y->stage_node;
    int rc;
    if (!(y->path = phc_join_path(y->base_dir, y->file)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if ((rc = phc_table_read(y->path, &y->t, err))) {
        if (rc == PHC_ERR_IO) /* a file that cannot be read: which key named it */
            phc_error_prefix(err, rc, "%s:%zu: key 'file'", doc->path, phc_key_line(node, "file"));
        return rc;
    }
    const phc_table *t = y->t;
    const size_t nr = y->n_rows = phc_table_rows(t);
    if (nr < 2)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:1: %zu data row%s below the header: a leaf_photos data set "
                             "needs a fresh leaf and at least one more photo", y->path, nr, nr == 1 ? "" : "s");
    if ((rc = phc_need_column(doc, sn->kind == PHC_YAML_MAPPING ? sn : node,
                              sn->kind == PHC_YAML_MAPPING ? "column" : "stage", y->stage_col, t, err)) ||
        (y->leaf_col && (rc = phc_need_column(doc, node, "leaf", y->leaf_col, t, err))) ||
        (y->id_col && (rc = phc_need_column(doc, node, "id", y->id_col, t, err))) ||
        (y->image_col && (rc = phc_need_column(doc, y->image_node, "column", y->image_col, t, err))) ||
        (rc = phc_table_column_numbers(t, y->stage_col, &y->stage, err)) ||
        (y->leaf_col && (rc = phc_table_column_numbers(t, y->leaf_col, &y->leafno, err))))
        return rc;
    y->o.rows_source = y->path;
    y->o.leaf_column = y->leaf_col;
    return PHC_OK;
}

/* One row per line of the table: its stage, photo (relative to the config
 * file), leaf number (a whole number >= 1) and id (the id column, else the
 * leaf column, else the line number). */
static int make_rows(lp_yaml *y, phc_error *err)
{
    const phc_table *t = y->t;
    const size_t nr = y->n_rows;
    y->rows = calloc(nr, sizeof *y->rows);
    y->images = calloc(nr, sizeof *y->images);
    if (!y->rows || !y->images)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    const long idc = phc_table_find(t, y->id_col ? y->id_col : y->leaf_col ? y->leaf_col : "");
    const long imc = y->image_col ? phc_table_find(t, y->image_col) : -1;
    for (size_t r = 0; r < nr; ++r) {
        phc_leaf_photos_row *row = &y->rows[r];
        row->line = phc_table_row_line(t, r);
        row->stage = y->stage[r];
        row->id = idc >= 0 ? phc_table_cell(t, r, (size_t)idc) : NULL;
        if (y->leafno) {
            if (!(y->leafno[r] >= 1 && y->leafno[r] == floor(y->leafno[r])))
                return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': the leaf number must be a whole "
                                     "number >= 1, found %g", y->path, row->line, y->leaf_col, y->leafno[r]);
            row->leaf = (size_t)y->leafno[r];
        }
        const char *name = imc >= 0 ? phc_table_cell(t, r, (size_t)imc) : y->image_name;
        if (name && *name && !(y->images[r] = phc_join_path(y->base_dir, name)))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        row->image = y->images[r]; /* NULL: the kind says no image was given */
    }
    return PHC_OK;
}

/* initial: a row id; reference: a row id or {image: FILE, leaf: N}. */
static int read_initial_reference(lp_yaml *y, phc_error *err)
{
    static const char *const ref_keys[] = {"image", "leaf", NULL};
    const phc_yaml_doc *doc = y->doc;
    const phc_yaml_node *ini = phc_yaml_get(y->node, "initial"), *rf = phc_yaml_get(y->node, "reference");
    int rc;
    if (ini && (rc = phc_yaml_string(doc, ini, "initial", &y->o.initial, err)))
        return rc;
    if (!rf) /* the kind says what is missing */
        return PHC_OK;
    if (rf->kind != PHC_YAML_MAPPING)
        return phc_yaml_string(doc, rf, "reference", &y->o.reference, err);
    const char *rimg;
    long rleaf = 1;
    if ((rc = phc_yaml_check_keys(doc, rf, ref_keys, "reference", err)) ||
        (rc = phc_yaml_map_string(doc, rf, "image", 1, "reference", &rimg, err)) ||
        (rc = phc_yaml_map_integer(doc, rf, "leaf", 0, "reference", &rleaf, err)))
        return rc;
    if (rleaf < 1)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: reference: leaf must be >= 1", doc->path, rf->line);
    if (!(y->reference_path = phc_join_path(y->base_dir, rimg)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    y->o.reference_image = y->reference_path;
    /* a leaf number beyond its leaves at `leaf:` when given, else at `image:` */
    y->o.reference_leaf = phc_yaml_get(rf, "leaf") ? (size_t)rleaf : 0;
    y->reference_origin = phc_yaml_origin(doc, rf);
    y->o.reference_origin = &y->reference_origin;
    return PHC_OK;
}

/* Every file read, in the order read: the table, the photos, the
 * reference photo, the map files (provenance). */
static int add_inputs(const lp_yaml *y, phc_dataset *ds)
{
    int rc = phc_dataset_add_input(ds, y->path);
    for (size_t r = 0; r < y->n_rows && !rc; ++r)
        if (y->images[r])
            rc = phc_dataset_add_input(ds, y->images[r]);
    if (!rc && y->reference_path)
        rc = phc_dataset_add_input(ds, y->reference_path);
    const char *const map_files[] = {y->veins_file, y->stomata_file, y->inflow_file};
    for (size_t q = 0; q < 3 && !rc; ++q)
        if (map_files[q])
            rc = phc_dataset_add_input(ds, map_files[q]);
    return rc;
}

static int leaf_photos_yaml(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                            phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out, phc_error *err)
{
    lp_yaml y = {.doc = doc, .node = node, .base_dir = base_dir, .o = phc_leaf_photos_options_default()};
    int rc;
    *out = NULL;
    y.origin = phc_yaml_origin(doc, node);
    y.o.origin = &y.origin;
    y.o.is_parameter = is_parameter;
    y.o.user_data = user_data;
    if ((rc = read_values(&y, err)) || (rc = read_stage(&y, err)) || (rc = read_image(&y, err)) ||
        (rc = read_table(&y, err)) || (rc = make_rows(&y, err)) || (rc = read_initial_reference(&y, err)) ||
        (rc = phc_leaf_photos_new(y.rows, y.n_rows, &y.o, out, err)))
        goto done;
    if (add_inputs(&y, *out)) {
        phc_dataset_free(*out);
        *out = NULL;
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
done:
    lp_yaml_free(&y);
    return rc;
}

const phc_kind phc_leaf_photos_kind = {
    .config = {.name = "leaf_photos",
               .summary = "photos of an aging leaf -> vein, stomata, inflow and time scales and the "
                          "colour transfer of the leaf colour aging model (Silva et al. §3)",
               .keys = leaf_photos_keys,
               .help = leaf_photos_help},
    .ops = &phc_leaf_photos_ops,
    .load_yaml = leaf_photos_yaml,
};
