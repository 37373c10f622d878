/* `elasticity_curve` data sets built in C, without a config
 * (fit/costs/elasticity_curve.h):
 *
 * 1. bulk moduli made in the test from the logistic elasticity (wilting
 *    eq. 9, model/elasticity.h) with kappa = 30, chi0 = 0.9, e_min = 0.4,
 *    e_max = 9 MPa at 21 relative water contents, exact, in a table built
 *    from arrays (phc_table_from_columns); phc_elasticity_curve_new, bound by
 *    name to a hand-built problem, fits them back (to 1e-6) with analytic
 *    derivatives;
 * 2. absolute water contents with a sigma column: the labels and sigmas;
 * 3. without an origin the messages name the kind ("elasticity_curve: ..."),
 *    with one they name the config file and the key's line, as a config
 *    load does; row errors name the table and the row's line either way. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/costs/elasticity_curve.h"
#include "fit/engine/fit.h"
#include "fit/engine/problem.h"
#include "measurements/table.h"
#include "model/elasticity.h"

#define N_POINTS 21
static const phc_elasticity_params truth = {.kappa = 30, .chi0 = 0.9, .e_min = 0.4, .e_max = 9};

/* Moduli at RWC 0.70, 0.715, ..., 1.00 (exact), and a sigma column. */
static phc_table *moduli_table(double rwc_factor)
{
    double rwc[N_POINTS], e[N_POINTS], sd[N_POINTS];
    for (int i = 0; i < N_POINTS; ++i) {
        rwc[i] = 0.70 + 0.015 * i;
        e[i] = phc_elasticity_eval(&truth, rwc[i], NULL, NULL);
        sd[i] = 0.1 + 0.01 * i;
        rwc[i] *= rwc_factor;
    }
    const char *names[] = {"rwc", "E", "sd"};
    const double *cols[] = {rwc, e, sd};
    phc_table *t = NULL;
    phc_error err;
    CHECK(phc_table_from_columns("moduli", 3, names, cols, N_POINTS, &t, &err) == PHC_OK);
    return t;
}

static void test_fit(void)
{
    phc_table *t = moduli_table(1.0);
    if (!t)
        return;
    phc_elasticity_curve_options o = phc_elasticity_curve_options_default();
    o.water = "rwc";
    o.water_content = PHC_WATER_CONTENT_RWC;
    o.modulus = "E";
    phc_dataset *ds = NULL;
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_elasticity_curve_new(t, &o, &ds, &err) == PHC_OK);
    phc_table_free(t); /* the data set keeps its own copy */
    if (!ds) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    CHECK(ds->n == N_POINTS && ds->k == 4);
    CHECK(ds->ops == &phc_elasticity_curve_ops && strcmp(ds->ops->kind, "elasticity_curve") == 0);
    CHECK(strcmp(ds->slot_names[0], "kappa") == 0 && strcmp(ds->slot_names[1], "chi0") == 0 &&
          strcmp(ds->slot_names[2], "e_min") == 0 && strcmp(ds->slot_names[3], "e_max") == 0);
    CHECK(ds->derivatives == PHC_DERIV_ANALYTIC);
    CHECK(ds->sigma == NULL);
    CHECK(strcmp(ds->x_label, "relative water content (RWC)") == 0);
    CHECK(strcmp(ds->y_label, "bulk modulus of elasticity (MPa)") == 0);
    CHECK(ds->data_lines[0] == 2 && ds->data_lines[N_POINTS - 1] == N_POINTS + 1);
    CHECK(ds->config_line == 0 && ds->n_inputs == 0);

    phc_problem *pb = phc_problem_new("moduli");
    CHECK(phc_problem_add_parameter(pb, "kappa", 20.0, NULL, &err) == PHC_OK);
    CHECK(phc_problem_add_parameter(pb, "chi0", 0.85, NULL, &err) == PHC_OK);
    CHECK(phc_problem_add_parameter(pb, "e_min", 0.0, NULL, &err) == PHC_OK);
    CHECK(phc_problem_add_parameter(pb, "e_max", 5.0, NULL, &err) == PHC_OK);
    pb->params[0].lower = pb->params[3].lower = 0;
    ds->name = strdup("moduli");
    CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_OK);
    CHECK(phc_problem_add_dataset(pb, ds, &err) == PHC_OK);
    phc_fit_result *res = NULL;
    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    if (res) {
        const double want[] = {truth.kappa, truth.chi0, truth.e_min, truth.e_max};
        for (size_t i = 0; i < 4; ++i) {
            printf("fitted %-5s %.12g (truth %g)\n", res->params[i].name, res->params[i].value, want[i]);
            CHECK_NEAR(res->params[i].value, want[i], 1e-6, 1e-6);
        }
    } else {
        fprintf(stderr, "%s\n", err.message);
    }
    phc_fit_result_free(res);
    phc_problem_free(pb);
}

