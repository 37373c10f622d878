/* The bundled example (scripts/demo's main job) keeps giving the answer an
 * independent tool gives: SciPy 1.10 curve_fit (Levenberg–Marquardt,
 * tolerances 1e-15, sigma = 5, absolute_sigma = False) on the same CSV:
 *   vmax = 205.661507 +- 2.34872191, km = 0.0614254976 +- 0.00252545.
 * Also: the run directory is written whole, and `report` reads it back. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "fit/config.h"
#include "fit/engine/fit.h"
#include "fit/result_json.h"
#include "fit/run_dir.h"
#include "fit/simulate.h"

static const phc_param_result *param(const phc_fit_result *r, const char *name)
{
    for (size_t i = 0; i < r->n_params; ++i)
        if (strcmp(r->params[i].name, name) == 0)
            return &r->params[i];
    return NULL;
}

int main(void)
{
    const char *config = PHC_SOURCE_DIR "/measurements/examples/enzyme_kinetics/enzyme.yaml";
    phc_error err;
    phc_error_clear(&err);
    phc_problem *pb = NULL;
    CHECK(phc_config_load(config, &pb, &err) == PHC_OK);
    if (!pb) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    /* simulate: the model at the start values, written whole */
    char sim_root[] = "/tmp/phc-simulate-XXXXXX";
    CHECK(mkdtemp(sim_root) != NULL);
    char sim[300], sim_file[400];
    snprintf(sim, sizeof sim, "%s/sim", sim_root);
    CHECK(phc_simulate_write(pb, NULL, sim, 0, &err) == PHC_OK);
    struct stat sst;
    snprintf(sim_file, sizeof sim_file, "%s/assay_simulated.csv", sim);
    CHECK(stat(sim_file, &sst) == 0 && sst.st_size > 0);
    snprintf(sim_file, sizeof sim_file, "%s/assay_simulated.png", sim);
    CHECK(stat(sim_file, &sst) == 0 && sst.st_size > 0);
    CHECK(phc_simulate_write(pb, NULL, sim, 0, &err) == PHC_ERR_EXISTS);
    CHECK(phc_simulate_write(pb, NULL, sim, 1, &err) == PHC_OK);
    char sim_cmd[400];
    snprintf(sim_cmd, sizeof sim_cmd, "rm -rf %s", sim_root);
    if (system(sim_cmd) != 0)
        fprintf(stderr, "warning: could not remove %s\n", sim_root);

    phc_fit_result *res = NULL;
    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    phc_problem_free(pb);
    if (!res)
        return 1;
    const phc_param_result *vmax = param(res, "vmax"), *km = param(res, "km");
    CHECK(vmax && km);
    if (vmax && km) {
        CHECK_NEAR(vmax->value, 205.661507, 0, 1e-7);
        CHECK_NEAR(km->value, 0.0614254976, 0, 1e-7);
        CHECK_NEAR(vmax->stderr_, 2.34872191, 0, 1e-5);
        CHECK_NEAR(km->stderr_, 0.00252545, 0, 1e-5);
        /* the generating values lie inside the 95% intervals */
        CHECK(vmax->ci_lo < 210 && 210 < vmax->ci_hi);
        CHECK(km->ci_lo < 0.065 && 0.065 < km->ci_hi);
    }
    CHECK(res->summary.outcome == PHC_NLS_CONVERGED);
    CHECK(res->starts == 8 && res->starts_at_best == 8);
    CHECK(res->n_warnings == 0);

    char dir[] = "/tmp/phc-enzyme-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char out[256], path[512];
    snprintf(out, sizeof out, "%s/run", dir);
    CHECK(phc_run_dir_write(res, NULL, out, 0, &err) == PHC_OK);
    const char *files[] = {"result.json", "report.md", "assay_fit.png", "assay_residuals.png", "assay_qq.png",
                           "assay_acf.png"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; ++i) {
        struct stat st;
        snprintf(path, sizeof path, "%s/%s", out, files[i]);
        CHECK(stat(path, &st) == 0 && st.st_size > 0);
    }
    /* a second write without force is refused and leaves the run intact */
    CHECK(phc_run_dir_write(res, NULL, out, 0, &err) == PHC_ERR_EXISTS);
    phc_fit_result *back = NULL;
    snprintf(path, sizeof path, "%s/result.json", out);
    CHECK(phc_result_read_json(path, &back, &err) == PHC_OK);
    if (back) {
        CHECK_NEAR(param(back, "vmax")->value, vmax->value, 0, 1e-15);
        CHECK(back->n_warnings == res->n_warnings);
        for (size_t c = 0; c < PHC_CHECK_COUNT; ++c) {
            /* not applicable (daily_cycle: the assay is not a time series): NAN both times */
            if (!res->datasets[0].checks[c].applicable) {
                CHECK(!back->datasets[0].checks[c].applicable && isnan(back->datasets[0].checks[c].p_value));
                continue;
            }
            CHECK_NEAR(back->datasets[0].checks[c].p_value, res->datasets[0].checks[c].p_value, 1e-12, 1e-9);
        }
    }
    phc_fit_result_free(back);
    phc_fit_result_free(res);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "warning: could not remove %s\n", dir);
    return check_finish("regression/enzyme_example");
}
