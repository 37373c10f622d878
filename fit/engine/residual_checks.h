/* Statistical checks of fit residuals: serial correlation, normality,
 * heteroscedasticity.  Each check returns a statistic and a p-value for its
 * null hypothesis (residuals are independent / normal / of constant variance).
 *
 * All functions return PHC_OK, or PHC_ERR_INVALID when the sample is too
 * small or degenerate for the test (the minimum n is given per test; e.g. all
 * residuals equal).  In that case *statistic and *p_value are set to NAN so a
 * report can print "not applicable".  No function prints or allocates beyond
 * temporary buffers freed before returning. */
#ifndef PHC_RESIDUAL_CHECKS_H
#define PHC_RESIDUAL_CHECKS_H

#include <stddef.h>

#include "model/status.h"

/* Wald–Wolfowitz runs test on the signs of r (in the given order, e.g. time).
 * Zeros are dropped.  Statistic: the standard normal z of the number of runs
 * (with continuity correction, applied at every N: z = 0 when |R - E R| <= 1/2;
 * statsmodels applies it only for N < 50); p two-sided.  Needs >= 2 positive
 * and >= 2 negative values.  *runs receives the observed number of runs (may
 * be NULL; 0 on error). */
int phc_check_runs(const double *r, size_t n, double *statistic,
                   double *p_value, size_t *runs);

/* Durbin–Watson d = sum (r_i - r_{i-1})^2 / sum r_i^2, H1: positive lag-1
 * autocorrelation.  The p-value uses the normal approximation with the exact
 * mean and variance of d under H0 given the regressors (Durbin & Watson 1971,
 * as in R lmtest::dwtest(exact = FALSE)): with M = I - X (X'X)^+ X' and A the
 * first-difference matrix, P = tr(MA), Q = tr(MAMA), E[d] = P/(n-k),
 * Var[d] = 2 (Q - P E[d]) / ((n-k)(n-k+2)).  X is the n x k Jacobian of the
 * model at the optimum, row-major (the regressors of the linearised model);
 * X may be NULL (k = 0), then M = I - 11'/n (mean removed); k = 0 always
 * means this intercept-only design.  For a rank-deficient X, k in E[d] and
 * Var[d] is rank(X) = n - tr(M) (pivoted QR on unit-norm columns, relative
 * tolerance 1e-7 as R's lm); a full-rank X gives lmtest's numbers.
 * Needs n > k + 2 and r not constant.
 * p is one-sided (small d = positive autocorrelation). */
int phc_check_durbin_watson(const double *r, size_t n, const double *X,
                            size_t k, double *statistic, double *p_value);

/* Ljung–Box Q = n (n + 2) sum_{h=1..lags} rho_h^2 / (n - h), chi-square with
 * `lags` - `fitted_dof` degrees of freedom (fitted_dof usually 0 for
 * regression residuals).  lags = 0 chooses min(10, n / 5) (at least 1).
 * Needs n > lags + 1, lags > fitted_dof and r not constant. */
int phc_check_ljung_box(const double *r, size_t n, size_t lags,
                        size_t fitted_dof, double *statistic, double *p_value);

/* Shapiro–Wilk W test of normality, Royston (1995) algorithm AS R94, valid
 * for 3 <= n <= 5000 (larger n: PHC_ERR_INVALID).  p from Royston's
 * normalising transformations; n = 3 exact.  As R's swilk.c, p = 1e-99 when
 * 4 <= n <= 11 and log(1 - W) is beyond the transformation's pole.  Needs
 * finite x with x_max > x_min. */
int phc_check_shapiro_wilk(const double *x, size_t n, double *statistic,
                           double *p_value);

/* Anderson–Darling A^2 test of normality with estimated mean and variance,
 * statistic adjusted A*^2 = A^2 (1 + 0.75/n + 2.25/n^2), p from D'Agostino &
 * Stephens (1986) Table 4.9; for A*^2 >= 10 p = 3.7e-24 (R nortest::ad.test;
 * the table's last formula would rise again beyond).  Needs n >= 8 and x not
 * constant. */
