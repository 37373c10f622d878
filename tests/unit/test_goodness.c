/* Unit tests of fit/engine/goodness.c: a hand-computed example and R's nls
 * log-likelihood / AIC / BIC.
 *
 * References: hand arithmetic (shown in comments); Python 3.11
 * /usr/bin/python3 with scipy 1.10.1 (Debian 12); R 4.2 (Debian 12,
 * r-base-core) stats::nls, logLik, AIC, BIC.  Numbers printed with "%.17g". */
#include <math.h>
#include <stddef.h>

#include "check.h"
#include "fit/engine/goodness.h"

static void test_hand_example(void)
{
    /* y = 1..5, yhat = (1.1, 1.9, 3.2, 3.7, 5.2), sigma = (0.1, 0.2, 0.1,
     * 0.4, 0.2), k = 2.
     * e = y - yhat = (-0.1, 0.1, -0.2, 0.3, -0.2)
     * rss  = 0.01 + 0.01 + 0.04 + 0.09 + 0.04 = 0.19
     * wrss = 1 + 0.25 + 4 + 0.5625 + 1 = 6.8125
     * rmse = sqrt(0.19/5) = sqrt(0.038); mae = 0.9/5 = 0.18
     * bias = mean(yhat - y) = (0.1 - 0.1 + 0.2 - 0.3 + 0.2)/5 = 0.02
     * sum (y - ybar)^2 = 10, r2 = nse = 1 - 0.019 = 0.981
     * reduced chi2 = 6.8125 / 3
     * logL: scipy.stats.norm.logpdf(y, yhat, sqrt(wrss/5)*sigma).sum()
     *       = 0.87234095781892562 (the Gaussian density with the ML scale,
     *       an independent route to the header's closed form)
     * AIC  = -2 logL + 2 (k+1) = 4.2553180843621483
     * AICc = AIC + 2*3*4/(5-2-2) = 28.255318084362148
     * BIC  = -2 logL + 3 log 5 = 3.0836318216644494 */
    const double y[5] = {1, 2, 3, 4, 5};
    const double yhat[5] = {1.1, 1.9, 3.2, 3.7, 5.2};
    const double sigma[5] = {0.1, 0.2, 0.1, 0.4, 0.2};
    phc_goodness g;
    CHECK(phc_goodness_compute(y, yhat, sigma, 5, 2, &g) == PHC_OK);
    CHECK(g.n == 5 && g.k == 2);
    CHECK_NEAR(g.rss, 0.19, 0, 1e-13);
    CHECK_NEAR(g.wrss, 6.8125, 0, 1e-13);
    CHECK_NEAR(g.rmse, sqrt(0.038), 0, 1e-13);
    CHECK_NEAR(g.mae, 0.18, 0, 1e-13);
    CHECK_NEAR(g.bias, 0.02, 1e-15, 1e-12);
    CHECK_NEAR(g.r2, 0.981, 0, 1e-13);
    CHECK_NEAR(g.nse, 0.981, 0, 1e-13);
    CHECK_NEAR(g.reduced_chi2, 6.8125 / 3.0, 0, 1e-13);
    CHECK_NEAR(g.log_likelihood, 0.87234095781892562, 0, 1e-12);
    CHECK_NEAR(g.aic, 4.2553180843621483, 0, 1e-12);
    CHECK_NEAR(g.aic, -2.0 * g.log_likelihood + 2.0 * (2 + 1), 0, 1e-15);
    CHECK_NEAR(g.aicc, 28.255318084362148, 0, 1e-12);
    CHECK_NEAR(g.bic, 3.0836318216644494, 0, 1e-12);

    /* same without sigmas: wrss = rss, no reduced chi2;
     * scipy.stats.norm.logpdf(y, yhat, sqrt(0.19/5)).sum() =
     * 1.0807301321160143, AIC = 3.8385397357679714, BIC = 2.666853473070272 */
    CHECK(phc_goodness_compute(y, yhat, NULL, 5, 2, &g) == PHC_OK);
    CHECK_NEAR(g.wrss, 0.19, 0, 1e-13);
    CHECK(isnan(g.reduced_chi2));
    CHECK_NEAR(g.log_likelihood, 1.0807301321160143, 0, 1e-12);
    CHECK_NEAR(g.aic, 3.8385397357679714, 0, 1e-12);
    CHECK_NEAR(g.bic, 2.666853473070272, 0, 1e-12);
}

