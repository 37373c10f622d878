/* Statistical checks of fit residuals: see residual_checks.h.
 *
 * References
 *   [WW40]  Wald, A. & Wolfowitz, J. (1940).  On a test whether two samples
 *           are from the same population.  Ann. Math. Stat. 11, 147-162.
 *   [DW50]  Durbin, J. & Watson, G. S. (1950, 1951, 1971).  Testing for serial
 *           correlation in least squares regression I, II, III.  Biometrika
 *           37, 409-428; 38, 159-178; 58, 1-19.
 *   [LB78]  Ljung, G. M. & Box, G. E. P. (1978).  On a measure of lack of fit
 *           in time series models.  Biometrika 65, 297-303.
 *   [R95]   Royston, P. (1995).  Remark AS R94: A remark on algorithm AS 181:
 *           The W-test for normality.  Appl. Statist. 44, 547-551.
 *   [R92]   Royston, P. (1992).  Approximating the Shapiro-Wilk W-test for
 *           non-normality.  Statistics and Computing 2, 117-119.
 *   [DS86]  D'Agostino, R. B. & Stephens, M. A. (1986).  Goodness-of-Fit
 *           Techniques.  Marcel Dekker.  Ch. 4, Table 4.9 and eq. 4.2.
 *   [K81]   Koenker, R. (1981).  A note on studentizing a test for
 *           heteroscedasticity.  J. Econometrics 17, 107-112.
 *   [BP79]  Breusch, T. S. & Pagan, A. R. (1979).  A simple test for
 *           heteroscedasticity and random coefficient variation.
 *           Econometrica 47, 1287-1294.
 *   [GVL13] Golub, G. H. & Van Loan, C. F. (2013).  Matrix Computations, 4th
 *           ed., §5.4.2 (QR with column pivoting).
 *   [EK88]  Edelson, R. A. & Krolik, J. H. (1988).  The discrete correlation
 *           function: a new method for analyzing unevenly sampled
 *           variability data.  Astrophys. J. 333, 646-659.
 *   [R11]   Rehfeld, K., Marwan, N., Heitzig, J. & Kurths, J. (2011).
 *           Comparison of correlation analysis techniques for irregularly
 *           sampled time series.  Nonlin. Processes Geophys. 18, 389-404.
 *   [L76]   Lomb, N. R. (1976).  Least-squares frequency analysis of unequally
 *           spaced data.  Astrophys. Space Sci. 39, 447-462.
 *   [S82]   Scargle, J. D. (1982).  Studies in astronomical time series
 *           analysis II.  Statistical aspects of spectral analysis of
 *           unevenly spaced data.  Astrophys. J. 263, 835-853.
 *   [B08]   Baluev, R. V. (2008).  Assessing the statistical significance of
 *           periodogram peaks.  Mon. Not. R. Astron. Soc. 385, 1279-1285.
 *   [HB86]  Horne, J. H. & Baliunas, S. L. (1986).  A prescription for
 *           period analysis of unevenly sampled time series.  Astrophys. J.
 *           302, 757-763.
 *
 * Linear algebra and distribution functions come from GSL.  GSL reports
 * errors through a process-wide handler that aborts by default; the library
 * must not abort, so every GSL call below is made only with arguments that
 * GSL accepts (sizes checked, finite values), and GSL never allocates here:
 * matrices and vectors are views on buffers obtained with malloc, so that an
 * out-of-memory condition is returned as PHC_ERR_NOMEM instead of reaching
 * the GSL error handler. */
#include "fit/engine/residual_checks.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_math.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_permutation.h>
#include <gsl/gsl_sf_erf.h>
#include <gsl/gsl_vector.h>

/* Relative tolerance on |R_jj| of the pivoted QR of the column-normalised
 * regressor matrix below which a column counts as linearly dependent on the
 * previous ones: the value R's lm() (LINPACK dqrdc2) uses. */
#define PHC_RANK_TOL 1e-7

/* ------------------------------------------------------------------------ */
/* small helpers                                                             */

static void set_nan2(double *statistic, double *p_value)
{
    if (statistic)
        *statistic = NAN;
    if (p_value)
        *p_value = NAN;
}

static int all_finite(const double *x, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(x[i]))
            return 0;
    return 1;
}

/* 1 when every x[i] equals x[0] (exact comparison: the test is "is there any
 * variation at all", not a tolerance). */
static int is_constant(const double *x, size_t n)
{
    for (size_t i = 1; i < n; ++i)
        if (x[i] != x[0])
            return 0;
    return 1;
}

/* sum_i (r_i - rbar)^2 over n > 0 values, with their mean rbar in *mean
 * (the autocorrelations' c_0 times n). */
static double centred_sum_of_squares(const double *r, size_t n, double *mean)
{
    double m = 0.0, ss = 0.0;
    for (size_t i = 0; i < n; ++i)
        m += r[i];
    m /= (double)n;
    for (size_t i = 0; i < n; ++i)
        ss += (r[i] - m) * (r[i] - m);
    *mean = m;
    return ss;
}

static int cmp_double(const void *pa, const void *pb)
{
    double a = *(const double *)pa, b = *(const double *)pb;
    return (a > b) - (a < b);
}

/* Horner evaluation of c[0] + c[1] x + ... + c[m-1] x^(m-1) (AS R94's POLY). */
static double poly(const double *c, int m, double x)
{
    double s = 0.0;
    for (int i = m - 1; i >= 0; --i)
        s = s * x + c[i];
    return s;
}

/* Euclidean norm of column j of the n x k row-major A, computed on the
 * column divided by its largest |entry| so that it cannot overflow or
 * underflow. */
static double column_norm(const double *A, size_t n, size_t k, size_t j)
{
    double amax = 0.0;
    for (size_t i = 0; i < n; ++i)
        if (fabs(A[i * k + j]) > amax)
            amax = fabs(A[i * k + j]);
    if (!(amax > 0.0))
        return 0.0;
    double ss = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double t = A[i * k + j] / amax;
        ss += t * t;
    }
    return amax * sqrt(ss);
}

