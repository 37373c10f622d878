/* `infiltration` data sets built in C, without a config
 * (fit/costs/infiltration.h):
 *
 * 1. a 2 m column (40 voxels) of one layer, dry at the start, under 2 h of
 *    rain at 10 mm/h; the depth above which 80% of the applied water lies,
 *    at 6 times, made by the data set's own model at p = 0.05 m/h, c = 50
 *    and given in cm through a table built from arrays: the permeability
 *    alone (the front identifies p, README) is fitted back from 0.1 m/h to
 *    1e-6, bound by name to a hand-built problem;
 * 2. without an origin the messages name the kind ("infiltration: ..."),
 *    with one they name the config file and the key's line, or the soil
 *    block's line for a soil without water. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/costs/infiltration.h"
#include "fit/engine/fit.h"
#include "fit/engine/problem.h"
#include "measurements/table.h"

#define N_OBS 6

static const double t_h[N_OBS] = {1, 2, 3, 4, 6, 8};
static phc_soil_setup_layer layer;
static phc_soil_rain rain = {.start = 0, .end = 2, .rate = 0.01};

static phc_soil_setup_options soil_options(void)
{
    phc_soil_setup_options s = phc_soil_setup_options_default();
    s.nz = 40;
    s.dx = 0.05;
    s.params.dt = 0.05;
    layer = phc_soil_setup_layer_default();
    layer.c = 50;
    layer.p = 0.05;
    layer.fill = 1e-4;
    s.layers = &layer;
    s.n_layers = 1;
    s.rain = &rain;
    s.n_rain = 1;
    return s;
}

static int only_p(const char *name, void *user_data)
{
    (void)user_data;
    return !strcmp(name, "p");
}

static phc_table *front_table(const double *d_cm)
{
    const char *names[] = {"t", "d80"};
    const double *cols[] = {t_h, d_cm};
    phc_table *t = NULL;
    phc_error err;
    CHECK(phc_table_from_columns("front", 2, names, cols, N_OBS, &t, &err) == PHC_OK);
    return t;
}

static phc_infiltration_options options(phc_soil_setup_options *s)
{
    phc_infiltration_options o = phc_infiltration_options_default();
    o.time = "t";
    o.depth = "d80";
    o.depth_unit = "cm";
    o.sigma = 1; /* cm */
    o.soil = s;
    o.is_parameter = only_p;
    return o;
}

static void fit_back(void)
{
    /* the truth's depths, in cm */
    double d_cm[N_OBS] = {0};
    phc_table *t = front_table(d_cm);
    phc_soil_setup_options s = soil_options();
    phc_infiltration_options o = options(&s);
    phc_dataset *ds = NULL;
    phc_error err;
    phc_error_clear(&err);
    CHECK(t && phc_infiltration_new(t, &o, &ds, &err) == PHC_OK);
    phc_table_free(t);
    if (!ds) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    CHECK(ds->n == N_OBS && ds->k == 1 && strcmp(ds->slot_names[0], "p") == 0);
    CHECK(ds->sigma[0] == 0.01 && ds->x[5] == 8 && ds->data_lines[0] == 2);
    CHECK(strcmp(ds->y_label, "depth of 80% of the applied water (m)") == 0);
    const double truth = 0.05;
    double d_m[N_OBS];
    CHECK(ds->ops->predict(ds, &truth, d_m, NULL) == 0);
    phc_dataset_free(ds);
    printf("80%% depths at the truth (m):");
    for (int i = 0; i < N_OBS; ++i) {
        d_cm[i] = 100 * d_m[i];
        printf(" %.4f", d_m[i]);
    }
    printf("\n");
    CHECK(d_m[0] > 0 && d_m[N_OBS - 1] > d_m[0]);

    t = front_table(d_cm);
    CHECK(t && phc_infiltration_new(t, &o, &ds, &err) == PHC_OK);
    phc_table_free(t);
    if (!ds) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    phc_problem *pb = phc_problem_new("front");
    CHECK(phc_problem_add_parameter(pb, "p", 0.1, NULL, &err) == PHC_OK);
    pb->params[0].lower = 1e-4;
    pb->params[0].upper = 1;
    ds->name = strdup("front");
    CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_OK);
    CHECK(phc_problem_add_dataset(pb, ds, &err) == PHC_OK);
    phc_fit_result *res = NULL;
    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    if (res) {
        printf("fitted p %.10g m/h (truth 0.05) with c = 50 given\n", res->params[0].value);
        CHECK_NEAR(res->params[0].value, 0.05, 0, 1e-6);
    } else {
        fprintf(stderr, "%s\n", err.message);
    }
    phc_fit_result_free(res);
    phc_problem_free(pb);
}

static size_t fake_key_line(const void *map, const char *key)
{
    (void)map;
    return !key ? 5 : !strcmp(key, "fraction") ? 12 : !strcmp(key, "depth") ? 9 : 5;
}

static void messages(void)
{
    double d_cm[N_OBS] = {1, 2, 3, 4, 5, 6};
    phc_table *t = front_table(d_cm);
    if (!t)
        return;
    phc_soil_setup_options s = soil_options();
    phc_infiltration_options o = options(&s);
    phc_dataset *ds = NULL;
    phc_error err;
    o.fraction = 1.5;
    CHECK(phc_infiltration_new(t, &o, &ds, &err) == PHC_ERR_INPUT && ds == NULL);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "infiltration: key 'fraction': must be in (0, 1], found 1.5") == 0);
    const phc_origin origin = {.path = "cfg.yaml", .map = "", .key_line = fake_key_line, .line = 5};
    o.origin = &origin;
    CHECK(phc_infiltration_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(strcmp(err.message, "cfg.yaml:12: key 'fraction': must be in (0, 1], found 1.5") == 0);
    o.fraction = 0.8;

    o.depth = "d8";
    CHECK(phc_infiltration_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(strcmp(err.message, "cfg.yaml:9: key 'depth': 'd8' is not a column of front; did you mean 'd80'?") == 0);
    o.origin = NULL;
    CHECK(phc_infiltration_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    CHECK(strcmp(err.message, "infiltration: key 'depth': 'd8' is not a column of front; did you mean 'd80'?") == 0);
    o.depth = "d80";

    o.depth_unit = "kg";
    CHECK(phc_infiltration_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "infiltration: depth unit: 'kg' cannot be converted to 'm'") == 0);
    o.depth_unit = "cm";

    o.sigma = NAN;
    CHECK(phc_infiltration_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    CHECK(strcmp(err.message, "infiltration: infiltration data set: missing key 'sigma' (the depth's standard "
                              "deviation, or a column)") == 0);
    o.sigma = 1;

    s.n_rain = 0;
    CHECK(phc_infiltration_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "infiltration: infiltration data set: the soil has no rain or source, so nothing "
                              "infiltrates") == 0);
    const phc_origin soil_origin = {.path = "cfg.yaml", .map = "", .key_line = fake_key_line, .line = 14};
    s.origin = &soil_origin;
    CHECK(phc_infiltration_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(strncmp(err.message, "cfg.yaml:14: infiltration data set: the soil has no rain", 56) == 0);
    phc_table_free(t);
}

int main(void)
{
    fit_back();
    messages();
    return check_finish("test_infiltration_new");
}
