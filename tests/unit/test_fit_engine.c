/* End-to-end tests of the fitting engine: phc_config_load + phc_fit_run on
 * small CSV/YAML files written to a mkdtemp() directory, then
 * phc_result_write_json / phc_result_read_json / phc_fit_recheck.
 *
 *  (a) a straight line: values, standard errors, correlation, t-based 95%
 *      intervals, sensitivities and the collinearity index against the
 *      textbook OLS formulas computed here (t quantile from GSL);
 *  (b) two data sets sharing one parameter (one under another slot name):
 *      the stacked linear least-squares solution by GSL;
 *  (c) multi-start: `starts: 8` on a convex and on a multimodal problem;
 *  (d) a parameter ending on its lower bound: flagged and warned about, and
 *      the other parameter at its conditional optimum;
 *  (e) y = (a+b)*x: an undetermined combination and warnings, no crash;
 *  (f) sigmas: absolute_sigma gives s2 = 1; per-point sigma columns against
 *      GSL's weighted least squares;
 *  (g) result.json round trip and re-checking at other levels. */
#include <gsl/gsl_cdf.h>
#include <gsl/gsl_multifit.h>
#include <glob.h>
#include <jansson.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "fit/config.h"
#include "fit/engine/fit.h"
#include "fit/result_json.h"

static char tmp_dir[] = "/tmp/phc_test_fit_engine_XXXXXX";
static char *created[64];
static size_t n_created;

static const char *path_in(const char *name)
{
    static char buf[4][512];
    static int which;
    which = (which + 1) % 4;
    snprintf(buf[which], sizeof buf[which], "%s/%s", tmp_dir, name);
    return buf[which];
}

static void remember(const char *path)
{
    for (size_t i = 0; i < n_created; ++i)
        if (strcmp(created[i], path) == 0)
            return;
    if (n_created < sizeof created / sizeof created[0])
        created[n_created++] = strdup(path);
}

static void write_text(const char *name, const char *fmt, ...)
{
    const char *path = path_in(name);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    va_list ap;
    va_start(ap, fmt);
    vfprintf(f, fmt, ap);
    va_end(ap);
    fclose(f);
    remember(path);
}

/* CSV with columns named in `header` ("x,y" or "x,y,s"), ncol values per row. */
static void write_csv(const char *name, const char *header, size_t n, size_t ncol, const double *const *cols)
{
    const char *path = path_in(name);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fprintf(f, "%s\n", header);
    for (size_t i = 0; i < n; ++i)
        for (size_t c = 0; c < ncol; ++c)
            fprintf(f, "%.17g%s", cols[c][i], c + 1 < ncol ? "," : "\n");
    fclose(f);
    remember(path);
}

/* Loads the config and fits it; NULL (and a failed check) on error. */
static phc_fit_result *fit_config(const char *name)
{
    phc_problem *pb = NULL;
    phc_fit_result *res = NULL;
    phc_error err;
    phc_error_clear(&err);
    int rc = phc_config_load(path_in(name), &pb, &err);
    if (rc != PHC_OK) {
        fprintf(stderr, "%s: %s\n", name, err.message);
        CHECK(rc == PHC_OK);
        return NULL;
    }
    rc = phc_fit_run(pb, NULL, NULL, &res, &err);
    if (rc != PHC_OK)
        fprintf(stderr, "%s: fit: %s\n", name, err.message);
    CHECK(rc == PHC_OK);
    phc_problem_free(pb);
    return res;
}

static const phc_param_result *param(const phc_fit_result *res, const char *name)
{
    for (size_t i = 0; res && i < res->n_params; ++i)
        if (strcmp(res->params[i].name, name) == 0)
            return &res->params[i];
    fprintf(stderr, "no parameter '%s' in the result\n", name);
    CHECK(!"parameter missing");
    static phc_param_result none;
    none.value = none.stderr_ = none.ci_lo = none.ci_hi = NAN;
    return &none;
}

static int any_warning(const phc_fit_result *res, const char *a, const char *b)
{
    for (size_t i = 0; i < res->n_warnings; ++i)
        if (strstr(res->warnings[i], a) && (!b || strstr(res->warnings[i], b)))
            return 1;
    return 0;
}

static void print_warnings(const char *what, const phc_fit_result *res)
{
    for (size_t i = 0; i < res->n_warnings; ++i)
        fprintf(stderr, "  %s warning: %s\n", what, res->warnings[i]);
}

/* ---- (a) the straight line ------------------------------------------------------ */

#define NL 15
static double lx[NL], ly[NL];

static void make_line(void)
{
    for (size_t i = 0; i < NL; ++i) {
        lx[i] = 1.0 + 0.5 * (double)i;
        ly[i] = 1.5 + 0.8 * lx[i] + 0.2 * sin(2.1 * (double)i + 0.4);
    }
    const double *cols[2] = {lx, ly};
    write_csv("line.csv", "x,y", NL, 2, cols);
}

typedef struct ols {
    double a, b, se_a, se_b, corr, rss, s2, xm, sxx, syy;
} ols;

