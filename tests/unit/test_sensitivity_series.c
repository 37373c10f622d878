/* Indices per observation, their summary over x and named outputs of a
 * sensitivity study (fit/sensitivity_study.c), on a model with exact
 * answers: a `curve` y_t = a t + b at t = 0, 1, ..., 10 with independent
 * a ~ U(0, 1) and b ~ U(0, 2) (uniform priors from the bounds).
 *
 * Exact: Var(y_t) = t^2 Var(a) + Var(b) with Var(a) = 1/12, Var(b) = 4/12;
 * the model is additive, so S_a(t) = ST_a(t) = t^2 Var(a) / Var(y_t) and
 * S_b(t) = ST_b(t) = Var(b) / Var(y_t); the generalised index over the
 * series (Lamboni et al. 2011; Gamboa et al. 2013) is
 * S_a = sum_t t^2 Var(a) / sum_t Var(y_t).
 *
 * Checks: every per-observation S1 and ST (22 + 22) and the four summary
 * indices hold the exact value inside their 95% bootstrap interval and
 * within 0.02 of it (N = 2048, Sobol sequence); the named outputs are the
 * predictions a t + b at the given x (through predict_at, and interpolated
 * for a kind without it) and at the given observation; --points 4 keeps
 * observations 1, 4, 8, 11; phc_problem_add_output refuses bad input,
 * naming the config line. */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "fit/costs/curve.h"
#include "fit/engine/problem.h"
#include "fit/sensitivity_study.h"
#include "measurements/table.h"

enum { NT = 11 };
static const double VA = 1.0 / 12, VB = 4.0 / 12;

static phc_problem *linear_problem(void)
{
    double x[NT], y[NT];
    for (int i = 0; i < NT; ++i) {
        x[i] = i;
        y[i] = 0.5 * i + 1;
    }
    const char *names[] = {"t", "y"};
    const double *cols[] = {x, y};
    phc_table *t = NULL;
    phc_error err;
    phc_problem *pb = phc_problem_new("linear");
    CHECK(phc_table_from_columns("linear", 2, names, cols, NT, &t, &err) == PHC_OK);
    phc_curve_options o = phc_curve_options_default();
    o.x = "t";
    o.y = "y";
    o.expression = "a * t + b";
    o.sigma = 1;
    size_t idx;
    CHECK(phc_problem_add_parameter(pb, "a", 0.5, &idx, &err) == PHC_OK);
    pb->params[idx].lower = 0;
    pb->params[idx].upper = 1;
    CHECK(phc_problem_add_parameter(pb, "b", 1, &idx, &err) == PHC_OK);
    pb->params[idx].lower = 0;
    pb->params[idx].upper = 2;
    phc_dataset *ds = NULL;
    CHECK(phc_curve_new(t, &o, &ds, &err) == PHC_OK);
    ds->name = strdup("line");
    CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_OK);
    CHECK(phc_problem_add_dataset(pb, ds, &err) == PHC_OK);
    phc_table_free(t);
    return pb;
}

static double exact_sa(double t)
{
    return t * t * VA / (t * t * VA + VB);
}

static double num(json_t *v)
{
    return json_is_number(v) ? json_number_value(v) : NAN;
}

/* max |estimate - exact| over the checks, for the printout */
static double worst = 0;

static void check_index(const char *what, double est, double lo, double hi, double exact)
{
    CHECK(lo <= exact && exact <= hi);
    CHECK_NEAR(est, exact, 0.02, 0);
    if (!(lo <= exact && exact <= hi) || !(fabs(est - exact) <= 0.02))
        fprintf(stderr, "  %s: %.4f [%.4f, %.4f], exact %.4f\n", what, est, lo, hi, exact);
    if (fabs(est - exact) > worst)
        worst = fabs(est - exact);
}

