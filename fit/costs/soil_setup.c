/* The `soil:` block of the soil data sets: see soil_setup.h. */
#include "fit/costs/soil_setup.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

void phc_soil_setup_free(phc_soil_setup *su)
{
    if (!su)
        return;
    for (size_t L = 0; su->layer_names && L < su->n_layers; ++L)
        free(su->layer_names[L]);
    for (size_t q = 0; su->slot_names && q < su->k; ++q)
        free(su->slot_names[q]);
    free(su->layer_names);
    free(su->slot_names);
    free(su->layers);
    free(su->layer_of_k);
    free(su->rock);
    free(su->pocket);
    free(su->rain);
    free(su->sources);
    free(su->slot_p);
    free(su->slot_c);
    free(su);
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

static int add_slot(phc_soil_setup *su, const char *name, int *slot)
{
    for (size_t q = 0; q < su->k; ++q)
        if (!strcmp(su->slot_names[q], name)) {
            *slot = (int)q;
            return PHC_OK;
        }
    char **names = realloc(su->slot_names, (su->k + 1) * sizeof *names);
    if (!names)
        return PHC_ERR_NOMEM;
    su->slot_names = names;
    if (!(names[su->k] = strdup(name)))
        return PHC_ERR_NOMEM;
    *slot = (int)su->k++;
    return PHC_OK;
}

static int parse_layers(const phc_yaml_doc *doc, const phc_yaml_node *seq, phc_soil_setup *su, phc_error *err)
{
    static const char *const keys[] = {"soil", "c", "p", "d", "thickness", "fill", "water", "nutrient", NULL};
    int rc;
    if ((rc = expect_seq(doc, seq, "soil layers", err)))
        return rc;
    if (!seq->count)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil layers: give at least one layer", doc->path, seq->line);
    su->n_layers = seq->count;
    su->layers = calloc(seq->count, sizeof *su->layers);
    su->layer_names = calloc(seq->count, sizeof *su->layer_names);
    if (!su->layers || !su->layer_names)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t L = 0; L < seq->count; ++L) {
        const phc_yaml_node *n = seq->items[L];
        char ctx[48];
        snprintf(ctx, sizeof ctx, "soil layer %zu", L + 1);
        if ((rc = expect_map(doc, n, ctx, err)) || (rc = phc_yaml_check_keys(doc, n, keys, ctx, err)))
            return rc;
        phc_soil_layer *l = &su->layers[L];
        l->c = NAN;
        l->p = NAN;
        l->d = 1;
        l->fill = -1;
        l->water = -1;
        const char *preset = NULL;
        if ((rc = phc_yaml_map_string(doc, n, "soil", 0, ctx, &preset, err)))
            return rc;
        if (preset && phc_soil_preset(preset, &l->c, &l->p)) {
            char list[256] = "";
            for (size_t i = 0; phc_soil_preset_name(i); ++i) {
                size_t used = strlen(list);
                snprintf(list + used, sizeof list - used, "%s%s", i ? ", " : "", phc_soil_preset_name(i));
            }
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: unknown soil '%s' (known: %s)", doc->path,
                                 phc_key_line(n, "soil"), ctx, preset, list);
        }
        if ((rc = phc_yaml_map_number(doc, n, "c", 0, ctx, &l->c, err)) ||
            (rc = phc_yaml_map_number(doc, n, "p", 0, ctx, &l->p, err)) ||
            (rc = phc_yaml_map_number(doc, n, "d", 0, ctx, &l->d, err)) ||
            (rc = phc_yaml_map_number(doc, n, "thickness", L + 1 < seq->count, ctx, &l->thickness, err)) ||
            (rc = phc_yaml_map_number(doc, n, "fill", 0, ctx, &l->fill, err)) ||
            (rc = phc_yaml_map_number(doc, n, "water", 0, ctx, &l->water, err)) ||
            (rc = phc_yaml_map_number(doc, n, "nutrient", 0, ctx, &l->nutrient, err)))
            return rc;
        if (isnan(l->c) || isnan(l->p))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: give `soil: NAME` or both c and p", doc->path,
                                 n->line, ctx);
        if (phc_yaml_get(n, "fill") && phc_yaml_get(n, "water"))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: give the initial water as fill or water, not both",
                                 doc->path, n->line, ctx);
        if (!phc_yaml_get(n, "fill") && !phc_yaml_get(n, "water"))
            l->water = 0;
        if ((phc_yaml_get(n, "fill") && !(l->fill >= 0)) || (phc_yaml_get(n, "water") && !(l->water >= 0)))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: the initial water must be >= 0", doc->path,
                                 n->line, ctx);
        if (L + 1 < seq->count && !(l->thickness > 0))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: thickness must be > 0 m, found %g", doc->path,
                                 phc_key_line(n, "thickness"), ctx, l->thickness);
        phc_error model_err;
        if (phc_soil_layer_check(l, L + 1, L + 1 == seq->count, &model_err)) /* the model's checks, with the line */
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s", doc->path, n->line, model_err.message);
        if (!(su->layer_names[L] = strdup(preset ? preset : "custom")))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    return PHC_OK;
}

