/* Convergence and summary diagnostics of MCMC chains, one parameter at a
 * time.  x holds `chains` chains of n draws each, chain after chain
 * (x[c * n + t]), burn-in already removed.  Pure: no I/O.
 *
 *  - integrated autocorrelation time (Sokal 1997, "Monte Carlo methods in
 *    statistical mechanics", §3; as emcee's `integrated_time`):
 *      rho(k) = sum_t (x_t - m)(x_{t+k} - m) / sum_t (x_t - m)^2 averaged over chains,
 *      tau(M) = 1 + 2 sum_{k=1..M} rho(k),
 *    at the smallest window M >= c tau(M) (c = 5); when no lag below n
 *    satisfies it, the last one (emcee likewise) and `reliable` = 0;
 *    emcee's rule: the estimate is trusted when n >= 50 tau; the sums for
 *    every lag come from one FFT per chain (Wiener-Khinchin, zero-padded
 *    to a power of two >= 2 n, GSL), O(n log n) instead of O(n M);
 *  - effective sample size ESS = chains n / tau;
 *  - split-R-hat (Gelman et al. 2013, BDA3 §11.4, eq. 11.3-11.4): each chain
 *    cut in halves, m = 2 chains sequences of n' = floor(n/2);
 *      B = n'/(m-1) sum_j (mean_j - mean)^2,  W = mean_j s_j^2,
 *      var+ = (n'-1)/n' W + B/n',  R-hat = sqrt(var+ / W);
 *  - mean, standard deviation, median and the 2.5% / 97.5% quantiles of
 *    the pooled draws (GSL's linear interpolation, R's type 7). */
#ifndef PHC_MCMC_DIAGNOSTICS_H
#define PHC_MCMC_DIAGNOSTICS_H

#include <stddef.h>

#include "model/status.h"

typedef struct phc_mcmc_summary {
    double mean, sd, median, q025, q975;
    double tau;     /* integrated autocorrelation time, steps */
    size_t window;  /* Sokal's window M */
    int reliable;   /* n >= 50 tau and a window was found */
    double ess;     /* chains n / tau */
    double rhat;    /* split-R-hat (NAN when n < 4) */
    double mcse_mean; /* Monte Carlo standard error of the mean: sd / sqrt(ESS) */
} phc_mcmc_summary;

/* Integrated autocorrelation time of x (chains x n), window constant c
 * (5 as emcee); *window and *reliable as above (either may be NULL). */
double phc_mcmc_autocorr_time(const double *x, size_t chains, size_t n, double c, size_t *window, int *reliable);

/* Split-R-hat of x (chains x n); NAN when n < 4. */
double phc_mcmc_split_rhat(const double *x, size_t chains, size_t n);

/* Every number above for x (chains x n, n >= 2).  PHC_ERR_NOMEM or
 * PHC_ERR_INVALID (n < 2, a non-finite draw). */
int phc_mcmc_summarise(const double *x, size_t chains, size_t n, phc_mcmc_summary *out, phc_error *err);

#endif /* PHC_MCMC_DIAGNOSTICS_H */
