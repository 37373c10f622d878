/* Variance-based global sensitivity: Sobol first-order, total and (optional)
 * second-order indices from a Saltelli design, with bootstrap intervals.
 *
 * Design (Saltelli 2002; Saltelli et al. 2010, Comput. Phys. Commun. 181,
 * 259, §3): two N x k matrices A and B of points in the unit hypercube, and
 * for every factor i the matrix A_B^i (A with the columns of factor i taken
 * from B); with second order also B_A^i (B with factor i's columns from A).
 * The rows are ordered by base sample j: A_j, B_j, A_B^1_j .. A_B^f_j
 * (then B_A^1_j .. B_A^f_j), so a design of M = N (f + 2) (or N (2f + 2))
 * points is evaluated block by block.
 *
 * Base points: by default the quasi-random Sobol sequence of GSL
 * (gsl_qrng_sobol, dimension 2k <= 40; its first point, the centre
 * (1/2, ..., 1/2), is skipped: it would make A_j = B_j, a row that adds
 * nothing to the estimates but weight to the variance)
 * with A its first k and B its last k coordinates, as Saltelli et al. 2010
 * recommend: for the same N its error is smaller than random sampling's.
 * `randomised` draws A and B from a seeded Mersenne Twister instead (GSL's
 * gsl_rng_mt19937): independent rows, for which the bootstrap is exact in
 * law, and needed beyond 20 factors' columns.  The bootstrap of a QMC design
 * treats its rows as independent, so its intervals are conservative.
 *
 * Factors and groups: `group_of[c]` names the factor of column c; a group of
 * columns moves together in A_B^i and gets one index (Saltelli et al. 2008,
 * §1.2.15).  NULL: each column is its own factor.
 *
 * Estimators, with f centred on the mean of f(A) and f(B) and V their
 * variance (divisor 2N):
 *   first order  S_i  = mean_j f(B)_j (f(A_B^i)_j - f(A)_j) / V   (Saltelli 2010, Table 2 (b))
 *   total        ST_i = mean_j (f(A)_j - f(A_B^i)_j)^2 / (2V)     (Jansen 1999; Saltelli 2010 (f))
 *   second order S_ij = mean_j (f(B_A^i)_j f(A_B^j)_j - f(A)_j f(B)_j) / V - S_i - S_j
 *                                                                   (Saltelli 2002, eq. 12)
 * Bootstrap: R resamples of the base samples j with replacement (seeded
 * gsl_rng_mt19937), the percentile interval at `level` (0.95).
 * A base sample whose block holds a non-finite output (a failed evaluation)
 * is left out of every estimate and counted.  Pure: no I/O. */
#ifndef PHC_SOBOL_INDICES_H
#define PHC_SOBOL_INDICES_H

#include <stddef.h>

#include "model/status.h"

typedef struct phc_saltelli_options {
    size_t n;             /* base samples N, >= 8 (>= 16 with second order) */
    int second_order;     /* 1: add B_A^i and estimate S_ij */
    int randomised;       /* 0: GSL's Sobol sequence; 1: Mersenne Twister with seed */
    unsigned long seed;   /* design (randomised) and bootstrap */
    size_t bootstrap;     /* resamples R, >= 100 (1000) */
    double level;         /* interval coverage, in (0, 1) (0.95) */
} phc_saltelli_options;

phc_saltelli_options phc_saltelli_options_default(void);

typedef struct phc_saltelli_design phc_saltelli_design;

/* k columns (parameters), n_factors factors; group_of (k entries, each <
 * n_factors, every factor used) or NULL (n_factors must equal k).  Errors
 * (PHC_ERR_INPUT): N too small for the requested order, k = 0, an empty
 * factor, more than 40 Sobol dimensions without randomised. */
int phc_saltelli_design_new(size_t k, const size_t *group_of, size_t n_factors, const phc_saltelli_options *o,
                            phc_saltelli_design **out, phc_error *err);