/* A noise block {seed, scale, fraction[, amount]} into a per-voxel mask or amount. */
static int parse_noise(const phc_yaml_doc *doc, const phc_yaml_node *n, const char *what, phc_soil_setup *su,
                       int rocks, phc_error *err)
{
    static const char *const rock_keys[] = {"seed", "scale", "fraction", NULL};
    static const char *const pocket_keys[] = {"seed", "scale", "fraction", "amount", NULL};
    long seed = 1;
    double scale = NAN, fraction = NAN, amount = 1;
    int rc;
    if ((rc = expect_map(doc, n, what, err)) ||
        (rc = phc_yaml_check_keys(doc, n, rocks ? rock_keys : pocket_keys, what, err)) ||
        (rc = phc_yaml_map_integer(doc, n, "seed", 0, what, &seed, err)) ||
        (rc = phc_yaml_map_number(doc, n, "scale", 1, what, &scale, err)) ||
        (rc = phc_yaml_map_number(doc, n, "fraction", 1, what, &fraction, err)) ||
        (!rocks && (rc = phc_yaml_map_number(doc, n, "amount", 1, what, &amount, err))))
        return rc;
    if (!(scale > 0) || !(fraction >= 0 && fraction < 1) || !(amount >= 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: needs scale > 0 m, 0 <= fraction < 1%s", doc->path,
                             n->line, what, rocks ? "" : " and amount >= 0");
    phc_soil *tmp = phc_soil_new(su->nx, su->ny, su->nz, su->dx);
    if (!tmp)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    size_t nvox = tmp->n;
    if (rocks) {
        for (size_t i = 0; i < nvox; ++i)
            tmp->p[i] = 1;
        phc_soil_add_rocks(tmp, (uint64_t)seed, scale, fraction);
        su->rock = malloc(nvox);
        if (su->rock)
            for (size_t i = 0; i < nvox; ++i)
                su->rock[i] = tmp->p[i] == 0;
    } else {
        phc_soil_add_nutrient_pockets(tmp, (uint64_t)seed, scale, fraction, amount);
        su->pocket = malloc(nvox * sizeof *su->pocket);
        if (su->pocket)
            memcpy(su->pocket, tmp->v, nvox * sizeof *su->pocket);
    }
    phc_soil_free(tmp);
    if (rocks ? !su->rock : !su->pocket)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    return PHC_OK;
}

static int parse_rain(const phc_yaml_doc *doc, const phc_yaml_node *seq, phc_soil_setup *su, phc_error *err)
{
    static const char *const keys[] = {"start", "end", "rate", "nutrient", "x0", "x1", "y0", "y1", NULL};
    int rc;
    if ((rc = expect_seq(doc, seq, "soil rain", err)))
        return rc;
    su->rain = calloc(seq->count ? seq->count : 1, sizeof *su->rain);
    if (!su->rain)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    su->n_rain = seq->count;
    for (size_t r = 0; r < seq->count; ++r) {
        const phc_yaml_node *n = seq->items[r];
        phc_soil_rain *rn = &su->rain[r];
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
        if (!(rn->rate >= 0) || !(rn->end >= rn->start) || !(rn->nutrient >= 0))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: needs rate >= 0 m/h, nutrient >= 0 and start <= end",
                                 doc->path, n->line, ctx);
    }
    return PHC_OK;
}

