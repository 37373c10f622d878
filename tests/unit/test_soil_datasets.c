/* The analytic Jacobians of the soil data sets (fit/costs/soil_probe.c,
 * fit/costs/infiltration.c) against central differences of their own
 * predictions: probes reading w and w/c in a two-layer soil with per-layer
 * p and c and the forces f_diff and f_grav as slots, and an infiltration
 * front.  The data sets are built through the C API (phc_soil_probe_new,
 * phc_infiltration_new) from arrays, the soil from phc_soil_setup_options,
 * and bound by name to a problem's parameters. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/costs/infiltration.h"
#include "fit/costs/soil_probe.h"
#include "fit/costs/soil_setup.h"
#include "fit/engine/problem.h"
#include "measurements/soil_probes.h"
#include "measurements/table.h"

/* The fitted slots and their values. */
static const char *const slot_names[6] = {"p_1", "c_1", "p_2", "c_2", "f_diff", "f_grav"};
static const double slot_values[6] = {0.04, 40, 0.01, 15, 0.8, 1.2};

static int is_slot(const char *name, void *user_data)
{
    (void)user_data;
    for (int i = 0; i < 6; ++i)
        if (!strcmp(name, slot_names[i]))
            return 1;
    return 0;
}

/* Compares every data set's Jacobian with central differences (relative
 * step 1e-6) at the start values; takes ds (NULL: its build failed). */
static void check_dataset(phc_dataset *built, const char *label, const phc_error *build_err)
{
    CHECK(built != NULL);
    if (!built) {
        fprintf(stderr, "%s: %s\n", label, build_err->message);
        return;
    }
    phc_problem *pb = phc_problem_new("t");
    phc_error err;
    phc_error_clear(&err);
    for (int i = 0; i < 6; ++i)
        CHECK(phc_problem_add_parameter(pb, slot_names[i], slot_values[i], NULL, &err) == PHC_OK);
    CHECK(phc_problem_bind_by_name(pb, built, &err) == PHC_OK);
    CHECK(phc_problem_add_dataset(pb, built, &err) == PHC_OK);
    for (size_t d = 0; d < pb->n_datasets; ++d) {
        phc_dataset *ds = pb->datasets[d];
        const size_t n = ds->n, k = ds->k;
        double *p = malloc(k * sizeof *p), *y = malloc(n * sizeof *y), *jac = malloc(n * k * sizeof *jac);
        double *yp = malloc(n * sizeof *yp), *ym = malloc(n * sizeof *ym);
        for (size_t j = 0; j < k; ++j)
            p[j] = pb->params[ds->param_index[j]].value;
        CHECK(ds->ops->predict(ds, p, y, jac) == 0);
        double worst = 0;
        for (size_t j = 0; j < k; ++j) {
            const double h = 1e-6 * fabs(p[j]), keep = p[j];
            p[j] = keep + h;
            CHECK(ds->ops->predict(ds, p, yp, NULL) == 0);
            p[j] = keep - h;
            CHECK(ds->ops->predict(ds, p, ym, NULL) == 0);
            p[j] = keep;
            double scale = 0, diff = 0;
            for (size_t i = 0; i < n; ++i) {
                const double fd = (yp[i] - ym[i]) / (2 * h);
                scale = fmax(scale, fabs(fd));
                diff = fmax(diff, fabs(fd - jac[i * k + j]));
            }
            const double rel = diff / (scale > 0 ? scale : 1);
            printf("%s: d/d %-7s max |analytic - central| = %.3g of max |d/d| %.3g\n", label, ds->slot_names[j], rel,
                   scale);
            CHECK(scale > 0); /* every slot moves the predictions */
            worst = fmax(worst, rel);
        }
        CHECK(worst < 1e-6);
        free(p);
        free(y);
        free(jac);
        free(yp);
        free(ym);
    }
    phc_problem_free(pb);
}

