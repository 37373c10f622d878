/* Every data-set kind records the files its loader read
 * (phc_dataset_add_input, fit/engine/dataset.h), for provenance.  Checked here with
 * phc_config_load, list against list (in any order, each path as opened:
 * the config's directory joined with the name it gives):
 *
 * 1. the bundled examples of measurements/examples/: enzyme (curve),
 *    seedling (weight_curve: the balance table and the plant graph),
 *    pv_leaves (pv_curve), soil_probe (the readings and the probe table);
 * 2. in a temporary folder, elasticity_curve and infiltration (one table
 *    each), and the kinds that read several files: root_shoot
 *    from a table and from a BAAD study folder (data.csv,
 *    dataMatchColumns.csv, dataNew.csv and the parent's
 *    variableDefinitions.csv; studyMetadata.csv is not read, so not listed),
 *    and leaf_photos (the table, every photo once although two rows share
 *    one, the reference photo and a vein map file). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "fit/config.h"
#include "measurements/photo.h"

static char tmp_dir[] = "/tmp/phc_test_inputs_XXXXXX";
static char tmp_paths[32][512]; /* files, then folders, removed in reverse order */
static int n_tmp_paths = 0;

static const char *tmp_path(const char *name)
{
    static char slots[8][512];
    static int slot = 0;
    char *p = slots[slot++ % 8];
    snprintf(p, sizeof slots[0], "%s/%s", tmp_dir, name);
    return p;
}

static void remember(const char *path)
{
    if (n_tmp_paths < 32)
        snprintf(tmp_paths[n_tmp_paths++], sizeof tmp_paths[0], "%s", path);
}

static void write_file(const char *name, const char *text)
{
    const char *path = tmp_path(name);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fputs(text, f);
    fclose(f);
    remember(path);
}

static void make_dir(const char *name)
{
    const char *path = tmp_path(name);
    CHECK(mkdir(path, 0700) == 0);
    remember(path);
}

static void remove_all(void)
{
    for (int i = n_tmp_paths - 1; i >= 0; --i)
        remove(tmp_paths[i]); /* remove() deletes empty folders too */
    rmdir(tmp_dir);
}

/* Loads `config` and checks that its first data set lists exactly the
 * files in `expected` (NULL-terminated). */
static void check_inputs(const char *label, const char *config, const char *const *expected)
{
    phc_problem *pb = NULL;
    phc_error err;
    phc_error_clear(&err);
    int rc = phc_config_load(config, &pb, &err);
    CHECK(rc == PHC_OK);
    if (rc) {
        fprintf(stderr, "%s: %s\n", label, err.message);
        return;
    }
    const phc_dataset *ds = pb->datasets[0];
    size_t n_expected = 0;
    while (expected[n_expected])
        ++n_expected;
    int ok = ds->n_inputs == n_expected;
    for (size_t i = 0; i < n_expected; ++i) {
        int found = 0;
        for (size_t j = 0; j < ds->n_inputs && !found; ++j)
            found = strcmp(ds->inputs[j], expected[i]) == 0;
        if (!found) {
            fprintf(stderr, "%s: '%s' is not among the inputs\n", label, expected[i]);
            ok = 0;
        }
    }
    CHECK(ok);
    printf("%s: %zu input%s%s\n", label, ds->n_inputs, ds->n_inputs == 1 ? "" : "s", ok ? "" : " (wrong)");
    for (size_t j = 0; j < ds->n_inputs; ++j)
        printf("  %s\n", ds->inputs[j]);
    phc_problem_free(pb);
}

#define EXAMPLES PHC_SOURCE_DIR "/measurements/examples"

static void test_examples(void)
{
    check_inputs("enzyme (curve)", EXAMPLES "/enzyme_kinetics/enzyme.yaml",
                 (const char *const[]){EXAMPLES "/enzyme_kinetics/enzyme.csv", NULL});
    check_inputs("seedling (weight_curve)", EXAMPLES "/weight_curve/seedling.yaml",
                 (const char *const[]){EXAMPLES "/weight_curve/balance.csv",
                                       EXAMPLES "/weight_curve/seedling.csv", NULL});
    check_inputs("pv_leaves (pv_curve)", EXAMPLES "/pressure_volume/pv_leaves.yaml",
                 (const char *const[]){EXAMPLES "/pressure_volume/pv_leaves.csv", NULL});
    check_inputs("soil_probe", EXAMPLES "/soil_probe/soil_probe.yaml",
                 (const char *const[]){EXAMPLES "/soil_probe/readings.csv", EXAMPLES "/soil_probe/probes.csv",
                                       NULL});
}

