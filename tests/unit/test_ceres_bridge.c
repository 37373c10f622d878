/* Unit tests of fit/engine/ceres_bridge.cc through the phc_nls_* C API with small C
 * callbacks (no data sets, no configs).
 *
 *  - linear least squares y = a + b x: the exact normal-equations solution,
 *    the final cost, with Levenberg–Marquardt, dogleg and two threads;
 *  - bounds (an optimum outside the box ends on the bound, and the free
 *    parameter takes its exact conditional optimum), a fixed parameter;
 *  - robust losses: each of huber, cauchy, soft_l1, arctan pulls a location
 *    estimate back from a gross outlier; the solution satisfies the loss's
 *    own stationarity condition (which pins down the documented rho, incl.
 *    the arctan scale convention); Huber has a closed form;
 *  - numerical (central, Ridders) vs analytic derivatives: same optimum;
 *  - callbacks: > 0 (or a NaN residual) in part of the domain is avoided,
 *    < 0 stops the solve with an error, never a crash;
 *  - invalid arguments give errors with messages;
 *  - phc_nls_evaluate: residuals, cost with and without losses, and the
 *    Jacobian (analytic, central, Ridders; with parameter scales and fixed
 *    parameters) against numerical derivatives computed here;
 *  - an analytic block's accepted candidates are served from the
 *    candidate's evaluation (fewer callback runs than Ceres's residual plus
 *    Jacobian evaluations, same optimum);
 *  - one data set over free, unbounded parameters (one Ceres parameter
 *    block) solves bitwise as with blocks of size 1. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/engine/ceres_bridge.h"

/* The trust-region solver accepts a step only when the cost decreases; near
 * the optimum a parameter error e changes the cost by O(e^2), below the
 * cost's round-off once e ~ 1e-8 relative, so a bare phc_nls_solve stops
 * with about 8 correct digits however tight its tolerances (fit.c polishes
 * afterwards with Gauss-Newton steps).  Checks of the bare solver's optimum
 * allow that much. */
#define SOLVER_TOL 1e-7

/* ---- data and callbacks ------------------------------------------------------ */

#define NLIN 12
typedef struct line_data {
    size_t n;
    double x[64], y[64];
} line_data;

static void make_line(line_data *d)
{
    d->n = NLIN;
    for (size_t i = 0; i < d->n; ++i) {
        d->x[i] = 0.5 * (double)i - 1.0;
        d->y[i] = 2.0 + 0.75 * d->x[i] + 0.1 * sin(3.0 * (double)i + 1.0); /* deterministic "noise" */
    }
}

/* r_i = y_i - (a + b x_i); params = (a, b) */
static int line_residuals(const double *p, double *r, double *jac, void *ud)
{
    const line_data *d = ud;
    for (size_t i = 0; i < d->n; ++i) {
        r[i] = d->y[i] - (p[0] + p[1] * d->x[i]);
        if (jac) {
            jac[2 * i] = -1.0;
            jac[2 * i + 1] = -d->x[i];
        }
    }
    return 0;
}

/* Exact least-squares line by the normal equations. */
static void line_exact(const line_data *d, double *a, double *b)
{
    double sx = 0, sy = 0;
    for (size_t i = 0; i < d->n; ++i) {
        sx += d->x[i];
        sy += d->y[i];
    }
    const double xm = sx / (double)d->n, ym = sy / (double)d->n;
    double sxx = 0, sxy = 0;
    for (size_t i = 0; i < d->n; ++i) {
        sxx += (d->x[i] - xm) * (d->x[i] - xm);
        sxy += (d->x[i] - xm) * (d->y[i] - ym);
    }
    *b = sxy / sxx;
    *a = ym - *b * xm;
}

static phc_nls *line_problem(line_data *d, phc_derivatives derivs)
{
    phc_nls *nls = phc_nls_new(2);
    const size_t idx[2] = {0, 1};
    phc_error err;
    CHECK(nls != NULL);
    if (!nls)
        return NULL;
    CHECK(phc_nls_add_block(nls, d->n, idx, 2, line_residuals, derivs, PHC_LOSS_NONE, 1.0, d, &err) == PHC_OK);
    return nls;
}

/* ---- linear least squares ------------------------------------------------------ */

static void test_linear(void)
{
    line_data d;
    make_line(&d);
    double a_ex, b_ex;
    line_exact(&d, &a_ex, &b_ex);
    double rss = 0;
    for (size_t i = 0; i < d.n; ++i) {
        const double e = d.y[i] - a_ex - b_ex * d.x[i];
        rss += e * e;
    }
    for (int variant = 0; variant < 3; ++variant) {
        phc_nls *nls = line_problem(&d, PHC_DERIV_ANALYTIC);
        if (!nls)
            return;
        CHECK(phc_nls_residual_count(nls) == d.n);
        phc_nls_options o = phc_nls_options_default();
        if (variant == 1)
            o.method = PHC_DOGLEG;
        if (variant == 2)
            o.num_threads = 2;
        double x[2] = {0, 0};
        double start_cost = 0;
        for (size_t i = 0; i < d.n; ++i)
            start_cost += 0.5 * d.y[i] * d.y[i];
        phc_nls_summary s;
        phc_error err;
        phc_error_clear(&err);
        CHECK(phc_nls_solve(nls, &o, x, &s, &err) == PHC_OK);
        CHECK(s.outcome == PHC_NLS_CONVERGED);
        CHECK_NEAR(x[0], a_ex, 1e-13, 1e-12);
        CHECK_NEAR(x[1], b_ex, 1e-13, 1e-12);
        CHECK_NEAR(s.final_cost, 0.5 * rss, 0, 1e-10);
        CHECK_NEAR(s.initial_cost, start_cost, 0, 1e-14);
        CHECK(s.iterations >= 1 && s.residual_evaluations >= 2 && s.jacobian_evaluations >= 1);
        CHECK(s.termination[0] != '\0');
        CHECK(s.wall_time >= 0);
        /* solving again from the optimum stays there */
        CHECK(phc_nls_solve(nls, &o, x, &s, &err) == PHC_OK);
        CHECK_NEAR(x[0], a_ex, 1e-13, 1e-12);
        CHECK_NEAR(x[1], b_ex, 1e-13, 1e-12);
        phc_nls_free(nls);
    }
    phc_nls_free(NULL);
    CHECK(phc_nls_residual_count(NULL) == 0);
    CHECK(phc_nls_version() && strlen(phc_nls_version()) > 0);
}

