/* `weight_curve` data sets: see weight_curve.h. */
#include "fit/costs/weight_curve.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/costs/source_file.h"
#include "fit/config/yaml_keys.h" /* until this kind is YAML-free */
#include "fit/costs/weight_drivers.h"
#include "fit/costs/unique_times.h"
#include "measurements/c_number.h"
#include "measurements/logger_time.h"
#include "measurements/plant_io.h"
#include "measurements/table.h"
#include "measurements/units.h"
#include "model/plant_graph.h"
#include "model/water.h"
#include "model/water_balance.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

const char *const phc_weight_curve_keys[] = {
    "file", "time", "mass", "select", "plant", "plant_format", "plant_unit", "leaf_area",
    "chain_segments", "vein_radius", "dry_mass", "sigma", "exclude", "jumps", "jump_threshold",
    "tare", "max_gap", "day", "covariates", "pot", "conductance", "method", "step", "viscosity", "x_label", "y_label", NULL};
const phc_key_help phc_weight_curve_help[] = {
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

/* A stretch of the curve between irrigations.  Piece 0 starts from the
 * `initial_water` slot, piece k > 0 from its own slot `initial_water_<k+1>`. */
typedef struct piece {
    size_t first, count;  /* residuals first .. first+count-1 */
    double start_x;       /* time of the piece's start, user time unit from the first row */
    int slot;             /* slot of the piece's initial water */
} piece;

enum { SLOT_DELTA, SLOT_DRY, SLOT_MU, N_SLOT_KINDS }; /* initial waters: per piece */

typedef struct wc_impl {
    phc_plant_graph *graph;
    phc_water_params params;   /* weights (conductance), edge options */
    phc_water_method method;
    double step;               /* BDF6 step, s (0 = the model's choice) */
    phc_water_system *sys;     /* built for sys_mu; rebuilt when μ changes */
    double sys_mu;
    double viscosity;          /* mPa·s when not a slot */
    double dry_measured;       /* g, or NAN */
    int slot[N_SLOT_KINDS];    /* slot index of each quantity, -1 when fixed */
    double *t_model;           /* n: s since the start of the residual's piece */
    double *t_unique;          /* m_unique sorted distinct values of t_model: the pieces
                                  share δ and μ, so one unit response serves them all */
    size_t m_unique;
    size_t *t_at;              /* n: index of t_model[i] in t_unique */
    size_t n_pieces;
    piece *pieces;
    double seconds_per_x;      /* the user's time unit in s */
    double t0_posix;           /* POSIX time (s) at x = 0, the first weighing kept; NAN when
                                  the time is a plain number (not timestamps or an absolute unit) */
    char *timezone;            /* IANA zone of the clock (malloc'd), NULL = UTC / as written */
    size_t tare_n, tare_line[2]; /* tare readings dropped, their first and last lines */
    double max_gap;            /* s */
    size_t n_gaps;             /* gaps longer than max_gap: their lengths (s) and the line */
    double *gap_s;             /*   of the weighing before each */
    size_t *gap_line;
    double *u, *du;            /* workspace: unit response and its derivatives
                                  (m_unique, or the largest piece, x (PHC_WB_COEF + coefs)) */
    phc_weight_drivers drv;    /* day and night, covariates, pot (weight_drivers.h) */
    int drv_slot;              /* slot of the drivers' first slot (-1: none) */
    size_t n_coef;             /* coefficients of g */
    double *t_abs;             /* n: s since the first weighing (time-varying loss) */
} wc_impl;

static void wc_free(void *p)
{
    wc_impl *w = p;
    if (!w)
        return;
    phc_plant_graph_free(w->graph);
    phc_water_system_free(w->sys);
    free(w->t_model);
    free(w->t_unique);
    free(w->t_at);
    free(w->pieces);
    free(w->u);
    free(w->du);
    free(w->timezone);
    phc_weight_drivers_free(&w->drv);
    free(w->t_abs);
    free(w->gap_s);
    free(w->gap_line);
    free(w);
}

static double slot_value(const wc_impl *w, const double *p, int kind, double fallback)
{
    return w->slot[kind] >= 0 ? p[w->slot[kind]] : fallback;
}

/* Builds the water system for viscosity mu (rebuilt only when mu changes;
 * delta is set in place, O(n)).  1 = outside the model's domain. */
static int water_system(wc_impl *w, double delta, double mu)
{
    phc_error err;
    phc_error_clear(&err);
    if (!w->sys || w->sys_mu != mu) {
        phc_water_system_free(w->sys);
        w->sys = NULL;
        phc_water_params p = w->params;
        p.viscosity = mu;
        p.loss_rate = delta;
        p.initial_water = 1.0;
        int rc = phc_water_system_new(w->graph, &p, &w->sys, &err);
        if (rc)
            return rc == PHC_ERR_NOMEM ? -1 : 1;
        w->sys_mu = mu;
    }
    if (phc_water_system_set_loss_rate(w->sys, delta, &err))
        return 1; /* a trial point outside the model's domain: reject the step */
    return 0;
}

/* The unit response u(t) = W(t)/W(0) of the water model (plant, and pot
 * when there is one) at m sorted times t (s) of a piece starting at t_start
 * (s since the first weighing), and, when du is given, du (m x (PHC_WB_COEF
 * + n_coef): d/dδ, d/dW0, d/dμ, d/dC, d/dk, d/dc_j; model/water_balance.h).
 * p: the slot values. */
static int unit_response(wc_impl *w, const double *p, double delta, double mu, double t_start,
                         const double *t, size_t m, double *u, double *du)
{
    int rc = water_system(w, delta, mu);
    if (rc)
        return rc;
    phc_error err;
    phc_error_clear(&err);
    if (!w->drv.pot && !phc_weight_drivers_time_varying(&w->drv)) {
        /* the plant alone with a constant loss: model/water.h (du m x 3) */
        rc = phc_water_system_total_curve(w->sys, w->method, w->step, t, m, u, du, &err);
        if (!rc && du) /* spread to the balance's columns, back to front */
            for (size_t i = m; i-- > 0;) {
                double d0 = du[3 * i], d1 = du[3 * i + 1], d2 = du[3 * i + 2];
                double *row = du + i * (PHC_WB_COEF + w->n_coef);
                for (size_t c = 0; c < PHC_WB_COEF + w->n_coef; ++c)
                    row[c] = 0;
                row[PHC_WB_DELTA] = d0;
                row[PHC_WB_W0] = d1;
                row[PHC_WB_MU] = d2;
            }
    } else {
        const phc_water_loss_pattern *loss;
        const phc_water_pot *pot;
        phc_water_loss_pattern loss_buf;
        phc_water_pot pot_buf;
        phc_weight_drivers_model(&w->drv, w->drv_slot >= 0 ? p + w->drv_slot : NULL, &loss,
                                 &loss_buf, &pot, &pot_buf);
        if (pot && !(pot->capacity > 0 && pot->conductance >= 0))
            return 1;
        for (size_t k = 0; loss && k < loss->n; ++k)
            if (!(loss->g[k] >= 0))
                return 1; /* a negative loss: outside the domain */
        rc = phc_water_balance_curve(w->sys, pot, loss, t_start, w->method, w->step, t, m, u, du, &err);
    }
    if (rc == PHC_ERR_NOMEM || rc == PHC_ERR_INTERNAL || rc == PHC_ERR_INVALID)
        return -1;
    return rc ? 1 : 0;
}

/* Fills a Jacobian row from the piece's unit response (start: the piece's
 * initial water; d: du row). */
static void jacobian_row(const wc_impl *w, const phc_dataset *ds, const piece *pc, double start,
                         double u, const double *d, double *row)
{
    for (size_t j = 0; j < ds->k; ++j)
        row[j] = 0;
    if (w->slot[SLOT_DELTA] >= 0)
        row[w->slot[SLOT_DELTA]] = start * d[PHC_WB_DELTA];
    if (w->slot[SLOT_MU] >= 0)
        row[w->slot[SLOT_MU]] = start * d[PHC_WB_MU];
    row[pc->slot] = u;
    if (w->slot[SLOT_DRY] >= 0)
        row[w->slot[SLOT_DRY]] = 1.0;
    if (w->drv_slot >= 0) {
        int s = w->drv_slot;
        for (size_t j = 0; j < w->n_coef; ++j)
            row[s++] = start * d[PHC_WB_COEF + j];
        if (w->drv.pot && isnan(w->drv.capacity))
            row[s++] = start * d[PHC_WB_CAPACITY];
        if (w->drv.pot && isnan(w->drv.conductance))
            row[s++] = start * d[PHC_WB_CONDUCTANCE];
    }
}

static int wc_predict(phc_dataset *ds, const double *p, double *yhat, double *jac)
{
    wc_impl *w = ds->impl;
    const double delta = slot_value(w, p, SLOT_DELTA, 0);
    const double dry = slot_value(w, p, SLOT_DRY, w->dry_measured);
    const double mu = slot_value(w, p, SLOT_MU, w->viscosity);
    const size_t nw = PHC_WB_COEF + w->n_coef;
    if (!(delta >= 0) || !(mu > 0) || !isfinite(dry))
        return 1;
    const int varying = phc_weight_drivers_time_varying(&w->drv);
    int rc = 0;
    if (!varying) /* the pieces share one response over the time since their start */
        rc = unit_response(w, p, delta, mu, 0, w->t_unique, w->m_unique, w->u, jac ? w->du : NULL);
    for (size_t k = 0; k < w->n_pieces && !rc; ++k) {
        const piece *pc = &w->pieces[k];
        const double start = p[pc->slot];
        if (varying) /* the loss depends on the clock: each piece from its own start */
            rc = unit_response(w, p, delta, mu, w->t_abs[pc->first], w->t_abs + pc->first, pc->count,
                               w->u, jac ? w->du : NULL);
        for (size_t r = pc->first; r < pc->first + pc->count && !rc; ++r) {
            const size_t i = varying ? r - pc->first : w->t_at[r];
            yhat[r] = dry + start * w->u[i];
            if (jac)
                jacobian_row(w, ds, pc, start, w->u[i], w->du + i * nw, jac + r * ds->k);
        }
    }
    return rc;
}

/* The fitted curve at arbitrary x (user time unit since the first row),
 * piece by piece; x must be sorted (the plot's grid is). */
static int wc_predict_at(phc_dataset *ds, const double *p, const double *x, size_t m, double *y)
{
    wc_impl *w = ds->impl;
    const double delta = slot_value(w, p, SLOT_DELTA, 0);
    const double dry = slot_value(w, p, SLOT_DRY, w->dry_measured);
    const double mu = slot_value(w, p, SLOT_MU, w->viscosity);
    double *t = malloc((m ? m : 1) * sizeof *t), *u = malloc((m ? m : 1) * sizeof *u);
    int rc = 0;
    if (!t || !u) {
        rc = -1;
        goto done;
    }
    for (size_t i = 0; i < m && !rc;) {
        size_t k = 0;
        while (k + 1 < w->n_pieces && w->pieces[k + 1].start_x <= x[i])
            ++k;
        const double end = k + 1 < w->n_pieces ? w->pieces[k + 1].start_x : INFINITY;
        size_t j = i;
        while (j < m && x[j] < end) {
            const double dt = (x[j] - w->pieces[k].start_x) * w->seconds_per_x;
            t[j - i] = dt > 0 ? dt : 0;
            ++j;
        }
        if (j == i) { /* before the first piece */
            y[i++] = NAN;
            continue;
        }
        const double t_start = w->pieces[k].start_x * w->seconds_per_x;
        if (phc_weight_drivers_time_varying(&w->drv))
            for (size_t q = i; q < j; ++q) /* the clock since the first weighing */
                t[q - i] += t_start;
        rc = unit_response(w, p, delta, mu, phc_weight_drivers_time_varying(&w->drv) ? t_start : 0,
                           t, j - i, u, NULL);
        const double start = p[w->pieces[k].slot];
        for (size_t q = i; q < j && !rc; ++q)
            y[q] = dry + start * u[q - i];
        i = j;
    }
done:
    free(t);
    free(u);
    return rc;
}

static int wc_report_section(phc_dataset *ds, const double *p, char **markdown, phc_error *err);

static const phc_dataset_ops weight_curve_ops = {"weight_curve", wc_predict, wc_predict_at,
                                                 wc_free, wc_report_section, NULL, NULL, NULL};

/* ---- loading ------------------------------------------------------------- */

/* A quantity given as a number, or {value: X | column: NAME, unit: UNIT};
 * a column is read at the first selected row.  Converted to `model_unit`. */
static int quantity(const phc_yaml_doc *doc, const phc_yaml_node *v, const char *key,
                    const char *default_unit, const char *model_unit, phc_units *units,
                    const phc_table *t, size_t row, double *out, phc_error *err)
{
    static const char *const q_keys[] = {"value", "column", "unit", NULL};
    char ctx[64];
    const char *unit = default_unit, *column = NULL;
    double value = NAN;
    int rc;
    snprintf(ctx, sizeof ctx, "key '%s'", key);
    if (v->kind == PHC_YAML_SCALAR) {
        if ((rc = phc_yaml_number(doc, v, key, &value, err)))
            return rc;
    } else {
        if ((rc = phc_yaml_check_keys(doc, v, q_keys, ctx, err)) ||
            (rc = phc_yaml_map_number(doc, v, "value", 0, ctx, &value, err)) ||
            (rc = phc_yaml_map_string(doc, v, "column", 0, ctx, &column, err)) ||
            (rc = phc_yaml_map_string(doc, v, "unit", 0, ctx, &unit, err)))
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
    char where[160];
    snprintf(where, sizeof where, "%s:%zu: %s unit", doc->path, v->line, key);
    phc_unit_conversion conv;
    if ((rc = phc_units_conversion(units, unit, model_unit, where, &conv, err)))
        return rc;
    *out = phc_unit_apply(conv, value);
    if (!(*out > 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key '%s': must be positive, found %g",
                             doc->path, v->line, key, value);
    return PHC_OK;
}

/* Does row r match every `select` pair?  Text equality, or numeric equality
 * when both sides are numbers ("1" matches "1.0"). */
static int row_selected(const phc_table *t, size_t r, const phc_yaml_node *sel, const long *cols)
{
    for (size_t i = 0; sel && i < sel->count; ++i) {
        const char *cell = phc_table_cell(t, r, (size_t)cols[i]);
        const char *want = sel->values[i]->scalar;
        if (strcmp(cell, want) == 0)
            continue;
        char *e1 = NULL, *e2 = NULL;
        double a = phc_strtod_c(cell, &e1), b = phc_strtod_c(want, &e2);
        if (e1 && e2 && e1 != cell && e2 != want && !*e1 && !*e2 && a == b)
            continue;
        return 0;
    }
    return 1;
}

static int parse_choice(const phc_yaml_doc *doc, const phc_yaml_node *node, const char *key,
                        const char *const *names, int *out, phc_error *err)
{
    const char *s = NULL;
    int rc;
    if ((rc = phc_yaml_map_string(doc, node, key, 0, "weight_curve data set", &s, err)) || !s)
        return rc;
    char list[160] = "";
    for (int i = 0; names[i]; ++i) {
        if (strcmp(names[i], s) == 0) {
            *out = i;
            return PHC_OK;
        }
        size_t used = strlen(list);
        snprintf(list + used, sizeof list - used, "%s%s", i ? ", " : "", names[i]);
    }
    return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key '%s': '%s' is not one of %s", doc->path,
                         phc_yaml_get(node, key)->line, key, s, list);
}

/* The `time` key: a numeric column ({column, unit} or a bare name), or logger
 * timestamps ({column: STAMP | columns: [DATE, TIME], format, timezone}); a
 * `columns` or `format` key, or `timezone` without `unit`, makes timestamps. */
typedef struct time_spec {
    const char *col[2], *unit, *format, *tz; /* col[1]: NULL or the second column */
    int stamp;
    size_t line;
} time_spec;

static int time_spec_read(const phc_yaml_doc *doc, const phc_yaml_node *node, time_spec *ts,
                          phc_error *err)
{
    static const char *const keys[] = {"column", "columns", "unit", "format", "timezone", NULL};
    const phc_yaml_node *v = phc_yaml_get(node, "time"), *cols = phc_yaml_get(v, "columns");
    const char *ctx = "key 'time'";
    int rc;
    memset(ts, 0, sizeof *ts);
    if (!v || v->kind != PHC_YAML_MAPPING || (!cols && !phc_yaml_get(v, "format") && !phc_yaml_get(v, "timezone")))
        return phc_column_spec(doc, node, "time", "weight_curve data set", "s", &ts->col[0], &ts->unit, err);
    ts->line = v->line;
    if ((rc = phc_yaml_check_keys(doc, v, keys, ctx, err)) ||
        (rc = phc_yaml_map_string(doc, v, "column", !cols, ctx, &ts->col[0], err)) ||
        (rc = phc_yaml_map_string(doc, v, "unit", 0, ctx, &ts->unit, err)) ||
        (rc = phc_yaml_map_string(doc, v, "format", 0, ctx, &ts->format, err)) ||
        (rc = phc_yaml_map_string(doc, v, "timezone", 0, ctx, &ts->tz, err)))
        return rc;
    ts->stamp = cols || ts->format || !ts->unit;
    if (cols && (ts->col[0] || cols->kind != PHC_YAML_SEQUENCE || cols->count < 1 || cols->count > 2 ||
                 cols->items[0]->kind != PHC_YAML_SCALAR || cols->items[cols->count - 1]->kind != PHC_YAML_SCALAR))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'time': give either column: STAMP or columns: [DATE, TIME] (one or two column names)",
                             doc->path, phc_key_line(v, "columns"));
    for (size_t i = 0; cols && i < cols->count; ++i)
        ts->col[i] = cols->items[i]->scalar;
    if (ts->stamp && ts->unit)
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'time': 'unit' is for numeric times; timestamps (format, columns) become hours since the first weighing",
                             doc->path, phc_key_line(v, "unit"));
    if ((rc = phc_time_zone_check(ts->tz, err)))
        return phc_error_prefix(err, rc, "%s:%zu: key 'timezone'", doc->path, phc_key_line(v, "timezone"));
    if (!ts->stamp && !strstr(ts->unit, "since"))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'timezone': needs timestamps (format or columns) or an absolute time unit such as \"seconds since 1970-01-01\"",
                             doc->path, phc_key_line(v, "timezone"));
    return PHC_OK;
}

