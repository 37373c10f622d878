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
 * slot's.
 *
 * A kind's declared slot: a weight_curve (a five-segment plant built in
 * memory, 37 weighings made by the water model with delta = 1.5e-4 s-1 cm-2,
 * 1.5 g of water, 0.8 g dry mass, plus a small deterministic disturbance)
 * fitted once with delta in s-1 cm-2, water and dry mass in g, and once with
 * delta in h-1 cm-2, water in mg and dry mass in kg: the second fit reports
 * every value, standard error and interval in its own units, equal to the
 * first times 3600, 1000 and 1/1000; delta in g is an error naming it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/costs/curve.h"
#include "fit/costs/weight_curve.h"
#include "fit/engine/fit.h"
#include "fit/engine/parameter_units.h"
#include "fit/engine/problem.h"
#include "model/plant_graph.h"
#include "model/water.h"

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

/* A stem of two segments (radius 2 mm) carrying three leaf segments (radius
 * 1 mm), every segment 5 cm long. */
static phc_plant_graph *small_plant(void)
{
    static const size_t parent[5] = {PHC_PLANT_NO_PARENT, 0, 1, 1, 0};
    phc_plant_graph *g = phc_plant_graph_new(5);
    if (!g)
        return NULL;
    for (size_t i = 0; i < 5; ++i) {
        g->parent[i] = parent[i];
        g->length[i] = 0.05;
        g->radius[i] = i < 2 ? 2e-3 : 1e-3;
        g->leaf[i] = i >= 2;
        g->tail[3 * i + 2] = g->head[3 * i + 2] + 0.05;
    }
    phc_error err;
    if (phc_plant_graph_finish(g, "", &err)) {
        phc_plant_graph_free(g);
        return NULL;
    }
    return g;
}

/* The weight curve bound to delta, initial_water, dry_mass given in the
 * units named (NULL: no `unit:`), starting at the values given in them;
 * fitted, the result (NULL on failure); *status the conversion's status
 * and msg (1024 bytes) its message. */
static phc_fit_result *weight_fit(const phc_plant_graph *g, const double *t_h, const double *mass, size_t n,
                                  const char *const units[3], const double start[3], int *status, char *msg)
{
    static const char *const names[3] = {"delta", "initial_water", "dry_mass"};
    phc_weighings w = phc_weighings_default();
    w.n = n;
    w.t = t_h;
    w.mass = mass;
    w.seconds_per_unit = 3600;
    w.time_unit = "h";
    phc_weight_curve_options o = phc_weight_curve_options_default();
    o.sigma = 0.002;
    phc_dataset *ds = NULL;
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_weight_curve_new(g, &w, &o, &ds, &err) == PHC_OK);
    if (!ds)
        return NULL;
    CHECK(ds->slot_units[0] && strcmp(ds->slot_units[0], "s-1 cm-2") == 0);
    CHECK(ds->slot_units[1] && strcmp(ds->slot_units[1], "g") == 0);
    CHECK(ds->slot_units[2] && strcmp(ds->slot_units[2], "g") == 0);
    ds->name = strdup("balance");
    phc_problem *pb = phc_problem_new("weight-units");
    for (int j = 0; j < 3; ++j) {
        size_t idx = 0;
        CHECK(phc_problem_add_parameter(pb, names[j], start[j], &idx, &err) == PHC_OK);
        pb->params[idx].lower = 0;
        if (units[j])
            pb->params[idx].unit = strdup(units[j]);
    }
    CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_OK);
    CHECK(phc_problem_add_dataset(pb, ds, &err) == PHC_OK);
    phc_fit_result *res = NULL;
    if (!(*status = phc_problem_convert_units(pb, &err)))
        CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    else
        snprintf(msg, 1024, "%s", err.message);
    phc_problem_free(pb);
    return res;
}

static void test_weight_curve_units(void)
{
    phc_plant_graph *g = small_plant();
    CHECK(g != NULL);
    if (!g)
        return;
    enum { N = 37 };
    double t_h[N], t_s[N], W[N], mass[N];
    for (int i = 0; i < N; ++i) {
        t_h[i] = 0.5 * i;
        t_s[i] = 3600.0 * t_h[i];
    }
    phc_water_params wp = phc_water_params_default();
    wp.loss_rate = 1.5e-4;
    wp.initial_water = 1.5;
    wp.viscosity = 0.89;
    phc_error err;
    CHECK(phc_water_total_curve(g, &wp, PHC_WATER_AUTO, 0, t_s, N, W, NULL, &err) == PHC_OK);
    for (int i = 0; i < N; ++i)
        mass[i] = 0.8 + W[i] + 0.002 * ((i % 3) - 1);

    const char *const model_units[3] = {"s-1 cm-2", "g", "g"};
    const char *const user_units[3] = {"h-1 cm-2", "mg", "kg"};
    const double factor[3] = {3600.0, 1000.0, 1e-3}; /* user value = factor * model value */
    const double start_model[3] = {1e-4, 1.0, 0.5};
    const double start_user[3] = {0.36, 1000.0, 5e-4};
    int status = 0;
    char msg[1024] = "";
    phc_fit_result *a = weight_fit(g, t_h, mass, N, model_units, start_model, &status, msg);
    CHECK(status == PHC_OK && a != NULL);
    phc_fit_result *b = weight_fit(g, t_h, mass, N, user_units, start_user, &status, msg);
    CHECK(status == PHC_OK && b != NULL);
    if (a && b) {
        for (int j = 0; j < 3; ++j) {
            const phc_param_result *pa = &a->params[j], *pb = &b->params[j];
            const double rel = fabs(pb->value - factor[j] * pa->value) / fabs(factor[j] * pa->value);
            const double rel_se = fabs(pb->stderr_ - factor[j] * pa->stderr_) / (factor[j] * pa->stderr_);
            printf("weight_curve %s: %.10g +- %.4g %s  vs  %.10g +- %.4g %s (relative differences %.2g, %.2g)\n",
                   pa->name, pa->value, pa->stderr_, pa->unit, pb->value, pb->stderr_, pb->unit, rel, rel_se);
            CHECK(strcmp(pa->unit, model_units[j]) == 0 && strcmp(pb->unit, user_units[j]) == 0);
            CHECK(rel < 1e-9);
            CHECK(rel_se < 1e-9);
            CHECK_NEAR(pb->ci_lo, factor[j] * pa->ci_lo, 0, 1e-6);
            CHECK_NEAR(pb->ci_hi, factor[j] * pa->ci_hi, 0, 1e-6);
            CHECK_NEAR(pb->start, start_user[j], 0, 1e-12);
        }
        CHECK_NEAR(a->params[0].value, 1.5e-4, 0, 1e-2); /* the data's delta */
    }
    phc_fit_result_free(a);
    phc_fit_result_free(b);

    const char *const wrong[3] = {"g", NULL, NULL}; /* delta in a mass unit */
    phc_fit_result *c = weight_fit(g, t_h, mass, N, wrong, start_model, &status, msg);
    CHECK(status == PHC_ERR_INPUT && c == NULL);
    printf("delta in g: %s\n", msg);
    CHECK(strstr(msg, "parameter 'delta': unit") != NULL && strstr(msg, "cannot be converted") != NULL);
    phc_fit_result_free(c);
    phc_plant_graph_free(g);
}

int main(void)
{
    test_conversion_and_fit();
    test_errors();
    test_weight_curve_units();
    return check_finish("test_parameter_units");
}
