/* `kind: weight_curve` in a config: its keys and their help, and the
 * translation of its mapping (and of the files it names: the weighings'
 * table, the plant graph) into phc_weight_curve_read_options
 * (fit/costs/weight_table.h) and phc_weight_curve_options
 * (fit/costs/weight_curve.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/config/kind.h"
#include "fit/config/kinds.h"
#include "fit/config/yaml_keys.h"
#include "fit/costs/source_file.h"
#include "fit/costs/weight_curve.h"
#include "fit/costs/weight_table.h"
#include "measurements/c_number.h"
#include "measurements/plant_io.h"
#include "measurements/table.h"
#include "measurements/units.h"
#include "model/plant_graph.h"

static const char *const weight_curve_keys[] = {
    "file", "time", "mass", "select", "plant", "plant_format", "plant_unit", "leaf_area",
    "chain_segments", "vein_radius", "dry_mass", "sigma", "exclude", "jumps", "jump_threshold",
    "tare", "max_gap", "day", "covariates", "pot", "conductance", "method", "step", "viscosity", "x_label", "y_label", NULL};
static const phc_key_help weight_curve_help[] = {
    {"file", "CSV table of weighings, in time order, relative to the config file. Required."},
    {"time", "{column: NAME, unit: UNIT} or a column name: the time of each weighing as a "
             "number; any UDUNITS-2 time unit (also \"seconds since 1970-01-01\" for POSIX "
             "times), default s. Or logger timestamps: {columns: [DATE, TIME], format: F, "
             "timezone: Z} (two columns joined by a space) or {column: STAMP, format: F, "
             "timezone: Z}; a `columns`, `format` or `timezone` key (without `unit`) makes the "
             "time a timestamp. F: a strptime format such as \"%d/%m/%Y %H:%M:%S\" (a fraction "
             "after %S is accepted), default ISO 8601 (2024-10-24T13:05:00, optional fraction, "
             "Z or +02:00). Z: the logger clock's IANA zone (Europe/Berlin) so daylight-saving "
             "steps are handled (a time in the repeated hour takes the instant that keeps the "
             "series in order); without it times are taken as written (UTC) and a step back is "
             "an error. With timestamps the time unit is h since the first weighing (exclude, "
             "step, max_gap). With a numeric absolute unit, timezone only sets the local "
             "clock. Required."},
    {"mass", "{column: NAME, unit: UNIT} or a column name: the masses, > 0; any mass unit, "
             "default g. Required."},
    {"select", "{COLUMN: VALUE, ...}: keep only the rows matching every pair (one plant of a "
               "long table; \"1\" matches \"1.0\"; a logger's stable readings: "
               "{Status: ST}). Default: every row."},
    {"plant", "A plant-graph file (paper, TreeQSM, SWC or native CSV), relative to the config "
              "file. Give exactly one of plant and leaf_area."},
    {"plant_format", "Format of the plant file: auto (by extension and content), paper, "
                     "treeqsm, swc or native. Default: auto."},
    {"plant_unit", "Length unit of the plant file (UDUNITS-2, e.g. mm). Default: the format's "
                   "(paper, TreeQSM: m; SWC: um; native: its `# unit:` line, else m)."},
    {"leaf_area", "A detached leaf instead of plant, modelled as a venation chain: its area, a "
                  "number or {value: A | column: NAME, unit: UNIT} (a column is read at the "
                  "first selected row); default unit cm2. Give exactly one of plant and "
                  "leaf_area."},
    {"chain_segments", "With leaf_area: segments of the venation chain, 2 to 100000. "
                       "Default: 20."},
    {"vein_radius", "With leaf_area: radius of the chain's segments, a number or {value | "
                    "column, unit}; default unit mm. Default: 0.5 mm."},
    {"dry_mass", "Measured dry mass, a number or {value | column, unit} (default: the mass "
                 "unit), below every mass: fixes the dry_mass slot. Default: dry_mass is a "
                 "fitted slot."},
    {"sigma", "Balance standard deviation, > 0: a number in the mass unit or the name of a "
              "column of per-point sigmas. Default: unweighted."},
    {"exclude", "[[from, to], ...], from < to: time windows to drop, in the time unit, counted "
                "from the first selected row. Default: none."},
    {"jumps", "What a rise of the mass above jump_threshold (an irrigation) does: error (stop "
              "and name the line), split (the curve restarts; piece k = 2, 3, ... gets its "
              "own slot initial_water_<k>) or keep. Default: error."},
    {"jump_threshold", "The rise between weighings that counts as a jump, > 0, in the mass "
                       "unit. Default: max(5 sigma, 0.5% of the largest mass)."},
    {"tare", "auto: drop the readings at the start of the selected rows that are below 50% of "
             "the median of the next 10 (the empty balance, a pot without its plant) and list "
             "them in the report; keep: use every row. Default: auto."},
    {"max_gap", "Longest expected pause between weighings, a number in the time unit or "
                "{value: V, unit: U}; longer gaps (logger off) are listed in the report. "
                "Default: 6 h, or 3 times the median step when weighings are sparser."},
    {"day", "{start: \"07:00\", end: \"23:00\", night_factor: F, clock: \"HH:MM\"}: a light "
            "schedule, local clock times, start before end; leaves lose night_factor times the "
            "day's rate by night (left out: a fitted slot night_factor). With logger timestamps "
            "the hours follow the time zone (daylight saving included); with a plain numeric time "
            "give clock, the local time of the first weighing. Default: one rate all day."},
    {"covariates", "{columns: [PAR, VPD, ...], law: linear}: the loss rate follows columns "
                   "read at every weighing, g = 1 + sum loss_<column> x column (one fitted slot "
                   "per column; each interval between weighings takes the mean of its two "
                   "readings; a reading missing is an error). Not with day. Default: none."},
    {"pot", "{capacity: C, conductance: k}: the pot's soil as a water store joined to the "
            "plant's root segment; C (g) is the soil water at which its pressure equals that "
            "of a full plant segment, k (g/s) the exchange per unit difference of relative "
            "fill; a key left out is a fitted slot (pot_capacity, pot_conductance); plant and "
            "soil start in equilibrium, sharing initial_water. Default: no pot."},
    {"conductance", "Edge weights of the water model: poiseuille, mean, paper, reference or "
                    "reference_2024 (model/water.h). Default: poiseuille."},
    {"method", "Evaluator: auto (exact up to 400 segments when not stiff, else BDF6), exact "
               "or bdf6. Default: auto."},
    {"step", "BDF6 time step in the time unit, >= 0; 0 = a thousandth of the time span. "
             "Default: 0."},
    {"viscosity", "Sap viscosity, mPa s, > 0, when no parameter named viscosity makes it a "
                  "fitted slot. Default: 0.89 (water at 25 °C); 0.9 with the reference "
                  "conductances."},
    {"x_label", "Axis label of time. Default: \"time since the first weighing (<time unit>)\"."},
    {"y_label", "Axis label of mass. Default: \"mass (g)\"."},
    {NULL, NULL}};


static const char *const ctx = "weight_curve data set";

/* What a translation holds while it runs. */
typedef struct wc_yaml {
    const phc_yaml_doc *doc;
    const phc_yaml_node *node;
    const char *base_dir;
    phc_origin origin;
    phc_weight_curve_read_options ro;
    phc_weight_curve_options o;
    const char *file, *munit;       /* the table's file, the mass unit */
    const char **select_cols, **select_vals, **covariates;
    double *exclude;
    phc_units *units;
    phc_table *table;
    char *path, *gpath;             /* the table and the plant graph as opened */
    phc_plant_graph *graph;
    phc_weighings w;
} wc_yaml;

