/* `leaf_photos` data sets built in C, without a config or a file
 * (fit/costs/leaf_photos.h):
 *
 * 1. a green leaf (an ellipse with veins on white paper) and a yellow
 *    reference are drawn in memory; the data set's own set-up
 *    (leaf_setup.h, phc_photo_cache_add) ages the green leaf with inflow
 *    scale 0.3, and the simulated leaves put back on paper are the photos
 *    of days 2, 4 and 6, passed as images (rows[i].pixels);
 *    phc_leaf_photos_new over them, bound by name to a hand-built problem,
 *    fits the inflow scale back from 0.15 (within 10 %: the photos went
 *    model grid -> photo size -> model grid, which blurs); the engine's
 *    leave-one-out (fit/engine/cross_validation.h, run by phc_fit_run because the
 *    data set asks for it) puts its table in the report section, with the
 *    numbers phc_cross_validate gives;
 * 2. histogram residuals over a "scan" of two leaves shared by two rows
 *    (segmented once, leaf numbers in reading order): the residual count,
 *    the series and the labels;
 * 3. without an origin the messages name the kind and rows[i]; with one
 *    (and a table's lines) they name the config line of the key and the
 *    table line and column, as a config load does. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/costs/leaf_photos.h"
#include "fit/costs/leaf_setup.h"
#include "fit/engine/cross_validation.h"
#include "fit/engine/fit.h"
#include "fit/engine/problem.h"

#define W 120
#define H 80

/* `leaves` leaves side by side on white paper: ellipses, green with darker
 * veins, or yellow. */
static int draw_leaves(phc_image *img, size_t leaves, int yellow)
{
    phc_error err;
    const size_t w = W * leaves;
    if (phc_image_alloc(img, w, H, &err))
        return 1;
    for (size_t y = 0; y < H; ++y)
        for (size_t x = 0; x < w; ++x) {
            double *c = img->data + 3 * (x + w * y);
            const double cx = W * ((double)(x / W) + 0.5);
            const double u = (x - cx) / (0.42 * W), v = (y - H / 2.0) / (0.40 * H);
            c[0] = c[1] = c[2] = 1;
            if (u * u + v * v >= 1)
                continue;
            const double dy = fabs(y - H / 2.0), dx = fmod(fabs(x - cx + dy) + 1000, 15.0);
            const int vein = dy < 1.0 || dx < 1.0;
            const double tex = 0.03 * sin(0.7 * x) * cos(0.5 * y);
            if (yellow) {
                c[0] = 0.85 + tex;
                c[1] = 0.75 + tex;
                c[2] = 0.25;
            } else {
                c[0] = (vein ? 0.30 : 0.18) + tex;
                c[1] = (vein ? 0.55 : 0.42) + tex;
                c[2] = (vein ? 0.25 : 0.12) + tex;
            }
        }
    return 0;
}

/* The simulated leaf at day t, enlarged to the photo's size on white. */
static int aged_photo(phc_leaf_setup *su, double t, phc_colour_transfer tf, const phc_leaf_photo *fresh,
                      phc_image *page)
{
    phc_error err;
    phc_image sim = {0}, big = {0};
    int rc = 1;
    phc_leaf_reset(su->leaf, 1.0);
    if (phc_leaf_advance(su->leaf, t) || phc_leaf_setup_colours(su, tf, NULL, &sim, &err) ||
        phc_photo_resize(&sim, fresh->crop.width, fresh->crop.height, &big, &err) ||
        phc_image_alloc(page, W, H, &err))
        goto done;
    for (size_t i = 0; i < 3 * W * H; ++i)
        page->data[i] = 1;
    for (size_t y = 0; y < big.height; ++y)
        for (size_t x = 0; x < big.width; ++x)
            if (fresh->mask[x + big.width * y])
                memcpy(page->data + 3 * (fresh->x0 + x + W * (fresh->y0 + y)), big.data + 3 * (x + big.width * y),
                       3 * sizeof(double));
    rc = 0;
done:
    phc_image_free(&sim);
    phc_image_free(&big);
    return rc;
}