/* The times of the selected rows: numbers in the time unit, or for
 * timestamps hours since the first selected row.  *origin is the POSIX time
 * at tv = 0 (NAN when unknown); w->timezone is set. */
static int time_values(const phc_yaml_doc *doc, const time_spec *ts, const phc_table *t,
                       const size_t *keep, size_t n, phc_units *units, wc_impl *w, double **tv,
                       double *origin, phc_error *err)
{
    int rc = PHC_OK;
    *origin = NAN;
    if (ts->tz && !(w->timezone = strdup(ts->tz)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    if (!ts->stamp) {
        phc_unit_conversion ac;
        phc_error ignore;
        if ((rc = phc_table_column_numbers_rows(t, ts->col[0], keep, n, tv, err))) {
            const char *found = err ? strstr(err->message, "found '") : NULL;
            if (found && strpbrk(found + 8, ":/")) /* a date or a clock time */
                snprintf(err->message + strlen(err->message), sizeof err->message - strlen(err->message),
                         "; for date and time text give time: {column: NAME, format: ..., timezone: ...}");
            return rc;
        }
        if (strstr(ts->unit, "since") && !phc_units_conversion(units, ts->unit, "seconds since 1970-01-01 00:00:00 UTC", "", &ac, &ignore))
            *origin = ac.offset;
        return PHC_OK;
    }
    long c[2] = {phc_table_find(t, ts->col[0]), ts->col[1] ? phc_table_find(t, ts->col[1]) : -1};
    if (ts->col[1] && c[1] < 0)
        return phc_unknown_column(doc, ts->line, "time column", ts->col[1], t, err);
    char what[160];
    if (ts->col[1])
        snprintf(what, sizeof what, "columns '%s' and '%s'", ts->col[0], ts->col[1]);
    else
        snprintf(what, sizeof what, "column '%s'", ts->col[0]);
    char **text = calloc(n ? n : 1, sizeof *text);
    size_t *lines = malloc((n ? n : 1) * sizeof *lines);
    *tv = malloc((n ? n : 1) * sizeof **tv);
    if (!text || !lines || !*tv)
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < n && !rc; ++i) {
        const char *a = phc_table_cell(t, keep[i], (size_t)c[0]);
        const char *b = ts->col[1] ? phc_table_cell(t, keep[i], (size_t)c[1]) : NULL;
        lines[i] = phc_table_row_line(t, keep[i]);
        if (!(text[i] = malloc(strlen(a) + (b ? strlen(b) + 2 : 1))))
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        else
            sprintf(text[i], b ? "%s %s" : "%s", a, b);
    }
    phc_logger_clock clock = {ts->format, ts->tz, phc_table_source(t), what};
    if (!rc && !(rc = phc_logger_times(&clock, (const char *const *)text, lines, n, *tv, err)) && n) {
        *origin = (*tv)[0];
        for (size_t i = n; i-- > 0;)
            (*tv)[i] = ((*tv)[i] - *origin) / 3600.0;
    }
    for (size_t i = 0; text && i < n; ++i)
        free(text[i]);
    free(text);
    free(lines);
    return rc;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* `tare` and `max_gap`: drops the tare readings at the start of the selected
 * rows (each below 50% of the median of the 10 readings after it; at least 2
 * rows stay) and lists the pauses longer than max_gap (default 6 h, or 3
 * median steps, so that daily weighings are not all gaps). */
static int tare_and_gaps(const phc_yaml_doc *doc, const phc_yaml_node *node, phc_units *units,
                         const phc_table *t, size_t *keep, double *tv, double *mv, size_t *n_sel,
                         wc_impl *w, phc_error *err)
{
    static const char *const tare_names[] = {"auto", "keep", NULL};
    int tare = 0, rc;
    const phc_yaml_node *mg = phc_yaml_get(node, "max_gap");
    w->max_gap = 6 * 3600.0;
    if ((rc = parse_choice(doc, node, "tare", tare_names, &tare, err)))
        return rc;
    if (mg && mg->kind == PHC_YAML_SCALAR) {
        if ((rc = phc_yaml_number(doc, mg, "max_gap", &w->max_gap, err)))
            return rc;
        w->max_gap *= w->seconds_per_x;
    } else if (mg && (rc = quantity(doc, mg, "max_gap", "h", "s", units, t, keep[0], &w->max_gap, err))) {
        return rc;
    }
    if (!(w->max_gap > 0))
        return phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'max_gap': must be positive", doc->path, mg->line);
    size_t k = 0, n = *n_sel;
    while (tare == 0 && k + 2 < n) {
        double next[10];
        size_t m = 0;
        for (size_t j = k + 1; j < n && m < 10; ++j)
            next[m++] = mv[j];
        qsort(next, m, sizeof *next, cmp_double);
        const double median = m % 2 ? next[m / 2] : 0.5 * (next[m / 2 - 1] + next[m / 2]);
        if (!(mv[k] < 0.5 * median))
            break;
        ++k;
    }
    if (k > 0) {
        w->tare_n = k;
        w->tare_line[0] = phc_table_row_line(t, keep[0]);
        w->tare_line[1] = phc_table_row_line(t, keep[k - 1]);
        memmove(keep, keep + k, (n - k) * sizeof *keep);
        memmove(tv, tv + k, (n - k) * sizeof *tv);
        memmove(mv, mv + k, (n - k) * sizeof *mv);
        *n_sel = n -= k;
    }
    double *step = mg || n < 2 ? NULL : malloc((n - 1) * sizeof *step);
    if (step) { /* default: 6 h, or 3 times the median step of sparse weighings */
        for (size_t i = 1; i < n; ++i)
            step[i - 1] = tv[i] - tv[i - 1];
        qsort(step, n - 1, sizeof *step, cmp_double);
        w->max_gap = fmax(w->max_gap, 3 * step[(n - 1) / 2] * w->seconds_per_x);
        free(step);
    }
    for (size_t i = 1; i < n; ++i)
        if ((tv[i] - tv[i - 1]) * w->seconds_per_x > w->max_gap) {
            double *g = realloc(w->gap_s, (w->n_gaps + 1) * sizeof *g);
            size_t *l = g ? realloc(w->gap_line, (w->n_gaps + 1) * sizeof *l) : NULL;
            if (g)
                w->gap_s = g;
            if (!l)
                return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            w->gap_line = l;
            w->gap_s[w->n_gaps] = (tv[i] - tv[i - 1]) * w->seconds_per_x;
            w->gap_line[w->n_gaps++] = phc_table_row_line(t, keep[i - 1]);
        }
    return PHC_OK;
}

/* The report rows of a logger file: the clock, tare readings, long gaps. */
static void logger_rows(const wc_impl *w, char *buf, size_t size)
{
    size_t used = strlen(buf);
    char iso[64];
    if (!isnan(w->t0_posix) && used < size && !phc_local_iso(w->timezone, w->t0_posix, iso, sizeof iso, NULL))
        used += snprintf(buf + used, size - used, "| clock | %s; time 0 (the first weighing kept) is %s |\n",
                         w->timezone ? w->timezone : "UTC (times as written)", iso);
    if (w->tare_n == 1 && used < size)
        used += snprintf(buf + used, size - used, "| tare readings dropped | 1 (line %zu) |\n", w->tare_line[0]);
    else if (w->tare_n > 1 && used < size)
        used += snprintf(buf + used, size - used, "| tare readings dropped | %zu (lines %zu–%zu) |\n",
                         w->tare_n, w->tare_line[0], w->tare_line[1]);
    if (w->n_gaps && used < size) {
        used += snprintf(buf + used, size - used, "| logger gaps longer than %g h | %zu:", w->max_gap / 3600,
                         w->n_gaps);
        for (size_t i = 0; i < w->n_gaps && i < 10 && used < size; ++i)
            used += snprintf(buf + used, size - used, "%s %.1f h after line %zu", i ? "," : "",
                             w->gap_s[i] / 3600, w->gap_line[i]);
        if (used < size)
            snprintf(buf + used, size - used, "%s |\n", w->n_gaps > 10 ? ", ..." : "");
    }
}

/* x_seconds, t0_posix and the local clock of every weighing kept. */
static int set_clock(phc_dataset *ds, wc_impl *w, double origin, double first, phc_error *err)
{
    ds->x_seconds = w->seconds_per_x;
    w->t0_posix = origin + first * w->seconds_per_x;
    if (isnan(w->t0_posix))
        return PHC_OK;
    if (!(ds->time_of_day = malloc(ds->n * sizeof *ds->time_of_day)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < ds->n; ++i)
        ds->time_of_day[i] = w->t0_posix + ds->x[i] * w->seconds_per_x;
    int rc = phc_local_clocks(w->timezone, ds->time_of_day, ds->n, ds->time_of_day, err);
    for (size_t i = 0; i < ds->n && !rc; ++i)
        ds->time_of_day[i] /= 3600.0;
    return rc;
}

enum { JUMPS_ERROR, JUMPS_SPLIT, JUMPS_KEEP };

int phc_weight_curve_load(const phc_yaml_doc *doc, const phc_yaml_node *node,
                          const char *base_dir, phc_is_parameter_fn is_parameter,
                          void *user_data, phc_dataset **out, phc_error *err)
{
    const char *ctx = "weight_curve data set";
    const char *file = NULL, *tcol = NULL, *tunit = NULL, *mcol = NULL, *munit = NULL;
    const char *x_label = NULL, *y_label = NULL;
    phc_units *units = NULL;
    phc_table *table = NULL;
    phc_dataset *ds = NULL;
    wc_impl *w = NULL;
    char *path = NULL, *gpath = NULL; /* the data file; the plant-graph file (or NULL) */
    double *tv = NULL, *mv = NULL, *sv = NULL;
    size_t *keep = NULL;
    long *sel_cols = NULL;
    int rc;
    time_spec ts;
    double t_origin = NAN; /* POSIX time at tv = 0, NAN when unknown */

    *out = NULL;
    if ((rc = phc_yaml_map_string(doc, node, "file", 1, ctx, &file, err)) ||
        (rc = time_spec_read(doc, node, &ts, err)) ||
        (rc = phc_column_spec(doc, node, "mass", "weight_curve data set", "g", &mcol, &munit, err)) ||
        (rc = phc_yaml_map_string(doc, node, "x_label", 0, ctx, &x_label, err)) ||
        (rc = phc_yaml_map_string(doc, node, "y_label", 0, ctx, &y_label, err)))
        return rc;
    tcol = ts.col[0];
    tunit = ts.stamp ? "h" : ts.unit; /* timestamps: hours since the first weighing */
    if (!(units = phc_units_new(err)))
        return err->status;
    w = calloc(1, sizeof *w);
    if (!w) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    w->params = phc_water_params_default();
    w->method = PHC_WATER_AUTO;
    w->viscosity = 0.89; /* mPa·s, water at 25 °C (model/water.h) */
    w->dry_measured = NAN;

    /* Units: time to s, mass to g. */
    phc_unit_conversion tconv, mconv;
    char where[160];
    snprintf(where, sizeof where, "%s:%zu: time unit", doc->path, phc_yaml_get(node, "time")->line);
    if ((rc = phc_units_conversion(units, tunit, "s", where, &tconv, err)))
        goto fail;
    snprintf(where, sizeof where, "%s:%zu: mass unit", doc->path, phc_yaml_get(node, "mass")->line);
    if ((rc = phc_units_conversion(units, munit, "g", where, &mconv, err)))
        goto fail;
    w->seconds_per_x = tconv.scale;

    if (!(path = phc_join_path(base_dir, file))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if ((rc = phc_table_read(path, &table, err))) {
        if (rc == PHC_ERR_IO) /* a file that cannot be read: which key named it */
            phc_error_prefix(err, rc, "%s:%zu: key 'file'", doc->path, phc_key_line(node, "file"));
        goto fail;
    }
    const size_t rows = phc_table_rows(table);
    if (phc_table_find(table, tcol) < 0) {
        rc = phc_unknown_column(doc, phc_yaml_get(node, "time")->line, "time column", tcol, table, err);
        goto fail;
    }
    if (phc_table_find(table, mcol) < 0) {
        rc = phc_unknown_column(doc, phc_yaml_get(node, "mass")->line, "mass column", mcol, table, err);
        goto fail;
    }

    /* Rows of this plant. */
    const phc_yaml_node *sel = phc_yaml_get(node, "select");
    if (sel) {
        if (sel->kind != PHC_YAML_MAPPING) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'select': expected a mapping {COLUMN: VALUE}",
                               doc->path, sel->line);
            goto fail;
        }
        sel_cols = malloc((sel->count ? sel->count : 1) * sizeof *sel_cols);
        if (!sel_cols) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        for (size_t i = 0; i < sel->count; ++i) {
            sel_cols[i] = phc_table_find(table, sel->keys[i]);
            if (sel_cols[i] < 0) {
                rc = phc_unknown_column(doc, sel->key_lines[i], "select column", sel->keys[i], table, err);
                goto fail;
            }
            if (sel->values[i]->kind != PHC_YAML_SCALAR) {
                rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: select '%s': expected a value",
                                   doc->path, sel->key_lines[i], sel->keys[i]);
                goto fail;
            }
        }
    }
    keep = malloc((rows ? rows : 1) * sizeof *keep);
    if (!keep) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    size_t n_sel = 0;
    for (size_t r = 0; r < rows; ++r)
        if (row_selected(table, r, sel, sel_cols))
            keep[n_sel++] = r;
    if (n_sel == 0) {
        rc = sel ? phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'select': no row of %s matches", doc->path,
                                 phc_key_line(node, "select"), path)
                 : phc_error_set(err, PHC_ERR_INPUT, "%s:1: no data rows below the header; expected at least one",
                                 path);
        goto fail;
    }
    if ((rc = time_values(doc, &ts, table, keep, n_sel, units, w, &tv, &t_origin, err)) ||
        (rc = phc_table_column_numbers_rows(table, mcol, keep, n_sel, &mv, err)) ||
        (rc = tare_and_gaps(doc, node, units, table, keep, tv, mv, &n_sel, w, err)))
        goto fail;
    for (size_t i = 0; i < n_sel; ++i) {
        if (i > 0 && !(tv[i] > tv[i - 1])) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: column '%s': time %g is not after the previous weighing's %g (line %zu); weighings must be in time order",
                               path, phc_table_row_line(table, keep[i]), tcol, tv[i], tv[i - 1],
                               phc_table_row_line(table, keep[i - 1]));
            goto fail;
        }
        if (!(mv[i] > 0)) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': a mass must be positive, found %g",
                               path, phc_table_row_line(table, keep[i]), mcol, mv[i]);
            goto fail;
        }
    }

    /* Per-point sigma (mass unit -> g). */
    const phc_yaml_node *sig = phc_yaml_get(node, "sigma");
    double sigma_scalar = NAN;
    if (sig) {
        if (sig->kind == PHC_YAML_SCALAR && phc_table_find(table, sig->scalar) >= 0) {
            if ((rc = phc_table_column_numbers_rows(table, sig->scalar, keep, n_sel, &sv, err)))
                goto fail;
            for (size_t i = 0; i < n_sel; ++i)
                if (!(sv[i] > 0)) {
                    rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: column '%s': sigma must be positive, found %g",
                                       path, phc_table_row_line(table, keep[i]), sig->scalar, sv[i]);
                    goto fail;
                }
        } else {
            if ((rc = phc_yaml_number(doc, sig, "sigma", &sigma_scalar, err)))
                goto fail;
            if (!(sigma_scalar > 0)) {
                rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'sigma': must be positive, found %g",
                                   doc->path, sig->line, sigma_scalar);
                goto fail;
            }
        }
    }

    /* Measured dry mass: fixes the slot and bounds the masses. */
    const phc_yaml_node *dry = phc_yaml_get(node, "dry_mass");
    if (dry) {
        if ((rc = quantity(doc, dry, "dry_mass", munit, "g", units, table, keep[0], &w->dry_measured, err)))
            goto fail;
        for (size_t i = 0; i < n_sel; ++i)
            if (phc_unit_apply(mconv, mv[i]) < w->dry_measured) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: column '%s': mass %g is below the measured dry mass %g %s",
                                   path, phc_table_row_line(table, keep[i]), mcol, mv[i],
                                   (w->dry_measured - mconv.offset) / mconv.scale, munit);
                goto fail;
            }
    }

    /* The plant: a graph file or a leaf's venation chain. */
    const phc_yaml_node *plant = phc_yaml_get(node, "plant");
    const phc_yaml_node *area = phc_yaml_get(node, "leaf_area");
    if ((plant != NULL) == (area != NULL)) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s:%zu: weight_curve data set: give either 'plant' (a plant-graph file) or 'leaf_area' (a detached leaf)",
                           doc->path, node->line);
        goto fail;
    }
    if (plant) {
        const char *pfile = NULL, *fmt_name = "auto", *punit = NULL;
        if ((rc = phc_yaml_string(doc, plant, "plant", &pfile, err)) ||
            (rc = phc_yaml_map_string(doc, node, "plant_format", 0, ctx, &fmt_name, err)) ||
            (rc = phc_yaml_map_string(doc, node, "plant_unit", 0, ctx, &punit, err)))
            goto fail;
        int fmt = phc_plant_format_from_name(fmt_name);
        if (fmt < 0) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: key 'plant_format': '%s' is not one of auto, paper, treeqsm, swc, native",
                               doc->path, phc_yaml_get(node, "plant_format")->line, fmt_name);
            goto fail;
        }
        double to_m = 0;
        if (punit) {
            phc_unit_conversion lc;
            snprintf(where, sizeof where, "%s:%zu: plant_unit", doc->path, phc_yaml_get(node, "plant_unit")->line);
            if ((rc = phc_units_conversion(units, punit, "m", where, &lc, err)))
                goto fail;
            to_m = lc.scale;
        }
        if (!(gpath = phc_join_path(base_dir, pfile))) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }
        if ((rc = phc_plant_io_read(gpath, (phc_plant_format)fmt, to_m, &w->graph, err))) {
            if (rc == PHC_ERR_IO) /* a file that cannot be read: which key named it */
                phc_error_prefix(err, rc, "%s:%zu: key 'plant'", doc->path, phc_key_line(node, "plant"));
            goto fail;
        }
        if (phc_plant_graph_leaf_count(w->graph) == 0) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: plant '%s' has no leaf segments, so it cannot lose water",
                               doc->path, plant->line, pfile);
            goto fail;
        }
    } else {
        double area_m2 = 0, radius_m = 0.5e-3;
        long segments = 20;
        if ((rc = quantity(doc, area, "leaf_area", "cm2", "m2", units, table, keep[0], &area_m2, err)) ||
            (rc = phc_yaml_map_integer(doc, node, "chain_segments", 0, ctx, &segments, err)))
            goto fail;
        const phc_yaml_node *vr = phc_yaml_get(node, "vein_radius");
        if (vr && (rc = quantity(doc, vr, "vein_radius", "mm", "m", units, table, keep[0], &radius_m, err)))
            goto fail;
        if (segments < 2 || segments > 100000) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'chain_segments': expected 2 to 100000, found %ld",
                               doc->path, phc_yaml_get(node, "chain_segments")->line, segments);
            goto fail;
        }
        w->graph = phc_plant_graph_leaf_chain(area_m2, (size_t)segments, radius_m);
        if (!w->graph) {
            rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: cannot build a leaf of area %g m2 and vein radius %g m",
                               doc->path, area->line, area_m2, radius_m);
            goto fail;
        }
    }

    /* Model options. */
    static const char *const cond_names[] = {"poiseuille", "mean", "paper", "reference",
                                             "reference_2024", NULL};
    static const char *const method_names[] = {"auto", "exact", "bdf6", NULL};
    static const char *const jump_names[] = {"error", "split", "keep", NULL};
    int cond = 0, method = 0, jumps = JUMPS_ERROR;
    double step = 0, jump_threshold = NAN;
    if ((rc = parse_choice(doc, node, "conductance", cond_names, &cond, err)) ||
        (rc = parse_choice(doc, node, "method", method_names, &method, err)) ||
        (rc = parse_choice(doc, node, "jumps", jump_names, &jumps, err)) ||
        (rc = phc_yaml_map_number(doc, node, "step", 0, ctx, &step, err)) ||
        (rc = phc_yaml_map_number(doc, node, "jump_threshold", 0, ctx, &jump_threshold, err)) ||
        (rc = phc_yaml_map_number(doc, node, "viscosity", 0, ctx, &w->viscosity, err)))
        goto fail;
    static const phc_water_weights cond_values[] = {PHC_WATER_POISEUILLE, PHC_WATER_MEAN_CONDUCTANCE,
                                                    PHC_WATER_PAPER, PHC_WATER_REFERENCE,
                                                    PHC_WATER_REFERENCE_2024};
    static const phc_water_method method_values[] = {PHC_WATER_AUTO, PHC_WATER_EXACT, PHC_WATER_BDF6};
    w->params.weights = cond_values[cond];
    w->method = method_values[method];
    if (!phc_yaml_get(node, "viscosity") && cond >= 3)
        w->viscosity = 0.9; /* the authors' code */
    if (step < 0 || !(w->viscosity > 0) || (!isnan(jump_threshold) && !(jump_threshold > 0))) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: weight_curve data set: step must be >= 0, viscosity and jump_threshold positive",
                           doc->path, node->line);
        goto fail;
    }
    w->step = step * tconv.scale;

    /* Exclusion windows, then irrigation jumps, over the selected rows. */
    const phc_yaml_node *excl = phc_yaml_get(node, "exclude");
    if (excl && excl->kind != PHC_YAML_SEQUENCE) {
        rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: key 'exclude': expected a list of [from, to] windows",
                           doc->path, excl->line);
        goto fail;
    }
    size_t n_kept = 0;
    const double t_first = tv[0]; /* the loop below overwrites tv[0] once a row is dropped */
    for (size_t i = 0; i < n_sel; ++i) {
        const double rel = tv[i] - t_first;
        int drop = 0;
        for (size_t e = 0; excl && e < excl->count && !drop; ++e) {
            const phc_yaml_node *win = excl->items[e];
            double lo, hi;
            if (win->kind != PHC_YAML_SEQUENCE || win->count != 2 ||
                phc_yaml_number(doc, win->items[0], "exclude", &lo, err) ||
                phc_yaml_number(doc, win->items[1], "exclude", &hi, err) || !(lo < hi)) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: key 'exclude': each window is [from, to] with from < to (time unit, from the first row)",
                                   doc->path, win->line);
                goto fail;
            }
            drop = rel >= lo && rel <= hi;
        }
        if (drop)
            continue;
        tv[n_kept] = tv[i];
        mv[n_kept] = phc_unit_apply(mconv, mv[i]);
        if (sv)
            sv[n_kept] = sv[i] * mconv.scale;
        keep[n_kept++] = keep[i];
    }
    if (n_kept < 2) {
        rc = phc_error_set(err, PHC_ERR_INPUT,
                           "%s: %zu weighing%s left after select and exclude; a weight curve needs at least 2",
                           path, n_kept, n_kept == 1 ? "" : "s");
        goto fail;
    }
    if (isnan(jump_threshold)) {
        double mmax = 0;
        for (size_t i = 0; i < n_kept; ++i)
            mmax = fmax(mmax, mv[i]);
        jump_threshold = fmax(isnan(sigma_scalar) ? 0 : 5 * sigma_scalar * mconv.scale, 0.005 * mmax);
    } else {
        jump_threshold *= mconv.scale;
    }

    /* Pieces: an irrigation (a rise above the threshold) starts a new one. */
    size_t n_pieces = 1;
    for (size_t i = 1; i < n_kept; ++i)
        if (mv[i] - mv[i - 1] > jump_threshold) {
            if (jumps == JUMPS_ERROR) {
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: the mass rises by %g g since line %zu (an irrigation?); set `jumps: split` or `exclude` the window",
                                   path, phc_table_row_line(table, keep[i]), mv[i] - mv[i - 1],
                                   phc_table_row_line(table, keep[i - 1]));
                goto fail;
            }
            if (jumps == JUMPS_SPLIT)
                ++n_pieces;
        }

    /* Day and night, covariates, a pot (weight_drivers.h), over the kept
     * weighings' times since the first (s). */
    w->t_abs = malloc(n_kept * sizeof *w->t_abs);
    if (!w->t_abs) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    for (size_t i = 0; i < n_kept; ++i)
        w->t_abs[i] = (tv[i] - tv[0]) * w->seconds_per_x;
    if ((rc = phc_weight_drivers_load(doc, node, table, keep, w->t_abs, n_kept,
                                      t_origin + tv[0] * w->seconds_per_x, w->timezone, &w->drv, err)))
        goto fail;
    w->n_coef = phc_weight_drivers_coef_count(&w->drv);
    const size_t n_drv = phc_weight_drivers_slot_count(&w->drv);

    /* Slots: delta, one initial water per piece (initial_water, then
     * initial_water_2, ...), dry_mass unless measured, viscosity when the
     * user made it a parameter, then the drivers' (night_factor, loss_<col>,
     * pot_capacity, pot_conductance). */
    const size_t k_slots =
        1 + n_pieces + isnan(w->dry_measured) + is_parameter("viscosity", user_data) + n_drv;
    for (int q = 0; q < N_SLOT_KINDS; ++q)
        w->slot[q] = -1;
    w->pieces = calloc(n_pieces, sizeof *w->pieces);
    ds = phc_dataset_new(&weight_curve_ops, k_slots);
    if (!w->pieces || !ds) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    size_t js = 0;
    char slot_name[48];
    w->slot[SLOT_DELTA] = (int)js;
    ds->slot_names[js++] = strdup("delta");
    for (size_t q = 0; q < n_pieces; ++q) {
        if (q == 0)
            snprintf(slot_name, sizeof slot_name, "initial_water");
        else
            snprintf(slot_name, sizeof slot_name, "initial_water_%zu", q + 1);
        w->pieces[q].slot = (int)js;
        ds->slot_names[js++] = strdup(slot_name);
    }
    if (isnan(w->dry_measured)) {
        w->slot[SLOT_DRY] = (int)js;
        ds->slot_names[js++] = strdup("dry_mass");
    }
    if (js + n_drv < k_slots) {
        w->slot[SLOT_MU] = (int)js;
        ds->slot_names[js++] = strdup("viscosity");
    }
    w->drv_slot = n_drv ? (int)js : -1;
    if (n_drv && phc_weight_drivers_slot_names(&w->drv, ds->slot_names + js)) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    js += n_drv;
    for (size_t j = 0; j < k_slots; ++j)
        if (!ds->slot_names[j]) {
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
            goto fail;
        }

    const size_t n = n_kept;
    w->t_model = malloc(n * sizeof *w->t_model);
    ds->n = n;
    ds->x = malloc(n * sizeof *ds->x);
    ds->y = malloc(n * sizeof *ds->y);
    ds->sigma = (sv || !isnan(sigma_scalar)) ? malloc(n * sizeof *ds->sigma) : NULL;
    ds->data_lines = malloc(n * sizeof *ds->data_lines);
    ds->data_file = strdup(path);
    if (!w->t_model || !ds->x || !ds->y || !ds->data_lines || !ds->data_file ||
        ((sv || !isnan(sigma_scalar)) && !ds->sigma) || phc_dataset_add_input(ds, path) ||
        (gpath && phc_dataset_add_input(ds, gpath))) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    size_t k = 0;
    double piece_t0 = tv[0];
    w->pieces[0].start_x = 0;
    for (size_t i = 0; i < n_kept; ++i) {
        if (i > 0 && jumps == JUMPS_SPLIT && mv[i] - mv[i - 1] > jump_threshold) {
            w->pieces[k].count = i - w->pieces[k].first;
            ++k;
            w->pieces[k].first = i;
            w->pieces[k].start_x = tv[i] - tv[0];
            piece_t0 = tv[i];
        }
        ds->x[i] = tv[i] - tv[0];
        ds->y[i] = mv[i];
        w->t_model[i] = (tv[i] - piece_t0) * tconv.scale;
        if (ds->sigma)
            ds->sigma[i] = sv ? sv[i] : sigma_scalar * mconv.scale;
        ds->data_lines[i] = phc_table_row_line(table, keep[i]);
    }
    w->pieces[k].count = n_kept - w->pieces[k].first;
    w->n_pieces = n_pieces;
    if ((rc = phc_unique_times(w->t_model, n, &w->t_unique, &w->m_unique, &w->t_at, err)))
        goto fail;
    {
        const size_t rows = w->m_unique > n ? w->m_unique : n;
        w->u = malloc(rows * sizeof *w->u);
        w->du = malloc(rows * (PHC_WB_COEF + w->n_coef) * sizeof *w->du);
    }
    if ((rc = set_clock(ds, w, t_origin, tv[0], err)))
        goto fail;
    if (!w->u || !w->du) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }

    ds->derivatives = PHC_DERIV_ANALYTIC;
    /* BDF6 with its extrapolated start reaches ~1e-10 relative (model/water.h) */
    ds->model_tolerance = 1e-10;
    char label[160];
    snprintf(label, sizeof label, "time since the first weighing (%s)", tunit);
    ds->x_label = strdup(x_label ? x_label : label);
    ds->y_label = strdup(y_label ? y_label : "mass (g)");
    if (!ds->x_label || !ds->y_label) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        goto fail;
    }
    ds->config_line = node->line;
    ds->impl = w;
    w = NULL;
    *out = ds;
    ds = NULL;
    rc = PHC_OK;