static ols line_ols(const double *x, const double *y, size_t n)
{
    ols o;
    double sx = 0, sy = 0;
    for (size_t i = 0; i < n; ++i) {
        sx += x[i];
        sy += y[i];
    }
    o.xm = sx / (double)n;
    const double ym = sy / (double)n;
    double sxy = 0;
    o.sxx = o.syy = 0;
    for (size_t i = 0; i < n; ++i) {
        o.sxx += (x[i] - o.xm) * (x[i] - o.xm);
        o.syy += (y[i] - ym) * (y[i] - ym);
        sxy += (x[i] - o.xm) * (y[i] - ym);
    }
    o.b = sxy / o.sxx;
    o.a = ym - o.b * o.xm;
    o.rss = 0;
    for (size_t i = 0; i < n; ++i) {
        const double e = y[i] - o.a - o.b * x[i];
        o.rss += e * e;
    }
    o.s2 = o.rss / (double)(n - 2);
    o.se_b = sqrt(o.s2 / o.sxx);
    o.se_a = sqrt(o.s2 * (1.0 / (double)n + o.xm * o.xm / o.sxx));
    o.corr = -o.xm / sqrt(o.xm * o.xm + o.sxx / (double)n);
    return o;
}

static void test_line(void)
{
    write_text("line.yaml",
               "name: line\n"
               "parameters:\n"
               "  a: {value: 0}\n"
               "  b: {value: 1, unit: \"g h-1\"}\n"
               "datasets:\n"
               "  - kind: curve\n"
               "    name: balance\n"
               "    file: line.csv\n"
               "    x: x\n"
               "    y: y\n"
               "    expression: \"a + b*x\"\n");
    phc_fit_result *res = fit_config("line.yaml");
    if (!res)
        return;
    const ols o = line_ols(lx, ly, NL);
    const phc_param_result *a = param(res, "a"), *b = param(res, "b");
    CHECK(strcmp(res->name, "line") == 0);
    CHECK(res->summary.outcome == PHC_NLS_CONVERGED);
    CHECK(res->n_obs == NL && res->n_free == 2 && res->dof == NL - 2);
    CHECK(res->starts == 1 && res->starts_at_best == 1 && res->rescue_starts == 0);
    CHECK_NEAR(a->value, o.a, 1e-13, 1e-11);
    CHECK_NEAR(b->value, o.b, 1e-13, 1e-11);
    CHECK_NEAR(res->rss, o.rss, 0, 1e-11);
    CHECK_NEAR(res->wrss, o.rss, 0, 1e-11);
    CHECK_NEAR(res->cost, 0.5 * o.rss, 0, 1e-11);
    CHECK_NEAR(res->s2, o.s2, 0, 1e-11);
    CHECK(res->absolute_sigma == 0);
    CHECK_NEAR(a->stderr_, o.se_a, 0, 1e-9);
    CHECK_NEAR(b->stderr_, o.se_b, 0, 1e-9);
    /* 95% interval with the t quantile of dof = n - 2 (not the normal 1.96) */
    const double t = gsl_cdf_tdist_Pinv(0.975, (double)(NL - 2));
    CHECK(t > 2.1 && t < 2.2); /* t(0.975, 13) = 2.160 */
    CHECK_NEAR(a->ci_lo, o.a - t * o.se_a, 1e-12, 1e-9);
    CHECK_NEAR(a->ci_hi, o.a + t * o.se_a, 1e-12, 1e-9);
    CHECK_NEAR(b->ci_lo, o.b - t * o.se_b, 1e-12, 1e-9);
    CHECK_NEAR(b->ci_hi, o.b + t * o.se_b, 1e-12, 1e-9);
    CHECK_NEAR((b->ci_hi - b->ci_lo) / (2 * b->stderr_), t, 0, 1e-12);
    CHECK(a->fixed == 0 && a->at_bound == 0 && b->at_bound == 0);
    CHECK(a->start == 0 && b->start == 1);
    CHECK(b->unit && strcmp(b->unit, "g h-1") == 0);
    CHECK(a->unit == NULL);
    /* correlation of a and b: -xm / sqrt(xm^2 + Sxx/n) */
    CHECK(res->rank == 2 && res->n_undetermined == 0);
    CHECK_NEAR(res->correlation[1], o.corr, 0, 1e-9);
    CHECK_NEAR(res->correlation[2], o.corr, 0, 1e-9);
    CHECK_NEAR(res->correlation[0], 1.0, 0, 1e-14);
    /* sensitivities S_ij = d yhat/d p_j * p_j / s: for b, x_i b / s; for a, a / s */
    const double s = sqrt(o.s2);
    double mx = 0, mx2 = 0;
    for (size_t i = 0; i < NL; ++i) {
        mx += lx[i] / NL;
        mx2 += lx[i] * lx[i] / NL;
    }
    CHECK_NEAR(b->sens_l1, mx * fabs(o.b) / s, 0, 1e-9);
    CHECK_NEAR(b->sens_l2, sqrt(mx2) * fabs(o.b) / s, 0, 1e-9);
    CHECK_NEAR(a->sens_l1, fabs(o.a) / s, 0, 1e-9);
    CHECK_NEAR(a->sens_l2, fabs(o.a) / s, 0, 1e-9);
    /* collinearity of {a, b}: columns 1 and x, cos = mean x / sqrt(mean x^2) */
    CHECK(res->sensitivity.n_sets == 1);
    if (res->sensitivity.n_sets == 1)
        CHECK_NEAR(res->sensitivity.sets[0].gamma, 1.0 / sqrt(1.0 - mx / sqrt(mx2)), 0, 1e-9);
    /* the data set */
    CHECK(res->n_datasets == 1);
    if (res->n_datasets == 1) {
        const phc_dataset_result *d = &res->datasets[0];
        CHECK(strcmp(d->name, "balance") == 0 && strcmp(d->kind, "curve") == 0);
        CHECK(d->n == NL && d->k == 2);
        CHECK_NEAR(d->goodness.rss, o.rss, 0, 1e-11);
        CHECK_NEAR(d->goodness.r2, 1.0 - o.rss / o.syy, 0, 1e-12);
        for (size_t i = 0; i < NL; ++i) {
            CHECK(d->x[i] == lx[i] && d->y[i] == ly[i]);
            CHECK_NEAR(d->yhat[i], o.a + o.b * lx[i], 1e-12, 1e-11);
            CHECK_NEAR(d->residual[i], ly[i] - d->yhat[i], 0, 0);
            CHECK_NEAR(d->std_residual[i], d->residual[i] / s, 1e-15, 1e-12);
        }
        CHECK(d->sigma == NULL);
        for (size_t c = 0; c < PHC_CHECK_COUNT; ++c) {
            CHECK(d->checks[c].name[0] != '\0');
            CHECK(!d->checks[c].applicable || (d->checks[c].p_value >= 0 && d->checks[c].p_value <= 1));
            CHECK(d->checks[c].pass == (!d->checks[c].applicable || d->checks[c].p_value >= 0.05));
        }
        CHECK(d->curve_n > 0 && d->curve_x[0] == lx[0] && d->curve_x[d->curve_n - 1] == lx[NL - 1]);
        if (d->curve_n > 0)
            CHECK_NEAR(d->curve_y[d->curve_n - 1], o.a + o.b * lx[NL - 1], 1e-12, 1e-11);
    }
    phc_fit_result_free(res);
}

