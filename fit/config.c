/* YAML configuration -> calibration problem: see config.h. */
#include "fit/config.h"

#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/config/kinds.h"
#include "fit/config/soil_setup_yaml.h"
#include "fit/config/yaml_keys.h"
#include "fit/costs/source_file.h"
#include "fit/engine/parameter_units.h"
#include "fit/engine/prior.h"
#include "measurements/suggest.h"
#include "measurements/yaml_doc.h"

/* The data-set kinds this build knows, alphabetical: each descriptor
 * (fit/config/kind.h) holds the name, summary, keys and their help, the
 * operations and the YAML translation. */

static const phc_kind *const kinds[] = {
    &phc_curve_kind,
    &phc_elasticity_curve_kind,
    &phc_infiltration_kind,
    &phc_leaf_photos_kind,
    &phc_pv_curve_kind,
    &phc_root_shoot_kind,
    &phc_shape_series_kind,
    &phc_shoot_traces_kind,
    &phc_soil_probe_kind,
    &phc_weight_curve_kind,
};
#define N_KINDS (sizeof kinds / sizeof kinds[0])

/* The blocks' key tables (what the parsers below accept) and their help. */
static const char *const common_dataset_keys[] = {"kind", "name", "parameters", "loss",
                                                  "loss_scale", "derivatives", NULL};
static const phc_key_help common_dataset_help[] = {
    {"kind", "The data set's kind: one of the kinds listed by `phytocal help`; `phytocal help "
             "KIND` lists its own keys. Required."},
    {"name", "Name used in reports, plots and output file names; unique among the data sets. "
             "Default: <kind>-<index>, counting from 1."},
    {"parameters", "Binding {slot: global_name, ...}: which global parameter each of the kind's "
                   "parameter slots uses (two data sets bound to one name share it: a joint fit). "
                   "A key that names no slot is an error. Default: each slot uses the global "
                   "parameter of its own name."},
    {"loss", "Robust loss on each weighted residual: none, huber, cauchy, soft_l1 or arctan. "
             "Default: none."},
    {"loss_scale", "Scale of the robust loss, > 0, in units of the weighted residual. "
                   "Default: 1."},
    {"derivatives", "How the Jacobian is computed: central or ridders (numerical differences), "
                    "or analytic for kinds that provide it. Default: analytic where the kind "
                    "has it, else central."},
    {NULL, NULL}};

static const char *const top_keys[] = {"name", "parameters", "datasets", "solver", "report", "groups", "outputs", NULL};
static const phc_key_help top_help[] = {
    {"name", "Run name, used for the output directory runs/<name>/ and in the report. "
             "Default: the config file's name without its extension."},
    {"parameters", "The global parameters: {NAME: {value, lower, upper, fixed, unit, scale, "
                   "range, prior}, ...} or NAME: number (the start value). Required."},
    {"datasets", "Non-empty list of data sets, each with `kind`, the common data-set keys and "
                 "its kind's keys. Required."},
    {"solver", "Mapping: how the fit is solved (keys below). Optional."},
    {"report", "Mapping: the report's checks (keys below). Optional."},
    {"groups", "Mapping {GROUP: [parameter, ...], ...}: parameters that `phytocal sensitivity` "
               "varies together as one factor, with one index per group. A parameter belongs to "
               "at most one group; a group is not empty. Optional."},
    {"outputs", "List of named outputs `phytocal sensitivity` estimates indices of, beside the "
                "cost and the predictions: {name, dataset, at: X} (the data set's prediction at x = "
                "X in its x unit, e.g. hours since its first row; within its x range) or {name, "
                "dataset, observation: N} (at its N-th observation, from 1). Optional."},
    {NULL, NULL}};

static const char *const parameter_keys[] = {"value", "lower", "upper", "fixed", "unit",
                                             "scale", "range", "per_piece", "prior", NULL};
static const phc_key_help parameter_help[] = {
    {"value", "Start value, within the bounds. Required (or write NAME: number)."},
    {"lower", "Lower bound; not above upper. Default: none (-inf)."},
    {"upper", "Upper bound. Default: none (+inf)."},
    {"fixed", "true: the parameter keeps its start value and is not fitted. Default: false."},
    {"unit", "The unit of value, lower, upper, range and scale (UDUNITS-2 syntax, e.g. g h-1). "
             "When the model slot it is bound to declares a unit, the parameter is converted into "
             "it for the fit and reported back in this unit (a unit of another dimension is an "
             "error); otherwise it is a label for tables and plots. Default: the slot's unit."},
    {"scale", "Typical magnitude, > 0: the solver works on value/scale. Default: |value|, or 1 "
              "when value is 0."},
    {"range", "[low, high], low < high: the box in which multi-start draws start points "
              "(solver starts and rescue_starts). Default: the bounds when both are finite, "
              "else a decade either side of value."},
    {"per_piece", "true: the slots NAME_2, NAME_3, ... of a weight curve split at irrigations "
                  "(jumps: split) get their own copies of this parameter, with its start, "
                  "bounds, unit and scale, named as the slots. Default: false."},
    {"prior", "The distribution `phytocal sensitivity` samples, in the parameter's unit: "
              "{dist: uniform | log-uniform, lower, upper} (default: the bounds), "
              "{dist: normal, mean, sd} or {dist: log-normal, meanlog, sdlog} (of ln x); normal "
              "kinds are truncated to the bounds. Default: uniform on the bounds, which must then "
              "be finite."},
    {NULL, NULL}};

static const char *const solver_keys[] = {"method", "max_iterations", "function_tolerance",
                                          "gradient_tolerance", "parameter_tolerance",
                                          "threads", "starts", "rescue_starts", NULL};