/* Orthonormal basis of the column space of the n x k row-major matrix X
 * (with each column's mean removed first when `center` is set).
 *
 * Householder QR with column pivoting, X P = Q R [GVL13 §5.4.2], computed by
 * gsl_linalg_QRPT_decomp on a copy of X whose columns are scaled to unit
 * Euclidean norm (the column space, and so the projector X (X'X)^+ X', does
 * not change under column scaling, while the rank decision then no longer
 * depends on the units of the parameters).  The numerical rank is the number
 * of leading |R_jj| > PHC_RANK_TOL |R_00|; the first `rank` columns of Q then
 * span range(X).  On success *U_out is a malloc'd n x rank array stored
 * column by column (column j at U + j n; NULL when rank = 0), to be freed by
 * the caller.  Requires n >= k >= 1 and finite X. */
static int column_space_basis(const double *X, size_t n, size_t k, int center,
                              double **U_out, size_t *rank_out)
{
    int status = PHC_ERR_NOMEM;
    double *A = NULL, *tau = NULL, *norm = NULL, *U = NULL;
    size_t *perm_data = NULL;
    size_t rank = 0;

    *U_out = NULL;
    *rank_out = 0;

    A = malloc(n * k * sizeof *A);
    tau = malloc(k * sizeof *tau);
    norm = malloc(k * sizeof *norm);
    perm_data = malloc(k * sizeof *perm_data);
    if (!A || !tau || !norm || !perm_data)
        goto fail;
    memcpy(A, X, n * k * sizeof *A);

    for (size_t j = 0; j < k; ++j) {
        double norm0 = column_norm(A, n, k, j);
        if (center) {
            double mean = 0.0;
            for (size_t i = 0; i < n; ++i)
                mean += A[i * k + j];
            mean /= (double)n;
            for (size_t i = 0; i < n; ++i)
                A[i * k + j] -= mean;
            /* ||x - xbar|| / ||x|| is the R_jj that column j would get after
             * an intercept column in the QR of [1, X] on unit-norm columns:
             * below the rank tolerance the column is (numerically) constant,
             * and what the centring left is rounding noise, not a direction. */
            if (!(column_norm(A, n, k, j) > PHC_RANK_TOL * norm0)) {
                for (size_t i = 0; i < n; ++i)
                    A[i * k + j] = 0.0;
                continue;
            }
        }
        double cn = column_norm(A, n, k, j);
        if (cn > 0.0)
            for (size_t i = 0; i < n; ++i)
                A[i * k + j] /= cn;
    }

    {
        gsl_matrix_view Av = gsl_matrix_view_array(A, n, k);
        gsl_vector_view tv = gsl_vector_view_array(tau, k);
        gsl_vector_view nv = gsl_vector_view_array(norm, k);
        gsl_permutation perm = {k, perm_data};
        int signum = 0;
        if (gsl_linalg_QRPT_decomp(&Av.matrix, &tv.vector, &perm, &signum,
                                   &nv.vector) != 0) {
            status = PHC_ERR_NUMERIC;
            goto fail;
        }

        double r00 = fabs(A[0]);
        if (r00 > 0.0) {
            while (rank < k && fabs(A[rank * k + rank]) > PHC_RANK_TOL * r00)
                ++rank;
        }
        if (rank > 0) {
            U = calloc(n * rank, sizeof *U);
            if (!U)
                goto fail;
            for (size_t j = 0; j < rank; ++j) {
                /* column j of Q = Q e_j */
                gsl_vector_view uv = gsl_vector_view_array(U + j * n, n);
                U[j * n + j] = 1.0;
                if (gsl_linalg_QR_Qvec(&Av.matrix, &tv.vector, &uv.vector) != 0) {
                    status = PHC_ERR_NUMERIC;
                    goto fail;
                }
            }
        }
    }

    *U_out = U;
    *rank_out = rank;
    U = NULL;
    status = PHC_OK;
fail:
    free(U);
    free(perm_data);
    free(norm);
    free(tau);
    free(A);
    return status;
}

/* ------------------------------------------------------------------------ */
/* runs test                                                                 */

/* [WW40]: with n1 positive and n2 negative signs (N = n1 + n2) and R runs,
 * under H0 (random order)
 *   E[R]   = 2 n1 n2 / N + 1,
 *   Var[R] = 2 n1 n2 (2 n1 n2 - N) / (N^2 (N - 1)),
 * z = (R - E[R] -+ 1/2) / sd[R], the 1/2 moving R towards E[R] (continuity
 * correction, always applied, z = 0 when |R - E[R]| <= 1/2); p = 2 Q(|z|). */
int phc_check_runs(const double *r, size_t n, double *statistic,
                   double *p_value, size_t *runs)
{
    set_nan2(statistic, p_value);
    if (runs)
        *runs = 0;
    if (!r || !statistic || !p_value || !all_finite(r, n))
        return PHC_ERR_INVALID;

    size_t n1 = 0, n2 = 0, nruns = 0;
    int prev = 0;
    for (size_t i = 0; i < n; ++i) {
        int s = (r[i] > 0.0) - (r[i] < 0.0);
        if (s == 0)
            continue; /* zeros are dropped */
        if (s > 0)
            ++n1;
        else
            ++n2;
        if (s != prev)
            ++nruns;
        prev = s;
    }
    if (n1 < 2 || n2 < 2)
        return PHC_ERR_INVALID;

    double a = (double)n1, b = (double)n2, N = a + b;
    double mean = 2.0 * a * b / N + 1.0;
    double var = 2.0 * a * b * (2.0 * a * b - N) / (N * N * (N - 1.0));
    if (!(var > 0.0))
        return PHC_ERR_INVALID;
    double dev = (double)nruns - mean;
    double adj = fabs(dev) > 0.5 ? fabs(dev) - 0.5 : 0.0;
    double z = copysign(adj, dev) / sqrt(var);
    if (adj == 0.0)
        z = 0.0;

    *statistic = z;
    *p_value = 2.0 * gsl_cdf_ugaussian_Q(fabs(z));
    if (*p_value > 1.0)
        *p_value = 1.0;
    if (runs)
        *runs = nruns;
    return PHC_OK;
}

/* ------------------------------------------------------------------------ */
/* Durbin-Watson                                                             */

/* y = A v with A the n x n matrix of the DW quadratic form, d = r'A r / r'r:
 * A = D'D, D the (n-1) x n first-difference matrix, i.e. tridiagonal with
 * diagonal (1, 2, ..., 2, 1) and off-diagonals -1.  n >= 2. */
static void dw_apply_A(const double *v, double *y, size_t n)
{
    y[0] = v[0] - v[1];
    for (size_t i = 1; i + 1 < n; ++i)
        y[i] = 2.0 * v[i] - v[i - 1] - v[i + 1];
    y[n - 1] = v[n - 1] - v[n - 2];
}