/* ---- (b) joint fit ----------------------------------------------------------- */

#define N1 10
#define N2 8
static double j1x[N1], j1y[N1], j2x[N2], j2y[N2];

static void test_joint(phc_fit_result **keep)
{
    for (size_t i = 0; i < N1; ++i) {
        j1x[i] = (double)i;
        j1y[i] = 2.0 + 0.5 * j1x[i] + 0.1 * cos(1.3 * (double)i);
    }
    for (size_t i = 0; i < N2; ++i) {
        j2x[i] = 0.5 + (double)i;
        j2y[i] = 2.0 - 0.3 * j2x[i] + 0.1 * sin(2.7 * (double)i + 1.0);
    }
    const double *c1[2] = {j1x, j1y}, *c2[2] = {j2x, j2y};
    write_csv("joint1.csv", "x,y", N1, 2, c1);
    write_csv("joint2.csv", "t,v", N2, 2, c2);
    write_text("joint.yaml",
               "name: joint\n"
               "parameters:\n"
               "  a: 1\n"
               "  b: {value: 1}\n"
               "  c: {value: -1}\n"
               "datasets:\n"
               "  - kind: curve\n"
               "    name: first\n"
               "    file: joint1.csv\n"
               "    x: x\n"
               "    y: y\n"
               "    expression: \"a + b*x\"\n"
               "  - kind: curve\n"
               "    name: second\n"
               "    file: joint2.csv\n"
               "    x: t\n"
               "    y: v\n"
               "    expression: \"off + c*t\"\n"
               "    parameters: {off: a}\n");
    phc_fit_result *res = fit_config("joint.yaml");
    if (!res)
        return;
    /* stacked design: first rows (1, x, 0), second rows (1, 0, t) */
    gsl_matrix *X = gsl_matrix_calloc(N1 + N2, 3);
    gsl_vector *y = gsl_vector_alloc(N1 + N2), *coef = gsl_vector_alloc(3);
    gsl_matrix *cov = gsl_matrix_alloc(3, 3);
    for (size_t i = 0; i < N1; ++i) {
        gsl_matrix_set(X, i, 0, 1);
        gsl_matrix_set(X, i, 1, j1x[i]);
        gsl_vector_set(y, i, j1y[i]);
    }
    for (size_t i = 0; i < N2; ++i) {
        gsl_matrix_set(X, N1 + i, 0, 1);
        gsl_matrix_set(X, N1 + i, 2, j2x[i]);
        gsl_vector_set(y, N1 + i, j2y[i]);
    }
    double chisq;
    gsl_multifit_linear_workspace *w = gsl_multifit_linear_alloc(N1 + N2, 3);
    gsl_multifit_linear(X, y, coef, cov, &chisq, w);
    gsl_multifit_linear_free(w);
    /* gsl_multifit_linear's cov is already s2 (X'X)^-1, s2 = chisq / dof */
    CHECK(res->n_params == 3);           /* the shared parameter exists once */
    CHECK(res->n_free == 3 && res->n_obs == N1 + N2 && res->dof == N1 + N2 - 3);
    static const char *const names[3] = {"a", "b", "c"};
    for (size_t j = 0; j < 3; ++j) {
        const phc_param_result *p = param(res, names[j]);
        CHECK_NEAR(p->value, gsl_vector_get(coef, j), 1e-13, 1e-11);
        CHECK_NEAR(p->stderr_, sqrt(gsl_matrix_get(cov, j, j)), 0, 1e-9);
    }
    CHECK_NEAR(res->rss, chisq, 0, 1e-11);
    CHECK(res->n_datasets == 2);
    if (res->n_datasets == 2) {
        CHECK(strcmp(res->datasets[0].name, "first") == 0 && res->datasets[0].n == N1);
        CHECK(strcmp(res->datasets[1].name, "second") == 0 && res->datasets[1].n == N2);
        CHECK(res->datasets[0].k == 2 && res->datasets[1].k == 2); /* free parameters each uses */
        double r1 = 0, r2 = 0;
        for (size_t i = 0; i < N1; ++i) {
            const double e = j1y[i] - gsl_vector_get(coef, 0) - gsl_vector_get(coef, 1) * j1x[i];
            r1 += e * e;
        }
        for (size_t i = 0; i < N2; ++i) {
            const double e = j2y[i] - gsl_vector_get(coef, 0) - gsl_vector_get(coef, 2) * j2x[i];
            r2 += e * e;
        }
        CHECK_NEAR(res->datasets[0].goodness.rss, r1, 0, 1e-10);
        CHECK_NEAR(res->datasets[1].goodness.rss, r2, 0, 1e-10);
        CHECK(strcmp(res->datasets[1].x_label, "t") == 0 && strcmp(res->datasets[1].y_label, "v") == 0);
    }
    gsl_matrix_free(X);
    gsl_vector_free(y);
    gsl_vector_free(coef);
    gsl_matrix_free(cov);
    *keep = res;
}

