/* The R package photosynthesis's own example, analysed with its conventions
 * (`convention: photosynthesis`, fit/costs/pv_curve.h) and compared with the
 * values the package documents.
 *
 * Data: ../shared/data/pressure_volume/photosynthesis_PV_curve.csv (the
 * package's inst/extdata/PV_curve.csv: leaves L2, L3, L4, 8 points each).
 * Documented values, leaf L2: the package's vignette "pressure-volume"
 * (https://stat.ethz.ch/CRAN/web/packages/photosynthesis/vignettes/
 * pressure-volume.html), which prints for fit_PV_curve(filter(dat, ID ==
 * "L2")):
 *        SWC      PI_o psi_TLP  RWC_TLP      eps       C_FT      C_TLP  C_FTStar
 *   2.438935 -1.399302   -1.75 88.67684 12.20175 0.06456207 0.09923338 0.5161476
 * The vignette prints 7 significant digits; the test asks for agreement to
 * 5e-7 relative (half a unit in the 7th digit, rounded up).
 * The other two leaves are printed with the package's conventions and with
 * phytocal's defaults side by side (the README's conventions table). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "fit/config.h"
#include "fit/costs/pv_curve.h"
#include "fit/engine/problem.h"

static phc_problem *load(const char *dir, const char *data, const char *convention)
{
    char cfg[600];
    snprintf(cfg, sizeof cfg, "%s/pv_%s.yaml", dir, convention);
    FILE *f = fopen(cfg, "w");
    if (!f)
        return NULL;
    fprintf(f,
            "name: photosynthesis-%s\n"
            "parameters:\n  kappa: {value: 20, lower: 0}\n  chi0: {value: 0.85}\n  e_min: {value: 0, fixed: true}\n"
            "  e_max: {value: 10, lower: 0}\n"
            "datasets:\n  - kind: pv_curve\n    file: %s/photosynthesis_PV_curve.csv\n    psi: psi\n"
            "    fresh_mass: mass\n    bag_mass: bag_mass\n    dry_mass: leaf_mass\n"
            "    saturated_mass: extrapolate\n    leaf_area: leaf_area\n    group: ID\n    leaf: pooled\n"
            "    convention: %s\n",
            convention, data, convention);
    fclose(f);
    phc_error err;
    phc_problem *pb = NULL;
    if (phc_config_load(cfg, &pb, &err) != PHC_OK)
        fprintf(stderr, "%s\n", err.message);
    return pb;
}

/* The package's eight numbers of leaf i from the data set's values. */
typedef struct eight {
    double swc, pi_o, psi_tlp, rwc_tlp, eps, c_ft, c_tlp, c_star;
} eight;

static double number_after(const char *json, const char *leaf, const char *key)
{
    char pat[96];
    snprintf(pat, sizeof pat, "\"%s\": {", leaf);
    const char *p = strstr(json, pat);
    if (!p)
        return NAN;
    snprintf(pat, sizeof pat, "\"%s\": {\"value\": ", key);
    p = strstr(p, pat);
    return p ? strtod(p + strlen(pat), NULL) : NAN;
}

static eight values(const phc_problem *pb, const char *leaf)
{
    eight e = {NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN};
    char *json = NULL;
    phc_error err;
    if (phc_pv_curve_values_json(pb->datasets[0], &json, &err) != PHC_OK)
        return e;
    e.swc = number_after(json, leaf, "swc");
    e.pi_o = number_after(json, leaf, "pi_o");
    e.psi_tlp = number_after(json, leaf, "psi_tlp");
    e.rwc_tlp = number_after(json, leaf, "rwc_tlp_percent");
    e.eps = number_after(json, leaf, "epsilon");
    e.c_ft = number_after(json, leaf, "c_ft");
    e.c_tlp = number_after(json, leaf, "c_tlp");
    e.c_star = number_after(json, leaf, "c_ft_star");
    free(json);
    return e;
}

static void print_row(const char *what, const eight *e)
{
    printf("%-26s %9.6g %9.6g %8.4g %9.6g %9.6g %10.6g %10.6g %9.6g\n", what, e->swc, e->pi_o, e->psi_tlp,
           e->rwc_tlp, e->eps, e->c_ft, e->c_tlp, e->c_star);
}

int main(void)
{
    const char *data = PHC_SHARED_DATA "/pressure_volume";
    struct stat st;
    char file[512];
    snprintf(file, sizeof file, "%s/photosynthesis_PV_curve.csv", data);
    if (stat(file, &st) != 0) {
        printf("SKIP: %s is absent (../shared/data)\n", file);
        return 0;
    }
    char dir[] = "/tmp/phc_pv_photosynthesis_XXXXXX";
    if (!mkdtemp(dir)) {
        CHECK(0);
        return check_finish("pv_photosynthesis");
    }
    phc_problem *pkg = load(dir, data, "photosynthesis"), *ours = load(dir, data, "phytocal");
    CHECK(pkg && ours);
    if (pkg && ours) {
        const eight doc = {2.438935, -1.399302, -1.75, 88.67684, 12.20175, 0.06456207, 0.09923338, 0.5161476};
        printf("%-26s %9s %9s %8s %9s %9s %10s %10s %9s\n", "leaf L2", "SWC", "PI_o", "psi_TLP", "RWC_TLP", "eps",
               "C_FT", "C_TLP", "C_FTStar");
        print_row("the package's vignette", &doc);
        const eight got = values(pkg, "L2");
        print_row("convention: photosynthesis", &got);
        const double *a = &doc.swc, *b = &got.swc;
        double worst = 0;
        for (int k = 0; k < 8; ++k)
            worst = fmax(worst, fabs(b[k] - a[k]) / fabs(a[k]));
        printf("largest relative difference from the vignette: %.2e (it prints 7 digits)\n", worst);
        CHECK(worst < 5e-7);
        printf("\nphytocal's defaults (min_rss, tlp fitted, modulus above the break) on the same leaves:\n");
        static const char *const leaves[] = {"L2", "L3", "L4"};
        for (int i = 0; i < 3; ++i) {
            char what[64];
            const eight p = values(pkg, leaves[i]), q = values(ours, leaves[i]);
            snprintf(what, sizeof what, "%s photosynthesis", leaves[i]);
            print_row(what, &p);
            snprintf(what, sizeof what, "%s phytocal", leaves[i]);
            print_row(what, &q);
            CHECK(fabs(p.swc - q.swc) < 1e-12 * p.swc); /* the same saturated water */
            CHECK(isfinite(q.pi_o) && isfinite(q.psi_tlp) && isfinite(q.eps) && isfinite(q.c_ft));
        }
    }
    phc_problem_free(pkg);
    phc_problem_free(ours);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    return check_finish("pv_photosynthesis");
}