static int parse_sources(const phc_yaml_doc *doc, const phc_yaml_node *seq, phc_soil_setup *su, phc_error *err)
{
    static const char *const keys[] = {"x", "y", "depth", "radius", "water_rate", "nutrient_rate", "start", "end",
                                       NULL};
    int rc;
    if ((rc = expect_seq(doc, seq, "soil sources", err)))
        return rc;
    su->sources = calloc(seq->count ? seq->count : 1, sizeof *su->sources);
    if (!su->sources)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    su->n_sources = seq->count;
    const double top = su->nz * su->dx;
    for (size_t q = 0; q < seq->count; ++q) {
        const phc_yaml_node *n = seq->items[q];
        phc_soil_source *src = &su->sources[q];
        double depth = NAN;
        char ctx[48];
        snprintf(ctx, sizeof ctx, "source %zu", q + 1);
        src->end = INFINITY;
        if ((rc = expect_map(doc, n, ctx, err)) || (rc = phc_yaml_check_keys(doc, n, keys, ctx, err)) ||
            (rc = phc_yaml_map_number(doc, n, "x", 1, ctx, &src->x, err)) ||
            (rc = phc_yaml_map_number(doc, n, "y", 1, ctx, &src->y, err)) ||
            (rc = phc_yaml_map_number(doc, n, "depth", 1, ctx, &depth, err)) ||
            (rc = phc_yaml_map_number(doc, n, "radius", 0, ctx, &src->radius, err)) ||
            (rc = phc_yaml_map_number(doc, n, "water_rate", 0, ctx, &src->water_rate, err)) ||
            (rc = phc_yaml_map_number(doc, n, "nutrient_rate", 0, ctx, &src->nutrient_rate, err)) ||
            (rc = phc_yaml_map_number(doc, n, "start", 0, ctx, &src->start, err)) ||
            (rc = phc_yaml_map_number(doc, n, "end", 0, ctx, &src->end, err)))
            return rc;
        src->z = top - depth;
        if (!(src->x >= 0 && src->x < su->nx * su->dx && src->y >= 0 && src->y < su->ny * su->dx && depth >= 0 &&
              depth < top))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: %s: (x %g m, y %g m, depth %g m) is outside the soil grid (%g x %g m, "
                                 "%g m deep)", doc->path, n->line, ctx, src->x, src->y, depth, su->nx * su->dx,
                                 su->ny * su->dx, top);
        if (!(src->radius >= 0) || !(src->end >= src->start))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: needs radius >= 0 and start <= end", doc->path,
                                 n->line, ctx);
    }
    return PHC_OK;
}

static int parse_geo(const phc_yaml_doc *doc, const phc_yaml_node *n, phc_soil_setup *su, phc_error *err)
{
    static const char *const keys[] = {"lat", "lon", "height", NULL};
    const char *lat = NULL, *lon = NULL;
    int rc;
    if ((rc = expect_map(doc, n, "geo_origin", err)) || (rc = phc_yaml_check_keys(doc, n, keys, "geo_origin", err)) ||
        (rc = phc_yaml_map_string(doc, n, "lat", 1, "geo_origin", &lat, err)) ||
        (rc = phc_yaml_map_string(doc, n, "lon", 1, "geo_origin", &lon, err)) ||
        (rc = phc_yaml_map_number(doc, n, "height", 0, "geo_origin", &su->geo.h0, err)))
        return rc;
    char where[512];
    snprintf(where, sizeof where, "%s:%zu: geo_origin lat", doc->path, phc_key_line(n, "lat"));
    if ((rc = phc_geo_parse_angle(lat, PHC_GEO_LATITUDE, where, &su->geo.lat0, err)))
        return rc;
    snprintf(where, sizeof where, "%s:%zu: geo_origin lon", doc->path, phc_key_line(n, "lon"));
    if ((rc = phc_geo_parse_angle(lon, PHC_GEO_LONGITUDE, where, &su->geo.lon0, err)))
        return rc;
    su->has_geo = 1;
    return PHC_OK;
}