/* ---- (c) multi-start ---------------------------------------------------------- */

static void test_multistart(void)
{
    write_text("line8.yaml",
               "parameters:\n"
               "  a: {value: 0, lower: -10, upper: 10}\n"
               "  b: {value: 1, lower: -5, upper: 5}\n"
               "datasets:\n"
               "  - {kind: curve, file: line.csv, x: x, y: y, expression: \"a + b*x\"}\n"
               "solver: {starts: 8}\n");
    phc_fit_result *res = fit_config("line8.yaml");
    if (res) {
        const ols o = line_ols(lx, ly, NL);
        CHECK(strcmp(res->name, "line8") == 0); /* default name: the config's stem */
        CHECK(res->starts == 8);
        CHECK(res->starts_at_best >= 1 && res->starts_at_best <= 8);
        CHECK(res->starts_at_best == 8); /* a convex problem: every start finds the optimum */
        CHECK(res->rescue_starts == 0);
        CHECK_NEAR(param(res, "a")->value, o.a, 1e-13, 1e-11);
        CHECK_NEAR(param(res, "b")->value, o.b, 1e-13, 1e-11);
        CHECK(res->total_time >= res->summary.wall_time);
        phc_fit_result_free(res);
    }

    /* y = sin(w x) with w = 2.7: many local minima in w; from w = 0.5 alone the
     * solver stops in a wrong one, a Sobol start inside [0.1, 6] finds 2.7 */
    enum { NS = 40 };
    double sx[NS], sy[NS];
    for (size_t i = 0; i < NS; ++i) {
        sx[i] = 0.15 * (double)i;
        sy[i] = sin(2.7 * sx[i]);
    }
    const double *cols[2] = {sx, sy};
    write_csv("sine.csv", "x,y", NS, 2, cols);
    for (int starts = 1; starts <= 8; starts += 7) {
        write_text("sine.yaml",
                   "parameters:\n"
                   "  w: {value: 0.5, lower: 0.1, upper: 6}\n"
                   "datasets:\n"
                   "  - {kind: curve, file: sine.csv, x: x, y: y, expression: \"sin(w*x)\"}\n"
                   "solver: {starts: %d, rescue_starts: 0}\n",
                   starts);
        res = fit_config("sine.yaml");
        if (!res)
            continue;
        const double w = param(res, "w")->value;
        printf("sine, starts %d: w = %.15g, starts at best %zu of %zu\n", starts, w, res->starts_at_best,
               res->starts);
        CHECK(res->starts == (size_t)starts);
        CHECK(res->starts_at_best >= 1 && res->starts_at_best <= (size_t)starts);
        if (starts == 1)
            CHECK(fabs(w - 2.7) > 0.1); /* the single start really is trapped */
        else {
            CHECK_NEAR(w, 2.7, 0, 1e-9);
            CHECK(res->starts_at_best < 8); /* not every start reached it */
            CHECK(res->cost < 1e-20);
        }
        phc_fit_result_free(res);
    }
}

/* ---- (d) a parameter at its bound ---------------------------------------------- */

