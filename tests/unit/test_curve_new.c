/* `curve` data sets built in C, without a config (fit/costs/curve.h):
 *
 * 1. phc_table_from_columns keeps every value exactly (17 digits), quotes
 *    awkward column names, and a NaN is refused with its row's line;
 * 2. phc_curve_new over Michaelis-Menten data made with Vmax = 2, Km = 0.5,
 *    bound by name to a hand-built problem, fits them back (exact data: to
 *    1e-8) with analytic derivatives;
 * 3. without an origin the messages name the kind ("curve: ..."), with one
 *    they name the config file and the key's line, as a config load does;
 * 4. a slot without a parameter of its name is refused by
 *    phc_problem_bind_by_name, naming both. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/costs/curve.h"
#include "fit/engine/fit.h"
#include "fit/engine/problem.h"
#include "measurements/table.h"

static void test_table_from_columns(void)
{
    const double a[] = {0.1, 1e-300, -3.141592653589793, 12345678901234567.0};
    const double b[] = {1, 2, 3, 4};
    const char *names[] = {"t", "odd, \"name\""};
    const double *cols[] = {a, b};
    phc_table *t = NULL;
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_table_from_columns("arrays", 2, names, cols, 4, &t, &err) == PHC_OK);
    CHECK(t && phc_table_rows(t) == 4 && phc_table_columns(t) == 2);
    if (!t)
        return;
    CHECK(strcmp(phc_table_column_name(t, 1), names[1]) == 0);
    double *back = NULL;
    CHECK(phc_table_column_numbers(t, "t", &back, &err) == PHC_OK);
    for (size_t i = 0; back && i < 4; ++i)
        CHECK(back[i] == a[i]);
    free(back);
    CHECK(phc_table_row_line(t, 2) == 4);
    phc_table_free(t);

    const double with_nan[] = {1, NAN};
    const double *cols2[] = {with_nan};
    CHECK(phc_table_from_columns("arrays", 1, names, cols2, 2, &t, &err) == PHC_OK);
    back = NULL;
    CHECK(phc_table_column_numbers(t, "t", &back, &err) == PHC_ERR_INPUT);
    printf("NaN cell: %s\n", err.message);
    CHECK(strstr(err.message, "arrays:3: column 't'") != NULL);
    free(back);
    phc_table_free(t);

    CHECK(phc_table_from_columns("arrays", 0, names, cols, 4, &t, &err) == PHC_ERR_INVALID);
    CHECK(t == NULL);
}

/* Michaelis-Menten rates at 8 substrate concentrations (mM), exact. */
static phc_table *mm_table(void)
{
    double s[8], v[8];
    for (int i = 0; i < 8; ++i) {
        s[i] = 0.05 * pow(2.0, i);
        v[i] = 2.0 * s[i] / (0.5 + s[i]);
    }
    const char *names[] = {"S", "v"};
    const double *cols[] = {s, v};
    phc_table *t = NULL;
    phc_error err;
    CHECK(phc_table_from_columns("mm", 2, names, cols, 8, &t, &err) == PHC_OK);
    return t;
}

