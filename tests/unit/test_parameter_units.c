/* Parameter units (fit/engine/parameter_units.h): a parameter given in the user's
 * unit is converted into the unit its model slot declares, fitted there,
 * and reported back in the user's unit.
 *
 * The model is y = a * t with slot `a` declared in g s-1 (as a kind would),
 * data made with a = 2e-3 g s-1; the user gives `a` in g h-1 (7.2 g h-1)
 * with bounds [0, 100] g h-1.  Checked: the start and bounds held by the
 * problem are in g s-1 (x 1/3600), the fitted value and its standard error
 * come back in g h-1, the model sees g s-1 through unit_scale; an unknown
 * unit, a unit of another dimension and two slot units on one parameter are
 * errors naming the parameter; a parameter without `unit:` takes the
 * slot's. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/costs/curve.h"
#include "fit/engine/fit.h"
#include "fit/engine/parameter_units.h"
#include "fit/engine/problem.h"

/* Mass loss y (g) at times t (s) for a = 2e-3 g s-1, with a small
 * deterministic disturbance so that the standard error is not zero. */
static phc_dataset *line_dataset(const char *name, const char *slot_unit)
{
    double t[10], y[10];
    for (int i = 0; i < 10; ++i) {
        t[i] = 600.0 * (i + 1);
        y[i] = 2e-3 * t[i] + 0.01 * ((i % 3) - 1);
    }
    const char *names[] = {"t", "y"};
    const double *cols[] = {t, y};
    phc_table *tab = NULL;
    phc_error err;
    CHECK(phc_table_from_columns(name, 2, names, cols, 10, &tab, &err) == PHC_OK);
    phc_curve_options o = phc_curve_options_default();
    o.x = "t";
    o.y = "y";
    o.expression = "a * t";
    phc_dataset *ds = NULL;
    CHECK(phc_curve_new(tab, &o, &ds, &err) == PHC_OK);
    phc_table_free(tab);
    if (ds) {
        ds->name = strdup(name);
        if (slot_unit)
            CHECK(phc_dataset_declare_unit(ds, "a", slot_unit) == PHC_OK);
        CHECK(phc_dataset_declare_unit(ds, "nope", "g") == PHC_ERR_INVALID);
    }
    return ds;
}

static phc_problem *problem(const char *user_unit, const char *slot_unit, const char *slot_unit2)
{
    phc_problem *pb = phc_problem_new("units");
    phc_error err;
    CHECK(phc_problem_add_parameter(pb, "a", 7.2, NULL, &err) == PHC_OK);
    pb->params[0].lower = 0;
    pb->params[0].upper = 100;
    pb->params[0].scale = 3.6;
    if (user_unit)
        pb->params[0].unit = strdup(user_unit);
    phc_dataset *ds = line_dataset("first", slot_unit);
    CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_OK);
    CHECK(phc_problem_add_dataset(pb, ds, &err) == PHC_OK);
    if (slot_unit2) {
        ds = line_dataset("second", slot_unit2);
        CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_OK);
        CHECK(phc_problem_add_dataset(pb, ds, &err) == PHC_OK);
    }
    return pb;
}

