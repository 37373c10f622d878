/* `weight_curve` data sets built in C, without a config
 * (fit/costs/weight_curve.h, fit/costs/weight_table.h):
 *
 * 1. a five-segment plant graph built in memory and 49 weighings (arrays,
 *    hours and grams) made from the water model with delta = 1.5e-4
 *    s-1 cm-2, initial water 1.5 g, dry mass 0.8 g: phc_weight_curve_new,
 *    bound by name to a hand-built problem, fits them back (exact data: to
 *    1e-6 relative);
 * 2. a logger-like table made with phc_table_from_columns (minutes,
 *    milligrams, two plants, a tare reading, a window to leave out, a
 *    watering): phc_weight_curve_read_table selects plant 1 ("1.0" matches
 *    "1"), drops the tare, marks the window, and the data set split at the
 *    watering fits delta, both initial waters and the dry mass back;
 * 3. a light schedule from C: with night_factor at 1 the model is the
 *    constant-loss one; on a calendar the local clock of each weighing
 *    follows the time zone;
 * 5. the BDF6 runs a data set keeps (the last two δ): the values and the
 *    Jacobian at a point evaluated again, after other points, are those of
 *    a fresh data set bit for bit, and W those of phc_water_total_curve;
 * 4. without an origin the messages name the kind ("weight_curve: ..."),
 *    with one they name the config file and the key's line; the weighings'
 *    own places are "weighings:LINE" (or the table's name and line). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/costs/weight_curve.h"
#include "fit/costs/weight_table.h"
#include "fit/engine/fit.h"
#include "fit/engine/problem.h"
#include "measurements/table.h"
#include "model/plant_graph.h"
#include "model/water.h"

#define DELTA 1.5e-4  /* s-1 cm-2 */
#define W0 1.5        /* g */
#define DRY 0.8       /* g */

/* A stem of two segments (radius 2 mm) carrying three leaf segments
 * (radius 1 mm), every segment 5 cm long: built in memory. */
static phc_plant_graph *small_plant(int with_leaves)
{
    static const size_t parent[5] = {PHC_PLANT_NO_PARENT, 0, 1, 1, 0};
    phc_plant_graph *g = phc_plant_graph_new(5);
    if (!g)
        return NULL;
    for (size_t i = 0; i < 5; ++i) {
        g->parent[i] = parent[i];
        g->length[i] = 0.05;
        g->radius[i] = i < 2 ? 2e-3 : 1e-3;
        g->leaf[i] = with_leaves && i >= 2;
        g->tail[3 * i + 2] = g->head[3 * i + 2] + 0.05;
    }
    phc_error err;
    if (phc_plant_graph_finish(g, "", &err)) {
        fprintf(stderr, "%s\n", err.message);
        phc_plant_graph_free(g);
        return NULL;
    }
    return g;
}

/* Water in the plant at times t (s) from the model itself: W0 at t = 0. */
static int water(const phc_plant_graph *g, double w0, const double *t, size_t m, double *W)
{
    phc_water_params p = phc_water_params_default();
    p.loss_rate = DELTA;
    p.initial_water = w0;
    p.viscosity = 0.89;
    phc_error err;
    int rc = phc_water_total_curve(g, &p, PHC_WATER_AUTO, 0, t, m, W, NULL, &err);
    if (rc)
        fprintf(stderr, "%s\n", err.message);
    return rc;
}

static const phc_param_result *param(const phc_fit_result *r, const char *name)
{
    for (size_t i = 0; r && i < r->n_params; ++i)
        if (strcmp(r->params[i].name, name) == 0)
            return &r->params[i];
    return NULL;
}

/* Fits ds with parameters named after its slots, starting from `start`;
 * the result (NULL on failure). */
static phc_fit_result *fit(phc_dataset *ds, const char *const *names, const double *start, size_t k)
{
    phc_error err;
    phc_error_clear(&err);
    phc_problem *pb = phc_problem_new("c-api");
    for (size_t j = 0; j < k; ++j) {
        size_t idx = 0;
        CHECK(phc_problem_add_parameter(pb, names[j], start[j], &idx, &err) == PHC_OK);
        pb->params[idx].lower = 0;
    }
    ds->name = strdup("balance");
    phc_fit_result *res = NULL;
    CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_OK);
    CHECK(phc_problem_add_dataset(pb, ds, &err) == PHC_OK);
    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    if (!res)
        fprintf(stderr, "%s\n", err.message);
    phc_problem_free(pb);
    return res;
}

