/* Morris elementary effects: a screening of which factors matter, from r
 * one-at-a-time trajectories (Morris 1991, Technometrics 33, 161; mu* from
 * Campolongo, Cariboni & Saltelli 2007, Environ. Model. Softw. 22, 1509).
 *
 * Design (Morris 1991, §3): a grid of p levels (p even, default 4) per
 * column, with the jump Delta = p / (2 (p - 1)) of the grid's [0, 1] scale
 * (p/2 levels).  A trajectory starts at a random grid point (each column's
 * level drawn so that its jump stays on the grid: up from the lower half or
 * down from the upper half, with probability 1/2 each, which is Morris's
 * B* = (J x* + (Delta/2)[(2B - J) D* + J]) P*), then moves the factors one at
 * a time in a random order: f + 1 points per trajectory, r (f + 1) in all.
 * Grid level l of p is the probability u = (l + 1/2) / p of the factor's
 * prior, the centres of p equal-probability bins, so that unbounded priors
 * (normal) stay finite; a uniform prior on [a, b] thus sees the levels
 * a + (l + 1/2)(b - a)/p.  Randomness: gsl_rng_mt19937 with the seed.
 * Groups (group_of, as in sobol_indices.h) move all their columns in one
 * step (Campolongo et al. 2007, §2.2), and get one mu*.
 *
 * Effects, per factor i and trajectory t: EE = (y(after) - y(before)) / (+-Delta)
 * in output units per unit of the grid's [0, 1] scale.  mu = mean EE, mu* =
 * mean |EE|, sigma = standard deviation of EE (divisor r - 1); 95%
 * percentile intervals from R bootstrap resamples of the trajectories.  A
 * trajectory with a non-finite output (failed evaluation) is left out and
 * counted.  Pure: no I/O. */
#ifndef PHC_MORRIS_H
#define PHC_MORRIS_H

#include <stddef.h>

#include "model/status.h"

typedef struct phc_morris_options {
    size_t trajectories;  /* r >= 4 (Campolongo et al. suggest 10 to 50 and more) */
    unsigned levels;      /* p, even, >= 2 (4) */
    unsigned long seed;
    size_t bootstrap;     /* >= 100 (1000) */
    double level;         /* interval coverage (0.95) */
} phc_morris_options;

phc_morris_options phc_morris_options_default(void);

typedef struct phc_morris_design phc_morris_design;

int phc_morris_design_new(size_t k, const size_t *group_of, size_t n_factors, const phc_morris_options *o,
                          phc_morris_design **out, phc_error *err);
void phc_morris_design_free(phc_morris_design *d);
size_t phc_morris_design_rows(const phc_morris_design *d); /* r (f + 1) */
size_t phc_morris_design_factors(const phc_morris_design *d);
/* The probability point u (k values in (0, 1)) of row `row`. */
void phc_morris_design_point(const phc_morris_design *d, size_t row, double *u);

typedef struct phc_morris_effects {
    size_t n_factors;
    double *mu, *mu_lo, *mu_hi;
    double *mu_star, *mu_star_lo, *mu_star_hi;
    double *sigma, *sigma_lo, *sigma_hi;
    size_t n_used, n_failed; /* trajectories */
} phc_morris_effects;

/* mu, mu*, sigma of one output from its rows' values y.  Fewer than 2
 * usable trajectories: PHC_ERR_NUMERIC. */
int phc_morris_estimate(const phc_morris_design *d, const double *y, phc_morris_effects *out, phc_error *err);
void phc_morris_effects_clear(phc_morris_effects *e);

#endif /* PHC_MORRIS_H */
