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
 *    day, 0 by night): 1 + 600 loss_PAR is the day/night ratio, 10. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/config.h"
#include "fit/engine/fit.h"

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
    char path[] = "/tmp/phc_pot_cov_XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    if (fd >= 0) {
        FILE *f = fdopen(fd, "w");
        fprintf(f,
                "name: pot-covariates\n"
                "parameters:\n"
                "  delta: {value: 1.0e-3, lower: 0}\n"
                "  loss_PAR: {value: 0.001, lower: 0}\n"
                "  initial_water: {value: 150, lower: 0}\n"
                "  dry_mass: {value: 300, lower: 0}\n"
                "  pot_capacity: {value: 100, lower: 1}\n"
                "  pot_conductance: {value: 1.0e-2, lower: 0}\n"
                "datasets:\n"
                "  - kind: weight_curve\n"
                "    name: pot\n"
                "    plant: %sseedling.csv\n"
                "    conductance: reference_2024\n"
                "    file: %spot_balance.csv\n"
                "    time: {column: timestamp, timezone: Europe/Berlin}\n"
                "    mass: {column: mass_g, unit: g}\n"
                "    sigma: 0.02\n"
                "    covariates: {columns: [PAR], law: linear}\n"
                "    pot: {}\n",
                EX, EX);
        fclose(f);
        pb = load(path);
        CHECK(pb != NULL);
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
        remove(path);
    }
    (void)err;
    return check_finish("test_weight_curve_pot");
}