static void test_one_table_kinds(void)
{
    write_file("moduli.csv", "rwc,e\n0.80,0.5\n0.85,1.4\n0.90,2.9\n0.95,4.1\n1.00,4.7\n");
    write_file("elasticity.yaml", "name: t\n"
                                  "parameters:\n"
                                  "  kappa: {value: 20, lower: 0}\n"
                                  "  chi0: {value: 0.85}\n"
                                  "  e_min: {value: 0, fixed: true}\n"
                                  "  e_max: {value: 5, lower: 0}\n"
                                  "datasets:\n"
                                  "  - kind: elasticity_curve\n"
                                  "    file: moduli.csv\n"
                                  "    water: rwc\n"
                                  "    water_content: rwc\n"
                                  "    modulus: e\n");
    check_inputs("elasticity_curve", tmp_path("elasticity.yaml"),
                 (const char *const[]){tmp_path("moduli.csv"), NULL});
    write_file("front.csv", "t,d\n1,0.05\n2,0.1\n4,0.2\n");
    write_file("infiltration.yaml", "name: t\n"
                                    "parameters:\n"
                                    "  p: {value: 0.05, lower: 1e-6}\n"
                                    "  c: {value: 50, lower: 1e-3}\n"
                                    "datasets:\n"
                                    "  - kind: infiltration\n"
                                    "    file: front.csv\n"
                                    "    time: {column: t, unit: h}\n"
                                    "    depth: {column: d, unit: m}\n"
                                    "    sigma: 0.01\n"
                                    "    soil:\n"
                                    "      grid: {nx: 1, ny: 1, nz: 40, dx: 0.05}\n"
                                    "      layers: [{soil: silt, fill: 0.0001}]\n"
                                    "      rain: [{start: 0, end: 2, rate: 0.01}]\n");
    check_inputs("infiltration", tmp_path("infiltration.yaml"), (const char *const[]){tmp_path("front.csv"), NULL});
}

/* A harvest table and the same three plants as a BAAD study folder. */
static void test_root_shoot(void)
{
    static const char *const rs_head = "name: t\n"
                                       "parameters:\n"
                                       "  phi_rg: {value: 0.6, lower: 0.05, upper: 0.95}\n"
                                       "datasets:\n"
                                       "  - kind: root_shoot\n"
                                       "    sigma: 0.3\n"
                                       "    days: 30\n";
    char text[1024];
    write_file("harvest.csv", "d_mm,root_g,shoot_g\n1.0,0.05,0.10\n1.5,0.08,0.15\n2.0,0.12,0.22\n");
    snprintf(text, sizeof text,
             "%s    file: harvest.csv\n"
             "    diameter: {column: d_mm, unit: mm}\n"
             "    root_mass: {column: root_g, unit: g}\n"
             "    shoot_mass: {column: shoot_g, unit: g}\n",
             rs_head);
    write_file("rs_table.yaml", text);
    check_inputs("root_shoot (table)", tmp_path("rs_table.yaml"),
                 (const char *const[]){tmp_path("harvest.csv"), NULL});

    make_dir("baad");
    make_dir("baad/Std2000");
    write_file("baad/variableDefinitions.csv",
               "variable,units,group,type,has_methods,essential,label,minValue,maxValue,allowableValues,"
               "description\n"
               "species,NA,species,character,FALSE,TRUE,species,NA,NA,NA,latin name\n"
               "d.ba,m,tree,numeric,TRUE,FALSE,basal diameter,1e-20,25,NA,basal diameter\n"
               "m.so,kg,tree,numeric,TRUE,FALSE,aboveground mass,1e-20,1e+07,NA,shoot mass\n"
               "m.rt,kg,tree,numeric,TRUE,FALSE,total root mass,1e-20,1e+07,NA,root mass\n");
    write_file("baad/Std2000/data.csv", "sp,diam (mm),root (g),shoot (g)\n"
                                        "AA,1.0,0.05,0.10\nAA,1.5,0.08,0.15\nAA,2.0,0.12,0.22\n");
    write_file("baad/Std2000/dataMatchColumns.csv", "\"var_in\",\"method\",\"unit_in\",\"var_out\",\"notes\"\n"
                                                    "\"sp\",NA,NA,\"species\",NA\n"
                                                    "\"diam (mm)\",\"d1\",\"mm\",\"d.ba\",NA\n"
                                                    "\"root (g)\",\"m3\",\"g\",\"m.rt\",NA\n"
                                                    "\"shoot (g)\",\"m3\",\"g\",\"m.so\",NA\n");
    write_file("baad/Std2000/dataNew.csv", "\"lookupVariable\",\"lookupValue\",\"newVariable\",\"newValue\","
                                           "\"source\"\n"
                                           "\"species\",\"AA\",\"species\",\"Alpha alpha\",\"paper\"\n");
    write_file("baad/Std2000/studyMetadata.csv", "Topic,Description\nTitle,not read\n");
    snprintf(text, sizeof text, "%s    baad: baad/Std2000\n    species: Alpha alpha\n", rs_head);
    write_file("rs_baad.yaml", text);
    check_inputs("root_shoot (BAAD study)", tmp_path("rs_baad.yaml"),
                 (const char *const[]){tmp_path("baad/Std2000/data.csv"), tmp_path("baad/Std2000/dataMatchColumns.csv"),
                                       tmp_path("baad/Std2000/dataNew.csv"), tmp_path("baad/variableDefinitions.csv"),
                                       NULL});
}

