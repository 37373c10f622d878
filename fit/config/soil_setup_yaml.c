/* The `soil:` block in a config: see soil_setup_yaml.h. */
#include "fit/config/soil_setup_yaml.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/config/yaml_keys.h"

const char *const phc_soil_setup_keys[] = {"grid", "dt", "substep", "max_substeps", "f_diff", "f_grav", "f_nutrient",
                                           "boundaries", "absorb", "layers", "rocks", "nutrient_pockets",
                                           "rain", "sources", "geo_origin", NULL};
const phc_key_help phc_soil_setup_help[] = {
    {"grid", "{nx, ny, nz, dx}: voxels along x (east), y (north) (default 1 each) and z "
             "(required), and the voxel side dx in m (required); at most 5e8 voxels. "
             "Required."},
    {"dt", "Time step, h, > 0 (sub-stepped over the stability limit unless substep is false). "
           "Default: 0.01."},
    {"substep", "true: sub-step a dt over the explicit step's stability limit; false: refuse "
                "such a dt. Default: true."},
    {"max_substeps", "Most sub-steps per dt (a fit's trial point needing more is refused); 0 = "
                     "no limit. Default: 100."},
    {"f_diff", "Diffusion force, m, >= 0 (fitted when there is a parameter f_diff). "
               "Default: 1."},
    {"f_grav", "Gravity force, >= 0 (fitted when there is a parameter f_grav). Default: 1."},
    {"f_nutrient", "Nutrient transport factor, >= 0. Default: 1."},
    {"boundaries", "{sides, x_min, x_max, y_min, y_max, bottom, top}: each block, absorb or "
                   "periodic; sides sets the four vertical faces, periodic faces come in "
                   "pairs. Default: block everywhere."},
    {"absorb", "{form, width}: the damping of absorbing faces, form code (the authors' code) or "
               "paper (eq. 31), over width voxel layers, 1 to 1000. Default: code, 5."},
    {"layers", "List of layers from the surface down, each {soil: PRESET or c and p (m/h), "
               "thickness (m; not for the last, which reaches the bottom), fill (w/c) or water "
               "(m³/m³) (default water 0), d (default 1), nutrient (default 0)}. Presets: clay, "
               "clay_loam, sandy_clay_loam, sandy_loam, silt_loam, silt. Required."},
    {"rocks", "{seed, scale, fraction}: random rocks (p = 0), scale the noise's length in m "
              "(> 0), fraction the share of the soil they fill (0 <= fraction < 1), seed a "
              "whole number (default 1). Default: none."},
    {"nutrient_pockets", "{seed, scale, fraction, amount}: random nutrient pockets as for rocks, "
                         "with amount >= 0 (required). Default: none."},
    {"rain", "List of {start, end, rate, nutrient, x0, x1, y0, y1}: rain of rate m/h from start "
             "to end h carrying nutrient units/m³ (default 0), on the rectangle x0..x1, y0..y1 "
             "m (default the whole surface). Default: none."},
    {"sources", "List of {x, y, depth, radius, water_rate, nutrient_rate, start, end}: point "
                "sources (negative rates: sinks) at x, y, depth m (required), spread over "
                "radius m (default 0), water_rate m³/h, nutrient_rate units/h, from start "
                "(default 0) to end (default never) h. Default: none."},
    {"geo_origin", "{lat, lon, height}: where the grid's west-south corner at the surface is, "
                   "e.g. lat: \"43.6481 N\", lon: \"79.3832 W\" (height default 0); needed for "
                   "probes placed by latitude and longitude. Default: none."},
    {NULL, NULL}};

void phc_soil_setup_yaml_free(phc_soil_setup_yaml *y)
{
    if (!y)
        return;
    free(y->layers);
    free(y->rain);
    free(y->sources);
    y->layers = NULL;
    y->rain = NULL;
    y->sources = NULL;
}

/* The line the soil's messages have always named for a place in the soil
 * mapping: for a key holding a mapping or a list (grid, absorb, layers, ...)
 * the line that value starts on, for other keys the key's own line, for an
 * item of a list ("layers[2]") the item's line, and within it
 * ("layers[2].thickness") its key's line; the enclosing mapping's line
 * when a key is absent. */