/* ---- bounds and fixed parameters --------------------------------------------- */

static double mean_resid(const line_data *d, double b)
{
    double s = 0;
    for (size_t i = 0; i < d->n; ++i)
        s += d->y[i] - b * d->x[i];
    return s / (double)d->n;
}

static void test_bounds_and_fixed(void)
{
    line_data d;
    make_line(&d);
    double a_ex, b_ex;
    line_exact(&d, &a_ex, &b_ex);
    phc_error err;
    phc_nls_options o = phc_nls_options_default();
    phc_nls_summary s;

    /* upper bound on b below the optimum: b ends on it; a = mean(y - b_u x) */
    const double bu = 0.5;
    CHECK(bu < b_ex);
    phc_nls *nls = line_problem(&d, PHC_DERIV_ANALYTIC);
    CHECK(phc_nls_set_parameter(nls, 1, -INFINITY, bu, 0, 1.0, &err) == PHC_OK);
    double x[2] = {0, 0};
    CHECK(phc_nls_solve(nls, &o, x, &s, &err) == PHC_OK);
    CHECK(x[1] == bu);
    CHECK_NEAR(x[0], mean_resid(&d, bu), 0, SOLVER_TOL);
    phc_nls_free(nls);

    /* lower bound on a above the optimum and b free, a scale != 1 */
    const double al = a_ex + 0.3;
    nls = line_problem(&d, PHC_DERIV_ANALYTIC);
    CHECK(phc_nls_set_parameter(nls, 0, al, 10.0, 0, 4.0, &err) == PHC_OK);
    x[0] = 5;
    x[1] = 0;
    CHECK(phc_nls_solve(nls, &o, x, &s, &err) == PHC_OK);
    CHECK(x[0] == al);
    { /* b's conditional optimum given a: sum x (y - a - b x) = 0 */
        double sxy = 0, sxx = 0;
        for (size_t i = 0; i < d.n; ++i) {
            sxy += d.x[i] * (d.y[i] - al);
            sxx += d.x[i] * d.x[i];
        }
        CHECK_NEAR(x[1], sxy / sxx, 0, SOLVER_TOL);
    }
    phc_nls_free(nls);

    /* a start on the bound with the optimum inside: the parameter leaves it */
    nls = line_problem(&d, PHC_DERIV_ANALYTIC);
    CHECK(phc_nls_set_parameter(nls, 1, -INFINITY, 1.0, 0, 1.0, &err) == PHC_OK);
    x[0] = 0;
    x[1] = 1.0;
    CHECK(phc_nls_solve(nls, &o, x, &s, &err) == PHC_OK);
    CHECK_NEAR(x[0], a_ex, 0, SOLVER_TOL);
    CHECK_NEAR(x[1], b_ex, 0, SOLVER_TOL);
    phc_nls_free(nls);

    /* an optimum inside the box is not affected by the box */
    nls = line_problem(&d, PHC_DERIV_ANALYTIC);
    CHECK(phc_nls_set_parameter(nls, 0, a_ex - 1, a_ex + 1, 0, 1.0, &err) == PHC_OK);
    CHECK(phc_nls_set_parameter(nls, 1, b_ex - 1, b_ex + 1, 0, 1.0, &err) == PHC_OK);
    x[0] = a_ex - 0.9;
    x[1] = b_ex + 0.9;
    CHECK(phc_nls_solve(nls, &o, x, &s, &err) == PHC_OK);
    CHECK_NEAR(x[0], a_ex, 0, SOLVER_TOL);
    CHECK_NEAR(x[1], b_ex, 0, SOLVER_TOL);
    phc_nls_free(nls);

    /* a fixed parameter stays put (bit for bit); the other is conditionally optimal */
    for (int derivs = 0; derivs < 3; ++derivs) {
        nls = line_problem(&d, (phc_derivatives)derivs);
        CHECK(phc_nls_set_parameter(nls, 1, -INFINITY, INFINITY, 1, 1.0, &err) == PHC_OK);
        const double bfix = 0.3141592653589793;
        x[0] = -7;
        x[1] = bfix;
        CHECK(phc_nls_solve(nls, &o, x, &s, &err) == PHC_OK);
        CHECK(x[1] == bfix);
        CHECK_NEAR(x[0], mean_resid(&d, bfix), 0, SOLVER_TOL);
        phc_nls_free(nls);
    }

    /* a fixed parameter with lower == upper is allowed */
    nls = line_problem(&d, PHC_DERIV_ANALYTIC);
    CHECK(phc_nls_set_parameter(nls, 1, 0.25, 0.25, 1, 1.0, &err) == PHC_OK);
    x[0] = 0;
    x[1] = 0.25;
    CHECK(phc_nls_solve(nls, &o, x, &s, &err) == PHC_OK);
    CHECK(x[1] == 0.25);
    CHECK_NEAR(x[0], mean_resid(&d, 0.25), 0, SOLVER_TOL);
    phc_nls_free(nls);
}

/* ---- robust losses ------------------------------------------------------------ */

#define NLOC 8
static const double loc_y[NLOC] = {1.0, 1.1, 0.9, 1.05, 0.95, 1.02, 0.98, 50.0};

/* r_i = y_i - mu */
static int loc_residuals(const double *p, double *r, double *jac, void *ud)
{
    (void)ud;
    for (size_t i = 0; i < NLOC; ++i) {
        r[i] = loc_y[i] - p[0];
        if (jac)
            jac[i] = -1.0;
    }
    return 0;
}