static void test_r_nls(void)
{
    /* R: x <- 1:6; y <- c(1.3, 1.9, 3.2, 3.8, 5.3, 5.9);
     *    w <- c(4, 1, 4, 0.25, 1, 1)   (sigma = 1/sqrt(w))
     *    fw <- nls(y ~ a + b*x, weights = w, start = list(a = 0, b = 1))
     *    sprintf("%.17g", fitted(fw)); logLik(fw); AIC(fw); BIC(fw)
     * (attr(logLik(fw), "df") = 3 = k + 1 with k = 2) */
    const double y[6] = {1.3, 1.9, 3.2, 3.8, 5.3, 5.9};
    const double sigma[6] = {0.5, 1, 0.5, 2, 1, 1};
    const double fw[6] = {1.2607662835249043, 2.2136398467432952,
                          3.1665134099616861, 4.1193869731800765,
                          5.0722605363984679, 6.0251340996168583};
    phc_goodness g;
    CHECK(phc_goodness_compute(y, fw, sigma, 6, 2, &g) == PHC_OK);
    CHECK_NEAR(g.log_likelihood, 2.3526881652969864, 0, 1e-9);
    CHECK_NEAR(g.aic, 1.2946236694060271, 0, 1e-8);
    CHECK_NEAR(g.bic, 0.66990207709019245, 0, 1e-8);
    /* AICc: AIC + 2*3*4/(6-2-2) = AIC + 12 */
    CHECK_NEAR(g.aicc, 1.2946236694060271 + 12.0, 0, 1e-9);

    /*    fu <- nls(y ~ a*exp(b*x), start = list(a = 1, b = 0.3)) (unweighted) */
    const double fu[6] = {1.6906980810502148, 2.1972068826691613,
                          2.8554584283019291, 3.710912659191882,
                          4.8226486604253473, 6.2674447603321477};
    CHECK(phc_goodness_compute(y, fu, NULL, 6, 2, &g) == PHC_OK);
    CHECK_NEAR(g.log_likelihood, -2.1962841916943541, 0, 1e-9);
    CHECK_NEAR(g.aic, 10.392568383388708, 0, 1e-9);
    CHECK_NEAR(g.bic, 9.7678467910728735, 0, 1e-9);
}

static void test_degenerate(void)
{
    const double y[4] = {1, 2, 3, 4};
    const double yhat[4] = {1.5, 2, 2.5, 4.5};
    phc_goodness g;

    /* n = 0 */
    CHECK(phc_goodness_compute(y, yhat, NULL, 0, 1, &g) == PHC_ERR_INVALID);
    CHECK(isnan(g.rss) && isnan(g.aic) && isnan(g.r2));
    /* sigma <= 0 */
    const double s0[4] = {1, 0, 1, 1};
    CHECK(phc_goodness_compute(y, yhat, s0, 4, 1, &g) == PHC_ERR_INVALID);
    CHECK(isnan(g.rss) && isnan(g.log_likelihood));
    const double sneg[4] = {1, 1, -1, 1};
    CHECK(phc_goodness_compute(y, yhat, sneg, 4, 1, &g) == PHC_ERR_INVALID);
    const double snan[4] = {1, 1, NAN, 1};
    CHECK(phc_goodness_compute(y, yhat, snan, 4, 1, &g) == PHC_ERR_INVALID);
    /* non-finite data */
    const double ynan[4] = {1, NAN, 3, 4};
    CHECK(phc_goodness_compute(ynan, yhat, NULL, 4, 1, &g) == PHC_ERR_INVALID);
    CHECK(isnan(g.rss) && isnan(g.mae));
    const double yinf[4] = {1, 2, 3, INFINITY};
    CHECK(phc_goodness_compute(y, yinf, NULL, 4, 1, &g) == PHC_ERR_INVALID);
    CHECK(phc_goodness_compute(NULL, yhat, NULL, 4, 1, &g) == PHC_ERR_INVALID);
    CHECK(phc_goodness_compute(y, yhat, NULL, 4, 1, NULL) == PHC_ERR_INVALID);

    /* all y equal: r2 and nse undefined, the rest defined */
    const double yc[4] = {2, 2, 2, 2};
    CHECK(phc_goodness_compute(yc, yhat, NULL, 4, 1, &g) == PHC_OK);
    CHECK(isnan(g.r2) && isnan(g.nse));
    CHECK_NEAR(g.rss, 0.25 + 0 + 0.25 + 6.25, 0, 1e-14);

    /* n <= k + 2: AICc undefined; n <= k: reduced chi2 undefined */
    const double s1[4] = {1, 1, 1, 1};
    CHECK(phc_goodness_compute(y, yhat, s1, 4, 2, &g) == PHC_OK);
    CHECK(isnan(g.aicc) && !isnan(g.aic) && !isnan(g.bic));
    CHECK_NEAR(g.reduced_chi2, 0.75 / 2.0, 0, 1e-14);
    CHECK(phc_goodness_compute(y, yhat, s1, 4, 4, &g) == PHC_OK);
    CHECK(isnan(g.reduced_chi2));

    /* perfect fit: likelihood unbounded, criteria NAN; r2 = 1 */
    CHECK(phc_goodness_compute(y, y, NULL, 4, 1, &g) == PHC_OK);
    CHECK(g.rss == 0.0 && g.r2 == 1.0);
    CHECK(isnan(g.log_likelihood) && isnan(g.aic) && isnan(g.aicc) && isnan(g.bic));

    /* n = 1 works (no r2) */
    CHECK(phc_goodness_compute(y, yhat, NULL, 1, 0, &g) == PHC_OK);
    CHECK_NEAR(g.rmse, 0.5, 0, 1e-15);
    CHECK(isnan(g.r2));
}

int main(void)
{
    test_hand_example();
    test_r_nls();
    test_degenerate();
    return check_finish("test_goodness");
}