int phc_soil_setup_parse(const phc_yaml_doc *doc, const phc_yaml_node *soil, phc_is_parameter_fn is_parameter,
                         void *user_data, phc_soil_setup **out, phc_error *err)
{
    static const char *const grid_keys[] = {"nx", "ny", "nz", "dx", NULL};
    static const char *const bnd_keys[] = {"x_min", "x_max", "y_min", "y_max", "bottom", "top", "sides", NULL};
    static const char *const abs_keys[] = {"form", "width", NULL};
    const char *ctx = "soil";
    int rc;
    *out = NULL;
    if ((rc = expect_map(doc, soil, "key 'soil'", err)) || (rc = phc_yaml_check_keys(doc, soil, phc_soil_setup_keys, ctx, err)))
        return rc;
    phc_soil_setup *su = calloc(1, sizeof *su);
    if (!su)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    su->line = soil->line;
    su->params = phc_soil_params_default();
    su->params.dt = 0.01;
    su->params.max_substeps = 100; /* a fit's trial point 100x too fast for dt is refused, not run */
    su->slot_fd = su->slot_fg = -1;
    const phc_yaml_node *grid = phc_yaml_get(soil, "grid");
    long nx = 1, ny = 1, nz = 0;
    double dx = NAN;
    if (!grid) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil: missing key 'grid' ({nx, ny, nz, dx})", doc->path,
                           soil->line);
        goto fail;
    }
    if ((rc = expect_map(doc, grid, "soil grid", err)) ||
        (rc = phc_yaml_check_keys(doc, grid, grid_keys, "soil grid", err)) ||
        (rc = phc_yaml_map_integer(doc, grid, "nx", 0, "soil grid", &nx, err)) ||
        (rc = phc_yaml_map_integer(doc, grid, "ny", 0, "soil grid", &ny, err)) ||
        (rc = phc_yaml_map_integer(doc, grid, "nz", 1, "soil grid", &nz, err)) ||
        (rc = phc_yaml_map_number(doc, grid, "dx", 1, "soil grid", &dx, err)))
        goto fail;
    if (nx < 1 || ny < 1 || nz < 1 || !(dx > 0) || (double)nx * ny * nz > 5e8) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil grid: needs nx, ny, nz >= 1 (at most 5e8 voxels) and "
                           "dx > 0 m", doc->path, grid->line);
        goto fail;
    }
    su->nx = (size_t)nx;
    su->ny = (size_t)ny;
    su->nz = (size_t)nz;
    su->dx = dx;
    phc_soil_params *pr = &su->params;
    long max_sub = (long)pr->max_substeps;
    if ((rc = phc_yaml_map_number(doc, soil, "dt", 0, ctx, &pr->dt, err)) ||
        (rc = phc_yaml_map_integer(doc, soil, "max_substeps", 0, ctx, &max_sub, err)) ||
        (rc = phc_yaml_map_boolean(doc, soil, "substep", 0, ctx, &pr->substep, err)) ||
        (rc = phc_yaml_map_number(doc, soil, "f_diff", 0, ctx, &pr->f_diff, err)) ||
        (rc = phc_yaml_map_number(doc, soil, "f_grav", 0, ctx, &pr->f_grav, err)) ||
        (rc = phc_yaml_map_number(doc, soil, "f_nutrient", 0, ctx, &pr->f_nutrient, err)))
        goto fail;
    if (max_sub < 0) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil: max_substeps must be >= 0 (0 = no limit)", doc->path,
                           phc_key_line(soil, "max_substeps"));
        goto fail;
    }
    pr->max_substeps = (size_t)max_sub;
    if (!(pr->dt > 0) || !(pr->f_diff >= 0) || !(pr->f_grav >= 0) || !(pr->f_nutrient >= 0)) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil: needs dt > 0 h and f_diff, f_grav, f_nutrient >= 0",
                           doc->path, soil->line);
        goto fail;
    }
    const phc_yaml_node *bnd = phc_yaml_get(soil, "boundaries");
    if (bnd) {
        phc_soil_boundary sides = PHC_SOIL_BLOCK;
        if ((rc = expect_map(doc, bnd, "soil boundaries", err)) ||
            (rc = phc_yaml_check_keys(doc, bnd, bnd_keys, "soil boundaries", err)) ||
            (rc = parse_boundary(doc, bnd, "sides", &sides, err)))
            goto fail;
        for (int f = 0; f < 4; ++f)
            pr->boundary[f] = sides;
        static const char *face_keys[] = {"x_min", "x_max", "y_min", "y_max", "bottom", "top"};
        for (int f = 0; f < PHC_SOIL_FACES; ++f)
            if ((rc = parse_boundary(doc, bnd, face_keys[f], &pr->boundary[f], err)))
                goto fail;
    }
    const phc_yaml_node *ab = phc_yaml_get(soil, "absorb");
    if (ab) {
        const char *form = NULL;
        long width = pr->absorb_width;
        if ((rc = expect_map(doc, ab, "soil absorb", err)) ||
            (rc = phc_yaml_check_keys(doc, ab, abs_keys, "soil absorb", err)) ||
            (rc = phc_yaml_map_string(doc, ab, "form", 0, "soil absorb", &form, err)) ||
            (rc = phc_yaml_map_integer(doc, ab, "width", 0, "soil absorb", &width, err)))
            goto fail;
        if (form && strcmp(form, "code") && strcmp(form, "paper")) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil absorb form '%s': expected code or paper", doc->path,
                               phc_key_line(ab, "form"), form);
            goto fail;
        }
        pr->absorb_form = form && !strcmp(form, "paper") ? PHC_SOIL_ABSORB_PAPER : PHC_SOIL_ABSORB_CODE;
        if (width < 1 || width > 1000) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil absorb width must be 1..1000 voxels", doc->path,
                               ab->line);
            goto fail;
        }
        pr->absorb_width = (int)width;
    }
    {
        size_t dims[3] = {su->nx, su->ny, su->nz};
        static const char *face[] = {"x_min", "x_max", "y_min", "y_max", "bottom", "top"};
        for (int f = 0; f < PHC_SOIL_FACES; ++f) {
            if (pr->boundary[f] == PHC_SOIL_ABSORB && (size_t)pr->absorb_width > dims[f / 2]) {
                rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil boundary %s absorbs over %d layers but the grid "
                                   "has %zu voxels along that axis", doc->path, bnd ? bnd->line : soil->line, face[f],
                                   pr->absorb_width, dims[f / 2]);
                goto fail;
            }
            if ((pr->boundary[f] == PHC_SOIL_PERIODIC) != (pr->boundary[f ^ 1] == PHC_SOIL_PERIODIC)) {
                rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil boundaries: %s is periodic but %s is not; "
                                   "periodic faces come in pairs", doc->path, bnd ? bnd->line : soil->line,
                                   face[f & ~1], face[f | 1]);
                goto fail;
            }
        }
    }
    const phc_yaml_node *layers = phc_yaml_get(soil, "layers");
    if (!layers) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: soil: missing key 'layers'", doc->path, soil->line);
        goto fail;
    }
    if ((rc = parse_layers(doc, layers, su, err)))
        goto fail;
    if (!(su->layer_of_k = malloc(su->nz * sizeof *su->layer_of_k))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    {
        phc_soil tmp = {.nx = su->nx, .ny = su->ny, .nz = su->nz, .dx = su->dx};
        phc_soil_layer_of_planes(&tmp, su->layers, su->n_layers, su->layer_of_k);
    }
    const phc_yaml_node *n;
    if ((n = phc_yaml_get(soil, "rocks")) && (rc = parse_noise(doc, n, "soil rocks", su, 1, err)))
        goto fail;
    if ((n = phc_yaml_get(soil, "nutrient_pockets")) && (rc = parse_noise(doc, n, "soil nutrient_pockets", su, 0, err)))
        goto fail;
    if ((n = phc_yaml_get(soil, "rain")) && (rc = parse_rain(doc, n, su, err)))
        goto fail;
    if ((n = phc_yaml_get(soil, "sources")) && (rc = parse_sources(doc, n, su, err)))
        goto fail;
    if ((n = phc_yaml_get(soil, "geo_origin")) && (rc = parse_geo(doc, n, su, err)))
        goto fail;

    /* Without sub-stepping, a step over the stability limit at the configured
       soil is refused here, with the limit (trial points of a fit that cross
       it are rejected as outside the model's domain). */
    if (!pr->substep) {
        phc_soil *tmp = NULL;
        if ((rc = phc_soil_setup_build(su, NULL, &tmp, err)))
            goto fail;
        size_t at = 0;
        double lim = phc_soil_stable_dt(tmp, &at);
        if (pr->dt > lim) {
            size_t i = at % su->nx, j = (at / su->nx) % su->ny, k = at / (su->nx * su->ny);
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: soil: dt = %g h exceeds the stability limit %g h of the explicit step "
                               "(set by voxel (%zu, %zu, %zu), p = %g m/h, c = %g) and substep is false; lower "
                               "dt or allow sub-stepping", doc->path, phc_key_line(soil, "dt"), pr->dt, lim, i, j, k,
                               tmp->p[at], tmp->c[at]);
        }
        phc_soil_free(tmp);
        if (rc)
            goto fail;
    }

    /* Slots. */
    su->slot_p = malloc(su->n_layers * sizeof *su->slot_p);
    su->slot_c = malloc(su->n_layers * sizeof *su->slot_c);
    if (!su->slot_p || !su->slot_c) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    for (size_t L = 0; L < su->n_layers; ++L) {
        char name[32];
        su->slot_p[L] = su->slot_c[L] = -1;
        for (int which = 0; which < 2; ++which) {
            int *slot = which ? &su->slot_c[L] : &su->slot_p[L];
            const char *base = which ? "c" : "p";
            snprintf(name, sizeof name, "%s_%zu", base, L + 1);
            const char *use = is_parameter(name, user_data) ? name : is_parameter(base, user_data) ? base : NULL;
            if (use && add_slot(su, use, slot)) {
                rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
                goto fail;
            }
        }
    }
    if ((is_parameter("f_diff", user_data) && add_slot(su, "f_diff", &su->slot_fd)) ||
        (is_parameter("f_grav", user_data) && add_slot(su, "f_grav", &su->slot_fg))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    *out = su;
    return PHC_OK;
fail:
    phc_soil_setup_free(su);
    return rc;
}

