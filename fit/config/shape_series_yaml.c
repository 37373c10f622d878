/* `kind: shape_series` in a config: its keys and their help, and the
 * translation of its mapping into a phc_shape_spec (measurements/
 * shape_series.h: which columns, which units) and phc_shape_series_options
 * (fit/costs/shape_series.h: which series is which stalk). */
#include <math.h>

#define PHC_SS_PI 3.14159265358979323846
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/config/kind.h"
#include "fit/config/kinds.h"
#include "fit/config/yaml_keys.h"
#include "fit/costs/shape_series.h"
#include "fit/costs/source_file.h"
#include "measurements/plant_io.h"
#include "measurements/units.h"

static const char *const shape_series_keys[] = {"file",  "time",  "y_down", "series", "rwc0",    "t0",
                                                "e_min", "sigma", "every",  "density", "fd_step", "frames",
                                                "plant", "plant_format", "plant_unit", "water", "conductance",
                                                "viscosity", "water_step", "dynamics", "particle_iterations",
                                                "particle_time_step", "particle_steps", "particle_damping",
                                                "parent_weight", NULL};
static const char *const stalk_keys[] = {"id",     "column",   "unit",           "length", "radius",
                                         "segments", "tip_mass", "base_angle_deg", "offset", "segment", NULL};
static const phc_key_help shape_series_help[] = {
    {"file", "CSV of tracked organ angles over time (one column per organ), relative to the config "
             "file. Required."},
    {"time", "Time column: a name, or {column: NAME, unit: UNIT} with any UDUNITS-2 time unit "
             "(default unit s). Times must increase strictly. Required."},
    {"y_down", "true when the angles are measured in image axes (y down, clockwise on screen, as "
               "OpenCV trackers write them): they are negated so that the model's angles turn "
               "counter-clockwise with z up. Default false."},
    {"series", "Non-empty list of stalks, one per tracked organ: {id, column, unit (deg or rad, "
               "default deg), length (m), radius (m), segments (default 8), tip_mass (kg, >= 0), "
               "base_angle_deg (direction of the clamped base, counter-clockwise from +x; default "
               "the first observed angle), offset (true: a parameter slot offset_<id>, rad, added "
               "to the model angle; default false)}. Required."},
    {"rwc0", "Relative water content at t0, in (0, 1.5]. Default 1."},
    {"t0", "Time origin of the water loss RWC(t) = rwc0 exp(-delta (t - t0)), s. Default the "
           "first sample."},
    {"e_min", "E_min, Pa, > 0, when `e_min` is not a parameter. Default 1e4."},
    {"sigma", "Standard deviation of an angle, rad (> 0). Default unweighted."},
    {"every", "Keep every k-th sample (k >= 1) to thin long tracks. Default 1."},
    {"density", "Stalk tissue density, kg m-3 (> 0). Default 1000."},
    {"fd_step", "dynamics: particles only: relative step in s of the central difference d angle / d s (rods use the exact derivative of the equilibrium). Default 1e-4."},
    {"plant", "A plant-graph file (relative to the config): the organ model is then the whole "
              "plant as one rod, every segment at E(t), and each series gives `segment` (the "
              "id of the segment whose direction is its angle) instead of length, radius, "
              "segments and base_angle_deg. Default: one stalk per series."},
    {"plant_format", "Format of the plant file: auto, paper, treeqsm, swc, native. Default auto."},
    {"plant_unit", "Length unit of the plant file (UDUNITS-2, e.g. mm). Default: the format's."},
    {"water", "What drives the modulus: compartment (one compartment per stalk, RWC(t) = rwc0 "
              "exp(-delta (t - t0)), delta in s-1) or plant (with `plant:`: the wilting paper's water "
              "model on the plant graph, each segment its own relative water content and modulus; "
              "delta is then the leaf loss in s-1 cm-2, the delta of a weight_curve on the same "
              "plant, so a joint fit can share it). Default compartment."},
    {"conductance", "With water: plant, the water model's edge weights: poiseuille, mean, paper, "
                    "reference or reference_2024 (as in weight_curve). Default poiseuille."},
    {"viscosity", "With water: plant, the sap viscosity, mPa s (> 0). Default 0.89 (0.9 with the "
                  "reference weights)."},
    {"water_step", "With water: plant, the BDF6 step of the water model, s (> 0). Default a "
                   "thousandth of the data's time span."},
    {"dynamics", "The organ model's dynamics: rods (elastic rods, static equilibrium) or "
                 "particles (oriented particles of the climbing-plants paper relaxed from rest to rest "
                 "under gravity; stiffness s(t) = E(t)/(e_min + e_max), see README \"Fitting with "
                 "particles\"). Default rods."},
    {"particle_iterations", "Particles: projection iterations per time step, 1 to 1000. Default 16."},
    {"particle_time_step", "Particles: time step, s, in (0, 1]. Default 5e-4."},
    {"particle_steps", "Particles: most time steps of one relaxation (1 to 1e7); a system not at rest "
                       "by then is refused. Default 20000."},
    {"particle_damping", "Particles: fraction of the velocity removed per step, in (0, 1). Default "
                         "0.1 (it does not move the rest state)."},
    {"parent_weight", "Particles: weight of the parent's group in a particle's goal blend, >= 1. "
                      "Default 2."},
    {"frames", "Frames (side views, graphs in native format and VTK) that simulate and fit write "
               "per series, evenly spaced over the data's times; 0 none. Default 6."},
    {NULL, NULL}};

