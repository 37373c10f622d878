/* `root_shoot` data sets built in C, without a config
 * (fit/costs/root_shoot.h, fit/costs/harvest.h):
 *
 * 1. five harvested plants from arrays (basal diameters 1 to 2 mm), their
 *    root:shoot made by the data set's own model (oak preset, no soil, 40
 *    days) at a root tissue density of 5e5 g/m^3: bound by name to a
 *    hand-built problem, a fit from 3.5e5 gives the truth back (to 1e-6).
 *    (phi_rg, the README's example, barely moves root:shoot of plants this
 *    young, and a pot grown for a season takes minutes: the realdata test
 *    fits it);
 * 2. a tiny pot as the soil: the default slots are the soil's p and c,
 *    then phi_rg;
 * 3. phc_harvest_from_table converts units (cm, kg, months), adds leaf and
 *    stem masses and keeps the selected rows;
 * 4. without an origin the messages name the kind ("root_shoot: ..."), with
 *    one they name the config file and the key's line;
 * 5. a BAAD study folder through phc_harvest_read_baad, when the shared
 *    data are there. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "fit/costs/root_shoot.h"
#include "fit/engine/fit.h"
#include "fit/engine/problem.h"
#include "measurements/table.h"

#define N_PLANTS 5
#define DAYS 40

static double diameter[N_PLANTS] = {1.0e-3, 1.25e-3, 1.5e-3, 1.75e-3, 2.0e-3}; /* m */
static double root[N_PLANTS], shoot[N_PLANTS];
static phc_harvest plants = {.n = N_PLANTS, .diameter = diameter, .root_mass = root, .shoot_mass = shoot,
                             .file = "harvest"};

static phc_soil_setup_layer pot_layer;
static phc_soil_rain pot_rain = {.start = 0, .end = 1e6, .rate = 1e-4};

/* A 20 cm pot of one soil, watered all along. */
static phc_soil_setup_options pot(void)
{
    phc_soil_setup_options s = phc_soil_setup_options_default();
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
    return s;
}

static int only_root_density(const char *name, void *user_data)
{
    (void)user_data;
    return !strcmp(name, "root_density");
}

static phc_root_shoot_options options(void)
{
    phc_root_shoot_options o = phc_root_shoot_options_default();
    o.sigma = 0.05;
    o.days = DAYS;
    return o;
}

static void fit_back(void)
{
    for (int i = 0; i < N_PLANTS; ++i)
        root[i] = shoot[i] = 1;
    phc_root_shoot_options o = options();
    o.is_parameter = only_root_density;
    phc_dataset *ds = NULL;
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_root_shoot_new(&plants, &o, &ds, &err) == PHC_OK);
    if (!ds) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    CHECK(ds->n == N_PLANTS && ds->k == 1 && strcmp(ds->slot_names[0], "root_density") == 0);
    CHECK(ds->x[4] == 2.0 && ds->data_lines[0] == 2 && strcmp(ds->data_file, "harvest") == 0);
    const double truth = 5e5;
    double lrs[N_PLANTS];
    CHECK(ds->ops->predict(ds, &truth, lrs, NULL) == 0);
    phc_dataset_free(ds);
    printf("ln(root:shoot) at root_density = 5e5 g/m3:");
    for (int i = 0; i < N_PLANTS; ++i) {
        printf(" %.4f", lrs[i]);
        CHECK(isfinite(lrs[i]));
        shoot[i] = 0.1;
        root[i] = 0.1 * exp(lrs[i]);
    }
    printf("\n");

    CHECK(phc_root_shoot_new(&plants, &o, &ds, &err) == PHC_OK);
    if (!ds)
        return;
    phc_problem *pb = phc_problem_new("harvest");
    CHECK(phc_problem_add_parameter(pb, "root_density", 3.5e5, NULL, &err) == PHC_OK);
    pb->params[0].lower = 1e5;
    pb->params[0].upper = 1e6;
    ds->name = strdup("oaks");
    CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_OK);
    CHECK(phc_problem_add_dataset(pb, ds, &err) == PHC_OK);
    phc_fit_result *res = NULL;
    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    if (res) {
        printf("fitted root_density %.10g g/m3 (truth 5e5)\n", res->params[0].value);
        CHECK_NEAR(res->params[0].value, 5e5, 0, 1e-6);
    } else {
        fprintf(stderr, "%s\n", err.message);
    }
    phc_fit_result_free(res);
    phc_problem_free(pb);
}

