/* Wilting paper (Maggioli et al., SIGGRAPH Asia 2023), Fig. 7's question as
 * a global sensitivity study: over plausible ranges of the loss rate delta,
 * the steepness kappa and the midpoint chi0 of eq. 9's stiffness logistic,
 * which of them decide how much water the plant holds, and which decide its
 * shape?
 *
 * The paper's claim (§5, Fig. 7): delta sets how fast the plant loses water
 * and so how far it wilts; kappa (with chi0) shapes how stiffness follows
 * the water, so it changes the shape but not the water: the total water
 * W(t) does not depend on kappa, the wilted shape depends on both.
 *
 * Ours (wilting_shape.h for the common setting): plant000, physical water
 * model (BDF6, 60 s steps), after T = 6 h: the total water W (g) and the
 * height of the plant's highest tip (the tail of the segment highest at
 * rest, m) after the static equilibrium of the rods with moduli from eq. 9
 * on relative water content and the water's mass.  Factors, as priors of a
 * phytocal problem: delta log-uniform between the rates that leave 90% and
 * 60% of the water after 6 h, kappa log-uniform on [5, 80], chi0 uniform on
 * [0.7, 0.9].  The model is a data set of two "observations" (W and the
 * height) built in C, and the study is `phytocal sensitivity`'s own
 * (phc_study_run, Sobol indices from a Saltelli design of N = 48 base
 * samples from GSL's Sobol sequence, 95% bootstrap intervals) with the two
 * named outputs `W_6h` and `tip_height_6h`.  The water model runs once per
 * distinct delta (two per base sample: A's and B's).
 *
 * Prints S1 and ST with intervals for both outputs.  Checks (exit 1 when
 * one fails): for W, the interval of ST_delta holds 1 and ST of kappa and
 * chi0 is below 0.01 (exactly 0: W is computed without them); for the tip height, ST of
 * delta and of kappa both at least 0.05 (both shape the plant).  Writes the
 * study's run directory (result.json, report.md, bar plots) under
 * OUTPUT_DIR/wilting_fig7_sobol/ and wilting_fig7_sobol.md.
 *
 * Usage: notebook_wilting_fig7_sobol OUTPUT_DIR */
#include "wilting_shape.h"

#include <jansson.h>

#include "fit/engine/problem.h"
#include "fit/sensitivity_study.h"
#include "notebook_plot.h"

#define T_DRY (6.0 * 3600.0)
#define N_BASE 48

typedef struct wilt_impl {
    phc_plant_graph *g;
    phc_rod *rod;
    double *E, *theta, *cache_theta[2]; /* n each; the water after T_DRY for two deltas */
    double cache_delta[2];
    int cache_next;
    size_t top;                         /* the segment highest at rest */
    size_t water_runs, rod_runs;
    double secs;
} wilt_impl;

/* The water after T_DRY at loss rate delta (cached for the last two). */
static const double *water_at(wilt_impl *w, double delta)
{
    for (int c = 0; c < 2; ++c)
        if (w->cache_theta[c] && w->cache_delta[c] == delta)
            return w->cache_theta[c] + w->g->n; /* row 1: at T_DRY */
    const size_t n = w->g->n;
    const int c = w->cache_next;
    w->cache_next ^= 1;
    if (!w->cache_theta[c] && !(w->cache_theta[c] = malloc(2 * n * sizeof(double))))
        return NULL;
    phc_water_params wp = ws_water_params(w->g, delta);
    const double times[2] = {0.0, T_DRY};
    phc_error err;
    w->cache_delta[c] = NAN;
    if (ws_water(w->g, &wp, times, 2, w->cache_theta[c], &err) != PHC_OK) {
        fprintf(stderr, "water at delta %g: %s\n", delta, err.message);
        return NULL;
    }
    w->water_runs++;
    w->cache_delta[c] = delta;
    return w->cache_theta[c] + n;
}

/* yhat[0] = W (g), yhat[1] = the highest tip's height (m) at p = (delta, kappa, chi0). */
static int wilt_predict(phc_dataset *ds, const double *p, double *yhat, double *jac)
{
    (void)jac;
    wilt_impl *w = ds->impl;
    const size_t n = w->g->n;
    const double *theta = water_at(w, p[0]);
    if (!theta)
        return 1;
    double W = 0;
    for (size_t i = 0; i < n; ++i)
        W += theta[i];
    phc_error err;
    phc_segment_stiffness_params sp = ws_stiffness(p[1], p[2]);
    if (phc_segment_stiffness_water(w->g, &sp, theta, w->E, NULL, NULL, &err) != PHC_OK)
        return 1;
    phc_rod_reset(w->rod);
    if (ws_solve(w->rod, w->E, theta, &w->secs, NULL, &err) != PHC_OK)
        return 1;
    w->rod_runs++;
    double tail[3];
    phc_rod_tail(w->rod, w->top, tail);
    yhat[0] = W;
    yhat[1] = tail[2];
    return 0;
}