static void test_at_bound(void)
{
    enum { NB = 12 };
    double bx[NB], by[NB];
    double ym = 0;
    for (size_t i = 0; i < NB; ++i) {
        bx[i] = (double)i;
        by[i] = 3.0 - 0.4 * bx[i] + 0.05 * cos(1.9 * (double)i);
        ym += by[i] / NB;
    }
    const double *cols[2] = {bx, by};
    write_csv("bound.csv", "x,y", NB, 2, cols);
    write_text("bound.yaml",
               "parameters:\n"
               "  a: {value: 1}\n"
               "  b: {value: 0.5, lower: 0}\n"
               "datasets:\n"
               "  - {kind: curve, file: bound.csv, x: x, y: y, expression: \"a + b*x\"}\n");
    phc_fit_result *res = fit_config("bound.yaml");
    if (!res)
        return;
    const phc_param_result *a = param(res, "a"), *b = param(res, "b");
    CHECK(b->value == 0.0); /* the unconstrained slope is -0.4 */
    CHECK(b->at_bound == -1);
    CHECK(a->at_bound == 0);
    CHECK(any_warning(res, "'b'", "lower bound"));
    CHECK(!any_warning(res, "'a'", "bound"));
    /* with b = 0 the best a is the mean of y (to the bare solver's ~8 digits:
     * the Gauss-Newton polish of fit.c stops at a bound) */
    if (!(fabs(a->value - ym) <= 1e-7 * fabs(ym)))
        fprintf(stderr, "at bound: a = %.17g, conditional optimum mean(y) = %.17g\n", a->value, ym);
    CHECK_NEAR(a->value, ym, 0, 1e-7);
    phc_fit_result_free(res);
}

/* ---- (e) rank deficiency ----------------------------------------------------------- */

static void test_rank_deficient(phc_fit_result **keep)
{
    enum { NR = 9 };
    double rx[NR], ry[NR];
    double sxy = 0, sxx = 0;
    for (size_t i = 0; i < NR; ++i) {
        rx[i] = 0.5 + (double)i;
        ry[i] = 1.3 * rx[i] + 0.1 * sin(3.3 * (double)i);
        sxy += rx[i] * ry[i];
        sxx += rx[i] * rx[i];
    }
    const double *cols[2] = {rx, ry};
    write_csv("sum.csv", "x,y", NR, 2, cols);
    write_text("sum.yaml",
               "parameters:\n"
               "  a: 1\n"
               "  b: 1\n"
               "datasets:\n"
               "  - {kind: curve, file: sum.csv, x: x, y: y, expression: \"(a+b)*x\"}\n");
    phc_fit_result *res = fit_config("sum.yaml");
    if (!res)
        return;
    const phc_param_result *a = param(res, "a"), *b = param(res, "b");
    CHECK_NEAR(a->value + b->value, sxy / sxx, 0, 1e-9); /* the sum is determined */
    CHECK(res->rank == 1);
    CHECK(res->n_undetermined == 1);
    if (res->n_undetermined == 1) {
        if (strcmp(res->undetermined[0], "0.707 a - 0.707 b") != 0)
            fprintf(stderr, "undetermined: '%s'\n", res->undetermined[0]);
        CHECK(strcmp(res->undetermined[0], "0.707 a - 0.707 b") == 0);
    }
    CHECK(isnan(a->stderr_) && isnan(b->stderr_));
    CHECK(isnan(a->ci_lo) && isnan(b->ci_hi));
    CHECK(isnan(res->correlation[1]));
    CHECK(isinf(res->condition));
    CHECK(any_warning(res, "cannot determine", "0.707 a - 0.707 b"));
    CHECK(any_warning(res, "collinear", "{a, b}"));
    CHECK(isinf(res->sensitivity.max_gamma[2]));
    *keep = res;
}

/* ---- (f) sigmas ---------------------------------------------------------------------- */

