/* Baselines: see baseline.h. */
#include "fit/engine/baseline.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int finish(const double *y, const double *yhat, const double *sigma, size_t n, size_t k, const char *name,
                  const char *what, phc_baseline *out)
{
    phc_baseline b;
    memset(&b, 0, sizeof b);
    snprintf(b.name, sizeof b.name, "%s", name);
    snprintf(b.what, sizeof b.what, "%s", what);
    const int rc = phc_goodness_compute(y, yhat, sigma, n, k, &b.goodness);
    if (rc)
        return rc;
    *out = b;
    return PHC_OK;
}

int phc_baseline_mean(const double *y, const double *sigma, size_t n, phc_baseline *out)
{
    if (n == 0)
        return PHC_ERR_INVALID;
    double sw = 0, swy = 0;
    for (size_t i = 0; i < n; ++i) {
        const double w = sigma ? 1.0 / (sigma[i] * sigma[i]) : 1.0;
        if (!isfinite(w) || !(w > 0) || !isfinite(y[i]))
            return PHC_ERR_INVALID;
        sw += w;
        swy += w * y[i];
    }
    double *yhat = malloc(n * sizeof *yhat);
    if (!yhat)
        return PHC_ERR_NOMEM;
    for (size_t i = 0; i < n; ++i)
        yhat[i] = swy / sw;
    const int rc = finish(y, yhat, sigma, n, 1, "mean", "the mean of the data", out);
    free(yhat);
    return rc;
}

int phc_baseline_line(const double *u, const double *y, const double *sigma, size_t n, const char *name,
                      const char *what, phc_baseline *out)
{
    if (n < 3)
        return 1;
    /* centred weighted sums: b = Σ w (u − ū)(y − ȳ) / Σ w (u − ū)², a = ȳ − b ū */
    double sw = 0, su = 0, sy = 0;
    for (size_t i = 0; i < n; ++i) {
        const double w = sigma ? 1.0 / (sigma[i] * sigma[i]) : 1.0;
        if (!isfinite(w) || !(w > 0) || !isfinite(y[i]) || !isfinite(u[i]))
            return PHC_ERR_INVALID;
        sw += w;
        su += w * u[i];
        sy += w * y[i];
    }
    const double ub = su / sw, yb = sy / sw;
    double suu = 0, suy = 0, span = 0;
    for (size_t i = 0; i < n; ++i) {
        const double w = sigma ? 1.0 / (sigma[i] * sigma[i]) : 1.0;
        suu += w * (u[i] - ub) * (u[i] - ub);
        suy += w * (u[i] - ub) * (y[i] - yb);
        span = fmax(span, fabs(u[i] - ub));
    }
    if (!(span > 1e-12 * fmax(1.0, fabs(ub))) || !(suu > 0))
        return 1;
    const double b = suy / suu, a = yb - b * ub;
    double *yhat = malloc(n * sizeof *yhat);
    if (!yhat)
        return PHC_ERR_NOMEM;
    for (size_t i = 0; i < n; ++i)
        yhat[i] = a + b * u[i];
    const int rc = finish(y, yhat, sigma, n, 2, name, what, out);
    free(yhat);
    return rc;
}
