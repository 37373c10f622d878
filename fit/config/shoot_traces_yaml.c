/* `kind: shoot_traces` in a config: its keys and their help, and the
 * translation of its mapping (the traces file and the grow config it
 * names) into phc_shoot_traces_new's inputs (fit/costs/shoot_traces.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/config/kind.h"
#include "fit/config/kinds.h"
#include "fit/costs/shoot_traces.h"
#include "fit/costs/source_file.h"
#include "fit/grow.h"
#include "fit/grow_config.h"
#include "measurements/shoot_traces.h"
#include "measurements/support_mesh.h"

static const char *const shoot_traces_keys[] = {"file", "plant", "seeds", "first_seed", "times", "sigma",
                                                "fd_step", "frame_interval", "covariance_seeds", "correlation",
                                                "covariance_at", "covariance_rounds", "covariance_tolerance", NULL};
static const phc_key_help shoot_traces_help[] = {
    {"file", "CSV of traced shoots: columns time (s), shoot, x, y, z (m) and optionally parent "
             "(measurements/shoot_traces.h), relative to the config file. Required."},
    {"plant", "The grow config (`phytocal help grow`) the model plant is grown from: seed position "
              "and direction, support mesh, light, time step and every option the fit does not "
              "estimate, relative to the config file. Required."},
    {"seeds", "K, the number of seeds the model statistics are averaged over, the same K at every "
              "parameter value (common random numbers), 1..1000. Default: 8."},
    {"first_seed", "The seeds are first_seed .. first_seed + K - 1. Default: the grow config's seed."},
    {"times", "Observation times, s, increasing, at most the traces' last time. Default: 4 evenly "
              "spaced up to the traces' last time."},
    {"sigma", "{relative, length, fraction, cosine, angle}: lengths and height have sigma "
              "max(relative * value, length) (default 0.1, 0.01 m), attached fraction and light "
              "cosine `fraction` and `cosine` (0.05), angles `angle` degrees (5); shoot counts "
              "sqrt(max(1, count)); then the statistics' covariance C between model plants at the "
              "grow config's values is added: sigma^2 + (1 + 1/K) C (see covariance_seeds, "
              "correlation). Default: those values."},
    {"fd_step", "Relative step of the central differences, in (0, 1). Default: 0.2."},
    {"covariance_seeds", "M: the statistics' covariance (the synthetic likelihood's) is estimated from "
                         "max(K, M) model plants at the start values, 0..100000. Default: 64."},
    {"correlation", "g in [0, 1]: the weight of the estimated correlations between the statistics "
                    "(0: independent sigmas; 1: the covariance as estimated). Default: 0.5."},
    {"covariance_at", "start or fitted: where the statistics' covariance is computed. start: at the start "
                      "values, once. fitted: after the fit it is recomputed at the fitted values and the "
                      "fit solved again from there, until the estimates move by at most "
                      "covariance_tolerance from the values of the last covariance or covariance_rounds "
                      "recomputations were made (the report says which). Default: start."},
    {"covariance_rounds", "With covariance_at: fitted, the most recomputations of the covariance, "
                          "1..100. Default: 5."},
    {"covariance_tolerance", "With covariance_at: fitted, the rounds stop when no estimate moved by more "
                             "than this fraction of its value (of its scale when 0) from the values of the "
                             "last covariance, > 0. Default: 0.02."},
    {"frame_interval", "s, > 0: the tracer looked at the plant every frame_interval seconds (each "
                       "apex recorded where it was then; nodes may carry the time they were laid "
                       "down). The model plants are traced at the same frames. Default: every "
                       "distinct point time of the traces is a frame."},
    {NULL, NULL}};

/* What the data set keeps alive: the support mesh (closest points) and its
 * triangles as arrays (shadows). */
typedef struct support_owner {
    phc_support_mesh *mesh;
    double *vertices;
    size_t *triangles;
} support_owner;

static void support_owner_free(void *p)
{
    support_owner *s = p;
    if (!s) return;
    phc_support_mesh_free(s->mesh);
    free(s->vertices);
    free(s->triangles);
    free(s);
}