static void test_arrays(void)
{
    phc_plant_graph *g = small_plant(1);
    CHECK(g != NULL);
    if (!g)
        return;
    double t_h[49], t_s[49], mass[49], W[49];
    for (int i = 0; i < 49; ++i) {
        t_h[i] = 0.5 * i;
        t_s[i] = 3600.0 * t_h[i];
    }
    CHECK(water(g, W0, t_s, 49, W) == 0);
    for (int i = 0; i < 49; ++i)
        mass[i] = DRY + W[i];
    printf("made: mass %.6f g at 0 h, %.6f g at 24 h\n", mass[0], mass[48]);

    phc_weighings w = phc_weighings_default();
    w.n = 49;
    w.t = t_h;
    w.mass = mass;
    w.seconds_per_unit = 3600;
    w.time_unit = "h";
    phc_weight_curve_options o = phc_weight_curve_options_default();
    o.sigma = 0.001;
    phc_dataset *ds = NULL;
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_weight_curve_new(g, &w, &o, &ds, &err) == PHC_OK);
    phc_plant_graph_free(g); /* the data set keeps its own copy */
    if (!ds) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    CHECK(ds->n == 49 && ds->k == 3);
    CHECK(strcmp(ds->slot_names[0], "delta") == 0 && strcmp(ds->slot_names[1], "initial_water") == 0 &&
          strcmp(ds->slot_names[2], "dry_mass") == 0);
    CHECK(strcmp(ds->x_label, "time since the first weighing (h)") == 0);
    CHECK(ds->x_seconds == 3600 && ds->x[48] == 24.0 && ds->data_lines[3] == 4);
    CHECK(strcmp(ds->data_file, "weighings") == 0 && ds->time_of_day == NULL);

    static const char *const names[] = {"delta", "initial_water", "dry_mass"};
    const double start[] = {1e-4, 1.0, 0.5};
    phc_fit_result *res = fit(ds, names, start, 3);
    const phc_param_result *d = param(res, "delta"), *w0 = param(res, "initial_water"), *dry = param(res, "dry_mass");
    CHECK(d && w0 && dry);
    if (d && w0 && dry) {
        printf("arrays: fitted delta %.12g (truth 1.5e-4), initial_water %.12g (1.5), dry_mass %.12g (0.8)\n",
               d->value, w0->value, dry->value);
        CHECK_NEAR(d->value, DELTA, 0, 1e-6);
        CHECK_NEAR(w0->value, W0, 0, 1e-6);
        CHECK_NEAR(dry->value, DRY, 0, 1e-6);
    }
    phc_fit_result_free(res);
}

/* Two plants in minutes and milligrams; plant 1 has a tare reading first,
 * weighings every 20 min for 16 h, a watering of 0.6 g after 8 h and an odd
 * reading at 100 min (left out by an exclusion window). */
static phc_table *logger_table(const phc_plant_graph *g, double *w2_out)
{
    enum { N1 = 49, ROWS = 2 + N1 + 3 };
    double t_min[ROWS], mg[ROWS], plant[ROWS];
    double ts[N1], W[N1];
    size_t r = 0;
    plant[r] = 2, t_min[r] = 0, mg[r++] = 5000; /* another plant's row */
    plant[r] = 1, t_min[r] = -2, mg[r++] = 0.3; /* the empty balance */
    /* piece 1: weighings 0 .. 23 (0 .. 460 min) from W0; piece 2: weighings
     * 24 .. 48 (480 .. 960 min) from the water left at 480 min + 0.6 g */
    for (int i = 0; i < N1; ++i)
        ts[i] = 1200.0 * (i < 24 ? i : i - 24);
    double w480[1], t480[1] = {1200.0 * 24};
    if (water(g, W0, ts, 24, W) || water(g, W0, t480, 1, w480))
        return NULL;
    *w2_out = w480[0] + 0.6;
    if (water(g, *w2_out, ts + 24, N1 - 24, W + 24))
        return NULL;
    for (int i = 0; i < N1; ++i) {
        plant[r] = 1;
        t_min[r] = 20.0 * i;
        mg[r++] = 1000 * (DRY + W[i] + (i == 5 ? 0.2 : 0)); /* 100 min: a hand on the pan */
    }
    for (int i = 0; i < 3; ++i)
        plant[r] = 2, t_min[r] = 30.0 * i + 30, mg[r++] = 4900 - 10 * i;
    const char *names[] = {"plant", "time_min", "mass_mg"};
    const double *cols[] = {plant, t_min, mg};
    phc_table *t = NULL;
    phc_error err;
    if (phc_table_from_columns("arrays", 3, names, cols, r, &t, &err))
        fprintf(stderr, "%s\n", err.message);
    return t;
}

