/* Identifiability of the leaf colour aging model (Silva et al. §3) from a
 * photo series: can s_β (beta_scale), s_O (stomata_scale), s_I
 * (inflow_scale) and the colour transfer (y_lo, y_hi) be recovered from
 * photographs of one leaf at a few times?
 *
 * Synthetic series made by the model from a real leaf:
 *   1. ivy leaf 9 of the scan (the greenest) is cut out on the model grid
 *      (model_size MODEL_SIZE) and drawn, enlarged LEAF_ZOOM times, on a
 *      sheet of white paper PAPER_ZOOM times the grid: fresh.png, the
 *      fresh leaf "as its own photo";
 *   2. the data set's own pipeline (fit/costs/leaf_setup.h) is built from
 *      fresh.png and ivy leaf 1 (the most yellow) as the reference, and run
 *      with the true parameters; its colours at days 2, 4, 6, 8, 10 are
 *      drawn on the paper the same way (time_scale fixed at 1, stage = day);
 *   3. case "perturbed": each frame is then misaligned (1° rotation about
 *      the sheet centre and a 1.5 px shift, phc_photo_warp with a known
 *      warp, before it is laid on the paper), lit differently (gains 1.05,
 *      0.97, 1.02 on linear R, G, B of the whole frame) and noisy (Gaussian,
 *      σ = 0.02 in sRGB, seeded), and fitted with `register: true` and
 *      `colour_correction: gray_world`; case "control": no misalignment, no
 *      lighting change, no noise, fitted with `colour_correction: none`.
 * The frames are written into a temporary directory as PNG photos; each
 * case's problem is built through the C API (phc_leaf_photos_new over the
 * rows fresh, d2 ... d10, a problem of its own) and fitted with phc_fit_run
 * from two starts off the truth.
 *
 * Reported per parameter: true, fitted, standard error, |error| / SE, the
 * correlation matrix and the undetermined combinations of the fit, and a
 * verdict.  Exit 1 only when a fit or a file fails (an unidentifiable
 * parameter is a finding, not a failure).
 *
 * Usage: notebook_silva_identifiability OUTPUT_DIR */
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

#include "notebook_plot.h"

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

static const double days[NDAY] = {2, 4, 6, 8, 10};
static const double gains[3] = {1.05, 0.97, 1.02};
static const char *const pname[NPAR] = {"beta_scale", "stomata_scale", "inflow_scale", "y_lo", "y_hi"};
static const double truth[NPAR] = {20.0, 0.12, 0.4, 0.3, 0.8};
static const double lower[NPAR] = {0.5, 0.005, 0.0, -0.5, 0.35};
static const double upper[NPAR] = {500.0, 1.0, 4.0, 0.75, 2.0};
/* the starts: ×2 / ×0.5 for the scales; the transfer moved inside its order */
static const double start[NSTART][NPAR] = {{40.0, 0.06, 0.8, 0.15, 0.95}, {10.0, 0.24, 0.2, 0.45, 0.65}};
static const char *const case_name[NCASE] = {"perturbed", "control"};