static const phc_key_help solver_help[] = {
    {"method", "Ceres trust-region strategy: levenberg_marquardt or dogleg. "
               "Default: levenberg_marquardt."},
    {"max_iterations", "Most iterations per start, 1 to 1e6. Default: 1000."},
    {"function_tolerance", "Stop when the relative change of the cost falls below this, >= 0. "
                           "Default: 1e-15, raised to a model's relative accuracy when a data "
                           "set has one (weight_curve, root_shoot) and this key is not given."},
    {"gradient_tolerance", "Stop when the scaled gradient falls below this, >= 0. Default: 1e-15, "
                           "raised like function_tolerance."},
    {"parameter_tolerance", "Stop when the relative step falls below this, >= 0. Default: 1e-15, "
                            "raised like function_tolerance."},
    {"threads", "Threads the solver uses, 1 to 256. Default: 1."},
    {"starts", "Number of starts, 1 to 1e5; more than 1 adds Sobol points in the parameters' "
               "range boxes, the best fit is kept and the report says how many reached it. "
               "Default: 1."},
    {"rescue_starts", "With a single start: Sobol starts added when it fails to converge or "
                      "stalls where a parameter has no effect; 0 to 1e5, 0 turns this off. "
                      "Default: 16."},
    {NULL, NULL}};

static const char *const report_keys[] = {"level", "absolute_sigma", "collinearity_threshold",
                                          "correlation_threshold", NULL};
static const phc_key_help report_help[] = {
    {"level", "Significance level of the residual checks, in (0, 1). Default: 0.05."},
    {"absolute_sigma", "true: the sigmas are the true standard deviations (s^2 = 1); false: "
                       "standard errors are scaled by s^2 = weighted RSS / dof. Default: false."},
    {"collinearity_threshold", "Collinearity index above which a parameter set is reported as "
                               "not identifiable, > 1 (FME's rule of thumb). Default: 20."},
    {"correlation_threshold", "|correlation| of two parameters above which the pair is "
                              "reported, in (0, 1]. Default: 0.95."},
    {NULL, NULL}};

static const phc_config_section blocks[PHC_CONFIG_N_BLOCKS] = {
    [PHC_CONFIG_TOP] = {"top level", "the configuration file is a YAML mapping with these keys; "
                                     "unknown keys anywhere are errors naming the nearest valid key",
                        top_keys, top_help},
    [PHC_CONFIG_PARAMETER] = {"parameters", "NAME: {value, lower, upper, fixed, unit, scale, "
                                            "range, prior} or NAME: number (the start value)",
                              parameter_keys, parameter_help},
    [PHC_CONFIG_DATASET] = {"datasets", "a list; every data set has these keys besides its "
                                        "kind's own",
                            common_dataset_keys, common_dataset_help},
    [PHC_CONFIG_SOLVER] = {"solver", "how the fit is solved (Ceres Solver)", solver_keys,
                           solver_help},
    [PHC_CONFIG_REPORT] = {"report", "the report's checks of residuals and parameters",
                           report_keys, report_help},
    [PHC_CONFIG_SOIL] = {"soil", "the Rhizomorph soil (model/soil.h, §6) of soil_probe, "
                                 "infiltration and root_shoot data sets: grid, layers, "
                                 "boundaries, rain and sources; parameters named p, c, p_<L>, "
                                 "c_<L> (layer L from 1 at the surface), f_diff, f_grav are "
                                 "fitted, otherwise the values here are used",
                         phc_soil_setup_keys, phc_soil_setup_help},
};

size_t phc_config_kind_count(void)
{
    return N_KINDS;
}

const phc_config_section *phc_config_kind_at(size_t i)
{
    return i < N_KINDS ? &kinds[i]->config : NULL;
}

const phc_config_section *phc_config_kind_find(const char *name)
{
    for (size_t i = 0; name && i < N_KINDS; ++i)
        if (strcmp(kinds[i]->config.name, name) == 0)
            return &kinds[i]->config;
    return NULL;
}

const phc_config_section *phc_config_block(phc_config_block_id id)
{
    return (int)id >= 0 && id < PHC_CONFIG_N_BLOCKS ? &blocks[id] : NULL;
}

static int expect_kind(const phc_yaml_doc *doc, const phc_yaml_node *node, phc_yaml_kind kind,
                       const char *what, phc_error *err)
{
    static const char *names[] = {"a scalar", "a sequence", "a mapping"};
    if (node && node->kind == kind)
        return PHC_OK;
    return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu:%zu: %s: expected %s, found %s", doc->path,
                         node ? node->line : 1, node ? node->column : 1, what, names[kind],
                         node ? names[node->kind] : "nothing");
}

/* prior: {dist, lower, upper | mean, sd | meanlog, sdlog} (fit/engine/prior.h);
 * the numbers are checked here (phc_prior_resolve) so that a bad prior
 * names its line whatever command reads the config. */
static int parse_prior(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *ctx, phc_parameter *p,
                       phc_error *err)
{
    static const char *const prior_keys[] = {"dist", "lower", "upper", "mean", "sd", "meanlog", "sdlog", NULL};
    char pctx[200], what[400];
    snprintf(pctx, sizeof pctx, "%s: prior", ctx);
    snprintf(what, sizeof what, "%s:%zu: %s", doc->path, node->line, ctx);
    int rc;
    const char *dist = NULL;
    if ((rc = expect_kind(doc, node, PHC_YAML_MAPPING, pctx, err)) ||
        (rc = phc_yaml_check_keys(doc, node, prior_keys, pctx, err)) ||
        (rc = phc_yaml_map_string(doc, node, "dist", 1, pctx, &dist, err)))
        return rc;
    const int kind = phc_prior_kind_parse(dist);
    if (kind < 0)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: dist: unknown distribution '%s'; expected uniform, "
                             "log-uniform, normal or log-normal", doc->path, phc_yaml_get(node, "dist")->line, pctx,
                             dist);
    /* the keys each kind takes */
    const char *first = "lower", *second = "upper";
    if (kind == PHC_PRIOR_NORMAL) {
        first = "mean";
        second = "sd";
    } else if (kind == PHC_PRIOR_LOG_NORMAL) {
        first = "meanlog";
        second = "sdlog";
    }
    for (size_t i = 0; i < node->count; ++i)
        if (strcmp(node->keys[i], "dist") && strcmp(node->keys[i], first) && strcmp(node->keys[i], second))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: key '%s' does not belong to a %s prior (it takes "
                                 "%s and %s)", doc->path, node->key_lines[i], pctx, node->keys[i], dist, first,
                                 second);
    const int bounded = kind == PHC_PRIOR_UNIFORM || kind == PHC_PRIOR_LOG_UNIFORM;
    /* uniform kinds default to the bounds (in the same unit) */
    double a = bounded ? p->lower : NAN, b = bounded ? p->upper : NAN;
    if ((rc = phc_yaml_map_number(doc, node, first, !bounded, pctx, &a, err)) ||
        (rc = phc_yaml_map_number(doc, node, second, !bounded, pctx, &b, err)))
        return rc;
    p->prior.kind = (phc_prior_kind)kind;
    p->prior.a = a;
    p->prior.b = b;
    p->prior.lower = p->lower;
    p->prior.upper = p->upper;
    p->prior_line = node->line;
    phc_prior check;
    return phc_prior_resolve(&p->prior, p->lower, p->upper, what, &check, err);
}