/* Durbin & Watson (1971) moments of d under H0 (r = M e, e ~ N(0, s^2 I)),
 * with M = I - H and H = U U' the orthogonal projector on range(X):
 *   P = tr(MA)   = tr(A) - tr(U'AU)                = 2(n-1) - tr B,
 *   Q = tr(MAMA) = tr(A^2) - 2 tr(U'A^2U) + tr(B^2) = 2(3n-4) - 2 tr C + tr B^2,
 * B = U'AU, C = (AU)'(AU), using tr(A) = 2(n-1), tr(A^2) = 2(3n-4) and the
 * cyclic property of the trace; this avoids forming the n x n matrix M.
 *   E[d] = P / (n-p),  Var[d] = 2 (Q - P E[d]) / ((n-p)(n-p+2)),  p = rank X
 * (the header's k; they agree for full-rank X, and n - rank X = tr M is what
 * the derivation needs for a rank-deficient X).  Same quantities as R
 * lmtest::dwtest(exact = FALSE), which forms them from X and (X'X)^-1. */
int phc_check_durbin_watson(const double *r, size_t n, const double *X,
                            size_t k, double *statistic, double *p_value)
{
    int status = PHC_ERR_INVALID;
    double *U = NULL, *AU = NULL;
    size_t rank = 0;

    set_nan2(statistic, p_value);
    if (!r || !statistic || !p_value || n < 3 || k >= n - 2) /* n > k + 2 */
        return PHC_ERR_INVALID;
    if (k > 0 && !X)
        return PHC_ERR_INVALID;
    if (!all_finite(r, n) || is_constant(r, n))
        return PHC_ERR_INVALID;
    if (k > 0 && !all_finite(X, n * k))
        return PHC_ERR_INVALID;

    /* d = sum_{i>=2} (r_i - r_{i-1})^2 / sum r_i^2, scaled by max |r| so that
     * neither sum overflows or underflows. */
    double rmax = 0.0;
    for (size_t i = 0; i < n; ++i)
        if (fabs(r[i]) > rmax)
            rmax = fabs(r[i]);
    double num = 0.0, den = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double ri = r[i] / rmax;
        den += ri * ri;
        if (i > 0) {
            double di = ri - r[i - 1] / rmax;
            num += di * di;
        }
    }
    double d = num / den;

    double P = 2.0 * ((double)n - 1.0);
    double Q = 2.0 * (3.0 * (double)n - 4.0);
    if (k == 0) {
        /* X = 1 (mean removed): A 1 = 0, so B = C = 0 and rank = 1. */
        rank = 1;
    } else {
        status = column_space_basis(X, n, k, 0, &U, &rank);
        if (status != PHC_OK)
            goto fail;
        status = PHC_ERR_NOMEM;
        if (rank > 0) {
            AU = malloc(n * rank * sizeof *AU);
            if (!AU)
                goto fail;
        }
        double trB = 0.0, trC = 0.0, trB2 = 0.0;
        for (size_t j = 0; j < rank; ++j)
            dw_apply_A(U + j * n, AU + j * n, n);
        /* row i of B and C: the rank sums B_ij, C_ij side by side along t
         * (each in the order of t, as one at a time would), then added up
         * in the order of j */
        double *bi = malloc(2 * (rank ? rank : 1) * sizeof *bi), *ci = bi + (rank ? rank : 1);
        if (!bi)
            goto fail;
        for (size_t i = 0; i < rank; ++i) {
            for (size_t j = 0; j < rank; ++j)
                bi[j] = ci[j] = 0.0;
            for (size_t t = 0; t < n; ++t) {
                const double u = U[i * n + t], au = AU[i * n + t];
                for (size_t j = 0; j < rank; ++j) {
                    bi[j] += u * AU[j * n + t];
                    ci[j] += au * AU[j * n + t];
                }
            }
            for (size_t j = 0; j < rank; ++j) {
                if (i == j) {
                    trB += bi[j];
                    trC += ci[j];
                }
                trB2 += bi[j] * bi[j]; /* B symmetric: tr(B^2) = sum B_ij^2 */
            }
        }
        free(bi);
        P -= trB;
        Q += trB2 - 2.0 * trC;
    }

    status = PHC_ERR_INVALID;
    if (n <= rank + 2)
        goto fail;
    {
        double dof = (double)(n - rank);
        double mean = P / dof;
        double var = 2.0 * (Q - P * mean) / (dof * (dof + 2.0));
        if (!(var > 0.0) || !isfinite(var) || !isfinite(mean))
            goto fail;
        *statistic = d;
        /* one-sided, H1: positive autocorrelation (small d) */
        *p_value = gsl_cdf_ugaussian_P((d - mean) / sqrt(var));
    }
    status = PHC_OK;
fail:
    free(AU);
    free(U);
    return status;
}

/* ------------------------------------------------------------------------ */
/* autocorrelation and Ljung-Box                                             */

/* rho_h = c_h / c_0, c_h = (1/n) sum_{t=1}^{n-h} (r_t - rbar)(r_{t+h} - rbar)
 * (Box & Jenkins; R acf(), statsmodels acf(adjusted=False)). */
int phc_check_acf(const double *r, size_t n, size_t max_lag, double *acf)
{
    if (!acf)
        return PHC_ERR_INVALID;
    if (!r || n < 2 || n <= max_lag || !all_finite(r, n) || is_constant(r, n)) {
        for (size_t h = 0;; ++h) { /* acf[0..max_lag] */
            acf[h] = NAN;
            if (h == max_lag)
                break;
        }
        return PHC_ERR_INVALID;
    }

    double mean;
    const double c0 = centred_sum_of_squares(r, n, &mean);
    if (!(c0 > 0.0) || !isfinite(c0)) {
        for (size_t h = 0; h <= max_lag; ++h)
            acf[h] = NAN;
        return PHC_ERR_INVALID;
    }
    acf[0] = 1.0;
    for (size_t h = 1; h <= max_lag; ++h) {
        double ch = 0.0;
        for (size_t t = 0; t + h < n; ++t)
            ch += (r[t] - mean) * (r[t + h] - mean);
        acf[h] = ch / c0;
    }
    return PHC_OK;
}