static void test_series(void)
{
    char dir[] = "/tmp/phc_series_XXXXXX";
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    char run[300], path[400];
    snprintf(run, sizeof run, "%s/run", dir);
    phc_problem *pb = linear_problem();
    CHECK(phc_study_scalar_outputs(pb) == 2); /* cost, line.mean */
    CHECK(phc_study_outputs(pb) == 2 + NT);
    phc_study_options o = phc_study_options_default();
    o.samples = 2048;
    phc_study_summary sum;
    phc_error err;
    CHECK(phc_study_run(pb, &o, NULL, run, &sum, &err) == PHC_OK);
    phc_study_summary_clear(&sum);
    snprintf(path, sizeof path, "%s/result.json", run);
    json_error_t jerr;
    json_t *root = json_load_file(path, 0, &jerr);
    CHECK(root != NULL);
    json_t *series = json_array_get(json_object_get(root, "series"), 0);
    CHECK(series && strcmp(json_string_value(json_object_get(series, "dataset")), "line") == 0);
    CHECK(json_array_size(json_object_get(series, "observations")) == NT);
    const char *f[2] = {"a", "b"};
    const char *keys[2] = {"S1", "ST"};
    json_t *idx = json_object_get(series, "indices");
    double sum_num = 0, sum_var = 0;
    for (int t = 0; t < NT; ++t) {
        sum_num += t * t * VA;
        sum_var += t * t * VA + VB;
        for (int g = 0; g < 2; ++g)
            for (int k = 0; k < 2; ++k) {
                json_t *fg = json_object_get(idx, f[g]);
                char lo_key[32], hi_key[32], what[64];
                snprintf(lo_key, sizeof lo_key, "%s_ci95_lower", keys[k]);
                snprintf(hi_key, sizeof hi_key, "%s_ci95_upper", keys[k]);
                snprintf(what, sizeof what, "%s_%s(t = %d)", keys[k], f[g], t);
                const double exact = g == 0 ? exact_sa(t) : 1 - exact_sa(t);
                const double est = num(json_array_get(json_object_get(fg, keys[k]), (size_t)t));
                if (t == 0 || t == 1 || t == 5 || t == 10)
                    printf("%s = %.4f [%.4f, %.4f], exact %.4f\n", what, est,
                           num(json_array_get(json_object_get(fg, lo_key), (size_t)t)),
                           num(json_array_get(json_object_get(fg, hi_key), (size_t)t)), exact);
                check_index(what, est, num(json_array_get(json_object_get(fg, lo_key), (size_t)t)),
                            num(json_array_get(json_object_get(fg, hi_key), (size_t)t)), exact);
            }
    }
    json_t *summary = json_object_get(json_object_get(series, "summary"), "indices");
    for (int g = 0; g < 2; ++g)
        for (int k = 0; k < 2; ++k) {
            json_t *fg = json_object_get(summary, f[g]);
            char ci[32], what[64];
            snprintf(ci, sizeof ci, "%s_ci95", keys[k]);
            snprintf(what, sizeof what, "summary %s_%s", keys[k], f[g]);
            const double exact = g == 0 ? sum_num / sum_var : 1 - sum_num / sum_var;
            const double est = num(json_object_get(fg, keys[k]));
            const double lo = num(json_array_get(json_object_get(fg, ci), 0)),
                         hi = num(json_array_get(json_object_get(fg, ci), 1));
            printf("%s over t = %.4f [%.4f, %.4f], exact %.4f\n", what, est, lo, hi, exact);
            check_index(what, est, lo, hi, exact);
        }
    printf("largest |estimate - exact| over the 44 per-observation and 4 summary indices: %.4f\n", worst);
    json_decref(root);
    /* the report and the plot of the series */
    snprintf(path, sizeof path, "%s/line_over_x.png", run);
    CHECK(access(path, R_OK) == 0);
    /* Morris: mu* per observation.  Levels sit at the quantiles (l + 1/2)/p
       (p = 4) and a jump of Delta = p / (2 (p - 1)) = 2/3 grid units moves u
       by 1/2, so an effect per unit of the grid is 3/4 of the change per
       unit of u: mu*_a(t) = 3/4 t (a spans 1) and mu*_b(t) = 3/4 * 2 = 1.5 */
    o.method = PHC_STUDY_MORRIS;
    o.samples = 20;
    o.force = 1;
    CHECK(phc_study_run(pb, &o, NULL, run, &sum, &err) == PHC_OK);
    phc_study_summary_clear(&sum);
    snprintf(path, sizeof path, "%s/result.json", run);
    root = json_load_file(path, 0, &jerr);
    json_t *mi = json_object_get(json_array_get(json_object_get(root, "series"), 0), "indices");
    json_t *ma = json_object_get(json_object_get(mi, "a"), "mu_star"), *mb = json_object_get(json_object_get(mi, "b"),
                                                                                             "mu_star");
    double morris_err = 0;
    for (int t = 0; t < NT; ++t) {
        morris_err = fmax(morris_err, fabs(num(json_array_get(ma, (size_t)t)) - 0.75 * t));
        morris_err = fmax(morris_err, fabs(num(json_array_get(mb, (size_t)t)) - 1.5));
    }
    printf("Morris mu*_a(t) against 3/4 t and mu*_b(t) against 1.5: largest difference %.3g\n", morris_err);
    CHECK(morris_err < 1e-12);
    json_decref(root);
    phc_problem_free(pb);
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    CHECK(system(cmd) == 0);
}

