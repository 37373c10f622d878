/* Real data: one Arabidopsis pot (Col-0, C2M43-7) on the PHENOPSIS balance,
 * PhenoLeaks experiment C2M43A (Westgeest et al. 2023, Plant Cell 35:3444;
 * GPL-3.0 data in measurements/examples/phenoleaks/, the upstream raw file
 * unchanged).  3.7 days without irrigation, weighings every 30-60 min,
 * lights 08:05-20:05 on the robot's winter-time clock (Etc/GMT-1).
 *
 * 1. pot.yaml (day and night, a pot of fixed capacity) loads the 112
 *    weighings and converges; night_factor is below 1 with its whole 95%
 *    interval, delta positive with a finite interval, and the daily_cycle
 *    check passes.
 * 2. pot_constant.yaml (one constant loss, no pot) converges but fails the
 *    daily_cycle check.
 * 3. The day/night fit has the much larger daily_cycle p-value and the
 *    lower RMSE.
 * What the data do NOT support (so it is not checked): white residuals.
 * The rosette grows from 13.9 to 23.1 cm2 over the stretch, the loss rate
 * rises by about half, and the model's leaf area is fixed, so the runs,
 * Durbin-Watson and Ljung-Box checks fail for both fits. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "fit/config.h"
#include "fit/engine/fit.h"

#define EX PHC_SOURCE_DIR "/measurements/examples/phenoleaks/"

static const phc_param_result *param(const phc_fit_result *r, const char *name)
{
    for (size_t i = 0; i < r->n_params; ++i)
        if (strcmp(r->params[i].name, name) == 0)
            return &r->params[i];
    return NULL;
}

static phc_fit_result *load_and_fit(const char *path)
{
    phc_error err;
    phc_problem *pb = NULL;
    phc_fit_result *res = NULL;
    if (phc_config_load(path, &pb, &err) != PHC_OK) {
        fprintf(stderr, "%s: %s\n", path, err.message);
        return NULL;
    }
    printf("%s: %zu weighings\n", path, pb->datasets[0]->n);
    CHECK(pb->datasets[0]->n == 112);
    if (phc_fit_run(pb, NULL, NULL, &res, &err) != PHC_OK)
        fprintf(stderr, "fit: %s\n", err.message);
    phc_problem_free(pb);
    return res;
}

static void show(const char *title, const phc_fit_result *res)
{
    printf("%s: %s\n", title, phc_fit_status_name(res->summary.outcome));
    for (size_t i = 0; i < res->n_params; ++i) {
        const phc_param_result *p = &res->params[i];
        printf("  %-14s %.6g ± %.3g  95%% [%.6g, %.6g] %s\n", p->name, p->value, p->stderr_, p->ci_lo,
               p->ci_hi, p->unit ? p->unit : "");
    }
    const phc_dataset_result *d = &res->datasets[0];
    printf("  RMSE %.4f g, daily_cycle p = %.3g (%s)\n", d->goodness.rmse,
           d->checks[PHC_CHECK_DAILY_CYCLE].p_value, d->checks[PHC_CHECK_DAILY_CYCLE].pass ? "pass" : "FAIL");
}

int main(void)
{
    phc_fit_result *dn = load_and_fit(EX "pot.yaml");
    phc_fit_result *cst = load_and_fit(EX "pot_constant.yaml");
    CHECK(dn != NULL && cst != NULL);
    if (!dn || !cst) {
        phc_fit_result_free(dn);
        phc_fit_result_free(cst);
        return check_finish("test_weight_curve_phenoleaks");
    }
    show("day and night, pot", dn);
    show("one constant loss", cst);

    /* 1. day and night */
    CHECK(dn->summary.outcome == PHC_NLS_CONVERGED);
    const phc_param_result *nf = param(dn, "night_factor"), *delta = param(dn, "delta");
    CHECK(nf != NULL && delta != NULL);
    if (nf && delta) {
        CHECK(nf->value > 0.2 && nf->value < 1.0);
        CHECK(isfinite(nf->ci_hi) && nf->ci_hi < 1.0 && nf->ci_lo > 0.0);
        CHECK(delta->value > 0 && isfinite(delta->ci_lo) && delta->ci_lo > 0);
    }
    const phc_check_result *c_dn = &dn->datasets[0].checks[PHC_CHECK_DAILY_CYCLE];
    CHECK(c_dn->applicable && c_dn->pass);

    /* 2. one constant loss */
    CHECK(cst->summary.outcome == PHC_NLS_CONVERGED);
    const phc_check_result *c_cst = &cst->datasets[0].checks[PHC_CHECK_DAILY_CYCLE];
    CHECK(c_cst->applicable && !c_cst->pass);

    /* 3. the comparison */
    CHECK(c_dn->p_value > 10 * c_cst->p_value);
    CHECK(dn->datasets[0].goodness.rmse < cst->datasets[0].goodness.rmse);

    phc_fit_result_free(dn);
    phc_fit_result_free(cst);
    return check_finish("test_weight_curve_phenoleaks");
}