static uint64_t rng_state;
static uint64_t splitmix64(void)
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}
static double uniform01(void) { return ((double)(splitmix64() >> 11) + 0.5) * (1.0 / 9007199254740992.0); }
static double gauss(void)
{
    const double u = uniform01(), v = uniform01();
    return sqrt(-2.0 * log(u)) * cos(6.283185307179586 * v);
}
static double decode(double v) { return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4); }
static double encode(double v)
{
    v = fmin(fmax(v, 0.0), 1.0);
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

/* A frame: the leaf (sRGB on the model grid, mask) enlarged LEAF_ZOOM times,
 * optionally warped, laid at the centre of a sheet of paper; then
 * optionally the lighting gains and the noise.  *out allocated here. */
static int compose(const phc_image *leaf, const unsigned char *mask, int perturb, phc_image *out, phc_error *err)
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
static void frame_path(char *buf, size_t size, const char *dir, int cs, int d)
{
    if (d < 0)
        snprintf(buf, size, "%s/fresh.png", dir);
    else
        snprintf(buf, size, "%s/%s_day%02d.png", dir, case_name[cs], (int)days[d]);
}

static int is_fitted(const char *name, void *user_data)
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
static phc_problem *build_problem(const char *dir, int cs, int st, phc_error *err)
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

typedef struct outcome {
    int ok, converged;
    double value[NPAR], se[NPAR], corr[NPAR][NPAR], wrss, s, seconds, initial_wrss;
    size_t n_obs, n_undet;
    char undet[6][160];
} outcome;

static int run_fit(const char *dir, int cs, int st, outcome *o, phc_error *err)
{
    phc_fit_result *res = NULL;
    memset(o, 0, sizeof *o);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    phc_problem *pb = build_problem(dir, cs, st, err);
    int rc = pb ? PHC_OK : err->status ? err->status : PHC_ERR_INPUT;
    if (!rc)
        rc = phc_fit_run(pb, NULL, NULL, &res, err);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    o->seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    if (rc) {
        phc_problem_free(pb);
        return rc;
    }
    o->ok = 1;
    o->converged = res->summary.outcome == PHC_NLS_CONVERGED;
    o->wrss = res->wrss;
    o->initial_wrss = 2.0 * res->summary.initial_cost;
    o->s = sqrt(res->s2);
    o->n_obs = res->n_obs;
    long fidx[NPAR];
    for (int p = 0; p < NPAR; ++p) {
        o->value[p] = o->se[p] = NAN;
        fidx[p] = -1;
        for (size_t i = 0; i < res->n_params; ++i)
            if (!strcmp(res->params[i].name, pname[p])) {
                o->value[p] = res->params[i].value;
                o->se[p] = res->params[i].stderr_;
                for (size_t q = 0; q < res->n_free; ++q)
                    if (res->free_index[q] == i)
                        fidx[p] = (long)q;
            }
    }
    for (int p = 0; p < NPAR; ++p)
        for (int q = 0; q < NPAR; ++q)
            o->corr[p][q] = fidx[p] >= 0 && fidx[q] >= 0
                                ? res->correlation[(size_t)fidx[p] * res->n_free + (size_t)fidx[q]]
                                : NAN;
    o->n_undet = res->n_undetermined < 6 ? res->n_undetermined : 6;
    for (size_t k = 0; k < o->n_undet; ++k)
        snprintf(o->undet[k], sizeof o->undet[k], "%s", res->undetermined[k]);
    phc_fit_result_free(res);
    phc_problem_free(pb);
    return 0;
}

/* The best of the starts of a case: the lowest weighted residual sum. */
static int best_of(const outcome o[NSTART])
{
    int b = -1;
    for (int s = 0; s < NSTART; ++s)
        if (o[s].ok && (b < 0 || o[s].wrss < o[b].wrss))
            b = s;
    return b;
}

static const char *verdict(double v, double se, double t)
{
    const double z = fabs(v - t) / se, rel = se / fabs(v);
    if (!isfinite(v))
        return "no fit";
    if (!isfinite(se))
        return "not determined";
    if (rel > 0.5)
        return "poorly determined (SE > 50%)";
    if (z > 3)
        return fabs(v - t) / fabs(t) < 0.1 ? "recovered within 10%, SE too small" : "biased (> 3 SE)";
    return "recovered";
}

int main(int argc, char **argv)
{
    const char *out;
    int rc = nb_begin(argc, argv, SCAN, &out);
    if (rc)
        return rc == 77 ? 77 : rc;
    struct timespec tstart, tend;
    clock_gettime(CLOCK_MONOTONIC, &tstart);
    phc_error err = {0};
    phc_photo_cache *cache = phc_photo_cache_new();
    phc_leaf_photo fresh0 = {0}, ref = {0}, fresh = {0};
    phc_leaf_setup *su0 = NULL, *su = NULL;
    phc_image sheet = {0}, frame_img = {0};
    char dir[] = "/tmp/phc_silva_ident_XXXXXX", path[2048], names[64][2048];
    size_t n_names = 0;
    int status = 1;
    outcome o[NCASE][NSTART], at_truth[NCASE];
    memset(o, 0, sizeof o);
    if (!cache || !mkdtemp(dir)) {
        fprintf(stderr, "silva_identifiability: cannot create a temporary directory\n");
        phc_photo_cache_free(cache);
        return 1;
    }
#define REMEMBER(p) (n_names < 64 ? (void)snprintf(names[n_names++], sizeof names[0], "%s", p) : (void)0)

    /* 1. the fresh leaf as its own photo */
    phc_leaf_setup_options so = phc_leaf_setup_options_default();
    so.model_size = MODEL_SIZE;
    if (phc_leaf_photo_load(cache, SCAN, FRESH_LEAF, PHC_CC_NONE, NULL, &fresh0, &err) ||
        phc_leaf_photo_load(cache, SCAN, REF_LEAF, PHC_CC_NONE, NULL, &ref, &err) ||
        phc_leaf_setup_new(&fresh0, &ref, &so, &su0, &err))
        goto fail;
    {
        phc_image leaf = {0};
        if (phc_image_alloc(&leaf, su0->w, su0->h, &err))
            goto fail;
        memcpy(leaf.data, su0->fresh.data, 3 * su0->w * su0->h * sizeof(double));
        rc = compose(&leaf, su0->mask, 0, &sheet, &err);
        phc_image_free(&leaf);
        snprintf(path, sizeof path, "%s/fresh.png", dir);
        if (rc || phc_photo_write_png(path, &sheet, &err))
            goto fail;
        REMEMBER(path);
        phc_image_free(&sheet);
    }
    /* 2. the generating set-up: the data set's own pipeline on fresh.png */
    if (phc_leaf_photo_load(cache, path, 1, PHC_CC_NONE, NULL, &fresh, &err) ||
        phc_leaf_setup_new(&fresh, &ref, &so, &su, &err))
        goto fail;
    phc_leaf_params lp = phc_leaf_get_params(su->leaf);
    lp.beta_scale = truth[0];
    lp.stomata_scale = truth[1];
    lp.inflow_scale = truth[2];
    if (phc_leaf_set_params(su->leaf, lp, &err))
        goto fail;
    const phc_colour_transfer tf = {truth[3], truth[4]};
    phc_image frames[NDAY];
    memset(frames, 0, sizeof frames);
    phc_leaf_reset(su->leaf, 1.0);
    double mean_y[NDAY];
    for (int d = 0; d < NDAY; ++d) {
        if (phc_leaf_advance(su->leaf, days[d] - phc_leaf_time(su->leaf)) ||
            phc_leaf_setup_colours(su, tf, NULL, &frames[d], &err))
            goto fail;
        const double *yy = phc_leaf_fluid(su->leaf);
        mean_y[d] = 0;
        for (size_t i = 0; i < su->w * su->h; ++i)
            mean_y[d] += yy[i];
        mean_y[d] /= (double)su->cells;
    }
    /* 3. the two cases: frames, CSV, configs, fits */
    rng_state = SEED;
    for (int cs = 0; cs < NCASE; ++cs) {
        for (int d = 0; d < NDAY; ++d) {
            if (compose(&frames[d], su->mask, cs == 0, &frame_img, &err))
                goto fail_frames;
            frame_path(path, sizeof path, dir, cs, d);
            rc = phc_photo_write_png(path, &frame_img, &err);
            if (!rc && cs == 0 && d == NDAY - 1) {
                char keep[1024];
                snprintf(keep, sizeof keep, "%s/silva_identifiability_frame.png", out);
                rc = phc_photo_write_png(keep, &frame_img, &err);
            }
            phc_image_free(&frame_img);
            if (rc)
                goto fail_frames;
            REMEMBER(path);
        }
        for (int st = 0; st < NSTART; ++st) {
            if (run_fit(dir, cs, st, &o[cs][st], &err))
                goto fail_frames;
            printf("fit %s start %d: %s, %.1f s, weighted RSS %.4g over %zu residuals\n", case_name[cs], st + 1,
                   o[cs][st].converged ? "converged" : "not converged", o[cs][st].seconds, o[cs][st].wrss,
                   o[cs][st].n_obs);
        }
        if (run_fit(dir, cs, NSTART, &at_truth[cs], &err))
            goto fail_frames;
        printf("ident_wrss_at_truth_%s: %.4g\n", case_name[cs], at_truth[cs].initial_wrss);
    }
    for (int d = 0; d < NDAY; ++d)
        phc_image_free(&frames[d]);

    /* the printed numbers: the best start of each case */
    int best[NCASE];
    for (int cs = 0; cs < NCASE; ++cs)
        best[cs] = best_of(o[cs]);
    for (int p = 0; p < NPAR; ++p) {
        const outcome *b = &o[0][best[0]], *c = &o[1][best[1]];
        printf("ident_%s_ratio: %.4f\n", pname[p], b->value[p] / truth[p]);
        printf("ident_%s_ratio_control: %.4f\n", pname[p], c->value[p] / truth[p]);
    }
    clock_gettime(CLOCK_MONOTONIC, &tend);
    const double total = (double)(tend.tv_sec - tstart.tv_sec) + 1e-9 * (double)(tend.tv_nsec - tstart.tv_nsec);
    printf("ident_runtime_s: %.1f\n", total);

    /* the page */
    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "silva_identifiability.md", md, mdtmp, sizeof md);
    if (!f) {
        phc_error_set(&err, PHC_ERR_IO, "%s: cannot write the page", out);
        goto fail;
    }
    fprintf(f,
            "# Identifiability of the leaf colour aging model from a photo series\n\n"
            "**Question.** Silva et al. (§3) drive the leaf's colours with a fluid model of three scales —\n"
            "s_β (`beta_scale`, diffusion along the venation), s_O (`stomata_scale`, transpiration) and s_I\n"
            "(`inflow_scale`, inflow along the veins) — and a colour transfer g(y) between two fluid levels\n"
            "(`y_lo`, `y_hi`, eq. 9). Which of the five can a `leaf_photos` data set recover from a few\n"
            "photographs of one leaf, when the photos are noisy, lit differently and not aligned?\n\n"
            "**Synthetic series from a real leaf.** Ivy leaf %d of `leaf_photos/ivy_spad/ivy_15_leaves_scan.jpg`\n"
            "(the greenest) on a %zu × %zu model grid (model_size %d), drawn %d× enlarged on grey-white paper\n"
            "(sRGB %.2f) %d× the grid, is the fresh leaf's own photo; the data set's pipeline built from that\n"
            "photo and ivy leaf %d (the most yellow) as the reference (`{image: scan, leaf: %d}`) was run with\n"
            "the true values below (time_scale fixed at 1, stage = day, dt = 0.1 day) and its colours at days",
            FRESH_LEAF, su->w, su->h, MODEL_SIZE, LEAF_ZOOM, PAPER, PAPER_ZOOM, REF_LEAF, REF_LEAF);
    for (int d = 0; d < NDAY; ++d)
        fprintf(f, "%s%g", d ? ", " : " ", days[d]);
    fprintf(f, " (mean fluid");
    for (int d = 0; d < NDAY; ++d)
        fprintf(f, "%s%.2f", d ? ", " : " ", mean_y[d]);
    fprintf(f,
            ") drawn the same way. Two cases:\n\n"
            "- **perturbed**: each frame's leaf is rotated by %g° about the sheet centre and shifted by %g px\n"
            "  (x) and %g px (y) (`phc_photo_warp`, known warp), the whole frame is lit with per-channel gains\n"
            "  %.2f, %.2f, %.2f on linear R, G, B, and Gaussian noise σ = %g (sRGB) is added (seed %u); fitted\n"
            "  with `register: true` (ECC alignment to the fresh photo) and `colour_correction: gray_world`\n"
            "  (every photo, the fresh one and the reference scan included, is corrected the same way);\n"
            "- **control**: the same frames without misalignment, lighting change or noise, `register: true`,\n"
            "  `colour_correction: none`.\n\n"
            "Residuals: `pixels` (ΔL*, Δa*, Δb* of %d-cell-grid means, σ = %g ΔE). Each case was fitted from\n"
            "two starts off the truth (scales ×2 / ×0.5, transfer moved); the table shows the start with the\n"
            "lower weighted residual sum.\n\n"
            "![a perturbed frame (day %g) as written](silva_identifiability_frame.png)\n\n",
            ROT_DEG, SHIFT_PX, 0.5 * SHIFT_PX, gains[0], gains[1], gains[2], NOISE, SEED, GRID, SIGMA,
            days[NDAY - 1]);
    for (int cs = 0; cs < NCASE; ++cs) {
        const outcome *b = &o[cs][best[cs]];
        fprintf(f, "### Case %s\n\n", case_name[cs]);
        fprintf(f, "| start | outcome | weighted RSS | residuals | s | time (s) |\n|---|---|---:|---:|---:|---:|\n");
        for (int st = 0; st < NSTART; ++st)
            fprintf(f, "| %d | %s | %.4g | %zu | %.3g | %.1f |\n", st + 1,
                    o[cs][st].converged ? "converged" : "not converged", o[cs][st].wrss, o[cs][st].n_obs,
                    o[cs][st].s, o[cs][st].seconds);
        fprintf(f, "| (truth) | objective at the true values | %.4g | %zu | | |\n", at_truth[cs].initial_wrss,
                at_truth[cs].n_obs);
        fprintf(f, "\n| parameter | true | start | fitted | SE | fitted / true | abs(error) / SE | verdict |\n"
                   "|---|---:|---:|---:|---:|---:|---:|---|\n");
        for (int p = 0; p < NPAR; ++p)
            fprintf(f, "| %s | %g | %g | %.4g | %.3g | %.3f | %.2f | %s |\n", pname[p], truth[p],
                    start[best[cs]][p], b->value[p], b->se[p], b->value[p] / truth[p],
                    fabs(b->value[p] - truth[p]) / b->se[p], verdict(b->value[p], b->se[p], truth[p]));
        fprintf(f, "\nCorrelations of the estimates:\n\n|  |");
        for (int q = 0; q < NPAR; ++q)
            fprintf(f, " %s |", pname[q]);
        fprintf(f, "\n|---|");
        for (int q = 0; q < NPAR; ++q)
            fprintf(f, "---:|");
        fprintf(f, "\n");
        for (int p = 0; p < NPAR; ++p) {
            fprintf(f, "| %s |", pname[p]);
            for (int q = 0; q < NPAR; ++q)
                fprintf(f, " %.3f |", b->corr[p][q]);
            fprintf(f, "\n");
        }
        fprintf(f, "\nUndetermined combinations reported by the fit: ");
        if (!b->n_undet)
            fprintf(f, "none.\n\n");
        for (size_t k = 0; k < b->n_undet; ++k)
            fprintf(f, "%s`%s`%s", k ? ", " : "", b->undet[k], k + 1 == b->n_undet ? ".\n\n" : "");
    }
    /* the verdict, from the numbers */
    fprintf(f, "### Verdict\n\n");
    int strong[NPAR][NPAR] = {{0}};
    for (int p = 0; p < NPAR; ++p)
        for (int q = p + 1; q < NPAR; ++q)
            strong[p][q] = fabs(o[0][best[0]].corr[p][q]) >= 0.9 || fabs(o[1][best[1]].corr[p][q]) >= 0.9;
    for (int p = 0; p < NPAR; ++p) {
        fprintf(f, "- **%s**: perturbed %s (fitted/true %.3f), control %s (%.3f)", pname[p],
                verdict(o[0][best[0]].value[p], o[0][best[0]].se[p], truth[p]), o[0][best[0]].value[p] / truth[p],
                verdict(o[1][best[1]].value[p], o[1][best[1]].se[p], truth[p]), o[1][best[1]].value[p] / truth[p]);
        int any = 0;
        for (int q = 0; q < NPAR; ++q) {
            const int a = p < q ? strong[p][q] : q < p ? strong[q][p] : 0;
            if (a)
                fprintf(f, "%s%s", any++ ? ", " : "; strongly correlated (|r| ≥ 0.9) with ", pname[q]);
        }
        fprintf(f, ".\n");
    }
    fprintf(f,
            "\nThe weighted RSS at the true values (the \"(truth)\" rows) against the fitted one tells a failed\n"
            "search from a shifted optimum: when the fit's RSS is lower than the truth's, the data themselves\n"
            "prefer the fitted values (model mismatch from resampling, segmentation, registration and the\n"
            "colour correction moves the optimum along the flat directions), and the standard errors, which\n"
            "only describe the noise, understate the real error along those directions.\n"
            "\nA parameter is *recovered* when its estimate lies within 3 standard errors of the truth and\n"
            "its SE is below half its value. What the colours see is the fluid through g(y): only where y\n"
            "crosses the band [y_lo, y_hi] does a pixel change colour, so the scales act through when and\n"
            "where each pixel crosses it. Transpiration and inflow act on the same pixels in opposite\n"
            "directions (on a vein the net rate is s_I·I − s_O·O), and moving y_lo and y_hi together trades\n"
            "against the overall drying rate; those are the combinations to watch in the correlations.\n"
            "The perturbed case adds what real photos bring: residual misregistration at the leaf's edge,\n"
            "the gray-world gains that differ slightly between frames as the leaf's share of the colour\n"
            "changes (the paper dominates, but not completely), and noise averaged over each cell.\n\n"
            "Runtime of the notebook: %.1f s.\n",
            total);
    if (nb_close_md(f, md, mdtmp) != 0) {
        phc_error_set(&err, PHC_ERR_IO, "%s: cannot write the page", md);
        goto fail;
    }
    (void)nb_plot;
    printf("ok: %s\n", md);
    status = 0;
    goto done;
fail_frames:
    for (int d = 0; d < NDAY; ++d)
        phc_image_free(&frames[d]);
fail:
    fprintf(stderr, "silva_identifiability: %s\n", err.message[0] ? err.message : "failed");
    status = 1;
done:
    for (size_t k = 0; k < n_names; ++k)
        unlink(names[k]);
    rmdir(dir);
    phc_image_free(&sheet);
    phc_image_free(&frame_img);
    phc_leaf_setup_free(su0);
    phc_leaf_setup_free(su);
    phc_leaf_photo_free(&fresh0);
    phc_leaf_photo_free(&fresh);
    phc_leaf_photo_free(&ref);
    phc_photo_cache_free(cache);
    return status;
}