fail:
    phc_dataset_free(ds);
    wc_free(w);
    phc_table_free(table);
    phc_units_free(units);
    free(path);
    free(gpath);
    free(tv);
    free(mv);
    free(sv);
    free(keep);
    free(sel_cols);
    return rc;
}

/* Report rows of the drivers: the night's loss, the covariates' law, the pot. */
static void driver_rows(const wc_impl *w, const double *p, char *buf, size_t size)
{
    const phc_weight_drivers *d = &w->drv;
    size_t used = strlen(buf);
    int s = w->drv_slot;
    if (d->schedule && used < size) {
        const int fitted = isnan(d->night_factor);
        const double f = fitted ? p[s++] : d->night_factor;
        used += (size_t)snprintf(buf + used, size - used,
                                 "| day and night | day %02d:%02d–%02d:%02d local; by night the leaves "
                                 "lose %.3g× the day's rate (night_factor, %s) |\n",
                                 (int)(d->day_start / 3600), (int)fmod(d->day_start / 60, 60),
                                 (int)(d->day_end / 3600), (int)fmod(d->day_end / 60, 60), f,
                                 fitted ? "fitted" : "fixed");
    }
    if (d->n_cov && used < size) {
        used += (size_t)snprintf(buf + used, size - used, "| loss law | g = 1");
        for (size_t j = 0; j < d->n_cov && used < size; ++j)
            used += (size_t)snprintf(buf + used, size - used, " %+.4g × %s", p[s++], d->cov_names[j]);
        if (used < size)
            used += (size_t)snprintf(buf + used, size - used,
                                     " (loss = δ A g; covariates averaged over each interval) |\n");
    }
    if (d->pot && used < size) {
        const double C = isnan(d->capacity) ? p[s++] : d->capacity;
        const double k = isnan(d->conductance) ? p[s++] : d->conductance;
        double vsum = phc_plant_graph_volume(w->graph) * 1e6;
        used += (size_t)snprintf(buf + used, size - used,
                                 "| pot | capacity %.4g g (%s), root–soil conductance %.4g g/s (%s); "
                                 "soil holds %.1f%% of the water at each start; the plant refills "
                                 "from the soil with time constant V/k = %.3g h (V = %.4g cm³), the "
                                 "soil empties into it over C/k = %.3g h |\n",
                                 C, isnan(d->capacity) ? "fitted" : "fixed", k,
                                 isnan(d->conductance) ? "fitted" : "fixed", 100 * C / (C + vsum),
                                 k > 0 ? vsum / k / 3600 : INFINITY, vsum,
                                 k > 0 ? C / k / 3600 : INFINITY);
    }
}

