/* Regression test of the shoot_traces kind (fit/costs/shoot_traces.h):
 *  1. Derivative against an exact solution: a straight shoot (BP = 0, full
 *     light, no support) has total length L_max(σ₀ + r t + σ₀⌊r t/(1 − σ₀)⌋)
 *     (model/climbing_growth.h), a staircase in r whose trend has slope
 *     L_max t/(1 − σ₀).  The kind's central difference with step h = 20% of r
 *     lies within σ₀ L_max/(2h) (one jump over the step) of the trend, and
 *     the model values equal the formula exactly.
 *  2. The same thing on both sides: traces of the model plant with seed
 *     1001 (phc_shoot_traces_from_model, every 10 s) against the data
 *     set's model with that seed alone (K = 1) at the same values: every
 *     statistic equal (difference 0).
 *  3. Recovery: those traces (BP 0.3, V 0.6, η 0.02, τ 0.5, r 0.15, steps
 *     of 0.5 s) fitted with 8 other seeds (1..8) from starts 30-50% off,
 *     absolute sigma (the statistics' covariance between plants is in it).
 *     Checked: the fit converges, every parameter's 95% interval covers
 *     the truth, growth_rate within 5%, the kind's Jacobian has full rank.
 *     Measured: BP 0.324 [0.219, 0.428], V 0.71 [0.07, 1.35], η 0.049
 *     [0.002, 0.096], τ 0.488 [0.161, 0.816], r 0.147 [0.137, 0.157]. */
#include "fit/costs/shoot_traces.h"
#include "fit/engine/fit.h"
#include "fit/engine/problem.h"
#include "measurements/shoot_traces.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../check.h"
#include "../shoot_traces_wall_plant.h"

static const char *only;
static int is_param(const char *name, void *user)
{
    const char *const *list = user;
    if (only) return !strcmp(name, only);
    for (; *list; ++list)
        if (!strcmp(*list, name)) return 1;
    return 0;
}

static void test_derivative(void)
{
    phc_error err;
    phc_error_clear(&err);
    phc_shoot_traces_options o = phc_shoot_traces_options_default();
    o.plant.branch_probability = 0;
    o.plant.growth_rate = 0.2;
    o.time_step = 0.25;
    o.seeds = 2;
    const double times[2] = {60, 120};
    o.times = times;
    o.n_times = 2;
    phc_shoot_traces *tr = NULL;
    CHECK(phc_shoot_traces_from_model(&o, times, 2, &tr, &err) == PHC_OK);
    only = "growth_rate";
    o.is_parameter = is_param;
    phc_dataset *ds = NULL;
    CHECK(phc_shoot_traces_new(tr, &o, &ds, &err) == PHC_OK);
    if (!ds) { fprintf(stderr, "%s\n", err.message); return; }
    CHECK(ds->k == 1 && !strcmp(ds->slot_names[0], "growth_rate"));
    double p = 0.2, *y = malloc(ds->n * sizeof *y), *J = malloc(ds->n * sizeof *J);
    CHECK(phc_shoot_traces_model_jacobian(ds, &p, y, J) == 0);
    const double L = o.plant.max_length, s0 = o.plant.bud_fraction, h = o.fd_step * p;
    for (size_t j = 0; j < 2; ++j) {
        const double t = times[j];
        const double exact = L * (s0 + p * t + s0 * floor(p * t / (1 - s0) + 1e-12));
        const double trend = L * t / (1 - s0);
        /* observation 5j is total_length at times[j] */
        printf("t %g s: total length %.15g m (formula %.15g); dL/dr %.6g (trend %.6g, bound %.3g)\n", t, y[5 * j],
               exact, J[5 * j], trend, s0 * L / (2 * h));
        CHECK_NEAR(y[5 * j], exact, 1e-12, 0);
        CHECK_NEAR(phc_shoot_traces_traced(ds)[5 * j], exact, 1e-9, 0); /* the traces from the same model */
        CHECK(fabs(J[5 * j] - trend) <= s0 * L / (2 * h) + 1e-9);
    }
    only = NULL;
    free(y);
    free(J);
    phc_dataset_free(ds);
}

