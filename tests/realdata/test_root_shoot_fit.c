/* The Rhizomorph shoot-root model (model/growth.h) in a pot soil
 * (model/soil.h) calibrated on real red oak seedlings: the example config
 * measurements/examples/root_shoot/quercus_rubra.yaml, which fits phi_rg,
 * the soil's permeability p and capacity c and water_use to ln(root:shoot)
 * of the high-light Quercus rubra seedlings of Baltzer & Thomas (2007) in
 * BAAD (../shared/data/baad/Baltzer2007).
 *
 * (a) The fit: it converges; 29 plants are fitted (30 high-light seedlings
 *     with a diameter, less data.csv:219, a 22.78 mm stem on a 4-month
 *     seedling, excluded as suspicious); the fitted values lie within their
 *     bounds; the fitted cost is below 0.8 times the start's (the RMSE of
 *     the constant model, the data's mean ln root:shoot, is printed beside
 *     the model's: the model does worse, see the README).  Prints
 *     the values, standard errors and the correlation matrix.
 * (b) The fitted plant's root system: grown again here at the fitted values
 *     (the config's pot built with model/soil.h), written with
 *     phc_growth_write_rsml and read back with phc_rsml_read: one RSML root
 *     per grown root branch, total length equal to the model's root_length
 *     to 1e-9 (relative); and the data set's own fit outputs
 *     (fit_outputs) give the same root system.
 *
 * Skips (77) when ../shared/data is absent. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "check.h"
#include "fit/config.h"
#include "fit/engine/fit.h"
#include "fit/growth_outputs.h"
#include "measurements/rsml.h"
#include "model/growth.h"
#include "model/soil.h"

#define NAME "test_root_shoot_fit"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Writes a copy of the example config with the baad path made absolute.
 * Returns 0 or -1. */
static int copy_config(const char *src, const char *dst, const char *baad_abs)
{
    FILE *in = fopen(src, "r"), *out = fopen(dst, "w");
    if (!in || !out) {
        if (in) fclose(in);
        if (out) fclose(out);
        return -1;
    }
    char line[1024];
    int replaced = 0;
    while (fgets(line, sizeof line, in)) {
        const char *key = strstr(line, "baad:");
        if (key && !replaced) {
            fprintf(out, "%.*sbaad: %s\n", (int)(key - line), line, baad_abs);
            replaced = 1;
        } else
            fputs(line, out);
    }
    fclose(in);
    int bad = ferror(out);
    bad |= fclose(out) != 0;
    return bad || !replaced ? -1 : 0;
}

static double param_value(const phc_fit_result *res, const char *name)
{
    for (size_t i = 0; i < res->n_params; ++i)
        if (!strcmp(res->params[i].name, name))
            return res->params[i].value;
    return NAN;
}

/* Grows the config's plant (preset oak, the pot soil of the example) at the
 * fitted values until its basal diameter reaches d_stop (m) or 300 d, as the
 * data set does.  Returns the plant (and its soil in *soil) or NULL. */
static phc_growth *grow_fitted(const phc_fit_result *res, double d_stop, phc_soil **soil, phc_error *err)
{
    *soil = NULL;
    phc_growth_params gp;
    if (phc_growth_preset("oak", &gp, err))
        return NULL;
    gp.phi_rg = param_value(res, "phi_rg");
    gp.water_use = param_value(res, "water_use");
    phc_soil *s = phc_soil_new(10, 10, 10, 0.03);
    if (!s)
        return NULL;
    s->params.dt = 1.0;
    s->params.max_substeps = 100;
    phc_soil_layer layer = {0.0, param_value(res, "c"), param_value(res, "p"), 1.0, 3.0, -1.0, 0.0};
    phc_soil_rain rain = {0.0, 1.0e6, 1.0e-4, 0.0, 0.0, 0.0, 0.0, 0.0};
    if (phc_soil_set_layers(s, &layer, 1, err) || phc_soil_set_rain(s, &rain, 1, err) || phc_soil_check(s, err)) {
        phc_soil_free(s);
        return NULL;
    }
    phc_soil_budget_reset(s);
    phc_growth_options o = phc_growth_options_default();
    o.base[0] = o.base[1] = 0.15;
    o.base[2] = 0.30;
    phc_growth *g = NULL;
    if (phc_growth_new(&gp, &o, s, &g, err)) {
        phc_soil_free(s);
        return NULL;
    }
    phc_growth_summary sm;
    for (int day = 0; day < 300; ++day) {
        if (phc_growth_step(g, 1.0, err)) {
            phc_growth_free(g);
            phc_soil_free(s);
            return NULL;
        }
        phc_growth_summarize(g, &sm);
        if (sm.basal_diameter >= d_stop)
            break;
    }
    *soil = s;
    return g;
}