static void test_fit(void)
{
    phc_table *t = mm_table();
    if (!t)
        return;
    phc_curve_options o = phc_curve_options_default();
    o.x = "S";
    o.y = "v";
    o.expression = "Vmax * S / (Km + S)";
    o.x_label = "S (mM)";
    phc_dataset *ds = NULL;
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_curve_new(t, &o, &ds, &err) == PHC_OK);
    phc_table_free(t); /* the data set keeps its own copy */
    if (!ds) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    CHECK(ds->n == 8 && ds->k == 2);
    const int vmax_first = strcmp(ds->slot_names[0], "Vmax") == 0;
    CHECK(strcmp(ds->slot_names[!vmax_first], "Vmax") == 0 && strcmp(ds->slot_names[vmax_first], "Km") == 0);
    CHECK(ds->derivatives == PHC_DERIV_ANALYTIC);
    CHECK(strcmp(ds->x_label, "S (mM)") == 0 && strcmp(ds->y_label, "v") == 0);

    phc_problem *pb = phc_problem_new("mm");
    CHECK(phc_problem_add_parameter(pb, "Vmax", 1.0, NULL, &err) == PHC_OK);
    CHECK(phc_problem_add_parameter(pb, "Km", 1.0, NULL, &err) == PHC_OK);
    pb->params[0].lower = pb->params[1].lower = 0;
    ds->name = strdup("rates");
    CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_OK);
    CHECK(phc_problem_add_dataset(pb, ds, &err) == PHC_OK);
    phc_fit_result *res = NULL;
    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    if (res) {
        printf("fitted Vmax %.12g (truth 2), Km %.12g (truth 0.5)\n", res->params[0].value,
               res->params[1].value);
        CHECK_NEAR(res->params[0].value, 2.0, 0, 1e-8);
        CHECK_NEAR(res->params[1].value, 0.5, 0, 1e-8);
        /* the dense curve (blocks of rows through the tape) is the formula
         * at the fitted values, at every point */
        const phc_dataset_result *d = &res->datasets[0];
        CHECK(d->curve_n > 64);
        const double vmax = res->params[0].value, km = res->params[1].value;
        for (size_t i = 0; i < d->curve_n; ++i)
            CHECK_NEAR(d->curve_y[i], vmax * d->curve_x[i] / (km + d->curve_x[i]), 1e-15, 1e-14);
    } else {
        fprintf(stderr, "%s\n", err.message);
    }
    phc_fit_result_free(res);
    phc_problem_free(pb);
}

/* The line of each key in a pretend config. */
static size_t fake_key_line(const void *map, const char *key)
{
    (void)map;
    return strcmp(key, "x") == 0 ? 7 : strcmp(key, "expression") == 0 ? 9 : 5;
}

static void test_messages(void)
{
    phc_table *t = mm_table();
    if (!t)
        return;
    phc_curve_options o = phc_curve_options_default();
    o.x = "s";
    o.y = "v";
    o.expression = "Vmax * S / (Km + S)";
    phc_dataset *ds = NULL;
    phc_error err;
    CHECK(phc_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT && ds == NULL);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "curve: x 's' is not a column of mm; did you mean 'S'?") == 0);

    const phc_origin origin = {.path = "cfg.yaml", .map = "", .key_line = fake_key_line, .line = 5};
    o.origin = &origin;
    CHECK(phc_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(strcmp(err.message, "cfg.yaml:7: x 's' is not a column of mm; did you mean 'S'?") == 0);

    o.x = "S";
    o.expression = "Vmax * S / (Km + S";
    CHECK(phc_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(strncmp(err.message, "cfg.yaml:9: expression \"Vmax * S / (Km + S\": ", 44) == 0);

    o.origin = NULL;
    o.expression = NULL;
    CHECK(phc_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    CHECK(strcmp(err.message, "curve: key 'expression' is required") == 0);
    o.expression = "Vmax * S / (Km + S)";
    o.sigma = -1;
    CHECK(phc_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    CHECK(strcmp(err.message, "curve: key 'sigma': must be positive, found -1") == 0);
    o.sigma = 0;
    o.sigma_column = "sd";
    CHECK(phc_curve_new(t, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strstr(err.message, "curve: sigma 'sd' is not a column of mm") == err.message);

    /* a slot the problem lacks */
    o.sigma_column = NULL;
    CHECK(phc_curve_new(t, &o, &ds, &err) == PHC_OK);
    phc_problem *pb = phc_problem_new("mm");
    CHECK(phc_problem_add_parameter(pb, "Vmax", 1.0, NULL, &err) == PHC_OK);
    if (ds) {
        ds->name = strdup("rates");
        CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_ERR_INPUT);
        printf("binding:      %s\n", err.message);
        CHECK(strstr(err.message, "slot 'Km' has no parameter") != NULL);
        phc_dataset_free(ds);
    }
    phc_problem_free(pb);
    phc_table_free(t);
}

int main(void)
{
    test_table_from_columns();
    test_fit();
    test_messages();
    return check_finish("test_curve_new");
}