/* rho'(s) as documented in ceres_bridge.h, scale a */
static double rho_prime(phc_loss_kind k, double s, double a)
{
    const double b = a * a;
    switch (k) {
    case PHC_LOSS_HUBER: return s <= b ? 1.0 : a / sqrt(s);
    case PHC_LOSS_CAUCHY: return 1.0 / (1.0 + s / b);
    case PHC_LOSS_SOFT_L1: return 1.0 / sqrt(1.0 + s / b);
    case PHC_LOSS_ARCTAN: return 1.0 / (1.0 + (s / b) * (s / b));
    default: return 1.0;
    }
}

static double rho(phc_loss_kind k, double s, double a)
{
    const double b = a * a;
    switch (k) {
    case PHC_LOSS_HUBER: return s <= b ? s : 2 * a * sqrt(s) - b;
    case PHC_LOSS_CAUCHY: return b * log1p(s / b);
    case PHC_LOSS_SOFT_L1: return 2 * b * (sqrt(1 + s / b) - 1);
    case PHC_LOSS_ARCTAN: return b * atan(s / b);
    default: return s;
    }
}

static double solve_location(phc_loss_kind loss, double scale, phc_derivatives derivs, double *cost)
{
    phc_nls *nls = phc_nls_new(1);
    const size_t idx[1] = {0};
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_nls_add_block(nls, NLOC, idx, 1, loc_residuals, derivs, loss, scale, NULL, &err) == PHC_OK);
    double mu = 1.5; /* a start near the bulk: redescending losses have other local minima */
    phc_nls_options o = phc_nls_options_default();
    phc_nls_summary s;
    CHECK(phc_nls_solve(nls, &o, &mu, &s, &err) == PHC_OK);
    CHECK(s.outcome == PHC_NLS_CONVERGED);
    *cost = s.final_cost;
    phc_nls_free(nls);
    return mu;
}

static void test_robust_losses(void)
{
    double sum = 0, sum_in = 0;
    for (size_t i = 0; i < NLOC; ++i)
        sum += loc_y[i];
    for (size_t i = 0; i + 1 < NLOC; ++i)
        sum_in += loc_y[i];
    double cost;
    const double mu_ls = solve_location(PHC_LOSS_NONE, 1.0, PHC_DERIV_ANALYTIC, &cost);
    CHECK_NEAR(mu_ls, sum / NLOC, 0, SOLVER_TOL); /* plain least squares: the mean */
    const double bulk = sum_in / (NLOC - 1);  /* 1.0 */
    static const phc_loss_kind kinds[] = {PHC_LOSS_HUBER, PHC_LOSS_CAUCHY, PHC_LOSS_SOFT_L1, PHC_LOSS_ARCTAN};
    static const char *const names[] = {"huber", "cauchy", "soft_l1", "arctan"};
    for (size_t k = 0; k < 4; ++k)
        for (int sc = 0; sc < 2; ++sc) {
            const double a = sc == 0 ? 1.0 : 0.5;
            for (int derivs = 0; derivs < 2; ++derivs) {
                const double mu = solve_location(kinds[k], a, derivs ? PHC_DERIV_CENTRAL : PHC_DERIV_ANALYTIC, &cost);
                /* the outlier's pull is much smaller than for least squares */
                if (!(fabs(mu - bulk) < 0.05 * fabs(mu_ls - bulk)))
                    fprintf(stderr, "%s (a=%g): mu %.6g, least squares %.6g\n", names[k], a, mu, mu_ls);
                CHECK(fabs(mu - bulk) < 0.05 * fabs(mu_ls - bulk));
                /* stationarity of 1/2 sum rho(r^2): sum rho'(r^2) r = 0 */
                double g = 0, gabs = 0, c = 0;
                for (size_t i = 0; i < NLOC; ++i) {
                    const double r = loc_y[i] - mu;
                    g += rho_prime(kinds[k], r * r, a) * r;
                    gabs += fabs(rho_prime(kinds[k], r * r, a) * r);
                    c += 0.5 * rho(kinds[k], r * r, a);
                }
                if (!(fabs(g) <= 1e-6 * gabs))
                    fprintf(stderr, "%s (a=%g): gradient %.3g of %.3g\n", names[k], a, g, gabs);
                CHECK(fabs(g) <= 1e-6 * gabs);
                CHECK_NEAR(cost, c, 0, 1e-12);
                if (kinds[k] == PHC_LOSS_HUBER) {
                    /* inliers within a, outlier beyond: sum_in (y - mu) + a = 0 */
                    CHECK_NEAR(mu, (sum_in + a) / (NLOC - 1), 0, SOLVER_TOL);
                }
            }
        }
}

/* ---- numerical vs analytic derivatives ----------------------------------------- */

#define NEXP 25
typedef struct exp_data {
    double t[NEXP], y[NEXP];
} exp_data;

/* r = y - (A exp(-k t) + c); params (A, k, c) */
static int exp_residuals(const double *p, double *r, double *jac, void *ud)
{
    const exp_data *d = ud;
    for (size_t i = 0; i < NEXP; ++i) {
        const double e = exp(-p[1] * d->t[i]);
        r[i] = d->y[i] - (p[0] * e + p[2]);
        if (jac) {
            jac[3 * i] = -e;
            jac[3 * i + 1] = p[0] * d->t[i] * e;
            jac[3 * i + 2] = -1.0;
        }
    }
    return 0;
}

static void exp_make(exp_data *d, double noise)
{
    for (size_t i = 0; i < NEXP; ++i) {
        d->t[i] = 0.2 * (double)i;
        d->y[i] = 3.0 * exp(-0.8 * d->t[i]) + 0.5 + noise * cos(7.0 * (double)i);
    }
}

static void exp_solve(exp_data *d, phc_derivatives derivs, const double *scale, double *x)
{
    phc_nls *nls = phc_nls_new(3);
    const size_t idx[3] = {0, 1, 2};
    phc_error err;
    phc_error_clear(&err);
    for (size_t j = 0; j < 3; ++j)
        CHECK(phc_nls_set_parameter(nls, j, -INFINITY, INFINITY, 0, scale[j], &err) == PHC_OK);
    CHECK(phc_nls_add_block(nls, NEXP, idx, 3, exp_residuals, derivs, PHC_LOSS_NONE, 1, d, &err) == PHC_OK);
    x[0] = 1;
    x[1] = 0.3;
    x[2] = 0;
    phc_nls_options o = phc_nls_options_default();
    phc_nls_summary s;
    CHECK(phc_nls_solve(nls, &o, x, &s, &err) == PHC_OK);
    CHECK(s.outcome == PHC_NLS_CONVERGED);
    phc_nls_free(nls);
}

