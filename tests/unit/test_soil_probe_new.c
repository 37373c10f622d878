/* `soil_probe` data sets built in C, without a config (fit/costs/soil_probe.h,
 * fit/costs/soil_setup.h):
 *
 * 1. a 1 m column of silt-like soil (20 voxels) under 2 h of rain, two
 *    probes in a probe table filled from arrays, readings of w every 2 h
 *    for 12 h made by the data set's own model at p = 0.05 m/h, c = 50:
 *    bound by name to a hand-built problem, a fit from p = 0.08, c = 30
 *    recovers the truth (exact data: to 1e-6);
 * 2. the same readings as w/c with per-layer slots p_1, c_1 chosen by an
 *    is_parameter rule;
 * 3. without an origin the messages name the kind ("soil_probe: ..."), with
 *    one they name the config file and the line of the key, or of the list
 *    item ("layers[0].soil"), as a config load does;
 * 4. inputs a file reader would never give (a probe index past the table)
 *    are refused with a message. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/costs/soil_probe.h"
#include "fit/engine/fit.h"
#include "fit/engine/problem.h"

#define N_READ 12 /* 2 probes x 6 times */

static phc_soil_setup_layer layer;
static phc_soil_rain rain = {.start = 0, .end = 2, .rate = 0.01};
static phc_probe probe_list[2] = {{.id = "P1", .x = 0.025, .y = 0.025, .depth = 0.1, .sigma = NAN, .line = 2},
                                  {.id = "P2", .x = 0.025, .y = 0.025, .depth = 0.3, .sigma = NAN, .line = 3}};
static phc_probe_table probes = {.path = "probes", .probes = probe_list, .n = 2};
static double t_h[N_READ], value[N_READ];
static size_t probe_of[N_READ];
static phc_probe_series readings = {.path = "readings", .n = N_READ, .t = t_h, .probe = probe_of, .value = value};

static phc_soil_setup_options soil_options(void)
{
    phc_soil_setup_options s = phc_soil_setup_options_default();
    s.nz = 20;
    s.dx = 0.05;
    s.params.dt = 0.05;
    layer = phc_soil_setup_layer_default();
    layer.c = 50;
    layer.p = 0.05;
    layer.fill = 0.001;
    s.layers = &layer;
    s.n_layers = 1;
    s.rain = &rain;
    s.n_rain = 1;
    return s;
}

/* Readings of the data set's own model at p = 0.05, c = 50 (slots in the
 * order the set-up lists them). */
static int make_readings(phc_soil_probe_quantity quantity)
{
    for (size_t r = 0; r < N_READ; ++r) {
        t_h[r] = 2.0 * (double)(r / 2 + 1);
        probe_of[r] = r % 2;
        value[r] = 0;
    }
    phc_soil_setup_options s = soil_options();
    phc_soil_probe_options o = phc_soil_probe_options_default();
    o.quantity = quantity;
    o.sigma = 0.001;
    o.soil = &s;
    phc_dataset *ds = NULL;
    phc_error err;
    if (phc_soil_probe_new(&probes, &readings, &o, &ds, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    const double truth[2] = {0.05, 50};
    int rc = ds->k == 2 && !strcmp(ds->slot_names[0], "p") && !strcmp(ds->slot_names[1], "c")
                 ? ds->ops->predict(ds, truth, value, NULL)
                 : 1;
    phc_dataset_free(ds);
    return rc;
}

static int per_layer(const char *name, void *user_data)
{
    (void)user_data;
    return !strcmp(name, "p_1") || !strcmp(name, "c_1");
}

static void fit_back(phc_soil_probe_quantity quantity, int layer_slots)
{
    CHECK(make_readings(quantity) == 0);
    phc_soil_setup_options s = soil_options();
    phc_soil_probe_options o = phc_soil_probe_options_default();
    o.quantity = quantity;
    o.sigma = 0.001;
    o.soil = &s;
    if (layer_slots)
        o.is_parameter = per_layer;
    phc_dataset *ds = NULL;
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_soil_probe_new(&probes, &readings, &o, &ds, &err) == PHC_OK);
    if (!ds) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    const char *pn = layer_slots ? "p_1" : "p", *cn = layer_slots ? "c_1" : "c";
    CHECK(ds->n == N_READ && ds->k == 2 && ds->derivatives == PHC_DERIV_ANALYTIC);
    CHECK(strcmp(ds->slot_names[0], pn) == 0 && strcmp(ds->slot_names[1], cn) == 0);
    CHECK(strcmp(ds->data_file, "readings") == 0 && ds->data_lines[3] == 5);
    CHECK(strcmp(ds->y_label, quantity == PHC_SOIL_PROBE_FILL ? "fill level w/c" : "water content w (m³/m³)") == 0);

    phc_problem *pb = phc_problem_new("probes");
    CHECK(phc_problem_add_parameter(pb, pn, 0.08, NULL, &err) == PHC_OK);
    CHECK(phc_problem_add_parameter(pb, cn, 30, NULL, &err) == PHC_OK);
    pb->params[0].lower = 1e-4;
    pb->params[0].upper = 1;
    pb->params[1].lower = 1;
    pb->params[1].upper = 1000;
    ds->name = strdup("column");
    CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_OK);
    CHECK(phc_problem_add_dataset(pb, ds, &err) == PHC_OK);
    CHECK(ds->n_series == 2 && strcmp(ds->series_names[1], "P2, 0.30 m deep") == 0);
    phc_fit_result *res = NULL;
    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    if (res) {
        printf("%s, slots %s %s: fitted p %.10g m/h (truth 0.05), c %.10g (truth 50)\n",
               quantity == PHC_SOIL_PROBE_FILL ? "w/c" : "w", pn, cn, res->params[0].value, res->params[1].value);
        CHECK_NEAR(res->params[0].value, 0.05, 0, 1e-6);
        CHECK_NEAR(res->params[1].value, 50, 0, 1e-6);
    } else {
        fprintf(stderr, "%s\n", err.message);
    }
    phc_fit_result_free(res);
    phc_problem_free(pb);
}

