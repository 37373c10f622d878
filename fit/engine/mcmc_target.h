/* The posterior an MCMC sampler (mcmc_dram.h, mcmc_stretch.h) draws from:
 *
 *   log p(theta | y, s2) = -SS(theta) / (2 s2) + log prior(theta)   (+ const)
 *
 * with SS the sum of squared (weighted) residuals of the model at theta
 * (Gaussian errors).  With known sigmas the residuals are already divided by
 * them and s2 = 1.  Otherwise the error variance s2 is sampled after every
 * step from its conjugate inverse-gamma full conditional (Gelman et al.,
 * BDA3 §14.8; as R FME's modMCMC with var0 / wvar0, Soetaert & Petzoldt
 * 2010, J. Stat. Softw. 33(3) §4):
 *
 *   s2 | theta, y ~ IG(shape (n0 + n) / 2, rate (n0 var0 + SS(theta)) / 2)
 *
 * a prior IG(n0/2, n0 var0/2) worth n0 observations at variance var0.
 * Pure: no I/O. */
#ifndef PHC_MCMC_TARGET_H
#define PHC_MCMC_TARGET_H

#include <stddef.h>

typedef struct phc_mcmc_target {
    size_t d; /* parameters sampled */
    /* 0: *ss and *log_prior set; non-zero: theta outside the prior's
       support or the model failed there (posterior density 0) */
    int (*eval)(void *data, const double *theta, double *ss, double *log_prior);
    void *data;
    int sample_sigma2;   /* 0: known sigmas, s2 = 1; 1: Gibbs step for s2 */
    size_t n_obs;        /* n of the full conditional */
    double var0, n0;     /* prior of s2 (sample_sigma2 only; var0 > 0, n0 >= 0) */
} phc_mcmc_target;

/* Where a sampler's draws go: chains x iterations x d, row-major
 * (theta[(c * n_iter + t) * d + j]); s2[c * n_iter + t] the error
 * variance at that draw (1 with known sigmas); log_post the log posterior
 * density there (given s2). */
typedef struct phc_mcmc_chains {
    size_t chains, n_iter, d;
    double *theta, *s2, *log_post;
    size_t accepted, proposed; /* over all chains (DRAM: both stages count as one proposal) */
    size_t accepted_dr;        /* DRAM: accepted at the delayed-rejection stage */
    size_t failed;             /* proposals where the model failed or left the support */
} phc_mcmc_chains;

/* Progress: done of total steps; non-zero return cancels. */
typedef int (*phc_mcmc_progress_fn)(void *data, size_t done, size_t total);

#endif /* PHC_MCMC_TARGET_H */