/* [LB78]: Q = n (n+2) sum_{h=1}^{L} rho_h^2 / (n-h) ~ chi^2(L - fitted_dof). */
int phc_check_ljung_box(const double *r, size_t n, size_t lags,
                        size_t fitted_dof, double *statistic, double *p_value)
{
    set_nan2(statistic, p_value);
    if (!r || !statistic || !p_value || n < 3)
        return PHC_ERR_INVALID;
    if (lags == 0) {
        lags = n / 5 < 10 ? n / 5 : 10;
        if (lags < 1)
            lags = 1;
    }
    if (lags >= n - 1 || lags <= fitted_dof) /* n > lags + 1 */
        return PHC_ERR_INVALID;

    double *acf = malloc((lags + 1) * sizeof *acf);
    if (!acf)
        return PHC_ERR_NOMEM;
    int status = phc_check_acf(r, n, lags, acf);
    if (status == PHC_OK) {
        double dn = (double)n, q = 0.0;
        for (size_t h = 1; h <= lags; ++h)
            q += acf[h] * acf[h] / (dn - (double)h);
        q *= dn * (dn + 2.0);
        *statistic = q;
        *p_value = gsl_cdf_chisq_Q(q, (double)(lags - fitted_dof));
    }
    free(acf);
    return status;
}

/* ------------------------------------------------------------------------ */
/* Shapiro-Wilk                                                              */

/* Royston's algorithm AS R94 [R95], following the published Fortran:
 *
 * Coefficients.  m_i = Phi^-1((i - 3/8) / (n + 1/4)), i = 1..n/2 (negative),
 * summ2 = sum_{all n} m_i^2 = 2 sum_{i<=n/2} m_i^2, u = 1/sqrt(n);
 *   a_n     = -m_1/sqrt(summ2) + 0.221157 u - 0.147981 u^2 - 2.071190 u^3
 *             + 4.434685 u^4 - 2.706056 u^5,
 *   a_{n-1} = -m_2/sqrt(summ2) + 0.042981 u - 0.293762 u^2 - 1.752461 u^3
 *             + 5.682633 u^4 - 3.582633 u^5          (n > 5 only),
 *   a_i     = -m_i / sqrt(phi) for the others, with
 *   phi = (summ2 - 2 m_1^2 - 2 m_2^2) / (1 - 2 a_n^2 - 2 a_{n-1}^2)
 *   (n <= 5: only a_n is special and phi = (summ2 - 2 m_1^2)/(1 - 2 a_n^2)),
 * so that sum a_i^2 = 1.  n = 3: a = (-1, 0, 1)/sqrt(2) exactly.
 *
 * Statistic.  W = (sum a_i x_(i))^2 / sum (x_i - xbar)^2, computed as in AS
 * R94 on x / range and as 1 - W = (sqrt(ssa ssx) - sax)(sqrt(ssa ssx) + sax)
 * / (ssa ssx) so that 1 - W keeps its precision when W is close to 1.
 *
 * p-value.  n = 3: exact, p = (6/pi) (asin(sqrt(W)) - asin(sqrt(3/4))).
 * 4 <= n <= 11: gamma = -2.273 + 0.459 n, y = -log(gamma - log(1 - W)),
 *   mu = 0.5440 - 0.39978 n + 0.025054 n^2 - 6.714e-4 n^3,
 *   sigma = exp(1.3822 - 0.77857 n + 0.062767 n^2 - 0.0020322 n^3);
 *   (log(1 - W) >= gamma gives p = 1e-99, as R's swilk.c).
 * 12 <= n <= 5000: y = log(1 - W), with v = log n,
 *   mu = -1.5861 - 0.31082 v - 0.083751 v^2 + 0.0038915 v^3,
 *   sigma = exp(-0.4803 - 0.082676 v + 0.0030302 v^2);
 * p = 1 - Phi((y - mu) / sigma). */
int phc_check_shapiro_wilk(const double *x, size_t n, double *statistic,
                           double *p_value)
{
    static const double c1[6] = {0.0, 0.221157, -0.147981,
                                 -2.071190, 4.434685, -2.706056};
    static const double c2[6] = {0.0, 0.042981, -0.293762,
                                 -1.752461, 5.682633, -3.582633};
    static const double c3[4] = {0.5440, -0.39978, 0.025054, -6.714e-4};
    static const double c4[4] = {1.3822, -0.77857, 0.062767, -0.0020322};
    static const double c5[4] = {-1.5861, -0.31082, -0.083751, 0.0038915};
    static const double c6[3] = {-0.4803, -0.082676, 0.0030302};
    static const double g[2] = {-2.273, 0.459};

    set_nan2(statistic, p_value);
    if (!x || !statistic || !p_value || n < 3 || n > 5000 || !all_finite(x, n))
        return PHC_ERR_INVALID;

    const size_t nn2 = n / 2;
    double *xs = malloc(n * sizeof *xs);
    double *a = malloc(nn2 * sizeof *a);
    if (!xs || !a) {
        free(xs);
        free(a);
        return PHC_ERR_NOMEM;
    }
    memcpy(xs, x, n * sizeof *xs);
    qsort(xs, n, sizeof *xs, cmp_double);

    int status = PHC_ERR_INVALID;
    const double an = (double)n;
    const double range = xs[n - 1] - xs[0];
    if (!(range > 0.0) || !isfinite(range))
        goto done; /* all values equal (or range overflows) */

    /* coefficients a[0..nn2-1] for the upper half, a[i] pairs x_(n-1-i) - x_(i) */
    if (n == 3) {
        a[0] = sqrt(0.5);
    } else {
        double summ2 = 0.0;
        for (size_t i = 0; i < nn2; ++i) {
            a[i] = gsl_cdf_ugaussian_Pinv(((double)(i + 1) - 0.375) / (an + 0.25));
            summ2 += a[i] * a[i]; /* a[] holds m_i for now */
        }
        summ2 *= 2.0;
        double ssumm2 = sqrt(summ2), rsn = 1.0 / sqrt(an);
        double m1 = a[0];
        double a1 = poly(c1, 6, rsn) - m1 / ssumm2;
        size_t i1;
        double fac;
        if (n > 5) {
            double m2 = a[1];
            double a2 = -m2 / ssumm2 + poly(c2, 6, rsn);
            fac = sqrt((summ2 - 2.0 * m1 * m1 - 2.0 * m2 * m2) /
                       (1.0 - 2.0 * a1 * a1 - 2.0 * a2 * a2));
            a[1] = a2;
            i1 = 2;
        } else {
            fac = sqrt((summ2 - 2.0 * m1 * m1) / (1.0 - 2.0 * a1 * a1));
            i1 = 1;
        }
        a[0] = a1;
        for (size_t i = i1; i < nn2; ++i)
            a[i] = -a[i] / fac;
    }

    /* W on x / range; the full coefficient vector is antisymmetric, so its
     * mean is exactly 0 and sum a_i (x_i - xbar) = sum_i a_i (x_(n-1-i) - x_(i)). */
    double sx = 0.0;
    for (size_t i = 0; i < n; ++i)
        sx += xs[i] / range;
    sx /= an;
    double ssx = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double t = xs[i] / range - sx;
        ssx += t * t;
    }
    double ssa = 0.0, sax = 0.0;
    for (size_t i = 0; i < nn2; ++i) {
        ssa += 2.0 * a[i] * a[i];
        sax += a[i] * (xs[n - 1 - i] / range - xs[i] / range);
    }
    double ssassx = sqrt(ssa * ssx);
    double w1 = (ssassx - sax) * (ssassx + sax) / (ssa * ssx); /* 1 - W */
    if (w1 < 0.0)
        w1 = 0.0;
    double w = 1.0 - w1;
    double pw;

    if (n == 3) {
        const double pi6 = 6.0 / M_PI, stqr = M_PI / 3.0; /* asin(sqrt(3/4)) */
        pw = pi6 * (asin(sqrt(w < 1.0 ? w : 1.0)) - stqr);
        if (pw < 0.0)
            pw = 0.0;
        if (pw > 1.0)
            pw = 1.0;
    } else if (w1 == 0.0) {
        pw = 1.0; /* W = 1: log(1 - W) = -inf, upper tail 1 */
    } else {
        double y = log(w1), m, s;
        if (n <= 11) {
            double gamma = poly(g, 2, an);
            if (y >= gamma) {
                pw = 1e-99;
                goto have_p;
            }
            y = -log(gamma - y);
            m = poly(c3, 4, an);
            s = exp(poly(c4, 4, an));
        } else {
            double xx = log(an);
            m = poly(c5, 4, xx);
            s = exp(poly(c6, 3, xx));
        }
        pw = gsl_cdf_ugaussian_Q((y - m) / s);
    }
