/* Verdicts that say when a fit should not be trusted (issue 18): baselines
 * (fit/engine/baseline.h), rank-deficient Jacobians and intervals that cross
 * a bound (fit/engine/fit.c's verdict), the headline status and their round
 * trip through result.json.  Every case is a `curve` fit built in C:
 *
 * 1. the baseline estimators against closed forms: the weighted mean and
 *    the weighted least-squares line of 4 points (by hand);
 * 2. a model that loses to the mean: y = x (x = 1..10) fitted by a (11 − x):
 *    R² < 0, and the verdict says so in words;
 * 3. a straight line that beats the model: y = 2 + 3x + small wiggles fitted
 *    by a x²: the line's AICc is lower by far, and the verdict says so;
 * 4. a rank-deficient fit: y = a b x has rank 1 of 2; the headline reads
 *    "converged, not identifiable (rank 1 of 2)" and the verdict says so;
 * 5. an interval across a bound: y ≈ 0.3 with σ = 1, a ≥ 0: the 95%
 *    interval of a crosses 0 and is flagged;
 * 6. a good fit (Michaelis–Menten on its own data) has none of these;
 * 7. result.json written and read back gives the same warnings;
 * 8. a parameter without any effect (y = a x + 0 b): the first start stalls
 *    on that plateau, and the rescue starts stop after three that stall too
 *    (fit.c's RESCUE_PATIENCE) instead of running all 16. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "fit/costs/curve.h"
#include "fit/engine/baseline.h"
#include "fit/engine/fit.h"
#include "fit/engine/problem.h"
#include "fit/report.h"
#include "fit/result_json.h"
#include "measurements/table.h"

typedef struct param_spec {
    const char *name;
    double start, lower;
} param_spec;

/* Fits y(x) with the expression; NULL with a message on failure. */
static phc_fit_result *fit(const char *name, const double *x, const double *y, size_t n, const char *expr,
                           const param_spec *ps, size_t np, double sigma)
{
    const char *cols[] = {"x", "y"};
    const double *data[] = {x, y};
    phc_table *t = NULL;
    phc_error err;
    phc_error_clear(&err);
    phc_fit_result *res = NULL;
    phc_problem *pb = phc_problem_new(name);
    phc_dataset *ds = NULL;
    phc_curve_options o = phc_curve_options_default();
    o.x = "x";
    o.y = "y";
    o.expression = expr;
    o.sigma = sigma;
    int rc = phc_table_from_columns(name, 2, cols, data, n, &t, &err);
    if (!rc)
        rc = phc_curve_new(t, &o, &ds, &err);
    phc_table_free(t);
    for (size_t j = 0; j < np && !rc; ++j) {
        size_t idx;
        rc = phc_problem_add_parameter(pb, ps[j].name, ps[j].start, &idx, &err);
        if (!rc)
            pb->params[idx].lower = ps[j].lower;
    }
    if (!rc) {
        ds->name = strdup("data");
        rc = phc_problem_bind_by_name(pb, ds, &err);
        if (rc)
            phc_dataset_free(ds);
        else
            rc = phc_problem_add_dataset(pb, ds, &err);
    } else {
        phc_dataset_free(ds);
    }
    if (!rc)
        rc = phc_problem_finish(pb, 0, &err);
    if (!rc) {
        pb->options.starts = 1;
        rc = phc_fit_run(pb, NULL, NULL, &res, &err);
    }
    if (rc)
        fprintf(stderr, "%s: %s\n", name, err.message);
    phc_problem_free(pb);
    return res;
}

/* 1 when some warning contains every one of the (NULL-terminated) words. */
static int warned(const phc_fit_result *r, const char *const *words)
{
    for (size_t i = 0; r && i < r->n_warnings; ++i) {
        int all = 1;
        for (size_t w = 0; words[w] && all; ++w)
            all = strstr(r->warnings[i], words[w]) != NULL;
        if (all)
            return 1;
    }
    return 0;
}

static void print_verdict(const char *what, const phc_fit_result *r)
{
    printf("%s:\n", what);
    phc_report_print_summary(r, stdout);
}

