/* Profile likelihood (fit/engine/profile.h) against exact answers:
 *   - a straight line y = a + b x (estimated sigma): profile intervals equal
 *     the exact t-intervals  theta_hat +- t_{n-2,0.975} se  (the profile of a
 *     linear model is exactly quadratic, and the F(1, n-p) threshold is t^2);
 *   - the same line with absolute sigmas: theta_hat +- z_{0.975} se;
 *   - y = a*b*x: only the product is identified, so the profile of a (b
 *     re-optimised) is flat and both sides are open to the bounds. */
#include <gsl/gsl_cdf.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "fit/config.h"
#include "fit/engine/profile.h"

static const double xs[] = {0.5, 1.1, 1.9, 3.2, 4.0, 5.3, 6.1, 7.4, 8.0, 9.6};
static const double ys[] = {1.92, 2.61, 3.95, 5.41, 7.02, 8.69, 9.4, 11.83, 12.21, 14.9};
#define N (sizeof xs / sizeof xs[0])

static int write_case(const char *dir, const char *expr, const char *params, const char *extra, char *cfg)
{
    char path[512];
    snprintf(path, sizeof path, "%s/d.csv", dir);
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "x,y\n");
    for (size_t i = 0; i < N; ++i)
        fprintf(f, "%.17g,%.17g\n", xs[i], ys[i]);
    fclose(f);
    snprintf(cfg, 512, "%s/c.yaml", dir);
    f = fopen(cfg, "w");
    if (!f)
        return -1;
    fprintf(f, "name: lin\nparameters:\n%sdatasets:\n  - kind: curve\n    name: d\n    file: d.csv\n    x: x\n"
               "    y: y\n    expression: \"%s\"\n%s",
            params, expr, extra);
    fclose(f);
    return 0;
}

/* Ordinary least squares of y = a + b x: estimates, standard errors (with
 * s^2 = RSS / (n - 2), or s^2 = 1 / sigma^2 weights for sigma given). */
static void ols(double sigma, double est[2], double se[2])
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (size_t i = 0; i < N; ++i) {
        sx += xs[i];
        sy += ys[i];
        sxx += xs[i] * xs[i];
        sxy += xs[i] * ys[i];
    }
    const double n = (double)N, det = n * sxx - sx * sx;
    est[1] = (n * sxy - sx * sy) / det;
    est[0] = (sy - est[1] * sx) / n;
    double rss = 0;
    for (size_t i = 0; i < N; ++i) {
        const double r = ys[i] - est[0] - est[1] * xs[i];
        rss += r * r;
    }
    const double s2 = sigma > 0 ? sigma * sigma : rss / (n - 2);
    se[0] = sqrt(s2 * sxx / det);
    se[1] = sqrt(s2 * n / det);
}

