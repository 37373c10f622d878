/* The bundled particle example, measurements/examples/plant_motion/
 * stalk_particles.yaml (`dynamics: particles`): two stalks whose angles
 * (stalk_particles.csv) make_stalk_particles.sh wrote from the model at
 * kappa = 12, chi0 = 0.7, e_max = 100 MPa, delta = 2e-4 s-1.
 *
 * 1. The config loads as particles and the model at the generating values
 *    gives the CSV's angles back (to the CSV's 12 digits and the particle
 *    solve's settling, 1e-8 rad).
 * 2. From the config's start (kappa 9, chi0 0.65), with e_max and delta
 *    held at their generating values (as a joint fit with a weight curve
 *    would pin delta; the four-parameter fit of the README takes minutes),
 *    the fit finds kappa and chi0 again. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "fit/config.h"
#include "fit/costs/shape_series.h"
#include "fit/engine/fit.h"

int main(void)
{
    const char *config = PHC_SOURCE_DIR "/measurements/examples/plant_motion/stalk_particles.yaml";
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
    CHECK(ds->n == 10 && ds->k == 4);
    CHECK(strcmp(ds->slot_names[0], "kappa") == 0 && strcmp(ds->slot_names[3], "delta") == 0);

    /* 1. the model at the generating values against the CSV */
    const double truth[4] = {12.0, 0.7, 100e6, 2e-4}; /* kappa, chi0, e_max (Pa), delta (s-1) */
    double yhat[10], s0 = NAN, s1 = NAN;
    CHECK(ds->ops->predict(ds, truth, yhat, NULL) == 0);
    double worst = 0;
    for (size_t i = 0; i < ds->n; ++i)
        worst = fmax(worst, fabs(yhat[i] - ds->y[i]));
    phc_shape_series_stiffness(ds, truth, 0, &s0);
    phc_shape_series_stiffness(ds, truth, 3600, &s1);
    printf("particles at the generating values: stiffness s %.4f -> %.4f over the hour; largest |model - CSV| "
           "%.2g rad\n", s0, s1, worst);
    CHECK(worst < 1e-8);

    /* 2. kappa and chi0 from the config's start */
    for (size_t i = 0; i < pb->n_params; ++i)
        if (strcmp(pb->params[i].name, "e_max") == 0 || strcmp(pb->params[i].name, "delta") == 0) {
            pb->params[i].value = strcmp(pb->params[i].name, "e_max") == 0 ? truth[2] : truth[3];
            pb->params[i].fixed = 1;
        }
    phc_fit_result *res = NULL;
    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    if (!res) {
        fprintf(stderr, "%s\n", err.message);
        phc_problem_free(pb);
        return check_finish("test_stalk_particles_example");
    }
    CHECK(res->summary.outcome == PHC_NLS_CONVERGED);
    printf("fit: %d iterations\n", res->summary.iterations);
    for (size_t i = 0; i < 2; ++i) {
        printf("fitted %-6s %.10g (truth %g, relative error %.2g)\n", res->params[i].name, res->params[i].value,
               truth[i], fabs(res->params[i].value / truth[i] - 1));
        CHECK_NEAR(res->params[i].value, truth[i], 0, 1e-6);
    }
    phc_fit_result_free(res);
    phc_problem_free(pb);
    return check_finish("test_stalk_particles_example");
}