static void test_estimators(void)
{
    const double u[] = {0, 1, 2, 3}, y[] = {1, 3, 2, 6}, s[] = {1, 1, 2, 2};
    phc_baseline m, l;
    CHECK(phc_baseline_mean(y, s, 4, &m) == PHC_OK);
    /* weights 1, 1, 1/4, 1/4: mean (1 + 3 + 0.5 + 1.5) / 2.5 = 2.4; wrss by hand */
    const double mean = 2.4, wrss = (1.4 * 1.4 + 0.6 * 0.6) + (0.4 * 0.4 + 3.6 * 3.6) / 4;
    CHECK_NEAR(m.goodness.wrss, wrss, 0, 1e-14);
    CHECK(m.goodness.k == 1 && strcmp(m.name, "mean") == 0);
    CHECK(phc_baseline_line(u, y, s, 4, "line", "a line", &l) == PHC_OK);
    /* weighted normal equations: Sw 2.5, Su 1.75, Suu 1 + 1 + 9/4 = 4.25... solve by hand in closed form */
    const double sw = 2.5, su = 0 + 1 + 0.5 + 0.75, sy = 6.0, suu = 0 + 1 + 1 + 2.25, suy = 0 + 3 + 1 + 4.5;
    const double b = (sw * suy - su * sy) / (sw * suu - su * su), a = (sy - b * su) / sw;
    double w2 = 0;
    for (int i = 0; i < 4; ++i)
        w2 += pow((y[i] - a - b * u[i]) / s[i], 2);
    printf("baselines: weighted mean %.15g (by hand %.15g), wrss %.15g (%.15g); line a %.6g b %.6g, wrss %.15g "
           "(by hand %.15g)\n",
           mean, mean, m.goodness.wrss, wrss, a, b, l.goodness.wrss, w2);
    CHECK_NEAR(l.goodness.wrss, w2, 0, 1e-13);
    CHECK(l.goodness.k == 2);
    const double same[] = {2, 2, 2, 2};
    CHECK(phc_baseline_line(same, y, s, 4, "line", "a line", &l) == 1); /* u all equal: no line */
    CHECK(phc_baseline_line(u, y, s, 2, "line", "a line", &l) == 1);    /* too few points */
}

