/* Goodness-of-fit measures of one data set at the optimum. */
#ifndef PHC_GOODNESS_H
#define PHC_GOODNESS_H

#include <stddef.h>

#include "model/status.h"

typedef struct phc_goodness {
    size_t n;            /* observations */
    size_t k;            /* free parameters the data set depends on */
    double rss;          /* sum (y - yhat)^2, unweighted, in y units^2 */
    double wrss;         /* sum ((y - yhat)/sigma)^2 (= rss when no sigmas) */
    double rmse;         /* sqrt(rss / n) */
    double mae;          /* mean |y - yhat| */
    double bias;         /* mean (yhat - y): positive = model above data */
    double r2;           /* 1 - rss / sum (y - mean y)^2 (coefficient of determination) */
    double nse;          /* Nash–Sutcliffe efficiency; equals r2 for this definition
                            of r2 and is reported under both names (hydrology readers
                            look for NSE) */
    double reduced_chi2; /* wrss / (n - k) when sigmas are given, else NAN */
    double log_likelihood; /* Gaussian, sigma^2 estimated by ML (R's logLik.nls):
                              -n/2 (log(2 pi) + 1 - log n + log wrss) + 1/2 sum log w,
                              w = 1/sigma^2 (all 1 without sigmas) */
    double aic;          /* -2 logL + 2 (k + 1)   (the +1 counts sigma, as R does) */
    double aicc;         /* aic + 2 (k+1)(k+2) / (n - k - 2); NAN if n <= k + 2 */
    double bic;          /* -2 logL + (k + 1) log n */
} phc_goodness;

/* y: observations, yhat: model values, sigma: per-point standard deviations
 * (NULL = unweighted), n >= 1.  PHC_ERR_INVALID for n = 0 or a sigma <= 0 or
 * non-finite input (then every field but n and k is NAN).  Quantities that
 * are undefined are NAN: r2 and nse when all y are equal, reduced_chi2 when
 * n <= k, aicc when n <= k + 2, and log_likelihood, aic, aicc, bic for a
 * perfect fit (wrss = 0: the ML scale is 0 and the likelihood unbounded). */
int phc_goodness_compute(const double *y, const double *yhat,
                         const double *sigma, size_t n, size_t k,
                         phc_goodness *out);

#endif /* PHC_GOODNESS_H */