static void test_numerical_derivatives(void)
{
    exp_data d;
    const double ones[3] = {1, 1, 1}, scales[3] = {3, 1e-2, 1e3};
    /* noise-free: every method finds the generating parameters */
    exp_make(&d, 0.0);
    for (int m = 0; m < 3; ++m) {
        double x[3];
        exp_solve(&d, (phc_derivatives)m, ones, x);
        CHECK_NEAR(x[0], 3.0, 0, 1e-8);
        CHECK_NEAR(x[1], 0.8, 0, 1e-8);
        CHECK_NEAR(x[2], 0.5, 0, 1e-8);
    }
    /* noisy: the three methods agree on the optimum, with any scales */
    exp_make(&d, 0.02);
    double ref[3];
    exp_solve(&d, PHC_DERIV_ANALYTIC, ones, ref);
    for (int sc = 0; sc < 2; ++sc)
        for (int m = 0; m < 3; ++m) {
            double x[3];
            exp_solve(&d, (phc_derivatives)m, sc ? scales : ones, x);
            for (size_t j = 0; j < 3; ++j) {
                if (!(fabs(x[j] - ref[j]) <= 1e-8 * fabs(ref[j])))
                    fprintf(stderr, "derivs %d scale set %d: x[%zu] = %.17g, analytic %.17g\n", m, sc, j, x[j],
                            ref[j]);
                CHECK_NEAR(x[j], ref[j], 0, 1e-8);
            }
        }
}

/* A nonlinear model with its rate held by an upper bound (k <= 0.5, data
 * made with k = 0.8): k ends on the bound and (A, c) at their conditional
 * optimum, the linear least-squares fit with regressors exp(-0.5 t) and 1. */
static void test_nonlinear_bound(void)
{
    exp_data d;
    exp_make(&d, 0.02);
    const double kb = 0.5;
    double s11 = 0, s12 = 0, s22 = 0, b1 = 0, b2 = 0;
    for (size_t i = 0; i < NEXP; ++i) {
        const double e = exp(-kb * d.t[i]);
        s11 += e * e;
        s12 += e;
        s22 += 1;
        b1 += e * d.y[i];
        b2 += d.y[i];
    }
    const double det = s11 * s22 - s12 * s12;
    const double A = (b1 * s22 - b2 * s12) / det, c = (s11 * b2 - s12 * b1) / det;
    for (int derivs = 0; derivs < 3; ++derivs) {
        phc_nls *nls = phc_nls_new(3);
        const size_t idx[3] = {0, 1, 2};
        phc_error err;
        phc_error_clear(&err);
        CHECK(phc_nls_set_parameter(nls, 1, 0.0, kb, 0, 1.0, &err) == PHC_OK);
        CHECK(phc_nls_add_block(nls, NEXP, idx, 3, exp_residuals, (phc_derivatives)derivs, PHC_LOSS_NONE, 1, &d,
                                &err) == PHC_OK);
        double x[3] = {1, 0.3, 0};
        phc_nls_options o = phc_nls_options_default();
        phc_nls_summary s;
        CHECK(phc_nls_solve(nls, &o, x, &s, &err) == PHC_OK);
        CHECK(s.outcome == PHC_NLS_CONVERGED);
        CHECK(x[1] == kb);
        if (!(fabs(x[0] - A) <= SOLVER_TOL * fabs(A) && fabs(x[2] - c) <= SOLVER_TOL * fabs(c)))
            fprintf(stderr, "bounded rate (derivs %d): A %.17g (want %.17g), c %.17g (want %.17g)\n", derivs, x[0],
                    A, x[2], c);
        CHECK_NEAR(x[0], A, 0, SOLVER_TOL);
        CHECK_NEAR(x[2], c, 0, SOLVER_TOL);
        /* the reported final cost is the cost at the returned point */
        double cost;
        CHECK(phc_nls_evaluate(nls, x, NULL, NULL, &cost, &err) == PHC_OK);
        CHECK_NEAR(s.final_cost, cost, 0, 1e-12);
        phc_nls_free(nls);
    }
}

/* ---- callback return codes ---------------------------------------------------- */

#define NDOM 6
typedef struct domain_data {
    double t[NDOM], y[NDOM];
    int mode;          /* 0: return 1 outside b > 0; 1: return NaN there; 2: fatal after `fatal_after` calls */
    int calls, outside, fatal_after;
} domain_data;

/* r_i = log(b t_i) - y_i with y_i = log(0.01 t_i): the optimum is b = 0.01 */
static int domain_residuals(const double *p, double *r, double *jac, void *ud)
{
    domain_data *d = ud;
    d->calls++;
    if (d->mode == 2 && d->calls > d->fatal_after)
        return -3;
    if (!(p[0] > 0)) {
        d->outside++;
        if (d->mode == 0)
            return 1;
    }
    for (size_t i = 0; i < NDOM; ++i) {
        r[i] = log(p[0] * d->t[i]) - d->y[i]; /* NaN (or -inf) for b <= 0 in mode 1 */
        if (jac)
            jac[i] = 1.0 / p[0];
    }
    return 0;
}

static void domain_make(domain_data *d, int mode)
{
    memset(d, 0, sizeof *d);
    d->mode = mode;
    for (size_t i = 0; i < NDOM; ++i) {
        d->t[i] = 1.0 + (double)i;
        d->y[i] = log(0.01 * d->t[i]);
    }
}