void phc_saltelli_design_free(phc_saltelli_design *d);
size_t phc_saltelli_design_rows(const phc_saltelli_design *d); /* M */
size_t phc_saltelli_design_factors(const phc_saltelli_design *d);
/* Writes the unit-cube point of row `row` (< M) into u (k values in (0, 1)). */
void phc_saltelli_design_point(const phc_saltelli_design *d, size_t row, double *u);

typedef struct phc_sobol_indices {
    size_t n_factors;
    double *s1, *s1_lo, *s1_hi;  /* first order and interval, per factor */
    double *st, *st_lo, *st_hi;  /* total */
    double *s2, *s2_lo, *s2_hi;  /* second order, n_factors^2 row-major (i < j filled, the rest NAN), or NULL */
    double mean, variance;       /* of the output over A and B */
    size_t n_used, n_failed;     /* base samples used; left out for a non-finite output */
} phc_sobol_indices;

/* Estimates the indices of one output from its M values y (row order as the
 * design; non-finite = failed).  An output with no variance over the design
 * gets NAN indices (nothing to apportion).  Fewer than 4 usable base
 * samples: PHC_ERR_NUMERIC. */
int phc_sobol_indices_estimate(const phc_saltelli_design *d, const double *y, phc_sobol_indices *out,
                               phc_error *err);
/* The same for n_out outputs at once: y holds M rows of n_out values
 * (row-major, y[row * n_out + j]), out n_out results.  Each output's result
 * is bit for bit what phc_sobol_indices_estimate gives for its column;
 * outputs with the same usable base samples draw their bootstrap resamples
 * once. */
int phc_sobol_indices_estimate_outputs(const phc_saltelli_design *d, const double *y, size_t n_out,
                                       phc_sobol_indices *out, phc_error *err);
void phc_sobol_indices_clear(phc_sobol_indices *s); /* frees the arrays; accepts zeroed */
/* phc_sobol_indices_estimate_outputs and, for n_agg runs of consecutive
 * outputs (agg_first[a] .. agg_first[a] + agg_count[a] - 1, a time series),
 * their aggregated indices (phc_sobol_indices_estimate_aggregate, below) in
 * aggs[a], in one call: an aggregate whose outputs share their usable base
 * samples takes its bootstrap from the sums its outputs' bootstrap already
 * took (the same resamples), so a study's series cost no second bootstrap.
 * Every result is bit for bit what the separate calls give.  The bootstrap
 * runs on OpenMP's threads (resamples shared out in fixed places: the
 * results do not depend on their number). */
int phc_sobol_indices_estimate_study(const phc_saltelli_design *d, const double *y, size_t n_out,
                                     phc_sobol_indices *outs, size_t n_agg, const size_t *agg_first,
                                     const size_t *agg_count, phc_sobol_indices *aggs, phc_error *err);

/* Generalised (aggregated) indices of T outputs together, for a time series
 * (Lamboni, Monod & Makowski 2011, Reliab. Eng. Syst. Saf. 96, 450;
 * Gamboa, Janon, Klein & Lagnoux 2013, arXiv:1311.1797, "Sensitivity
 * analysis for multidimensional and functional outputs", §2): the
 * output variances weight the indices of the single outputs,
 *   S_i = sum_t V_t S_i,t / sum_t V_t,   ST_i = sum_t V_t ST_i,t / sum_t V_t,
 * computed as the ratio of the estimators' summed numerators to the summed
 * variances (each output centred on its own mean), so an output without
 * variance adds nothing.  y holds the T outputs one after the other (T
 * columns of M values, column t at y + t M).  Bootstrap as for one output
 * (the same resamples); a base sample with a non-finite value in any output
 * is left out.  out->mean is the mean over the outputs of their means,
 * out->variance the summed variance sum_t V_t; no second order (s2 NULL). */
int phc_sobol_indices_estimate_aggregate(const phc_saltelli_design *d, const double *y, size_t n_outputs,
                                         phc_sobol_indices *out, phc_error *err);

#endif /* PHC_SOBOL_INDICES_H */