static void test_recovery(void)
{
    phc_error err;
    phc_error_clear(&err);
    static const char *const names[] = {"branch_probability", "direction_variance", "phototropism",
                                        "surface_adaption", "growth_rate", NULL};
    const double *truth = shoot_traces_wall_truth, *start = shoot_traces_wall_start;
    const double *lo = shoot_traces_wall_lower, *hi = shoot_traces_wall_upper;
    phc_shoot_traces_options o = shoot_traces_wall_options(1001);
    const double times[12] = {10, 20, 30, 40, 50, 60, 70, 80, 90, 100, 110, 120};
    phc_shoot_traces *tr = NULL;
    o.is_parameter = is_param;
    o.user_data = (void *)names;
    /* the same thing on both sides: the data set's model plant with the traces' seed, K = 1,
     * at the truth reproduces every traced statistic exactly */
    {
        CHECK(phc_shoot_traces_from_model(&o, times, 12, &tr, &err) == PHC_OK);
        o.seeds = 1;
        o.first_seed = 1001;
        phc_dataset *same = NULL;
        CHECK(phc_shoot_traces_new(tr, &o, &same, &err) == PHC_OK);
        if (same) {
            double *y = malloc(same->n * sizeof *y), worst = 0;
            CHECK(phc_shoot_traces_model(same, truth, y, NULL) == 0);
            const double *traced = phc_shoot_traces_traced(same);
            for (size_t i = 0; i < same->n; ++i) worst = fmax(worst, fabs(y[i] - traced[i]));
            printf("seed 1001, K = 1, at the truth: %zu statistics, max |model - traced| = %g\n", same->n, worst);
            CHECK(worst == 0);
            free(y);
        }
        phc_dataset_free(same); /* frees the traces */
        tr = NULL;
    }
    CHECK(phc_shoot_traces_from_model(&o, times, 12, &tr, &err) == PHC_OK);
    /* the fit knows only the starts (they also set the seed spread in sigma) */
    shoot_traces_wall_set(&o.plant, start);
    if (!tr) { fprintf(stderr, "%s\n", err.message); return; }
    printf("model traces (seed 1001): %zu shoots, %zu points\n", tr->n_shoots, tr->n_points);
    o.seeds = 8;
    o.first_seed = 1;
    phc_dataset *ds = NULL;
    CHECK(phc_shoot_traces_new(tr, &o, &ds, &err) == PHC_OK);
    if (!ds) { fprintf(stderr, "%s\n", err.message); return; }
    ds->name = strdup("model-traces");
    phc_problem *pb = phc_problem_new("recovery");
    pb->options.absolute_sigma = 1; /* sigma holds the seed spread: the intervals are not rescaled */
    for (size_t j = 0; j < 5; ++j) {
        CHECK(phc_problem_add_parameter(pb, names[j], start[j], NULL, &err) == PHC_OK);
        pb->params[j].lower = lo[j];
        pb->params[j].upper = hi[j];
    }
    CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_OK);
    CHECK(phc_problem_add_dataset(pb, ds, &err) == PHC_OK);
    phc_fit_result *res = NULL;
    CHECK(phc_fit_run(pb, NULL, NULL, &res, &err) == PHC_OK);
    if (res) {
        printf("fit: %s, cost %.6g, rank %zu of %zu\n", phc_fit_status_name(res->summary.outcome), res->cost,
               res->rank, res->n_free);
        int within[5];
        for (size_t j = 0; j < 5; ++j) {
            const phc_param_result *q = &res->params[j];
            within[j] = truth[j] >= q->ci_lo && truth[j] <= q->ci_hi;
            printf("%-20s truth %-6g estimate %-10.4g 95%% [%.4g, %.4g] %s\n", q->name, truth[j], q->value, q->ci_lo,
                   q->ci_hi, within[j] ? "within" : "outside");
        }
        CHECK(res->summary.outcome == PHC_NLS_CONVERGED);
        for (size_t j = 0; j < 5; ++j) CHECK(within[j]);
        CHECK_NEAR(res->params[4].value, truth[4], 0, 0.05);
        double p[5];
        for (size_t j = 0; j < 5; ++j) p[j] = res->params[j].value;
        phc_shoot_traces_ident id;
        CHECK(phc_shoot_traces_identifiability(ds, p, &id, &err) == PHC_OK);
        printf("kind's identifiability: rank %zu, condition %.3g\n", id.rank, id.condition);
        for (size_t j = 0; j < 5; ++j)
            printf("  %-20s sd %.3g sensitivity %.3g max cosine %.3f\n", ds->slot_names[j], id.sd[j],
                   id.sensitivity[j], id.max_corr[j]);
        CHECK(id.rank == 5);
    }
    phc_fit_result_free(res);
    phc_problem_free(pb);
}

int main(void)
{
    test_derivative();
    test_recovery();
    return check_finish("test_shoot_traces_recovery");
}