double phc_soil_setup_p(const phc_soil_setup *su, size_t L, const double *p)
{
    return p && su->slot_p[L] >= 0 ? p[su->slot_p[L]] : su->layers[L].p;
}

double phc_soil_setup_c(const phc_soil_setup *su, size_t L, const double *p)
{
    return p && su->slot_c[L] >= 0 ? p[su->slot_c[L]] : su->layers[L].c;
}

int phc_soil_setup_build(const phc_soil_setup *su, const double *p, phc_soil **out, phc_error *err)
{
    int rc;
    *out = NULL;
    phc_soil_layer *layers = malloc(su->n_layers * sizeof *layers);
    phc_soil *s = phc_soil_new(su->nx, su->ny, su->nz, su->dx);
    if (!layers || !s) {
        free(layers);
        phc_soil_free(s);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    memcpy(layers, su->layers, su->n_layers * sizeof *layers);
    for (size_t L = 0; L < su->n_layers; ++L) {
        layers[L].p = phc_soil_setup_p(su, L, p);
        layers[L].c = phc_soil_setup_c(su, L, p);
    }
    s->params = su->params;
    if (p && su->slot_fd >= 0)
        s->params.f_diff = p[su->slot_fd];
    if (p && su->slot_fg >= 0)
        s->params.f_grav = p[su->slot_fg];
    rc = phc_soil_set_layers(s, layers, su->n_layers, err);
    free(layers);
    if (!rc && (!(s->params.f_diff >= 0) || !(s->params.f_grav >= 0)))
        rc = phc_error_set(err, PHC_ERR_DOMAIN, "soil: f_diff and f_grav must be >= 0");
    if (rc) {
        phc_soil_free(s);
        return rc == PHC_ERR_INPUT ? PHC_ERR_DOMAIN : rc;
    }
    for (size_t i = 0; i < s->n; ++i) {
        if (su->rock && su->rock[i])
            s->p[i] = 0;
        if (su->pocket)
            s->v[i] += su->pocket[i];
    }
    if ((rc = phc_soil_set_rain(s, su->rain, su->n_rain, err)) ||
        (rc = phc_soil_set_sources(s, su->sources, su->n_sources, err))) {
        phc_soil_free(s);
        return rc;
    }
    phc_soil_budget_reset(s);
    *out = s;
    return PHC_OK;
}

void phc_soil_setup_tangent(const phc_soil_setup *su, const phc_soil *s, double **dp, double **dinv_c,
                            double *dfd, double *dfg, double **sw)
{
    const size_t plane = s->nx * s->ny;
    for (size_t q = 0; q < su->k; ++q) {
        memset(dp[q], 0, s->n * sizeof(double));
        memset(dinv_c[q], 0, s->n * sizeof(double));
        memset(sw[q], 0, s->n * sizeof(double));
        dfd[q] = (int)q == su->slot_fd ? 1.0 : 0.0;
        dfg[q] = (int)q == su->slot_fg ? 1.0 : 0.0;
    }
    for (size_t k = 0; k < s->nz; ++k) {
        size_t L = su->layer_of_k[k];
        int sp = su->slot_p[L], sc = su->slot_c[L];
        for (size_t e = 0; e < plane; ++e) {
            size_t i = e + plane * k;
            if (sp >= 0 && !(su->rock && su->rock[i]))
                dp[sp][i] = 1.0;
            if (sc >= 0) {
                dinv_c[sc][i] = -1.0 / (s->c[i] * s->c[i]);
                if (su->layers[L].fill >= 0)
                    sw[sc][i] = su->layers[L].fill; /* w0 = fill c */
            }
        }
    }
}

int phc_soil_setup_run(const phc_soil_setup *su, const double *p, const double *t, size_t m, int tangents,
                       phc_soil_visit_fn visit, void *user, phc_soil **keep, phc_error *err)
{
    phc_soil *s = NULL;
    int rc = phc_soil_setup_build(su, p, &s, err);
    if (rc)
        return rc;
    const size_t k = tangents ? su->k : 0;
    double **dp = NULL, **dic = NULL, **sw = NULL, *dfd = NULL, *dfg = NULL;
    if (k) {
        dp = calloc(k, sizeof *dp);
        dic = calloc(k, sizeof *dic);
        sw = calloc(k, sizeof *sw);
        dfd = calloc(k, sizeof *dfd);
        dfg = calloc(k, sizeof *dfg);
        int bad = !dp || !dic || !sw || !dfd || !dfg;
        for (size_t q = 0; q < k && !bad; ++q)
            bad = !(dp[q] = malloc(s->n * sizeof(double))) || !(dic[q] = malloc(s->n * sizeof(double))) ||
                  !(sw[q] = malloc(s->n * sizeof(double)));
        if (bad) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
        phc_soil_setup_tangent(su, s, dp, dic, dfd, dfg, sw);
    }
    phc_soil_tangent tan = {k, (const double *const *)dp, (const double *const *)dic, dfd, dfg, sw};
    for (size_t i = 0; i < m; ++i) {
        rc = k ? phc_soil_run_tangent(s, t[i], &tan, err) : phc_soil_run(s, t[i], err);
        if (rc)
            goto done;
        if (visit && visit(user, s, i, k ? &tan : NULL)) {
            rc = phc_error_set(err, PHC_ERR_DOMAIN, "soil: stopped at t = %g h", t[i]);
            goto done;
        }
    }
done:
    for (size_t q = 0; q < k; ++q) {
        if (dp) free(dp[q]);
        if (dic) free(dic[q]);
        if (sw) free(tan.sw[q]);
    }
    free(dp);
    free(dic);
    free(sw);
    free(dfd);
    free(dfg);
    if (!rc && keep)
        *keep = s;
    else
        phc_soil_free(s);
    return rc;
}

phc_dataset *phc_soil_setup_dataset(const phc_soil_setup *su, const phc_dataset_ops *ops, size_t n,
                                    const char *path)
{
    phc_dataset *ds = phc_dataset_new(ops, su->k);
    if (!ds)
        return NULL;
    int bad = 0;
    for (size_t q = 0; q < su->k && !bad; ++q)
        bad = !(ds->slot_names[q] = strdup(su->slot_names[q]));
    ds->n = n;
    ds->x = malloc((n ? n : 1) * sizeof *ds->x);
    ds->y = malloc((n ? n : 1) * sizeof *ds->y);
    ds->sigma = malloc((n ? n : 1) * sizeof *ds->sigma);
    ds->data_lines = malloc((n ? n : 1) * sizeof *ds->data_lines);
    ds->data_file = strdup(path);
    if (bad || !ds->x || !ds->y || !ds->sigma || !ds->data_lines || !ds->data_file) {
        phc_dataset_free(ds);
        return NULL;
    }
    return ds;
}

char *phc_soil_setup_markdown(const phc_soil_setup *su, const double *p, const phc_soil *s)
{
    char *b = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&b, &len);
    if (!f)
        return NULL;
    static const char *bn[] = {"block", "absorb", "periodic"};
    const phc_soil_params *pr = &s->params;
    fprintf(f, "Soil (Rhizomorph §6): %zu x %zu x %zu voxels of %g m (%g x %g m, %g m deep); "
        "f_diff = %g m, f_grav = %g; dt = %g h, %s.\n\n", su->nx, su->ny, su->nz, su->dx, su->nx * su->dx,
        su->ny * su->dx, su->nz * su->dx, pr->f_diff, pr->f_grav, pr->dt,
        pr->substep ? "sub-stepped over the stability limit" : "no sub-stepping");
    fprintf(f, "Boundaries: x %s/%s, y %s/%s, bottom %s, top %s", bn[pr->boundary[0]], bn[pr->boundary[1]],
        bn[pr->boundary[2]], bn[pr->boundary[3]], bn[pr->boundary[4]], bn[pr->boundary[5]]);
    for (int face = 0; face < PHC_SOIL_FACES; ++face)
        if (pr->boundary[face] == PHC_SOIL_ABSORB) {
            fprintf(f, "; absorbing layers: %d, %s form", pr->absorb_width,
                pr->absorb_form == PHC_SOIL_ABSORB_CODE ? "the authors' code (i²)" : "the paper's eq. 31 (i)");
            break;
        }
    fprintf(f, ".\n\n| layer | soil | thickness (m) | c | p (m/h) | D = f_diff p/c (m²/h) | gravity velocity f_grav p (m/h) |\n|---|---|---|---|---|---|---|\n");
    for (size_t L = 0; L < su->n_layers; ++L) {
        double pv = phc_soil_setup_p(su, L, p), cv = phc_soil_setup_c(su, L, p);
        char thick[32];
        if (su->layers[L].thickness > 0 && L + 1 < su->n_layers)
            snprintf(thick, sizeof thick, "%g", su->layers[L].thickness);
        else
            snprintf(thick, sizeof thick, "to the bottom");
        fprintf(f, "| %zu | %s | %s | %.6g%s | %.6g%s | %.4g | %.4g |\n", L + 1, su->layer_names[L], thick, cv,
            su->slot_c[L] >= 0 ? " (fitted)" : "", pv, su->slot_p[L] >= 0 ? " (fitted)" : "", pr->f_diff * pv / cv,
            pr->f_grav * pv);
    }
    size_t at = 0;
    double lim = phc_soil_stable_dt(s, &at);
    fprintf(f, "\nStability limit of the explicit step: %.4g h (voxel %zu); %zu steps, %zu sub-steps.\n\n",
        lim, at, s->budget.steps, s->budget.substeps);
    const phc_soil_budget *bu = &s->budget;
    fprintf(f, "Water budget (m³) over the run to t = %g h: initial %.6g, in %.6g, absorbed %.6g, "
        "taken by sinks %.6g, stored %.6g; closing error %.3g (%.2g of the water moved).\n", s->t, bu->water_initial,
        bu->water_in, bu->water_absorbed, bu->water_sunk, bu->water_stored, bu->water_closing,
        fabs(bu->water_closing) / fmax(1e-300, bu->water_initial + bu->water_in));
    if (ferror(f) | (fclose(f) != 0)) {
        free(b);
        return NULL;
    }
    return b;
}

int phc_soil_setup_report(const phc_soil_setup *su, const double *p, double t_end, char **markdown,
                          phc_error *err)
{
    phc_soil *s = NULL;
    int rc = phc_soil_setup_run(su, p, &t_end, 1, 0, NULL, NULL, &s, err);
    if (rc)
        return rc;
    *markdown = phc_soil_setup_markdown(su, p, s);
    phc_soil_free(s);
    return *markdown ? PHC_OK : phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
}
