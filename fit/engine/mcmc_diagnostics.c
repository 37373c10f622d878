/* MCMC diagnostics: see mcmc_diagnostics.h. */
#include "fit/engine/mcmc_diagnostics.h"

#include <gsl/gsl_fft_halfcomplex.h>
#include <gsl/gsl_fft_real.h>
#include <gsl/gsl_sort.h>
#include <gsl/gsl_statistics_double.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The chains' autocorrelation averaged over the chains that moved:
 * rho[k] = mean over chains of sum_t (x_t - m)(x_{t+k} - m) / sum_t (x_t - m)^2,
 * k = 0 .. n - 1, by the Wiener-Khinchin theorem: the sums for every lag at
 * once are the inverse FFT of |FFT(x - m)|^2 with x zero-padded to a power
 * of two L >= 2 n (no wrap-around), O(L log L) per chain where the sums lag
 * by lag cost O(n) each (GSL's radix-2 real FFT, halfcomplex layout).
 * Returns the number of chains used (0: none moved), -1 out of memory. */
static long mean_autocorr(const double *x, size_t chains, size_t n, double *rho)
{
    size_t L = 1;
    while (L < 2 * n)
        L <<= 1;
    double *f = malloc(L * sizeof *f);
    if (!f)
        return -1;
    memset(rho, 0, n * sizeof *rho);
    long used = 0;
    for (size_t ch = 0; ch < chains; ++ch) {
        const double *v = x + ch * n;
        double s = 0;
        for (size_t t = 0; t < n; ++t)
            s += v[t];
        const double mean = s / (double)n;
        for (size_t t = 0; t < n; ++t)
            f[t] = v[t] - mean;
        memset(f + n, 0, (L - n) * sizeof *f);
        gsl_fft_real_radix2_transform(f, 1, L);
        /* halfcomplex: f[0] and f[L/2] real, f[k] + i f[L-k] for 0 < k < L/2 */
        f[0] *= f[0];
        f[L / 2] *= f[L / 2];
        for (size_t k = 1; k < L / 2; ++k) {
            f[k] = f[k] * f[k] + f[L - k] * f[L - k];
            f[L - k] = 0;
        }
        gsl_fft_halfcomplex_radix2_inverse(f, 1, L);
        if (!(f[0] > 0))
            continue; /* a chain that never moved: no autocorrelation to average */
        for (size_t k = 0; k < n; ++k)
            rho[k] += f[k] / f[0];
        ++used;
    }
    free(f);
    if (used)
        for (size_t k = 0; k < n; ++k)
            rho[k] /= (double)used;
    return used;
}

double phc_mcmc_autocorr_time(const double *x, size_t chains, size_t n, double c, size_t *window, int *reliable)
{
    if (window)
        *window = 0;
    if (reliable)
        *reliable = 0;
    if (n < 2 || chains == 0)
        return NAN;
    double *rho = malloc(n * sizeof *rho);
    const long used = rho ? mean_autocorr(x, chains, n, rho) : -1;
    free(used > 0 ? NULL : rho);
    if (used < 0)
        return NAN;
    if (used == 0) { /* no chain moved */
        if (window)
            *window = 1;
        return NAN;
    }
    double tau = 1; /* rho(0) = 1 */
    size_t m;
    int found = 0;
    for (m = 1; m < n; ++m) {
        tau += 2 * rho[m];
        if ((double)m >= c * tau) {
            found = 1;
            break;
        }
    }
    free(rho);
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

static void swap_d(double *v, size_t a, size_t b)
{
    const double t = v[a];
    v[a] = v[b];
    v[b] = t;
}

/* Reorders v[0..n-1] so that v[k] is its k-th smallest value, with nothing
 * larger before it and nothing smaller after it (Hoare's selection,
 * median-of-three pivot): expected O(n), where a sort takes O(n log n). */
static void select_kth(double *v, size_t n, size_t k)
{
    size_t lo = 0, hi = n - 1;
    while (hi > lo) {
        const size_t mid = lo + (hi - lo) / 2;
        if (v[mid] < v[lo])
            swap_d(v, lo, mid);
        if (v[hi] < v[lo])
            swap_d(v, lo, hi);
        if (v[hi] < v[mid])
            swap_d(v, mid, hi);
        const double pivot = v[mid];
        size_t i = lo, j = hi;
        for (;;) {
            while (v[i] < pivot)
                ++i;
            while (v[j] > pivot)
                --j;
            if (i >= j)
                break;
            swap_d(v, i, j);
            ++i;
            --j;
        }
        /* now v[lo..j] <= pivot <= v[j+1..hi] */
        if (k <= j)
            hi = j;
        else
            lo = j + 1;
    }
}

/* The f-quantile of v (n values, reordered here), the value
 * gsl_stats_quantile_from_sorted_data gives on the sorted values: that
 * function reads the order statistics at floor(f (n - 1)) and the next
 * one, which are put in their sorted places first. */
static double quantile_select(double *v, size_t n, double f)
{
    const size_t lhs = (size_t)(int)(f * (double)(n - 1));
    select_kth(v, n, lhs);
    if (lhs + 1 < n) {
        size_t next = lhs + 1;
        for (size_t i = lhs + 2; i < n; ++i)
            if (v[i] < v[next])
                next = i;
        swap_d(v, lhs + 1, next);
    }
    return gsl_stats_quantile_from_sorted_data(v, 1, n, f);
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
    out->mean = gsl_stats_mean(x, 1, total);
    out->sd = gsl_stats_sd_m(x, 1, total, out->mean);
    out->median = quantile_select(sorted, total, 0.5);
    out->q025 = quantile_select(sorted, total, 0.025);
    out->q975 = quantile_select(sorted, total, 0.975);
    free(sorted);
    out->tau = phc_mcmc_autocorr_time(x, chains, n, 5.0, &out->window, &out->reliable);
    out->ess = isfinite(out->tau) && out->tau > 0 ? (double)total / out->tau : NAN;
    out->rhat = phc_mcmc_split_rhat(x, chains, n);
    out->mcse_mean = out->ess > 0 ? out->sd / sqrt(out->ess) : NAN;
    return PHC_OK;
}