static void test_callback_codes(void)
{
    phc_nls_options o = phc_nls_options_default();
    const size_t idx[1] = {0};
    for (int mode = 0; mode < 2; ++mode)
        for (int derivs = 0; derivs < 2; ++derivs) {
            domain_data d;
            domain_make(&d, mode);
            phc_nls *nls = phc_nls_new(1);
            phc_error err;
            phc_error_clear(&err);
            CHECK(phc_nls_add_block(nls, NDOM, idx, 1, domain_residuals,
                                    derivs ? PHC_DERIV_CENTRAL : PHC_DERIV_ANALYTIC, PHC_LOSS_NONE, 1, &d,
                                    &err) == PHC_OK);
            double b = 10; /* the first Gauss–Newton step goes to b = 10 - 10 log(1000) < 0 */
            phc_nls_summary s;
            CHECK(phc_nls_solve(nls, &o, &b, &s, &err) == PHC_OK);
            CHECK(s.outcome == PHC_NLS_CONVERGED);
            CHECK_NEAR(b, 0.01, 0, 1e-10);
            CHECK(d.outside > 0); /* the invalid region was really tried, and rejected */
            phc_nls_free(nls);
        }

    /* a fatal callback: an error with a message, no crash; at the first call and later;
     * analytic, numerical, and with a loss (per-point blocks sharing one evaluation) */
    for (int after = 0; after < 2; ++after)
        for (int variant = 0; variant < 3; ++variant) {
            domain_data d;
            domain_make(&d, 2);
            d.fatal_after = after ? 4 : 0;
            phc_nls *nls = phc_nls_new(1);
            phc_error err;
            phc_error_clear(&err);
            CHECK(phc_nls_add_block(nls, NDOM, idx, 1, domain_residuals,
                                    variant == 1 ? PHC_DERIV_RIDDERS : PHC_DERIV_ANALYTIC,
                                    variant == 2 ? PHC_LOSS_CAUCHY : PHC_LOSS_NONE, 1, &d, &err) == PHC_OK);
            double b = 10;
            phc_nls_summary s;
            const int rc = phc_nls_solve(nls, &o, &b, &s, &err);
            CHECK(rc != PHC_OK);
            CHECK(err.status == rc);
            CHECK(strlen(err.message) > 0);
            CHECK_STR_CONTAINS(err.message, "-3");
            CHECK(isfinite(b));
            phc_nls_free(nls);
        }
}

/* ---- invalid arguments ---------------------------------------------------------- */

static int dummy_residuals(const double *p, double *r, double *jac, void *ud)
{
    (void)ud;
    r[0] = p[0] - 1;
    if (jac)
        jac[0] = 1;
    return 0;
}

#define EXPECT_ERR(call, substring)                                          \
    do {                                                                     \
        phc_error_clear(&err);                                               \
        const int rc_ = (call);                                              \
        CHECK(rc_ != PHC_OK);                                                \
        CHECK(err.status == rc_);                                            \
        CHECK_STR_CONTAINS(err.message, substring);                          \
    } while (0)

static void test_invalid_arguments(void)
{
    phc_error err;
    phc_nls *nls = phc_nls_new(2);
    const size_t dup[2] = {1, 1}, out[2] = {0, 7}, one[1] = {0};

    EXPECT_ERR(phc_nls_add_block(nls, 1, dup, 2, dummy_residuals, PHC_DERIV_ANALYTIC, PHC_LOSS_NONE, 1, NULL, &err),
               "appears twice");
    EXPECT_ERR(phc_nls_add_block(nls, 1, out, 2, dummy_residuals, PHC_DERIV_ANALYTIC, PHC_LOSS_NONE, 1, NULL, &err),
               "out of range");
    EXPECT_ERR(phc_nls_add_block(nls, 0, one, 1, dummy_residuals, PHC_DERIV_ANALYTIC, PHC_LOSS_NONE, 1, NULL, &err),
               "at least one residual");
    EXPECT_ERR(phc_nls_add_block(nls, 1, one, 0, dummy_residuals, PHC_DERIV_ANALYTIC, PHC_LOSS_NONE, 1, NULL, &err),
               "at least one");
    EXPECT_ERR(phc_nls_add_block(nls, 1, one, 1, NULL, PHC_DERIV_ANALYTIC, PHC_LOSS_NONE, 1, NULL, &err), "NULL");
    EXPECT_ERR(phc_nls_add_block(nls, 1, one, 1, dummy_residuals, (phc_derivatives)7, PHC_LOSS_NONE, 1, NULL, &err),
               "derivative");
    EXPECT_ERR(phc_nls_add_block(nls, 1, one, 1, dummy_residuals, PHC_DERIV_ANALYTIC, (phc_loss_kind)9, 1, NULL, &err),
               "loss");
    EXPECT_ERR(phc_nls_add_block(nls, 1, one, 1, dummy_residuals, PHC_DERIV_ANALYTIC, PHC_LOSS_HUBER, 0, NULL, &err),
               "loss scale");
    EXPECT_ERR(phc_nls_add_block(nls, 1, one, 1, dummy_residuals, PHC_DERIV_ANALYTIC, PHC_LOSS_CAUCHY, NAN, NULL, &err),
               "loss scale");
    CHECK(phc_nls_residual_count(nls) == 0); /* nothing was added */

    EXPECT_ERR(phc_nls_set_parameter(nls, 2, 0, 1, 0, 1, &err), "out of range");
    EXPECT_ERR(phc_nls_set_parameter(nls, 0, 2, 1, 0, 1, &err), "not an interval");
    EXPECT_ERR(phc_nls_set_parameter(nls, 0, 1, 1, 0, 1, &err), "not an interval"); /* free needs lower < upper */
    EXPECT_ERR(phc_nls_set_parameter(nls, 0, NAN, 1, 0, 1, &err), "not an interval");
    EXPECT_ERR(phc_nls_set_parameter(nls, 0, 0, 1, 0, 0, &err), "scale");
    EXPECT_ERR(phc_nls_set_parameter(nls, 0, 0, 1, 0, -2, &err), "scale");
    EXPECT_ERR(phc_nls_set_parameter(nls, 0, 0, 1, 0, INFINITY, &err), "scale");
    EXPECT_ERR(phc_nls_set_parameter(nls, 0, 0, 1, 0, NAN, &err), "scale");
    EXPECT_ERR(phc_nls_set_parameter(NULL, 0, 0, 1, 0, 1, &err), "NULL");

    phc_nls_options o = phc_nls_options_default();
    phc_nls_summary s;
    double x[2] = {0.5, 0.5};
    EXPECT_ERR(phc_nls_solve(nls, &o, x, &s, &err), "no residual blocks");

    CHECK(phc_nls_add_block(nls, 1, one, 1, dummy_residuals, PHC_DERIV_ANALYTIC, PHC_LOSS_NONE, 1, NULL, &err) ==
          PHC_OK);
    CHECK(phc_nls_set_parameter(nls, 0, 0, 0.75, 0, 1, &err) == PHC_OK);
    x[0] = NAN;
    EXPECT_ERR(phc_nls_solve(nls, &o, x, &s, &err), "not finite");
    x[0] = 0.5;
    x[1] = INFINITY; /* an unused parameter must be finite too */
    EXPECT_ERR(phc_nls_solve(nls, &o, x, &s, &err), "not finite");
    x[1] = 0;
    x[0] = 0.9; /* start outside [0, 0.75] */
    EXPECT_ERR(phc_nls_solve(nls, &o, x, &s, &err), "outside its bounds");
    x[0] = 0.5;
    o.max_iterations = 0;
    EXPECT_ERR(phc_nls_solve(nls, &o, x, &s, &err), "max_iterations");
    o = phc_nls_options_default();
    o.num_threads = 0;
    EXPECT_ERR(phc_nls_solve(nls, &o, x, &s, &err), "num_threads");
    EXPECT_ERR(phc_nls_solve(nls, NULL, x, &s, &err), "NULL");
    double bad[2] = {NAN, 0};
    EXPECT_ERR(phc_nls_evaluate(nls, bad, NULL, NULL, NULL, &err), "not finite");
    EXPECT_ERR(phc_nls_evaluate(NULL, x, NULL, NULL, NULL, &err), "NULL");

    /* after all that, the problem still solves: r = p - 1 with p <= 0.75 -> 0.75 */
    o = phc_nls_options_default();
    x[0] = 0.5;
    CHECK(phc_nls_residual_count(nls) == 1);
    CHECK(phc_nls_solve(nls, &o, x, &s, &err) == PHC_OK);
    CHECK(x[0] == 0.75);
    CHECK(x[1] == 0); /* a parameter no block uses is left alone */
    phc_nls_free(nls);
}

