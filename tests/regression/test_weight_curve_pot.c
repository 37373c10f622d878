/* The bundled potted-seedling example: measurements/examples/weight_curve/
 * pot.yaml on pot_balance.csv, made by generate_pot.py (the seedling in a
 * covered pot, lights 07:00-23:00 Europe/Berlin, night_factor 0.10,
 * delta 4.0e-3 s-1 cm-2, water 160 g, dry mass 310 g, pot capacity 150 g,
 * conductance 2.0e-4 g/s; SciPy's expm, independent of phytocal).
 *
 * 1. The model at the generating values agrees with generate_pot.py's
 *    noiseless water at 24 h and 96 h (the file's header line).
 * 2. The analytic Jacobian (night_factor, pot_capacity, pot_conductance and
 *    the rest) agrees with central differences of the predictions.
 * 3. The fit recovers every generating value inside its 95% interval and
 *    the daily-cycle check passes.
 * 4. pot_constant.yaml (one constant loss, no pot) fails the daily-cycle
 *    check and the verdict names the day/night difference.
 * 5. The same data through covariates (g = 1 + loss_PAR PAR, PAR 600 by
 *    day, 0 by night), built through the C API (phc_weight_curve_read_table,
 *    phc_weight_curve_new, a problem of its own): 1 + 600 loss_PAR is the
 *    day/night ratio, 10. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/config.h"
#include "fit/costs/weight_curve.h"
#include "fit/costs/weight_table.h"
#include "fit/engine/fit.h"
#include "fit/engine/parameter_units.h"
#include "fit/engine/problem.h"
#include "measurements/plant_io.h"
#include "measurements/table.h"

#define EX PHC_SOURCE_DIR "/measurements/examples/weight_curve/"

static const phc_param_result *param(const phc_fit_result *r, const char *name)
{
    for (size_t i = 0; i < r->n_params; ++i)
        if (strcmp(r->params[i].name, name) == 0)
            return &r->params[i];
    return NULL;
}

static long at_x(const phc_dataset *ds, double x)
{
    for (size_t i = 0; i < ds->n; ++i)
        if (fabs(ds->x[i] - x) < 1e-9)
            return (long)i;
    return -1;
}

static phc_problem *load(const char *path)
{
    phc_error err;
    phc_problem *pb = NULL;
    if (phc_config_load(path, &pb, &err) != PHC_OK) {
        fprintf(stderr, "%s: %s\n", path, err.message);
        return NULL;
    }
    return pb;
}

static phc_fit_result *fit(phc_problem *pb)
{
    phc_error err;
    phc_fit_result *res = NULL;
    if (phc_fit_run(pb, NULL, NULL, &res, &err) != PHC_OK)
        fprintf(stderr, "fit: %s\n", err.message);
    return res;
}

/* Section 5's problem, built through the C API (no config): the seedling
 * graph, pot_balance.csv read with logger timestamps in Europe/Berlin and
 * masses in g, the PAR column as a linear covariate of the loss, a pot
 * whose capacity and conductance are fitted, the 2024 reference weights,
 * sigma 0.02 g; parameters delta 1e-3, loss_PAR 1e-3, initial_water 150,
 * dry_mass 300, pot_capacity 100 (>= 1), pot_conductance 1e-2, all >= 0,
 * bound by name; units converted and the stopping tolerances kept above the
 * ODE solver's accuracy, as phc_config_load does. */