/* ---- message places ---------------------------------------------------------- */

/* The line a message about `path` names, as the loader always has: the line
 * of the value at the dotted path ("time", "day.start", "exclude.1",
 * "covariates.columns.0"; an index into a mapping, "select.2", is the line of
 * that key), "select" the line of the key itself; where the path ends early,
 * the line of the last node found. */
static size_t path_line(const void *map, const char *path)
{
    const phc_yaml_node *node = map;
    size_t line = node->line;
    if (strcmp(path, "select") == 0)
        return phc_key_line(node, "select");
    while (*path) {
        char part[64];
        const size_t len = strcspn(path, ".");
        snprintf(part, sizeof part, "%.*s", (int)len, path);
        char *end = NULL;
        const unsigned long i = strtoul(part, &end, 10);
        const int index = end != part && !*end;
        const phc_yaml_node *next = NULL;
        if (node->kind == PHC_YAML_MAPPING && index && i < node->count) {
            next = node->values[i];
            line = node->key_lines[i];
        } else if (node->kind == PHC_YAML_MAPPING && (next = phc_yaml_get(node, part))) {
            line = next->line;
        } else if (node->kind == PHC_YAML_SEQUENCE && index && i < node->count) {
            next = node->items[i];
            line = next->line;
        }
        if (!next)
            return line;
        node = next;
        path += len + (path[len] == '.');
    }
    return line;
}