/* ---- phc_nls_evaluate ------------------------------------------------------------ */

/* Block 1 uses (p0, p1, p2): r_i = y_i - p0 exp(-p1 t_i) - p2 t_i^2
 * Block 2 uses (p3, p1):     r_i = (z_i - sin(p3 t_i) p1) / 0.3
 * p1 is shared; p4 is not used by any block. */
typedef struct ev_data {
    double t[7], y[7], z[5];
} ev_data;

static int ev_block1(const double *p, double *r, double *jac, void *ud)
{
    const ev_data *d = ud;
    for (size_t i = 0; i < 7; ++i) {
        const double e = exp(-p[1] * d->t[i]);
        r[i] = d->y[i] - p[0] * e - p[2] * d->t[i] * d->t[i];
        if (jac) {
            jac[3 * i] = -e;
            jac[3 * i + 1] = p[0] * d->t[i] * e;
            jac[3 * i + 2] = -d->t[i] * d->t[i];
        }
    }
    return 0;
}

static int ev_block2(const double *p, double *r, double *jac, void *ud)
{
    const ev_data *d = ud;
    for (size_t i = 0; i < 5; ++i) {
        r[i] = (d->z[i] - sin(p[0] * d->t[i]) * p[1]) / 0.3;
        if (jac) {
            jac[2 * i] = -cos(p[0] * d->t[i]) * d->t[i] * p[1] / 0.3;
            jac[2 * i + 1] = -sin(p[0] * d->t[i]) / 0.3;
        }
    }
    return 0;
}

static void all_residuals(const ev_data *d, const double *x, double *r)
{
    const double p1[3] = {x[0], x[1], x[2]}, p2[2] = {x[3], x[1]};
    ev_block1(p1, r, NULL, (void *)d);
    ev_block2(p2, r + 7, NULL, (void *)d);
}

/* Ridders' extrapolated central difference of all 12 residuals in x[j]. */
static void ridders_column(const ev_data *d, double *x, size_t j, double *col)
{
    enum { NT = 10, M = 12 };
    const double con = 1.4, con2 = con * con;
    for (size_t i = 0; i < M; ++i) {
        double a[NT][NT], err = INFINITY, ans = NAN, h = 0.1 * (fabs(x[j]) > 0 ? fabs(x[j]) : 1.0);
        const double keep = x[j];
        double rp[M], rm[M];
        for (int k = 0; k < NT; ++k) {
            x[j] = keep + h;
            all_residuals(d, x, rp);
            x[j] = keep - h;
            all_residuals(d, x, rm);
            x[j] = keep;
            a[0][k] = (rp[i] - rm[i]) / (2 * h);
            double fac = con2;
            for (int l = 1; l <= k; ++l) {
                a[l][k] = (a[l - 1][k] * fac - a[l - 1][k - 1]) / (fac - 1);
                fac *= con2;
                const double e = fmax(fabs(a[l][k] - a[l - 1][k]), fabs(a[l][k] - a[l - 1][k - 1]));
                if (e <= err) {
                    err = e;
                    ans = a[l][k];
                }
            }
            if (k > 0 && fabs(a[k][k] - a[k - 1][k - 1]) >= 2 * err)
                break;
            h /= con;
        }
        col[i] = ans;
    }
}

