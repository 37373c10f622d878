/* What makes root:shoot fits cheaper must not change a number, and the
 * report must say which growth preset was used for which species
 * (fit/costs/root_shoot.h, model/growth.h):
 *
 * 1. the Jacobian (its 2k + 1 plants grown in parallel threads) equals,
 *    bit for bit, central differences built by hand from values asked of a
 *    fresh data set one point at a time, with the same steps (2% of each
 *    slot value);
 * 2. asking again at the same slot values is answered by kept trajectories
 *    (the counts say so) with the same bits; so is a request for smaller
 *    diameters (predict_at); after more than 32 other points the first is
 *    grown again, with the same bits;
 * 3. phc_growth_preset_for_species: the genus picks the preset (case
 *    ignored), conifers are named as such, other genera get none;
 * 4. the report names the preset and says plainly when it does not
 *    describe the species (a conifer, a maple fitted with the oak preset),
 *    and when the species is not given. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/costs/root_shoot.h"
#include "model/growth.h"

#define N_PLANTS 4
#define K 3 /* p, c, phi_rg */

static double diameter[N_PLANTS] = {1.5e-3, 1.8e-3, 2.1e-3, 2.4e-3}; /* m */
static double root[N_PLANTS] = {0.2, 0.3, 0.4, 0.5}, shoot[N_PLANTS] = {0.5, 0.5, 0.6, 0.7};
static phc_harvest plants = {.n = N_PLANTS, .diameter = diameter, .root_mass = root, .shoot_mass = shoot,
                             .file = "harvest"};
static phc_soil_setup_layer pot_layer;
static phc_soil_rain pot_rain = {.start = 0, .end = 1e6, .rate = 1e-4};

/* A 20 cm pot of one soil, watered all along; 40 days, slots p, c, phi_rg. */
static phc_dataset *make(const char *preset, const char *species)
{
    static phc_soil_setup_options s;
    s = phc_soil_setup_options_default();
    s.nx = s.ny = s.nz = 4;
    s.dx = 0.05;
    s.params.dt = 1;
    pot_layer = phc_soil_setup_layer_default();
    pot_layer.c = 10;
    pot_layer.p = 0.0015;
    pot_layer.water = 3;
    s.layers = &pot_layer;
    s.n_layers = 1;
    s.rain = &pot_rain;
    s.n_rain = 1;
    phc_root_shoot_options o = phc_root_shoot_options_default();
    o.sigma = 0.35;
    o.days = 40;
    o.soil = &s;
    o.preset = preset;
    o.species = species;
    phc_dataset *ds = NULL;
    phc_error err;
    phc_error_clear(&err);
    if (phc_root_shoot_new(&plants, &o, &ds, &err) != PHC_OK)
        fprintf(stderr, "%s\n", err.message);
    return ds;
}

static int same_bits(const double *a, const double *b, size_t n)
{
    return memcmp(a, b, n * sizeof *a) == 0;
}

static void jacobian_and_reuse(void)
{
    phc_dataset *ds = make(NULL, NULL), *fresh = make(NULL, NULL);
    CHECK(ds && fresh && ds->k == K);
    if (!ds || !fresh || ds->k != K) {
        phc_dataset_free(ds);
        phc_dataset_free(fresh);
        return;
    }
    const double p[K] = {0.0015, 10, 0.6};
    double y[N_PLANTS], J[N_PLANTS * K];
    CHECK(ds->ops->predict(ds, p, y, J) == 0);
    phc_root_shoot_counts c;
    CHECK(phc_root_shoot_counts_get(ds, &c) == PHC_OK);
    printf("one Jacobian: %lu asked, %lu reused, %lu grown, %.0f days, %lu soil sub-steps\n", c.requested,
           c.reused, c.simulated, c.days, c.soil_substeps);
    CHECK(c.requested == 2 * K + 1 && c.reused == 0 && c.simulated == 2 * K + 1 && c.days > 0);

    /* 1. by hand, one point at a time, on a data set that has kept nothing */
    double y0[N_PLANTS], hi[N_PLANTS], lo[N_PLANTS], Jh[N_PLANTS * K];
    CHECK(fresh->ops->predict(fresh, p, y0, NULL) == 0);
    for (int j = 0; j < K; ++j) {
        double q[K];
        memcpy(q, p, sizeof q);
        const double h = 0.02 * fabs(p[j]);
        q[j] = p[j] + h;
        CHECK(fresh->ops->predict(fresh, q, hi, NULL) == 0);
        q[j] = p[j] - h;
        CHECK(fresh->ops->predict(fresh, q, lo, NULL) == 0);
        for (int i = 0; i < N_PLANTS; ++i)
            Jh[i * K + j] = (hi[i] - lo[i]) / (2 * h);
    }
    printf("ln(root:shoot): %.6f %.6f %.6f %.6f; largest plant's d/dp %.6g, d/dc %.6g, d/dphi_rg %.6g\n",
           y[0], y[1], y[2], y[3], J[9], J[10], J[11]);
    CHECK(same_bits(y, y0, N_PLANTS));
    CHECK(same_bits(J, Jh, N_PLANTS * K));
    int finite = 1, moves = 0;
    for (int i = 0; i < N_PLANTS * K; ++i) {
        finite &= isfinite(J[i]);
        moves |= J[i] != 0;
    }
    CHECK(finite && moves); /* a Jacobian of zeros would match trivially */

    /* 2. again: answered by the kept trajectories, same bits */
    double y2[N_PLANTS], J2[N_PLANTS * K];
    CHECK(ds->ops->predict(ds, p, y2, J2) == 0);
    CHECK(phc_root_shoot_counts_get(ds, &c) == PHC_OK);
    CHECK(c.requested == 2 * (2 * K + 1) && c.reused == 2 * K + 1 && c.simulated == 2 * K + 1);
    CHECK(same_bits(y, y2, N_PLANTS) && same_bits(J, J2, N_PLANTS * K));
    /* smaller diameters (x in mm) from the kept trajectory of p */
    const double x[2] = {1.5, 1.8};
    double ya[2];
    CHECK(ds->ops->predict_at(ds, p, x, 2, ya) == 0);
    CHECK(phc_root_shoot_counts_get(ds, &c) == PHC_OK);
    CHECK(c.reused == 2 * K + 2 && c.simulated == 2 * K + 1);
    phc_dataset *third = make(NULL, NULL); /* grows its own plant for them */
    double yb[2] = {NAN, NAN};
    CHECK(third && third->ops->predict_at(third, p, x, 2, yb) == 0);
    CHECK(same_bits(ya, yb, 2));
    CHECK_NEAR(ya[0], y[0], 0, 1e-9); /* x * 1e-3 may differ from the stored diameter in the last bit */
    phc_dataset_free(third);
    /* 40 other points push p out of the 32 kept; it is grown again, same bits */
    for (int a = 0; a < 40; ++a) {
        const double q[K] = {0.0015, 10, 0.3 + 0.005 * a};
        double yq[N_PLANTS];
        CHECK(ds->ops->predict(ds, q, yq, NULL) == 0);
    }
    const unsigned long before = (phc_root_shoot_counts_get(ds, &c), c.simulated);
    CHECK(ds->ops->predict(ds, p, y2, NULL) == 0);
    CHECK(phc_root_shoot_counts_get(ds, &c) == PHC_OK);
    printf("after 40 other points p is grown again: %lu -> %lu plants\n", before, c.simulated);
    CHECK(c.simulated == before + 1 && same_bits(y, y2, N_PLANTS));
    CHECK(phc_root_shoot_counts_get(NULL, &c) == PHC_ERR_INVALID);
    phc_dataset_free(ds);
    phc_dataset_free(fresh);
}