static void run_linear(const char *dir, int absolute)
{
    char cfg[512];
    const double sigma = absolute ? 0.3 : 0;
    char extra[256];
    snprintf(extra, sizeof extra, "%s", absolute ? "    sigma: 0.3\nreport:\n  absolute_sigma: true\n" : "");
    CHECK(write_case(dir, "a + b*x", "  a: {value: 1}\n  b: {value: 1}\n", extra, cfg) == 0);
    phc_problem *pb = NULL;
    phc_error err;
    phc_error_clear(&err);
    if (phc_config_load(cfg, &pb, &err)) {
        fprintf(stderr, "load: %s\n", err.message);
        CHECK(0);
        return;
    }
    phc_profile_options opt = phc_profile_options_default();
    phc_profile_result *res = NULL;
    const int rc = phc_profile_run(pb, NULL, NULL, &opt, &res, &err);
    CHECK(rc == PHC_OK);
    if (rc) {
        fprintf(stderr, "profile: %s\n", err.message);
        phc_problem_free(pb);
        return;
    }
    double est[2], se[2];
    ols(sigma, est, se);
    const double q = absolute ? gsl_cdf_ugaussian_Pinv(0.975) : gsl_cdf_tdist_Pinv(0.975, (double)N - 2);
    printf("linear (%s sigma): threshold on delta cost %.10g\n", absolute ? "absolute" : "estimated",
           res->threshold);
    CHECK(res->n_profiles == 2);
    for (size_t k = 0; k < res->n_profiles && k < 2; ++k) {
        const phc_profile *p = &res->profiles[k];
        const double lo = est[k] - q * se[k], hi = est[k] + q * se[k];
        printf("  %s: profile [%.12g, %.12g]  exact %s [%.12g, %.12g]  rel. diff %.2e %.2e  (%zu points, %zu "
               "fits)\n",
               pb->params[p->param].name, p->lo, p->hi, absolute ? "z" : "t", lo, hi, fabs(p->lo - lo) / fabs(lo),
               fabs(p->hi - hi) / fabs(hi), p->n, p->inner_fits);
        CHECK(p->lo_end == PHC_PROFILE_CROSSED && p->hi_end == PHC_PROFILE_CROSSED);
        CHECK_NEAR(p->lo, lo, 0, 1e-6);
        CHECK_NEAR(p->hi, hi, 0, 1e-6);
        CHECK(!p->flat);
        CHECK(p->n >= 7);
        /* the points are sorted and delta is the exact parabola */
        for (size_t i = 0; i + 1 < p->n; ++i)
            CHECK(p->theta[i] < p->theta[i + 1]);
        double worst = 0;
        for (size_t i = 0; i < p->n; ++i) {
            const double z = (p->theta[i] - est[k]) / se[k];
            const double exact = absolute ? 0.5 * z * z : res->best_cost * z * z / ((double)N - 2);
            worst = fmax(worst, fabs(p->delta[i] - exact) / (res->threshold));
        }
        printf("     largest |delta - exact parabola| / threshold over the points: %.2e\n", worst);
        CHECK(worst < 1e-7);
    }
    phc_profile_result_free(res);
    phc_problem_free(pb);
}

static void run_product(const char *dir)
{
    char cfg[512];
    CHECK(write_case(dir, "a*b*x", "  a: {value: 1, lower: 0.1, upper: 10}\n  b: {value: 1, lower: 0.1, upper: 10}\n",
                     "", cfg) == 0);
    phc_problem *pb = NULL;
    phc_error err;
    phc_error_clear(&err);
    if (phc_config_load(cfg, &pb, &err)) {
        fprintf(stderr, "load: %s\n", err.message);
        CHECK(0);
        return;
    }
    phc_profile_options opt = phc_profile_options_default();
    phc_profile_result *res = NULL;
    const int rc = phc_profile_run(pb, NULL, NULL, &opt, &res, &err);
    CHECK(rc == PHC_OK);
    if (rc) {
        fprintf(stderr, "profile: %s\n", err.message);
        phc_problem_free(pb);
        return;
    }
    for (size_t k = 0; k < res->n_profiles; ++k) {
        const phc_profile *p = &res->profiles[k];
        double md = 0;
        for (size_t i = 0; i < p->n; ++i)
            md = fmax(md, p->delta[i]);
        printf("a*b*x: %s profile over [%.6g, %.6g], ends %d %d (1 = at bound), max delta %.3g (threshold %.6g), "
               "flat %d, %zu points\n",
               pb->params[p->param].name, p->lo, p->hi, (int)p->lo_end, (int)p->hi_end, md, res->threshold, p->flat,
               p->n);
        /* the product a*b = c_hat is reachable only while the other stays in
           [0.1, 10]: theta in [c_hat/10, 10] is flat, outside the cost rises */
        CHECK(p->flat || p->lo_end != PHC_PROFILE_CROSSED || p->hi_end != PHC_PROFILE_CROSSED);
    }
    phc_profile_result_free(res);
    phc_problem_free(pb);
}