static void test_table(void)
{
    phc_plant_graph *g = small_plant(1);
    double w2 = 0;
    phc_table *t = g ? logger_table(g, &w2) : NULL;
    CHECK(t != NULL);
    if (!t) {
        phc_plant_graph_free(g);
        return;
    }
    static const char *const sel_cols[] = {"plant"}, *const sel_vals[] = {"1.0"};
    static const double windows[] = {90, 110};
    phc_weight_curve_read_options ro = phc_weight_curve_read_options_default();
    ro.time_column = "time_min";
    ro.time_unit = "min";
    ro.mass_column = "mass_mg";
    ro.mass_unit = "mg";
    ro.n_select = 1;
    ro.select_columns = sel_cols;
    ro.select_values = sel_vals;
    ro.n_exclude = 1;
    ro.exclude = windows;
    phc_weighings w;
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_weight_curve_read_table(t, &ro, &w, &err) == PHC_OK);
    phc_table_free(t); /* the weighings keep their own copies */
    if (!w.storage) {
        fprintf(stderr, "%s\n", err.message);
        phc_plant_graph_free(g);
        return;
    }
    size_t skipped = 0;
    for (size_t i = 0; i < w.n; ++i)
        skipped += w.skip[i];
    printf("read: %zu weighings of plant 1, tare %zu (line %zu), %zu left out, %g s per unit, %g g per unit\n",
           w.n, w.tare_n, w.tare_line[0], skipped, w.seconds_per_unit, w.grams_per_unit);
    CHECK(w.n == 49 && w.tare_n == 1 && w.tare_line[0] == 3 && w.lines[0] == 4 && w.rows[0] == 2);
    CHECK(skipped == 1 && w.skip[5] == 1);
    CHECK(w.seconds_per_unit == 60 && fabs(w.grams_per_unit - 1e-3) < 1e-18);
    CHECK(strcmp(w.time_unit, "min") == 0 && strcmp(w.mass_unit, "mg") == 0 && strcmp(w.source, "arrays") == 0);
    CHECK(w.n_gaps == 0 && w.calendar == 0);

    phc_weight_curve_options o = phc_weight_curve_options_default();
    o.jumps = PHC_WEIGHT_JUMPS_SPLIT;
    o.sigma = 1.0; /* mg */
    phc_dataset *ds = NULL;
    CHECK(phc_weight_curve_new(g, &w, &o, &ds, &err) == PHC_OK);
    phc_weighings_release(&w);
    phc_plant_graph_free(g);
    CHECK(w.storage == NULL && w.t == NULL);
    if (!ds) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    CHECK(ds->n == 48 && ds->k == 4 && strcmp(ds->slot_names[2], "initial_water_2") == 0);
    CHECK(ds->sigma && fabs(ds->sigma[0] - 1e-3) < 1e-15 && ds->x[47] == 960 && ds->data_lines[0] == 4);
    static const char *const names[] = {"delta", "initial_water", "initial_water_2", "dry_mass"};
    const double start[] = {1e-4, 1.0, 1.0, 0.5};
    phc_fit_result *res = fit(ds, names, start, 4);
    const phc_param_result *d = param(res, "delta"), *a = param(res, "initial_water"),
                           *b = param(res, "initial_water_2"), *dry = param(res, "dry_mass");
    CHECK(d && a && b && dry);
    if (d && a && b && dry) {
        printf("table: fitted delta %.12g (truth 1.5e-4), initial_water %.12g (1.5), initial_water_2 %.12g "
               "(%.12g), dry_mass %.12g (0.8)\n", d->value, a->value, b->value, w2, dry->value);
        CHECK_NEAR(d->value, DELTA, 0, 1e-6);
        CHECK_NEAR(a->value, W0, 0, 1e-6);
        CHECK_NEAR(b->value, w2, 0, 1e-6);
        CHECK_NEAR(dry->value, DRY, 0, 1e-6);
    }
    phc_fit_result_free(res);
}