/* The slots this test fits: the inflow scale, and the stomata scale fixed. */
static int inflow_and_stomata(const char *name, void *user_data)
{
    (void)user_data;
    return !strcmp(name, "inflow_scale") || !strcmp(name, "stomata_scale");
}

static phc_image fresh_img, old_img, days[3];

static void test_fit(void)
{
    const double truth_inflow = 0.3, stomata = 0.1, beta = 50; /* beta_scale: the kind's default */
    const phc_colour_transfer tf = {0.2, 0.8};
    phc_error err;
    phc_error_clear(&err);
    /* the truth: the set-up the data set will build (model_size 48) */
    phc_photo_cache *cache = phc_photo_cache_new();
    phc_leaf_photo fresh = {0}, ref = {0};
    phc_leaf_setup *su = NULL;
    CHECK(phc_photo_cache_add(cache, "fresh", &fresh_img, PHC_CC_NONE, NULL, &err) == PHC_OK);
    CHECK(phc_photo_cache_add(cache, "old", &old_img, PHC_CC_NONE, NULL, &err) == PHC_OK);
    CHECK(phc_leaf_photo_load(cache, "fresh", 1, PHC_CC_NONE, NULL, &fresh, &err) == PHC_OK);
    CHECK(phc_leaf_photo_load(cache, "old", 1, PHC_CC_NONE, NULL, &ref, &err) == PHC_OK);
    phc_leaf_setup_options so = phc_leaf_setup_options_default();
    so.model_size = 48;
    CHECK(phc_leaf_setup_new(&fresh, &ref, &so, &su, &err) == PHC_OK);
    if (!su) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    phc_leaf_params lp = phc_leaf_get_params(su->leaf);
    lp.beta_scale = beta;
    lp.inflow_scale = truth_inflow;
    lp.stomata_scale = stomata;
    CHECK(phc_leaf_set_params(su->leaf, lp, &err) == PHC_OK);
    for (int d = 0; d < 3; ++d)
        CHECK(aged_photo(su, 2.0 * (d + 1), tf, &fresh, &days[d]) == 0);
    /* the Lab colours equal eq. 9's blend converted pixel by pixel, to the
       bit, although pixels with g = 0 or 1 copy a Lab computed at set-up */
    CHECK(su->space == PHC_COLOUR_RGB && su->lab_original && su->lab_matched);
    {
        const size_t n = su->w * su->h;
        double *lab = malloc(3 * n * sizeof *lab);
        size_t n_end = 0, n_mid = 0, n_bad = 0;
        for (int d = 0; lab && d < 4; ++d) {
            phc_leaf_reset(su->leaf, 1.0);
            CHECK(phc_leaf_advance(su->leaf, 1.5 * d) == 0);
            CHECK(phc_leaf_setup_colours(su, tf, lab, NULL, &err) == PHC_OK);
            const double *y = phc_leaf_fluid(su->leaf);
            for (size_t i = 0; i < n; ++i) {
                double want[3] = {0, 0, 0};
                if (su->mask[i]) {
                    double rgb[3];
                    const double g = phc_colour_transfer_weight(tf, y[i], NULL, NULL, NULL);
                    phc_colour_blend(1, su->original + 3 * i, su->matched + 3 * i, y + i, tf, rgb);
                    phc_colour_srgb_to_lab(rgb, want);
                    if (g == 0.0 || g == 1.0)
                        ++n_end;
                    else
                        ++n_mid;
                }
                n_bad += memcmp(want, lab + 3 * i, sizeof want) != 0;
            }
        }
        printf("setup_colours: %zu leaf pixels at g = 0 or 1, %zu in between, %zu differ\n", n_end, n_mid, n_bad);
        CHECK(lab && n_end > 0 && n_mid > 0 && n_bad == 0);
        free(lab);
    }
    phc_leaf_setup_free(su);
    phc_leaf_photo_free(&fresh);
    phc_leaf_photo_free(&ref);
    phc_photo_cache_free(cache);

    /* the data set, from the images in memory */
    const phc_leaf_photos_row rows[] = {{.stage = 0, .pixels = &fresh_img, .image = "fresh", .id = "d0"},
                                        {.stage = 2, .pixels = &days[0], .id = "d2"},
                                        {.stage = 4, .pixels = &days[1], .id = "d4"},
                                        {.stage = 6, .pixels = &days[2], .id = "d6"}};
    phc_leaf_photos_options o = phc_leaf_photos_options_default();
    o.reference_pixels = &old_img;
    o.reference_image = "old";
    o.setup.model_size = 48;
    o.grid = 12;
    o.sigma = 1;
    o.stage_name = "day";
    o.is_parameter = inflow_and_stomata;
    o.cross_validate = 1;
    phc_dataset *ds = NULL;
    CHECK(phc_leaf_photos_new(rows, 4, &o, &ds, &err) == PHC_OK);
    if (!ds) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    printf("pixels data set: %zu residuals, slots %s %s, x label '%s', y label '%s'\n", ds->n, ds->slot_names[0],
           ds->slot_names[1], ds->x_label, ds->y_label);
    CHECK(ds->k == 2 && !strcmp(ds->slot_names[0], "stomata_scale") && !strcmp(ds->slot_names[1], "inflow_scale"));
    CHECK(ds->n >= 3 * 3 * 20 && ds->n % 3 == 0); /* three photos, >= 20 cells, ΔL* Δa* Δb* */
    CHECK(!strcmp(ds->x_label, "day") && !strcmp(ds->y_label, "CIELAB cell mean (L*, a*, b*)"));
    CHECK(ds->data_file == NULL && ds->data_lines == NULL && ds->n_inputs == 0);

    phc_problem *pb = phc_problem_new("leaf");
    CHECK(phc_problem_add_parameter(pb, "stomata_scale", stomata, NULL, &err) == PHC_OK);
    CHECK(phc_problem_add_parameter(pb, "inflow_scale", 0.15, NULL, &err) == PHC_OK);
    pb->params[0].fixed = 1;
    pb->params[1].lower = 0;
    pb->params[1].upper = 5;
    ds->name = strdup("leaf");
    CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_OK);
    CHECK(phc_problem_add_dataset(pb, ds, &err) == PHC_OK);
    phc_fit_result *res = NULL;
    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    if (res) {
        CHECK(res->summary.outcome == PHC_NLS_CONVERGED);
        printf("fitted inflow_scale %.5g +- %.2g (truth %g, start 0.15), wrss %.4g\n", res->params[1].value,
               res->params[1].stderr_, truth_inflow, res->wrss);
        CHECK_NEAR(res->params[1].value, truth_inflow, 0, 0.10);
        /* the engine's leave-one-out, in the data set's report section */
        const char *md = res->datasets[0].extra_markdown, *cv = md ? strstr(md, "\n**Leave-one-out") : NULL;
        CHECK(cv && strstr(cv, "**Leave-one-out prediction of day** (each row left out in turn; the free "
                               "parameters refitted on the others; the stage read off the model time whose "
                               "colours match the photo best).  Baseline: ") == cv + 1);
        CHECK(cv && strstr(cv, "\n| row | measured | model | baseline |\n|---|---|---|---|\n| d2 | 2 | "));
        CHECK(cv && strstr(cv, "\nRMSE of the prediction (day units): model **"));
        /* the same numbers through the engine's API.  (The days are read
         * back poorly here: with these scales every leaf pixel's fluid is
         * still above y_hi = 0.8 on day 2 (0.86 to 0.95; 47 % of them on day
         * 4), where the colour transfer shows the fresh colours, so days 0
         * to 2 look alike; and the blurred photos pull the readings.) */
        phc_cv_result *loo = NULL;
        const double p[2] = {stomata, res->params[1].value};
        CHECK(phc_cross_validate(pb, ds, p, NULL, NULL, &loo, &err) == PHC_OK);
        if (loo) {
            CHECK(loo->n_groups == 3 && loo->n_predictions == 2 && !strcmp(loo->names[1], "d4"));
            double s2 = 0;
            for (size_t g = 0; g < loo->n_groups; ++g) {
                const double *v = loo->predicted + 2 * g;
                printf("leave-one-out %s: day %g, model %.3f, baseline %.3f\n", loo->names[g], loo->observed[g],
                       v[0], v[1]);
                /* searched from day 0 to 1.5 times the last day */
                CHECK(v[0] >= 0 && v[0] <= 9 && isfinite(v[1]));
                char line[128];
                snprintf(line, sizeof line, "\n| %s | %g | %.2f | %.2f |\n", loo->names[g], loo->observed[g], v[0],
                         v[1]);
                CHECK(cv && strstr(cv, line));
                s2 += pow(v[0] - loo->observed[g], 2);
            }
            printf("leave-one-out RMSE: model %.3f, baseline %.3f day\n", loo->rmse[0], loo->rmse[1]);
            CHECK_NEAR(loo->rmse[0], sqrt(s2 / 3), 1e-12, 0);
            phc_cv_result_free(loo);
        } else
            fprintf(stderr, "%s\n", err.message);
    } else
        fprintf(stderr, "%s\n", err.message);
    phc_fit_result_free(res);
    phc_problem_free(pb);
}

