/* A `leaf_photos` data set in pixels mode, end to end, on photos made here
 * (no shared data needed): a synthetic green leaf (an ellipse with a midrib
 * and side veins on white paper) and a yellow reference are written as PNG;
 * the data set's own set-up (leaf_setup.h) ages the green leaf with known
 * scales, and the simulated leaves, enlarged back to the photo's size and
 * put on white paper, become the photos of days 2, 4 and 6.
 *
 * Checks: the config loads (segmentation, registration by silhouette, grid
 * cells); the residuals at the true values are clearly smaller than at a
 * doubled inflow scale; a fit from a wrong start converges to a cost no
 * higher than the truth's (within 5%) with the inflow scale within 10% of
 * the truth (beta_scale is printed: on this 48 px grid it is weakly
 * determined);
 * `fit` writes the observed-vs-simulated sheet and `simulate` the frames,
 * fluid maps and contact sheet. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "fit/config.h"
#include "fit/leaf_images.h"
#include "fit/costs/leaf_setup.h"
#include "fit/engine/fit.h"
#include "fit/run_dir.h"
#include "fit/simulate.h"

#define W 240
#define H 160

/* A leaf on white paper: an ellipse, green with darker veins, or yellow. */
static int draw_leaf(const char *path, int yellow)
{
    phc_image img = {0};
    phc_error err;
    if (phc_image_alloc(&img, W, H, &err))
        return 1;
    for (size_t y = 0; y < H; ++y)
        for (size_t x = 0; x < W; ++x) {
            double *c = img.data + 3 * (x + W * y);
            const double u = (x - W / 2.0) / (0.42 * W), v = (y - H / 2.0) / (0.40 * H);
            c[0] = c[1] = c[2] = 1;
            if (u * u + v * v >= 1)
                continue;
            /* midrib along y = H/2 and side veins at 45 degrees */
            const double dy = fabs(y - H / 2.0), dx = fmod(fabs(x - W / 2.0 + dy) + 1000, 30.0);
            const int vein = dy < 1.5 || dx < 1.5;
            /* a little texture so that registration has something to hold */
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
    int rc = phc_photo_write_png(path, &img, &err);
    if (rc)
        fprintf(stderr, "%s\n", err.message);
    phc_image_free(&img);
    return rc;
}

/* The simulated leaf at day t, enlarged to the photo's size on white. */
static int write_day(phc_leaf_setup *su, double t, phc_colour_transfer tf, const char *path, const phc_leaf_photo *fresh)
{
    phc_error err;
    phc_image sim = {0}, big = {0}, page = {0};
    int rc = 1;
    phc_leaf_reset(su->leaf, 1.0);
    if (phc_leaf_advance(su->leaf, t) || phc_leaf_setup_colours(su, tf, NULL, &sim, &err) ||
        phc_photo_resize(&sim, fresh->crop.width, fresh->crop.height, &big, &err) ||
        phc_image_alloc(&page, W, H, &err))
        goto done;
    for (size_t i = 0; i < 3 * W * H; ++i)
        page.data[i] = 1;
    for (size_t y = 0; y < big.height; ++y)
        for (size_t x = 0; x < big.width; ++x)
            if (fresh->mask[x + big.width * y])
                memcpy(page.data + 3 * (fresh->x0 + x + W * (fresh->y0 + y)), big.data + 3 * (x + big.width * y),
                       3 * sizeof(double));
    rc = phc_photo_write_png(path, &page, &err);
done:
    if (rc)
        fprintf(stderr, "write_day: %s\n", err.message);
    phc_image_free(&sim);
    phc_image_free(&big);
    phc_image_free(&page);
    return rc;
}

static double wrss_at(phc_dataset *ds, const double *p)
{
    double *yh = malloc(ds->n * sizeof *yh), s = 0;
    if (ds->ops->predict(ds, p, yh, NULL) != 0) {
        free(yh);
        return NAN;
    }
    for (size_t i = 0; i < ds->n; ++i)
        s += pow((ds->y[i] - yh[i]) / ds->sigma[i], 2);
    free(yh);
    return s;
}

int main(void)
{
    char dir[] = "/tmp/phc_leaf_pixels_XXXXXX", path[1024], fresh_png[512], ref_png[512];
    if (!mkdtemp(dir))
        return 1;
    snprintf(fresh_png, sizeof fresh_png, "%s/fresh.png", dir);
    snprintf(ref_png, sizeof ref_png, "%s/old.png", dir);
    CHECK(draw_leaf(fresh_png, 0) == 0);
    CHECK(draw_leaf(ref_png, 1) == 0);

    /* the truth: the same set-up the data set will build (model_size 48) */
    const double truth_beta = 20, truth_inflow = 0.3, stomata = 0.1;
    const phc_colour_transfer tf = {0.2, 0.8};
    phc_error err;
    phc_photo_cache *cache = phc_photo_cache_new();
    phc_leaf_photo fresh, ref;
    phc_leaf_setup *su = NULL;
    CHECK(phc_leaf_photo_load(cache, fresh_png, 1, PHC_CC_NONE, NULL, &fresh, &err) == PHC_OK);
    CHECK(phc_leaf_photo_load(cache, ref_png, 1, PHC_CC_NONE, NULL, &ref, &err) == PHC_OK);
    CHECK(fresh.leaves == 1);
    phc_leaf_setup_options so = phc_leaf_setup_options_default();
    so.model_size = 48;
    CHECK(phc_leaf_setup_new(&fresh, &ref, &so, &su, &err) == PHC_OK);
    if (!su) {
        fprintf(stderr, "%s\n", err.message);
        return check_finish("test_leaf_pixels");
    }
    phc_leaf_params lp = phc_leaf_get_params(su->leaf);
    lp.beta_scale = truth_beta;
    lp.inflow_scale = truth_inflow;
    lp.stomata_scale = stomata;
    CHECK(phc_leaf_set_params(su->leaf, lp, &err) == PHC_OK);
    const double days[3] = {2, 4, 6};
    char csv[512], cfg[512];
    snprintf(csv, sizeof csv, "%s/photos.csv", dir);
    FILE *f = fopen(csv, "w");
    fprintf(f, "day,image\n0,fresh.png\n");
    for (int d = 0; d < 3; ++d) {
        snprintf(path, sizeof path, "%s/day%d.png", dir, (int)days[d]);
        CHECK(write_day(su, days[d], tf, path, &fresh) == 0);
        fprintf(f, "%g,day%d.png\n", days[d], (int)days[d]);
    }
    fclose(f);
    phc_leaf_setup_free(su);
    phc_leaf_photo_free(&fresh);
    phc_leaf_photo_free(&ref);
    phc_photo_cache_free(cache);

    snprintf(cfg, sizeof cfg, "%s/pixels.yaml", dir);
    f = fopen(cfg, "w");
    fprintf(f, "name: leaf-pixels\n"
               "parameters:\n"
               "  beta_scale: {value: 35, lower: 0, upper: 500}\n"
               "  inflow_scale: {value: 0.15, lower: 0, upper: 5}\n"
               "  stomata_scale: {value: %g, fixed: true}\n"
               "datasets:\n"
               "  - kind: leaf_photos\n"
               "    name: leaf\n"
               "    file: photos.csv\n"
               "    image: {column: image}\n"
               "    stage: {column: day}\n"
               "    reference: {image: old.png}\n"
               "    residual: pixels\n"
               "    grid: 12\n"
               "    model_size: 48\n"
               "    sigma: 1\n",
            stomata);
    fclose(f);

    phc_problem *pb = NULL;
    phc_fit_result *res = NULL;
    CHECK(phc_config_load(cfg, &pb, &err) == PHC_OK);
    if (!pb) {
        fprintf(stderr, "%s\n", err.message);
        return check_finish("test_leaf_pixels");
    }
    phc_dataset *ds = pb->datasets[0];
    printf("leaf_pixels_residuals: %zu\n", ds->n);
    CHECK(ds->n >= 3 * 3 * 20); /* three photos, at least 20 cells each, 3 components */
    /* slots in order beta_scale, stomata_scale, inflow_scale */
    const double p_true[3] = {truth_beta, stomata, truth_inflow}, p_wrong[3] = {truth_beta, stomata, 2 * truth_inflow};
    const double w_true = wrss_at(ds, p_true), w_wrong = wrss_at(ds, p_wrong);
    printf("leaf_pixels_wrss_truth: %.4g\nleaf_pixels_wrss_inflow_x2: %.4g\n", w_true, w_wrong);
    /* the photos went model grid -> photo size -> model grid, which blurs:
     * the truth is not a perfect fit (RMS about 1.8 ΔE per component), but
     * it is clearly better than a wrong inflow */
    CHECK(w_true < 0.6 * w_wrong);

    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    if (res) {
        CHECK(res->summary.outcome == PHC_NLS_CONVERGED);
        printf("leaf_pixels_wrss_fit: %.4g\n", res->wrss);
        CHECK(res->wrss <= 1.05 * w_true);
        for (size_t i = 0; i < res->n_params; ++i) {
            printf("leaf_pixels_%s: %.5g +- %.3g\n", res->params[i].name, res->params[i].value, res->params[i].stderr_);
            /* beta_scale is weakly determined on a 48 px grid whose veins are
             * one pixel wide: only its sign and finiteness are checked */
            if (!strcmp(res->params[i].name, "beta_scale"))
                CHECK(isfinite(res->params[i].value) && res->params[i].value >= 0);
            if (!strcmp(res->params[i].name, "inflow_scale"))
                CHECK_NEAR(res->params[i].value, truth_inflow, 0, 0.10);
        }
        char out[600];
        snprintf(out, sizeof out, "%s/run", dir);
        CHECK(phc_run_dir_write(res, pb, out, 0, &err) == PHC_OK);
        snprintf(path, sizeof path, "%s/leaf_observed_vs_simulated.png", out);
        CHECK(access(path, R_OK) == 0);
        snprintf(out, sizeof out, "%s/sim", dir);
        CHECK(phc_simulate_write(pb, NULL, out, 0, &err) == PHC_OK);
        snprintf(path, sizeof path, "%s/leaf_contact_sheet.png", out);
        CHECK(access(path, R_OK) == 0);
        snprintf(path, sizeof path, "%s/leaf_fluid_07.png", out);
        CHECK(access(path, R_OK) == 0);
        snprintf(path, sizeof path, "%s/leaf_veins_map.png", out);
        CHECK(access(path, R_OK) == 0);
    } else
        fprintf(stderr, "%s\n", err.message);
    phc_fit_result_free(res);
    phc_problem_free(pb);
    char cmd[700];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    return check_finish("test_leaf_pixels");
}