/* The product with wide bounds: both sides flat and open to the bounds. */
static void run_product_wide(const char *dir)
{
    char cfg[512];
    CHECK(write_case(dir, "a*b*x", "  a: {value: 1, lower: 0.5, upper: 2}\n  b: {value: 1, lower: 0.01, upper: 100}\n",
                     "", cfg) == 0);
    phc_problem *pb = NULL;
    phc_error err;
    phc_error_clear(&err);
    if (phc_config_load(cfg, &pb, &err)) {
        fprintf(stderr, "load: %s\n", err.message);
        CHECK(0);
        return;
    }
    phc_profile_options opt = phc_profile_options_default();
    phc_profile_result *res = NULL;
    CHECK(phc_profile_run(pb, NULL, NULL, &opt, &res, &err) == PHC_OK);
    if (res) {
        const phc_profile *p = &res->profiles[0]; /* a: b can always compensate */
        double md = 0;
        for (size_t i = 0; i < p->n; ++i)
            md = fmax(md, p->delta[i]);
        printf("a*b*x, a in [0.5, 2], b in [0.01, 100]: a profile [%.6g, %.6g] ends %d %d, max delta %.3g, flat %d\n",
               p->lo, p->hi, (int)p->lo_end, (int)p->hi_end, md, p->flat);
        CHECK(p->lo_end == PHC_PROFILE_AT_BOUND && p->hi_end == PHC_PROFILE_AT_BOUND);
        CHECK(p->lo == 0.5 && p->hi == 2.0);
        CHECK(p->flat);
        CHECK(md < 1e-6 * res->threshold);
    }
    phc_profile_result_free(res);
    phc_problem_free(pb);
}

/* The product without bounds: every side open (the reach limit), both flat. */
static void run_product_unbounded(const char *dir)
{
    char cfg[512];
    CHECK(write_case(dir, "a*b*x", "  a: {value: 1}\n  b: {value: 1}\n", "", cfg) == 0);
    phc_problem *pb = NULL;
    phc_error err;
    phc_error_clear(&err);
    if (phc_config_load(cfg, &pb, &err)) {
        fprintf(stderr, "load: %s\n", err.message);
        CHECK(0);
        return;
    }
    phc_profile_options opt = phc_profile_options_default();
    phc_profile_result *res = NULL;
    CHECK(phc_profile_run(pb, NULL, NULL, &opt, &res, &err) == PHC_OK);
    for (size_t k = 0; res && k < res->n_profiles; ++k) {
        const phc_profile *p = &res->profiles[k];
        const double est = res->best[p->param];
        double md = 0;
        for (size_t i = 0; i < p->n; ++i)
            md = fmax(md, p->delta[i]);
        printf("a*b*x unbounded: %s = %.6g traced over [%.6g, %.6g] ends %d %d (2 = open), max delta %.3g, flat %d, "
               "%zu fits\n",
               pb->params[p->param].name, est, p->lo, p->hi, (int)p->lo_end, (int)p->hi_end, md, p->flat,
               p->inner_fits);
        CHECK(p->lo_end == PHC_PROFILE_OPEN && p->hi_end == PHC_PROFILE_OPEN);
        CHECK(p->flat);
        const double unit = fmax(fabs(est), 1.0);
        CHECK(est - p->lo > PHC_PROFILE_MAX_REACH * unit && p->hi - est > PHC_PROFILE_MAX_REACH * unit);
    }
    phc_profile_result_free(res);
    phc_problem_free(pb);
}

static void run_bad(const char *dir)
{
    char cfg[512];
    CHECK(write_case(dir, "a + b*x", "  a: {value: 1}\n  b: {value: 1}\n", "", cfg) == 0);
    phc_problem *pb = NULL;
    phc_error err;
    phc_error_clear(&err);
    if (phc_config_load(cfg, &pb, &err)) {
        CHECK(0);
        return;
    }
    phc_profile_options opt = phc_profile_options_default();
    phc_profile_result *res = NULL;
    opt.points = 2;
    CHECK(phc_profile_run(pb, NULL, NULL, &opt, &res, &err) == PHC_ERR_INPUT);
    printf("points = 2: %s\n", err.message);
    opt.points = 12;
    pb->params[0].fixed = pb->params[1].fixed = 1;
    CHECK(phc_profile_run(pb, NULL, NULL, &opt, &res, &err) == PHC_ERR_INPUT);
    printf("all fixed: %s\n", err.message);
    CHECK_STR_CONTAINS(err.message, "no free parameter");
    CHECK(res == NULL);
    phc_problem_free(pb);
}

int main(void)
{
    char dir[] = "/tmp/phc_profile_XXXXXX";
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    run_linear(dir, 0);
    run_linear(dir, 1);
    run_product(dir);
    run_product_wide(dir);
    run_product_unbounded(dir);
    run_bad(dir);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    return check_finish("profile");
}