static void test_evaluate(void)
{
    ev_data d;
    for (size_t i = 0; i < 7; ++i) {
        d.t[i] = 0.3 * (double)i;
        d.y[i] = 2.2 * exp(-0.6 * d.t[i]) + 0.04 * d.t[i] * d.t[i] + 0.01 * cos(5.0 * (double)i);
    }
    for (size_t i = 0; i < 5; ++i)
        d.z[i] = 0.8 * sin(1.2 * d.t[i]) + 0.02 * sin(3.0 * (double)i);
    static const phc_loss_kind losses[5] = {PHC_LOSS_NONE, PHC_LOSS_HUBER, PHC_LOSS_CAUCHY, PHC_LOSS_SOFT_L1,
                                            PHC_LOSS_ARCTAN};
    const double x0[5] = {2.0, 0.7, 0.05, 1.3, 9.9};
    double worst = 0;
    for (int d1 = 0; d1 < 3; ++d1)
        for (int d2 = 0; d2 < 3; ++d2)
            for (int l = 0; l < 5; ++l) {
                const phc_loss_kind l1 = losses[l], l2 = losses[(l + 2) % 5];
                const double a1 = 0.05, a2 = 2.0; /* block 1 has residuals beyond its scale */
                phc_nls *nls = phc_nls_new(5);
                phc_error err;
                phc_error_clear(&err);
                const size_t i1[3] = {0, 1, 2}, i2[2] = {3, 1};
                CHECK(phc_nls_set_parameter(nls, 0, -INFINITY, INFINITY, 1, 1.0, &err) == PHC_OK); /* fixed */
                CHECK(phc_nls_set_parameter(nls, 2, -INFINITY, INFINITY, 0, 1e-3, &err) == PHC_OK);
                /* scale 2 (u = 0.65): Ceres's Ridders starts from an absolute
                 * step of 0.32 in u when |u| < 1, so a scale far above the
                 * value (e.g. 50, u = 0.026) gives wrong Ridders derivatives
                 * (reported, not fixed here) */
                CHECK(phc_nls_set_parameter(nls, 3, 0.0, 10.0, 0, 2.0, &err) == PHC_OK);
                CHECK(phc_nls_add_block(nls, 7, i1, 3, ev_block1, (phc_derivatives)d1, l1, a1, &d, &err) == PHC_OK);
                CHECK(phc_nls_add_block(nls, 5, i2, 2, ev_block2, (phc_derivatives)d2, l2, a2, &d, &err) == PHC_OK);
                CHECK(phc_nls_residual_count(nls) == 12);
                double x[5], r[12], J[60], cost = NAN, r_ref[12];
                memcpy(x, x0, sizeof x);
                CHECK(phc_nls_evaluate(nls, x, r, J, &cost, &err) == PHC_OK);
                all_residuals(&d, x, r_ref);
                double c_ref = 0;
                for (size_t i = 0; i < 12; ++i) {
                    CHECK(r[i] == r_ref[i]); /* plain weighted residuals, losses not applied */
                    c_ref += 0.5 * (i < 7 ? rho(l1, r_ref[i] * r_ref[i], a1) : rho(l2, r_ref[i] * r_ref[i], a2));
                }
                CHECK_NEAR(cost, c_ref, 0, 1e-13);
                /* the same without the Jacobian, and with NULL outputs */
                double r2[12], cost2 = NAN;
                CHECK(phc_nls_evaluate(nls, x, r2, NULL, &cost2, &err) == PHC_OK);
                CHECK(memcmp(r, r2, sizeof r) == 0 && cost2 == cost);
                CHECK(phc_nls_evaluate(nls, x, NULL, NULL, NULL, &err) == PHC_OK);
                /* Jacobian columns against Ridders' differences of the residuals */
                const double tol = (d1 == PHC_DERIV_CENTRAL || d2 == PHC_DERIV_CENTRAL) ? 1e-7 : 1e-9;
                for (size_t j = 0; j < 5; ++j) {
                    double col[12];
                    ridders_column(&d, x, j, col);
                    double cmax = 0;
                    for (size_t i = 0; i < 12; ++i)
                        cmax = fmax(cmax, fabs(col[i]));
                    for (size_t i = 0; i < 12; ++i) {
                        const double got = J[i * 5 + j];
                        if (j == 4 || (j == 2 && i >= 7) || (j == 0 && i >= 7) || (j == 3 && i < 7)) {
                            CHECK(got == 0.0); /* parameters a block does not use */
                            continue;
                        }
                        const double rel = fabs(got - col[i]) / fmax(fabs(col[i]), 1e-6 * cmax);
                        worst = fmax(worst, rel);
                        if (!(rel < tol))
                            fprintf(stderr, "derivs %d/%d loss %d: J[%zu][%zu] = %.17g, numerical %.17g\n", d1, d2,
                                    l, i, j, got, col[i]);
                        CHECK(rel < tol);
                    }
                }
                /* evaluation is at the given x even outside the bounds (p3 = 12 > 10) */
                x[3] = 12;
                CHECK(phc_nls_evaluate(nls, x, r, NULL, NULL, &err) == PHC_OK);
                all_residuals(&d, x, r_ref);
                CHECK(r[7] == r_ref[7]);
                phc_nls_free(nls);
            }
    printf("phc_nls_evaluate: worst Jacobian relative error %.3g\n", worst);
}

/* An evaluation outside the domain is an error, not a crash. */
static void test_evaluate_domain(void)
{
    domain_data d;
    domain_make(&d, 0);
    phc_nls *nls = phc_nls_new(1);
    const size_t idx[1] = {0};
    phc_error err;
    CHECK(phc_nls_add_block(nls, NDOM, idx, 1, domain_residuals, PHC_DERIV_CENTRAL, PHC_LOSS_NONE, 1, &d, &err) ==
          PHC_OK);
    double b = -1, r[NDOM], J[NDOM];
    phc_error_clear(&err);
    CHECK(phc_nls_evaluate(nls, &b, r, J, NULL, &err) == PHC_ERR_DOMAIN);
    CHECK(strlen(err.message) > 0);
    b = 0.02; /* the optimum is 0.01: r = log 2 everywhere, dr/db = 1/b */
    CHECK(phc_nls_evaluate(nls, &b, r, J, NULL, &err) == PHC_OK);
    for (size_t i = 0; i < NDOM; ++i) {
        CHECK_NEAR(r[i], log(2.0), 1e-15, 1e-13);
        CHECK_NEAR(J[i], 50.0, 0, 1e-8);
    }
    phc_nls_free(nls);
}

/* y = a exp(-b x) on exact data (a = 3, b = 0.7), counting the callback's
 * runs with and without a Jacobian. */