static void preset_lookup(void)
{
    const char *group = NULL;
    CHECK(!strcmp(phc_growth_preset_for_species("Quercus rubra", &group), "oak") && !strcmp(group, "Quercus"));
    CHECK(!strcmp(phc_growth_preset_for_species("acer RUBRUM", &group), "maple") && !strcmp(group, "Acer"));
    CHECK(!strcmp(phc_growth_preset_for_species("Prunus serotina", NULL), "cherry"));
    CHECK(!strcmp(phc_growth_preset_for_species("Malus domestica", NULL), "apple"));
    CHECK(!strcmp(phc_growth_preset_for_species("Populus tremuloides", NULL), "poplar"));
    CHECK(phc_growth_preset_for_species("Pinus taeda", &group) == NULL && !strcmp(group, "conifer"));
    CHECK(phc_growth_preset_for_species("Pseudotsuga menziesii", &group) == NULL && !strcmp(group, "conifer"));
    CHECK(phc_growth_preset_for_species("Shorea leprosula", &group) == NULL && !strcmp(group, "other"));
    CHECK(phc_growth_preset_for_species("Acerola glabra", &group) == NULL && !strcmp(group, "other"));
    CHECK(phc_growth_preset_for_species(NULL, &group) == NULL && !strcmp(group, "other"));
}

/* The report section of a data set with this preset and species. */
static char *report(const char *preset, const char *species)
{
    phc_dataset *ds = make(preset, species);
    char *md = NULL;
    phc_error err;
    const double p[K] = {0.0015, 10, 0.6};
    CHECK(ds && ds->ops->report_section(ds, p, &md, &err) == PHC_OK && md);
    phc_dataset_free(ds);
    return md ? md : calloc(1, 1);
}

static void report_names_preset(void)
{
    char *md = report("oak", "Pinus taeda");
    const char *line = strstr(md, "**Preset:**");
    printf("%.*s\n", line ? (int)strcspn(line, "\n") : 0, line ? line : "");
    CHECK_STR_CONTAINS(md, "**Preset:** `oak` was used for *Pinus taeda*, a species it does not describe. No "
                           "preset describes conifers");
    CHECK_STR_CONTAINS(md, "there is no conifer or tropical preset");
    CHECK_STR_CONTAINS(md, "Simulations before this report: 0 trajectories asked for");
    free(md);
    md = report("oak", "Acer rubrum");
    CHECK_STR_CONTAINS(md, "**Preset:** `oak` was used for *Acer rubrum*, a species it does not describe. The "
                           "preset for its genus *Acer* is `maple`.");
    free(md);
    md = report("maple", "Acer rubrum");
    CHECK_STR_CONTAINS(md, "Preset: `maple`, the preset for the genus *Acer* of *Acer rubrum*.");
    CHECK(!strstr(md, "**Preset:**"));
    free(md);
    md = report(NULL, "Shorea leprosula");
    CHECK_STR_CONTAINS(md, "**Preset:** `oak` was used for *Shorea leprosula*, a species it does not describe. "
                           "No preset describes its genus");
    free(md);
    md = report("poplar", NULL);
    CHECK_STR_CONTAINS(md, "Preset: `poplar`. The plants' species is not given");
    free(md);
}

int main(void)
{
    jacobian_and_reuse();
    preset_lookup();
    report_names_preset();
    return check_finish("test_root_shoot_reuse");
}
