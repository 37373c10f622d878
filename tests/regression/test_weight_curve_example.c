/* The bundled weight-curve example (scripts/demo's main job):
 * measurements/examples/weight_curve/, made by generate.py from the
 * project-authored seedling graph with delta = 2.0e-3 s-1 cm-2, initial water
 * 12 g, dry mass 2.5 g, watered with 6 g after 24 h, balance noise 0.01 g.
 *
 * 1. The model agrees with generate.py's independent implementation (NumPy,
 *    deflated slow mode; see its docstring): without noise, the mass at
 *    24 h is 6.314818921820 g there (printed by
 *    `python3 -c "import generate as g; ..."`, see the README).
 * 2. The fit recovers every generating value inside its 95% interval, and
 *    the residual checks pass (the data are the model plus white noise). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "fit/config.h"
#include "fit/engine/fit.h"

static const phc_param_result *param(const phc_fit_result *r, const char *name)
{
    for (size_t i = 0; i < r->n_params; ++i)
        if (strcmp(r->params[i].name, name) == 0)
            return &r->params[i];
    return NULL;
}

int main(void)
{
    const char *config = PHC_SOURCE_DIR "/measurements/examples/weight_curve/seedling.yaml";
    phc_error err;
    phc_error_clear(&err);
    phc_problem *pb = NULL;
    CHECK(phc_config_load(config, &pb, &err) == PHC_OK);
    if (!pb) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    CHECK(pb->n_datasets == 1);
    phc_dataset *ds = pb->datasets[0];
    CHECK(ds->n == 577 && ds->k == 4);
    CHECK(strcmp(ds->slot_names[2], "initial_water_2") == 0);

    /* 1. noiseless model at the generating values against generate.py */
    double truth[4] = {2.0e-3, 12.0, 9.814818921820, 2.5}; /* slot order: delta, w0, w0_2, dry */
    double yhat[577];
    CHECK(ds->ops->predict(ds, truth, yhat, NULL) == 0);
    size_t at24 = 288; /* weighings every 5 min: 24 h is row 288 */
    CHECK_NEAR(ds->x[at24], 24.0, 1e-9, 0);
    CHECK_NEAR(yhat[at24], 6.314818921820, 0, 1e-9);
    printf("model at 24 h: %.12f g (generate.py, independent: 6.314818921820 g)\n", yhat[at24]);

    /* 2. the fit */
    phc_fit_result *res = NULL;
    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    phc_problem_free(pb);
    if (!res) {
        fprintf(stderr, "%s\n", err.message);
        return check_finish("test_weight_curve_example");
    }
    CHECK(res->summary.outcome == PHC_NLS_CONVERGED);
    const char *names[4] = {"delta", "initial_water", "initial_water_2", "dry_mass"};
    /* initial_water_2's true value: the water left at 24 h plus 6 g (3.814818921820 + 6) */
    const double want[4] = {2.0e-3, 12.0, 9.814818921820, 2.5};
    for (int i = 0; i < 4; ++i) {
        const phc_param_result *p = param(res, names[i]);
        CHECK(p != NULL);
        if (!p)
            continue;
        printf("%-16s %.6g ± %.3g  95%% [%.6g, %.6g]  truth %g\n", names[i], p->value, p->stderr_,
               p->ci_lo, p->ci_hi, want[i]);
        CHECK(p->ci_lo < want[i] && want[i] < p->ci_hi);
    }
    const phc_dataset_result *d = &res->datasets[0];
    CHECK_NEAR(d->goodness.rmse, 0.01, 0.0015, 0);
    for (int c = 0; c < PHC_CHECK_COUNT; ++c)
        CHECK(d->checks[c].pass);
    CHECK(d->curve_n > 0); /* the fitted curve for the plot, across both pieces */
    phc_fit_result_free(res);
    return check_finish("test_weight_curve_example");
}