typedef struct decay_data {
    long with_jac, without_jac;
} decay_data;

#define NDEC 20
static int decay_residuals(const double *p, double *r, double *jac, void *ud)
{
    decay_data *d = ud;
    ++*(jac ? &d->with_jac : &d->without_jac);
    for (size_t i = 0; i < NDEC; ++i) {
        const double x = 0.25 * (double)i, e = exp(-p[1] * x);
        r[i] = 3.0 * exp(-0.7 * x) - p[0] * e;
        if (jac) {
            jac[2 * i] = -e;
            jac[2 * i + 1] = p[0] * x * e;
        }
    }
    return 0;
}

/* Ceres asks for the residuals at a candidate and, once it accepts the
 * step, for the residuals and the Jacobian there: the bridge serves the
 * second from the first, so the callback runs fewer times than Ceres
 * evaluates, and the optimum is the exact one. */
static void test_candidate_reuse(void)
{
    decay_data d = {0, 0};
    phc_nls *nls = phc_nls_new(2);
    const size_t idx[2] = {0, 1};
    phc_error err;
    CHECK(phc_nls_add_block(nls, NDEC, idx, 2, decay_residuals, PHC_DERIV_ANALYTIC, PHC_LOSS_NONE, 1.0, &d, &err) ==
          PHC_OK);
    phc_nls_options o = phc_nls_options_default();
    phc_nls_summary s;
    double x[2] = {1.0, 2.0};
    CHECK(phc_nls_solve(nls, &o, x, &s, &err) == PHC_OK);
    CHECK(s.outcome == PHC_NLS_CONVERGED);
    CHECK_NEAR(x[0], 3.0, 0, SOLVER_TOL);
    CHECK_NEAR(x[1], 0.7, 0, SOLVER_TOL);
    const long runs = d.with_jac + d.without_jac;
    printf("candidate reuse: %ld callback runs (%ld with the Jacobian) for %d residual and %d Jacobian "
           "evaluations\n", runs, d.with_jac, s.residual_evaluations, s.jacobian_evaluations);
    CHECK(s.jacobian_evaluations >= 3);
    /* at most one run per residual evaluation (candidates) plus the start's
     * Jacobian and one per rejected candidate's successor */
    CHECK(runs < s.residual_evaluations + s.jacobian_evaluations);
    CHECK(runs <= s.residual_evaluations + 1 + (s.iterations - s.jacobian_evaluations + 1));
    phc_nls_free(nls);
}

/* exp_residuals with a fourth parameter that the model ignores (held fixed
 * below): the same residuals and Jacobian columns for (A, k, c). */
static int exp4_residuals(const double *p, double *r, double *jac, void *ud)
{
    double j3[3 * NEXP];
    const int rc = exp_residuals(p, r, jac ? j3 : NULL, ud);
    for (size_t i = 0; jac && i < NEXP; ++i) {
        for (size_t j = 0; j < 3; ++j)
            jac[4 * i + j] = j3[3 * i + j];
        jac[4 * i + 3] = 0.0;
    }
    return rc;
}

/* One data set over free, unbounded parameters is declared to Ceres as one
 * parameter block of size k instead of k blocks of size 1 (less of Ceres's
 * per-block work): the same Jacobian columns in the same order, so the
 * same solve.  The same model with a fourth, fixed parameter takes the k
 * blocks of size 1: optimum, cost and every count bitwise the same, with
 * unit and with uneven parameter scales. */
static void test_one_parameter_block(void)
{
    exp_data d;
    exp_make(&d, 0.02);
    const double ones[4] = {1, 1, 1, 1}, scales[4] = {3, 1e-2, 1e3, 1};
    for (int sc = 0; sc < 2; ++sc) {
        double x[2][4];
        phc_nls_summary s[2];
        for (int blocks = 0; blocks < 2; ++blocks) {
            const size_t np = blocks ? 4 : 3, idx[4] = {0, 1, 2, 3};
            phc_nls *nls = phc_nls_new(np);
            phc_error err;
            phc_error_clear(&err);
            for (size_t j = 0; j < np; ++j)
                CHECK(phc_nls_set_parameter(nls, j, -INFINITY, INFINITY, j == 3, (sc ? scales : ones)[j], &err) ==
                      PHC_OK);
            CHECK(phc_nls_add_block(nls, NEXP, idx, np, blocks ? exp4_residuals : exp_residuals, PHC_DERIV_ANALYTIC,
                                    PHC_LOSS_NONE, 1, &d, &err) == PHC_OK);
            x[blocks][0] = 1;
            x[blocks][1] = 0.3;
            x[blocks][2] = 0;
            x[blocks][3] = 0;
            phc_nls_options o = phc_nls_options_default();
            CHECK(phc_nls_solve(nls, &o, x[blocks], &s[blocks], &err) == PHC_OK);
            CHECK(s[blocks].outcome == PHC_NLS_CONVERGED);
            phc_nls_free(nls);
        }
        CHECK(memcmp(x[0], x[1], 3 * sizeof x[0][0]) == 0);
        CHECK(memcmp(&s[0].final_cost, &s[1].final_cost, sizeof s[0].final_cost) == 0);
        CHECK(s[0].iterations == s[1].iterations);
        CHECK(s[0].residual_evaluations == s[1].residual_evaluations);
        CHECK(s[0].jacobian_evaluations == s[1].jacobian_evaluations);
        printf("one parameter block (scales %s): %d iterations, x = %.17g %.17g %.17g; blocks of size 1: %d, "
               "%.17g %.17g %.17g\n", sc ? "uneven" : "1", s[0].iterations, x[0][0], x[0][1], x[0][2],
               s[1].iterations, x[1][0], x[1][1], x[1][2]);
    }
}

int main(void)
{
    test_linear();
    test_bounds_and_fixed();
    test_robust_losses();
    test_numerical_derivatives();
    test_nonlinear_bound();
    test_callback_codes();
    test_invalid_arguments();
    test_evaluate();
    test_evaluate_domain();
    test_candidate_reuse();
    test_one_parameter_block();
    return check_finish("test_ceres_bridge");
}
