/* Profile likelihood of each free parameter (Venzon & Moolgavkar 1988,
 * Appl. Statist. 37:87-94; Raue et al. 2009, Bioinformatics 25:1923-1929).
 *
 * For a free parameter theta_j the profile is
 *     PL(theta_j) = min over the other free parameters of cost(theta),
 * cost = 1/2 sum rho(r^2) of the weighted residuals (ceres_bridge.h).  It is
 * traced from the optimum in both directions with theta_j fixed and the
 * others re-optimised by Ceres (warm start from the previous point), with an
 * adaptive step: the step grows when sqrt(delta) (delta = PL - cost_best)
 * rises little and shrinks when it jumps or the inner fit fails.  A side
 * stops when delta reaches the threshold (the crossing is then refined by
 * regula falsi on sqrt(delta) - sqrt(threshold), exact for a linear model
 * whose sqrt(delta) is linear in theta_j), at a bound ("open to the bound"),
 * or after max_steps steps or PHC_PROFILE_MAX_REACH times max(|estimate|,
 * scale) away from the estimate ("open").
 *
 * Threshold on delta (in cost units, cost = chi^2 / 2):
 *   absolute sigmas:  delta* = chi2_1(level) / 2      (1.9207 at 0.95);
 *   sigma estimated from the residuals (s^2 = 2 cost_best / (n - p)): the
 *   F-test of lmfit's conf_interval (f_compare):
 *       F(1, n - p) cdf of (PL / cost_best - 1) (n - p) = level  <=>
 *       delta* = cost_best F_{1,n-p}^{-1}(level) / (n - p),
 *   which for a linear model is s^2 t_{n-p}^2 / 2, the exact t-interval.
 *
 * Values are in the model slots' units (phc_problem after
 * phc_problem_finish); callers convert for display.  Pure: no I/O. */
#ifndef PHC_PROFILE_H
#define PHC_PROFILE_H

#include <stddef.h>

#include "fit/engine/problem.h"
#include "fit/engine/progress.h"
#include "model/status.h"

/* How far (in units of max(|estimate|, the parameter's scale)) a side may go
 * before it is called open. */
#define PHC_PROFILE_MAX_REACH 1e6

typedef struct phc_profile_options {
    double level;        /* confidence level, 0 < level < 1 (0.95) */
    size_t points;       /* target points per side before the threshold, >= 3 (12) */
    size_t max_steps;    /* steps per side before it is called open (0: 8 * points + 40) */
    double flat_fraction;/* a profile whose delta stays below this fraction of the
                            threshold everywhere is flat (0.01) */
    phc_progress_fn progress;
    void *progress_data;
    /* NULL: one process.  Else the processes of an MPI run
       (fit/study_dist.h): every rank calls phc_profile_run with the same
       problem and x0, polishes the same optimum, then the free parameters'
       profiles are shared out (one per message; each is traced from the
       optimum alone, so the order does not matter) and the master (rank 0)
       receives them bit for bit: its result equals one process's.  A
       worker's result has n_profiles = 0.  Every rank calls agree() once,
       also when the set-up fails. */
    struct phc_dist *dist;
} phc_profile_options;

phc_profile_options phc_profile_options_default(void);

typedef enum phc_profile_end {
    PHC_PROFILE_CROSSED,  /* delta reached the threshold: the interval end is finite */
    PHC_PROFILE_AT_BOUND, /* the bound was reached below the threshold */
    PHC_PROFILE_OPEN      /* max_steps taken, or the step shrank to nothing, below it */
} phc_profile_end;

typedef struct phc_profile {
    size_t param;           /* index into the problem's parameters */
    size_t n;               /* points, sorted by theta (the optimum included) */
    double *theta;          /* n values of the parameter (slot units) */
    double *delta;          /* n values of PL - cost_best */
    double *others;         /* n x n_params re-optimised parameter vectors (row-major) */
    double lo, hi;          /* interval ends (slot units); with an open side the last
                               value reached (the bound for AT_BOUND) */
    phc_profile_end lo_end, hi_end;
    int flat;               /* max delta < flat_fraction * threshold: practically
                               non-identifiable */
    size_t inner_fits, failed_fits;
    double min_delta;       /* < 0 when a lower cost than the optimum was found */
} phc_profile;

typedef struct phc_profile_result {
    double level, threshold;/* threshold on delta, cost units */
    double best_cost;       /* the optimum re-polished with the profile's own solver */
    double *best;           /* n_params values at the optimum (slot units) */
    size_t n_params, n_obs, n_free;
    int absolute_sigma;
    size_t n_profiles;      /* = n_free, in parameter order */
    phc_profile *profiles;
} phc_profile_result;

/* The threshold on delta described above; NAN when n_obs <= n_free without
 * absolute sigmas. */
double phc_profile_threshold(double level, int absolute_sigma, double best_cost, size_t n_obs,
                             size_t n_free);

/* Profiles every free parameter of pb from x0 (n_params slot values, the
 * fitted optimum, or NULL for the start values, which are then fitted
 * first).  initial_step: n_params first steps (e.g. the Wald standard
 * errors), NULL or NAN/<= 0 entries for 0.1 * the parameter's scale.
 * PHC_ERR_INPUT when pb has no free parameter or no degrees of freedom for
 * an estimated sigma. */
int phc_profile_run(phc_problem *pb, const double *x0, const double *initial_step,
                    const phc_profile_options *opt, phc_profile_result **out, phc_error *err);

void phc_profile_result_free(phc_profile_result *res); /* accepts NULL */

#endif /* PHC_PROFILE_H */