static int parse_parameter(const phc_yaml_doc *doc, phc_problem *pb, const char *name,
                           const phc_yaml_node *spec, size_t key_line, phc_error *err)
{
    char ctx[160];
    snprintf(ctx, sizeof ctx, "parameter '%s'", name);
    double value = NAN;
    int rc;
    if (spec->kind == PHC_YAML_SCALAR) {
        if ((rc = phc_yaml_number(doc, spec, name, &value, err)))
            return rc;
    } else {
        if ((rc = expect_kind(doc, spec, PHC_YAML_MAPPING, ctx, err)) ||
            (rc = phc_yaml_check_keys(doc, spec, parameter_keys, ctx, err)) ||
            (rc = phc_yaml_map_number(doc, spec, "value", 1, ctx, &value, err)))
            return rc;
    }
    size_t index;
    if ((rc = phc_problem_add_parameter(pb, name, value, &index, err))) {
        if (rc == PHC_ERR_INPUT) /* duplicate: give the place */
            return phc_error_set(err, rc, "%s:%zu: parameter '%s' is defined twice", doc->path, key_line, name);
        return rc;
    }
    phc_parameter *p = &pb->params[index];
    p->config_line = key_line; /* phc_problem_validate's messages name it */
    if (spec->kind == PHC_YAML_SCALAR)
        return PHC_OK;
    const char *unit = NULL;
    if ((rc = phc_yaml_map_number(doc, spec, "lower", 0, ctx, &p->lower, err)) ||
        (rc = phc_yaml_map_number(doc, spec, "upper", 0, ctx, &p->upper, err)) ||
        (rc = phc_yaml_map_boolean(doc, spec, "fixed", 0, ctx, &p->fixed, err)) ||
        (rc = phc_yaml_map_boolean(doc, spec, "per_piece", 0, ctx, &p->per_piece, err)) ||
        (rc = phc_yaml_map_number(doc, spec, "scale", 0, ctx, &p->scale, err)) ||
        (rc = phc_yaml_map_string(doc, spec, "unit", 0, ctx, &unit, err)))
        return rc;
    if (unit && !(p->unit = strdup(unit)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if (p->lower > p->upper)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: lower bound %g is above upper bound %g",
                             doc->path, spec->line, ctx, p->lower, p->upper);
    if (p->value < p->lower || p->value > p->upper)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: start value %g is outside its bounds [%g, %g]",
                             doc->path, spec->line, ctx, p->value, p->lower, p->upper);
    const phc_yaml_node *scale = phc_yaml_get(spec, "scale");
    if (scale && !(p->scale > 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: scale must be positive, found %g",
                             doc->path, scale->line, ctx, p->scale);
    const phc_yaml_node *range = phc_yaml_get(spec, "range");
    if (range) {
        if (range->kind != PHC_YAML_SEQUENCE || range->count != 2)
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: range: expected [low, high]",
                                 doc->path, range->line, ctx);
        if ((rc = phc_yaml_number(doc, range->items[0], "range", &p->range_lo, err)) ||
            (rc = phc_yaml_number(doc, range->items[1], "range", &p->range_hi, err)))
            return rc;
        if (!(p->range_lo < p->range_hi))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: range [%g, %g] is empty",
                                 doc->path, range->line, ctx, p->range_lo, p->range_hi);
    }
    const phc_yaml_node *prior = phc_yaml_get(spec, "prior");
    if (prior)
        return parse_prior(doc, prior, ctx, p, err);
    return PHC_OK;
}

static int parse_solver(const phc_yaml_doc *doc, const phc_yaml_node *node, phc_fit_options *o,
                        phc_error *err)
{
    const char *ctx = "solver";
    int rc;
    if ((rc = expect_kind(doc, node, PHC_YAML_MAPPING, ctx, err)) ||
        (rc = phc_yaml_check_keys(doc, node, solver_keys, ctx, err)))
        return rc;
    const char *method = NULL;
    long max_it = o->nls.max_iterations, threads = o->nls.num_threads, starts = (long)o->starts;
    long rescue = (long)o->rescue_starts;
    if ((rc = phc_yaml_map_string(doc, node, "method", 0, ctx, &method, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "max_iterations", 0, ctx, &max_it, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "threads", 0, ctx, &threads, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "starts", 0, ctx, &starts, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "rescue_starts", 0, ctx, &rescue, err)) ||
        (rc = phc_yaml_map_number(doc, node, "function_tolerance", 0, ctx, &o->nls.function_tolerance, err)) ||
        (rc = phc_yaml_map_number(doc, node, "gradient_tolerance", 0, ctx, &o->nls.gradient_tolerance, err)) ||
        (rc = phc_yaml_map_number(doc, node, "parameter_tolerance", 0, ctx, &o->nls.parameter_tolerance, err)))
        return rc;
    if (method) {
        if (strcmp(method, "levenberg_marquardt") == 0)
            o->nls.method = PHC_LEVENBERG_MARQUARDT;
        else if (strcmp(method, "dogleg") == 0)
            o->nls.method = PHC_DOGLEG;
        else
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: solver.method: expected levenberg_marquardt or dogleg, found '%s'",
                                 doc->path, phc_yaml_get(node, "method")->line, method);
    }
    if (max_it < 1 || max_it > 1000000 || threads < 1 || threads > 256 || starts < 1 || starts > 100000 ||
        rescue < 0 || rescue > 100000)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: solver: max_iterations (1..1e6), threads (1..256), starts (1..1e5) and rescue_starts (0..1e5) "
                             "must be positive whole numbers in range", doc->path, node->line);
    if (!(o->nls.function_tolerance >= 0) || !(o->nls.gradient_tolerance >= 0) ||
        !(o->nls.parameter_tolerance >= 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: solver: tolerances must not be negative",
                             doc->path, node->line);
    o->nls.max_iterations = (int)max_it;
    o->nls.num_threads = (int)threads;
    o->starts = (size_t)starts;
    o->rescue_starts = (size_t)rescue;
    return PHC_OK;
}

