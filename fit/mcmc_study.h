/* `phytocal mcmc`: the Bayesian posterior of a problem's free parameters by
 * Markov chain Monte Carlo, written as a run directory.
 *
 * Posterior (fit/engine/mcmc_target.h): Gaussian likelihood of the weighted
 * residuals the engine computes (phc_study_evaluate's cost = SS / 2) times
 * the prior: each free parameter's `prior:` from the config, else uniform
 * on its bounds; a parameter with an open bound and no prior gets the flat
 * improper prior on its bounds (the report says which).  Parameters are
 * sampled in the user's unit (the config's) and converted to the slots'
 * units for the model.  Fixed parameters keep their values.
 * The error scale: when every data set gives sigmas they are the known
 * standard deviations; otherwise the residual variance s2 is sampled from
 * its inverse-gamma full conditional with var0 = the fit's s2 and n0 = 0.1 n
 * (FME modMCMC's wvar0 = 0.1).
 *
 * The fit (phc_fit_run) runs first: its optimum starts chain 1 (DRAM) and
 * its covariance (standard errors and correlations) the proposal; other
 * chains / walkers start at draws from N(optimum, covariance) inside the
 * support.  Burn-in: the first half of every chain.
 *
 * The run directory (run_dir.h rules): result.json (per parameter: mean,
 * sd, median, 95% interval, tau, ESS, split-R-hat; the sampler's settings and
 * acceptance; the kept chains thinned to at most 500 draws each), report.md
 * (verdict: the chains mixed when every R-hat < 1.01 and every ESS > 400),
 * mcmc_trace.png, mcmc_pairs.png and the manifest.
 *
 * Resume (DRAM): every finished chain goes to the run ledger
 * (fit/run_ledger.h) at DIR.ledger, one row per chain (its counts, then its
 * draws, error variances and log posterior densities at full precision);
 * `resume` takes the chains it holds and runs the others (each chain has its
 * own seeded generator, so the result equals an uninterrupted run's).  The
 * ledger is removed when the run directory is written.  The stretch ensemble
 * moves all walkers together and cannot resume. */
#ifndef PHC_MCMC_STUDY_H
#define PHC_MCMC_STUDY_H

#include <stddef.h>

#include "fit/engine/problem.h"
#include "fit/engine/progress.h"
#include "fit/engine/provenance.h"
#include "model/status.h"

typedef enum phc_mcmc_method { PHC_MCMC_DRAM = 0, PHC_MCMC_STRETCH = 1 } phc_mcmc_method;

/* Fewest draws per chain (sweeps per walker): split-R-hat cuts the kept
 * half in two, and the autocorrelation window needs room. */
#define PHC_MCMC_MIN_SAMPLES 100

typedef struct phc_mcmc_options {
    phc_mcmc_method method;
    size_t samples;      /* draws per chain (DRAM, default 5000) or sweeps (stretch, default 10000) */
    size_t chains;       /* DRAM: chains (default 4); stretch: walkers (default max(32, 2 d), even) */
    unsigned long seed;  /* (1) */
    int force;           /* replace DIR and a stale DIR.ledger */
    int resume;          /* DRAM: take the chains DIR.ledger holds, run the others */
    size_t stop_after;   /* for tests: stop after this many chains, as a killed run would (0: never) */
    phc_progress_fn progress;
    void *progress_data;
    /* NULL: one process.  Else the processes of an MPI run
       (fit/study_dist.h, phc_dist_open): every rank calls phc_mcmc_run and
       fits the same start.  DRAM: the chains are shared out (one chain per
       message; a chain is sequential, each has its own seeded generator),
       rank 0 records each in DIR.ledger as it arrives and writes DIR,
       identical to one process's; --resume works as in one process.
       Stretch: every rank runs the ensemble with the same generator (so
       draws the same proposals), evaluates its contiguous block of the
       starts and of each half's proposals, and one all-gather per
       half-step gives every rank every density, so every rank makes the
       same acceptance draws (mcmc_stretch.h: the draws never depend on a
       density); DIR is one process's, report.md's count of model
       evaluations included (the ranks' counts, summed).  The workers
       return PHC_OK with an empty summary. */
    struct phc_dist *dist;
} phc_mcmc_options;

phc_mcmc_options phc_mcmc_options_default(void);

typedef struct phc_mcmc_run_summary {
    int mixed;           /* every R-hat < 1.01 and ESS > 400 */
    char *text;          /* malloc'd: a table of the parameters and the verdict */
} phc_mcmc_run_summary;
void phc_mcmc_run_summary_clear(phc_mcmc_run_summary *s);

/* Fits, samples and writes DIR.  Errors: PHC_ERR_INPUT (too few samples,
 * too few walkers, a prior with invalid numbers, nothing free, a fit that
 * failed), PHC_ERR_IO, PHC_ERR_EXISTS (DIR). */
int phc_mcmc_run(phc_problem *pb, const phc_mcmc_options *o, const phc_provenance *pv, const char *dir,
                 phc_mcmc_run_summary *summary, phc_error *err);

#endif /* PHC_MCMC_STUDY_H */
