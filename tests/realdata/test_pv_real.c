/* Real pressure–volume curves from ../shared/data/pressure_volume through the
 * pv_curve kind (the same path as a user's config):
 *  - photosynthesis_PV_curve.csv (R package photosynthesis, C. Muir): 3 leaves
 *    × 8 points; psi in MPa; mass = leaf + bag (g), bag_mass (g), leaf_mass =
 *    the leaf's DRY mass (g; fit_PV_curve computes leaf water as mass −
 *    leaf_mass − bag_mass and reports saturated water content per leaf dry
 *    mass); no saturated mass: it is extrapolated to ψ = 0 as fit_PV_curve
 *    does.
 *  - pvldcurve_pressure_volume.csv (R package pvldcurve 1.2.6, A. Raesch):
 *    kohlrabi leaves, water.potential in bar (all negative), fresh.weight,
 *    dry.weight, fresh.weight.saturated (g).  Its documentation says samples
 *    1–12; the file holds 16 (ids 1–16, two dates) and all are analysed.
 * Neither package publishes numerical PV parameters for these data (the
 * vignettes show plots only), so the checks are physiological plausibility:
 * π_o in [−3, −0.3] MPa, ψ_tlp below π_o and above −4 MPa, RWC_tlp in
 * (0.6, 1), ε in (0, 60] MPa, finite positive standard errors, and a warning
 * wherever the apoplastic fraction leaves [0, 1).  The tables are printed. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "fit/config.h"
#include "fit/costs/pv_curve.h"
#include "fit/engine/fit.h"

static const char *params_block = "parameters:\n"
                                  "  kappa: {value: 20, lower: 0, upper: 1000}\n"
                                  "  chi0:  {value: 0.85, lower: 0.3, upper: 1.2}\n"
                                  "  e_min: {value: 0, fixed: true}\n"
                                  "  e_max: {value: 10, lower: 0}\n";

static void run(const char *dir, const char *name, const char *dataset, size_t want_leaves, int af_strict)
{
    char cfg[600];
    snprintf(cfg, sizeof cfg, "%s/%s.yaml", dir, name);
    FILE *f = fopen(cfg, "w");
    if (!f) {
        CHECK(0);
        return;
    }
    fprintf(f, "name: %s\n%sdatasets:\n%s", name, params_block, dataset);
    fclose(f);
    phc_error err;
    phc_problem *pb = NULL;
    CHECK(phc_config_load(cfg, &pb, &err) == PHC_OK);
    if (!pb) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    const phc_dataset *ds = pb->datasets[0];
    CHECK(phc_pv_curve_leaf_count(ds) == want_leaves);
    char *md = NULL;
    CHECK(phc_pv_curve_markdown(ds, &md, &err) == PHC_OK);
    if (md)
        printf("%s\n", md);
    free(md);
    for (size_t i = 0; i < phc_pv_curve_leaf_count(ds); ++i) {
        const char *label = NULL;
        const phc_pv_result *r = phc_pv_curve_leaf(ds, i, &label);
        if (!r)
            continue;
        const int ok_pi = r->pi_o.value >= -3 && r->pi_o.value <= -0.3;
        const int ok_tlp = r->psi_tlp.value < r->pi_o.value && r->psi_tlp.value > -4;
        const int ok_rwc = r->rwc_tlp.value > 0.6 && r->rwc_tlp.value < 1;
        const int ok_eps = r->epsilon.value > 0 && r->epsilon.value <= 60;
        const int ok_se = r->pi_o.stderr_ > 0 && r->psi_tlp.stderr_ > 0 && r->rwc_tlp.stderr_ > 0 &&
                          r->epsilon.stderr_ > 0 && r->apoplastic_fraction.stderr_ > 0;
        const int af_in = r->apoplastic_fraction.value >= 0 && r->apoplastic_fraction.value < 1;
        if (!(ok_pi && ok_tlp && ok_rwc && ok_eps && ok_se))
            fprintf(stderr, "%s leaf %s: implausible PV parameters\n", name, label);
        CHECK(ok_pi);
        CHECK(ok_tlp);
        CHECK(ok_rwc);
        CHECK(ok_eps);
        CHECK(ok_se);
        CHECK(af_in == !(r->warnings & PHC_PV_WARN_APOPLAST_RANGE));
        if (af_strict)
            CHECK(af_in);
    }
    /* the pooled logistic elasticity over every leaf's moduli */
    phc_fit_result *res = NULL;
    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    if (res) {
        printf("%s: pooled logistic elasticity over %zu moduli (%s):\n", name, ds->n,
               res->summary.outcome == PHC_NLS_CONVERGED ? "converged" : "NOT converged");
        for (size_t i = 0; i < res->n_params; ++i)
            printf("  %-6s %10.4g ± %.3g\n", res->params[i].name, res->params[i].value, res->params[i].stderr_);
        printf("\n");
        CHECK(res->summary.outcome == PHC_NLS_CONVERGED);
    }
    phc_fit_result_free(res);
    phc_problem_free(pb);
}

int main(void)
{
    const char *data = PHC_SHARED_DATA "/pressure_volume";
    struct stat st;
    if (stat(data, &st) != 0 || !S_ISDIR(st.st_mode)) {
        printf("skipped: %s is absent (real reference data live beside the project in ../shared/data)\n", data);
        return 77;
    }
    char dir[] = "/tmp/phc-pvreal-XXXXXX";
    if (!mkdtemp(dir))
        return 1;
    char ds[1200];
    snprintf(ds, sizeof ds,
             "  - kind: pv_curve\n    name: muir\n    file: %s/photosynthesis_PV_curve.csv\n"
             "    psi: psi\n    psi_unit: MPa\n    fresh_mass: mass\n    bag_mass: bag_mass\n"
             "    dry_mass: leaf_mass\n    saturated_mass: extrapolate\n    group: ID\n    leaf: pooled\n",
             data);
    run(dir, "photosynthesis_pv", ds, 3, 1);
    snprintf(ds, sizeof ds,
             "  - kind: pv_curve\n    name: kohlrabi\n    file: %s/pvldcurve_pressure_volume.csv\n"
             "    psi: water.potential\n    psi_unit: bar\n    fresh_mass: fresh.weight\n"
             "    dry_mass: dry.weight\n    saturated_mass: fresh.weight.saturated\n    group: sample\n"
             "    leaf: pooled\n",
             data);
    run(dir, "pvldcurve_pv", ds, 16, 0);
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "warning: could not remove %s\n", dir);
    return check_finish("realdata/pv_real");
}
