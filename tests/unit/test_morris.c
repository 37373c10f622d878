/* Unit tests of fit/engine/morris.c.
 *
 * Limit case: for a linear function y = sum c_i u_i every elementary effect
 * of factor i on the [0, 1] grid scale is exactly c_i times the ratio of the
 * probability scale to the grid scale ((p-1)/p: level l sits at (l + 1/2)/p),
 * so mu = mu* = c_i (p-1)/p and sigma = 0.
 * Sobol G-function (a = 0, 1, 4.5, 9, 99 x4): the factors' importance falls
 * with a_i, so mu* must rank x1 > x2 > x3 > x4 > each of x5..x8
 * (Campolongo et al. 2007, §4, use the same test). */
#include <math.h>
#include <stdlib.h>

#include "check.h"
#include "fit/engine/morris.h"

static const double g_a[8] = {0, 1, 4.5, 9, 99, 99, 99, 99};

static double gfun(const double *u, size_t k)
{
    double y = 1;
    for (size_t i = 0; i < k; ++i)
        y *= (fabs(4 * u[i] - 2) + g_a[i]) / (1 + g_a[i]);
    return y;
}

static double *evaluate(const phc_morris_design *d, size_t k, double (*fn)(const double *, size_t))
{
    const size_t m = phc_morris_design_rows(d);
    double *y = malloc(m * sizeof *y), u[16];
    for (size_t r = 0; r < m; ++r) {
        phc_morris_design_point(d, r, u);
        y[r] = fn(u, k);
    }
    return y;
}

static double linear(const double *u, size_t k)
{
    (void)k;
    return 2.0 * u[0] - 5.0 * u[1] + 0.0 * u[2];
}

static void test_linear(void)
{
    phc_morris_options o = phc_morris_options_default();
    o.trajectories = 10;
    o.levels = 6;
    phc_morris_design *d = NULL;
    phc_error err;
    CHECK(phc_morris_design_new(3, NULL, 3, &o, &d, &err) == PHC_OK);
    CHECK(phc_morris_design_rows(d) == 40);
    /* every point on the grid (l + 1/2)/p and consecutive points differ in one factor */
    double u[3], prev[3];
    int on_grid = 1, one_at_a_time = 1;
    for (size_t r = 0; r < 40; ++r) {
        phc_morris_design_point(d, r, u);
        int changed = 0;
        for (int c = 0; c < 3; ++c) {
            const double l = u[c] * 6 - 0.5;
            on_grid &= fabs(l - rint(l)) < 1e-12 && l > -0.5 && l < 5.5;
            if (r % 4 && u[c] != prev[c]) {
                changed++;
                one_at_a_time &= fabs(fabs(u[c] - prev[c]) - 0.5) < 1e-12; /* p/2 levels = 1/2 */
            }
        }
        if (r % 4)
            one_at_a_time &= changed == 1;
        for (int c = 0; c < 3; ++c)
            prev[c] = u[c];
    }
    CHECK(on_grid);
    CHECK(one_at_a_time);
    double *y = evaluate(d, 3, linear);
    phc_morris_effects e = {0};
    CHECK(phc_morris_estimate(d, y, &e, &err) == PHC_OK);
    const double scale = 5.0 / 6.0;
    CHECK_NEAR(e.mu[0], 2 * scale, 1e-12, 0);
    CHECK_NEAR(e.mu[1], -5 * scale, 1e-12, 0);
    CHECK_NEAR(e.mu_star[1], 5 * scale, 1e-12, 0);
    CHECK_NEAR(e.mu_star[2], 0, 1e-12, 0);
    CHECK_NEAR(e.sigma[0], 0, 1e-12, 0);
    CHECK_NEAR(e.mu_star_lo[0], 2 * scale, 1e-12, 0);
    printf("linear 2, -5, 0 (p = 6): mu = %.15g %.15g %.15g, sigma = %.3g %.3g %.3g\n", e.mu[0], e.mu[1], e.mu[2],
           e.sigma[0], e.sigma[1], e.sigma[2]);
    phc_morris_effects_clear(&e);
    /* a failed trajectory is left out and counted */
    y[5] = NAN;
    CHECK(phc_morris_estimate(d, y, &e, &err) == PHC_OK);
    CHECK(e.n_failed == 1 && e.n_used == 9);
    phc_morris_effects_clear(&e);
    free(y);
    phc_morris_design_free(d);
    o.levels = 5;
    CHECK(phc_morris_design_new(3, NULL, 3, &o, &d, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "even number of levels");
    o.levels = 4;
    o.trajectories = 2;
    CHECK(phc_morris_design_new(3, NULL, 3, &o, &d, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "too few");
}

static void test_gfunction_ranking(void)
{
    phc_morris_options o = phc_morris_options_default();
    o.trajectories = 100;
    o.seed = 7;
    phc_morris_design *d = NULL;
    phc_error err;
    CHECK(phc_morris_design_new(8, NULL, 8, &o, &d, &err) == PHC_OK);
    double *y = evaluate(d, 8, gfun);
    phc_morris_effects e = {0};
    CHECK(phc_morris_estimate(d, y, &e, &err) == PHC_OK);
    printf("G-function, Morris r = %zu, p = %u (%zu evaluations):\n", o.trajectories, o.levels,
           phc_morris_design_rows(d));
    for (int i = 0; i < 8; ++i)
        printf("  x%d (a = %g)  mu* = %.5f [%.5f, %.5f]  mu = %+.5f  sigma = %.5f\n", i + 1, g_a[i], e.mu_star[i],
               e.mu_star_lo[i], e.mu_star_hi[i], e.mu[i], e.sigma[i]);
    for (int i = 0; i < 3; ++i)
        CHECK(e.mu_star[i] > e.mu_star[i + 1]);
    for (int i = 4; i < 8; ++i)
        CHECK(e.mu_star[3] > e.mu_star[i]);
    /* the intervals separate the first three */
    CHECK(e.mu_star_lo[0] > e.mu_star_hi[1] && e.mu_star_lo[1] > e.mu_star_hi[2]);
    phc_morris_effects_clear(&e);
    free(y);
    phc_morris_design_free(d);
}

int main(void)
{
    test_linear();
    test_gfunction_ranking();
    return check_finish("test_morris");
}
