/* Adaptive Metropolis with delayed rejection (DRAM; Haario, Laine, Mira &
 * Saksman 2006, Stat. Comput. 16:339-354), as R FME's modMCMC (Soetaert &
 * Petzoldt 2010):
 *   - Gaussian random-walk proposal N(x, C); C starts from cov0 (the fit's
 *     covariance) scaled by s_d = 2.4^2 / d (Gelman, Roberts & Gilks 1996);
 *   - adaptation (Haario, Saksman & Tamminen 2001, eq. 3): every
 *     `adapt_every` steps C = s_d (Cov(chain so far) + eps D), D the
 *     diagonal of that covariance and eps = 1e-10 (Haario's eps I in
 *     coordinates scaled by each parameter's sd, so parameters of very
 *     different magnitudes keep their scales); an update that is not
 *     positive definite (nothing accepted yet) keeps the old C;
 *   - one delayed-rejection stage (Tierney & Mira 1999; Haario et al. 2006
 *     §2.2): after a rejection, a second proposal y2 ~ N(x, gamma^2 C),
 *     accepted with probability
 *       a2 = min(1, pi(y2) q1(y2, y1) (1 - a1(y2, y1)) / (pi(x) q1(x, y1) (1 - a1(x, y1))))
 *     with q1 the first-stage Gaussian density and a1 its acceptance.
 * Independent chains (for split-R-hat) run one after the other, each with its
 * own seeded GSL Mersenne Twister: the same seed gives the same chains.
 * Pure: no I/O. */
#ifndef PHC_MCMC_DRAM_H
#define PHC_MCMC_DRAM_H

#include "fit/engine/mcmc_target.h"
#include "model/status.h"

typedef struct phc_dram_options {
    size_t n_iter;       /* draws per chain, the start included (>= 2) */
    size_t chains;       /* independent chains (>= 1) */
    size_t adapt_every;  /* steps between covariance updates (100; 0 = no adaptation) */
    double dr_scale;     /* gamma of the second stage (0.2; 0 = no delayed rejection) */
    unsigned long seed;  /* chain c draws from its own Mersenne Twister seeded seed + 7919 c, so
                            that a chain does not depend on the others (resume) */
    phc_mcmc_progress_fn progress;
    void *progress_data;
    /* Resume (optional): chains with have[c] = 1 are not run; their draws
       come from have_draws (laid out as phc_mcmc_chains' arrays, chains x
       n_iter) and their counts from have_counts[4 c ..]: accepted,
       accepted_dr, proposed, failed. */
    const unsigned char *have;
    const phc_mcmc_chains *have_draws;
    const size_t *have_counts;
    /* Called after each chain that was run (counts as above); non-zero stops
       the run with that status (the caller has set err). */
    int (*chain_done)(void *data, size_t c, const phc_mcmc_chains *out, const size_t counts[4], phc_error *err);
    void *chain_data;
} phc_dram_options;

phc_dram_options phc_dram_options_default(void);

/* Runs the chains from starts x0 (chains x d: each chain its own start;
 * every start must have a finite posterior density) with initial proposal
 * covariance cov0 (d x d, symmetric positive definite, before scaling).
 * Fills *out (arrays malloc'd; phc_mcmc_chains_clear frees). Errors:
 * PHC_ERR_INVALID (a start outside the support, cov0 not positive
 * definite), PHC_ERR_NOMEM, PHC_ERR_INTERNAL (cancelled). */
int phc_dram_run(const phc_mcmc_target *t, const double *x0, const double *cov0, const phc_dram_options *o,
                 phc_mcmc_chains *out, phc_error *err);

void phc_mcmc_chains_clear(phc_mcmc_chains *c);

#endif /* PHC_MCMC_DRAM_H */