static phc_dataset_ops without_predict_at;

static void test_named_outputs(void)
{
    phc_problem *pb = linear_problem();
    phc_error err;
    CHECK(phc_problem_add_output(pb, "y_at_2.5", "line", 2.5, 0, 0, &err) == PHC_OK);
    CHECK(phc_problem_add_output(pb, "y_obs_4", "line", NAN, 4, 0, &err) == PHC_OK);
    CHECK(phc_study_scalar_outputs(pb) == 4);
    char name[64];
    phc_study_output_name(pb, 2, name, sizeof name);
    CHECK(strcmp(name, "y_at_2.5") == 0);
    phc_study_output_name(pb, 4, name, sizeof name);
    CHECK(strcmp(name, "line@1") == 0);
    phc_study_eval *w = phc_study_eval_new(pb);
    const double x[2] = {0.37, 1.21};
    double out[4 + NT];
    CHECK(phc_study_evaluate(w, x, out) == 0);
    printf("named outputs at a = 0.37, b = 1.21: y(2.5) = %.17g (exact %.17g), observation 4: %.17g (exact %.17g)\n",
           out[2], 0.37 * 2.5 + 1.21, out[3], 0.37 * 3 + 1.21);
    CHECK_NEAR(out[2], 0.37 * 2.5 + 1.21, 0, 1e-15);
    CHECK_NEAR(out[3], 0.37 * 3 + 1.21, 0, 1e-15);
    for (int t = 0; t < NT; ++t)
        CHECK_NEAR(out[4 + t], 0.37 * t + 1.21, 0, 1e-15);
    phc_study_eval_free(w);
    /* a kind without predict_at: linear between the observations 3 and 4 */
    without_predict_at = *pb->datasets[0]->ops;
    without_predict_at.predict_at = NULL;
    pb->datasets[0]->ops = &without_predict_at;
    w = phc_study_eval_new(pb);
    CHECK(phc_study_evaluate(w, x, out) == 0);
    CHECK_NEAR(out[2], 0.37 * 2.5 + 1.21, 0, 1e-15);
    phc_study_eval_free(w);
    /* at the last x: the last observation */
    CHECK(phc_problem_add_output(pb, "y_end", "line", 10, 0, 0, &err) == PHC_OK);
    w = phc_study_eval_new(pb);
    double out2[5 + NT];
    CHECK(phc_study_evaluate(w, x, out2) == 0);
    CHECK_NEAR(out2[4], 0.37 * 10 + 1.21, 0, 1e-15);
    phc_study_eval_free(w);
    /* --points 4 of 11: observations 1, 4, 8, 11 (round(t * 10 / 3) + 1) */
    pb->series_points = 4;
    CHECK(phc_study_outputs(pb) == 5 + 4);
    const char *expect[4] = {"line@1", "line@4", "line@8", "line@11"};
    for (size_t t = 0; t < 4; ++t) {
        phc_study_output_name(pb, 5 + t, name, sizeof name);
        CHECK(strcmp(name, expect[t]) == 0);
    }
    pb->series_points = 0;
    CHECK(phc_study_outputs(pb) == 5);
    /* bad input */
    pb->source = strdup("cfg.yaml");
    CHECK(phc_problem_add_output(pb, "q", "lines", 1, 0, 30, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:30: outputs: 'q': dataset: no data set is called 'lines' (the data "
                                    "sets: line)");
    CHECK(phc_problem_add_output(pb, "q", "line", 10.5, 0, 31, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:31: outputs: 'q': at: 10.5 lies outside data set 'line''s x range [0, 10]");
    CHECK(phc_problem_add_output(pb, "q", "line", NAN, 12, 32, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "observation: 12 is beyond the 11 observations");
    CHECK(phc_problem_add_output(pb, "y_end", "line", 1, 0, 33, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "the name is used twice");
    CHECK(phc_problem_add_output(pb, "cost", "line", 1, 0, 34, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "'cost' is the name of the study's cost output");
    CHECK(phc_problem_add_output(pb, "line.mean", "line", 1, 0, 36, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "a study names data set 'line''s own output so");
    CHECK(phc_problem_add_output(pb, "a b", "line", 1, 0, 35, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "a name holds only letters");
    CHECK(pb->n_outputs == 3);
    phc_problem_free(pb);
}

int main(void)
{
    test_named_outputs();
    test_series();
    return check_finish("test_sensitivity_series");
}