/* Histogram residuals over a scan of two leaves shared by two rows. */
static void test_histogram(void)
{
    phc_image scan = {0};
    CHECK(draw_leaves(&scan, 2, 0) == 0);
    const phc_leaf_photos_row rows[] = {{.stage = 50, .pixels = &scan, .leaf = 2, .id = "b"},
                                        {.stage = 60, .pixels = &scan, .leaf = 1, .id = "a"},
                                        {.stage = 30, .pixels = &days[2], .id = "old"},
                                        {.stage = 45, .pixels = &days[0]}};
    phc_leaf_photos_options o = phc_leaf_photos_options_default();
    o.residual = PHC_LEAF_RESIDUAL_HISTOGRAM;
    o.quantiles = 8;
    o.direction = -1;
    o.reference = "old";
    o.setup.model_size = 32;
    o.stage_name = "SPAD";
    phc_dataset *ds = NULL;
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_leaf_photos_new(rows, 4, &o, &ds, &err) == PHC_OK);
    if (ds) {
        /* fresh: the highest SPAD (row "a"); data rows "b" and the unnamed 4th */
        printf("histogram data set: %zu residuals, %zu slots, series %s\n", ds->n, ds->k,
               ds->series ? "per quantile" : "none");
        CHECK(ds->n == 2 * 3 * 8 && ds->k == 6 && ds->series && ds->series[3 * 8 - 1] == 3 * 8 - 1);
        CHECK(!strcmp(ds->y_label, "CIELAB quantile (L*, a*, b*)"));
        ds->name = strdup("scan");
        CHECK(phc_dataset_describe_series(ds, &err) == PHC_OK);
        if (ds->series_names)
            printf("first series: '%s', last: '%s'\n", ds->series_names[0], ds->series_names[ds->n_series - 1]);
        CHECK(ds->n_series == 24 && ds->series_names && !strcmp(ds->series_names[0], "L*, 6.25 %"));
        phc_dataset_free(ds);
    } else
        fprintf(stderr, "%s\n", err.message);
    phc_image_free(&scan);
}