static int parse_report(const phc_yaml_doc *doc, const phc_yaml_node *node, phc_fit_options *o,
                        phc_error *err)
{
    const char *ctx = "report";
    int rc;
    if ((rc = expect_kind(doc, node, PHC_YAML_MAPPING, ctx, err)) ||
        (rc = phc_yaml_check_keys(doc, node, report_keys, ctx, err)) ||
        (rc = phc_yaml_map_number(doc, node, "level", 0, ctx, &o->level, err)) ||
        (rc = phc_yaml_map_boolean(doc, node, "absolute_sigma", 0, ctx, &o->absolute_sigma, err)) ||
        (rc = phc_yaml_map_number(doc, node, "collinearity_threshold", 0, ctx, &o->collinearity_threshold, err)) ||
        (rc = phc_yaml_map_number(doc, node, "correlation_threshold", 0, ctx, &o->correlation_threshold, err)))
        return rc;
    if (!(o->level > 0 && o->level < 1))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: report.level must be in (0, 1), found %g",
                             doc->path, node->line, o->level);
    if (!(o->collinearity_threshold > 1) || !(o->correlation_threshold > 0 && o->correlation_threshold <= 1))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: report: collinearity_threshold must exceed 1 and correlation_threshold be in (0, 1]",
                             doc->path, node->line);
    return PHC_OK;
}

/* Splitting the data sets' tables into groups (phc_config_load_group):
 * value NULL collects the column's distinct values instead of selecting. */
typedef struct row_filter {
    const char *column, *value;
    char **values; /* collected, in order of first appearance */
    size_t n_values;
    size_t tables; /* tables the filter was applied to */
    phc_config_table_cache *cache; /* NULL: every table read afresh */
} row_filter;

/* phc_config_table_cache: the tables read so far, by the path the config
 * named them with. */
struct phc_config_table_cache {
    char **paths;
    phc_table **tables;
    size_t n;
};

phc_config_table_cache *phc_config_table_cache_new(void)
{
    return calloc(1, sizeof(phc_config_table_cache));
}

void phc_config_table_cache_free(phc_config_table_cache *c)
{
    if (!c)
        return;
    for (size_t i = 0; i < c->n; ++i) {
        free(c->paths[i]);
        phc_table_free(c->tables[i]);
    }
    free(c->paths);
    free(c->tables);
    free(c);
}

/* The table at path: from the cache, or read (and kept there when there
 * is a cache; then *owned is 0 and the caller must not free it). */