/* ---- values ------------------------------------------------------------------ */

/* A quantity given as a number, or {value: X | column: NAME, unit: UNIT};
 * a column is read at table row `row`.  Converted to `model_unit`. */
static int quantity(const wc_yaml *y, const phc_yaml_node *v, const char *key, const char *default_unit,
                    const char *model_unit, size_t row, double *out, phc_error *err)
{
    static const char *const q_keys[] = {"value", "column", "unit", NULL};
    const phc_yaml_doc *doc = y->doc;
    const phc_table *t = y->table;
    char ctx_key[64];
    const char *unit = default_unit, *column = NULL;
    double value = NAN;
    int rc;
    snprintf(ctx_key, sizeof ctx_key, "key '%s'", key);
    if (v->kind == PHC_YAML_SCALAR) {
        if ((rc = phc_yaml_number(doc, v, key, &value, err)))
            return rc;
    } else {
        if ((rc = phc_yaml_check_keys(doc, v, q_keys, ctx_key, err)) ||
            (rc = phc_yaml_map_number(doc, v, "value", 0, ctx_key, &value, err)) ||
            (rc = phc_yaml_map_string(doc, v, "column", 0, ctx_key, &column, err)) ||
            (rc = phc_yaml_map_string(doc, v, "unit", 0, ctx_key, &unit, err)))
            return rc;
        if ((column != NULL) == !isnan(value))
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key '%s': give either value or column",
                                 doc->path, v->line, key);
        if (column) {
            long c = phc_table_find(t, column);
            if (c < 0)
                return phc_unknown_column(doc, v->line, key, column, t, err);
            const char *cell = phc_table_cell(t, row, (size_t)c);
            char *end = NULL;
            value = phc_strtod_c(cell, &end);
            if (!end || end == cell || *end || !isfinite(value))
                return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': expected a number, found '%s'",
                                     phc_table_source(t), phc_table_row_line(t, row), column, cell);
        }
    }
    char where[4300];
    snprintf(where, sizeof where, "%s:%zu: %s unit", doc->path, v->line, key);
    phc_unit_conversion conv;
    if ((rc = phc_units_conversion(y->units, unit, model_unit, where, &conv, err)))
        return rc;
    *out = phc_unit_apply(conv, value);
    if (!(*out > 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key '%s': must be positive, found %g",
                             doc->path, v->line, key, value);
    return PHC_OK;
}

/* "HH:MM" or "HH:MM:SS" -> s since midnight, or -1. */
static double clock_seconds(const char *s)
{
    int h = -1, m = -1, sec = 0, used = 0;
    if (sscanf(s, "%2d:%2d%n", &h, &m, &used) != 2)
        return -1;
    if (s[used] == ':') {
        int more = 0;
        if (sscanf(s + used + 1, "%2d%n", &sec, &more) != 1)
            return -1;
        used += 1 + more;
    }
    if (s[used] || h < 0 || h > 24 || m < 0 || m > 59 || sec < 0 || sec > 59 || (h == 24 && (m || sec)))
        return -1;
    return h * 3600.0 + m * 60.0 + sec;
}

