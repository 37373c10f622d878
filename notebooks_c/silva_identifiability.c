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

#include "silva_series.h"

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