static void test_day(void)
{
    phc_plant_graph *g = small_plant(1);
    if (!g)
        return;
    double t_h[25], mass[25];
    for (int i = 0; i < 25; ++i) {
        t_h[i] = i;
        mass[i] = 2.3 - 0.01 * i;
    }
    phc_weighings w = phc_weighings_default();
    w.n = 25;
    w.t = t_h;
    w.mass = mass;
    w.seconds_per_unit = 3600;
    phc_weight_curve_options o = phc_weight_curve_options_default();
    phc_dataset *plain = NULL, *day = NULL;
    phc_error err;
    CHECK(phc_weight_curve_new(g, &w, &o, &plain, &err) == PHC_OK);
    o.day.on = 1;
    o.day.start = 7 * 3600.0;
    o.day.end = 23 * 3600.0;
    o.day.clock = 9 * 3600.0; /* the first weighing at 09:00 */
    CHECK(phc_weight_curve_new(g, &w, &o, &day, &err) == PHC_OK);
    if (plain && day) {
        CHECK(day->k == 4 && strcmp(day->slot_names[3], "night_factor") == 0);
        const double p_plain[] = {DELTA, W0, DRY}, p_day[] = {DELTA, W0, DRY, 1.0};
        double y_plain[25], y_day[25], worst = 0;
        CHECK(plain->ops->predict(plain, p_plain, y_plain, NULL) == 0);
        CHECK(day->ops->predict(day, p_day, y_day, NULL) == 0);
        for (int i = 0; i < 25; ++i)
            worst = fmax(worst, fabs(y_day[i] - y_plain[i]) / y_plain[i]);
        printf("day with night_factor 1 against constant loss: largest relative difference %.2g\n", worst);
        CHECK(worst < 1e-8);
    }
    phc_dataset_free(plain);
    phc_dataset_free(day);

    /* on a calendar: 2024-10-24T09:00:00Z is 11:00 in Berlin (CEST) */
    o.day.clock = NAN;
    w.calendar = 1;
    w.t0_posix = 1729760400.0;
    w.timezone = "Europe/Berlin";
    CHECK(phc_weight_curve_new(g, &w, &o, &day, &err) == PHC_OK);
    if (day) {
        CHECK(day->time_of_day != NULL);
        if (day->time_of_day) {
            printf("calendar: first weighing at %.3f h local, last at %.3f h\n", day->time_of_day[0],
                   day->time_of_day[24]);
            CHECK_NEAR(day->time_of_day[0], 11.0, 1e-9, 0);
            CHECK_NEAR(day->time_of_day[24], 11.0, 1e-9, 0);
        }
    }
    phc_dataset_free(day);
    phc_plant_graph_free(g);
}

/* The line of each key in a pretend config. */
static size_t fake_key_line(const void *map, const char *key)
{
    (void)map;
    return strcmp(key, "day.start") == 0 ? 12 : strcmp(key, "select") == 0 ? 9 : strcmp(key, "sigma") == 0 ? 10 : 5;
}