static void test_sigmas(void)
{
    const ols o = line_ols(lx, ly, NL);
    const double sigma = 0.2;
    for (int absolute = 0; absolute < 2; ++absolute) {
        write_text("sig.yaml",
                   "parameters: {a: 0, b: 1}\n"
                   "datasets:\n"
                   "  - {kind: curve, file: line.csv, x: x, y: y, expression: \"a + b*x\", sigma: %g}\n"
                   "report: {absolute_sigma: %s}\n",
                   sigma, absolute ? "true" : "false");
        phc_fit_result *res = fit_config("sig.yaml");
        if (!res)
            continue;
        const phc_param_result *b = param(res, "b");
        CHECK_NEAR(b->value, o.b, 1e-13, 1e-11);
        CHECK_NEAR(res->wrss, o.rss / (sigma * sigma), 0, 1e-10);
        CHECK_NEAR(res->rss, o.rss, 0, 1e-10);
        CHECK(res->absolute_sigma == absolute);
        if (absolute) {
            CHECK(res->s2 == 1.0);
            CHECK_NEAR(b->stderr_, sigma / sqrt(o.sxx), 0, 1e-9); /* the sigma taken at its word */
        } else {
            CHECK_NEAR(res->s2, o.rss / (sigma * sigma) / (NL - 2), 0, 1e-10);
            CHECK_NEAR(b->stderr_, o.se_b, 0, 1e-9); /* a common sigma cancels out */
        }
        CHECK(res->datasets[0].sigma != NULL && res->datasets[0].sigma[3] == sigma);
        phc_fit_result_free(res);
    }

    /* per-point sigmas from a column: weighted least squares by GSL */
    double s[NL];
    for (size_t i = 0; i < NL; ++i)
        s[i] = 0.1 + 0.05 * (double)(i % 4);
    const double *cols[3] = {lx, ly, s};
    write_csv("wline.csv", "x,y,s", NL, 3, cols);
    gsl_matrix *X = gsl_matrix_alloc(NL, 2), *cov = gsl_matrix_alloc(2, 2);
    gsl_vector *w = gsl_vector_alloc(NL), *y = gsl_vector_alloc(NL), *coef = gsl_vector_alloc(2);
    for (size_t i = 0; i < NL; ++i) {
        gsl_matrix_set(X, i, 0, 1);
        gsl_matrix_set(X, i, 1, lx[i]);
        gsl_vector_set(y, i, ly[i]);
        gsl_vector_set(w, i, 1.0 / (s[i] * s[i]));
    }
    double chisq;
    gsl_multifit_linear_workspace *ws = gsl_multifit_linear_alloc(NL, 2);
    gsl_multifit_wlinear(X, w, y, coef, cov, &chisq, ws); /* cov = (X'WX)^-1 */
    gsl_multifit_linear_free(ws);
    for (int absolute = 0; absolute < 2; ++absolute) {
        write_text("wsig.yaml",
                   "parameters: {a: 0, b: 1}\n"
                   "datasets:\n"
                   "  - {kind: curve, file: wline.csv, x: x, y: y, expression: \"a + b*x\", sigma: s}\n"
                   "report: {absolute_sigma: %s}\n",
                   absolute ? "true" : "false");
        phc_fit_result *res = fit_config("wsig.yaml");
        if (!res)
            continue;
        const double f = absolute ? 1.0 : chisq / (NL - 2);
        CHECK_NEAR(res->wrss, chisq, 0, 1e-10);
        CHECK_NEAR(res->s2, f, 0, absolute ? 0 : 1e-10);
        CHECK_NEAR(param(res, "a")->value, gsl_vector_get(coef, 0), 1e-13, 1e-11);
        CHECK_NEAR(param(res, "b")->value, gsl_vector_get(coef, 1), 1e-13, 1e-11);
        CHECK_NEAR(param(res, "a")->stderr_, sqrt(f * gsl_matrix_get(cov, 0, 0)), 0, 1e-9);
        CHECK_NEAR(param(res, "b")->stderr_, sqrt(f * gsl_matrix_get(cov, 1, 1)), 0, 1e-9);
        CHECK_NEAR(res->datasets[0].goodness.reduced_chi2, chisq / (NL - 2), 0, 1e-10);
        phc_fit_result_free(res);
    }
    gsl_matrix_free(X);
    gsl_matrix_free(cov);
    gsl_vector_free(w);
    gsl_vector_free(y);
    gsl_vector_free(coef);
}

/* ---- (g) result.json round trip and re-checks --------------------------------------- */

static size_t failed_check_warnings(const phc_fit_result *res)
{
    size_t n = 0;
    for (size_t i = 0; i < res->n_warnings; ++i)
        n += strstr(res->warnings[i], "check failed") != NULL;
    return n;
}

static size_t failing_checks(const phc_fit_result *res)
{
    size_t n = 0;
    for (size_t d = 0; d < res->n_datasets; ++d)
        for (size_t c = 0; c < PHC_CHECK_COUNT; ++c)
            n += res->datasets[d].checks[c].applicable && !res->datasets[d].checks[c].pass;
    return n;
}

static int same_number(double a, double b, double rel)
{
    if (isnan(a) || isnan(b))
        return isnan(a) && isnan(b);
    return fabs(a - b) <= rel * fabs(b);
}

