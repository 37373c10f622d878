/* The analytic Jacobians of the soil data sets (fit/costs/soil_probe.c,
 * fit/costs/infiltration.c) against central differences of their own
 * predictions: probes reading w and w/c in a two-layer soil with per-layer
 * p and c and the forces f_diff and f_grav as slots, and an infiltration
 * front.  The configs and data are written to a temporary directory. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "fit/config.h"

static char dir[] = "/tmp/phc_soil_ds_XXXXXX";

static void write_file(const char *name, const char *text)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fputs(text, f);
    fclose(f);
}

/* Loads config `name`, compares every data set's Jacobian with central
 * differences (relative step 1e-6) at the start values. */
static void check_config(const char *name, const char *label)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    phc_problem *pb = NULL;
    phc_error err;
    phc_error_clear(&err);
    int rc = phc_config_load(path, &pb, &err);
    CHECK(rc == PHC_OK);
    if (rc) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    for (size_t d = 0; d < pb->n_datasets; ++d) {
        phc_dataset *ds = pb->datasets[d];
        const size_t n = ds->n, k = ds->k;
        double *p = malloc(k * sizeof *p), *y = malloc(n * sizeof *y), *jac = malloc(n * k * sizeof *jac);
        double *yp = malloc(n * sizeof *yp), *ym = malloc(n * sizeof *ym);
        for (size_t j = 0; j < k; ++j)
            p[j] = pb->params[ds->param_index[j]].value;
        CHECK(ds->ops->predict(ds, p, y, jac) == 0);
        double worst = 0;
        for (size_t j = 0; j < k; ++j) {
            const double h = 1e-6 * fabs(p[j]), keep = p[j];
            p[j] = keep + h;
            CHECK(ds->ops->predict(ds, p, yp, NULL) == 0);
            p[j] = keep - h;
            CHECK(ds->ops->predict(ds, p, ym, NULL) == 0);
            p[j] = keep;
            double scale = 0, diff = 0;
            for (size_t i = 0; i < n; ++i) {
                const double fd = (yp[i] - ym[i]) / (2 * h);
                scale = fmax(scale, fabs(fd));
                diff = fmax(diff, fabs(fd - jac[i * k + j]));
            }
            const double rel = diff / (scale > 0 ? scale : 1);
            printf("%s: d/d %-7s max |analytic - central| = %.3g of max |d/d| %.3g\n", label, ds->slot_names[j], rel,
                   scale);
            CHECK(scale > 0); /* every slot moves the predictions */
            worst = fmax(worst, rel);
        }
        CHECK(worst < 1e-6);
        free(p);
        free(y);
        free(jac);
        free(yp);
        free(ym);
    }
    phc_problem_free(pb);
}

int main(void)
{
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    write_file("probes.csv", "id,x,y,depth\nA,0.01,0.01,0.05\nB,0.01,0.01,0.17\nC,0.01,0.01,0.31\n");
    write_file("readings.csv", "t,probe,v\n0.5,A,0.03\n0.5,B,0.02\n1,A,0.02\n1,C,0.01\n2,B,0.02\n2,C,0.02\n");
    write_file("front.csv", "t,d\n0.5,0.02\n1,0.04\n1.5,0.05\n2,0.07\n2.5,0.08\n3,0.1\n3.5,0.11\n");
    static const char *const soil =
        "    soil:\n"
        "      grid: {nx: 1, ny: 1, nz: 25, dx: 0.02}\n"
        "      dt: 0.005\n"
        "      substep: false\n"
        "      boundaries: {sides: periodic, bottom: absorb, top: block}\n"
        "      layers:\n"
        "        - {c: 40, p: 0.04, thickness: 0.15, fill: 5.0e-4}\n"
        "        - {c: 15, p: 0.01, fill: 1.0e-3}\n"
        "      rain: [{start: 0, end: 1, rate: 0.01}]\n";
    static const char *const params =
        "parameters:\n"
        "  p_1: {value: 0.04}\n  c_1: {value: 40}\n  p_2: {value: 0.01}\n  c_2: {value: 15}\n"
        "  f_diff: {value: 0.8}\n  f_grav: {value: 1.2}\n";
    char text[4096];
    for (int fill = 0; fill < 2; ++fill) {
        snprintf(text, sizeof text,
                 "name: t\n%sdatasets:\n  - kind: soil_probe\n    file: readings.csv\n    time: {column: t, unit: h}\n"
                 "    probe: probe\n    value: v\n    quantity: %s\n    sigma: 0.002\n    probes: {file: probes.csv}\n%s",
                 params, fill ? "fill" : "water", soil);
        write_file(fill ? "fill.yaml" : "water.yaml", text);
    }
    snprintf(text, sizeof text,
             "name: t\n%sdatasets:\n  - kind: infiltration\n    file: front.csv\n    time: {column: t, unit: h}\n"
             "    depth: {column: d, unit: m}\n    fraction: 0.8\n    sigma: 0.01\n%s",
             params, soil);
    write_file("front.yaml", text);
    check_config("water.yaml", "soil_probe w");
    check_config("fill.yaml", "soil_probe w/c");
    check_config("front.yaml", "infiltration");
    const char *files[] = {"probes.csv", "readings.csv", "front.csv", "water.yaml", "fill.yaml", "front.yaml"};
    char path[256];
    for (size_t i = 0; i < sizeof files / sizeof files[0]; ++i) {
        snprintf(path, sizeof path, "%s/%s", dir, files[i]);
        unlink(path);
    }
    rmdir(dir);
    return check_finish("test_soil_datasets");
}
