/* Parameter units through a config (fit/engine/parameter_units.h): the bundled
 * pressure-volume example fitted with e_max given in MPa (the unit pv_curve
 * declares for e_min and e_max) and again in bar (start 50 bar = 5 MPa).
 * The fitted value and its standard error must come back 10x larger in bar,
 * result and model otherwise the same; e_max in metres is an error naming
 * the parameter's config line. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "fit/config.h"
#include "fit/engine/fit.h"

static char dir[] = "/tmp/phc_units_pv_XXXXXX";

static int load(const char *e_max, phc_problem **pb, phc_error *err)
{
    char path[256];
    snprintf(path, sizeof path, "%s/pv.yaml", dir);
    FILE *f = fopen(path, "w");
    if (!f)
        return PHC_ERR_IO;
    fprintf(f,
            "name: pv-units\n"
            "parameters:\n"
            "  kappa: {value: 20, lower: 0, upper: 500}\n"
            "  chi0:  {value: 0.85, lower: 0.3, upper: 1.2}\n"
            "  e_min: {value: 0, fixed: true}\n"
            "  e_max: %s\n"
            "datasets:\n"
            "  - kind: pv_curve\n"
            "    file: %s/measurements/examples/pressure_volume/pv_leaves.csv\n"
            "    psi: psi_MPa\n"
            "    psi_unit: MPa\n"
            "    fresh_mass: fresh_g\n"
            "    dry_mass: dry_g\n"
            "    saturated_mass: saturated_g\n"
            "    group: leaf\n"
            "    leaf: pooled\n"
            "solver:\n"
            "  starts: 8\n",
            e_max, PHC_SOURCE_DIR);
    fclose(f);
    return phc_config_load(path, pb, err);
}

static const phc_param_result *fit(const char *e_max, phc_fit_result **res)
{
    phc_problem *pb = NULL;
    phc_error err;
    phc_error_clear(&err);
    *res = NULL;
    if (load(e_max, &pb, &err) || phc_fit_run(pb, NULL, NULL, res, &err)) {
        fprintf(stderr, "%s\n", err.message);
        CHECK(0);
        phc_problem_free(pb);
        return NULL;
    }
    phc_problem_free(pb);
    for (size_t i = 0; i < (*res)->n_params; ++i)
        if (strcmp((*res)->params[i].name, "e_max") == 0)
            return &(*res)->params[i];
    return NULL;
}

int main(void)
{
    if (!mkdtemp(dir))
        return 1;
    phc_fit_result *r_mpa = NULL, *r_bar = NULL;
    const phc_param_result *mpa = fit("{value: 5, lower: 0, unit: MPa}", &r_mpa);
    const phc_param_result *bar = fit("{value: 50, lower: 0, unit: bar}", &r_bar);
    const phc_param_result *none = NULL;
    phc_fit_result *r_none = NULL;
    none = fit("{value: 5, lower: 0}", &r_none);
    CHECK(mpa && bar && none);
    if (mpa && bar && none) {
        printf("e_max = %.10g +- %.6g %s; in bar: %.10g +- %.6g %s (ratio %.12g); no unit: %s\n", mpa->value,
               mpa->stderr_, mpa->unit, bar->value, bar->stderr_, bar->unit, bar->value / mpa->value,
               none->unit ? none->unit : "(none)");
        CHECK_NEAR(bar->value, 10 * mpa->value, 0, 1e-7);
        CHECK_NEAR(bar->stderr_, 10 * mpa->stderr_, 0, 1e-6);
        CHECK_NEAR(bar->start, 50, 0, 1e-12);
        CHECK(strcmp(bar->unit, "bar") == 0);
        CHECK(none->unit && strcmp(none->unit, "MPa") == 0); /* the slot's unit */
        CHECK_NEAR(r_bar->cost, r_mpa->cost, 0, 1e-8);
    }
    phc_fit_result_free(r_mpa);
    phc_fit_result_free(r_bar);
    phc_fit_result_free(r_none);

    phc_problem *pb = NULL;
    phc_error err;
    CHECK(load("{value: 5, lower: 0, unit: m}", &pb, &err) == PHC_ERR_INPUT);
    printf("wrong dimension: %s\n", err.message);
    CHECK(strstr(err.message, "pv.yaml:6: parameter 'e_max': unit: 'm' cannot be converted to 'MPa'") != NULL);
    phc_problem_free(pb);

    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    return check_finish("test_parameter_units_pv");
}