static int clock_key(const phc_yaml_doc *doc, const phc_yaml_node *map, const char *key, int required,
                     double *out, phc_error *err)
{
    const char *s = NULL;
    int rc = phc_yaml_map_string(doc, map, key, required, "key 'day'", &s, err);
    if (rc || !s)
        return rc;
    *out = clock_seconds(s);
    if (*out < 0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: day: %s '%s' is not a clock time; expected \"HH:MM\" (24 h)",
                             doc->path, phc_yaml_get(map, key)->line, key, s);
    return PHC_OK;
}

/* ---- the table's keys ----------------------------------------------------------- */

/* `time`: a numeric column ({column, unit} or a bare name), or logger
 * timestamps ({column: STAMP | columns: [DATE, TIME], format, timezone}); a
 * `columns` or `format` key, or `timezone` without `unit`, makes timestamps.
 * Their consistency (unit, zone) is checked by the reader. */
static int time_key(const wc_yaml *y, phc_weight_curve_read_options *ro, phc_error *err)
{
    static const char *const keys[] = {"column", "columns", "unit", "format", "timezone", NULL};
    const phc_yaml_doc *doc = y->doc;
    const phc_yaml_node *v = phc_yaml_get(y->node, "time"), *cols = phc_yaml_get(v, "columns");
    const char *tctx = "key 'time'";
    int rc;
    if (!v || v->kind != PHC_YAML_MAPPING || (!cols && !phc_yaml_get(v, "format") && !phc_yaml_get(v, "timezone")))
        return phc_column_spec(doc, y->node, "time", ctx, NULL, &ro->time_column, &ro->time_unit, err);
    if ((rc = phc_yaml_check_keys(doc, v, keys, tctx, err)) ||
        (rc = phc_yaml_map_string(doc, v, "column", !cols, tctx, &ro->time_column, err)) ||
        (rc = phc_yaml_map_string(doc, v, "unit", 0, tctx, &ro->time_unit, err)) ||
        (rc = phc_yaml_map_string(doc, v, "format", 0, tctx, &ro->time_format, err)) ||
        (rc = phc_yaml_map_string(doc, v, "timezone", 0, tctx, &ro->timezone, err)))
        return rc;
    ro->timestamps = cols || ro->time_format || !ro->time_unit;
    if (cols && (ro->time_column || cols->kind != PHC_YAML_SEQUENCE || cols->count < 1 || cols->count > 2 ||
                 cols->items[0]->kind != PHC_YAML_SCALAR || cols->items[cols->count - 1]->kind != PHC_YAML_SCALAR))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'time': give either column: STAMP or columns: [DATE, TIME] (one or two column names)",
                             doc->path, phc_key_line(v, "columns"));
    if (cols) {
        ro->time_column = cols->items[0]->scalar;
        ro->time_column_2 = cols->count > 1 ? cols->items[1]->scalar : NULL;
    }
    return PHC_OK;
}

/* `select: {COLUMN: VALUE, ...}`. */
static int select_key(wc_yaml *y, phc_error *err)
{
    const phc_yaml_node *sel = phc_yaml_get(y->node, "select");
    if (!sel)
        return PHC_OK;
    if (sel->kind != PHC_YAML_MAPPING)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'select': expected a mapping {COLUMN: VALUE}",
                             y->doc->path, sel->line);
    y->select_cols = malloc((sel->count ? sel->count : 1) * sizeof *y->select_cols);
    y->select_vals = malloc((sel->count ? sel->count : 1) * sizeof *y->select_vals);
    if (!y->select_cols || !y->select_vals)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < sel->count; ++i) {
        if (sel->values[i]->kind != PHC_YAML_SCALAR)
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: select '%s': expected a value",
                                 y->doc->path, sel->key_lines[i], sel->keys[i]);
        y->select_cols[i] = sel->keys[i];
        y->select_vals[i] = sel->values[i]->scalar;
    }
    y->ro.n_select = sel->count;
    y->ro.select_columns = y->select_cols;
    y->ro.select_values = y->select_vals;
    return PHC_OK;
}

/* `exclude: [[from, to], ...]`: a window that is not two numbers is passed
 * as [NAN, NAN], which the reader refuses at the window's line. */