have_p:
    *statistic = w;
    *p_value = pw;
    status = PHC_OK;
done:
    free(a);
    free(xs);
    return status;
}

/* ------------------------------------------------------------------------ */
/* Anderson-Darling                                                          */

/* log Phi(t), accurate in both tails: Phi(t) = erfc(-t/sqrt 2) / 2. */
static double log_ugaussian_P(double t)
{
    return gsl_sf_log_erfc(-t / M_SQRT2) - M_LN2;
}

/* [DS86] eq. 4.2 and Table 4.9 (case 3: mean and variance estimated):
 * z_(i) = (x_(i) - xbar) / s (s with divisor n - 1),
 *   A^2 = -n - (1/n) sum_{i=1}^n (2i - 1) [log Phi(z_(i)) + log(1 - Phi(z_(n+1-i)))],
 *   A*^2 = A^2 (1 + 0.75/n + 2.25/n^2),
 *   p = 1 - exp(-13.436 + 101.14 A* - 223.73 A*^2)   A* < 0.2
 *       1 - exp(-8.318  + 42.796 A* - 59.938 A*^2)   0.2  <= A* < 0.34
 *       exp(0.9177 - 4.279 A* - 1.38   A*^2)         0.34 <= A* < 0.6
 *       exp(1.2937 - 5.709 A* + 0.0186 A*^2)         0.6  <= A* < 10
 *       3.7e-24                                      A* >= 10
 * (A* written for A*^2; the cut at 10, where the last formula has fallen to
 * 3.7e-24 and beyond which its quadratic term would make it rise again, is
 * the one of R nortest::ad.test). */
int phc_check_anderson_darling(const double *x, size_t n, double *statistic,
                               double *p_value)
{
    set_nan2(statistic, p_value);
    if (!x || !statistic || !p_value || n < 8 || !all_finite(x, n) ||
        is_constant(x, n))
        return PHC_ERR_INVALID;

    double *xs = malloc(n * sizeof *xs);
    if (!xs)
        return PHC_ERR_NOMEM;
    memcpy(xs, x, n * sizeof *xs);
    qsort(xs, n, sizeof *xs, cmp_double);

    int status = PHC_ERR_INVALID;
    const double dn = (double)n;
    double mean = 0.0;
    for (size_t i = 0; i < n; ++i)
        mean += xs[i];
    mean /= dn;
    double ss = 0.0;
    for (size_t i = 0; i < n; ++i)
        ss += (xs[i] - mean) * (xs[i] - mean);
    double sd = sqrt(ss / (dn - 1.0));
    if (!(sd > 0.0) || !isfinite(sd))
        goto done;

    double sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double zi = (xs[i] - mean) / sd;
        double zj = (xs[n - 1 - i] - mean) / sd;
        /* log(1 - Phi(zj)) = log Phi(-zj) */
        sum += (2.0 * (double)(i + 1) - 1.0) *
               (log_ugaussian_P(zi) + log_ugaussian_P(-zj));
    }
    double a2 = -dn - sum / dn;
    double as = a2 * (1.0 + 0.75 / dn + 2.25 / (dn * dn));
    double p;
    if (as < 0.2)
        p = 1.0 - exp(-13.436 + 101.14 * as - 223.73 * as * as);
    else if (as < 0.34)
        p = 1.0 - exp(-8.318 + 42.796 * as - 59.938 * as * as);
    else if (as < 0.6)
        p = exp(0.9177 - 4.279 * as - 1.38 * as * as);
    else if (as < 10.0)
        p = exp(1.2937 - 5.709 * as + 0.0186 * as * as);
    else
        p = 3.7e-24;
    if (p > 1.0)
        p = 1.0;
    if (p < 0.0)
        p = 0.0;
    *statistic = as;
    *p_value = p;
    status = PHC_OK;
done:
    free(xs);
    return status;
}

/* ------------------------------------------------------------------------ */
/* Breusch-Pagan (Koenker)                                                   */