/* Root branches that have grown (at least one segment of positive length). */
static size_t grown_root_branches(const phc_growth *g)
{
    size_t n = 0, *first = NULL, *parent = NULL;
    const phc_growth_node *node = phc_growth_nodes(g, &n);
    size_t nb = phc_growth_branches(g, PHC_GROWTH_ROOT, &first, &parent);
    size_t grown = 0;
    for (size_t b = 0; b < nb; ++b)
        for (size_t i = first[b]; i != PHC_GROWTH_NONE; i = node[i].apical_child)
            if (node[i].length > 0) {
                ++grown;
                break;
            }
    free(first);
    free(parent);
    return grown;
}

static void remove_dir(const char *dir)
{
    char cmd[1200];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
}

int main(void)
{
    const char *study = PHC_SHARED_DATA "/baad/Baltzer2007";
    char data_csv[512];
    snprintf(data_csv, sizeof data_csv, "%s/data.csv", study);
    if (access(data_csv, R_OK) != 0) {
        printf("skipped: %s is absent (the real-data folder ../shared/data is not here)\n", data_csv);
        return 77;
    }
    char tmp[] = "/tmp/phc_root_shoot_XXXXXX";
    if (!mkdtemp(tmp)) {
        perror("mkdtemp");
        return 1;
    }
    /* The example config reaches the data as ../../../../shared/data/...
     * relative to itself; a copy with an absolute path works wherever the
     * real-data folder is. */
    char cfg[600];
    snprintf(cfg, sizeof cfg, "%s/quercus_rubra.yaml", tmp);
    char abs_study[4096];
    char cwd[2048] = "";
    if (study[0] != '/' && !getcwd(cwd, sizeof cwd))
        cwd[0] = '\0';
    snprintf(abs_study, sizeof abs_study, "%s%s%s", study[0] != '/' ? cwd : "", study[0] != '/' ? "/" : "", study);
    if (copy_config(PHC_SOURCE_DIR "/measurements/examples/root_shoot/quercus_rubra.yaml", cfg, abs_study)) {
        fprintf(stderr, "cannot copy the example config into %s\n", tmp);
        remove_dir(tmp);
        return 1;
    }

    double t0 = now();
    phc_error err;
    phc_error_clear(&err);
    phc_problem *pb = NULL;
    phc_fit_result *res = NULL;
    CHECK(phc_config_load(cfg, &pb, &err) == PHC_OK);
    if (!pb) {
        fprintf(stderr, "%s\n", err.message);
        remove_dir(tmp);
        return check_finish(NAME);
    }
    CHECK(pb->n_datasets == 1);
    phc_dataset *ds = pb->datasets[0];

    /* (a) the data set: 29 plants, data.csv:219 (22.78 mm) not among them */
    printf("rs_plants_fitted: %zu\n", ds->n);
    CHECK(ds->n == 29);
    CHECK(ds->data_lines != NULL);
    int has_219 = 0;
    double mean = 0, d_max = 0;
    for (size_t i = 0; i < ds->n; ++i) {
        if (ds->data_lines && ds->data_lines[i] == 219)
            has_219 = 1;
        mean += ds->y[i] / (double)ds->n;
        d_max = fmax(d_max, ds->x[i] * 1e-3);
    }
    CHECK(!has_219);
    printf("rs_line_219_excluded: %s\n", has_219 ? "no" : "yes");
    double rmse_const = 0;
    for (size_t i = 0; i < ds->n; ++i)
        rmse_const += pow(ds->y[i] - mean, 2) / (double)ds->n;
    rmse_const = sqrt(rmse_const);
    printf("rs_mean_ln_root_shoot: %.4f (root:shoot %.3f)\nrs_largest_diameter: %.3f mm\n", mean, exp(mean),
           d_max * 1e3);

    /* the fit */
    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    if (!res) {
        fprintf(stderr, "%s\n", err.message);
        goto done;
    }
    double t_fit = now() - t0;
    printf("rs_fit_outcome: %s (%zu starts, %.1f s)\n", phc_fit_status_name(res->summary.outcome), res->starts,
           t_fit);
    CHECK(res->summary.outcome == PHC_NLS_CONVERGED);
    for (size_t i = 0; i < res->n_params; ++i) {
        const phc_param_result *q = &res->params[i];
        const phc_parameter *bp = &pb->params[i];
        printf("rs_%s: %.6g +- %.3g (start %.6g, bounds [%g, %g]%s)\n", q->name, q->value, q->stderr_, q->start,
               bp->lower, bp->upper, q->at_bound ? ", at a bound" : "");
        CHECK(q->value >= bp->lower && q->value <= bp->upper);
    }
    printf("rs_correlation:\n%12s", "");
    for (size_t b = 0; b < res->n_free; ++b)
        printf(" %11s", res->params[res->free_index[b]].name);
    printf("\n");
    for (size_t a = 0; a < res->n_free; ++a) {
        printf("%12s", res->params[res->free_index[a]].name);
        for (size_t b = 0; b < res->n_free; ++b)
            printf(" %11.3f", res->correlation[a * res->n_free + b]);
        printf("\n");
    }
    const phc_dataset_result *dr = &res->datasets[0];
    double rmse = 0;
    for (size_t i = 0; i < dr->n; ++i)
        rmse += dr->residual[i] * dr->residual[i] / (double)dr->n;
    rmse = sqrt(rmse);
    printf("rs_rows: data.csv line, D mm, ln root:shoot data, model\n");
    for (size_t i = 0; i < dr->n; ++i)
        printf("  %4zu %6.2f %7.3f %7.3f\n", ds->data_lines[i], dr->x[i], dr->y[i], dr->yhat[i]);
    printf("rs_rmse_model: %.4f (ln root:shoot)\nrs_rmse_constant: %.4f (ln root:shoot)\n", rmse,
           rmse_const);
    /* The fitted oak does worse than a constant here (README: a seedling's
     * first growth goes to leaves, a red oak's to its taproot); what must
     * hold is that the fit improves clearly on its start. */
    printf("rs_cost: initial %.4f, final %.4f\n", res->summary.initial_cost, res->cost);
    CHECK(isfinite(rmse) && res->cost < 0.8 * res->summary.initial_cost);
    /* diagnostic (not checked): the largest residual and the RMSEs without that plant */
    {
        size_t worst = 0;
        for (size_t i = 1; i < dr->n; ++i)
            if (fabs(dr->residual[i]) > fabs(dr->residual[worst]))
                worst = i;
        double m1 = 0, r1 = 0, c1 = 0;
        for (size_t i = 0; i < dr->n; ++i)
            if (i != worst)
                m1 += dr->y[i] / (double)(dr->n - 1);
        for (size_t i = 0; i < dr->n; ++i)
            if (i != worst) {
                r1 += dr->residual[i] * dr->residual[i] / (double)(dr->n - 1);
                c1 += pow(dr->y[i] - m1, 2) / (double)(dr->n - 1);
            }
        printf("rs_worst_row: data.csv:%zu, D %.2f mm, ln root:shoot %.3f, model %.3f (residual %.3f)\n"
               "rs_rmse_without_it: model %.4f, constant %.4f\n",
               ds->data_lines[worst], dr->x[worst], dr->y[worst], dr->yhat[worst], dr->residual[worst], sqrt(r1),
               sqrt(c1));
    }
    for (size_t i = 0; i < res->n_warnings; ++i)
        printf("rs_warning: %s\n", res->warnings[i]);

    /* (b) the fitted plant's root system through RSML */
    {
        phc_soil *soil = NULL;
        phc_growth *g = grow_fitted(res, d_max, &soil, &err);
        CHECK(g != NULL);
        if (!g) {
            fprintf(stderr, "%s\n", err.message);
            goto done;
        }
        phc_growth_summary sm;
        phc_growth_summarize(g, &sm);
        size_t grown = grown_root_branches(g);
        printf("rs_plant: age %.0f d, D %.3f mm, root:shoot %.3f, %zu root segments, %zu grown root branches, "
               "root length %.6g m\n",
               sm.age, sm.basal_diameter * 1e3, sm.root_shoot, sm.root_nodes, grown, sm.root_length);
        char path[700];
        snprintf(path, sizeof path, "%s/fitted_roots.rsml", tmp);
        CHECK(phc_growth_write_rsml(g, path, &err) == PHC_OK);
        phc_rsml *r = NULL;
        CHECK(phc_rsml_read(path, &r, &err) == PHC_OK);
        if (r) {
            double total = phc_rsml_total_length(r);
            printf("rs_rsml: %zu roots, total length %.12g m (model %.12g m), unit %s\n", r->n_roots, total,
                   sm.root_length, r->unit ? r->unit : "(none)");
            CHECK(r->n_roots == grown);
            CHECK(r->n_roots >= 1);
            CHECK_NEAR(total, sm.root_length, 0.0, 1e-9);
            CHECK(r->unit && !strcmp(r->unit, "m"));
            CHECK(r->dimension == 3);
            phc_rsml_free(r);
        } else
            fprintf(stderr, "%s\n", err.message);

        /* the data set's own fit outputs: the same plant */
        double *p = malloc(ds->k * sizeof *p);
        for (size_t j = 0; p && j < ds->k; ++j)
            p[j] = res->params[ds->param_index[j]].value;
        CHECK(p && ds->ops->fit_outputs && ds->ops->fit_outputs(ds, p, tmp, "ds", &err) == PHC_OK);
        free(p);
        snprintf(path, sizeof path, "%s/ds_roots.rsml", tmp);
        r = NULL;
        CHECK(phc_rsml_read(path, &r, &err) == PHC_OK);
        if (r) {
            double total = phc_rsml_total_length(r);
            printf("rs_fit_outputs_rsml: %zu roots, total length %.12g m\n", r->n_roots, total);
            CHECK(r->n_roots == grown);
            CHECK_NEAR(total, sm.root_length, 0.0, 1e-9);
            phc_rsml_free(r);
        } else
            fprintf(stderr, "%s\n", err.message);
        phc_growth_free(g);
        phc_soil_free(soil);
    }
    printf("rs_total_time: %.1f s\n", now() - t0);
done:
    phc_fit_result_free(res);
    phc_problem_free(pb);
    remove_dir(tmp);
    return check_finish(NAME);
}