static int exclude_key(wc_yaml *y, phc_error *err)
{
    const phc_yaml_node *excl = phc_yaml_get(y->node, "exclude");
    if (!excl)
        return PHC_OK;
    if (excl->kind != PHC_YAML_SEQUENCE)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'exclude': expected a list of [from, to] windows",
                             y->doc->path, excl->line);
    if (!(y->exclude = malloc((excl->count ? 2 * excl->count : 1) * sizeof *y->exclude)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t e = 0; e < excl->count; ++e) {
        const phc_yaml_node *win = excl->items[e];
        phc_error ignore;
        double lo = NAN, hi = NAN;
        if (win->kind != PHC_YAML_SEQUENCE || win->count != 2 ||
            phc_yaml_number(y->doc, win->items[0], "exclude", &lo, &ignore) ||
            phc_yaml_number(y->doc, win->items[1], "exclude", &hi, &ignore))
            lo = hi = NAN;
        y->exclude[2 * e] = lo;
        y->exclude[2 * e + 1] = hi;
    }
    y->ro.n_exclude = excl->count;
    y->ro.exclude = y->exclude;
    return PHC_OK;
}

/* `covariates: {columns: [NAME, ...], law: linear}`. */
static int covariates_key(wc_yaml *y, phc_error *err)
{
    static const char *const keys[] = {"columns", "law", NULL};
    const phc_yaml_doc *doc = y->doc;
    const phc_yaml_node *cov = phc_yaml_get(y->node, "covariates");
    const char *law = "linear";
    int rc;
    if (!cov)
        return PHC_OK;
    if (phc_yaml_get(y->node, "day")) /* as phc_weight_curve_new would, before the columns are read */
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: give either 'day' (a light schedule) or 'covariates', not both",
                             doc->path, cov->line);
    if (cov->kind != PHC_YAML_MAPPING)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: key 'covariates': expected {columns: [NAME, ...], law: linear}",
                             doc->path, cov->line);
    if ((rc = phc_yaml_check_keys(doc, cov, keys, "key 'covariates'", err)) ||
        (rc = phc_yaml_map_string(doc, cov, "law", 0, "key 'covariates'", &law, err)))
        return rc;
    if (strcmp(law, "linear") != 0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: covariates: law '%s' is not known; the one law is linear "
                             "(g = 1 + sum of loss_<column> x column)",
                             doc->path, phc_yaml_get(cov, "law")->line, law);
    const phc_yaml_node *cols = phc_yaml_get(cov, "columns");
    if (!cols || cols->kind != PHC_YAML_SEQUENCE || cols->count == 0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: covariates: 'columns' must be a non-empty list of column names",
                             doc->path, cols ? cols->line : cov->line);
    if (!(y->covariates = malloc(cols->count * sizeof *y->covariates)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t j = 0; j < cols->count; ++j) {
        if (cols->items[j]->kind != PHC_YAML_SCALAR)
            return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: covariates: expected a column name",
                                 doc->path, cols->items[j]->line);
        y->covariates[j] = cols->items[j]->scalar;
    }
    y->ro.n_covariates = cols->count;
    y->ro.covariates = y->covariates;
    return PHC_OK;
}

/* The keys that say how to read the table: time, mass, select, tare,
 * exclude, covariates. */
static int table_keys(wc_yaml *y, phc_error *err)
{
    static const char *const tare_names[] = {"auto", "keep", NULL};
    int tare = 0, rc;
    if ((rc = phc_yaml_map_string(y->doc, y->node, "file", 1, ctx, &y->file, err)) ||
        (rc = time_key(y, &y->ro, err)) ||
        (rc = phc_column_spec(y->doc, y->node, "mass", ctx, "g", &y->ro.mass_column, &y->munit, err)) ||
        (rc = phc_yaml_map_string(y->doc, y->node, "x_label", 0, ctx, &y->o.x_label, err)) ||
        (rc = phc_yaml_map_string(y->doc, y->node, "y_label", 0, ctx, &y->o.y_label, err)) ||
        (rc = select_key(y, err)) ||
        (rc = phc_yaml_map_choice(y->doc, y->node, "tare", ctx, tare_names, &tare, err)) ||
        (rc = exclude_key(y, err)) || (rc = covariates_key(y, err)))
        return rc;
    y->ro.mass_unit = y->munit;
    y->ro.tare = tare ? PHC_WEIGHT_TARE_KEEP : PHC_WEIGHT_TARE_AUTO;
    return PHC_OK;
}