int main(void)
{
    test_estimators();
    double x[10], y[10];
    for (int i = 0; i < 10; ++i)
        x[i] = i + 1, y[i] = i + 1;

    const param_spec pa[] = {{"a", 1.0, -INFINITY}};
    phc_fit_result *r = fit("loses-to-mean", x, y, 10, "a * (11 - x)", pa, 1, 0);
    CHECK(r != NULL);
    if (r) {
        print_verdict("a decreasing model on increasing data", r);
        CHECK(r->datasets[0].goodness.r2 < 0);
        CHECK(warned(r, (const char *const[]){"worse than their mean", "R² = -", NULL}));
        CHECK(warned(r, (const char *const[]){"a straight line in x", "fits these data exactly", NULL}));
    }

    /* y = 2 + 3x + wiggles, model a x² */
    double yl[10];
    for (int i = 0; i < 10; ++i)
        yl[i] = 2 + 3 * x[i] + 0.05 * sin(3.0 * i);
    phc_fit_result *r2 = fit("line-wins", x, yl, 10, "a * x^2", pa, 1, 0);
    CHECK(r2 != NULL);
    if (r2) {
        print_verdict("a parabola through the origin on a straight line", r2);
        CHECK(r2->datasets[0].n_baselines == 2);
        CHECK(warned(r2, (const char *const[]){"a straight line in x", "fits these data better", NULL}));
        CHECK(!warned(r2, (const char *const[]){"worse than their mean", NULL}));
    }

    const param_spec pab[] = {{"a", 1.0, -INFINITY}, {"b", 2.0, -INFINITY}};
    phc_fit_result *r3 = fit("rank-1", x, yl, 10, "a * b * x", pab, 2, 0);
    CHECK(r3 != NULL);
    if (r3) {
        print_verdict("y = a b x", r3);
        CHECK(r3->rank == 1 && r3->n_free == 2);
        CHECK(warned(r3, (const char *const[]){"rank 1 of 2", "not identifiable", NULL}));
        char line[256] = "";
        FILE *mem = fmemopen(line, sizeof line - 1, "w");
        phc_report_print_summary(r3, mem);
        fclose(mem);
        CHECK_STR_CONTAINS(line, "converged, not identifiable (rank 1 of 2)");
    }

    /* a parameter with no effect anywhere: rescue starts stop after three that stall too */
    phc_fit_result *r6 = fit("no-effect", x, yl, 10, "a * x + 0 * b", pab, 2, 0);
    CHECK(r6 != NULL);
    if (r6) {
        printf("y = a x + 0 b: %zu starts, %zu rescue starts, stopped early: %s\n", r6->starts, r6->rescue_starts,
               r6->rescue_stopped ? "yes" : "no");
        CHECK(r6->rescue_stopped && r6->rescue_starts == 3 && r6->starts == 4);
    }
    phc_fit_result_free(r6);

    /* y ≈ 0.3 with σ = 1, a >= 0 */
    double yc[10];
    for (int i = 0; i < 10; ++i)
        yc[i] = 0.3 + 0.8 * sin(2.1 * i);
    const param_spec pc[] = {{"a", 1.0, 0.0}};
    phc_fit_result *r4 = fit("interval-bound", x, yc, 10, "a", pc, 1, 1.0);
    CHECK(r4 != NULL);
    if (r4) {
        print_verdict("a mean near 0 with a >= 0", r4);
        CHECK(r4->params[0].ci_lo < 0 && r4->params[0].lower == 0 && !r4->params[0].at_bound);
        CHECK(warned(r4, (const char *const[]){"'a'", "crosses its lower bound 0", NULL}));
    }

    /* Michaelis–Menten on its own data (with a wiggle): no warning of these kinds */
    double xm[10], ym[10];
    for (int i = 0; i < 10; ++i) {
        xm[i] = 0.02 * (i + 1) * (i + 1);
        ym[i] = 200 * xm[i] / (0.1 + xm[i]) + 0.5 * sin(1.7 * i);
    }
    const param_spec pm[] = {{"vmax", 150, 0}, {"km", 0.2, 0}};
    phc_fit_result *r5 = fit("good", xm, ym, 10, "vmax * x / (km + x)", pm, 2, 0);
    CHECK(r5 != NULL);
    if (r5) {
        print_verdict("Michaelis-Menten", r5);
        CHECK(!warned(r5, (const char *const[]){"mean", NULL}) &&
              !warned(r5, (const char *const[]){"straight line", NULL}) &&
              !warned(r5, (const char *const[]){"rank", NULL}) && !warned(r5, (const char *const[]){"crosses", NULL}));
    }

    /* result.json round trip: the same warnings after reading back */
    const phc_fit_result *rs[] = {r, r2, r3, r4};
    for (int k = 0; k < 4; ++k) {
        if (!rs[k])
            continue;
        char path[] = "/tmp/phc_verdict_XXXXXX";
        int fd = mkstemp(path);
        if (fd >= 0)
            close(fd);
        phc_error err;
        phc_fit_result *back = NULL;
        CHECK(phc_result_write_json(rs[k], path, &err) == PHC_OK);
        CHECK(phc_result_read_json(path, &back, &err) == PHC_OK);
        if (back) {
            CHECK(phc_fit_recheck(back, rs[k]->level, &err) == PHC_OK);
            int same = back->n_warnings == rs[k]->n_warnings;
            for (size_t i = 0; same && i < back->n_warnings; ++i)
                same = strcmp(back->warnings[i], rs[k]->warnings[i]) == 0;
            printf("result.json round trip of '%s': %zu warnings, the same after reading back: %s\n", rs[k]->name,
                   back->n_warnings, same ? "yes" : "no");
            CHECK(same);
        }
        phc_fit_result_free(back);
        remove(path);
    }
    phc_fit_result_free(r);
    phc_fit_result_free(r2);
    phc_fit_result_free(r3);
    phc_fit_result_free(r4);
    phc_fit_result_free(r5);
    return check_finish("verdict_baselines");
}
