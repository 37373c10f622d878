/* The study driver (fit/sensitivity_study.c) end to end on a problem built in
 * C: one `curve` observation at y = 0 whose expression is the Ishigami
 * function of three parameters with bounds [-pi, pi] (uniform priors from
 * the bounds), so the data set's mean prediction is the Ishigami function
 * and the cost is half its square.
 *
 * Checks: phc_study_evaluate's outputs against the formula; the run
 * directory's result.json holds the exact Ishigami indices (S1 = 0.3139,
 * 0.4424, 0; ST = 0.5576, 0.4424, 0.2437) inside its intervals for the mean
 * output; a group {a, c} gets one factor; a fixed parameter is not a
 * factor; an unbounded parameter without a prior is refused. */
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

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static phc_problem *ishigami_problem(void)
{
    const double x[1] = {0}, y[1] = {0};
    const char *names[] = {"x", "y"};
    const double *cols[] = {x, y};
    phc_table *t = NULL;
    phc_error err;
    phc_problem *pb = phc_problem_new("ishigami");
    CHECK(phc_table_from_columns("ishigami", 2, names, cols, 1, &t, &err) == PHC_OK);
    phc_curve_options o = phc_curve_options_default();
    o.x = "x";
    o.y = "y";
    o.expression = "sin(a) + 7 * sin(b)^2 + 0.1 * c^4 * sin(a)";
    o.sigma = 1;
    phc_dataset *ds = NULL;
    const char *pn[3] = {"a", "b", "c"};
    for (int i = 0; i < 3; ++i) {
        size_t idx;
        CHECK(phc_problem_add_parameter(pb, pn[i], 0.1, &idx, &err) == PHC_OK);
        pb->params[idx].lower = -M_PI;
        pb->params[idx].upper = M_PI;
    }
    CHECK(phc_curve_new(t, &o, &ds, &err) == PHC_OK);
    CHECK(phc_problem_bind_by_name(pb, ds, &err) == PHC_OK);
    CHECK(phc_problem_add_dataset(pb, ds, &err) == PHC_OK);
    phc_table_free(t);
    return pb;
}

static void test_evaluate(void)
{
    phc_problem *pb = ishigami_problem();
    CHECK(phc_study_outputs(pb) == 3); /* cost, mean, the prediction at the one observation */
    char name[64];
    phc_study_output_name(pb, 1, name, sizeof name);
    CHECK(strcmp(name, "dataset-1.mean") == 0); /* built in C without a name */
    phc_study_eval *w = phc_study_eval_new(pb);
    const double x[3] = {0.3, -1.2, 2.5};
    double out[3];
    CHECK(phc_study_evaluate(w, x, out) == 0);
    const double f = sin(0.3) + 7 * pow(sin(-1.2), 2) + 0.1 * pow(2.5, 4) * sin(0.3);
    CHECK_NEAR(out[1], f, 0, 1e-14);
    CHECK_NEAR(out[0], 0.5 * f * f, 0, 1e-14);
    CHECK(out[2] == out[1]); /* the one observation's prediction is the mean */
    phc_study_eval_free(w);
    phc_problem_free(pb);
}

static double get(json_t *root, size_t out, const char *factor, const char *key, int which)
{
    json_t *o = json_array_get(json_object_get(root, "outputs"), out);
    json_t *v = json_object_get(json_object_get(json_object_get(o, "indices"), factor), key);
    if (which >= 0)
        v = json_array_get(v, (size_t)which);
    return json_is_number(v) ? json_number_value(v) : NAN;
}