static void test_absolute_with_sigma_column(void)
{
    phc_table *t = moduli_table(12.0); /* 12 cm3 of water at full turgor */
    if (!t)
        return;
    phc_elasticity_curve_options o = phc_elasticity_curve_options_default();
    o.water = "rwc";
    o.water_content = PHC_WATER_CONTENT_ABSOLUTE;
    o.modulus = "E";
    o.sigma_column = "sd";
    o.y_label = "E (MPa)";
    phc_dataset *ds = NULL;
    phc_error err;
    CHECK(phc_elasticity_curve_new(t, &o, &ds, &err) == PHC_OK);
    if (ds) {
        CHECK(strcmp(ds->x_label, "water content (rwc)") == 0 && strcmp(ds->y_label, "E (MPa)") == 0);
        CHECK(ds->sigma && ds->sigma[0] == 0.1 && ds->sigma[N_POINTS - 1] == 0.1 + 0.01 * (N_POINTS - 1));
        CHECK(ds->x[N_POINTS - 1] == 12.0 * (0.70 + 0.015 * (N_POINTS - 1)));
        printf("absolute: x[%d] = %g, sigma[%d] = %g, x label \"%s\"\n", N_POINTS - 1, ds->x[N_POINTS - 1],
               N_POINTS - 1, ds->sigma ? ds->sigma[N_POINTS - 1] : NAN, ds->x_label);
    }
    phc_dataset_free(ds);
    /* as relative water content those values are refused, at their row */
    o.water_content = PHC_WATER_CONTENT_RWC;
    CHECK(phc_elasticity_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT && ds == NULL);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "moduli:2: column 'rwc': relative water content must be a fraction in [0, 1.5], "
                              "found 8.4 (percent? divide by 100)") == 0);
    phc_table_free(t);
}

/* The line of each key in a pretend config. */
static size_t fake_key_line(const void *map, const char *key)
{
    (void)map;
    return strcmp(key, "water") == 0 ? 10 : strcmp(key, "sigma") == 0 ? 13 : 8;
}

static void test_messages(void)
{
    phc_table *t = moduli_table(1.0);
    if (!t)
        return;
    phc_elasticity_curve_options o = phc_elasticity_curve_options_default();
    o.water = "rcw";
    o.modulus = "E";
    phc_dataset *ds = NULL;
    phc_error err;
    CHECK(phc_elasticity_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT && ds == NULL);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "elasticity_curve: key 'water_content': expected rwc or absolute (it is required)") == 0);

    o.water_content = PHC_WATER_CONTENT_RWC;
    CHECK(phc_elasticity_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "elasticity_curve: key 'water': 'rcw' is not a column of moduli; did you mean "
                              "'rwc'?") == 0);

    const phc_origin origin = {.path = "cfg.yaml", .map = "", .key_line = fake_key_line, .line = 8};
    o.origin = &origin;
    CHECK(phc_elasticity_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(strcmp(err.message, "cfg.yaml:10: key 'water': 'rcw' is not a column of moduli; did you mean "
                              "'rwc'?") == 0);

    o.water = "rwc";
    o.sigma = -1;
    CHECK(phc_elasticity_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(strcmp(err.message, "cfg.yaml:13: key 'sigma': expected a positive number (MPa), found -1") == 0);

    o.origin = NULL;
    o.sigma = 0.5;
    o.sigma_column = "sd";
    CHECK(phc_elasticity_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    CHECK(strcmp(err.message, "elasticity_curve: key 'sigma': give a number or a column, not both") == 0);
    o.sigma = 0;
    o.sigma_column = "sdev";
    CHECK(phc_elasticity_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strstr(err.message, "elasticity_curve: sigma 'sdev' is not a column of moduli") == err.message);
    o.sigma_column = NULL;
    o.modulus = NULL;
    CHECK(phc_elasticity_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    CHECK(strcmp(err.message, "elasticity_curve: key 'modulus' is required") == 0);
    CHECK(ds == NULL);
    CHECK(phc_elasticity_curve_new(NULL, &o, &ds, &err) == PHC_ERR_INVALID && ds == NULL);
    phc_table_free(t);
}

int main(void)
{
    test_fit();
    test_absolute_with_sigma_column();
    test_messages();
    return check_finish("test_elasticity_curve_new");
}
