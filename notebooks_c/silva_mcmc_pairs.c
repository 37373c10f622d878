/* The leaf colour model's non-identifiable combination (Silva et al. §3;
 * silva_identifiability, README "Photos of one leaf over time") as a
 * posterior: the identifiability notebook found that a few photos of one
 * leaf determine beta_scale but move stomata_scale and inflow_scale
 * together (fit correlation r = 0.96); an MCMC pair plot shows that ridge.
 *
 * The series is the identifiability notebook's "perturbed" case
 * (silva_series.h: ivy leaf 9 aged by the model at the true parameters,
 * frames on paper at days 2 .. 10, misaligned by 1 degree and 1.5 px,
 * lighting gains, pixel noise sd 0.02, fitted with registration and
 * gray-world correction, CIELAB residuals on a 24-cell grid with sigma 2).
 * `phytocal mcmc`'s driver (fit/mcmc_study.h: phc_mcmc_run) fits from the
 * truth (at most FIT_ITERATIONS iterations) and runs DRAM (CHAINS chains of
 * DRAWS draws, the first half burn-in; sigma known: the data set's) over
 * the five parameters in their boxes (uniform priors).
 *
 * Prints the posterior median and 95% interval of every parameter, the
 * correlation of stomata_scale and inflow_scale over the kept draws (from
 * result.json's thinned chains, pooled), in the parameters and in their
 * logarithms, and whether the chains mixed.  Check (exit 1 when it
 * fails): |corr(stomata_scale, inflow_scale)| >= 0.9, the ridge.  Writes
 * the run directory OUTPUT_DIR/silva_mcmc_pairs/ (mcmc_pairs.png,
 * mcmc_trace.png, result.json, report.md) and silva_mcmc_pairs.md.
 *
 * Usage: notebook_silva_mcmc_pairs OUTPUT_DIR */
#include "silva_series.h"

#include <jansson.h>

#include "fit/mcmc_study.h"
#include "notebook_plot.h"

#define FIT_ITERATIONS 10
#define CHAINS 2
#define DRAWS 300

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Pearson correlation of the pooled thinned draws of a and b (logs when
 * take_log). */
static double pooled_corr(json_t *draws, const char *a, const char *b, int take_log, size_t *count)
{
    json_t *ca = json_object_get(draws, a), *cb = json_object_get(draws, b);
    double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
    size_t n = 0;
    for (size_t c = 0; c < json_array_size(ca); ++c)
        for (size_t k = 0; k < json_array_size(json_array_get(ca, c)); ++k) {
            double x = json_number_value(json_array_get(json_array_get(ca, c), k));
            double y = json_number_value(json_array_get(json_array_get(cb, c), k));
            if (take_log) {
                x = log(x);
                y = log(y);
            }
            if (!isfinite(x) || !isfinite(y))
                continue;
            sa += x, sb += y, saa += x * x, sbb += y * y, sab += x * y, ++n;
        }
    *count = n;
    if (n < 3)
        return NAN;
    const double cov = sab / n - (sa / n) * (sb / n), va = saa / n - (sa / n) * (sa / n),
                 vb = sbb / n - (sb / n) * (sb / n);
    return cov / sqrt(va * vb);
}