static void test_study(void)
{
    const double pi4 = pow(M_PI, 4), pi8 = pow(M_PI, 8);
    const double v1 = 0.5 * pow(1 + 0.1 * pi4 / 5, 2), v2 = 49.0 / 8, v13 = 0.01 * pi8 * (1.0 / 18 - 1.0 / 50);
    const double v = v1 + v2 + v13;
    const double s1[3] = {v1 / v, v2 / v, 0}, st[3] = {(v1 + v13) / v, v2 / v, v13 / v};
    char dir[] = "/tmp/phc_study_XXXXXX";
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    char run[300];
    snprintf(run, sizeof run, "%s/run", dir);
    phc_problem *pb = ishigami_problem();
    phc_study_options o = phc_study_options_default();
    o.samples = 2048;
    phc_study_summary sum;
    phc_error err;
    CHECK(phc_study_run(pb, &o, NULL, run, &sum, &err) == PHC_OK);
    CHECK(sum.evaluations == 2048 * 5 && sum.computed == sum.evaluations && sum.failed == 0);
    printf("verdict:\n%s", sum.verdict ? sum.verdict : "(none)\n");
    phc_study_summary_clear(&sum);
    char path[400];
    snprintf(path, sizeof path, "%s/result.json", run);
    json_error_t jerr;
    json_t *root = json_load_file(path, 0, &jerr);
    CHECK(root != NULL);
    const char *f[3] = {"a", "b", "c"};
    for (int i = 0; root && i < 3; ++i) {
        const double e1 = get(root, 1, f[i], "S1", -1), et = get(root, 1, f[i], "ST", -1);
        const double l1 = get(root, 1, f[i], "S1_ci95", 0), h1 = get(root, 1, f[i], "S1_ci95", 1);
        const double lt = get(root, 1, f[i], "ST_ci95", 0), ht = get(root, 1, f[i], "ST_ci95", 1);
        printf("study through result.json, %s: S1 = %.4f [%.4f, %.4f] (exact %.4f), ST = %.4f [%.4f, %.4f] "
               "(exact %.4f)\n", f[i], e1, l1, h1, s1[i], et, lt, ht, st[i]);
        CHECK(l1 <= s1[i] && s1[i] <= h1);
        CHECK(lt <= st[i] && st[i] <= ht);
    }
    json_decref(root);
    /* groups: {a, c} as one factor (its closed index 1 - S_b); b fixed at its start */
    phc_parameter_group g = {strdup("ac"), malloc(2 * sizeof(size_t)), 2, 0};
    g.members[0] = 0;
    g.members[1] = 2;
    pb->groups = malloc(sizeof g);
    pb->groups[0] = g;
    pb->n_groups = 1;
    pb->params[1].fixed = 1;
    o.samples = 64;
    o.force = 1;
    CHECK(phc_study_run(pb, &o, NULL, run, &sum, &err) == PHC_OK);
    CHECK(sum.evaluations == 64 * 3); /* one factor: N (1 + 2) */
    phc_study_summary_clear(&sum);
    root = json_load_file(path, 0, &jerr);
    CHECK(root && json_array_size(json_object_get(root, "factors")) == 1);
    CHECK(root && isfinite(get(root, 1, "ac", "ST", -1)));
    /* with b fixed the group holds all the variance: S1 = ST = 1 within the intervals */
    const double gs1 = root ? get(root, 1, "ac", "S1", -1) : NAN, gst = root ? get(root, 1, "ac", "ST", -1) : NAN;
    printf("group {a, c} with b fixed, N = 64: S1 = %.4f [%.4f, %.4f], ST = %.4f [%.4f, %.4f] (exact 1)\n", gs1,
           get(root, 1, "ac", "S1_ci95", 0), get(root, 1, "ac", "S1_ci95", 1), gst, get(root, 1, "ac", "ST_ci95", 0),
           get(root, 1, "ac", "ST_ci95", 1));
    CHECK(get(root, 1, "ac", "S1_ci95", 0) <= 1 && 1 <= get(root, 1, "ac", "S1_ci95", 1));
    CHECK(get(root, 1, "ac", "ST_ci95", 0) <= 1 && 1 <= get(root, 1, "ac", "ST_ci95", 1));
    json_decref(root);
    /* an open bound without a prior */
    pb->params[1].fixed = 0;
    pb->params[1].upper = INFINITY;
    CHECK(phc_study_run(pb, &o, NULL, run, &sum, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "parameter 'b': a sensitivity study needs finite bounds");
    phc_problem_free(pb);
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    CHECK(system(cmd) == 0);
}

int main(void)
{
    test_evaluate();
    test_study();
    return check_finish("test_sensitivity_study");
}