/* ---- the model's keys ------------------------------------------------------------ */

/* `day: {start: "07:00", end: "23:00", night_factor: F, clock: "HH:MM"}`. */
static int day_key(wc_yaml *y, phc_error *err)
{
    static const char *const keys[] = {"start", "end", "night_factor", "clock", NULL};
    const phc_yaml_doc *doc = y->doc;
    const phc_yaml_node *day = phc_yaml_get(y->node, "day");
    phc_weight_day *d = &y->o.day;
    int rc;
    if (!day)
        return PHC_OK;
    if (day->kind != PHC_YAML_MAPPING)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: key 'day': expected {start: \"HH:MM\", end: \"HH:MM\", "
                             "night_factor: F}", doc->path, day->line);
    d->on = 1;
    if ((rc = phc_yaml_check_keys(doc, day, keys, "key 'day'", err)) ||
        (rc = clock_key(doc, day, "start", 1, &d->start, err)) ||
        (rc = clock_key(doc, day, "end", 1, &d->end, err)) ||
        (rc = clock_key(doc, day, "clock", 0, &d->clock, err)) ||
        (rc = phc_yaml_map_number(doc, day, "night_factor", 0, "key 'day'", &d->night_factor, err)))
        return rc;
    return PHC_OK;
}

/* `pot: {capacity: C, conductance: k}` (either may be left out: fitted). */
static int pot_key(wc_yaml *y, phc_error *err)
{
    static const char *const keys[] = {"capacity", "conductance", NULL};
    const phc_yaml_doc *doc = y->doc;
    const phc_yaml_node *pot = phc_yaml_get(y->node, "pot");
    int rc;
    if (!pot)
        return PHC_OK;
    if (pot->kind != PHC_YAML_MAPPING)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: key 'pot': expected {capacity: GRAMS, conductance: G_PER_S} "
                             "(either may be left out to fit it)", doc->path, pot->line);
    y->o.pot.on = 1;
    if ((rc = phc_yaml_check_keys(doc, pot, keys, "key 'pot'", err)) ||
        (rc = phc_yaml_map_number(doc, pot, "capacity", 0, "key 'pot'", &y->o.pot.capacity, err)) ||
        (rc = phc_yaml_map_number(doc, pot, "conductance", 0, "key 'pot'", &y->o.pot.conductance, err)))
        return rc;
    return PHC_OK;
}

/* conductance, method, jumps, step (still in the time unit), jump_threshold,
 * viscosity, day, pot. */
static int model_keys(wc_yaml *y, phc_error *err)
{
    static const char *const cond_names[] = {"poiseuille", "mean", "paper", "reference",
                                             "reference_2024", NULL};
    static const char *const method_names[] = {"auto", "exact", "bdf6", NULL};
    static const char *const jump_names[] = {"error", "split", "keep", NULL};
    static const phc_water_weights cond_values[] = {PHC_WATER_POISEUILLE, PHC_WATER_MEAN_CONDUCTANCE,
                                                    PHC_WATER_PAPER, PHC_WATER_REFERENCE,
                                                    PHC_WATER_REFERENCE_2024};
    static const phc_water_method method_values[] = {PHC_WATER_AUTO, PHC_WATER_EXACT, PHC_WATER_BDF6};
    static const phc_weight_jumps jump_values[] = {PHC_WEIGHT_JUMPS_ERROR, PHC_WEIGHT_JUMPS_SPLIT,
                                                   PHC_WEIGHT_JUMPS_KEEP};
    int cond = 0, method = 0, jumps = 0, rc;
    if ((rc = phc_yaml_map_choice(y->doc, y->node, "conductance", ctx, cond_names, &cond, err)) ||
        (rc = phc_yaml_map_choice(y->doc, y->node, "method", ctx, method_names, &method, err)) ||
        (rc = phc_yaml_map_choice(y->doc, y->node, "jumps", ctx, jump_names, &jumps, err)) ||
        (rc = phc_yaml_map_number(y->doc, y->node, "step", 0, ctx, &y->o.step, err)) ||
        (rc = phc_yaml_map_number(y->doc, y->node, "jump_threshold", 0, ctx, &y->o.jump_threshold, err)) ||
        (rc = phc_yaml_map_number(y->doc, y->node, "viscosity", 0, ctx, &y->o.viscosity, err)) ||
        (rc = day_key(y, err)) || (rc = pot_key(y, err)))
        return rc;
    y->o.conductance = cond_values[cond];
    y->o.method = method_values[method];
    y->o.jumps = jump_values[jumps];
    return PHC_OK;
}