/* [BP79] with Koenker's studentisation [K81]: u_i = r_i^2, auxiliary OLS of
 * u on (1, Z); LM = n R^2 with the centred R^2 = ESS / TSS,
 * TSS = sum (u_i - ubar)^2 and ESS = || Q_p' (u - ubar) ||^2, Q_p an
 * orthonormal basis of the centred columns of Z (the intercept is handled by
 * the centring), p = rank of the centred Z.  LM ~ chi^2(p) under H0; p = k
 * for the usual full-rank Z (statsmodels het_breuschpagan(robust=True)). */
int phc_check_breusch_pagan(const double *r, const double *Z, size_t n,
                            size_t k, double *statistic, double *p_value)
{
    int status = PHC_ERR_INVALID;
    double *u = NULL, *U = NULL;
    size_t rank = 0;

    set_nan2(statistic, p_value);
    if (!r || !Z || !statistic || !p_value || k == 0 || n < 2 ||
        k >= n - 1) /* n > k + 1 */
        return PHC_ERR_INVALID;
    if (!all_finite(r, n) || !all_finite(Z, n * k))
        return PHC_ERR_INVALID;

    status = PHC_ERR_NOMEM;
    u = malloc(n * sizeof *u);
    if (!u)
        goto fail;
    /* scale by max |r| before squaring: R^2 is scale free, and this keeps
     * r^2 from overflowing or underflowing */
    double rmax = 0.0;
    for (size_t i = 0; i < n; ++i)
        if (fabs(r[i]) > rmax)
            rmax = fabs(r[i]);
    status = PHC_ERR_INVALID;
    if (!(rmax > 0.0))
        goto fail;
    for (size_t i = 0; i < n; ++i) {
        double t = r[i] / rmax;
        u[i] = t * t;
    }
    if (is_constant(u, n))
        goto fail;
    double ubar = 0.0;
    for (size_t i = 0; i < n; ++i)
        ubar += u[i];
    ubar /= (double)n;
    double tss = 0.0;
    for (size_t i = 0; i < n; ++i) {
        u[i] -= ubar;
        tss += u[i] * u[i];
    }
    if (!(tss > 0.0))
        goto fail;

    status = column_space_basis(Z, n, k, 1, &U, &rank);
    if (status != PHC_OK)
        goto fail;
    status = PHC_ERR_INVALID;
    if (rank == 0)
        goto fail; /* every column of Z constant: nothing to test */
    double ess = 0.0;
    for (size_t j = 0; j < rank; ++j) {
        double c = 0.0;
        for (size_t i = 0; i < n; ++i)
            c += U[j * n + i] * u[i];
        ess += c * c;
    }
    double lm = (double)n * ess / tss;
    *statistic = lm;
    *p_value = gsl_cdf_chisq_Q(lm, (double)rank);
    status = PHC_OK;
fail:
    free(U);
    free(u);
    return status;
}

/* ------------------------------------------------------------------------ */
/* time series: time-lag autocorrelation and Lomb-Scargle                    */

typedef struct timed_index {
    double t;
    size_t i;
} timed_index;

static int cmp_timed(const void *pa, const void *pb)
{
    const timed_index *a = pa, *b = pb;
    if (a->t != b->t)
        return (a->t > b->t) - (a->t < b->t);
    return (a->i > b->i) - (a->i < b->i);
}

/* [EK88], [R11] (rectangular kernel): see the header. */
int phc_check_acf_time(const double *t, const double *r, size_t n,
                       double bin_h, size_t n_bins, double *acf,
                       size_t *pairs)
{
    if (!acf || n_bins == 0)
        return PHC_ERR_INVALID;
    for (size_t k = 0; k < n_bins; ++k) {
        acf[k] = NAN;
        if (pairs)
            pairs[k] = 0;
    }
    if (!t || !r || n < 3 || !(bin_h > 0.0) || !isfinite(bin_h) ||
        !all_finite(t, n) || !all_finite(r, n) || is_constant(r, n))
        return PHC_ERR_INVALID;
    double mean;
    const double c0 = centred_sum_of_squares(r, n, &mean) / (double)n;
    if (!(c0 > 0.0) || !isfinite(c0))
        return PHC_ERR_INVALID;
    timed_index *o = malloc(n * sizeof *o);
    double *sum = calloc(n_bins, sizeof *sum);
    size_t *count = calloc(n_bins, sizeof *count);
    if (!o || !sum || !count) {
        free(o);
        free(sum);
        free(count);
        return PHC_ERR_NOMEM;
    }
    for (size_t i = 0; i < n; ++i) {
        o[i].t = t[i];
        o[i].i = i;
    }
    qsort(o, n, sizeof *o, cmp_timed);
    /* pairs (a, b), a < b in time order, lag below the last bin's edge */
    const double edge = ((double)n_bins - 0.5) * bin_h;
    for (size_t a = 0; a < n; ++a) {
        const double ra = r[o[a].i] - mean;
        for (size_t b = a + 1; b < n; ++b) {
            const double lag = o[b].t - o[a].t;
            if (!(lag < edge))
                break;
            const double kk = floor(lag / bin_h + 0.5);
            if (kk < 1.0)
                continue; /* closer than half a bin: counts as lag 0 */
            const size_t k = (size_t)kk;
            if (k >= n_bins)
                break;
            sum[k] += ra * (r[o[b].i] - mean);
            count[k]++;
        }
    }
    acf[0] = 1.0;
    if (pairs)
        pairs[0] = n;
    for (size_t k = 1; k < n_bins; ++k) {
        if (count[k])
            acf[k] = sum[k] / ((double)count[k] * c0);
        if (pairs)
            pairs[k] = count[k];
    }
    free(o);
    free(sum);
    free(count);
    return PHC_OK;
}

double phc_check_acf_time_bin(const double *t, size_t n, double min_h)
{
    if (!t || n < 2)
        return NAN;
    double *s = malloc(n * sizeof *s);
    if (!s)
        return NAN;
    size_t m = 0;
    for (size_t i = 0; i < n; ++i)
        if (isfinite(t[i]))
            s[m++] = t[i];
    qsort(s, m, sizeof *s, cmp_double);
    size_t k = 0;
    for (size_t i = 1; i < m; ++i)
        if (s[i] > s[i - 1])
            s[k++] = s[i] - s[i - 1]; /* overwrites entries already read */
    double med = NAN;
    if (k > 0) {
        qsort(s, k, sizeof *s, cmp_double);
        med = k % 2 ? s[k / 2] : 0.5 * (s[k / 2 - 1] + s[k / 2]);
    }
    free(s);
    if (isnan(med))
        return NAN;
    return med > min_h ? med : min_h;
}

