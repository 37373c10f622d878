/* The affine-invariant ensemble sampler of Goodman & Weare (2010, Comm.
 * App. Math. Comp. Sci. 5:65-80) with the stretch move, in the parallel
 * form of emcee (Foreman-Mackey et al. 2013, PASP 125:306, Algorithm 3):
 * the walkers are split into two halves; each walker X_k of one half moves
 * along the line to a walker X_j drawn from the other half,
 *   Y = X_j + Z (X_k - X_j),  g(z) ∝ 1/sqrt(z) on [1/a, a]  (a = 2),
 * accepted with probability min(1, Z^(d-1) pi(Y) / pi(X_k)).
 * With an unknown error variance each walker carries its own s2, updated by
 * its Gibbs step (mcmc_target.h) after each sweep.  One seeded GSL Mersenne
 * Twister: the same seed gives the same ensemble.  Pure: no I/O. */
#ifndef PHC_MCMC_STRETCH_H
#define PHC_MCMC_STRETCH_H

#include "fit/engine/mcmc_target.h"
#include "model/status.h"

typedef struct phc_stretch_options {
    size_t n_iter;   /* sweeps, the start included (>= 2) */
    size_t walkers;  /* even, >= 2 d */
    double a;        /* stretch scale (2) */
    unsigned long seed;
    phc_mcmc_progress_fn progress;
    void *progress_data;
} phc_stretch_options;

phc_stretch_options phc_stretch_options_default(void);

/* Runs the ensemble from starts x0 (walkers x d, each with a finite
 * posterior density); out->chains = walkers.  Errors: PHC_ERR_INVALID
 * (fewer than 2 d walkers or an odd number, a start outside the support,
 * a <= 1), PHC_ERR_NOMEM, PHC_ERR_INTERNAL (cancelled). */
int phc_stretch_run(const phc_mcmc_target *t, const double *x0, const phc_stretch_options *o, phc_mcmc_chains *out,
                    phc_error *err);

#endif /* PHC_MCMC_STRETCH_H */
