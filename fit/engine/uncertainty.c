/* Covariance at the optimum: see uncertainty.h. */
#include "fit/engine/uncertainty.h"
#include "fit/engine/qr_lstsq.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/jacobi_svd.h"

/* |J_j| * scale_j: how much the residuals move for a relative change of p_j. */
static double column_effect(const double *J, size_t m, size_t ld, size_t j, const double *scale)
{
    double ss = 0;
    for (size_t i = 0; i < m; ++i)
        ss += J[i * ld + j] * J[i * ld + j];
    return sqrt(ss) * (scale ? scale[j] : 1.0);
}

void phc_covariance_clear(phc_covariance *c)
{
    if (!c)
        return;
    free(c->cov);
    free(c->stderr_);
    free(c->correlation);
    free(c->null_vectors);
    memset(c, 0, sizeof *c);
}

int phc_covariance_compute(const double *J, size_t m, size_t n, double s2, double rcond,
                           const double *scale, phc_covariance *out, phc_error *err)
{
    memset(out, 0, sizeof *out);
    if (!J || n == 0 || m == 0)
        return phc_error_set(err, PHC_ERR_INVALID, "covariance: empty Jacobian");
    const size_t mm = m > n ? m : n; /* rows padded with zeros when m < n */
    double *A = calloc(mm * n, sizeof *A);
    double *D = calloc(n, sizeof *D);
    double *S = calloc(n, sizeof *S);
    double *VT = calloc(n * n, sizeof *VT);
    double *V = calloc(n * n, sizeof *V);
    out->n = n;
    out->cov = calloc(n * n, sizeof *out->cov);
    out->stderr_ = calloc(n, sizeof *out->stderr_);
    out->correlation = calloc(n * n, sizeof *out->correlation);
    out->null_vectors = calloc(n * n, sizeof *out->null_vectors);
    int rc = PHC_OK;
    if (!A || !D || !S || !VT || !V || !out->cov || !out->stderr_ || !out->correlation ||
        !out->null_vectors) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "covariance: out of memory");
        goto fail;
    }
    for (size_t j = 0; j < n; ++j) {
        double ss = 0;
        for (size_t i = 0; i < m; ++i)
            ss += J[i * n + j] * J[i * n + j];
        D[j] = sqrt(ss);
    }
    int *negligible = calloc(n, sizeof *negligible);
    if (!negligible) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "covariance: out of memory");
        goto fail;
    }
    phc_negligible_columns(J, m, n, n, scale, NULL, rcond, negligible);
    for (size_t j = 0; j < n; ++j)
        if (negligible[j])
            D[j] = 0; /* treated as a zero column */
    free(negligible);
    for (size_t i = 0; i < m; ++i)
        for (size_t j = 0; j < n; ++j)
            A[i * n + j] = D[j] > 0 ? J[i * n + j] / D[j] : 0.0;
    /* the SVD by one-sided Jacobi (model/jacobi_svd.h: no LAPACK to load),
       of R from A = Q R (fit/engine/qr_lstsq.h) when A has more rows than
       columns: the same singular values and right singular vectors, a
       Jacobi SVD of n rows instead of m; VT[k][a] = V[a][k], the k-th
       right singular vector */
    double *B = A;
    size_t rows = mm;
    if (mm > n && phc_qr_triangle(A, mm, n, NULL, VT) == 0) {
        memcpy(A, VT, n * n * sizeof *A); /* R into A's first n rows */
        rows = n;
    }
    if (phc_jacobi_svd(B, rows, n, S, V)) {
        rc = phc_error_set(err, PHC_ERR_NUMERIC, "covariance: SVD did not converge (Jacobi, 60 sweeps)");
        goto fail;
    }
    for (size_t k = 0; k < n; ++k)
        for (size_t a = 0; a < n; ++a)
            VT[k * n + a] = V[a * n + k];
    const double smax = S[0];
    size_t rank = 0;
    for (size_t k = 0; k < n; ++k)
        if (S[k] > rcond * smax && S[k] > 0)
            ++rank;
    out->rank = rank;
    out->n_null = n - rank;
    out->condition = rank == n ? smax / S[n - 1] : INFINITY;
    /* Pseudo-inverse in scaled coordinates, then undo the scaling. */
    for (size_t a = 0; a < n; ++a)
        for (size_t b = 0; b < n; ++b) {
            double sum = 0;
            for (size_t k = 0; k < rank; ++k)
                sum += VT[k * n + a] * VT[k * n + b] / (S[k] * S[k]);
            const double da = D[a] > 0 ? D[a] : 1.0, db = D[b] > 0 ? D[b] : 1.0;
            out->cov[a * n + b] = s2 * sum / (da * db);
        }
    for (size_t k = rank; k < n; ++k)
        memcpy(out->null_vectors + (k - rank) * n, VT + k * n, n * sizeof *VT);
    /* A parameter with a visible share (> 1e-3) in a null direction is not
     * determined by the data. */
    for (size_t a = 0; a < n; ++a) {
        int undetermined = D[a] == 0;
        for (size_t k = rank; k < n && !undetermined; ++k)
            undetermined = fabs(VT[k * n + a]) > 1e-3;
        out->stderr_[a] = undetermined ? NAN : sqrt(out->cov[a * n + a]);
    }
    for (size_t a = 0; a < n; ++a)
        for (size_t b = 0; b < n; ++b) {
            const double sa = out->stderr_[a], sb = out->stderr_[b];
            out->correlation[a * n + b] = (isnan(sa) || isnan(sb) || sa == 0 || sb == 0)
                                              ? (a == b ? 1.0 : NAN)
                                              : out->cov[a * n + b] / (sa * sb);
        }