/* ---- the files ---------------------------------------------------------------------- */

/* The table named by `file`. */
static int read_table(wc_yaml *y, phc_error *err)
{
    int rc;
    if (!(y->path = phc_join_path(y->base_dir, y->file)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if ((rc = phc_kind_read_table(y->o.user_data, y->path, &y->table, err)) && rc == PHC_ERR_IO) /* which key named it */
        phc_error_prefix(err, rc, "%s:%zu: key 'file'", y->doc->path, phc_key_line(y->node, "file"));
    return rc;
}

/* `sigma` (a column of the table, else a number) and `max_gap` (a number in
 * the time unit, or a quantity whose column is read at the first selected
 * row). */
static int table_values(wc_yaml *y, phc_error *err)
{
    const phc_yaml_node *sig = phc_yaml_get(y->node, "sigma"), *mg = phc_yaml_get(y->node, "max_gap");
    int rc;
    if (sig && sig->kind == PHC_YAML_SCALAR && phc_table_find(y->table, sig->scalar) >= 0)
        y->ro.sigma_column = sig->scalar;
    else if (sig && (rc = phc_yaml_number(y->doc, sig, "sigma", &y->o.sigma, err)))
        return rc;
    if (mg && mg->kind == PHC_YAML_SCALAR)
        return phc_yaml_number(y->doc, mg, "max_gap", &y->ro.max_gap, err);
    if (mg) {
        size_t *rows = NULL, n = 0;
        if ((rc = phc_weight_curve_select_rows(y->table, &y->ro, &rows, &n, err)))
            return rc;
        rc = quantity(y, mg, "max_gap", "h", "s", rows[0], &y->ro.max_gap, err);
        free(rows);
        y->ro.max_gap_unit = "s";
        return rc;
    }
    return PHC_OK;
}

/* The plant: a graph file (`plant`, `plant_format`, `plant_unit`), or a
 * detached leaf's venation chain (`leaf_area`, `chain_segments`,
 * `vein_radius`), whose quantities may be read at the first weighing's row. */
static int plant_graph(wc_yaml *y, phc_error *err)
{
    const phc_yaml_doc *doc = y->doc;
    const phc_yaml_node *node = y->node, *plant = phc_yaml_get(node, "plant"), *area = phc_yaml_get(node, "leaf_area");
    int rc;
    if ((plant != NULL) == (area != NULL))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "%s:%zu: weight_curve data set: give either 'plant' (a plant-graph file) or 'leaf_area' (a detached leaf)",
                             doc->path, node->line);
    if (plant) {
        const char *pfile = NULL, *fmt_name = "auto", *punit = NULL;
        if ((rc = phc_yaml_string(doc, plant, "plant", &pfile, err)) ||
            (rc = phc_yaml_map_string(doc, node, "plant_format", 0, ctx, &fmt_name, err)) ||
            (rc = phc_yaml_map_string(doc, node, "plant_unit", 0, ctx, &punit, err)))
            return rc;
        int fmt = phc_plant_format_from_name(fmt_name);
        if (fmt < 0)
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "%s:%zu: key 'plant_format': '%s' is not one of auto, paper, treeqsm, swc, native",
                                 doc->path, phc_yaml_get(node, "plant_format")->line, fmt_name);
        double to_m = 0;
        if (punit) {
            phc_unit_conversion lc;
            char where[4300];
            snprintf(where, sizeof where, "%s:%zu: plant_unit", doc->path, phc_yaml_get(node, "plant_unit")->line);
            if ((rc = phc_units_conversion(y->units, punit, "m", where, &lc, err)))
                return rc;
            to_m = lc.scale;
        }
        if (!(y->gpath = phc_join_path(y->base_dir, pfile)))
            return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        if ((rc = phc_plant_io_read(y->gpath, (phc_plant_format)fmt, to_m, &y->graph, err))) {
            if (rc == PHC_ERR_IO) /* a file that cannot be read: which key named it */
                phc_error_prefix(err, rc, "%s:%zu: key 'plant'", doc->path, phc_key_line(node, "plant"));
            return rc;
        }
        y->o.plant_name = pfile;
        return PHC_OK;
    }
    double area_m2 = 0, radius_m = 0.5e-3;
    long segments = 20;
    const size_t row = y->w.rows[0];
    const phc_yaml_node *vr = phc_yaml_get(node, "vein_radius");
    if ((rc = quantity(y, area, "leaf_area", "cm2", "m2", row, &area_m2, err)) ||
        (rc = phc_yaml_map_integer(doc, node, "chain_segments", 0, ctx, &segments, err)) ||
        (vr && (rc = quantity(y, vr, "vein_radius", "mm", "m", row, &radius_m, err))))
        return rc;
    if (segments < 2 || segments > 100000)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'chain_segments': expected 2 to 100000, found %ld",
                             doc->path, phc_yaml_get(node, "chain_segments")->line, segments);
    if (!(y->graph = phc_plant_graph_leaf_chain(area_m2, (size_t)segments, radius_m)))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: cannot build a leaf of area %g m2 and vein radius %g m",
                             doc->path, area->line, area_m2, radius_m);
    return PHC_OK;
}

