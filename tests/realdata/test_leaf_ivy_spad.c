/* The leaf colour aging model calibrated on real photographs: 15 ivy leaves
 * (Hedera helix) on one scan, SPAD 59.1 to 2.4 (../shared/data/leaf_photos/
 * ivy_spad), treated as a chronosequence (the example config
 * measurements/examples/leaf_photos/ivy_spad.yaml, with absolute paths).
 *
 * Checks what must hold: the scan gives 15 leaves, the fit converges, the
 * model's colours get closer to the photos than at the start, and the
 * leave-one-out prediction of SPAD from the photo beats predicting the mean
 * SPAD (RMSE below the SPAD standard deviation).  Prints the RMSE of the
 * model and of the greenness baseline measured in the same run. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "fit/config.h"
#include "fit/costs/leaf_photos.h"
#include "fit/engine/fit.h"

int main(void)
{
    const char *dir = PHC_SHARED_DATA "/leaf_photos/ivy_spad";
    char csv[512], scan[512];
    snprintf(csv, sizeof csv, "%s/leaves.csv", dir);
    snprintf(scan, sizeof scan, "%s/ivy_15_leaves_scan.jpg", dir);
    if (access(csv, R_OK) != 0 || access(scan, R_OK) != 0) {
        printf("skipped: %s is absent (the real-data folder ../shared/data is not here)\n", dir);
        return 77;
    }
    char tmp[] = "/tmp/phc_ivy_XXXXXX";
    if (!mkdtemp(tmp)) {
        perror("mkdtemp");
        return 1;
    }
    char cfg[600];
    snprintf(cfg, sizeof cfg, "%s/ivy.yaml", tmp);
    FILE *f = fopen(cfg, "w");
    if (!f)
        return 1;
    fprintf(f,
            "name: ivy-spad\n"
            "parameters:\n"
            "  time_scale: {value: 0.1, fixed: true}\n"
            "  y_lo: {value: 0.2, lower: -2, upper: 2}\n"
            "  y_hi: {value: 0.8, lower: -2, upper: 3}\n"
            "  inflow_scale: {value: 0.05, lower: 0, upper: 1}\n"
            "datasets:\n"
            "  - kind: leaf_photos\n"
            "    name: ivy\n"
            "    file: %s\n"
            "    image: %s\n"
            "    leaf: leaf\n"
            "    stage: {column: spad, direction: decreasing}\n"
            "    initial: 9\n"
            "    reference: 1\n"
            "    residual: histogram\n"
            "    colour_space: lab\n"
            "    quantiles: 12\n"
            "    sigma: 2\n"
            "    model_size: 96\n",
            csv, scan);
    fclose(f);

    phc_error err;
    phc_error_clear(&err);
    phc_problem *pb = NULL;
    phc_fit_result *res = NULL;
    CHECK(phc_config_load(cfg, &pb, &err) == PHC_OK);
    if (!pb) {
        fprintf(stderr, "%s\n", err.message);
        return check_finish("test_leaf_ivy_spad");
    }
    phc_dataset *ds = pb->datasets[0];
    printf("ivy_residuals: %zu (13 leaves x 3 channels x 12 quantiles)\n", ds->n);
    CHECK(ds->n == 13 * 3 * 12);

    /* cost at the start values */
    double *x0 = malloc(pb->n_params * sizeof *x0), *yh = malloc(ds->n * sizeof *yh);
    double *p = malloc(ds->k * sizeof *p);
    for (size_t i = 0; i < pb->n_params; ++i)
        x0[i] = pb->params[i].value;
    for (size_t j = 0; j < ds->k; ++j)
        p[j] = x0[ds->param_index[j]];
    CHECK(ds->ops->predict(ds, p, yh, NULL) == 0);
    double rss0 = 0;
    for (size_t i = 0; i < ds->n; ++i)
        rss0 += pow((ds->y[i] - yh[i]) / ds->sigma[i], 2);

    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    if (!res) {
        fprintf(stderr, "%s\n", err.message);
        goto done;
    }
    CHECK(res->summary.outcome == PHC_NLS_CONVERGED);
    printf("ivy_wrss_start: %.6g\nivy_wrss_fit: %.6g\n", rss0, res->wrss);
    CHECK(res->wrss < rss0);
    for (size_t i = 0; i < res->n_params; ++i)
        printf("ivy_%s: %.6g +- %.3g\n", res->params[i].name, res->params[i].value, res->params[i].stderr_);

    /* leave-one-out prediction of SPAD */
    for (size_t j = 0; j < ds->k; ++j)
        p[j] = res->params[ds->param_index[j]].value;
    size_t n = 0;
    char **ids = NULL;
    double *stage = NULL, *model = NULL, *base = NULL, rmse[2];
    CHECK(phc_leaf_photos_cross_validate(ds, p, &n, &ids, &stage, &model, &base, rmse, &err) == PHC_OK);
    if (ids) {
        double mean = 0, sd = 0;
        for (size_t i = 0; i < n; ++i)
            mean += stage[i] / (double)n;
        for (size_t i = 0; i < n; ++i)
            sd += pow(stage[i] - mean, 2) / (double)(n - 1);
        sd = sqrt(sd);
        for (size_t i = 0; i < n; ++i) {
            if (!isnan(model[i]))
                printf("ivy_loo leaf %s: SPAD %.1f model %.2f baseline %.2f\n", ids[i], stage[i], model[i], base[i]);
            free(ids[i]);
        }
        printf("ivy_spad_sd: %.3f\nivy_loo_rmse_model: %.3f SPAD\nivy_loo_rmse_baseline: %.3f SPAD\n", sd, rmse[0],
               rmse[1]);
        CHECK(isfinite(rmse[0]) && isfinite(rmse[1]));
        CHECK(rmse[0] < sd);
    } else
        fprintf(stderr, "%s\n", err.message);
    free(ids);
    free(stage);
    free(model);
    free(base);
done:
    free(x0);
    free(yh);
    free(p);
    phc_fit_result_free(res);
    phc_problem_free(pb);
    unlink(cfg);
    rmdir(tmp);
    return check_finish("test_leaf_ivy_spad");
}