static size_t soil_key_line(const void *map, const char *path)
{
    const phc_yaml_node *n = map;
    size_t line = n->line;
    while (path && *path) {
        size_t len = strcspn(path, ".[");
        if (n->kind != PHC_YAML_MAPPING)
            return line;
        const phc_yaml_node *v = NULL;
        size_t key_line = n->line;
        for (size_t i = 0; i < n->count; ++i)
            if (strlen(n->keys[i]) == len && !strncmp(n->keys[i], path, len)) {
                v = n->values[i];
                key_line = n->key_lines[i];
                break;
            }
        if (!v)
            return n->line;
        line = v->kind == PHC_YAML_SCALAR ? key_line : v->line;
        path += len;
        if (*path == '[') {
            char *end;
            unsigned long i = strtoul(path + 1, &end, 10);
            if (*end != ']' || v->kind != PHC_YAML_SEQUENCE || i >= v->count)
                return line;
            v = v->items[i];
            line = v->line;
            path = end + 1;
        }
        if (*path == '.')
            ++path;
        n = v;
    }
    return line;
}

static int expect_map(const phc_yaml_doc *doc, const phc_yaml_node *n, const char *what, phc_error *err)
{
    if (n && n->kind == PHC_YAML_MAPPING)
        return PHC_OK;
    return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: expected a mapping", doc->path, n ? n->line : 1, what);
}

static int expect_seq(const phc_yaml_doc *doc, const phc_yaml_node *n, const char *what, phc_error *err)
{
    if (n && n->kind == PHC_YAML_SEQUENCE)
        return PHC_OK;
    return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: expected a list", doc->path, n ? n->line : 1, what);
}

static int parse_boundary(const phc_yaml_doc *doc, const phc_yaml_node *map, const char *key,
                          phc_soil_boundary *out, phc_error *err)
{
    const char *s = NULL;
    int rc;
    if ((rc = phc_yaml_map_string(doc, map, key, 0, "soil boundaries", &s, err)) || !s)
        return rc;
    static const char *names[] = {"block", "absorb", "periodic"};
    for (int i = 0; i < 3; ++i)
        if (!strcmp(s, names[i])) {
            *out = (phc_soil_boundary)i;
            return PHC_OK;
        }
    return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil boundary '%s': '%s' is not one of block, absorb, periodic",
                         doc->path, phc_yaml_get(map, key)->line, key, s);
}

/* grid: {nx, ny, nz, dx} */
static int parse_grid(const phc_yaml_doc *doc, const phc_yaml_node *soil, phc_soil_setup_options *o,
                      phc_error *err)
{
    static const char *const grid_keys[] = {"nx", "ny", "nz", "dx", NULL};
    const phc_yaml_node *grid = phc_yaml_get(soil, "grid");
    long nx = 1, ny = 1, nz = 0;
    int rc;
    if (!grid)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil: missing key 'grid' ({nx, ny, nz, dx})", doc->path,
                             soil->line);
    if ((rc = expect_map(doc, grid, "soil grid", err)) ||
        (rc = phc_yaml_check_keys(doc, grid, grid_keys, "soil grid", err)) ||
        (rc = phc_yaml_map_integer(doc, grid, "nx", 0, "soil grid", &nx, err)) ||
        (rc = phc_yaml_map_integer(doc, grid, "ny", 0, "soil grid", &ny, err)) ||
        (rc = phc_yaml_map_integer(doc, grid, "nz", 1, "soil grid", &nz, err)) ||
        (rc = phc_yaml_map_number(doc, grid, "dx", 1, "soil grid", &o->dx, err)))
        return rc;
    /* a count below 1 stays below 1 (0), so that the set-up names the grid */
    o->nx = nx < 1 ? 0 : (size_t)nx;
    o->ny = ny < 1 ? 0 : (size_t)ny;
    o->nz = nz < 1 ? 0 : (size_t)nz;
    return PHC_OK;
}

/* dt, substep, max_substeps and the forces */
static int parse_steps(const phc_yaml_doc *doc, const phc_yaml_node *soil, phc_soil_params *pr, phc_error *err)
{
    const char *ctx = "soil";
    long max_sub = (long)pr->max_substeps;
    int rc;
    if ((rc = phc_yaml_map_number(doc, soil, "dt", 0, ctx, &pr->dt, err)) ||
        (rc = phc_yaml_map_integer(doc, soil, "max_substeps", 0, ctx, &max_sub, err)) ||
        (rc = phc_yaml_map_boolean(doc, soil, "substep", 0, ctx, &pr->substep, err)) ||
        (rc = phc_yaml_map_number(doc, soil, "f_diff", 0, ctx, &pr->f_diff, err)) ||
        (rc = phc_yaml_map_number(doc, soil, "f_grav", 0, ctx, &pr->f_grav, err)) ||
        (rc = phc_yaml_map_number(doc, soil, "f_nutrient", 0, ctx, &pr->f_nutrient, err)))
        return rc;
    if (max_sub < 0)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil: max_substeps must be >= 0 (0 = no limit)", doc->path,
                             phc_key_line(soil, "max_substeps"));
    pr->max_substeps = (size_t)max_sub;
    return PHC_OK;
}