/* Common preconditions of the periodogram functions; fills the centred sum
 * of squares and the smallest time. */
static int ls_prepare(const double *t, const double *r, size_t n,
                      double *mean, double *ss, double *t0)
{
    if (!t || !r || n < 3 || !all_finite(t, n) || !all_finite(r, n) ||
        is_constant(r, n))
        return PHC_ERR_INVALID;
    double m = 0.0, lo = t[0];
    for (size_t i = 0; i < n; ++i) {
        m += r[i];
        lo = fmin(lo, t[i]);
    }
    m /= (double)n;
    double q = 0.0;
    for (size_t i = 0; i < n; ++i)
        q += (r[i] - m) * (r[i] - m);
    if (!(q > 0.0) || !isfinite(q))
        return PHC_ERR_INVALID;
    *mean = m;
    *ss = q;
    *t0 = lo;
    return PHC_OK;
}

/* Scargle's power from the four sums over the observations at one
 * frequency: yc = sum r_c cos wt, ys = sum r_c sin wt, c2 = sum cos 2wt,
 * s2 = sum sin 2wt.  With tan 2 w tau = s2 / c2 [S82 eq. 11]:
 *   sum r_c cos w(t - tau) = cos(w tau) yc + sin(w tau) ys,
 *   sum cos^2 w(t - tau) = (n + c2 cos 2 w tau + s2 sin 2 w tau) / 2,
 * and the sine terms likewise. */
static double ls_power_from_sums(size_t n, double yc, double ys, double c2,
                                 double s2, double ss)
{
    const double h = hypot(c2, s2);
    double cos2 = 1.0, sin2 = 0.0; /* of 2 w tau */
    if (h > 0.0) {
        cos2 = c2 / h;
        sin2 = s2 / h;
    }
    /* half-angle: w tau = atan2(sin2, cos2) / 2 */
    const double wt = 0.5 * atan2(sin2, cos2);
    const double c = cos(wt), s = sin(wt);
    const double yct = c * yc + s * ys, yst = c * ys - s * yc;
    const double cc = 0.5 * ((double)n + h), sq = 0.5 * ((double)n - h);
    const double tiny = 1e-12 * (double)n;
    double p = 0.0;
    if (cc > tiny)
        p += yct * yct / cc;
    if (sq > tiny)
        p += yst * yst / sq;
    p /= ss;
    return p < 0.0 ? 0.0 : p > 1.0 ? 1.0 : p;
}

static double ls_power_at(const double *t, const double *r, size_t n,
                          double mean, double ss, double t0, double f)
{
    const double w = 2.0 * M_PI * f;
    double yc = 0.0, ys = 0.0, c2 = 0.0, s2 = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const double a = w * (t[i] - t0);
        const double c = cos(a), s = sin(a), y = r[i] - mean;
        yc += y * c;
        ys += y * s;
        c2 += c * c - s * s;
        s2 += 2.0 * c * s;
    }
    return ls_power_from_sums(n, yc, ys, c2, s2, ss);
}

int phc_check_lomb_scargle(const double *t, const double *r, size_t n,
                           const double *freq, size_t m, double *power)
{
    if (!freq || !power)
        return PHC_ERR_INVALID;
    for (size_t k = 0; k < m; ++k)
        power[k] = NAN;
    double mean, ss, t0;
    int rc = ls_prepare(t, r, n, &mean, &ss, &t0);
    if (rc)
        return rc;
    for (size_t k = 0; k < m; ++k)
        if (!(freq[k] > 0.0) || !isfinite(freq[k]))
            return PHC_ERR_INVALID;
    for (size_t k = 0; k < m; ++k)
        power[k] = ls_power_at(t, r, n, mean, ss, t0, freq[k]);
    return PHC_OK;
}

/* log of gamma(N) = sqrt(2/N) Gamma(N/2) / Gamma((N-1)/2) of [B08]. */
static double baluev_log_gamma(double N)
{
    return 0.5 * log(2.0 / N) + lgamma(0.5 * N) - lgamma(0.5 * (N - 1.0));
}

/* [B08] Table 1 ("z_1" = standard normalisation): dH parameters under H0
 * (1: the mean; 2: mean and linear trend), dK = dH + 2 with the sinusoid. */
static double baluev_fap(double Z, size_t n, double W, double dH)
{
    const double N = (double)n, NH = N - dH, NK = N - dH - 2.0;
    if (!(Z > 0.0))
        return 1.0;
    if (Z >= 1.0)
        return 0.0;
    const double log1mz = log1p(-Z);
    const double fap_single = exp(0.5 * NK * log1mz);
    const double tau = exp(baluev_log_gamma(NH) + log(W) + 0.5 * (NK - 1.0) * log1mz +
                           0.5 * log(0.5 * NH * Z));
    /* 1 - (1 - fap_single) e^-tau, written without cancellation */
    double fap = -expm1(-tau) + fap_single * exp(-tau);
    return fap < 0.0 ? 0.0 : fap > 1.0 ? 1.0 : fap;
}

