/* MCMC diagnostics: see mcmc_diagnostics.h. */
#include "fit/engine/mcmc_diagnostics.h"

#include <gsl/gsl_sort.h>
#include <gsl/gsl_statistics_double.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

double phc_mcmc_autocorr_time(const double *x, size_t chains, size_t n, double c, size_t *window, int *reliable)
{
    if (window)
        *window = 0;
    if (reliable)
        *reliable = 0;
    if (n < 2 || chains == 0)
        return NAN;
    double *mean = malloc(chains * sizeof *mean), *var = malloc(chains * sizeof *var);
    if (!mean || !var) {
        free(mean);
        free(var);
        return NAN;
    }
    for (size_t ch = 0; ch < chains; ++ch) {
        const double *v = x + ch * n;
        double s = 0;
        for (size_t t = 0; t < n; ++t)
            s += v[t];
        mean[ch] = s / (double)n;
        double q = 0;
        for (size_t t = 0; t < n; ++t)
            q += (v[t] - mean[ch]) * (v[t] - mean[ch]);
        var[ch] = q;
    }
    double tau = 1; /* rho(0) = 1 */
    size_t m;
    int found = 0;
    for (m = 1; m < n; ++m) {
        double rho = 0;
        size_t used = 0;
        for (size_t ch = 0; ch < chains; ++ch) {
            if (!(var[ch] > 0))
                continue; /* a chain that never moved: no autocorrelation to average */
            const double *v = x + ch * n;
            double s = 0;
            for (size_t t = 0; t + m < n; ++t)
                s += (v[t] - mean[ch]) * (v[t + m] - mean[ch]);
            rho += s / var[ch];
            ++used;
        }
        if (!used) {
            tau = NAN;
            break;
        }
        tau += 2 * rho / (double)used;
        if ((double)m >= c * tau) {
            found = 1;
            break;
        }
    }
    free(mean);
    free(var);
    if (window)
        *window = m < n ? m : n - 1;
    if (reliable)
        *reliable = found && isfinite(tau) && (double)n >= 50 * tau;
    return tau;
}

double phc_mcmc_split_rhat(const double *x, size_t chains, size_t n)
{
    const size_t h = n / 2, m = 2 * chains;
    if (h < 2 || chains == 0)
        return NAN;
    double grand = 0, w = 0, b = 0;
    double *means = malloc(m * sizeof *means);
    if (!means)
        return NAN;
    for (size_t ch = 0; ch < chains; ++ch)
        for (size_t part = 0; part < 2; ++part) {
            /* the first and the last h draws (the middle one is left out when n is odd) */
            const double *v = x + ch * n + (part ? n - h : 0);
            const double mu = gsl_stats_mean(v, 1, h);
            means[2 * ch + part] = mu;
            grand += mu;
            w += gsl_stats_variance_m(v, 1, h, mu);
        }
    grand /= (double)m;
    w /= (double)m;
    for (size_t j = 0; j < m; ++j)
        b += (means[j] - grand) * (means[j] - grand);
    free(means);
    b *= (double)h / (double)(m - 1);
    if (!(w > 0))
        return b > 0 ? INFINITY : NAN;
    const double var_plus = ((double)h - 1) / (double)h * w + b / (double)h;
    return sqrt(var_plus / w);
}

int phc_mcmc_summarise(const double *x, size_t chains, size_t n, phc_mcmc_summary *out, phc_error *err)
{
    memset(out, 0, sizeof *out);
    const size_t total = chains * n;
    if (n < 2 || chains == 0)
        return phc_error_set(err, PHC_ERR_INVALID, "MCMC summary: %zu chains of %zu draws", chains, n);
    for (size_t i = 0; i < total; ++i)
        if (!isfinite(x[i]))
            return phc_error_set(err, PHC_ERR_INVALID, "MCMC summary: draw %zu is not finite", i);
    double *sorted = malloc(total * sizeof *sorted);
    if (!sorted)
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    memcpy(sorted, x, total * sizeof *sorted);
    gsl_sort(sorted, 1, total);
    out->mean = gsl_stats_mean(x, 1, total);
    out->sd = gsl_stats_sd_m(x, 1, total, out->mean);
    out->median = gsl_stats_quantile_from_sorted_data(sorted, 1, total, 0.5);
    out->q025 = gsl_stats_quantile_from_sorted_data(sorted, 1, total, 0.025);
    out->q975 = gsl_stats_quantile_from_sorted_data(sorted, 1, total, 0.975);
    free(sorted);
    out->tau = phc_mcmc_autocorr_time(x, chains, n, 5.0, &out->window, &out->reliable);
    out->ess = isfinite(out->tau) && out->tau > 0 ? (double)total / out->tau : NAN;
    out->rhat = phc_mcmc_split_rhat(x, chains, n);
    out->mcse_mean = out->ess > 0 ? out->sd / sqrt(out->ess) : NAN;
    return PHC_OK;
}