typedef struct parsed {
    size_t n;
    phc_shape_series_spec *spec;
    phc_shape_stalk *stalk;
    char (*where)[4200];
} parsed;

static void parsed_free(parsed *p)
{
    free(p->spec);
    free(p->stalk);
    free(p->where);
}

static int read_stalk(const phc_yaml_doc *doc, const phc_yaml_node *item, size_t i, int y_down, int plant,
                      parsed *p, phc_error *err)
{
    char ctx[64];
    snprintf(ctx, sizeof ctx, "series item %zu", i + 1);
    int rc;
    if (item->kind != PHC_YAML_MAPPING)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'series': item %zu must be a mapping {id, column, ...}",
                             doc->path, item->line, i + 1);
    if ((rc = phc_yaml_check_keys(doc, item, stalk_keys, ctx, err)))
        return rc;
    phc_shape_series_spec *sp = &p->spec[i];
    phc_shape_stalk *st = &p->stalk[i];
    snprintf(p->where[i], sizeof p->where[i], "%s:%zu", doc->path, item->line);
    sp->kind = PHC_SHAPE_ANGLE;
    sp->angle_unit = "deg";
    sp->y_down = y_down;
    sp->where = p->where[i];
    st->where = p->where[i];
    st->segments = 8;
    st->base_angle = NAN;
    long segments = 8, segment = -1;
    double base_deg = NAN;
    if ((rc = phc_yaml_map_string(doc, item, "id", 1, ctx, &sp->id, err)) ||
        (rc = phc_yaml_map_string(doc, item, "column", 1, ctx, &sp->angle, err)) ||
        (rc = phc_yaml_map_string(doc, item, "unit", 0, ctx, &sp->angle_unit, err)) ||
        (rc = phc_yaml_map_number(doc, item, "length", !plant, ctx, &st->length, err)) ||
        (rc = phc_yaml_map_number(doc, item, "radius", !plant, ctx, &st->radius, err)) ||
        (rc = phc_yaml_map_integer(doc, item, "segment", plant, ctx, &segment, err)) ||
        (rc = phc_yaml_map_number(doc, item, "tip_mass", 1, ctx, &st->tip_mass, err)) ||
        (rc = phc_yaml_map_integer(doc, item, "segments", 0, ctx, &segments, err)) ||
        (rc = phc_yaml_map_number(doc, item, "base_angle_deg", 0, ctx, &base_deg, err)) ||
        (rc = phc_yaml_map_boolean(doc, item, "offset", 0, ctx, &st->offset, err)))
        return rc;
    if (segments < 1 || segments > 10000)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'segments': expected 1 to 10000, found %ld", doc->path,
                             phc_key_line(item, "segments"), segments);
    if (!plant && phc_yaml_get(item, "segment"))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'segment': only with a `plant:` graph", doc->path,
                             phc_key_line(item, "segment"));
    if (plant && (phc_yaml_get(item, "length") || phc_yaml_get(item, "radius") || phc_yaml_get(item, "segments") ||
                  phc_yaml_get(item, "base_angle_deg")))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: series item %zu: with a `plant:` graph the segment gives the geometry; "
                             "remove length, radius, segments and base_angle_deg", doc->path, item->line, i + 1);
    st->segments = (size_t)segments;
    st->segment = segment;
    st->series = sp->id;
    if (!isnan(base_deg))
        st->base_angle = base_deg * PHC_SS_PI / 180.0;
    return PHC_OK;
}

