/* Unit tests of fit/engine/prior.c: inverse CDFs against closed forms and
 * tabulated normal quantiles, truncation, and the errors.
 *
 * References: Phi^-1(0.975) = 1.959963984540054, Phi^-1(0.75) =
 * 0.6744897501960817 (Abramowitz & Stegun 26.2; also R qnorm). */
#include <math.h>

#include "check.h"
#include "fit/engine/prior.h"

static phc_prior make(phc_prior_kind kind, double a, double b)
{
    phc_prior p = {kind, a, b, -INFINITY, INFINITY};
    return p;
}

static void test_quantiles(void)
{
    phc_error err;
    phc_prior r;
    /* no prior: uniform on the bounds */
    phc_prior none = make(PHC_PRIOR_NONE, 0, 0);
    CHECK(phc_prior_resolve(&none, 2, 6, "p", &r, &err) == PHC_OK);
    CHECK(r.kind == PHC_PRIOR_UNIFORM);
    CHECK_NEAR(phc_prior_quantile(&r, 0.25), 3.0, 0, 1e-15);
    CHECK_NEAR(phc_prior_quantile(&r, 0), 2.0, 0, 0);
    CHECK_NEAR(phc_prior_quantile(&r, 1), 6.0, 0, 0);
    CHECK(isnan(phc_prior_quantile(&r, 1.5)));
    /* log-uniform on [1e-3, 1e1]: u = 0.5 is the geometric mean 1e-1 */
    phc_prior lu = make(PHC_PRIOR_LOG_UNIFORM, 1e-3, 10);
    CHECK(phc_prior_resolve(&lu, 0, INFINITY, "p", &r, &err) == PHC_OK);
    CHECK_NEAR(phc_prior_quantile(&r, 0.5), 0.1, 0, 1e-14);
    CHECK_NEAR(phc_prior_quantile(&r, 0.75), 1.0, 0, 1e-14);
    /* normal(3, 2): 97.5% quantile 3 + 2 * 1.959963984540054 */
    phc_prior nr = make(PHC_PRIOR_NORMAL, 3, 2);
    CHECK(phc_prior_resolve(&nr, -INFINITY, INFINITY, "p", &r, &err) == PHC_OK);
    CHECK_NEAR(phc_prior_quantile(&r, 0.975), 3 + 2 * 1.959963984540054, 0, 1e-12);
    CHECK_NEAR(phc_prior_quantile(&r, 0.025), 3 - 2 * 1.959963984540054, 0, 1e-12);
    CHECK_NEAR(phc_prior_median(&r), 3.0, 0, 1e-15);
    CHECK(isnan(phc_prior_quantile(&r, 0)));
    /* right tail keeps its digits: 1 - 1e-12 */
    CHECK_NEAR(phc_prior_quantile(&r, 1 - 1e-12), 3 + 2 * 7.0344869100478356, 0, 1e-6);
    /* truncated to [3, inf): the median is the 75% quantile of the full normal */
    CHECK(phc_prior_resolve(&nr, 3, INFINITY, "p", &r, &err) == PHC_OK);
    CHECK_NEAR(phc_prior_median(&r), 3 + 2 * 0.6744897501960817, 0, 1e-12);
    CHECK(phc_prior_quantile(&r, 1e-9) >= 3.0);
    /* log-normal: median exp(meanlog); 97.5% exp(meanlog + 1.96 sdlog) */
    phc_prior ln = make(PHC_PRIOR_LOG_NORMAL, log(5.0), 0.5);
    CHECK(phc_prior_resolve(&ln, 0, INFINITY, "p", &r, &err) == PHC_OK);
    CHECK_NEAR(phc_prior_median(&r), 5.0, 0, 1e-14);
    CHECK_NEAR(phc_prior_quantile(&r, 0.975), 5.0 * exp(0.5 * 1.959963984540054), 0, 1e-12);
    /* monotone over a fine grid, and the inverse of the CDF by bisection-free
       check: F(Q(u)) = u for the uniform kinds */
    double last = -INFINITY;
    int monotone = 1;
    for (int i = 1; i < 1000; ++i) {
        const double q = phc_prior_quantile(&r, i / 1000.0);
        monotone &= q > last;
        last = q;
    }
    CHECK(monotone);
    CHECK(phc_prior_kind_parse("log-normal") == PHC_PRIOR_LOG_NORMAL);
    CHECK(phc_prior_kind_parse("lognormal") == PHC_PRIOR_LOG_NORMAL);
    CHECK(phc_prior_kind_parse("gamma") == -1);
}

static void test_errors(void)
{
    phc_error err;
    phc_prior r;
    phc_prior none = make(PHC_PRIOR_NONE, 0, 0);
    CHECK(phc_prior_resolve(&none, 0, INFINITY, "cfg.yaml:4: parameter 'k'", &r, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "cfg.yaml:4: parameter 'k': a sensitivity study needs finite bounds");
    phc_prior bad_sd = make(PHC_PRIOR_NORMAL, 1, 0);
    CHECK(phc_prior_resolve(&bad_sd, -INFINITY, INFINITY, "k", &r, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "sd positive");
    phc_prior bad_lu = make(PHC_PRIOR_LOG_UNIFORM, 0, 1);
    CHECK(phc_prior_resolve(&bad_lu, -INFINITY, INFINITY, "k", &r, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "lower must be positive");
    phc_prior bad_u = make(PHC_PRIOR_UNIFORM, 2, 1);
    CHECK(phc_prior_resolve(&bad_u, -INFINITY, INFINITY, "k", &r, &err) == PHC_ERR_INPUT);
    phc_prior out_u = make(PHC_PRIOR_UNIFORM, -1, 1);
    CHECK(phc_prior_resolve(&out_u, 0, 2, "k", &r, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "outside the bounds");
    /* a normal far outside its truncation interval holds no probability */
    phc_prior far = make(PHC_PRIOR_NORMAL, 100, 1);
    CHECK(phc_prior_resolve(&far, 0, 1, "k", &r, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "no probability");
}

int main(void)
{
    test_quantiles();
    test_errors();
    return check_finish("test_prior");
}