static void in_a_pot(void)
{
    phc_soil_setup_options s = pot();
    phc_root_shoot_options o = options();
    o.soil = &s;
    phc_dataset *ds = NULL;
    phc_error err;
    CHECK(phc_root_shoot_new(&plants, &o, &ds, &err) == PHC_OK);
    if (!ds) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    CHECK(ds->k == 3 && strcmp(ds->slot_names[0], "p") == 0 && strcmp(ds->slot_names[1], "c") == 0 &&
          strcmp(ds->slot_names[2], "phi_rg") == 0);
    printf("in a pot, slots: %s %s %s\n", ds->slot_names[0], ds->slot_names[1], ds->slot_names[2]);
    phc_dataset_free(ds);

    o.plant_x = 0.5;
    CHECK(phc_root_shoot_new(&plants, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strstr(err.message, "root_shoot: plant: the plant is seeded at x = 0.5, y = 0.1 m") == err.message);
}

static phc_table *harvest_table(void)
{
    const double d_cm[] = {0.1, 0.15, 0.2, 0.3}, root_kg[] = {5e-5, 8e-5, 1.2e-4, 2e-4};
    const double leaf_g[] = {0.06, 0.1, 0.12, 0.2}, stem_g[] = {0.04, 0.05, 0.1, 0.1};
    const double age_month[] = {1, 2, 3, 4}, light[] = {1, 1, 2, 1};
    const char *names[] = {"d", "root", "leaf", "stem", "age", "light"};
    const double *cols[] = {d_cm, root_kg, leaf_g, stem_g, age_month, light};
    phc_table *t = NULL;
    phc_error err;
    CHECK(phc_table_from_columns("harvest", 6, names, cols, 4, &t, &err) == PHC_OK);
    return t;
}

static size_t fake_key_line(const void *map, const char *key)
{
    (void)map;
    return !strcmp(key, "diameter") ? 7 : !strcmp(key, "select") ? 12 : !strcmp(key, "sigma") ? 9 : 5;
}

static void from_table(void)
{
    phc_table *t = harvest_table();
    if (!t)
        return;
    phc_harvest_columns c = {.diameter = "d", .diameter_unit = "cm", .root_mass = "root", .root_mass_unit = "kg",
                             .leaf_mass = "leaf", .stem_mass = "stem", .age = "age", .age_unit = "month",
                             .select_column = "light", .select_value = "1"};
    phc_harvest *h = NULL;
    phc_error err;
    CHECK(phc_harvest_from_table(t, &c, &h, &err) == PHC_OK);
    if (h) {
        printf("table: %s; plant 3: D %g m, root %g g, shoot %g g, age %g d, line %zu\n", h->source,
               h->diameter[2], h->root_mass[2], h->shoot_mass[2], h->age[2], h->line[2]);
        CHECK(h->n == 3 && h->line[2] == 5);
        CHECK_NEAR(h->diameter[2], 3e-3, 0, 1e-12);
        CHECK_NEAR(h->root_mass[2], 0.2, 0, 1e-12);
        CHECK_NEAR(h->shoot_mass[2], 0.3, 0, 1e-12);
        CHECK(h->age[2] > 120 && h->age[2] < 123); /* 4 months */
        CHECK(strcmp(h->source, "`harvest`, 3 harvested plants with light = 1") == 0);
        phc_harvest_free(h);
    }

    c.diameter = "dd";
    CHECK(phc_harvest_from_table(t, &c, &h, &err) == PHC_ERR_INPUT && h == NULL);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "root_shoot: key 'diameter': 'dd' is not a column of harvest; did you mean 'd'?") == 0);
    const phc_origin origin = {.path = "cfg.yaml", .map = "", .key_line = fake_key_line, .line = 5};
    c.origin = &origin;
    CHECK(phc_harvest_from_table(t, &c, &h, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(strcmp(err.message, "cfg.yaml:7: key 'diameter': 'dd' is not a column of harvest; did you mean 'd'?") == 0);
    c.diameter = "d";
    c.select_value = "3";
    CHECK(phc_harvest_from_table(t, &c, &h, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(strcmp(err.message, "cfg.yaml:12: select: no row of harvest has light = '3'") == 0);
    c.select_column = NULL;
    c.stem_mass = NULL;
    c.origin = NULL;
    CHECK(phc_harvest_from_table(t, &c, &h, &err) == PHC_ERR_INPUT);
    CHECK(strcmp(err.message, "root_shoot: root_shoot data set: missing key 'shoot_mass' (or both 'leaf_mass' and "
                              "'stem_mass')") == 0);
    phc_table_free(t);

    phc_root_shoot_options o = options();
    phc_dataset *ds = NULL;
    o.sigma = 0;
    CHECK(phc_root_shoot_new(&plants, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "root_shoot: key 'sigma': must be > 0, found 0") == 0);
    o.origin = &origin;
    CHECK(phc_root_shoot_new(&plants, &o, &ds, &err) == PHC_ERR_INPUT);
    CHECK(strcmp(err.message, "cfg.yaml:9: key 'sigma': must be > 0, found 0") == 0);
    o = options();
    o.preset = "birch";
    CHECK(phc_root_shoot_new(&plants, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strstr(err.message, "root_shoot: key 'preset': ") == err.message && strstr(err.message, "'birch'"));
    o = options();
    root[1] = -1;
    CHECK(phc_root_shoot_new(&plants, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strcmp(err.message, "harvest:3: the root mass must be a positive number, found -1") == 0);
    root[1] = 0.1;
}

static void from_baad(void)
{
    char dir[512];
    struct stat st;
    snprintf(dir, sizeof dir, "%s/baad/Baltzer2007", PHC_SHARED_DATA);
    if (stat(dir, &st) != 0) {
        printf("# skip - BAAD study: no %s\n", dir);
        return;
    }
    phc_harvest_baad_options b = {.species = "Quercus rubra"};
    phc_harvest *h = NULL;
    phc_error err;
    CHECK(phc_harvest_read_baad(dir, &b, &h, &err) == PHC_OK);
    if (!h) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    printf("BAAD: %zu plants, %zu files read; %s\n", h->n, h->n_inputs, h->source);
    CHECK(h->n > 10 && h->n_inputs >= 1 && strstr(h->file, "Baltzer2007/data.csv"));
    phc_root_shoot_options o = options();
    o.days = 1; /* not run here: only built */
    phc_dataset *ds = NULL;
    CHECK(phc_root_shoot_new(h, &o, &ds, &err) == PHC_OK);
    CHECK(ds && ds->n == h->n && ds->n_inputs == h->n_inputs);
    phc_dataset_free(ds);
    phc_harvest_free(h);
    b.species = "Quercus rubrum";
    CHECK(phc_harvest_read_baad(dir, &b, &h, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %.100s...\n", err.message);
    CHECK(strstr(err.message, "root_shoot: species 'Quercus rubrum' is not in ") == err.message);
}

int main(void)
{
    fit_back();
    in_a_pot();
    from_table();
    from_baad();
    return check_finish("test_root_shoot_new");
}