static void wilt_free(void *impl)
{
    wilt_impl *w = impl;
    if (!w)
        return;
    phc_rod_free(w->rod);
    phc_plant_graph_free(w->g);
    free(w->E);
    free(w->theta);
    free(w->cache_theta[0]);
    free(w->cache_theta[1]);
    free(w);
}

static const phc_dataset_ops wilt_ops = {.kind = "wilting_fig7", .predict = wilt_predict, .free_impl = wilt_free};

static double jget(json_t *root, const char *output, const char *factor, const char *key, int which)
{
    json_t *outs = json_object_get(root, "outputs");
    for (size_t j = 0; j < json_array_size(outs); ++j) {
        json_t *o = json_array_get(outs, j);
        if (strcmp(json_string_value(json_object_get(o, "name")), output) != 0)
            continue;
        json_t *v = json_object_get(json_object_get(json_object_get(o, "indices"), factor), key);
        if (which >= 0)
            v = json_array_get(v, (size_t)which);
        return json_is_number(v) ? json_number_value(v) : NAN;
    }
    return NAN;
}

int main(int argc, char **argv)
{
    const char *out = NULL;
    int started = nb_begin(argc, argv, WS_PLANT, &out);
    if (started)
        return started;
    phc_error err;
    phc_error_clear(&err);
    wilt_impl *w = calloc(1, sizeof *w);
    if (!w || !(w->g = ws_read(WS_PLANT)))
        return 1;
    const size_t n = w->g->n;
    w->E = malloc(n * sizeof *w->E);
    w->top = ws_highest(w->g);
    for (size_t i = 0; i < n; ++i)
        w->E[i] = WS_E_MAX;
    if (!w->E || !(w->rod = ws_rod(w->g, w->E, &err))) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    const double d_hi = ws_delta_for(w->g, 0.6, T_DRY), d_lo = ws_delta_for(w->g, 0.9, T_DRY);
    const double rest_top = w->g->tail[3 * w->top + 2];

    /* the problem: three parameters with priors, one data set of two outputs */
    phc_problem *pb = phc_problem_new("wilting-fig7-sobol");
    static const char *names[3] = {"delta", "kappa", "chi0"};
    const double start[3] = {sqrt(d_lo * d_hi), 20, 0.8};
    const phc_prior priors[3] = {{PHC_PRIOR_LOG_UNIFORM, d_lo, d_hi, 0, INFINITY},
                                 {PHC_PRIOR_LOG_UNIFORM, 5, 80, 0, INFINITY},
                                 {PHC_PRIOR_UNIFORM, 0.7, 0.9, 0, 1}};
    phc_dataset *ds = phc_dataset_new(&wilt_ops, 3);
    if (!pb || !ds)
        return 1;
    ds->impl = w;
    ds->name = strdup("plant000");
    ds->n = 2;
    ds->x = malloc(2 * sizeof *ds->x);
    ds->y = malloc(2 * sizeof *ds->y);
    ds->x_label = strdup("output (1: W, 2: tip height)");
    ds->y_label = strdup("W (g) or height (m)");
    ds->x[0] = 1, ds->x[1] = 2, ds->y[0] = ds->y[1] = 0;
    for (int i = 0; i < 3; ++i) {
        size_t idx;
        if (phc_problem_add_parameter(pb, names[i], start[i], &idx, &err) != PHC_OK) {
            fprintf(stderr, "%s\n", err.message);
            return 1;
        }
        pb->params[idx].lower = priors[i].lower;
        pb->params[idx].upper = priors[i].upper;
        pb->params[idx].prior = priors[i];
        ds->slot_names[i] = strdup(names[i]);
        ds->param_index[i] = idx;
    }
    pb->series_points = 0; /* the two predictions are named outputs instead */
    if (phc_problem_add_dataset(pb, ds, &err) != PHC_OK ||
        phc_problem_add_output(pb, "W_6h", "plant000", NAN, 1, 0, &err) != PHC_OK ||
        phc_problem_add_output(pb, "tip_height_6h", "plant000", NAN, 2, 0, &err) != PHC_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }

    char run[1024];
    snprintf(run, sizeof run, "%s/wilting_fig7_sobol", out);
    phc_study_options so = phc_study_options_default();
    so.samples = N_BASE;
    so.force = 1;
    phc_study_summary sum;
    const double t0 = ws_now();
    if (phc_study_run(pb, &so, NULL, run, &sum, &err) != PHC_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    const double secs = ws_now() - t0;
    char path[1100];
    snprintf(path, sizeof path, "%s/result.json", run);
    json_error_t jerr;
    json_t *root = json_load_file(path, 0, &jerr);
    if (!root) {
        fprintf(stderr, "%s: %s\n", path, jerr.text);
        return 1;
    }
    printf("plant000: %zu segments, highest tip at rest %.4f m; after T = %.0f h; N = %d base samples, %zu evaluations "
           "(%zu failed): %zu water runs, %zu static solves (%.2f s), %.1f s in all\n",
           n, rest_top, T_DRY / 3600, N_BASE, sum.evaluations, sum.failed, w->water_runs, w->rod_runs, w->secs, secs);
    printf("priors: delta log-uniform [%.4e, %.4e] 1/(cm^2 s) (90%% .. 60%% of the water left), kappa log-uniform [5, "
           "80], chi0 uniform [0.7, 0.9]\n", d_lo, d_hi);
    static const char *outputs[2] = {"W_6h", "tip_height_6h"};
    double st[2][3], st_hi[2][3], st_lo[2][3];
    for (int o = 0; o < 2; ++o) {
        printf("%s:\n", outputs[o]);
        for (int f = 0; f < 3; ++f) {
            st[o][f] = jget(root, outputs[o], names[f], "ST", -1);
            st_hi[o][f] = jget(root, outputs[o], names[f], "ST_ci95", 1);
            st_lo[o][f] = jget(root, outputs[o], names[f], "ST_ci95", 0);
            printf("  %-6s S1 = %7.4f [%7.4f, %7.4f]   ST = %7.4f [%7.4f, %7.4f]\n", names[f],
                   jget(root, outputs[o], names[f], "S1", -1), jget(root, outputs[o], names[f], "S1_ci95", 0),
                   jget(root, outputs[o], names[f], "S1_ci95", 1), st[o][f],
                   jget(root, outputs[o], names[f], "ST_ci95", 0), st_hi[o][f]);
        }
    }
    const int ok_w = st_lo[0][0] <= 1 && 1 <= st_hi[0][0] && st[0][1] < 0.01 && st[0][2] < 0.01;
    const int ok_h = st[1][0] >= 0.05 && st[1][1] >= 0.05;
    printf("W does not depend on kappa or chi0 (ST < 0.01) and delta decides it (ST's interval holds 1): %s\n",
           ok_w ? "yes" : "no");
    printf("the tip height depends on delta and on kappa (ST >= 0.05 each): %s\n", ok_h ? "yes" : "no");

    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "wilting_fig7_sobol.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f, "# Wilting paper, Fig. 7's question as a Sobol study\n\n"
               "plant000 after 6 h; delta log-uniform [%.4e, %.4e], kappa log-uniform [5, 80], chi0 uniform "
               "[0.7, 0.9]; N = %d (settings in the program's header). The study's own report: "
               "[wilting_fig7_sobol/report.md](wilting_fig7_sobol/report.md).\n\n"
               "| output | factor | ST | 95%% upper end |\n|---|---|---:|---:|\n", d_lo, d_hi, N_BASE);
    for (int o = 0; o < 2; ++o)
        for (int k = 0; k < 3; ++k)
            fprintf(f, "| %s | %s | %.4f | %.4f |\n", outputs[o], names[k], st[o][k], st_hi[o][k]);
    fprintf(f, "\nChecks: W decided by delta alone %s; the tip height by delta and kappa %s.\n",
            ok_w ? "(pass)" : "(**FAIL**)", ok_h ? "(pass)" : "(**FAIL**)");
    if (nb_close_md(f, md, mdtmp) != 0) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    json_decref(root);
    phc_study_summary_clear(&sum);
    phc_problem_free(pb); /* frees the data set and w */
    const int fail = !(ok_w && ok_h);
    printf("%s: %s\n", fail ? "FAIL" : "ok", out);
    return fail;
}