int main(int argc, char **argv)
{
    const char *out;
    int rc = nb_begin(argc, argv, SCAN, &out);
    if (rc)
        return rc == 77 ? 77 : rc;
    const double t_start = now();
    phc_error err = {0};
    phc_photo_cache *cache = phc_photo_cache_new();
    phc_leaf_photo fresh0 = {0}, ref = {0}, fresh = {0};
    phc_leaf_setup *su0 = NULL, *su = NULL;
    phc_image sheet = {0}, frame_img = {0}, frames[NDAY];
    memset(frames, 0, sizeof frames);
    char dir[] = "/tmp/phc_silva_mcmc_XXXXXX", path[2048], names[NDAY + 1][2048];
    size_t n_names = 0;
    int status = 1;
    if (!cache || !mkdtemp(dir)) {
        fprintf(stderr, "silva_mcmc_pairs: cannot create a temporary directory\n");
        phc_photo_cache_free(cache);
        return 1;
    }
    /* the fresh leaf as its own photo, and the generating set-up on it (as silva_identifiability) */
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
        snprintf(names[n_names++], sizeof names[0], "%s", path);
    }
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
    phc_leaf_reset(su->leaf, 1.0);
    rng_state = SEED; /* the perturbed case's noise, as in silva_identifiability */
    for (int d = 0; d < NDAY; ++d) {
        if (phc_leaf_advance(su->leaf, days[d] - phc_leaf_time(su->leaf)) ||
            phc_leaf_setup_colours(su, tf, NULL, &frames[d], &err) ||
            compose(&frames[d], su->mask, 1, &frame_img, &err))
            goto fail;
        frame_path(path, sizeof path, dir, 0, d);
        rc = phc_photo_write_png(path, &frame_img, &err);
        phc_image_free(&frame_img);
        if (rc)
            goto fail;
        snprintf(names[n_names++], sizeof names[0], "%s", path);
    }
    const double t_frames = now() - t_start;

    /* the posterior: fit from the truth, then DRAM */
    phc_problem *pb = build_problem(dir, 0, NSTART, &err);
    if (!pb)
        goto fail;
    pb->options.nls.max_iterations = FIT_ITERATIONS;
    char run[1100];
    snprintf(run, sizeof run, "%s/silva_mcmc_pairs", out);
    phc_mcmc_options mo = phc_mcmc_options_default();
    mo.samples = DRAWS;
    mo.chains = CHAINS;
    mo.force = 1;
    phc_mcmc_run_summary ms;
    const double t0 = now();
    rc = phc_mcmc_run(pb, &mo, NULL, run, &ms, &err);
    const double t_mcmc = now() - t0;
    phc_problem_free(pb);
    if (rc)
        goto fail;
    const int mixed = ms.mixed;
    phc_mcmc_run_summary_clear(&ms);
    snprintf(path, sizeof path, "%s/result.json", run);
    json_error_t jerr;
    json_t *root = json_load_file(path, 0, &jerr);
    if (!root) {
        fprintf(stderr, "%s: %s\n", path, jerr.text);
        goto fail;
    }
    json_t *params = json_object_get(root, "parameters");
    printf("perturbed series of ivy leaf %d (%d days, model grid %d); frames %.1f s; fit (<= %d iterations) and DRAM "
           "%d chains x %d draws: %.1f s\n",
           FRESH_LEAF, NDAY, MODEL_SIZE, t_frames, FIT_ITERATIONS, CHAINS, DRAWS, t_mcmc);
    printf("%-14s %9s %10s %10s  %-24s %7s %7s\n", "parameter", "truth", "fit", "median", "95% interval", "ESS",
           "R-hat");
    for (int k = 0; k < NPAR; ++k) {
        json_t *o = json_object_get(params, pname[k]);
        printf("%-14s %9.4g %10.4g %10.4g  [%9.4g, %9.4g] %7.0f %7.3f\n", pname[k], truth[k],
               json_number_value(json_object_get(o, "fit")), json_number_value(json_object_get(o, "median")),
               json_number_value(json_array_get(json_object_get(o, "ci95"), 0)),
               json_number_value(json_array_get(json_object_get(o, "ci95"), 1)),
               json_number_value(json_object_get(o, "ess")), json_number_value(json_object_get(o, "rhat")));
    }
    json_t *draws = json_object_get(json_object_get(root, "chains_thinned"), "draws");
    size_t n_draws = 0;
    const double r = pooled_corr(draws, "stomata_scale", "inflow_scale", 0, &n_draws);
    const double r_log = pooled_corr(draws, "stomata_scale", "inflow_scale", 1, &n_draws);
    const double r_beta = pooled_corr(draws, "beta_scale", "stomata_scale", 0, &n_draws);
    json_decref(root);
    printf("posterior correlation over %zu kept draws: stomata_scale vs inflow_scale %.4f (of their logarithms "
           "%.4f); beta_scale vs stomata_scale %.4f\n",
           n_draws, r, r_log, r_beta);
    printf("chains mixed (R-hat < 1.01, ESS > 400): %s\n", mixed ? "yes" : "no");
    const int ok = fabs(r) >= 0.9;
    printf("stomata_scale and inflow_scale lie on a ridge (|r| >= 0.9): %s\n", ok ? "yes" : "no");

    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "silva_mcmc_pairs.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        goto fail;
    }
    fprintf(f, "# Leaf colour model: the stomata–inflow ridge as a posterior\n\n"
               "The identifiability notebook's perturbed series; DRAM, %d chains x %d draws after a fit from the "
               "truth. Pair plot: ![pairs](silva_mcmc_pairs/mcmc_pairs.png)\n\n"
               "Posterior correlation of stomata_scale and inflow_scale: %.4f (logarithms %.4f) over %zu kept "
               "draws; beta_scale vs stomata_scale %.4f. Chains mixed: %s.\n\nCheck: |r| >= 0.9 %s.\n",
            CHAINS, DRAWS, r, r_log, n_draws, r_beta, mixed ? "yes" : "no", ok ? "(pass)" : "(**FAIL**)");
    if (nb_close_md(f, md, mdtmp) != 0) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        goto fail;
    }
    status = ok ? 0 : 1;
    printf("%s: %s (%.1f s)\n", ok ? "ok" : "FAIL", out, now() - t_start);
    goto done;
fail:
    fprintf(stderr, "silva_mcmc_pairs: %s\n", err.message);
    status = 1;
done:
    for (int d = 0; d < NDAY; ++d)
        phc_image_free(&frames[d]);
    phc_image_free(&sheet);
    for (size_t k = 0; k < n_names; ++k)
        unlink(names[k]);
    rmdir(dir);
    phc_leaf_setup_free(su0);
    phc_leaf_setup_free(su);
    phc_leaf_photo_free(&fresh0);
    phc_leaf_photo_free(&fresh);
    phc_leaf_photo_free(&ref);
    phc_photo_cache_free(cache);
    return status;
}