static void test_round_trip(const phc_fit_result *res, const char *file)
{
    const char *path = path_in(file);
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_result_write_json(res, path, &err) == PHC_OK);
    remember(path);
    char tmp[600];
    glob_t gl;
    snprintf(tmp, sizeof tmp, "%s.tmp*", path);
    CHECK(glob(tmp, 0, NULL, &gl) == GLOB_NOMATCH); /* the temporary name was renamed away */
    globfree(&gl);
    phc_fit_result *back = NULL;
    CHECK(phc_result_read_json(path, &back, &err) == PHC_OK);
    if (!back) {
        fprintf(stderr, "%s\n", err.message);
        return;
    }
    CHECK(strcmp(back->name, res->name) == 0);
    CHECK(back->summary.outcome == res->summary.outcome);
    CHECK(back->n_params == res->n_params && back->n_free == res->n_free);
    CHECK(back->dof == res->dof && back->n_obs == res->n_obs);
    CHECK(same_number(back->cost, res->cost, 1e-15) && same_number(back->rss, res->rss, 1e-15));
    CHECK(same_number(back->s2, res->s2, 1e-15));
    CHECK(back->rank == res->rank && back->n_undetermined == res->n_undetermined);
    for (size_t i = 0; i < back->n_undetermined && i < res->n_undetermined; ++i)
        CHECK(strcmp(back->undetermined[i], res->undetermined[i]) == 0);
    for (size_t i = 0; i < res->n_params; ++i) {
        const phc_param_result *p = &res->params[i], *q = param(back, p->name);
        CHECK(same_number(q->value, p->value, 1e-15));
        CHECK(same_number(q->stderr_, p->stderr_, 1e-15));
        CHECK(same_number(q->ci_lo, p->ci_lo, 1e-15) && same_number(q->ci_hi, p->ci_hi, 1e-15));
        CHECK(same_number(q->start, p->start, 1e-15));
        CHECK(same_number(q->sens_l1, p->sens_l1, 1e-15));
        CHECK(q->fixed == p->fixed && q->at_bound == p->at_bound);
        CHECK((q->unit == NULL) == (p->unit == NULL));
        if (q->unit && p->unit)
            CHECK(strcmp(q->unit, p->unit) == 0);
    }
    for (size_t a = 0; a < res->n_free; ++a)
        for (size_t b = 0; b < res->n_free; ++b) {
            /* stored in the writer's order of free parameters; compare by name */
            const char *na = res->params[res->free_index[a]].name, *nb = res->params[res->free_index[b]].name;
            size_t fa = back->n_free, fb = back->n_free;
            for (size_t f = 0; f < back->n_free; ++f) {
                if (strcmp(back->params[back->free_index[f]].name, na) == 0)
                    fa = f;
                if (strcmp(back->params[back->free_index[f]].name, nb) == 0)
                    fb = f;
            }
            CHECK(fa < back->n_free && fb < back->n_free);
            if (fa < back->n_free && fb < back->n_free)
                CHECK(same_number(back->correlation[fa * back->n_free + fb], res->correlation[a * res->n_free + b],
                                  1e-15));
        }
    CHECK(back->n_datasets == res->n_datasets);
    for (size_t d = 0; d < back->n_datasets && d < res->n_datasets; ++d) {
        const phc_dataset_result *x = &res->datasets[d], *y = &back->datasets[d];
        CHECK(strcmp(x->name, y->name) == 0 && strcmp(x->kind, y->kind) == 0 && x->n == y->n);
        for (size_t i = 0; i < x->n && i < y->n; ++i)
            CHECK(x->residual[i] == y->residual[i] && x->yhat[i] == y->yhat[i]);
        for (size_t c = 0; c < PHC_CHECK_COUNT; ++c) {
            const phc_check_result *cx = &x->checks[c], *cy = &y->checks[c];
            CHECK(strcmp(cx->name, cy->name) == 0);
            CHECK(cx->applicable == cy->applicable && cx->pass == cy->pass);
            if (!same_number(cy->p_value, cx->p_value, 1e-12))
                fprintf(stderr, "%s: check %s: p %.17g, read back %.17g\n", x->name, cx->name, cx->p_value,
                        cy->p_value);
            CHECK(same_number(cy->p_value, cx->p_value, 1e-12));
            CHECK(same_number(cy->statistic, cx->statistic, 1e-12));
        }
        CHECK(same_number(y->goodness.rmse, x->goodness.rmse, 1e-15));
        CHECK(same_number(y->goodness.aic, x->goodness.aic, 1e-15));
        /* the series (probes, leaves, ...) of the plots */
        CHECK((x->series == NULL) == (y->series == NULL) && x->n_series == y->n_series);
        for (size_t i = 0; x->series && y->series && i < x->n && i < y->n; ++i)
            CHECK(x->series[i] == y->series[i]);
        CHECK((x->series_names == NULL) == (y->series_names == NULL));
        for (size_t g = 0; x->series_names && y->series_names && g < x->n_series && g < y->n_series; ++g)
            CHECK(strcmp(x->series_names[g], y->series_names[g]) == 0);
        CHECK((x->series_title == NULL) == (y->series_title == NULL));
        if (x->series_title && y->series_title)
            CHECK(strcmp(x->series_title, y->series_title) == 0);
    }
    if (back->n_warnings != res->n_warnings) {
        print_warnings("written", res);
        print_warnings("read", back);
    }
    CHECK(back->n_warnings == res->n_warnings);
    for (size_t i = 0; i < back->n_warnings && i < res->n_warnings; ++i)
        CHECK(strcmp(back->warnings[i], res->warnings[i]) == 0);

    /* re-checks at other levels: pass flags follow p >= level, and the
     * verdict lists exactly the failing checks */
    static const double levels[] = {0.999, 0.5, 0.05, 1e-9};
    size_t prev_fail = SIZE_MAX;
    for (size_t l = 0; l < sizeof levels / sizeof levels[0]; ++l) {
        CHECK(phc_fit_recheck(back, levels[l], &err) == PHC_OK);
        CHECK(back->level == levels[l]);
        for (size_t d = 0; d < back->n_datasets; ++d)
            for (size_t c = 0; c < PHC_CHECK_COUNT; ++c) {
                const phc_check_result *ck = &back->datasets[d].checks[c];
                CHECK(ck->pass == (!ck->applicable || ck->p_value >= levels[l]));
                CHECK(same_number(ck->p_value, res->datasets[d].checks[c].p_value, 1e-12));
            }
        const size_t nf = failing_checks(back);
        CHECK(failed_check_warnings(back) == nf);
        CHECK(nf <= prev_fail); /* a lower level never fails more checks */
        prev_fail = nf;
        if (l == 0)
            CHECK(nf > 0); /* at 0.999 something fails: the re-check can fail */
        if (l == 3)
            CHECK(nf == 0);
    }
    /* back at the original level: the original verdict */
    CHECK(phc_fit_recheck(back, res->level, &err) == PHC_OK);
    CHECK(back->n_warnings == res->n_warnings);
    CHECK(failing_checks(back) == failing_checks(res));
    /* invalid levels */
    CHECK(phc_fit_recheck(back, 0.0, &err) == PHC_ERR_INVALID);
    CHECK(phc_fit_recheck(back, 1.0, &err) == PHC_ERR_INVALID);
    CHECK(phc_fit_recheck(back, NAN, &err) == PHC_ERR_INVALID);
    phc_fit_result_free(back);
}