/* The report hook: what the model was (graph, weights, evaluator) and what
 * the fitted curve means in plain numbers. */
static int wc_report_section(phc_dataset *ds, const double *p, char **markdown, phc_error *err)
{
    wc_impl *w = ds->impl;
    static const char *const weight_names[] = {"poiseuille (physical default)", "mean conductance",
                                               "paper", "reference (authors' code)",
                                               "reference_2024"};
    static const char *const method_names[] = {"auto", "exact", "bdf6"};
    const double delta = slot_value(w, p, SLOT_DELTA, 0);
    const double w0 = p[w->pieces[0].slot];
    const double dry = slot_value(w, p, SLOT_DRY, w->dry_measured);
    const double mu = slot_value(w, p, SLOT_MU, w->viscosity);
    const piece *last = &w->pieces[w->n_pieces - 1];
    const int varying = phc_weight_drivers_time_varying(&w->drv);
    const double t_end = varying ? w->t_abs[last->first + last->count - 1]
                                 : w->t_model[last->first + last->count - 1];
    double u_end = NAN;
    if (unit_response(w, p, delta, mu, varying ? w->t_abs[last->first] : 0, &t_end, 1, &u_end, NULL) != 0)
        u_end = NAN;
    const double start = p[last->slot];
    /* Initial loss rate: dW/dt(0) = -Σ ℓ_i θ_i(0) = -δ Σ A_i V_i / Σ V_i · W0. */
    size_t n = w->graph->n, leaves = phc_plant_graph_leaf_count(w->graph);
    double vol = phc_plant_graph_volume(w->graph) * 1e6; /* cm³ */
    /* The slow mode: where pressure equalises much faster than leaves lose
     * water (stiffness >> δ·Ā), W(t) = W0 exp(−δ Ā t) with the
     * volume-weighted leaf area proxy Ā = Σ A_i V_i / Σ V_i (A = r h, cm²). */
    double av = 0, vsum = 0;
    for (size_t i = 0; i < n; ++i) {
        const double r = 100 * w->graph->radius[i], h = 100 * w->graph->length[i];
        const double v = M_PI * r * r * h;
        vsum += v;
        if (w->graph->leaf[i])
            av += r * h * v;
    }
    const double abar = vsum > 0 ? av / vsum : 0;
    char *buf = malloc(4096);
    if (!buf)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    snprintf(buf, 2048,
             "#### Water model (%s)\n\n"
             "| | |\n|---|---|\n"
             "| plant graph | %zu segments, %zu leaf, volume %.4g cm³ |\n"
             "| edge weights | %s |\n"
             "| evaluator | %s%s, stiffness %.3g s⁻¹ |\n"
             "| viscosity μ | %g mPa·s%s |\n"
             "| dry mass | %.6g g (%s) |\n"
             "| curve pieces | %zu%s |\n"
             "| water at the first weighing | %.6g g |\n"
             "| water left at the last weighing | %.6g g (%.1f%% of its piece's start) |\n"
             "| volume-weighted leaf area Ā | %.4g cm² (fast-mixing limit W0 exp(−δĀt): half-life %.4g h) |\n",
             ds->name, n, leaves, vol, weight_names[w->params.weights], method_names[w->method],
             w->step > 0 ? " (fixed step)" : "", w->sys ? phc_water_system_stiffness(w->sys) : NAN, mu,
             w->slot[SLOT_MU] >= 0 ? " (fitted)" : " (fixed)", dry,
             w->slot[SLOT_DRY] >= 0 ? "fitted" : "measured", w->n_pieces,
             w->n_pieces > 1 ? " (split at irrigations; each piece has its own initial water, initial_water_2, ...)" : "",
             w0, start * u_end, 100 * u_end, abar,
             delta > 0 && abar > 0 ? log(2.0) / (delta * abar) / 3600.0 : INFINITY);
    logger_rows(w, buf, 4096);
    driver_rows(w, p, buf, 4096);
    *markdown = buf;
    return PHC_OK;
}
