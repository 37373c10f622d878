/* Goodness-of-fit measures of one data set: see goodness.h.
 *
 * Information criteria follow R's logLik.nls / AIC / BIC (R Core Team,
 * src/library/stats/R/nls.R): for weights w_i = 1/sigma_i^2 and the weighted
 * residual sum of squares wrss = sum w_i (y_i - yhat_i)^2, the Gaussian
 * log-likelihood maximised over the common scale s^2 (s^2_ML = wrss / n,
 * Var(y_i) = s^2 / w_i) is
 *   logL = -n/2 (log(2 pi) + 1 - log n + log wrss) + 1/2 sum log w_i,
 * and with k + 1 estimated quantities (k parameters and s):
 *   AIC  = -2 logL + 2 (k + 1)                        (Akaike 1974),
 *   AICc = AIC + 2 (k + 1)(k + 2) / (n - k - 2)       (Hurvich & Tsai 1989),
 *   BIC  = -2 logL + (k + 1) log n                    (Schwarz 1978).
 * The Nash-Sutcliffe efficiency (Nash & Sutcliffe 1970, eq. 1)
 * NSE = 1 - sum (y - yhat)^2 / sum (y - ybar)^2 is the same number as the
 * coefficient of determination defined that way. */
#include "fit/engine/goodness.h"

#include <math.h>

#include <gsl/gsl_math.h> /* M_PI under strict C11 */

static void goodness_fill_nan(phc_goodness *g, size_t n, size_t k)
{
    g->n = n;
    g->k = k;
    g->rss = g->wrss = g->rmse = g->mae = g->bias = NAN;
    g->r2 = g->nse = g->reduced_chi2 = NAN;
    g->log_likelihood = g->aic = g->aicc = g->bic = NAN;
}

int phc_goodness_compute(const double *y, const double *yhat,
                         const double *sigma, size_t n, size_t k,
                         phc_goodness *out)
{
    if (!out)
        return PHC_ERR_INVALID;
    goodness_fill_nan(out, n, k);
    if (!y || !yhat || n == 0)
        return PHC_ERR_INVALID;
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(y[i]) || !isfinite(yhat[i]))
            return PHC_ERR_INVALID;
        if (sigma && !(isfinite(sigma[i]) && sigma[i] > 0.0))
            return PHC_ERR_INVALID;
    }

    const double dn = (double)n;
    double rss = 0.0, wrss = 0.0, sum_abs = 0.0, sum_dev = 0.0;
    double sum_log_sigma = 0.0, ybar = 0.0;
    int y_constant = 1;
    for (size_t i = 0; i < n; ++i) {
        double e = y[i] - yhat[i];
        rss += e * e;
        sum_abs += fabs(e);
        sum_dev += yhat[i] - y[i];
        if (sigma) {
            double ew = e / sigma[i];
            wrss += ew * ew;
            sum_log_sigma += log(sigma[i]);
        }
        ybar += y[i];
        if (y[i] != y[0])
            y_constant = 0;
    }
    if (!sigma)
        wrss = rss;
    ybar /= dn;

    out->rss = rss;
    out->wrss = wrss;
    out->rmse = sqrt(rss / dn);
    out->mae = sum_abs / dn;
    out->bias = sum_dev / dn;

    if (!y_constant) {
        double sst = 0.0;
        for (size_t i = 0; i < n; ++i)
            sst += (y[i] - ybar) * (y[i] - ybar);
        if (sst > 0.0)
            out->r2 = 1.0 - rss / sst;
    }
    out->nse = out->r2;

    if (sigma && n > k)
        out->reduced_chi2 = wrss / (dn - (double)k);

    /* A perfect fit (wrss = 0) has an unbounded likelihood (s_ML = 0): the
     * criteria are then reported as undefined (NAN) rather than +-infinity. */
    if (wrss > 0.0 && isfinite(wrss)) {
        /* 1/2 sum log w_i = -sum log sigma_i */
        double ll = -0.5 * dn * (log(2.0 * M_PI) + 1.0 - log(dn) + log(wrss)) -
                    sum_log_sigma;
        double np = (double)k + 1.0; /* parameters + the scale s */
        out->log_likelihood = ll;
        out->aic = -2.0 * ll + 2.0 * np;
        if (n > k + 2)
            out->aicc = out->aic + 2.0 * np * (np + 1.0) / (dn - (double)k - 2.0);
        out->bic = -2.0 * ll + np * log(dn);
    }
    return PHC_OK;
}