int phc_check_anderson_darling(const double *x, size_t n, double *statistic,
                               double *p_value);

/* Breusch–Pagan test (Koenker's studentised form): regress r^2 on an
 * intercept and the `k` columns of Z (n x k, row-major; typically the fitted
 * values, k = 1); LM = n R^2 of that auxiliary regression, chi-square with k
 * dof (for a rank-deficient Z, or one with a constant column, the rank of the
 * centred Z).  Needs n > k + 1, k >= 1, Z not all constant and non-constant
 * r^2. */
int phc_check_breusch_pagan(const double *r, const double *Z, size_t n,
                            size_t k, double *statistic, double *p_value);

/* Sample autocorrelation rho_h, h = 0..max_lag (acf[0] = 1), with the mean
 * removed and the biased (1/n) estimator as in R acf().  acf has max_lag + 1
 * entries.  Needs n > max_lag and non-constant r. */
int phc_check_acf(const double *r, size_t n, size_t max_lag, double *acf);

/* ---- time series: correlation over time lags, daily cycles ------------
 *
 * The functions below take observation times t (any order, finite, in
 * hours: the report converts x with the data set's x_seconds) beside the
 * residuals, so that irregular sampling, gaps and several series sharing one
 * clock are handled without assuming one observation per time step. */

/* Autocorrelation of r over time lags, by slotting (binning) the pairs of
 * observations by their time lag: the "slotting" estimator of Edelson &
 * Krolik (1988, their discrete correlation function without measurement
 * error) and of Rehfeld et al. (2011, rectangular kernel):
 *     acf[k] = sum_{(i,j) in bin k} (r_i - rbar)(r_j - rbar) / (N_k c0),
 *     c0 = (1/n) sum_i (r_i - rbar)^2,
 * where bin k >= 1 holds the pairs i != j (each once) whose lag |t_j - t_i|
 * lies in [(k - 1/2) bin_h, (k + 1/2) bin_h) and N_k is their number;
 * acf[0] = 1 (lag 0).  For regular sampling with bin_h equal to the step
 * this is the ACF with the 1/(n - k) ("adjusted") normalisation, so a
 * sinusoid gives ~ cos(2 pi lag / period) at every lag, not a damped one.
 * bin_h > 0 (hours); n_bins >= 1 entries of acf (lag k bin_h, k < n_bins).
 * acf[k] is NAN when bin k holds no pair.  pairs (may be NULL) receives
 * N_k (pairs[0] = n).  Needs n >= 3, finite t and r, r not constant (else
 * PHC_ERR_INVALID, acf all NAN).  Time O(n log n + P), P the pairs within
 * the largest lag; allocates n indices. */
int phc_check_acf_time(const double *t, const double *r, size_t n,
                       double bin_h, size_t n_bins, double *acf,
                       size_t *pairs);

/* The lag bin the report uses for phc_check_acf_time: the larger of the
 * median interval between successive distinct times (hours) and min_h.
 * NAN when fewer than two distinct finite times (or out of memory). */
double phc_check_acf_time_bin(const double *t, size_t n, double min_h);

/* Lomb–Scargle periodogram (Lomb 1976; Scargle 1982, eq. 10, with the time
 * offset tau of his eq. 11) of r at m frequencies freq[] (cycles per hour;
 * > 0), the mean of r removed, in the "standard" normalisation
 *     power = [ (sum r_c cos w(t - tau))^2 / sum cos^2 w(t - tau)
 *             + (sum r_c sin w(t - tau))^2 / sum sin^2 w(t - tau) ] / sum r_c^2,
 * r_c = r - rbar, w = 2 pi f: the fraction of the residual sum of squares
 * that one sinusoid of that frequency explains, in [0, 1].  A term whose
 * denominator vanishes (all times at one phase: the frequency is aliased
 * to zero) contributes 0.  Needs n >= 3, finite t and r, r not constant,
 * freq > 0.  Times are taken relative to their minimum (long clocks lose
 * no digits).  Uses no memory beyond the outputs. */
int phc_check_lomb_scargle(const double *t, const double *r, size_t n,
                           const double *freq, size_t m, double *power);