int main(void)
{
    /* the soil: 1 x 1 x 25 voxels of 2 cm, fixed step 0.005 h, sides
     * periodic, bottom absorbing, two layers, 1 h of rain at 1 cm/h */
    phc_soil_setup_layer layers[2] = {phc_soil_setup_layer_default(), phc_soil_setup_layer_default()};
    layers[0].c = 40;
    layers[0].p = 0.04;
    layers[0].thickness = 0.15;
    layers[0].fill = 5.0e-4;
    layers[1].c = 15;
    layers[1].p = 0.01;
    layers[1].fill = 1.0e-3;
    const phc_soil_rain rain = {.start = 0, .end = 1, .rate = 0.01};
    phc_soil_setup_options so = phc_soil_setup_options_default();
    so.nz = 25;
    so.dx = 0.02;
    so.params.dt = 0.005;
    so.params.substep = 0;
    so.params.boundary[PHC_SOIL_XMIN] = so.params.boundary[PHC_SOIL_XMAX] = PHC_SOIL_PERIODIC;
    so.params.boundary[PHC_SOIL_YMIN] = so.params.boundary[PHC_SOIL_YMAX] = PHC_SOIL_PERIODIC;
    so.params.boundary[PHC_SOIL_ZMIN] = PHC_SOIL_ABSORB;
    so.layers = layers;
    so.n_layers = 2;
    so.rain = &rain;
    so.n_rain = 1;

    /* three probes and six readings (t in h) */
    phc_probe probe[3] = {{.id = (char *)"A", .x = 0.01, .y = 0.01, .depth = 0.05, .sigma = NAN, .line = 2},
                          {.id = (char *)"B", .x = 0.01, .y = 0.01, .depth = 0.17, .sigma = NAN, .line = 3},
                          {.id = (char *)"C", .x = 0.01, .y = 0.01, .depth = 0.31, .sigma = NAN, .line = 4}};
    const phc_probe_table probes = {.path = (char *)"probes", .probes = probe, .n = 3};
    double t[6] = {0.5, 0.5, 1, 1, 2, 2}, v[6] = {0.03, 0.02, 0.02, 0.01, 0.02, 0.02};
    size_t which[6] = {0, 1, 0, 2, 1, 2};
    const phc_probe_series readings = {.path = (char *)"readings", .n = 6, .t = t, .probe = which, .value = v};
    phc_error err;
    for (int fill = 0; fill < 2; ++fill) {
        phc_soil_probe_options o = phc_soil_probe_options_default();
        o.quantity = fill ? PHC_SOIL_PROBE_FILL : PHC_SOIL_PROBE_WATER;
        o.sigma = 0.002;
        o.soil = &so;
        o.is_parameter = is_slot;
        phc_dataset *ds = NULL;
        phc_error_clear(&err);
        CHECK(phc_soil_probe_new(&probes, &readings, &o, &ds, &err) == PHC_OK);
        check_dataset(ds, fill ? "soil_probe w/c" : "soil_probe w", &err);
    }

    /* the depth of 80% of the water (m) at seven times (h) */
    const double ft[7] = {0.5, 1, 1.5, 2, 2.5, 3, 3.5}, fd[7] = {0.02, 0.04, 0.05, 0.07, 0.08, 0.1, 0.11};
    const char *names[2] = {"t", "d"};
    const double *cols[2] = {ft, fd};
    phc_table *front = NULL;
    CHECK(phc_table_from_columns("front", 2, names, cols, 7, &front, &err) == PHC_OK);
    phc_infiltration_options io = phc_infiltration_options_default();
    io.time = "t";
    io.time_unit = "h";
    io.depth = "d";
    io.depth_unit = "m";
    io.fraction = 0.8;
    io.sigma = 0.01;
    io.soil = &so;
    io.is_parameter = is_slot;
    phc_dataset *ds = NULL;
    phc_error_clear(&err);
    CHECK(front && phc_infiltration_new(front, &io, &ds, &err) == PHC_OK);
    check_dataset(ds, "infiltration", &err);
    phc_table_free(front);
    return check_finish("test_soil_datasets");
}