static int periodogram_peak(const double *t, const double *r, size_t n,
                            double f_lo, double f_hi, double oversample,
                            double dH, phc_periodogram_peak *peak)
{
    if (!peak)
        return PHC_ERR_INVALID;
    peak->period = peak->frequency = peak->power = peak->fap = NAN;
    peak->n_freq = 0;
    peak->local_max = 0;
    double mean, ss, t0;
    if (n < 5 || !(f_lo > 0.0) || !(f_hi > f_lo) || !isfinite(f_hi) ||
        !(oversample >= 1.0) || !isfinite(oversample))
        return PHC_ERR_INVALID;
    int rc = ls_prepare(t, r, n, &mean, &ss, &t0);
    if (rc)
        return rc;
    double hi = t[0], tm = 0.0;
    for (size_t i = 0; i < n; ++i) {
        hi = fmax(hi, t[i]);
        tm += t[i] - t0;
    }
    const double span = hi - t0;
    if (!(span > 0.0))
        return PHC_ERR_INVALID;
    tm /= (double)n;
    double var_t = 0.0;
    for (size_t i = 0; i < n; ++i)
        var_t += (t[i] - t0 - tm) * (t[i] - t0 - tm);
    var_t /= (double)n;
    const double df = 1.0 / (oversample * span);
    const double steps = ceil((f_hi - f_lo) / df);
    if (!(steps < 1e7))
        return PHC_ERR_NOMEM; /* a grid this fine is a caller's mistake */
    /* grid f_lo + k df, k = -1 .. K + 1, with f_lo + K df >= f_hi */
    const size_t K = (size_t)steps, m = K + 3;
    double *pw = malloc(m * sizeof *pw);
    double *cs = malloc(4 * n * sizeof *cs); /* cos, sin of the point, of the step */
    if (!pw || !cs) {
        free(pw);
        free(cs);
        return PHC_ERR_NOMEM;
    }
    /* Trigonometric recurrence over the uniform grid (Press et al.,
     * Numerical Recipes §13.8): each point's phase advances by 2 pi df t
     * per step; re-seeded from sin/cos every 64 steps against drift. */
    const double f_first = f_lo - df;
    for (size_t k = 0; k < m; ++k) {
        const double f = f_first + (double)k * df;
        if (k % 64 == 0) {
            for (size_t i = 0; i < n; ++i) {
                const double a = 2.0 * M_PI * f * (t[i] - t0), d = 2.0 * M_PI * df * (t[i] - t0);
                cs[4 * i] = cos(a);
                cs[4 * i + 1] = sin(a);
                cs[4 * i + 2] = cos(d);
                cs[4 * i + 3] = sin(d);
            }
        }
        double yc = 0.0, ys = 0.0, c2 = 0.0, s2 = 0.0;
        for (size_t i = 0; i < n; ++i) {
            double *q = cs + 4 * i;
            const double c = q[0], s = q[1], y = r[i] - mean;
            yc += y * c;
            ys += y * s;
            c2 += c * c - s * s;
            s2 += 2.0 * c * s;
            q[0] = c * q[2] - s * q[3];
            q[1] = s * q[2] + c * q[3];
        }
        pw[k] = f > 0.0 ? ls_power_from_sums(n, yc, ys, c2, s2, ss) : 0.0;
    }
    /* best grid point inside the band [f_lo, f_hi] */
    size_t best = 0;
    for (size_t k = 1; k < m; ++k) {
        const double f = f_first + (double)k * df;
        if (f < f_lo - 1e-12 * df || f > f_hi + 1e-12 * df)
            continue;
        if (!best || pw[k] > pw[best])
            best = k;
    }
    const double fb = f_first + (double)best * df;
    peak->local_max = pw[best] >= pw[best - 1] && pw[best] >= pw[best + 1];
    /* golden-section refinement within one grid step, kept in the band */
    double a = fmax(fb - df, f_lo), b = fmin(fb + df, f_hi);
    const double g = 0.5 * (sqrt(5.0) - 1.0);
    double x1 = b - g * (b - a), x2 = a + g * (b - a);
    double p1 = ls_power_at(t, r, n, mean, ss, t0, x1), p2 = ls_power_at(t, r, n, mean, ss, t0, x2);
    for (int it = 0; it < 60 && b - a > 1e-12 * fb; ++it) {
        if (p1 >= p2) {
            b = x2;
            x2 = x1;
            p2 = p1;
            x1 = b - g * (b - a);
            p1 = ls_power_at(t, r, n, mean, ss, t0, x1);
        } else {
            a = x1;
            x1 = x2;
            p1 = p2;
            x2 = a + g * (b - a);
            p2 = ls_power_at(t, r, n, mean, ss, t0, x2);
        }
    }
    double f_best = fb, p_best = pw[best];
    const double fr = 0.5 * (a + b), pr = ls_power_at(t, r, n, mean, ss, t0, fr);
    if (pr > p_best) {
        f_best = fr;
        p_best = pr;
    }
    peak->frequency = f_best;
    peak->period = 1.0 / f_best;
    peak->power = p_best;
    peak->n_freq = m;
    peak->fap = baluev_fap(p_best, n, (f_hi - f_lo) * sqrt(4.0 * M_PI * var_t), dH);
    free(pw);
    free(cs);
    return PHC_OK;
}

int phc_check_periodogram_peak(const double *t, const double *r, size_t n,
                               double f_lo, double f_hi, double oversample,
                               phc_periodogram_peak *peak)
{
    return periodogram_peak(t, r, n, f_lo, f_hi, oversample, 1.0, peak);
}

int phc_check_daily_cycle(const double *t, const double *r, size_t n,
                          double *statistic, double *p_value,
                          double *period_h)
{
    set_nan2(statistic, p_value);
    if (period_h)
        *period_h = NAN;
    if (!t || !r || !statistic || !p_value || n < 5 || !all_finite(t, n))
        return PHC_ERR_INVALID;
    double lo = t[0], hi = t[0];
    for (size_t i = 1; i < n; ++i) {
        lo = fmin(lo, t[i]);
        hi = fmax(hi, t[i]);
    }
    if (!(hi - lo >= PHC_DAILY_MIN_SPAN_H))
        return PHC_ERR_INVALID;
    if (!all_finite(r, n))
        return PHC_ERR_INVALID;
    /* residuals minus their least-squares line in time: a drift is not a
     * cycle (the runs test reports it), but its periodogram reaches into
     * 22-26 h when the span is a few days */
    double *d = malloc(n * sizeof *d);
    if (!d)
        return PHC_ERR_NOMEM;
    double tm = 0.0, rm = 0.0;
    for (size_t i = 0; i < n; ++i) {
        tm += t[i] - lo;
        rm += r[i];
    }
    tm /= (double)n;
    rm /= (double)n;
    double stt = 0.0, str = 0.0;
    for (size_t i = 0; i < n; ++i) {
        stt += (t[i] - lo - tm) * (t[i] - lo - tm);
        str += (t[i] - lo - tm) * (r[i] - rm);
    }
    const double slope = str / stt; /* stt > 0: the span is >= 36 h */
    for (size_t i = 0; i < n; ++i)
        d[i] = r[i] - rm - slope * (t[i] - lo - tm);
    phc_periodogram_peak pk;
    int rc = periodogram_peak(t, d, n, 1.0 / PHC_DAILY_PERIOD_MAX_H, 1.0 / PHC_DAILY_PERIOD_MIN_H, 10.0, 2.0, &pk);
    free(d);
    if (rc)
        return rc;
    *statistic = pk.power;
    *p_value = pk.local_max ? pk.fap : 1.0;
    if (period_h)
        *period_h = pk.period;
    return PHC_OK;
}
