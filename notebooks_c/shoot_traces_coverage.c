/* Coverage of the shoot_traces kind's 95% intervals (fit/costs/shoot_traces.h;
 * README "Fitting growth to traced shoots"): one traced plant is one draw of
 * a random process, so an honest interval covers the truth in about 95% of
 * plants drawn with the same parameters.
 *
 * N model plants (trace seeds 1001 .. 1000 + N, default N = 10) are grown
 * by the climbing model (model/climbing_growth.h) at the same truth
 * (BP 0.3, V 0.6, η 0.02 s⁻¹, τ 0.5 s⁻¹, r 0.15 s⁻¹, apical dominance 0.6,
 * max order 2; a wall y = 0 3 cm behind the seed, light from (0, 1, 2)),
 * 60 s in steps of 0.5 s, and traced every 10 s (phc_shoot_traces_from_model).
 * Each is fitted with K = 8 model seeds (1..8, the same for every plant)
 * from starts 30-50% off, sigmas absolute (the seed spread is in them):
 *   pass 1: sigma widened by the seed sd at the start values (the kind's
 *           default);
 *   pass 2: sigma widened by the seed sd at pass 1's fitted values
 *           (phc_shoot_traces_covariance_at), refitted from there.
 * Prints every estimate and interval (* = the truth outside) and the count
 * of intervals that cover the truth per parameter and pass; writes
 * shoot_traces_coverage.md.  Exit 1 when a fit fails.
 *
 * Usage: notebook_shoot_traces_coverage OUTPUT_DIR [N] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/costs/shoot_traces.h"
#include "fit/engine/fit.h"
#include "fit/engine/problem.h"
#include "measurements/shoot_traces.h"
#include "notebook_plot.h"

#define NP 5
static const char *const names[NP + 1] = {"branch_probability", "direction_variance", "phototropism",
                                          "surface_adaption", "growth_rate", NULL};
static const double truth[NP] = {0.3, 0.6, 0.02, 0.5, 0.15}, start[NP] = {0.45, 0.4, 0.03, 0.3, 0.1};
static const double lo[NP] = {0.02, 0.05, 0, 0.01, 0.05}, hi[NP] = {0.9, 1, 0.5, 3, 0.5};

static int wall_y0(void *user, const double x[3], double c[3], double n[3])
{
    (void)user;
    c[0] = x[0]; c[1] = 0; c[2] = x[2] < 0 ? 0 : x[2];
    n[0] = 0; n[1] = 1; n[2] = 0;
    return 0;
}

static int is_param(const char *name, void *user)
{
    (void)user;
    for (const char *const *l = names; *l; ++l)
        if (!strcmp(*l, name)) return 1;
    return 0;
}

static void set_values(phc_climbing_options *p, const double v[NP])
{
    p->branch_probability = v[0];
    p->direction_variance = v[1];
    p->phototropism = v[2];
    p->surface_adaption = v[3];
    p->growth_rate = v[4];
}

/* Fits ds from start values s into est/ci; 0 or 1 (failed). */
static int fit_once(phc_dataset *ds, const double s[NP], double est[NP], double ci[NP][2], phc_problem **keep)
{
    phc_error err;
    phc_error_clear(&err);
    phc_problem *pb = phc_problem_new("coverage");
    pb->options.absolute_sigma = 1;
    for (size_t j = 0; j < NP; ++j) {
        phc_problem_add_parameter(pb, names[j], s[j], NULL, &err);
        pb->params[j].lower = lo[j];
        pb->params[j].upper = hi[j];
    }
    phc_fit_result *res = NULL;
    int bad = phc_problem_bind_by_name(pb, ds, &err) || phc_problem_add_dataset(pb, ds, &err) ||
              phc_fit_run(pb, NULL, NULL, &res, &err) || !res;
    if (!bad)
        for (size_t j = 0; j < NP; ++j) {
            est[j] = res->params[j].value;
            ci[j][0] = res->params[j].ci_lo;
            ci[j][1] = res->params[j].ci_hi;
        }
    if (bad) fprintf(stderr, "fit: %s\n", err.message);
    phc_fit_result_free(res);
    *keep = pb; /* owns ds now */
    return bad;
}

