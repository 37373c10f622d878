/* Least squares by Householder QR and a Jacobi SVD of R: see qr_lstsq.h. */
#include "fit/engine/qr_lstsq.h"

#include <math.h>
#include <string.h>

#include "model/jacobi_svd.h"

/* Most columns whose Householder updates run row by row (more: column by
 * column, the same numbers). */
#define PHC_QR_MAX_COLS 64

size_t phc_qr_lstsq_work(size_t m, size_t n)
{
    return m + 2 * n * n + 2 * n;
}

int phc_qr_triangle(double *A, size_t m, size_t n, double *c, double *R)
{
    if (m < n || n == 0)
        return 2;
    for (size_t k = 0; k < m * n; ++k)
        if (!isfinite(A[k]))
            return 1;
    /* Householder reflections H_k = I - tau v v' with tau = 2 / v'v,
     * applied in place: column k from the diagonal down becomes v. */
    for (size_t k = 0; k < n; ++k) {
        double scale = 0;
        for (size_t i = k; i < m; ++i)
            scale = fmax(scale, fabs(A[i * n + k]));
        if (scale == 0)
            continue; /* a zero column: H_k = I, R's diagonal entry 0 */
        double ss = 0;
        for (size_t i = k; i < m; ++i) {
            const double a = A[i * n + k] / scale;
            ss += a * a;
        }
        const double akk = A[k * n + k];
        const double alpha = (akk > 0 ? -1.0 : 1.0) * scale * sqrt(ss); /* -sign(a_kk) |a_k| */
        const double v0 = akk - alpha;
        /* v = (v0, a_{k+1,k}, ..., a_{m-1,k}): v'v = -2 alpha v0 */
        const double tau = -1.0 / (alpha * v0);
        A[k * n + k] = v0;
        /* d_j = tau v'a_j for every later column j at once, row by row:
         * each d_j sums the same products in the same order (i ascending)
         * as a column-by-column loop, so the numbers are the same, but the
         * n - k - 1 sums run side by side along contiguous rows instead of
         * one chain of dependent additions after another down a column */
        double d[PHC_QR_MAX_COLS];
        if (n <= PHC_QR_MAX_COLS) {
            for (size_t j = k + 1; j < n; ++j)
                d[j] = 0;
            for (size_t i = k; i < m; ++i) {
                const double vi = A[i * n + k];
                const double *row = A + i * n;
                for (size_t j = k + 1; j < n; ++j)
                    d[j] += vi * row[j];
            }
            for (size_t j = k + 1; j < n; ++j)
                d[j] *= tau;
            for (size_t i = k; i < m; ++i) {
                const double vi = A[i * n + k];
                double *row = A + i * n;
                for (size_t j = k + 1; j < n; ++j)
                    row[j] -= d[j] * vi;
            }
        } else {
            for (size_t j = k + 1; j < n; ++j) {
                double dj = 0;
                for (size_t i = k; i < m; ++i)
                    dj += A[i * n + k] * A[i * n + j];
                dj *= tau;
                for (size_t i = k; i < m; ++i)
                    A[i * n + j] -= dj * A[i * n + k];
            }
        }
        if (c) {
            double d = 0;
            for (size_t i = k; i < m; ++i)
                d += A[i * n + k] * c[i];
            d *= tau;
            for (size_t i = k; i < m; ++i)
                c[i] -= d * A[i * n + k];
        }
        A[k * n + k] = alpha; /* R's diagonal; below it stays v */
    }
    for (size_t i = 0; i < n; ++i)
        for (size_t j = 0; j < n; ++j)
            R[i * n + j] = j >= i ? A[i * n + j] : 0.0;
    return 0;
}

int phc_qr_lstsq(double *A, size_t m, size_t n, const double *b, double rcond, double *work, double *x,
                 size_t *rank)
{
    *rank = 0;
    if (m < n || n == 0)
        return 2;
    double *c = work, *R = work + m, *V = R + n * n, *w = V + n * n;
    memcpy(c, b, m * sizeof *c);
    const int rc = phc_qr_triangle(A, m, n, c, R);
    if (rc)
        return rc;
    return phc_jacobi_lstsq(R, n, n, c, rcond, V, w, x, rank);
}