/* The line of each key in a pretend config. */
static size_t fake_key_line(const void *map, const char *key)
{
    (void)map;
    return !strcmp(key, "grid") ? 12 : !strcmp(key, "initial") ? 9 : 5;
}

static void test_messages(void)
{
    phc_leaf_photos_row rows[] = {{.stage = 0, .pixels = &fresh_img, .image = "fresh.png", .line = 2},
                                  {.stage = 4, .pixels = &days[1], .line = 3},
                                  {.stage = 2, .pixels = &days[0], .line = 4}};
    phc_leaf_photos_options o = phc_leaf_photos_options_default();
    o.reference_pixels = &old_img;
    o.setup.model_size = 32;
    phc_dataset *ds = NULL;
    phc_error err;

    o.grid = 1;
    CHECK(phc_leaf_photos_new(rows, 3, &o, &ds, &err) == PHC_ERR_INPUT && ds == NULL);
    printf("C, no origin: %s\n", err.message);
    CHECK(!strcmp(err.message, "leaf_photos: key 'grid': must be an integer from 2 to 512"));
    const phc_origin origin = {.path = "cfg.yaml", .map = "", .key_line = fake_key_line, .line = 5};
    o.origin = &origin;
    CHECK(phc_leaf_photos_new(rows, 3, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(!strcmp(err.message, "cfg.yaml:12: key 'grid': must be an integer from 2 to 512"));
    o.grid = 24;

    o.initial = "7";
    CHECK(phc_leaf_photos_new(rows, 3, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("with origin:  %s\n", err.message);
    CHECK(!strcmp(err.message, "cfg.yaml:9: key 'initial': no row has id '7'"));
    o.initial = NULL;

    /* pixels rows must be in stage order: rows[2] is not */
    o.origin = NULL;
    CHECK(phc_leaf_photos_new(rows, 3, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(!strcmp(err.message, "leaf_photos: rows[2] (stage): stages out of order (2 after 4): the photos of one "
                               "leaf must be listed in time order"));
    o.rows_source = "leaves.csv";
    o.stage_name = "day";
    CHECK(phc_leaf_photos_new(rows, 3, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("from a table: %s\n", err.message);
    CHECK(!strncmp(err.message, "leaves.csv:4: column 'day': stages out of order (2 after 4)", 58));
    o.rows_source = NULL;
    rows[2].stage = 6;

    rows[1].leaf = 3;
    CHECK(phc_leaf_photos_new(rows, 3, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(!strcmp(err.message, "leaf_photos: rows[1] (leaf): rows[1].pixels: leaf 3 requested, 1 leaf found"));
    rows[1].leaf = 0;

    rows[1].pixels = NULL;
    CHECK(phc_leaf_photos_new(rows, 3, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(!strcmp(err.message, "leaf_photos: rows[1] (image): no image file given"));
    rows[1].pixels = &days[1];

    o.reference_pixels = NULL;
    CHECK(phc_leaf_photos_new(rows, 3, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(strstr(err.message, "leaf_photos: missing key 'reference'") == err.message);
    o.reference_pixels = &old_img;

    rows[1].id = rows[2].id = "x";
    CHECK(phc_leaf_photos_new(rows, 3, &o, &ds, &err) == PHC_ERR_INPUT);
    printf("C, no origin: %s\n", err.message);
    CHECK(!strcmp(err.message, "leaf_photos: rows[2]: id 'x' is used twice (also rows[1])"));
    rows[1].id = rows[2].id = NULL;

    CHECK(phc_leaf_photos_new(rows, 1, &o, &ds, &err) == PHC_ERR_INPUT);
    CHECK(!strcmp(err.message, "leaf_photos: 1 row: a leaf_photos data set needs a fresh leaf and at least one "
                               "more photo"));

    /* the valid set: ids default to the rows' lines */
    CHECK(phc_leaf_photos_new(rows, 3, &o, &ds, &err) == PHC_OK);
    if (ds) {
        char *md = NULL;
        double p[6] = {50, 0.1, 0.05, 1, 0.2, 0.8};
        ds->name = strdup("msgs");
        CHECK(ds->ops->report_section(ds, p, &md, &err) == PHC_OK);
        CHECK(md && strstr(md, "the fresh leaf is leaf 1 of `fresh.png` (row '2', day 0)") &&
              strstr(md, "leaf 1 of `reference_pixels`"));
        if (md)
            printf("report: %.120s...\n", md);
        free(md);
        phc_dataset_free(ds);
    }
}

int main(void)
{
    if (draw_leaves(&fresh_img, 1, 0) || draw_leaves(&old_img, 1, 1))
        return 1;
    test_fit();
    test_histogram();
    test_messages();
    phc_image_free(&fresh_img);
    phc_image_free(&old_img);
    for (int d = 0; d < 3; ++d)
        phc_image_free(&days[d]);
    return check_finish("test_leaf_photos_new");
}