int main(int argc, char **argv)
{
    const char *out = NULL;
    int started = nb_begin(argc, argv, NULL, &out);
    if (started) return started;
    const int n_plants = argc > 2 ? atoi(argv[2]) : 10;
    if (n_plants < 1 || n_plants > 1000) {
        fprintf(stderr, "N must be 1..1000\n");
        return 2;
    }
    static const char *const way[3] = {"independent sigmas (g = 0)", "g = 0.5 (default)",
                                       "g = 0.5, covariance at the fitted values"};
    int cover[3][NP] = {{0}}, fits = 0;
    char md[1024], mdtmp[1024];
    FILE *f = nb_open_md(out, "shoot_traces_coverage.md", md, mdtmp, sizeof md);
    if (!f) {
        fprintf(stderr, "%s: cannot write the page\n", out);
        return 1;
    }
    fprintf(f, "# Coverage of the shoot_traces intervals\n\n"
               "%d model plants at BP 0.3, V 0.6, eta 0.02, tau 0.5, r 0.15 (60 s, steps of 0.5 s, traced "
               "every 10 s), each fitted with K = 8 seeds; absolute sigmas. * = the truth outside the 95%% "
               "interval.\n\n| plant | fit | BP | V | eta | tau | r |\n|---|---|---|---|---|---|---|\n",
            n_plants);
    for (int pl = 0; pl < n_plants; ++pl) {
        phc_error err;
        phc_error_clear(&err);
        phc_shoot_traces_options o = phc_shoot_traces_options_default();
        set_values(&o.plant, truth);
        o.plant.apical_dominance = 0.6;
        o.plant.max_order = 2;
        o.plant.light.direction[0] = 0;
        o.plant.light.direction[1] = 1;
        o.plant.light.direction[2] = 2;
        o.plant.closest = wall_y0;
        o.position[1] = 0.03;
        o.time_step = 0.5;
        o.plant.seed = 1001 + (uint64_t)pl;
        const double times[6] = {10, 20, 30, 40, 50, 60};
        o.seeds = 8;
        o.first_seed = 1;
        o.is_parameter = is_param;
        double est[3][NP], ci[3][NP][2];
        int bad = 0;
        for (int w = 0; w < 2 && !bad; ++w) {
            o.correlation = w == 0 ? 0 : 0.5;
            phc_shoot_traces *traces = NULL; /* the data set takes them */
            set_values(&o.plant, truth);
            if (phc_shoot_traces_from_model(&o, times, 6, &traces, &err)) {
                fprintf(stderr, "plant %d: %s\n", pl, err.message);
                return 1;
            }
            set_values(&o.plant, start); /* the fit knows only the starts */
            phc_dataset *ds = NULL;
            if (phc_shoot_traces_new(traces, &o, &ds, &err)) {
                fprintf(stderr, "plant %d: %s\n", pl, err.message);
                return 1;
            }
            ds->name = strdup("model-traces");
            phc_problem *pb = NULL, *pb2 = NULL;
            bad = fit_once(ds, start, est[w], ci[w], &pb);
            if (w == 1 && !bad) { /* the covariance at the fitted values; the problem keeps owning ds */
                if (phc_shoot_traces_covariance_at(ds, est[1], &err)) bad = 1;
                if (!bad) {
                    pb->n_datasets = 0; /* hand ds to the second problem */
                    bad = fit_once(ds, est[1], est[2], ci[2], &pb2);
                }
            }
            phc_problem_free(pb);
            if (pb2) phc_problem_free(pb2);
        }
        if (bad) {
            fprintf(stderr, "plant %d: a fit failed\n", pl);
            return 1;
        }
        fits++;
        for (int pass = 0; pass < 3; ++pass) {
            printf("plant %d, %s:", 1001 + pl, way[pass]);
            fprintf(f, "| %d | %s |", 1001 + pl, way[pass]);
            for (size_t j = 0; j < NP; ++j) {
                const int in = truth[j] >= ci[pass][j][0] && truth[j] <= ci[pass][j][1];
                cover[pass][j] += in;
                printf(" %.3g [%.3g, %.3g]%s", est[pass][j], ci[pass][j][0], ci[pass][j][1], in ? "" : "*");
                fprintf(f, " %.3g [%.3g, %.3g]%s |", est[pass][j], ci[pass][j][0], ci[pass][j][1], in ? "" : " \\*");
            }
            printf("\n");
            fprintf(f, "\n");
        }
    }
    fprintf(f, "\n| intervals covering the truth | BP | V | eta | tau | r |\n|---|---|---|---|---|---|\n");
    for (int pass = 0; pass < 3; ++pass) {
        printf("coverage, %s, of %d plants:", way[pass], fits);
        fprintf(f, "| %s |", way[pass]);
        for (size_t j = 0; j < NP; ++j) {
            printf(" %s %d", names[j], cover[pass][j]);
            fprintf(f, " %d of %d |", cover[pass][j], fits);
        }
        printf("\n");
        fprintf(f, "\n");
    }
    /* The claim the README makes of these plants: the default weights (the
     * statistics' covariance between plants) cover the truth more often than
     * independent sigmas, and the covariance at the fitted values no less. */
    int total[3] = {0, 0, 0};
    for (int pass = 0; pass < 3; ++pass)
        for (size_t j = 0; j < NP; ++j)
            total[pass] += cover[pass][j];
    const int ok = total[1] > total[0] && total[2] >= total[1];
    printf("check: intervals covering the truth, of %d: %d (independent sigmas) < %d (default) <= %d (covariance "
           "at the fitted values): %s\n",
           fits * (int)NP, total[0], total[1], total[2], ok ? "pass" : "FAIL");
    fprintf(f, "\nIntervals covering the truth, of %d: %d, %d and %d.\n", fits * (int)NP, total[0], total[1],
            total[2]);
    if (nb_close_md(f, md, mdtmp)) {
        fprintf(stderr, "%s: cannot write the page\n", md);
        return 1;
    }
    return ok ? 0 : 1;
}