/* boundaries: {sides, x_min, ..., top} and absorb: {form, width} */
static int parse_faces(const phc_yaml_doc *doc, const phc_yaml_node *soil, phc_soil_params *pr, phc_error *err)
{
    static const char *const bnd_keys[] = {"x_min", "x_max", "y_min", "y_max", "bottom", "top", "sides", NULL};
    static const char *const abs_keys[] = {"form", "width", NULL};
    int rc;
    const phc_yaml_node *bnd = phc_yaml_get(soil, "boundaries");
    if (bnd) {
        phc_soil_boundary sides = PHC_SOIL_BLOCK;
        if ((rc = expect_map(doc, bnd, "soil boundaries", err)) ||
            (rc = phc_yaml_check_keys(doc, bnd, bnd_keys, "soil boundaries", err)) ||
            (rc = parse_boundary(doc, bnd, "sides", &sides, err)))
            return rc;
        for (int f = 0; f < 4; ++f)
            pr->boundary[f] = sides;
        static const char *face_keys[] = {"x_min", "x_max", "y_min", "y_max", "bottom", "top"};
        for (int f = 0; f < PHC_SOIL_FACES; ++f)
            if ((rc = parse_boundary(doc, bnd, face_keys[f], &pr->boundary[f], err)))
                return rc;
    }
    const phc_yaml_node *ab = phc_yaml_get(soil, "absorb");
    if (ab) {
        const char *form = NULL;
        long width = pr->absorb_width;
        if ((rc = expect_map(doc, ab, "soil absorb", err)) ||
            (rc = phc_yaml_check_keys(doc, ab, abs_keys, "soil absorb", err)) ||
            (rc = phc_yaml_map_string(doc, ab, "form", 0, "soil absorb", &form, err)) ||
            (rc = phc_yaml_map_integer(doc, ab, "width", 0, "soil absorb", &width, err)))
            return rc;
        if (form && strcmp(form, "code") && strcmp(form, "paper"))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil absorb form '%s': expected code or paper",
                                 doc->path, phc_key_line(ab, "form"), form);
        pr->absorb_form = form && !strcmp(form, "paper") ? PHC_SOIL_ABSORB_PAPER : PHC_SOIL_ABSORB_CODE;
        pr->absorb_width = width < 1 || width > 1000 ? 0 : (int)width; /* 0: refused by the set-up */
    }
    return PHC_OK;
}

static int parse_layers(const phc_yaml_doc *doc, const phc_yaml_node *seq, phc_soil_setup_yaml *y, phc_error *err)
{
    static const char *const keys[] = {"soil", "c", "p", "d", "thickness", "fill", "water", "nutrient", NULL};
    int rc;
    if ((rc = expect_seq(doc, seq, "soil layers", err)))
        return rc;
    y->layers = calloc(seq->count ? seq->count : 1, sizeof *y->layers);
    if (!y->layers)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t L = 0; L < seq->count; ++L) {
        const phc_yaml_node *n = seq->items[L];
        char ctx[48];
        snprintf(ctx, sizeof ctx, "soil layer %zu", L + 1);
        if ((rc = expect_map(doc, n, ctx, err)) || (rc = phc_yaml_check_keys(doc, n, keys, ctx, err)))
            return rc;
        phc_soil_setup_layer *l = &y->layers[L];
        *l = phc_soil_setup_layer_default();
        if ((rc = phc_yaml_map_string(doc, n, "soil", 0, ctx, &l->soil, err)) ||
            (rc = phc_yaml_map_number(doc, n, "c", 0, ctx, &l->c, err)) ||
            (rc = phc_yaml_map_number(doc, n, "p", 0, ctx, &l->p, err)) ||
            (rc = phc_yaml_map_number(doc, n, "d", 0, ctx, &l->d, err)) ||
            (rc = phc_yaml_map_number(doc, n, "thickness", L + 1 < seq->count, ctx, &l->thickness, err)) ||
            (rc = phc_yaml_map_number(doc, n, "fill", 0, ctx, &l->fill, err)) ||
            (rc = phc_yaml_map_number(doc, n, "water", 0, ctx, &l->water, err)) ||
            (rc = phc_yaml_map_number(doc, n, "nutrient", 0, ctx, &l->nutrient, err)))
            return rc;
    }
    y->options.layers = y->layers;
    y->options.n_layers = seq->count;
    return PHC_OK;
}