static phc_problem *covariate_problem(phc_error *err)
{
    static const char *const names[6] = {"delta", "loss_PAR", "initial_water", "dry_mass", "pot_capacity",
                                         "pot_conductance"};
    static const double start[6] = {1.0e-3, 0.001, 150, 300, 100, 1.0e-2};
    static const char *const covariates[1] = {"PAR"};
    phc_problem *pb = phc_problem_new("pot-covariates");
    phc_plant_graph *g = NULL;
    phc_table *t = NULL;
    phc_weighings w = phc_weighings_default();
    phc_dataset *ds = NULL;
    int rc = pb ? PHC_OK : phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (int j = 0; j < 6 && !rc; ++j) {
        size_t i = 0;
        if (!(rc = phc_problem_add_parameter(pb, names[j], start[j], &i, err)))
            pb->params[i].lower = j == 4 ? 1 : 0;
    }
    phc_weight_curve_read_options ro = phc_weight_curve_read_options_default();
    ro.time_column = "timestamp";
    ro.timestamps = 1; /* ISO 8601 */
    ro.timezone = "Europe/Berlin";
    ro.mass_column = "mass_g";
    ro.mass_unit = "g";
    ro.n_covariates = 1;
    ro.covariates = covariates;
    phc_weight_curve_options o = phc_weight_curve_options_default();
    o.conductance = PHC_WATER_REFERENCE_2024;
    o.sigma = 0.02;
    o.pot.on = 1; /* capacity and conductance NAN: fitted slots */
    if (!rc && !(rc = phc_plant_io_read(EX "seedling.csv", PHC_PLANT_FORMAT_AUTO, 0, &g, err)) &&
        !(rc = phc_table_read(EX "pot_balance.csv", &t, err)) &&
        !(rc = phc_weight_curve_read_table(t, &ro, &w, err)) && !(rc = phc_weight_curve_new(g, &w, &o, &ds, err))) {
        if (!(ds->name = strdup("pot")))
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        if (!rc && !(rc = phc_problem_bind_by_name(pb, ds, err))) {
            rc = phc_problem_add_dataset(pb, ds, err);
            ds = NULL;
        }
    }
    phc_dataset_free(ds);
    phc_weighings_release(&w);
    phc_table_free(t);
    phc_plant_graph_free(g);
    if (!rc)
        rc = phc_problem_finish(pb, 0, err);
    if (rc) {
        phc_problem_free(pb);
        return NULL;
    }
    return pb;
}