static int read_table_cached(phc_config_table_cache *c, const char *path, phc_table **t, int *owned,
                             phc_error *err)
{
    *owned = 1;
    for (size_t i = 0; c && i < c->n; ++i)
        if (strcmp(c->paths[i], path) == 0) {
            *t = c->tables[i];
            *owned = 0;
            return PHC_OK;
        }
    int rc = phc_table_read(path, t, err);
    if (rc || !c)
        return rc;
    char **paths = realloc(c->paths, (c->n + 1) * sizeof *paths);
    if (paths)
        c->paths = paths;
    phc_table **tables = realloc(c->tables, (c->n + 1) * sizeof *tables);
    if (tables)
        c->tables = tables;
    char *copy = paths && tables ? strdup(path) : NULL;
    if (!copy) {
        phc_table_free(*t);
        *t = NULL;
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    c->paths[c->n] = copy;
    c->tables[c->n++] = *t;
    *owned = 0;
    return PHC_OK;
}

/* The loader's context for a kind: which expression names are parameters,
 * and the row filter (phc_kind_read_table). */
typedef struct binding_ctx {
    const phc_problem *pb;
    const phc_yaml_node *binding; /* the data set's `parameters:` mapping or NULL */
    row_filter *rows;             /* NULL: every row */
} binding_ctx;

static int collect_value(row_filter *f, const char *v)
{
    for (size_t i = 0; i < f->n_values; ++i)
        if (strcmp(f->values[i], v) == 0)
            return 0;
    char **grown = realloc(f->values, (f->n_values + 1) * sizeof *grown);
    if (!grown)
        return -1;
    f->values = grown;
    if (!(f->values[f->n_values] = strdup(v)))
        return -1;
    f->n_values++;
    return 0;
}

int phc_kind_read_table(void *user_data, const char *path, phc_table **out, phc_error *err)
{
    const binding_ctx *b = user_data;
    phc_table *t = NULL;
    int rc, owned = 1;
    *out = NULL;
    row_filter *f = b ? b->rows : NULL;
    if (!f)
        return phc_table_read(path, out, err);
    if ((rc = read_table_cached(f->cache, path, &t, &owned, err)))
        return rc;
    const long col = phc_table_find(t, f->column);
    if (col < 0) {
        const size_t nc = phc_table_columns(t);
        const char *names[64];
        char list[512] = "";
        for (size_t j = 0; j < nc; ++j) {
            if (j < 64)
                names[j] = phc_table_column_name(t, j);
            const size_t used = strlen(list);
            snprintf(list + used, sizeof list - used, "%s%s", j ? ", " : "", phc_table_column_name(t, j));
        }
        const char *near = phc_suggest(f->column, names, nc < 64 ? nc : 64);
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s: --each: no column '%s'%s%s%s (columns: %s)", path, f->column,
                           near ? "; did you mean '" : "", near ? near : "", near ? "'?" : "", list);
        if (owned)
            phc_table_free(t);
        return rc;
    }
    const size_t n = phc_table_rows(t);
    f->tables++;
    /* collecting the groups: every value, and the table cut to the first
     * group, since the rows of all groups together need not make one valid
     * data set (a weight curve's times start again with each plant) */
    const char *value = f->value;
    if (!value) {
        const size_t before = f->n_values;
        for (size_t r = 0; r < n; ++r)
            if (collect_value(f, phc_table_cell(t, r, (size_t)col))) {
                if (owned)
                    phc_table_free(t);
                return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            }
        if (n == 0) {
            if (owned) {
                *out = t;
                return PHC_OK;
            }
            return phc_table_select_rows(t, NULL, 0, out, err);
        }
        value = before ? f->values[0] : phc_table_cell(t, 0, (size_t)col);
    }
    size_t *rows = malloc((n ? n : 1) * sizeof *rows), k = 0;
    if (!rows) {
        if (owned)
            phc_table_free(t);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    for (size_t r = 0; r < n; ++r)
        if (strcmp(phc_table_cell(t, r, (size_t)col), value) == 0)
            rows[k++] = r;
    if (k == 0 && !f->value) /* the first group is not in this table: its own first */
        for (size_t r = 0; r < n; ++r)
            if (strcmp(phc_table_cell(t, r, (size_t)col), phc_table_cell(t, 0, (size_t)col)) == 0)
                rows[k++] = r;
    if (k == 0)
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s: --each %s: no row has the value '%s'", path, f->column, value);
    else
        rc = phc_table_select_rows(t, rows, k, out, err);
    free(rows);
    if (owned)
        phc_table_free(t);
    return rc;
}

static int is_parameter(const char *name, void *user_data)
{
    const binding_ctx *b = user_data;
    if (b->binding && phc_yaml_get(b->binding, name))
        return 1;
    return phc_problem_find_parameter(b->pb, name) >= 0;
}

/* A slot NAME_<k> (k >= 2) with no parameter of its own, where NAME is a
 * parameter marked per_piece: adds NAME_<k> as a copy of NAME and sets *idx
 * to it (left -1 otherwise). */
static int per_piece_copy(phc_problem *pb, const char *global, long *idx, phc_error *err)
{
    const char *us = strrchr(global, '_');
    if (!us || !us[1] || strspn(us + 1, "0123456789") != strlen(us + 1) || atol(us + 1) < 2)
        return PHC_OK;
    char base[256];
    if ((size_t)(us - global) >= sizeof base)
        return PHC_OK;
    memcpy(base, global, (size_t)(us - global));
    base[us - global] = '\0';
    long b = phc_problem_find_parameter(pb, base);
    if (b < 0 || !pb->params[b].per_piece)
        return PHC_OK;
    phc_parameter copy = pb->params[b]; /* by value: adding may move the array */
    size_t index;
    int rc = phc_problem_add_parameter(pb, global, copy.value, &index, err);
    if (rc)
        return rc;
    phc_parameter *p = &pb->params[index];
    p->lower = copy.lower;
    p->upper = copy.upper;
    p->fixed = copy.fixed;
    p->scale = copy.scale;
    p->range_lo = copy.range_lo;
    p->range_hi = copy.range_hi;
    p->config_line = copy.config_line;
    p->prior = copy.prior;
    p->prior_line = copy.prior_line;
    if (copy.unit && !(p->unit = strdup(copy.unit)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    *idx = (long)index;
    return PHC_OK;
}

static int bind_slots(const phc_yaml_doc *doc, const phc_yaml_node *binding, phc_problem *pb,
                      phc_dataset *ds, size_t line, phc_error *err)
{
    int rc;
    for (size_t j = 0; j < ds->k; ++j) {
        const char *global = ds->slot_names[j];
        const phc_yaml_node *b = binding ? phc_yaml_get(binding, global) : NULL;
        size_t where = line;
        if (b) {
            if ((rc = phc_yaml_string(doc, b, global, &global, err)))
                return rc;
            where = b->line;
        }
        long idx = phc_problem_find_parameter(pb, global);
        if (idx < 0 && (rc = per_piece_copy(pb, global, &idx, err)))
            return rc;
        if (idx < 0) {
            const char **names = malloc((pb->n_params + 1) * sizeof *names);
            if (!names)
                return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            for (size_t i = 0; i < pb->n_params; ++i)
                names[i] = pb->params[i].name;
            const char *near = phc_suggest(global, names, pb->n_params);
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: data set '%s': slot '%s' is bound to '%s', which is not under parameters:%s%s%s",
                               doc->path, where, ds->name, ds->slot_names[j], global,
                               near ? " did you mean '" : "", near ? near : "", near ? "'?" : "");
            free(names);
            return rc;
        }
        for (size_t i = 0; i < j; ++i)
            if (ds->param_index[i] == (size_t)idx)
                return phc_error_set(err, PHC_ERR_INPUT,
                                     "%s:%zu: data set '%s': slots '%s' and '%s' are bound to the same parameter '%s'",
                                     doc->path, where, ds->name, ds->slot_names[i], ds->slot_names[j], global);
        ds->param_index[j] = (size_t)idx;
    }
    /* Binding keys that name no slot are mistakes (typos) too. */
    for (size_t i = 0; binding && i < binding->count; ++i) {
        int found = 0;
        for (size_t j = 0; j < ds->k && !found; ++j)
            found = strcmp(binding->keys[i], ds->slot_names[j]) == 0;
        if (!found)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: data set '%s': binding '%s' names no parameter slot of this data set%s%s%s",
                                 doc->path, binding->key_lines[i], ds->name, binding->keys[i],
                                 ds->k ? " (slots: " : "", ds->k ? ds->slot_names[0] : "", ds->k ? ", ...)" : "");
    }
    return PHC_OK;
}

static int parse_loss(const phc_yaml_doc *doc, const phc_yaml_node *node, phc_dataset *ds,
                      const char *ctx, phc_error *err)
{
    static const char *names[] = {"none", "huber", "cauchy", "soft_l1", "arctan"};
    const char *loss = NULL;
    int rc;
    if ((rc = phc_yaml_map_string(doc, node, "loss", 0, ctx, &loss, err)) ||
        (rc = phc_yaml_map_number(doc, node, "loss_scale", 0, ctx, &ds->loss_scale, err)))
        return rc;
    if (loss) {
        size_t i;
        for (i = 0; i < 5; ++i)
            if (strcmp(loss, names[i]) == 0)
                break;
        if (i == 5) {
            const char *near = phc_suggest(loss, names, 5);
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: %s: loss '%s' is not one of none, huber, cauchy, soft_l1, arctan%s%s%s",
                                 doc->path, phc_yaml_get(node, "loss")->line, ctx, loss,
                                 near ? "; did you mean '" : "", near ? near : "", near ? "'?" : "");
        }
        ds->loss = (phc_loss_kind)i;
    }
    if (!(ds->loss_scale > 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: loss_scale must be positive, found %g",
                             doc->path, node->line, ctx, ds->loss_scale);
    const char *derivs = NULL;
    if ((rc = phc_yaml_map_string(doc, node, "derivatives", 0, ctx, &derivs, err)))
        return rc;
    if (derivs) {
        if (strcmp(derivs, "central") == 0)
            ds->derivatives = PHC_DERIV_CENTRAL;
        else if (strcmp(derivs, "ridders") == 0)
            ds->derivatives = PHC_DERIV_RIDDERS;
        else if (strcmp(derivs, "analytic") == 0 && ds->derivatives == PHC_DERIV_ANALYTIC)
            ; /* the kind provides them */
        else
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: %s: derivatives '%s': expected central or ridders%s",
                                 doc->path, phc_yaml_get(node, "derivatives")->line, ctx, derivs,
                                 ds->derivatives == PHC_DERIV_ANALYTIC ? " or analytic" : "");
    }
    return PHC_OK;
}