fail:
    free(A);
    free(D);
    free(S);
    free(VT);
    free(V);
    if (rc)
        phc_covariance_clear(out);
    return rc;
}

size_t phc_negligible_columns(const double *J, size_t m, size_t n, size_t ld, const double *scale,
                              const int *skip, double rcond, int *negligible)
{
    /* First pass: the largest effect, kept column by column in negligible[]
     * as 0 (skipped) or 1 (measured); second pass: compare. */
    double top = 0;
    for (size_t j = 0; j < n; ++j) {
        negligible[j] = !(skip && skip[j]);
        if (negligible[j])
            top = fmax(top, column_effect(J, m, ld, j, scale));
    }
    size_t count = 0;
    for (size_t j = 0; j < n; ++j) {
        if (negligible[j])
            negligible[j] = column_effect(J, m, ld, j, scale) <= rcond * top;
        count += (size_t)negligible[j];
    }
    return count;
}

void phc_covariance_describe_null(const phc_covariance *c, size_t which,
                                  const char *const *names, char *buf, size_t size)
{
    if (!buf || size == 0)
        return;
    buf[0] = '\0';
    if (!c || which >= c->n_null)
        return;
    const double *v = c->null_vectors + which * c->n;
    /* components sorted by |v|, largest first; magnitudes equal to 1e-9
     * (e.g. +-0.70710678118654746 and 0.70710678118654757 for y = (a+b) x)
     * keep parameter order, so the text does not depend on the last bits
     * of the SVD (stable insertion sort; n is small) */
    size_t order[64];
    size_t cnt = 0;
    for (size_t j = 0; j < c->n && cnt < 64; ++j)
        if (fabs(v[j]) >= 0.05) {
            size_t a = cnt++;
            for (; a > 0 && fabs(v[j]) > fabs(v[order[a - 1]]) * (1 + 1e-9); --a)
                order[a] = order[a - 1];
            order[a] = j;
        }
    /* sign convention: first component positive */
    const double sign = cnt && v[order[0]] < 0 ? -1.0 : 1.0;
    size_t used = 0;
    for (size_t a = 0; a < cnt && used < size; ++a) {
        const double x = sign * v[order[a]];
        int w = snprintf(buf + used, size - used, "%s%.3g %s", a == 0 ? (x < 0 ? "-" : "") : (x < 0 ? " - " : " + "),
                         fabs(x), names[order[a]]);
        if (w < 0)
            break;
        used += (size_t)w;
    }
}