#define W 120
#define H 80

/* A leaf on white paper (an ellipse with a midrib), green or yellow. */
static void draw_leaf(const char *name, int yellow)
{
    phc_image img = {0};
    phc_error err;
    CHECK(phc_image_alloc(&img, W, H, &err) == PHC_OK);
    for (size_t y = 0; y < H; ++y)
        for (size_t x = 0; x < W; ++x) {
            double *c = img.data + 3 * (x + W * y);
            const double u = (x - W / 2.0) / (0.4 * W), v = (y - H / 2.0) / (0.4 * H);
            const int vein = fabs(y - H / 2.0) < 1.5;
            c[0] = c[1] = c[2] = 1;
            if (u * u + v * v < 1) {
                c[0] = yellow ? 0.8 : vein ? 0.3 : 0.2;
                c[1] = yellow ? 0.75 : vein ? 0.55 : 0.45;
                c[2] = yellow ? 0.25 : 0.15;
            }
        }
    const char *path = tmp_path(name);
    CHECK(phc_photo_write_png(path, &img, &err) == PHC_OK);
    remember(path);
    phc_image_free(&img);
}

static void test_leaf_photos(void)
{
    draw_leaf("fresh.png", 0);
    draw_leaf("later.png", 0);
    draw_leaf("old.png", 1);
    double veins[W * H];
    for (size_t i = 0; i < W * H; ++i)
        veins[i] = (i / W) == H / 2 ? 1 : 0.1;
    phc_error err;
    CHECK(phc_photo_write_map_png(tmp_path("veins.png"), W, H, veins, NULL, 0, 1, 0, &err) == PHC_OK);
    remember(tmp_path("veins.png"));
    write_file("photos.csv", "day,image\n0,fresh.png\n2,later.png\n3,later.png\n");
    write_file("lp.yaml", "name: t\n"
                          "parameters:\n"
                          "  stomata_scale: {value: 0.1, lower: 0}\n"
                          "datasets:\n"
                          "  - kind: leaf_photos\n"
                          "    file: photos.csv\n"
                          "    image: {column: image}\n"
                          "    stage: {column: day}\n"
                          "    reference: {image: old.png}\n"
                          "    veins: veins.png\n"
                          "    residual: histogram\n"
                          "    model_size: 32\n");
    check_inputs("leaf_photos", tmp_path("lp.yaml"),
                 (const char *const[]){tmp_path("photos.csv"), tmp_path("fresh.png"), tmp_path("later.png"),
                                       tmp_path("old.png"), tmp_path("veins.png"), NULL});
}

int main(void)
{
    if (!mkdtemp(tmp_dir)) {
        perror("mkdtemp");
        return 1;
    }
    test_examples();
    test_one_table_kinds();
    test_root_shoot();
    test_leaf_photos();
    remove_all();
    return check_finish("test_dataset_inputs");
}