static int parse_dataset(const phc_yaml_doc *doc, const phc_yaml_node *node, size_t index,
                         const char *base_dir, phc_problem *pb, row_filter *rows, phc_error *err)
{
    char ctx[96];
    snprintf(ctx, sizeof ctx, "data set %zu", index + 1);
    int rc;
    if ((rc = expect_kind(doc, node, PHC_YAML_MAPPING, ctx, err)))
        return rc;
    const char *kind = NULL, *name = NULL;
    if ((rc = phc_yaml_map_string(doc, node, "kind", 1, ctx, &kind, err)) ||
        (rc = phc_yaml_map_string(doc, node, "name", 0, ctx, &name, err)))
        return rc;
    const phc_kind *entry = NULL;
    const char *kind_names[N_KINDS];
    for (size_t i = 0; i < N_KINDS; ++i) {
        kind_names[i] = kinds[i]->config.name;
        if (strcmp(kinds[i]->config.name, kind) == 0)
            entry = kinds[i];
    }
    if (!entry) {
        const char *near = phc_suggest(kind, kind_names, N_KINDS);
        char known[256] = "";
        for (size_t i = 0; i < N_KINDS; ++i) {
            size_t used = strlen(known);
            snprintf(known + used, sizeof known - used, "%s%s", i ? ", " : "", kind_names[i]);
        }
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: unknown kind '%s'%s%s%s (known: %s)",
                             doc->path, phc_yaml_get(node, "kind")->line, ctx, kind,
                             near ? "; did you mean '" : "", near ? near : "", near ? "'?" : "", known);
    }
    /* Allowed keys: the common ones and the kind's own. */
    const char *allowed[64];
    size_t na = 0;
    for (size_t i = 0; common_dataset_keys[i] && na < 63; ++i)
        allowed[na++] = common_dataset_keys[i];
    for (size_t i = 0; entry->config.keys[i] && na < 63; ++i)
        allowed[na++] = entry->config.keys[i];
    allowed[na] = NULL;
    if ((rc = phc_yaml_check_keys(doc, node, allowed, ctx, err)))
        return rc;
    const phc_yaml_node *binding = phc_yaml_get(node, "parameters");
    if (binding && (rc = expect_kind(doc, binding, PHC_YAML_MAPPING, "parameters of a data set", err)))
        return rc;

    if (rows && !entry->each) {
        char can[256] = "";
        for (size_t i = 0; i < N_KINDS; ++i)
            if (kinds[i]->each) {
                const size_t used = strlen(can);
                snprintf(can + used, sizeof can - used, "%s%s", used ? ", " : "", kinds[i]->config.name);
            }
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: %s: --each %s: kind '%s' cannot be split into groups of rows (kinds that "
                             "can: %s)", doc->path, node->line, ctx, rows->column, kind, can);
    }
    binding_ctx bctx = {pb, binding, rows};
    phc_dataset *ds = NULL;
    if ((rc = entry->load_yaml(doc, node, base_dir, is_parameter, &bctx, &ds, err)))
        return rc;
    char fallback[64];
    snprintf(fallback, sizeof fallback, "%s-%zu", kind, index + 1);
    ds->name = strdup(name ? name : fallback);
    if (!ds->name) {
        phc_dataset_free(ds);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    for (size_t d = 0; d < pb->n_datasets; ++d)
        if (strcmp(pb->datasets[d]->name, ds->name) == 0) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: data set name '%s' is used twice",
                               doc->path, node->line, ds->name);
            phc_dataset_free(ds);
            return rc;
        }
    if ((rc = bind_slots(doc, binding, pb, ds, node->line, err)) ||
        (rc = parse_loss(doc, node, ds, ctx, err))) {
        phc_dataset_free(ds);
        return rc;
    }
    return phc_problem_add_dataset(pb, ds, err);
}