static int shoot_traces_yaml(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                             phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out, phc_error *err)
{
    const char *ctx = "shoot_traces data set", *file = NULL, *plant = NULL, *cov_at = NULL;
    char *path = NULL, *ppath = NULL;
    phc_grow_config *cfg = NULL;
    phc_support_mesh *mesh = NULL;
    support_owner *owner = NULL;
    phc_shoot_traces *tr = NULL;
    double *times = NULL;
    long seeds = 8, first = -1, cov_seeds = 64, cov_rounds = 5;
    phc_shoot_traces_options o = phc_shoot_traces_options_default();
    int rc;
    *out = NULL;
    if ((rc = phc_yaml_map_string(doc, node, "file", 1, ctx, &file, err)) ||
        (rc = phc_yaml_map_string(doc, node, "plant", 1, ctx, &plant, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "seeds", 0, ctx, &seeds, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "first_seed", 0, ctx, &first, err)) ||
        (rc = phc_yaml_map_number(doc, node, "fd_step", 0, ctx, &o.fd_step, err)) ||
        (rc = phc_yaml_map_number(doc, node, "frame_interval", 0, ctx, &o.frame_interval, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "covariance_seeds", 0, ctx, &cov_seeds, err)) ||
        (rc = phc_yaml_map_number(doc, node, "correlation", 0, ctx, &o.correlation, err)) ||
        (rc = phc_yaml_map_string(doc, node, "covariance_at", 0, ctx, &cov_at, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "covariance_rounds", 0, ctx, &cov_rounds, err)) ||
        (rc = phc_yaml_map_number(doc, node, "covariance_tolerance", 0, ctx, &o.covariance_tolerance, err)))
        goto done;
    if (cov_at && strcmp(cov_at, "start") && strcmp(cov_at, "fitted")) {
        const phc_yaml_node *v = phc_yaml_get(node, "covariance_at");
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu:%zu: key 'covariance_at': expected start or fitted, found '%s'",
                           doc->path, v->line, v->column, cov_at);
        goto done;
    }
    o.covariance_at_fitted = cov_at && !strcmp(cov_at, "fitted");
    if (cov_rounds < 1 || cov_rounds > 100) {
        const phc_yaml_node *v = phc_yaml_get(node, "covariance_rounds");
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu:%zu: key 'covariance_rounds': expected a whole number in 1..100, found %ld",
                           doc->path, v->line, v->column, cov_rounds);
        goto done;
    }
    o.covariance_rounds = (size_t)cov_rounds;
    if (!(o.covariance_tolerance > 0)) {
        const phc_yaml_node *v = phc_yaml_get(node, "covariance_tolerance");
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu:%zu: key 'covariance_tolerance': expected a number > 0, found %g",
                           doc->path, v->line, v->column, o.covariance_tolerance);
        goto done;
    }
    if (cov_seeds < 0 || cov_seeds > 100000) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: key 'covariance_seeds': expected a whole number in 0..100000, found %ld",
                           doc->path, phc_yaml_get(node, "covariance_seeds")->line, cov_seeds);
        goto done;
    }
    o.covariance_seeds = (size_t)cov_seeds;
    if (!(o.correlation >= 0 && o.correlation <= 1)) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'correlation': expected a number in [0, 1], found %g",
                           doc->path, phc_yaml_get(node, "correlation")->line, o.correlation);
        goto done;
    }
    if (phc_yaml_get(node, "frame_interval") && !(o.frame_interval > 0)) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'frame_interval': expected a time > 0 s, found %g",
                           doc->path, phc_yaml_get(node, "frame_interval")->line, o.frame_interval);
        goto done;
    }
    if (seeds < 1 || seeds > 1000) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'seeds': expected a whole number in 1..1000, found %ld",
                           doc->path, phc_yaml_get(node, "seeds")->line, seeds);
        goto done;
    }
    if (!(o.fd_step > 0 && o.fd_step < 1)) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'fd_step': expected a number in (0, 1), found %g",
                           doc->path, phc_yaml_get(node, "fd_step")->line, o.fd_step);
        goto done;
    }
    const phc_yaml_node *sg = phc_yaml_get(node, "sigma");
    if (sg) {
        static const char *const skeys[] = {"relative", "length", "fraction", "cosine", "angle", NULL};
        if ((rc = phc_yaml_check_keys(doc, sg, skeys, "sigma", err)) ||
            (rc = phc_yaml_map_number(doc, sg, "relative", 0, "sigma", &o.sigma_rel, err)) ||
            (rc = phc_yaml_map_number(doc, sg, "length", 0, "sigma", &o.sigma_length, err)) ||
            (rc = phc_yaml_map_number(doc, sg, "fraction", 0, "sigma", &o.sigma_fraction, err)) ||
            (rc = phc_yaml_map_number(doc, sg, "cosine", 0, "sigma", &o.sigma_cosine, err)) ||
            (rc = phc_yaml_map_number(doc, sg, "angle", 0, "sigma", &o.sigma_angle, err)))
            goto done;
        if (!(o.sigma_rel >= 0) || !(o.sigma_length > 0) || !(o.sigma_fraction > 0) || !(o.sigma_cosine > 0) ||
            !(o.sigma_angle > 0)) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: sigma: every value must be > 0 (relative >= 0)", doc->path, sg->line);
            goto done;
        }
    }
    const phc_yaml_node *tn = phc_yaml_get(node, "times");
    if (tn) {
        if (tn->kind != PHC_YAML_SEQUENCE || tn->count == 0) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'times': expected a list of times in s",
                               doc->path, tn->line);
            goto done;
        }
        if (!(times = malloc(tn->count * sizeof *times))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
        for (size_t i = 0; i < tn->count; ++i)
            if ((rc = phc_yaml_number(doc, tn->items[i], "times", &times[i], err))) goto done;
        o.times = times;
        o.n_times = tn->count;
    }
    if (!(path = phc_join_path(base_dir, file)) || !(ppath = phc_join_path(base_dir, plant))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto done;
    }
    if ((rc = phc_grow_config_load(ppath, &cfg, err))) {
        phc_error_prefix(err, rc, "%s:%zu: key 'plant'", doc->path, phc_yaml_get(node, "plant")->line);
        goto done;
    }
    if (cfg->support) {
        phc_error e;
        phc_error_clear(&e);
        if (!(mesh = phc_support_mesh_read(cfg->support, &e))) {
            rc = phc_error_set(err, e.status == PHC_ERR_NOMEM ? PHC_ERR_NOMEM : PHC_ERR_INPUT, "%s:%zu: support: %s",
                               cfg->source, cfg->support_line, e.message);
            goto done;
        }
    }
    o.plant = cfg->options;
    /* the light grid and the supports' shadows as `phytocal grow` sets them up (fit/grow.c) */
    phc_grow_light_grid(cfg, mesh, &o.plant);
    if (mesh) {
        if (!(owner = calloc(1, sizeof *owner))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto done;
        }
        owner->mesh = mesh;
        mesh = NULL;
        if (cfg->shadows &&
            (rc = phc_support_mesh_arrays(owner->mesh, &owner->vertices, &o.shadow_vertex_count,
                                          &owner->triangles, &o.shadow_triangle_count, err)))
            goto done;
        o.shadow_vertices = owner->vertices;
        o.shadow_triangles = owner->triangles;
        mesh = owner->mesh;
    }
    if (mesh) {
        o.plant.closest = phc_support_mesh_closest;
        o.plant.closest_user = mesh;
        double c[3], nn[3]; /* a first query builds the mesh's search tree */
        phc_support_mesh_closest(mesh, cfg->position, c, nn);
    }
    memcpy(o.position, cfg->position, sizeof o.position);
    memcpy(o.direction, cfg->direction, sizeof o.direction);
    o.time_step = cfg->time_step;
    o.seeds = (size_t)seeds;
    o.first_seed = first >= 0 ? (uint64_t)first : cfg->options.seed;
    o.is_parameter = is_parameter;
    o.user_data = user_data;
    o.support_owner = owner;
    o.support_free = support_owner_free;
    if ((rc = phc_shoot_traces_read(path, &tr, err))) {
        if (rc == PHC_ERR_IO) phc_error_prefix(err, rc, "%s:%zu: key 'file'", doc->path, phc_yaml_get(node, "file")->line);
        goto done;
    }
    mesh = NULL;
    owner = NULL; /* handed over, with the traces */
    rc = phc_shoot_traces_new(tr, &o, out, err);
    if (rc)
        phc_error_prefix(err, rc, "%s:%zu", doc->path, node->line);
    else if (phc_dataset_add_input(*out, ppath) || (cfg->support && phc_dataset_add_input(*out, cfg->support))) {
        phc_dataset_free(*out);
        *out = NULL;
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
done:
    if (owner)
        support_owner_free(owner); /* holds the mesh */
    else
        phc_support_mesh_free(mesh);
    phc_grow_config_free(cfg);
    free(times);
    free(path);
    free(ppath);
    return rc;
}

const phc_kind phc_shoot_traces_kind = {
    .config = {.name = "shoot_traces",
               .summary = "traced shoots of a climbing plant -> growth, branching and tropism parameters "
                          "(BP, V, eta, tau, r; Hädrich et al. 2017) by summary statistics over K seeds",
               .keys = shoot_traces_keys,
               .help = shoot_traces_help},
    .ops = &phc_shoot_traces_ops,
    .load_yaml = shoot_traces_yaml,
};