int main(void)
{
    phc_error err;
    /* generating values by slot name */
    const char *names[6] = {"delta", "initial_water", "dry_mass", "night_factor", "pot_capacity",
                            "pot_conductance"};
    const double truth[6] = {4.0e-3, 160.0, 310.0, 0.10, 150.0, 2.0e-4};

    phc_problem *pb = load(EX "pot.yaml");
    CHECK(pb != NULL);
    if (!pb)
        return check_finish("test_weight_curve_pot");
    phc_dataset *ds = pb->datasets[0];
    CHECK(ds->n == 577 && ds->k == 6 && ds->time_of_day != NULL);
    double p[6] = {0};
    for (size_t j = 0; j < ds->k && j < 6; ++j)
        for (int q = 0; q < 6; ++q)
            if (strcmp(ds->slot_names[j], names[q]) == 0)
                p[j] = truth[q];
    for (size_t j = 0; j < ds->k; ++j)
        CHECK(p[j] != 0); /* every slot is one of the six */

    /* 1. noiseless water against generate_pot.py */
    double *y = malloc(ds->n * sizeof *y), *J = malloc(ds->n * ds->k * sizeof *J);
    double *yp = malloc(ds->n * sizeof *yp), *ym = malloc(ds->n * sizeof *ym);
    CHECK(ds->ops->predict(ds, p, y, J) == 0);
    const long i24 = at_x(ds, 24.0), i96 = at_x(ds, 96.0);
    CHECK(i24 > 0 && i96 > 0);
    if (i24 > 0 && i96 > 0) {
        printf("W(24 h) = %.10f g (generate_pot.py 156.5023439828), W(96 h) = %.10f g (146.7579050009)\n",
               y[i24] - 310.0, y[i96] - 310.0);
        /* expm's backward error moves the generator's W by ~1e-6 (its docstring) */
        CHECK_NEAR(y[i24] - 310.0, 156.5023439828, 0, 1e-6);
        CHECK_NEAR(y[i96] - 310.0, 146.7579050009, 0, 1e-6);
    }

    /* 2. Jacobian against central differences (relative step 1e-4) */
    for (size_t j = 0; j < ds->k; ++j) {
        double q[6];
        memcpy(q, p, sizeof q);
        const double h = 1e-4 * p[j];
        q[j] = p[j] + h;
        CHECK(ds->ops->predict(ds, q, yp, NULL) == 0);
        q[j] = p[j] - h;
        CHECK(ds->ops->predict(ds, q, ym, NULL) == 0);
        double scale = 0, worst = 0;
        for (size_t i = 0; i < ds->n; ++i)
            scale = fmax(scale, fabs(J[i * ds->k + j]));
        for (size_t i = 0; i < ds->n; ++i)
            worst = fmax(worst, fabs(J[i * ds->k + j] - (yp[i] - ym[i]) / (2 * h)));
        printf("d mass / d %-16s max |analytic| %.4g, max |analytic - central difference| %.3g\n",
               ds->slot_names[j], scale, worst);
        CHECK(worst <= 1e-5 * scale);
    }
    free(y);
    free(J);
    free(yp);
    free(ym);

    /* 3. the fit */
    phc_fit_result *res = fit(pb);
    CHECK(res != NULL);
    if (res) {
        for (int q = 0; q < 6; ++q) {
            const phc_param_result *r = param(res, names[q]);
            CHECK(r != NULL);
            if (!r)
                continue;
            printf("%-16s %.6g ± %.3g  95%% [%.6g, %.6g]  truth %g\n", names[q], r->value, r->stderr_,
                   r->ci_lo, r->ci_hi, truth[q]);
            CHECK(r->ci_lo < truth[q] && truth[q] < r->ci_hi);
        }
        const phc_check_result *c = &res->datasets[0].checks[PHC_CHECK_DAILY_CYCLE];
        printf("daily_cycle with day and night and the pot: p = %.3g\n", c->p_value);
        CHECK(c->pass);
        phc_fit_result_free(res);
    }
    phc_problem_free(pb);

    /* 4. one constant loss, no pot: the report names the daily cycle */
    pb = load(EX "pot_constant.yaml");
    CHECK(pb != NULL);
    res = pb ? fit(pb) : NULL;
    CHECK(res != NULL);
    if (res) {
        const phc_check_result *c = &res->datasets[0].checks[PHC_CHECK_DAILY_CYCLE];
        printf("daily_cycle with one constant loss: p = %.3g\n", c->p_value);
        CHECK(c->applicable && !c->pass);
        int named = 0;
        for (size_t i = 0; i < res->n_warnings; ++i)
            named |= strstr(res->warnings[i], "the residuals follow a daily cycle") != NULL &&
                     strstr(res->warnings[i], "between day and night") != NULL;
        CHECK(named);
        phc_fit_result_free(res);
    }
    phc_problem_free(pb);

    /* 5. covariates */
    pb = covariate_problem(&err);
    CHECK(pb != NULL);
    if (!pb)
        fprintf(stderr, "covariates: %s\n", err.message);
    res = pb ? fit(pb) : NULL;
    CHECK(res != NULL);
    if (res) {
        const phc_param_result *b = param(res, "loss_PAR"), *d = param(res, "delta");
        CHECK(b && d);
        if (b && d) {
            /* by night g = 1 (PAR 0), by day 1 + 600 b: delta is the night's rate */
            printf("covariates: delta %.4g (night rate; truth 4e-4), 1 + 600 loss_PAR = %.4g "
                   "(truth 10), loss_PAR 95%% [%.4g, %.4g]\n",
                   d->value, 1 + 600 * b->value, b->ci_lo, b->ci_hi);
            CHECK(b->ci_lo < 0.015 && 0.015 < b->ci_hi);
            CHECK(d->ci_lo < 4e-4 && 4e-4 < d->ci_hi);
        }
        phc_fit_result_free(res);
    }
    phc_problem_free(pb);
    (void)err;
    return check_finish("test_weight_curve_pot");
}