/* A result.json whose series do not fit its data set: an error naming it. */
static void test_bad_series(const char *file)
{
    json_error_t jerr;
    json_t *root = json_load_file(path_in(file), 0, &jerr);
    json_t *series = json_object_get(json_array_get(json_object_get(root, "datasets"), 0), "series");
    CHECK(json_is_object(series));
    if (!json_is_object(series)) {
        json_decref(root);
        return;
    }
    json_object_set_new(series, "ids", json_pack("[i]", 0)); /* one id for many observations */
    const char *bad = path_in("bad_series.json");
    CHECK(json_dump_file(root, bad, 0) == 0);
    remember(bad);
    json_decref(root);
    phc_fit_result *res = NULL;
    phc_error err;
    CHECK(phc_result_read_json(bad, &res, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "datasets[0].series");
    CHECK(res == NULL);
}

static void test_read_errors(void)
{
    phc_fit_result *res = (phc_fit_result *)&res;
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_result_read_json(path_in("missing.json"), &res, &err) == PHC_ERR_IO);
    CHECK(res == NULL);
    CHECK_STR_CONTAINS(err.message, "missing.json");
    CHECK(phc_result_read_json(tmp_dir, &res, &err) != PHC_OK); /* a directory */
    write_text("broken.json", "{\n  \"name\": \"x\",\n  \"status\": \n}\n");
    CHECK(phc_result_read_json(path_in("broken.json"), &res, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "broken.json:");
    write_text("empty_obj.json", "{\"name\": \"x\", \"status\": \"converged\", \"termination\": \"\"}\n");
    CHECK(phc_result_read_json(path_in("empty_obj.json"), &res, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cost");
    CHECK(res == NULL);
}

/* ---- progress and cancellation ---------------------------------------------------- */

typedef struct progress_log {
    int calls, cancel_at, iterations, starts;
    const char *last;
} progress_log;

static int on_progress(const phc_progress *p, void *ud)
{
    progress_log *log = ud;
    CHECK(p->stage != NULL && (p->steps == 0 || (p->step >= 1 && p->step <= p->steps)));
    log->last = p->stage;
    if (p->iteration >= 0) {
        CHECK(isfinite(p->cost) && p->cost >= 0);
        log->iterations++;
    } else if (strcmp(p->stage, "start") == 0) {
        log->starts++;
    }
    return ++log->calls == log->cancel_at;
}

static void test_progress(void)
{
    phc_problem *pb = NULL;
    phc_error err;
    CHECK(phc_config_load(path_in("line8.yaml"), &pb, &err) == PHC_OK);
    if (!pb)
        return;
    progress_log log = {0};
    phc_fit_result *res = NULL;
    CHECK(phc_fit_run(pb, on_progress, &log, &res, &err) == PHC_OK);
    /* every start announced, the solver's iterations passed on, the
     * uncertainty stage last */
    CHECK(res && log.starts == (int)res->starts && log.iterations >= 1);
    CHECK(log.last && strcmp(log.last, "uncertainty") == 0);
    phc_fit_result_free(res);
    res = NULL;
    progress_log cancel = {0, 3, 0, 0, NULL};
    phc_error_clear(&err);
    CHECK(phc_fit_run(pb, on_progress, &cancel, &res, &err) != PHC_OK);
    CHECK(res == NULL);
    CHECK_STR_CONTAINS(err.message, "cancel");
    phc_problem_free(pb);
}

int main(void)
{
    if (!mkdtemp(tmp_dir)) {
        perror("mkdtemp");
        return 1;
    }
    make_line();
    test_line();
    phc_fit_result *joint = NULL, *sum = NULL;
    test_joint(&joint);
    test_multistart();
    test_at_bound();
    test_rank_deficient(&sum);
    test_sigmas();
    if (joint && joint->n_datasets > 1) {
        /* series written and read back: the first data set in two series
           with names and a title, the second with ids only */
        for (size_t k = 0; k < 2; ++k) {
            phc_dataset_result *d = &joint->datasets[k];
            d->series = malloc(d->n * sizeof *d->series);
            for (size_t i = 0; d->series && i < d->n; ++i)
                d->series[i] = k == 0 ? i % 2 : i / 3;
            d->n_series = k == 0 ? 2 : (d->n - 1) / 3 + 1;
        }
        phc_dataset_result *d = &joint->datasets[0];
        d->series_names = calloc(2, sizeof *d->series_names);
        if (d->series_names) {
            d->series_names[0] = strdup("even, 0.10 m");
            d->series_names[1] = strdup("odd \"#2\"");
        }
        d->series_title = strdup("probe");
    }
    if (joint) {
        test_round_trip(joint, "joint.json");
        test_bad_series("joint.json");
    }
    if (sum)
        test_round_trip(sum, "sum.json");
    test_read_errors();
    test_progress();
    phc_fit_result_free(joint);
    phc_fit_result_free(sum);
    for (size_t i = 0; i < n_created; ++i) {
        unlink(created[i]);
        free(created[i]);
    }
    CHECK(rmdir(tmp_dir) == 0);
    return check_finish("test_fit_engine");
}