/* A run's name names its folder runs/<name>/: a plain name, never a path. */
static int check_run_name(const phc_yaml_doc *doc, const phc_yaml_node *root, const char *name,
                          phc_error *err)
{
    size_t len = strlen(name);
    int ok = len > 0 && len <= 100 && name[0] != '.';
    for (size_t i = 0; ok && i < len; ++i) {
        const char c = name[i];
        ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
             c == '-' || c == '_';
    }
    if (ok)
        return PHC_OK;
    return phc_error_set(err, PHC_ERR_INPUT,
                         "%s:%zu: name: '%s' is not a plain name: it names the folder runs/<name>/, so use 1 to "
                         "100 letters, digits, '.', '-' and '_', not starting with '.' (to write elsewhere, give "
                         "-o DIR)", doc->path, phc_key_line(root, "name"), name);
}

/* Every `seed:` in the document, as "datasets[1].soil.rocks.seed: 7", for
 * provenance (a run that draws random numbers says from which seed). */
static int collect_seeds(const phc_yaml_node *node, const char *where, phc_problem *pb)
{
    char sub[512];
    if (node->kind == PHC_YAML_SEQUENCE) {
        for (size_t i = 0; i < node->count; ++i) {
            snprintf(sub, sizeof sub, "%s[%zu]", where, i + 1);
            if (collect_seeds(node->items[i], sub, pb))
                return -1;
        }
    } else if (node->kind == PHC_YAML_MAPPING) {
        for (size_t i = 0; i < node->count; ++i) {
            snprintf(sub, sizeof sub, "%s%s%s", where, where[0] ? "." : "", node->keys[i]);
            const phc_yaml_node *v = node->values[i];
            if (strcmp(node->keys[i], "seed") == 0 && v->kind == PHC_YAML_SCALAR) {
                char **grown = realloc(pb->seeds, (pb->n_seeds + 1) * sizeof *grown);
                if (!grown)
                    return -1;
                pb->seeds = grown;
                const size_t size = strlen(sub) + strlen(v->scalar) + 3;
                if (!(pb->seeds[pb->n_seeds] = malloc(size)))
                    return -1;
                snprintf(pb->seeds[pb->n_seeds++], size, "%s: %s", sub, v->scalar);
            } else if (collect_seeds(v, sub, pb)) {
                return -1;
            }
        }
    }
    return 0;
}

static char *stem_of(const char *path)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    char *s = strdup(base);
    if (!s)
        return NULL;
    char *dot = strrchr(s, '.');
    if (dot && dot != s)
        *dot = '\0';
    return s;
}

/* groups: {NAME: [parameter, ...]}: parameters a sensitivity study varies
 * as one factor.  Read after the data sets, whose per_piece copies may be
 * named. */
static int parse_groups(const phc_yaml_doc *doc, const phc_yaml_node *node, phc_problem *pb, phc_error *err)
{
    int rc;
    if ((rc = expect_kind(doc, node, PHC_YAML_MAPPING, "groups", err)))
        return rc;
    if (!(pb->groups = calloc(node->count ? node->count : 1, sizeof *pb->groups)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t g = 0; g < node->count; ++g) {
        const phc_yaml_node *list = node->values[g];
        phc_parameter_group *grp = &pb->groups[pb->n_groups++];
        grp->config_line = node->key_lines[g];
        if (!(grp->name = strdup(node->keys[g])))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        if (list->kind != PHC_YAML_SEQUENCE)
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: groups: group '%s': expected a list of parameter "
                                 "names", doc->path, list->line, node->keys[g]);
        if (list->count == 0)
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: groups: group '%s' is empty", doc->path, list->line,
                                 node->keys[g]);
        if (!(grp->members = calloc(list->count, sizeof *grp->members)))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        for (size_t i = 0; i < list->count; ++i) {
            const phc_yaml_node *item = list->items[i];
            const char *pname = NULL;
            if ((rc = phc_yaml_string(doc, item, "groups", &pname, err)))
                return rc;
            const long idx = phc_problem_find_parameter(pb, pname);
            if (idx < 0)
                return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: groups: group '%s': '%s' is not a parameter",
                                     doc->path, item->line, node->keys[g], pname);
            for (size_t h = 0; h < pb->n_groups; ++h)
                for (size_t m = 0; m < pb->groups[h].n_members; ++m)
                    if (pb->groups[h].members[m] == (size_t)idx)
                        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: groups: parameter '%s' is already in "
                                             "group '%s'", doc->path, item->line, pname, pb->groups[h].name);
            grp->members[grp->n_members++] = (size_t)idx;
        }
    }
    return PHC_OK;
}

/* outputs: [{name, dataset, at | observation}, ...]: named outputs of
 * sensitivity studies (problem.h: phc_problem_add_output checks them). */
static int parse_outputs(const phc_yaml_doc *doc, const phc_yaml_node *node, phc_problem *pb, phc_error *err)
{
    static const char *const keys[] = {"name", "dataset", "at", "observation", NULL};
    int rc;
    if ((rc = expect_kind(doc, node, PHC_YAML_SEQUENCE, "outputs", err)))
        return rc;
    for (size_t i = 0; i < node->count; ++i) {
        const phc_yaml_node *item = node->items[i];
        char ctx[64];
        snprintf(ctx, sizeof ctx, "outputs[%zu]", i + 1);
        if ((rc = expect_kind(doc, item, PHC_YAML_MAPPING, ctx, err)) ||
            (rc = phc_yaml_check_keys(doc, item, keys, ctx, err)))
            return rc;
        const char *name = NULL, *dataset = NULL;
        double at = NAN;
        long obs = 0;
        if ((rc = phc_yaml_map_string(doc, item, "name", 1, ctx, &name, err)) ||
            (rc = phc_yaml_map_string(doc, item, "dataset", 1, ctx, &dataset, err)) ||
            (rc = phc_yaml_map_number(doc, item, "at", 0, ctx, &at, err)) ||
            (rc = phc_yaml_map_integer(doc, item, "observation", 0, ctx, &obs, err)))
            return rc;
        const phc_yaml_node *at_node = phc_yaml_get(item, "at"), *obs_node = phc_yaml_get(item, "observation");
        if ((at_node != NULL) == (obs_node != NULL))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: give exactly one of 'at' (an x in the data set's "
                                 "unit) and 'observation' (its number, from 1)", doc->path, item->line, ctx);
        if (obs_node && obs < 1)
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: observation: %ld; observations count from 1",
                                 doc->path, obs_node->line, ctx, obs);
        if ((rc = phc_problem_add_output(pb, name, dataset, at, obs_node ? (size_t)obs : 0,
                                         at_node ? at_node->line : obs_node->line, err)))
            return rc;
    }
    return PHC_OK;
}