/* A noise block {seed, scale, fraction[, amount]}. */
static int parse_noise(const phc_yaml_doc *doc, const phc_yaml_node *n, const char *what, int rocks,
                       phc_soil_setup_noise *out, phc_error *err)
{
    static const char *const rock_keys[] = {"seed", "scale", "fraction", NULL};
    static const char *const pocket_keys[] = {"seed", "scale", "fraction", "amount", NULL};
    long seed = 1;
    int rc;
    *out = (phc_soil_setup_noise){.scale = NAN, .fraction = NAN, .amount = 1};
    if ((rc = expect_map(doc, n, what, err)) ||
        (rc = phc_yaml_check_keys(doc, n, rocks ? rock_keys : pocket_keys, what, err)) ||
        (rc = phc_yaml_map_integer(doc, n, "seed", 0, what, &seed, err)) ||
        (rc = phc_yaml_map_number(doc, n, "scale", 1, what, &out->scale, err)) ||
        (rc = phc_yaml_map_number(doc, n, "fraction", 1, what, &out->fraction, err)) ||
        (!rocks && (rc = phc_yaml_map_number(doc, n, "amount", 1, what, &out->amount, err))))
        return rc;
    out->seed = (uint64_t)seed;
    return PHC_OK;
}

static int parse_rain(const phc_yaml_doc *doc, const phc_yaml_node *seq, phc_soil_setup_yaml *y, phc_error *err)
{
    static const char *const keys[] = {"start", "end", "rate", "nutrient", "x0", "x1", "y0", "y1", NULL};
    int rc;
    if ((rc = expect_seq(doc, seq, "soil rain", err)))
        return rc;
    y->rain = calloc(seq->count ? seq->count : 1, sizeof *y->rain);
    if (!y->rain)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t r = 0; r < seq->count; ++r) {
        const phc_yaml_node *n = seq->items[r];
        phc_soil_rain *rn = &y->rain[r];
        char ctx[48];
        snprintf(ctx, sizeof ctx, "rain %zu", r + 1);
        if ((rc = expect_map(doc, n, ctx, err)) || (rc = phc_yaml_check_keys(doc, n, keys, ctx, err)) ||
            (rc = phc_yaml_map_number(doc, n, "start", 1, ctx, &rn->start, err)) ||
            (rc = phc_yaml_map_number(doc, n, "end", 1, ctx, &rn->end, err)) ||
            (rc = phc_yaml_map_number(doc, n, "rate", 1, ctx, &rn->rate, err)) ||
            (rc = phc_yaml_map_number(doc, n, "nutrient", 0, ctx, &rn->nutrient, err)) ||
            (rc = phc_yaml_map_number(doc, n, "x0", 0, ctx, &rn->x0, err)) ||
            (rc = phc_yaml_map_number(doc, n, "x1", 0, ctx, &rn->x1, err)) ||
            (rc = phc_yaml_map_number(doc, n, "y0", 0, ctx, &rn->y0, err)) ||
            (rc = phc_yaml_map_number(doc, n, "y1", 0, ctx, &rn->y1, err)))
            return rc;
    }
    y->options.rain = y->rain;
    y->options.n_rain = seq->count;
    return PHC_OK;
}