static int read_series(const phc_yaml_doc *doc, const phc_yaml_node *node, int y_down, int plant, parsed *p,
                       phc_error *err)
{
    const phc_yaml_node *list = phc_yaml_get(node, "series");
    if (!list)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: shape_series data set: missing key 'series'", doc->path,
                             node->line);
    if (list->kind != PHC_YAML_SEQUENCE || list->count == 0)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'series': expected a non-empty list of stalks",
                             doc->path, list->line);
    p->n = list->count;
    if (!(p->spec = calloc(p->n, sizeof *p->spec)) || !(p->stalk = calloc(p->n, sizeof *p->stalk)) ||
        !(p->where = calloc(p->n, sizeof *p->where)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < p->n; ++i) {
        int rc = read_stalk(doc, list->items[i], i, y_down, plant, p, err);
        if (rc)
            return rc;
    }
    return PHC_OK;
}

static int read_numbers(const phc_yaml_doc *doc, const phc_yaml_node *node, phc_shape_series_options *o,
                        phc_error *err)
{
    const char *ctx = "shape_series data set";
    long every = 1, frames = (long)o->frames;
    int rc, water = 0, cond = 0;
    static const char *const water_names[] = {"compartment", "plant", NULL};
    static const char *const cond_names[] = {"poiseuille", "mean", "paper", "reference", "reference_2024", NULL};
    static const phc_water_weights cond_values[] = {PHC_WATER_POISEUILLE, PHC_WATER_MEAN_CONDUCTANCE,
                                                    PHC_WATER_PAPER, PHC_WATER_REFERENCE,
                                                    PHC_WATER_REFERENCE_2024};
    if ((rc = phc_yaml_map_number(doc, node, "rwc0", 0, ctx, &o->rwc0, err)) ||
        (rc = phc_yaml_map_number(doc, node, "t0", 0, ctx, &o->t0, err)) ||
        (rc = phc_yaml_map_number(doc, node, "e_min", 0, ctx, &o->e_min, err)) ||
        (rc = phc_yaml_map_number(doc, node, "sigma", 0, ctx, &o->sigma, err)) ||
        (rc = phc_yaml_map_number(doc, node, "density", 0, ctx, &o->density, err)) ||
        (rc = phc_yaml_map_number(doc, node, "fd_step", 0, ctx, &o->fd_step, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "every", 0, ctx, &every, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "frames", 0, ctx, &frames, err)) ||
        (rc = phc_yaml_map_choice(doc, node, "water", ctx, water_names, &water, err)) ||
        (rc = phc_yaml_map_choice(doc, node, "conductance", ctx, cond_names, &cond, err)) ||
        (rc = phc_yaml_map_number(doc, node, "viscosity", 0, ctx, &o->viscosity, err)) ||
        (rc = phc_yaml_map_number(doc, node, "water_step", 0, ctx, &o->water_step, err)))
        return rc;
    o->water_model = water;
    o->conductance = cond_values[cond];
    if (!water)
        for (const char *const *k = (const char *const[]){"conductance", "viscosity", "water_step", NULL}; *k; ++k)
            if (phc_yaml_get(node, *k))
                return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key '%s': only with `water: plant`", doc->path,
                                     phc_key_line(node, *k), *k);
    if (phc_yaml_get(node, "viscosity") && !(o->viscosity > 0 && isfinite(o->viscosity)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'viscosity': must be positive (mPa s), found %g",
                             doc->path, phc_key_line(node, "viscosity"), o->viscosity);
    if (phc_yaml_get(node, "water_step") && !(o->water_step > 0 && isfinite(o->water_step)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'water_step': must be positive (s), found %g",
                             doc->path, phc_key_line(node, "water_step"), o->water_step);
    if (every < 1)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'every': expected an integer >= 1, found %ld", doc->path,
                             phc_key_line(node, "every"), every);
    if (frames < 0 || frames > 64)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'frames': expected 0 to 64, found %ld", doc->path,
                             phc_key_line(node, "frames"), frames);
    if (phc_yaml_get(node, "sigma") && !(o->sigma > 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'sigma': must be positive (rad), found %g", doc->path,
                             phc_key_line(node, "sigma"), o->sigma);
    o->every = (size_t)every;
    o->frames = (size_t)frames;
    return PHC_OK;
}