/* The highest periodogram peak with a frequency in [f_lo, f_hi] (cycles per
 * hour, 0 < f_lo < f_hi) and its false-alarm probability. */
typedef struct phc_periodogram_peak {
    double period;     /* of the peak, hours (1 / frequency) */
    double frequency;  /* cycles per hour */
    double power;      /* standard-normalised power, [0, 1] */
    double fap;        /* false-alarm probability: p-value of the peak under
                          H0 = Gaussian white noise, over the whole band */
    size_t n_freq;     /* frequencies on the grid */
    int local_max;     /* 1 when the peak is a local maximum of the
                          periodogram (not a band edge on a slope that keeps
                          rising outside the band) */
} phc_periodogram_peak;

/* Scans the band on a grid spaced 1 / (oversample T) (T = time span, hours;
 * oversample >= 1, 5-10 usual), includes one grid step beyond each band
 * edge to tell a true peak from a slope, refines the best grid point by a
 * golden-section search within one step, and returns the peak.  The FAP is
 * Baluev's (2008, MNRAS 385, 1279, Table 1 "standard" row and eq. 5) upper
 * bound for the maximum over the band, with dH = 1 (mean) and dK = 3 (mean
 * + sinusoid) degrees of freedom, N = n:
 *     FAP_single(Z) = (1 - Z)^((N - 3)/2),
 *     tau(Z) = gamma(N - 1) W (1 - Z)^((N - 4)/2) sqrt((N - 1) Z / 2),
 *     gamma(N) = sqrt(2/N) Gamma(N/2) / Gamma((N - 1)/2),
 *     W = (f_hi - f_lo) T_eff, T_eff = sqrt(4 pi Var(t)),
 *     FAP = 1 - (1 - FAP_single) exp(-tau)
 * (the same formulas as astropy's LombScargle.false_alarm_probability(
 * method="baluev"), with the band width in place of f_max).  Unlike Horne &
 * Baliunas's (1986) empirical count of independent frequencies it needs no
 * regular sampling, and it is conservative (never below the true FAP for
 * white noise; Baluev 2008 §5).  Needs n >= 5 and the checks of
 * phc_check_lomb_scargle; PHC_ERR_NOMEM when the grid cannot be held.  On
 * error every field is NAN / 0. */
int phc_check_periodogram_peak(const double *t, const double *r, size_t n,
                               double f_lo, double f_hi, double oversample,
                               phc_periodogram_peak *peak);

/* Search band of the daily-cycle test, hours. */
#define PHC_DAILY_PERIOD_MIN_H 22.0
#define PHC_DAILY_PERIOD_MAX_H 26.0
/* Shortest span of times (hours) over which the daily-cycle test and the
 * report's time-lag ACF are computed: 1.5 days, so that at least one and a
 * half cycles are seen and a 24 h period is resolved from a trend. */
#define PHC_DAILY_MIN_SPAN_H 36.0

/* Test for a 24-hour cycle in residuals r observed at times t (hours): the
 * residuals minus their least-squares line in time (a drift is not a cycle,
 * but over a few days its periodogram reaches into 22-26 h), then the
 * Lomb–Scargle peak in periods 22-26 h (as phc_check_periodogram_peak,
 * grid oversampled 10 times, Baluev's FAP with dH = 2 for mean and line,
 * dK = 4).  *statistic: its normalised power; *period_h: its
 * period (hours); *p_value: its Baluev FAP over the band, or 1 when the
 * band holds no local maximum of the periodogram (the power there is the
 * flank of a longer-period trend, which runs and Ljung–Box report; it is
 * not a daily cycle).  H0: no periodic signal (white noise).  Needs n >= 5
 * and a span of times >= PHC_DAILY_MIN_SPAN_H, else PHC_ERR_INVALID with
 * NAN outputs.  period_h may be NULL. */
int phc_check_daily_cycle(const double *t, const double *r, size_t n,
                          double *statistic, double *p_value,
                          double *period_h);

#endif /* PHC_RESIDUAL_CHECKS_H */