static int parse_sources(const phc_yaml_doc *doc, const phc_yaml_node *seq, phc_soil_setup_yaml *y,
                         phc_error *err)
{
    static const char *const keys[] = {"x", "y", "depth", "radius", "water_rate", "nutrient_rate", "start", "end",
                                       NULL};
    int rc;
    if ((rc = expect_seq(doc, seq, "soil sources", err)))
        return rc;
    y->sources = calloc(seq->count ? seq->count : 1, sizeof *y->sources);
    if (!y->sources)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t q = 0; q < seq->count; ++q) {
        const phc_yaml_node *n = seq->items[q];
        phc_soil_setup_source *src = &y->sources[q];
        char ctx[48];
        snprintf(ctx, sizeof ctx, "source %zu", q + 1);
        *src = phc_soil_setup_source_default();
        src->depth = NAN;
        if ((rc = expect_map(doc, n, ctx, err)) || (rc = phc_yaml_check_keys(doc, n, keys, ctx, err)) ||
            (rc = phc_yaml_map_number(doc, n, "x", 1, ctx, &src->x, err)) ||
            (rc = phc_yaml_map_number(doc, n, "y", 1, ctx, &src->y, err)) ||
            (rc = phc_yaml_map_number(doc, n, "depth", 1, ctx, &src->depth, err)) ||
            (rc = phc_yaml_map_number(doc, n, "radius", 0, ctx, &src->radius, err)) ||
            (rc = phc_yaml_map_number(doc, n, "water_rate", 0, ctx, &src->water_rate, err)) ||
            (rc = phc_yaml_map_number(doc, n, "nutrient_rate", 0, ctx, &src->nutrient_rate, err)) ||
            (rc = phc_yaml_map_number(doc, n, "start", 0, ctx, &src->start, err)) ||
            (rc = phc_yaml_map_number(doc, n, "end", 0, ctx, &src->end, err)))
            return rc;
    }
    y->options.sources = y->sources;
    y->options.n_sources = seq->count;
    return PHC_OK;
}

static int parse_geo(const phc_yaml_doc *doc, const phc_yaml_node *n, phc_soil_setup_yaml *y, phc_error *err)
{
    static const char *const keys[] = {"lat", "lon", "height", NULL};
    const char *lat = NULL, *lon = NULL;
    int rc;
    if ((rc = expect_map(doc, n, "geo_origin", err)) || (rc = phc_yaml_check_keys(doc, n, keys, "geo_origin", err)) ||
        (rc = phc_yaml_map_string(doc, n, "lat", 1, "geo_origin", &lat, err)) ||
        (rc = phc_yaml_map_string(doc, n, "lon", 1, "geo_origin", &lon, err)) ||
        (rc = phc_yaml_map_number(doc, n, "height", 0, "geo_origin", &y->geo.h0, err)))
        return rc;
    char where[512];
    snprintf(where, sizeof where, "%s:%zu: geo_origin lat", doc->path, phc_key_line(n, "lat"));
    if ((rc = phc_geo_parse_angle(lat, PHC_GEO_LATITUDE, where, &y->geo.lat0, err)))
        return rc;
    snprintf(where, sizeof where, "%s:%zu: geo_origin lon", doc->path, phc_key_line(n, "lon"));
    if ((rc = phc_geo_parse_angle(lon, PHC_GEO_LONGITUDE, where, &y->geo.lon0, err)))
        return rc;
    y->options.geo_origin = &y->geo;
    return PHC_OK;
}

int phc_soil_setup_yaml_read(const phc_yaml_doc *doc, const phc_yaml_node *soil, phc_soil_setup_yaml *y,
                             phc_error *err)
{
    int rc;
    memset(y, 0, sizeof *y);
    y->options = phc_soil_setup_options_default();
    if ((rc = expect_map(doc, soil, "key 'soil'", err)) ||
        (rc = phc_yaml_check_keys(doc, soil, phc_soil_setup_keys, "soil", err)))
        return rc;
    y->origin = (phc_origin){.path = doc->path, .map = soil, .key_line = soil_key_line, .line = soil->line};
    y->options.origin = &y->origin;
    if ((rc = parse_grid(doc, soil, &y->options, err)) || (rc = parse_steps(doc, soil, &y->options.params, err)) ||
        (rc = parse_faces(doc, soil, &y->options.params, err)))
        return rc;
    const phc_yaml_node *n = phc_yaml_get(soil, "layers");
    if (!n)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil: missing key 'layers'", doc->path, soil->line);
    if ((rc = parse_layers(doc, n, y, err)))
        return rc;
    if ((n = phc_yaml_get(soil, "rocks"))) {
        if ((rc = parse_noise(doc, n, "soil rocks", 1, &y->rocks, err)))
            return rc;
        y->options.rocks = &y->rocks;
    }
    if ((n = phc_yaml_get(soil, "nutrient_pockets"))) {
        if ((rc = parse_noise(doc, n, "soil nutrient_pockets", 0, &y->pockets, err)))
            return rc;
        y->options.nutrient_pockets = &y->pockets;
    }
    if (((n = phc_yaml_get(soil, "rain")) && (rc = parse_rain(doc, n, y, err))) ||
        ((n = phc_yaml_get(soil, "sources")) && (rc = parse_sources(doc, n, y, err))) ||
        ((n = phc_yaml_get(soil, "geo_origin")) && (rc = parse_geo(doc, n, y, err))))
        return rc;
    return PHC_OK;
}