static int load(const char *path, row_filter *rows, phc_problem **out, phc_error *err)
{
    phc_yaml_doc *doc = NULL;
    phc_problem *pb = NULL;
    char *dir_copy = NULL, *stem = NULL;
    int rc;
    *out = NULL;
    if ((rc = phc_yaml_load(path, &doc, err)))
        return rc;
    const phc_yaml_node *root = doc->root;
    if (!root) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s: the configuration is empty", path);
        goto fail;
    }
    if ((rc = expect_kind(doc, root, PHC_YAML_MAPPING, "configuration", err)) ||
        (rc = phc_yaml_check_keys(doc, root, top_keys, "the configuration", err)))
        goto fail;
    const char *name = NULL;
    if ((rc = phc_yaml_map_string(doc, root, "name", 0, "configuration", &name, err)))
        goto fail;
    if (name && (rc = check_run_name(doc, root, name, err)))
        goto fail;
    stem = stem_of(path);
    pb = phc_problem_new(name ? name : stem);
    dir_copy = strdup(path);
    if (!pb || !stem || !dir_copy || !(pb->source = strdup(path))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    const char *base_dir = dirname(dir_copy);

    const phc_yaml_node *params = phc_yaml_get(root, "parameters");
    if (!params) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: missing key 'parameters'", path, root->line);
        goto fail;
    }
    if ((rc = expect_kind(doc, params, PHC_YAML_MAPPING, "parameters", err)))
        goto fail;
    for (size_t i = 0; i < params->count; ++i)
        if ((rc = parse_parameter(doc, pb, params->keys[i], params->values[i], params->key_lines[i], err)))
            goto fail;

    const phc_yaml_node *solver = phc_yaml_get(root, "solver");
    if (solver && (rc = parse_solver(doc, solver, &pb->options, err)))
        goto fail;
    const phc_yaml_node *report = phc_yaml_get(root, "report");
    if (report && (rc = parse_report(doc, report, &pb->options, err)))
        goto fail;

    const phc_yaml_node *datasets = phc_yaml_get(root, "datasets");
    if (!datasets) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: missing key 'datasets'", path, root->line);
        goto fail;
    }
    if ((rc = expect_kind(doc, datasets, PHC_YAML_SEQUENCE, "datasets", err)))
        goto fail;
    if (datasets->count == 0) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: datasets: the list is empty", path, datasets->line);
        goto fail;
    }
    for (size_t i = 0; i < datasets->count; ++i)
        if ((rc = parse_dataset(doc, datasets->items[i], i, base_dir, pb, rows, err)))
            goto fail;
    const phc_yaml_node *groups = phc_yaml_get(root, "groups");
    if (groups && (rc = parse_groups(doc, groups, pb, err)))
        goto fail;
    const phc_yaml_node *named = phc_yaml_get(root, "outputs");
    if (named && (rc = parse_outputs(doc, named, pb, err)))
        goto fail;
    /* units converted, tolerances kept above the models' accuracy unless
     * the solver: block names them, the problem checked (problem.h) */
    unsigned keep = 0;
    if (solver) {
        keep |= phc_yaml_get(solver, "function_tolerance") ? PHC_KEEP_FUNCTION_TOLERANCE : 0;
        keep |= phc_yaml_get(solver, "gradient_tolerance") ? PHC_KEEP_GRADIENT_TOLERANCE : 0;
        keep |= phc_yaml_get(solver, "parameter_tolerance") ? PHC_KEEP_PARAMETER_TOLERANCE : 0;
    }
    if (collect_seeds(root, "", pb)) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if ((rc = phc_problem_finish(pb, keep, err)))
        goto fail;
    *out = pb;
    pb = NULL;
fail:
    phc_problem_free(pb);
    phc_yaml_free(doc);
    free(dir_copy);
    free(stem);
    return rc;
}

int phc_config_load(const char *path, phc_problem **out, phc_error *err)
{
    return load(path, NULL, out, err);
}

int phc_config_group_values(const char *path, const char *column, char ***values, size_t *n, phc_problem **whole,
                            phc_error *err)
{
    return phc_config_group_values_cached(path, column, NULL, values, n, whole, err);
}

int phc_config_group_values_cached(const char *path, const char *column, phc_config_table_cache *cache,
                                   char ***values, size_t *n, phc_problem **whole, phc_error *err)
{
    row_filter f = {column, NULL, NULL, 0, 0, cache};
    phc_problem *pb = NULL;
    *values = NULL;
    *n = 0;
    if (whole)
        *whole = NULL;
    int rc = load(path, &f, &pb, err);
    if (whole && !rc)
        *whole = pb;
    else
        phc_problem_free(pb);
    if (rc) {
        phc_config_group_values_free(f.values, f.n_values);
        return rc;
    }
    *values = f.values;
    *n = f.n_values;
    return PHC_OK;
}

void phc_config_group_values_free(char **values, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        free(values[i]);
    free(values);
}

int phc_config_load_group(const char *path, const char *column, const char *value, phc_problem **out,
                          phc_error *err)
{
    return phc_config_load_group_cached(path, column, value, NULL, out, err);
}

int phc_config_load_group_cached(const char *path, const char *column, const char *value,
                                 phc_config_table_cache *cache, phc_problem **out, phc_error *err)
{
    if (!column || !value)
        return phc_error_set(err, PHC_ERR_INVALID, "phc_config_load_group: invalid argument");
    row_filter f = {column, value, NULL, 0, 0, cache};
    return load(path, &f, out, err);
}