/* `dynamics` and the particle keys (only with dynamics: particles). */
static int read_dynamics(const phc_yaml_doc *doc, const phc_yaml_node *node, phc_shape_series_options *o,
                         phc_error *err)
{
    static const char *const particle_keys[] = {"particle_iterations", "particle_time_step", "particle_steps",
                                                "particle_damping", "parent_weight", NULL};
    static const char *const dynamics_names[] = {"rods", "particles", NULL};
    const char *ctx = "shape_series data set";
    int rc, dynamics = 0;
    if ((rc = phc_yaml_map_choice(doc, node, "dynamics", ctx, dynamics_names, &dynamics, err)))
        return rc;
    o->dynamics = dynamics ? PHC_SHAPE_PARTICLES : PHC_SHAPE_RODS;
    if (o->dynamics != PHC_SHAPE_PARTICLES) {
        for (size_t j = 0; particle_keys[j]; ++j)
            if (phc_yaml_get(node, particle_keys[j]))
                return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key '%s': only with `dynamics: particles`",
                                     doc->path, phc_key_line(node, particle_keys[j]), particle_keys[j]);
        return PHC_OK;
    }
    long iterations = (long)o->particle_iterations, steps = (long)o->particle_steps;
    if ((rc = phc_yaml_map_integer(doc, node, "particle_iterations", 0, ctx, &iterations, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "particle_steps", 0, ctx, &steps, err)) ||
        (rc = phc_yaml_map_number(doc, node, "particle_time_step", 0, ctx, &o->particle_time_step, err)) ||
        (rc = phc_yaml_map_number(doc, node, "particle_damping", 0, ctx, &o->particle_damping, err)) ||
        (rc = phc_yaml_map_number(doc, node, "parent_weight", 0, ctx, &o->parent_weight, err)))
        return rc;
    if (iterations < 1 || iterations > 1000)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'particle_iterations': expected 1 to 1000, found %ld",
                             doc->path, phc_key_line(node, "particle_iterations"), iterations);
    if (steps < 1 || steps > 10000000)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'particle_steps': expected 1 to 10000000, found %ld",
                             doc->path, phc_key_line(node, "particle_steps"), steps);
    o->particle_iterations = (size_t)iterations;
    o->particle_steps = (size_t)steps;
    return PHC_OK; /* the numbers' ranges: phc_shape_series_new, naming the key's line */
}