static void test_messages(void)
{
    phc_plant_graph *g = small_plant(1), *bare = small_plant(0);
    double t[4] = {0, 1, 1, 3}, m[4] = {4.0, 3.9, 3.8, 3.7};
    phc_weighings w = phc_weighings_default();
    w.n = 4;
    w.t = t;
    w.mass = m;
    phc_weight_curve_options o = phc_weight_curve_options_default();
    phc_dataset *ds = NULL;
    phc_error err;

    CHECK(phc_weight_curve_new(g, &w, &o, &ds, &err) == PHC_ERR_INPUT && ds == NULL);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "weighings:3: column 'time': time 1 is not after the previous weighing's 1 "
                              "(line 2); weighings must be in time order") == 0);
    t[2] = 2;
    m[2] = 4.5;
    CHECK(phc_weight_curve_new(g, &w, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strstr(err.message, "weighings:3: the mass rises by 0.6 g since line 2 (an irrigation?)") == err.message);
    m[2] = 3.8;
    o.sigma = -1;
    CHECK(phc_weight_curve_new(g, &w, &o, &ds, &err) == PHC_ERR_INPUT);
    CHECK(strcmp(err.message, "weight_curve: key 'sigma': must be positive, found -1") == 0);
    const phc_origin origin = {.path = "cfg.yaml", .map = "", .key_line = fake_key_line, .line = 5};
    o.origin = &origin;
    CHECK(phc_weight_curve_new(g, &w, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(strcmp(err.message, "cfg.yaml:10: key 'sigma': must be positive, found -1") == 0);
    o.sigma = NAN;
    o.day.on = 1;
    o.day.start = 23 * 3600.0;
    o.day.end = 7 * 3600.0;
    o.day.clock = 9 * 3600.0;
    CHECK(phc_weight_curve_new(g, &w, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(strcmp(err.message, "cfg.yaml:12: day: start (23:00) must be before end (07:00) on the same day") == 0);
    o.day.on = 0;
    o.origin = NULL;
    CHECK(phc_weight_curve_new(bare, &w, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "weight_curve: the plant graph has no leaf segments, so it cannot lose water") == 0);
    o.dry_mass = 3.75;
    CHECK(phc_weight_curve_new(g, &w, &o, &ds, &err) == PHC_ERR_INPUT);
    CHECK(strcmp(err.message, "weighings:4: column 'mass': mass 3.7 is below the measured dry mass 3.75 g") == 0);
    o.dry_mass = NAN;

    /* the reader: a select that keeps nothing, without and with an origin */
    const double *cols[] = {t, m};
    const char *names[] = {"t", "m"};
    phc_table *tab = NULL;
    CHECK(phc_table_from_columns("arrays", 2, names, cols, 4, &tab, &err) == PHC_OK);
    static const char *const sel_cols[] = {"t"}, *const sel_vals[] = {"99"};
    phc_weight_curve_read_options ro = phc_weight_curve_read_options_default();
    ro.time_column = "t";
    ro.mass_column = "m";
    ro.n_select = 1;
    ro.select_columns = sel_cols;
    ro.select_values = sel_vals;
    phc_weighings rw;
    CHECK(phc_weight_curve_read_table(tab, &ro, &rw, &err) == PHC_ERR_INPUT && rw.storage == NULL);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "weight_curve: key 'select': no row of arrays matches") == 0);
    ro.origin = &origin;
    CHECK(phc_weight_curve_read_table(tab, &ro, &rw, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(strcmp(err.message, "cfg.yaml:9: key 'select': no row of arrays matches") == 0);
    ro.n_select = 0;
    ro.origin = NULL;
    ro.mass_column = "mass";
    CHECK(phc_weight_curve_read_table(tab, &ro, &rw, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strstr(err.message, "weight_curve: mass column 'mass' is not a column of arrays") == err.message);
    phc_table_free(tab);

    /* a slot the problem lacks */
    t[2] = 2;
    CHECK(phc_weight_curve_new(g, &w, &o, &ds, &err) == PHC_OK);
    phc_problem *pb = phc_problem_new("c-api");
    CHECK(phc_problem_add_parameter(pb, "delta", 1e-4, NULL, &err) == PHC_OK);
    CHECK(phc_problem_add_parameter(pb, "initial_water", 1, NULL, &err) == PHC_OK);
    if (ds) {
        ds->name = strdup("balance");
        CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_ERR_INPUT);
        printf("binding:      %s\n", err.message);
        CHECK(strstr(err.message, "slot 'dry_mass' has no parameter") != NULL);
        phc_dataset_free(ds);
    }
    phc_problem_free(pb);
    phc_plant_graph_free(g);
    phc_plant_graph_free(bare);
}

/* 5. Kept BDF6 runs: a data set evaluated at p1 (with the Jacobian), p2,
 * p1 (residuals only: kept run), p3, p4 (p1 evicted), p1 with the Jacobian
 * (integrated anew) gives at p1 exactly what a fresh data set gives, and
 * the water of phc_water_total_curve (BDF6, the same step) bit for bit. */
static void test_kept_runs(void)
{
    phc_plant_graph *g = small_plant(1);
    CHECK(g != NULL);
    if (!g)
        return;
    double t_s[49], mass[49], W[49];
    for (int i = 0; i < 49; ++i)
        t_s[i] = 1800.0 * i;
    CHECK(water(g, W0, t_s, 49, W) == 0);
    for (int i = 0; i < 49; ++i)
        mass[i] = DRY + W[i];
    phc_weighings w = phc_weighings_default();
    w.n = 49;
    w.t = t_s;
    w.mass = mass;
    phc_weight_curve_options o = phc_weight_curve_options_default();
    o.sigma = 0.001;
    o.method = PHC_WATER_BDF6;
    phc_dataset *ds = NULL, *fresh = NULL;
    phc_error err;
    CHECK(phc_weight_curve_new(g, &w, &o, &ds, &err) == PHC_OK);
    CHECK(phc_weight_curve_new(g, &w, &o, &fresh, &err) == PHC_OK);
    if (!ds || !fresh) {
        phc_dataset_free(ds);
        phc_dataset_free(fresh);
        phc_plant_graph_free(g);
        return;
    }
    CHECK(ds->k == 3);
    const double p1[3] = {DELTA, W0, DRY}, p2[3] = {1.1 * DELTA, W0, DRY}, p3[3] = {0.9 * DELTA, 1.2, DRY},
                 p4[3] = {2 * DELTA, W0, DRY};
    double y1[49], J1[49 * 3], y[49], J[49 * 3], yf[49], Jf[49 * 3];
    CHECK(ds->ops->predict(ds, p1, y1, J1) == 0);
    CHECK(ds->ops->predict(ds, p2, y, NULL) == 0);
    CHECK(ds->ops->predict(ds, p1, y, NULL) == 0);
    int same = memcmp(y, y1, sizeof y) == 0;
    CHECK(ds->ops->predict(ds, p3, y, J) == 0);
    CHECK(ds->ops->predict(ds, p4, y, NULL) == 0);
    CHECK(ds->ops->predict(ds, p1, y, J) == 0);
    same &= memcmp(y, y1, sizeof y) == 0 && memcmp(J, J1, sizeof J) == 0;
    CHECK(fresh->ops->predict(fresh, p1, yf, Jf) == 0);
    same &= memcmp(yf, y1, sizeof y) == 0 && memcmp(Jf, J1, sizeof J) == 0;
    CHECK(fresh->ops->predict(fresh, p1, yf, NULL) == 0);
    same &= memcmp(yf, y1, sizeof y) == 0;
    CHECK(same);
    /* the model's own curve (BDF6, step t_max / 1000 as the data set) for
     * W0 = 1 g and no dry mass: the data set's unit response itself */
    phc_water_params wp = phc_water_params_default();
    wp.loss_rate = DELTA;
    wp.initial_water = 1.0;
    const double p0[3] = {DELTA, 1.0, 0.0};
    CHECK(ds->ops->predict(ds, p0, y, NULL) == 0);
    CHECK(phc_water_total_curve(g, &wp, PHC_WATER_BDF6, 0, t_s, 49, W, NULL, &err) == PHC_OK);
    double worst = 0;
    for (int i = 0; i < 49; ++i)
        worst = fmax(worst, fabs(y[i] - W[i]));
    printf("kept BDF6 runs: values and Jacobian at p1 after p2, p3, p4 identical to a fresh data "
           "set: %s; largest difference to phc_water_total_curve (W0 1 g) %.3g g\n",
           same ? "yes" : "NO", worst);
    CHECK(worst == 0);
    phc_dataset_free(ds);
    phc_dataset_free(fresh);
    phc_plant_graph_free(g);
}

int main(void)
{
    test_arrays();
    test_table();
    test_day();
    test_kept_runs();
    test_messages();
    return check_finish("test_weight_curve_new");
}