/* Lines of the keys in a pretend config: the data set at 5, its sigma at
 * 11, the soil block at 14 and its first layer's soil: at 17. */
static size_t fake_key_line(const void *map, const char *key)
{
    (void)map;
    return !key ? 5 : !strcmp(key, "sigma") ? 11 : 5;
}
static size_t fake_soil_line(const void *map, const char *key)
{
    (void)map;
    return key && !strcmp(key, "layers[0].soil") ? 17 : 14;
}

static void messages(void)
{
    phc_soil_setup_options s = soil_options();
    phc_soil_probe_options o = phc_soil_probe_options_default();
    o.soil = &s;
    o.sigma = -1;
    phc_dataset *ds = NULL;
    phc_error err;
    CHECK(phc_soil_probe_new(&probes, &readings, &o, &ds, &err) == PHC_ERR_INPUT && ds == NULL);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "soil_probe: key 'sigma': must be > 0") == 0);
    const phc_origin origin = {.path = "cfg.yaml", .map = "", .key_line = fake_key_line, .line = 5};
    o.origin = &origin;
    CHECK(phc_soil_probe_new(&probes, &readings, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(strcmp(err.message, "cfg.yaml:11: key 'sigma': must be > 0") == 0);

    o.sigma = NAN;
    CHECK(phc_soil_probe_new(&probes, &readings, &o, &ds, &err) == PHC_ERR_INPUT);
    CHECK(strcmp(err.message, "cfg.yaml:5: soil_probe data set: give `sigma:` or a sigma column in the probe "
                              "table (probe 'P1' has none)") == 0);

    o.sigma = 0.001;
    o.origin = NULL;
    layer.soil = "peat";
    CHECK(phc_soil_probe_new(&probes, &readings, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "soil_probe: soil layer 1: unknown soil 'peat' (known: clay, clay_loam, "
                              "sandy_clay_loam, sandy_loam, silt_loam, silt)") == 0);
    const phc_origin soil_origin = {.path = "cfg.yaml", .map = "", .key_line = fake_soil_line, .line = 14};
    s.origin = &soil_origin;
    CHECK(phc_soil_probe_new(&probes, &readings, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(strncmp(err.message, "cfg.yaml:17: soil layer 1: unknown soil 'peat'", 46) == 0);
    layer.soil = NULL;
    s.origin = NULL;

    s.nz = 0;
    CHECK(phc_soil_probe_new(&probes, &readings, &o, &ds, &err) == PHC_ERR_INPUT);
    CHECK(strcmp(err.message, "soil_probe: soil grid: needs nx, ny, nz >= 1 (at most 5e8 voxels) and dx > 0 m") == 0);
    s.nz = 20;

    probe_list[1].x = 0.07;
    CHECK(phc_soil_probe_new(&probes, &readings, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "probes:3: probe 'P2' at x = 0.070 m, y = 0.025 m, depth 0.300 m is outside the soil "
                              "grid (x 0..0.05 m, y 0..0.05 m, depth 0..1 m)") == 0);
    probe_list[1].x = 0.025;

    probe_of[3] = 2;
    CHECK(phc_soil_probe_new(&probes, &readings, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strstr(err.message, "soil_probe: reading 4: probe 3 of 2") == err.message);
    probe_of[3] = 1;

    o.soil = NULL;
    CHECK(phc_soil_probe_new(&probes, &readings, &o, &ds, &err) == PHC_ERR_INPUT);
    CHECK(strcmp(err.message, "soil_probe: soil_probe data set: missing key 'soil'") == 0);
}

int main(void)
{
    fit_back(PHC_SOIL_PROBE_WATER, 0);
    fit_back(PHC_SOIL_PROBE_FILL, 1);
    messages();
    return check_finish("test_soil_probe_new");
}
