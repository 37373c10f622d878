/* One-sided Jacobi SVD: see jacobi_svd.h. */
#include "model/jacobi_svd.h"

#include <float.h>
#include <math.h>

int phc_jacobi_svd(double *A, size_t m, size_t n, double *s, double *V)
{
    for (size_t i = 0; i < n; ++i)
        for (size_t j = 0; j < n; ++j)
            V[i * n + j] = i == j;
    double total = 0; /* |A|_F^2: columns below eps |A|_F are zero to working precision */
    for (size_t k = 0; k < m * n; ++k) {
        if (!isfinite(A[k]))
            return 1;
        total += A[k] * A[k];
    }
    const double tiny = DBL_EPSILON * DBL_EPSILON * total, tol = sqrt((double)m) * DBL_EPSILON;
    int converged = n < 2;
    for (int sweep = 0; sweep < 60 && !converged; ++sweep) {
        int rotated = 0;
        for (size_t p = 0; p + 1 < n; ++p)
            for (size_t q = p + 1; q < n; ++q) {
                double alpha = 0, beta = 0, gamma = 0;
                for (size_t i = 0; i < m; ++i) {
                    const double ap = A[i * n + p], aq = A[i * n + q];
                    alpha += ap * ap;
                    beta += aq * aq;
                    gamma += ap * aq;
                }
                /* columns orthogonal to working precision (the relative
                   test |a_p . a_q| <= tol |a_p| |a_q|, with tol = sqrt(m)
                   eps as LAPACK's dgesvj: the computed dot product of two
                   m-vectors itself carries that much rounding, so a smaller
                   tol can rotate forever), or one of them zero to working
                   precision (more columns than rows, rank deficiency) */
                if (!(fabs(gamma) > tol * sqrt(alpha) * sqrt(beta)) || alpha <= tiny || beta <= tiny)
                    continue;
                rotated = 1;
                /* the rotation that zeroes a_p . a_q: t = tan(theta), the
                   smaller root of t^2 + 2 zeta t - 1 = 0 */
                const double zeta = (beta - alpha) / (2 * gamma);
                const double t = (zeta >= 0 ? 1.0 : -1.0) / (fabs(zeta) + sqrt(1 + zeta * zeta));
                const double c = 1 / sqrt(1 + t * t), sn = c * t;
                for (size_t i = 0; i < m; ++i) {
                    const double ap = A[i * n + p], aq = A[i * n + q];
                    A[i * n + p] = c * ap - sn * aq;
                    A[i * n + q] = sn * ap + c * aq;
                }
                for (size_t i = 0; i < n; ++i) {
                    const double vp = V[i * n + p], vq = V[i * n + q];
                    V[i * n + p] = c * vp - sn * vq;
                    V[i * n + q] = sn * vp + c * vq;
                }
            }
        converged = !rotated;
    }
    for (size_t j = 0; j < n; ++j) {
        double ss = 0;
        for (size_t i = 0; i < m; ++i)
            ss += A[i * n + j] * A[i * n + j];
        s[j] = sqrt(ss);
    }
    /* descending order: selection sort, swapping columns of A and V */
    for (size_t j = 0; j + 1 < n; ++j) {
        size_t best = j;
        for (size_t k = j + 1; k < n; ++k)
            if (s[k] > s[best])
                best = k;
        if (best == j)
            continue;
        double tmp = s[j];
        s[j] = s[best];
        s[best] = tmp;
        for (size_t i = 0; i < m; ++i) {
            tmp = A[i * n + j];
            A[i * n + j] = A[i * n + best];
            A[i * n + best] = tmp;
        }
        for (size_t i = 0; i < n; ++i) {
            tmp = V[i * n + j];
            V[i * n + j] = V[i * n + best];
            V[i * n + best] = tmp;
        }
    }
    return converged ? 0 : 1;
}

int phc_jacobi_lstsq(double *A, size_t m, size_t n, const double *b, double rcond, double *V, double *work,
                     double *x, size_t *rank)
{
    double *sv = work, *coef = work + n;
    const int rc = phc_jacobi_svd(A, m, n, sv, V);
    size_t r = 0;
    const double smax = sv[0];
    /* x = V diag(1/s) U' b, with U' b = (A' b)_j / s_j for A = U diag(s) */
    for (size_t j = 0; j < n; ++j) {
        coef[j] = 0;
        if (sv[j] > rcond * smax && sv[j] > 0) {
            double d = 0;
            for (size_t i = 0; i < m; ++i)
                d += A[i * n + j] * b[i];
            coef[j] = d / (sv[j] * sv[j]);
            ++r;
        }
    }
    for (size_t i = 0; i < n; ++i) {
        double v = 0;
        for (size_t j = 0; j < n; ++j)
            v += V[i * n + j] * coef[j];
        x[i] = v;
    }
    *rank = r;
    return rc;
}