static void test_conversion_and_fit(void)
{
    phc_problem *pb = problem("g h-1", "g s-1", NULL);
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_problem_convert_units(pb, &err) == PHC_OK);
    const phc_parameter *p = &pb->params[0];
    printf("start %.10g g s-1, bounds [%g, %.10g] g s-1, scale %.10g (unit_scale %.10g)\n", p->value, p->lower,
           p->upper, p->scale, p->unit_scale);
    CHECK_NEAR(p->value, 2e-3, 0, 1e-12);
    CHECK_NEAR(p->upper, 100.0 / 3600.0, 0, 1e-12);
    CHECK(p->lower == 0);
    CHECK_NEAR(p->scale, 1e-3, 0, 1e-12);
    CHECK(strcmp(p->slot_unit, "g s-1") == 0 && strcmp(p->unit, "g h-1") == 0);

    /* the same fit without units, in g s-1, for the reference numbers */
    phc_problem *ref = problem(NULL, NULL, NULL);
    ref->params[0].value = 2e-3;
    ref->params[0].upper = 100.0 / 3600.0;
    ref->params[0].scale = 1e-3;
    phc_fit_result *r = NULL, *r_ref = NULL;
    CHECK(phc_fit_run(pb, NULL, NULL, &r, &err) == PHC_OK);
    CHECK(phc_fit_run(ref, NULL, NULL, &r_ref, &err) == PHC_OK);
    if (r && r_ref) {
        const phc_param_result *a = &r->params[0], *b = &r_ref->params[0];
        printf("fitted a = %.10g +- %.3g g h-1 (in g s-1: %.10g +- %.3g), start %.10g g h-1\n", a->value,
               a->stderr_, b->value, b->stderr_, a->start);
        CHECK_NEAR(a->value, b->value * 3600.0, 0, 1e-9);
        CHECK_NEAR(a->stderr_, b->stderr_ * 3600.0, 0, 1e-6);
        CHECK_NEAR(a->ci_hi - a->ci_lo, (b->ci_hi - b->ci_lo) * 3600.0, 0, 1e-6);
        CHECK_NEAR(a->start, 7.2, 0, 1e-12);
        CHECK(strcmp(a->unit, "g h-1") == 0);
        CHECK_NEAR(a->unit_scale * a->value + a->unit_offset, b->value, 0, 1e-9);
    }
    phc_fit_result_free(r);
    phc_fit_result_free(r_ref);
    phc_problem_free(ref);
    phc_problem_free(pb);
}

static void test_errors(void)
{
    phc_error err;
    phc_problem *pb = problem("blorps h-1", "g s-1", NULL);
    CHECK(phc_problem_convert_units(pb, &err) == PHC_ERR_INPUT);
    printf("unknown unit: %s\n", err.message);
    CHECK(strstr(err.message, "parameter 'a': unit: 'blorps h-1' is not a unit") != NULL);
    phc_problem_free(pb);

    pb = problem("m s-1", "g s-1", NULL);
    pb->source = strdup("cfg.yaml");
    pb->params[0].config_line = 4;
    CHECK(phc_problem_convert_units(pb, &err) == PHC_ERR_INPUT);
    printf("other dimension: %s\n", err.message);
    CHECK(strncmp(err.message, "cfg.yaml:4: parameter 'a': unit", 31) == 0);
    CHECK(strstr(err.message, "cannot be converted") != NULL);
    phc_problem_free(pb);

    pb = problem("g h-1", "g s-1", "kg s-1");
    CHECK(phc_problem_convert_units(pb, &err) == PHC_ERR_INPUT);
    printf("two slot units: %s\n", err.message);
    CHECK(strstr(err.message, "bound to slots of different units") != NULL);
    phc_problem_free(pb);

    /* no `unit:`: the slot's unit is shown, nothing converted */
    pb = problem(NULL, "g s-1", "g s-1");
    CHECK(phc_problem_convert_units(pb, &err) == PHC_OK);
    CHECK(pb->params[0].unit && strcmp(pb->params[0].unit, "g s-1") == 0);
    CHECK(pb->params[0].value == 7.2 && pb->params[0].unit_scale == 1.0);
    phc_problem_free(pb);

    /* no slot unit: `unit:` stays a label */
    pb = problem("furlongs", NULL, NULL);
    CHECK(phc_problem_convert_units(pb, &err) == PHC_OK);
    CHECK(pb->params[0].value == 7.2 && pb->params[0].slot_unit == NULL);
    phc_problem_free(pb);
}

int main(void)
{
    test_conversion_and_fit();
    test_errors();
    return check_finish("test_parameter_units");
}