/* ---- the translation ------------------------------------------------------------------ */

static int weight_curve_yaml(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *base_dir,
                             phc_is_parameter_fn is_parameter, void *user_data, phc_dataset **out,
                             phc_error *err)
{
    wc_yaml y = {.doc = doc, .node = node, .base_dir = base_dir,
                 .origin = {.path = doc->path, .map = node, .key_line = path_line, .line = node->line},
                 .ro = phc_weight_curve_read_options_default(),
                 .o = phc_weight_curve_options_default()};
    const phc_yaml_node *dry = phc_yaml_get(node, "dry_mass");
    int rc;

    *out = NULL;
    y.ro.origin = y.o.origin = &y.origin;
    y.o.is_parameter = is_parameter;
    y.o.user_data = user_data;
    if ((rc = table_keys(&y, err)) || (rc = model_keys(&y, err)))
        goto done;
    if (!(y.units = phc_units_new(err))) {
        rc = err->status;
        goto done;
    }
    y.ro.units = y.units;
    if ((rc = read_table(&y, err)) || (rc = table_values(&y, err)) ||
        (rc = phc_weight_curve_read_table(y.table, &y.ro, &y.w, err)) ||
        (dry && (rc = quantity(&y, dry, "dry_mass", y.munit, "g", y.w.rows[0], &y.o.dry_mass, err))) ||
        (rc = plant_graph(&y, err)))
        goto done;
    y.o.step *= y.w.seconds_per_unit; /* the time unit -> s */
    if ((rc = phc_weight_curve_new(y.graph, &y.w, &y.o, out, err)))
        goto done;
    if (phc_dataset_add_input(*out, y.path) || (y.gpath && phc_dataset_add_input(*out, y.gpath))) {
        phc_dataset_free(*out);
        *out = NULL;
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
done:
    phc_weighings_release(&y.w);
    phc_plant_graph_free(y.graph);
    phc_table_free(y.table);
    phc_units_free(y.units);
    free(y.path);
    free(y.gpath);
    free(y.select_cols);
    free(y.select_vals);
    free(y.covariates);
    free(y.exclude);
    return rc;
}

const phc_kind phc_weight_curve_kind = {
    .config = {.name = "weight_curve",
               .summary = "a plant or detached leaf weighed on a balance while it dries -> "
                          "water-loss rate delta, initial water, dry mass (wilting §3-4)",
               .keys = weight_curve_keys,
               .help = weight_curve_help},
    .ops = &phc_weight_curve_ops,
    .load_yaml = weight_curve_yaml,
    .each = 1,
};