/* `plant`, `plant_format`, `plant_unit`: the graph (NULL without `plant`). */
static int read_plant(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                      phc_plant_graph **graph, char **gpath, phc_error *err)
{
    const phc_yaml_node *plant = phc_yaml_get(node, "plant");
    const char *ctx = "shape_series data set", *pfile = NULL, *fmt_name = "auto", *punit = NULL;
    int rc;
    if (!plant)
        return PHC_OK;
    if ((rc = phc_yaml_string(doc, plant, "plant", &pfile, err)) ||
        (rc = phc_yaml_map_string(doc, node, "plant_format", 0, ctx, &fmt_name, err)) ||
        (rc = phc_yaml_map_string(doc, node, "plant_unit", 0, ctx, &punit, err)))
        return rc;
    const int fmt = phc_plant_format_from_name(fmt_name);
    if (fmt < 0)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'plant_format': '%s' is not one of auto, paper, treeqsm, swc, native",
                             doc->path, phc_key_line(node, "plant_format"), fmt_name);
    double to_m = 0;
    if (punit) {
        phc_units *u = phc_units_new(err);
        if (!u)
            return err ? err->status : PHC_ERR_INTERNAL;
        phc_unit_conversion lc;
        char where[4300];
        snprintf(where, sizeof where, "%s:%zu: plant_unit", doc->path, phc_key_line(node, "plant_unit"));
        rc = phc_units_conversion(u, punit, "m", where, &lc, err);
        phc_units_free(u);
        if (rc)
            return rc;
        to_m = lc.scale;
    }
    if (!(*gpath = phc_join_path(base_dir, pfile)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if ((rc = phc_plant_io_read(*gpath, (phc_plant_format)fmt, to_m, graph, err)) && rc == PHC_ERR_IO)
        phc_error_prefix(err, rc, "%s:%zu: key 'plant'", doc->path, phc_key_line(node, "plant"));
    return rc;
}

static int shape_series_yaml(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                             phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out, phc_error *err)
{
    const char *file = NULL, *time_col = NULL, *time_unit = NULL;
    phc_shape_series_options o = phc_shape_series_options_default();
    const phc_origin origin = phc_yaml_origin(doc, node);
    parsed p = {0};
    phc_shape_series *tracks = NULL;
    phc_plant_graph *graph = NULL;
    char *gpath = NULL;
    char *path = NULL, time_where[4200];
    int y_down = 0, rc;

    *out = NULL;
    if ((rc = phc_yaml_map_string(doc, node, "file", 1, "shape_series data set", &file, err)) ||
        (rc = phc_column_spec(doc, node, "time", "shape_series data set", "s", &time_col, &time_unit, err)) ||
        (rc = phc_yaml_map_boolean(doc, node, "y_down", 0, "shape_series data set", &y_down, err)) ||
        (rc = read_numbers(doc, node, &o, err)) || (rc = read_dynamics(doc, node, &o, err)) ||
        (rc = read_series(doc, node, y_down, phc_yaml_get(node, "plant") != NULL, &p, err)) ||
        (rc = read_plant(doc, node, base_dir, &graph, &gpath, err)))
        goto done;
    snprintf(time_where, sizeof time_where, "%s:%zu", doc->path, phc_key_line(node, "time"));
    const phc_shape_spec spec = {time_col, time_unit, time_where, p.n, p.spec};
    if (!(path = phc_join_path(base_dir, file))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    if ((rc = phc_shape_series_read(path, &spec, NULL, &tracks, err))) {
        if (rc == PHC_ERR_IO)
            phc_error_prefix(err, rc, "%s:%zu: key 'file'", doc->path, phc_key_line(node, "file"));
        goto done;
    }
    o.e_min_slot = is_parameter && is_parameter("e_min", user_data);
    o.n_stalks = p.n;
    o.stalks = p.stalk;
    o.origin = &origin;
    o.plant = graph;
    if ((rc = phc_shape_series_new(tracks, &o, out, err)))
        goto done;
    if (phc_dataset_add_input(*out, path) || (gpath && phc_dataset_add_input(*out, gpath))) {
        phc_dataset_free(*out);
        *out = NULL;
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
done:
    phc_shape_series_free(tracks);
    phc_plant_graph_free(graph);
    free(gpath);
    parsed_free(&p);
    free(path);
    return rc;
}

const phc_kind phc_shape_series_kind = {
    .config = {.name = "shape_series",
               .summary = "tracked organ angles over time -> kappa, chi0, e_max, delta of a drooping "
                          "stalk whose stiffness follows its water (wilting eq. 9, elastic rods or oriented particles)",
               .keys = shape_series_keys,
               .help = shape_series_help},
    .ops = &phc_shape_series_ops,
    .load_yaml = shape_series_yaml,
};
