/* Shared by the leaf-colour notebooks built on a synthetic photo series
 * (silva_identifiability, silva_mcmc_pairs): the series' settings (leaf,
 * grid, days, true parameters, boxes, starts), the frame composition
 * (misalignment, lighting, noise) and the leaf_photos problem of one case
 * built through the C API.  Header-only (static functions) because ctest
 * builds each notebook from its own .c file. */
#ifndef PHC_SILVA_SERIES_H
#define PHC_SILVA_SERIES_H


#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "fit/costs/leaf_photos.h"
#include "fit/costs/leaf_setup.h"
#include "fit/engine/fit.h"
#include "fit/engine/parameter_units.h"
#include "fit/engine/problem.h"
#include "measurements/photo.h"
#include "model/colour.h"
#include "model/leaf.h"

#define SCAN PHC_SHARED_DATA "/leaf_photos/ivy_spad/ivy_15_leaves_scan.jpg"
#define FRESH_LEAF 9
#define REF_LEAF 1
#define MODEL_SIZE 96
#define LEAF_ZOOM 2   /* the leaf on the sheet: this many px per model px */
#define PAPER_ZOOM 3  /* the sheet: this many times the model grid */
#define PAPER 0.92    /* sRGB grey level of the paper (below 1, so the gains do not clip it) */
#define NDAY 5
#define NPAR 5
#define NCASE 2
#define NSTART 2
#define NOISE 0.02
#define ROT_DEG 1.0
#define SHIFT_PX 1.5
#define SEED 77031u
#define GRID 24       /* residual cells on the long side */
#define SIGMA 2.0     /* ΔE per residual */

__attribute__((unused)) static const double days[NDAY] = {2, 4, 6, 8, 10};
__attribute__((unused)) static const double gains[3] = {1.05, 0.97, 1.02};
__attribute__((unused)) static const char *const pname[NPAR] = {"beta_scale", "stomata_scale", "inflow_scale", "y_lo", "y_hi"};
__attribute__((unused)) static const double truth[NPAR] = {20.0, 0.12, 0.4, 0.3, 0.8};
__attribute__((unused)) static const double lower[NPAR] = {0.5, 0.005, 0.0, -0.5, 0.35};
__attribute__((unused)) static const double upper[NPAR] = {500.0, 1.0, 4.0, 0.75, 2.0};
/* the starts: ×2 / ×0.5 for the scales; the transfer moved inside its order */
__attribute__((unused)) static const double start[NSTART][NPAR] = {{40.0, 0.06, 0.8, 0.15, 0.95}, {10.0, 0.24, 0.2, 0.45, 0.65}};
__attribute__((unused)) static const char *const case_name[NCASE] = {"perturbed", "control"};

