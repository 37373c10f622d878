/* The affine-invariant ensemble sampler of Goodman & Weare (2010, Comm.
 * App. Math. Comp. Sci. 5:65-80) with the stretch move, in the parallel
 * form of emcee (Foreman-Mackey et al. 2013, PASP 125:306, Algorithm 3):
 * the walkers are split into two halves; each walker X_k of one half moves
 * along the line to a walker X_j drawn from the other half,
 *   Y = X_j + Z (X_k - X_j),  g(z) ∝ 1/sqrt(z) on [1/a, a]  (a = 2),
 * accepted with probability min(1, Z^(d-1) pi(Y) / pi(X_k)).
 * With an unknown error variance each walker carries its own s2, updated by
 * its Gibbs step (mcmc_target.h) after each sweep.  One seeded GSL Mersenne
 * Twister: the same seed gives the same ensemble.  Pure: no I/O.
 *
 * Order of the random draws in a half-ensemble update (emcee's
 * RedBlueMove.propose and StretchMove.get_proposal): the half's W/2
 * stretch factors z, then its W/2 partner walkers j, then every proposal's
 * density, then W/2 acceptance uniforms in walker order, one per walker
 * whatever its proposal's density.  The stream therefore never depends on
 * a density, so the proposals of a half can be evaluated anywhere (on
 * other processes: phc_stretch_share) with the same result bit for bit. */
#ifndef PHC_MCMC_STRETCH_H
#define PHC_MCMC_STRETCH_H

#include "fit/engine/mcmc_target.h"
#include "model/status.h"

/* Sharing the density evaluations among processes (MPI ranks) that all run
 * the same sampler with the same seed, and so draw the same proposals.  For
 * a batch of n evaluations (the W starts, then each half's W/2 proposals)
 * block() gives the rows [lo, hi) this process evaluates; exchange() then
 * makes every process hold all n rows of PHC_STRETCH_ROW doubles (SS and
 * log prior; NAN where the density is 0), bit for bit: one collective per
 * batch; it fails on every process alike or on none.  agree() is
 * collective too: once before the first exchange with this process's
 * set-up status, and every 50 sweeps after the progress report (whether or
 * not there is a progress callback); it returns 0 when every process's
 * status is 0, else the status to stop with (err set), the same on every
 * process. */
#define PHC_STRETCH_ROW 2
typedef struct phc_stretch_share {
    void (*block)(void *data, size_t n, size_t *lo, size_t *hi);
    int (*exchange)(void *data, double *v, size_t n, phc_error *err); /* non-zero stops every process */
    int (*agree)(void *data, int status, phc_error *err);
    void *data;
} phc_stretch_share;

typedef struct phc_stretch_options {
    size_t n_iter;   /* sweeps, the start included (>= 2) */
    size_t walkers;  /* even, >= 2 d */
    double a;        /* stretch scale (2) */
    unsigned long seed;
    phc_mcmc_progress_fn progress;
    void *progress_data;
    const phc_stretch_share *share; /* NULL: every proposal evaluated here */
} phc_stretch_options;

phc_stretch_options phc_stretch_options_default(void);

/* Runs the ensemble from starts x0 (walkers x d, each with a finite
 * posterior density); out->chains = walkers.  Errors: PHC_ERR_INVALID
 * (fewer than 2 d walkers or an odd number, a start outside the support,
 * a <= 1), PHC_ERR_NOMEM, PHC_ERR_INTERNAL (cancelled), or what
 * share->agree returned.  With a share every process returns the same
 * status, once every process gave the same d, W and n_iter. */
int phc_stretch_run(const phc_mcmc_target *t, const double *x0, const phc_stretch_options *o, phc_mcmc_chains *out,
                    phc_error *err);

#endif /* PHC_MCMC_STRETCH_H */
