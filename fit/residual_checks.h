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

#endif /* PHC_RESIDUAL_CHECKS_H */