static uint64_t rng_state;
__attribute__((unused)) static uint64_t splitmix64(void)
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}
__attribute__((unused)) static double uniform01(void) { return ((double)(splitmix64() >> 11) + 0.5) * (1.0 / 9007199254740992.0); }
__attribute__((unused)) static double gauss(void)
{
    const double u = uniform01(), v = uniform01();
    return sqrt(-2.0 * log(u)) * cos(6.283185307179586 * v);
}
__attribute__((unused)) static double decode(double v) { return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4); }
__attribute__((unused)) static double encode(double v)
{
    v = fmin(fmax(v, 0.0), 1.0);
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

/* A frame: the leaf (sRGB on the model grid, mask) enlarged LEAF_ZOOM times,
 * optionally warped, laid at the centre of a sheet of paper; then
 * optionally the lighting gains and the noise.  *out allocated here. */
__attribute__((unused)) static int compose(const phc_image *leaf, const unsigned char *mask, int perturb, phc_image *out, phc_error *err)
{
    const size_t W = PAPER_ZOOM * leaf->width, H = PAPER_ZOOM * leaf->height;
    const size_t lw = LEAF_ZOOM * leaf->width, lh = LEAF_ZOOM * leaf->height;
    const size_t ox = (W - lw) / 2, oy = (H - lh) / 2;
    phc_image big = {0}, layer = {0}, alpha = {0}, wl = {0}, wa = {0};
    int rc;
    if ((rc = phc_photo_resize(leaf, lw, lh, &big, err)) || (rc = phc_image_alloc(&layer, W, H, err)) ||
        (rc = phc_image_alloc(&alpha, W, H, err)) || (rc = phc_image_alloc(out, W, H, err)))
        goto done;
    for (size_t y = 0; y < lh; ++y)
        for (size_t x = 0; x < lw; ++x) {
            const size_t i = (ox + x) + W * (oy + y), j = x + lw * y;
            const int in = mask[(x / LEAF_ZOOM) + leaf->width * (y / LEAF_ZOOM)] != 0;
            memcpy(layer.data + 3 * i, big.data + 3 * j, 3 * sizeof(double));
            alpha.data[3 * i] = alpha.data[3 * i + 1] = alpha.data[3 * i + 2] = in;
        }
    const phc_image *L = &layer, *A = &alpha;
    if (perturb) {
        /* out(x) = layer(M x): rotation by ROT_DEG about the centre, then a
         * shift of SHIFT_PX along x and y / 2 */
        const double th = ROT_DEG * 3.141592653589793 / 180.0, cx = 0.5 * (double)W, cy = 0.5 * (double)H;
        const double c = cos(th), s = sin(th);
        const double warp[6] = {c, -s, cx - c * cx + s * cy + SHIFT_PX, s, c, cy - s * cx - c * cy + 0.5 * SHIFT_PX};
        if ((rc = phc_photo_warp(&layer, warp, W, H, &wl, err)) || (rc = phc_photo_warp(&alpha, warp, W, H, &wa, err)))
            goto done;
        L = &wl, A = &wa;
    }
    for (size_t i = 0; i < W * H; ++i) {
        const double a = fmin(fmax(A->data[3 * i], 0.0), 1.0);
        for (int ch = 0; ch < 3; ++ch) {
            double v = a * L->data[3 * i + ch] + (1 - a) * PAPER;
            if (perturb) {
                v = encode(gains[ch] * decode(v)) + NOISE * gauss();
                v = fmin(fmax(v, 0.0), 1.0);
            }
            out->data[3 * i + ch] = v;
        }
    }
done:
    phc_image_free(&big);
    phc_image_free(&layer);
    phc_image_free(&alpha);
    phc_image_free(&wl);
    phc_image_free(&wa);
    if (rc)
        phc_image_free(out);
    return rc;
}

/* The paths of a case's photos in dir: fresh.png, then <case>_dayDD.png. */
__attribute__((unused)) static void frame_path(char *buf, size_t size, const char *dir, int cs, int d)
{
    if (d < 0)
        snprintf(buf, size, "%s/fresh.png", dir);
    else
        snprintf(buf, size, "%s/%s_day%02d.png", dir, case_name[cs], (int)days[d]);
}

__attribute__((unused)) static int is_fitted(const char *name, void *user_data)
{
    (void)user_data;
    for (int p = 0; p < NPAR; ++p)
        if (!strcmp(name, pname[p]))
            return 1;
    return 0; /* time_scale: its default, 1 (stage = day) */
}

/* Case cs's problem from start st, built through the C API: a leaf_photos
 * data set over the fresh photo (id "fresh", day 0) and the frames (id
 * "d<day>"), the scan's leaf REF_LEAF as the reference, pixels residuals on
 * a GRID grid with sigma SIGMA, registration on, gray-world correction in
 * the perturbed case, none in the control; the five parameters in their
 * boxes, one start, at most 60 iterations.  st = NSTART: a run from the
 * truth limited to one iteration, to read the objective at the truth
 * (summary.initial_cost). */
__attribute__((unused)) static phc_problem *build_problem(const char *dir, int cs, int st, phc_error *err)
{
    const double *v = st < NSTART ? start[st] : truth;
    char name[64], paths[NDAY + 1][2048], ids[NDAY + 1][16];
    snprintf(name, sizeof name, "silva-ident-%s-%d", case_name[cs], st + 1);
    phc_leaf_photos_row rows[NDAY + 1];
    memset(rows, 0, sizeof rows);
    for (int r = 0; r <= NDAY; ++r) {
        frame_path(paths[r], sizeof paths[r], dir, cs, r - 1);
        snprintf(ids[r], sizeof ids[r], r ? "d%d" : "fresh", r ? (int)days[r - 1] : 0);
        rows[r].stage = r ? days[r - 1] : 0;
        rows[r].image = paths[r];
        rows[r].id = ids[r];
    }
    phc_leaf_photos_options lo = phc_leaf_photos_options_default();
    lo.stage_name = "day";
    lo.initial = "fresh";
    lo.reference_image = SCAN;
    lo.reference_leaf = REF_LEAF;
    lo.residual = PHC_LEAF_RESIDUAL_PIXELS;
    lo.grid = GRID;
    lo.sigma = SIGMA;
    lo.register_photos = 1;
    lo.colour_correction = cs == 0 ? PHC_CC_GRAY_WORLD : PHC_CC_NONE;
    lo.setup.model_size = MODEL_SIZE;
    lo.setup.dt = 0.1;
    lo.is_parameter = is_fitted;
    phc_problem *pb = phc_problem_new(name);
    phc_dataset *ds = NULL;
    int rc = pb ? PHC_OK : phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    for (int p = 0; p < NPAR && !rc; ++p) {
        size_t i = 0;
        if (!(rc = phc_problem_add_parameter(pb, pname[p], v[p], &i, err))) {
            pb->params[i].lower = lower[p];
            pb->params[i].upper = upper[p];
        }
    }
    if (!rc) {
        pb->options.nls.max_iterations = st < NSTART ? 60 : 1;
        pb->options.starts = 1;
    }
    if (!rc && !(rc = phc_leaf_photos_new(rows, NDAY + 1, &lo, &ds, err))) {
        if (!(ds->name = strdup("frames")))
            rc = phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
        if (!rc && !(rc = phc_problem_bind_by_name(pb, ds, err))) {
            rc = phc_problem_add_dataset(pb, ds, err);
            ds = NULL;
        }
    }
    phc_dataset_free(ds);
    if (!rc)
        rc = phc_problem_finish(pb, 0, err);
    if (rc) {
        phc_problem_free(pb);
        return NULL;
    }
    return pb;
}

#endif /* PHC_SILVA_SERIES_H */
