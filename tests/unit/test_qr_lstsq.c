/* fit/engine/qr_lstsq: least squares by Householder QR and a Jacobi SVD of
 * R, against exact solutions (a consistent system; an inconsistent one
 * whose residual is built orthogonal to the columns, so the solution is
 * known exactly), against phc_jacobi_lstsq on A itself (random Jacobians of
 * the fit's shapes, columns scaled over 6 orders of magnitude), R's
 * singular values and vectors against those of A (the covariance), and the
 * limit cases: a square system, two proportional columns (rank n - 1, the
 * minimum-norm solution), a zero column, m < n and a NaN. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/engine/qr_lstsq.h"
#include "model/jacobi_svd.h"
#include "tests/check.h"

#define MMAX 260
#define NMAX 10

static unsigned long long rng = 0x9E3779B97F4A7C15ULL;
static double uniform(void) /* xorshift64, in (-1, 1) */
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return 2.0 * ((double)(rng >> 11) / 9007199254740992.0) - 1.0;
}

static double work[MMAX + 2 * NMAX * NMAX + 2 * NMAX];

/* x by phc_qr_lstsq on a copy of A; returns its status */
static int qr_solve(const double *A, size_t m, size_t n, const double *b, double *x, size_t *rank)
{
    static double Ac[MMAX * NMAX];
    memcpy(Ac, A, m * n * sizeof *A);
    CHECK(phc_qr_lstsq_work(m, n) <= sizeof work / sizeof *work);
    return phc_qr_lstsq(Ac, m, n, b, 1e-13, work, x, rank);
}

/* x by phc_jacobi_lstsq on a copy of A (the reference) */
static int jacobi_solve(const double *A, size_t m, size_t n, const double *b, double *x, size_t *rank)
{
    static double Ac[MMAX * NMAX], V[NMAX * NMAX], w[2 * NMAX];
    memcpy(Ac, A, m * n * sizeof *A);
    return phc_jacobi_lstsq(Ac, m, n, b, 1e-13, V, w, x, rank);
}

/* Consistent: b = A x_true with small integers, exact in floating point. */
static void test_consistent(void)
{
    const size_t m = 30, n = 5;
    double A[30 * 5], b[30], x[5], xt[5] = {1, -2, 3, 0.5, -0.25};
    for (size_t i = 0; i < m; ++i) {
        b[i] = 0;
        for (size_t j = 0; j < n; ++j) {
            A[i * n + j] = (double)((i * 7 + j * 13) % 11) - 5.0 + (i == j ? 20.0 : 0.0);
            b[i] += A[i * n + j] * xt[j];
        }
    }
    size_t rank;
    CHECK(qr_solve(A, m, n, b, x, &rank) == 0);
    CHECK(rank == n);
    for (size_t j = 0; j < n; ++j)
        CHECK_NEAR(x[j], xt[j], 1e-14, 1e-14);
}

/* Inconsistent with a known solution: b = A x_true + e with A' e = 0 (e is
 * a random vector minus its projection on the columns, computed by
 * Gram-Schmidt twice), so x_true is the least-squares solution. */
static void test_inconsistent(void)
{
    const size_t m = 40, n = 6;
    double A[40 * 6], Qc[40 * 6], e[40], b[40], x[6], xt[6];
    for (size_t k = 0; k < m * n; ++k)
        A[k] = uniform();
    memcpy(Qc, A, sizeof A);
    for (size_t j = 0; j < n; ++j) { /* orthonormal basis of the columns */
        for (int pass = 0; pass < 2; ++pass)
            for (size_t p = 0; p < j; ++p) {
                double d = 0;
                for (size_t i = 0; i < m; ++i)
                    d += Qc[i * n + p] * Qc[i * n + j];
                for (size_t i = 0; i < m; ++i)
                    Qc[i * n + j] -= d * Qc[i * n + p];
            }
        double s = 0;
        for (size_t i = 0; i < m; ++i)
            s += Qc[i * n + j] * Qc[i * n + j];
        for (size_t i = 0; i < m; ++i)
            Qc[i * n + j] /= sqrt(s);
    }
    for (size_t i = 0; i < m; ++i)
        e[i] = uniform();
    for (int pass = 0; pass < 2; ++pass)
        for (size_t p = 0; p < n; ++p) {
            double d = 0;
            for (size_t i = 0; i < m; ++i)
                d += Qc[i * n + p] * e[i];
            for (size_t i = 0; i < m; ++i)
                e[i] -= d * Qc[i * n + p];
        }
    for (size_t j = 0; j < n; ++j)
        xt[j] = uniform() * 10;
    for (size_t i = 0; i < m; ++i) {
        b[i] = e[i];
        for (size_t j = 0; j < n; ++j)
            b[i] += A[i * n + j] * xt[j];
    }
    size_t rank;
    CHECK(qr_solve(A, m, n, b, x, &rank) == 0);
    CHECK(rank == n);
    for (size_t j = 0; j < n; ++j)
        CHECK_NEAR(x[j], xt[j], 1e-13, 1e-13);
}

/* Random Jacobians of the fit's shapes, columns scaled by 10^-3 .. 10^3:
 * the same solution as phc_jacobi_lstsq on A, per component relative to
 * the component's own scale. */
static void test_against_jacobi(void)
{
    const size_t shapes[][2] = {{6, 2}, {14, 3}, {24, 6}, {37, 4}, {154, 7}, {168, 9}, {250, 8}, {250, 10}};
    double worst = 0;
    for (size_t s = 0; s < sizeof shapes / sizeof *shapes; ++s) {
        const size_t m = shapes[s][0], n = shapes[s][1];
        static double A[MMAX * NMAX], b[MMAX];
        double x[NMAX], xr[NMAX], colscale[NMAX];
        for (size_t j = 0; j < n; ++j)
            colscale[j] = pow(10.0, -3.0 + 6.0 * (double)j / (double)(n - 1));
        for (size_t i = 0; i < m; ++i) {
            b[i] = uniform();
            for (size_t j = 0; j < n; ++j)
                A[i * n + j] = uniform() * colscale[j];
        }
        size_t rank, rank_ref;
        CHECK(qr_solve(A, m, n, b, x, &rank) == 0);
        CHECK(jacobi_solve(A, m, n, b, xr, &rank_ref) == 0);
        CHECK(rank == n && rank_ref == n);
        for (size_t j = 0; j < n; ++j) {
            /* x_j scales as 1 / colscale_j */
            const double d = fabs(x[j] - xr[j]) * colscale[j];
            worst = fmax(worst, d);
            CHECK(d < 1e-13);
        }
    }
    printf("qr_lstsq vs jacobi_lstsq: largest difference %.3g (in units of 1 / column scale)\n", worst);
}

/* phc_qr_triangle: R has A's singular values and right singular vectors
 * (up to sign), against phc_jacobi_svd of A itself. */
static void test_triangle(void)
{
    const size_t m = 120, n = 7;
    static double A[120 * 7], Ac[120 * 7], R[7 * 7], sA[7], sR[7], VA[7 * 7], VR[7 * 7];
    for (size_t i = 0; i < m; ++i)
        for (size_t j = 0; j < n; ++j)
            A[i * n + j] = uniform() * pow(10.0, (double)j - 3.0);
    memcpy(Ac, A, sizeof A);
    CHECK(phc_qr_triangle(Ac, m, n, NULL, R) == 0);
    for (size_t i = 1; i < n; ++i)
        for (size_t j = 0; j < i; ++j)
            CHECK(R[i * n + j] == 0.0);
    memcpy(Ac, A, sizeof A);
    CHECK(phc_jacobi_svd(Ac, m, n, sA, VA) == 0);
    CHECK(phc_jacobi_svd(R, n, n, sR, VR) == 0);
    double worst = 0;
    for (size_t k = 0; k < n; ++k) {
        CHECK_NEAR(sR[k], sA[k], 0, 1e-14);
        double dot = 0; /* |v_A . v_R| = 1 for the same vector up to sign */
        for (size_t a = 0; a < n; ++a)
            dot += VA[a * n + k] * VR[a * n + k];
        worst = fmax(worst, fabs(fabs(dot) - 1));
        CHECK_NEAR(fabs(dot), 1.0, 1e-12, 0);
    }
    printf("qr_triangle: singular vectors agree to %.3g\n", worst);
    double b[3] = {1, 2, 3};
    CHECK(phc_qr_triangle(A, 2, 3, b, R) == 2);
}

/* Limit cases. */
static void test_limits(void)
{
    size_t rank;
    { /* square: the exact solution of a 3 x 3 system */
        double A[9] = {4, 1, 0, 1, 3, 1, 0, 1, 2}, b[3] = {5, 5, 3}, x[3];
        CHECK(qr_solve(A, 3, 3, b, x, &rank) == 0);
        CHECK(rank == 3);
        for (int j = 0; j < 3; ++j)
            CHECK_NEAR(x[j], 1.0, 1e-15, 1e-15);
    }
    { /* column 2 = 2 * column 0: rank 2; the minimum-norm solution of
         y = a t + b + c (2 t) puts a + 2 c on the slope with a : c = 1 : 2 */
        double A[8 * 3], b[8], x[3], xr[3];
        for (size_t i = 0; i < 8; ++i) {
            const double t = (double)i;
            A[i * 3] = t;
            A[i * 3 + 1] = 1;
            A[i * 3 + 2] = 2 * t;
            b[i] = 1.5 * t + 0.5;
        }
        CHECK(qr_solve(A, 8, 3, b, x, &rank) == 0);
        CHECK(rank == 2);
        CHECK_NEAR(x[0], 0.3, 1e-14, 1e-13); /* a + 2 c = 1.5, min a^2 + c^2: a = 0.3, c = 0.6 */
        CHECK_NEAR(x[2], 0.6, 1e-14, 1e-13);
        CHECK_NEAR(x[1], 0.5, 1e-14, 1e-13);
        CHECK(jacobi_solve(A, 8, 3, b, xr, &rank) == 0 && rank == 2);
        for (int j = 0; j < 3; ++j)
            CHECK_NEAR(x[j], xr[j], 1e-14, 1e-13);
    }
    { /* a zero column: rank 1, its coefficient 0 */
        double A[5 * 2], b[5], x[2];
        for (size_t i = 0; i < 5; ++i) {
            A[i * 2] = (double)i + 1;
            A[i * 2 + 1] = 0;
            b[i] = 2 * ((double)i + 1);
        }
        CHECK(qr_solve(A, 5, 2, b, x, &rank) == 0);
        CHECK(rank == 1);
        CHECK_NEAR(x[0], 2.0, 1e-15, 1e-14);
        CHECK(x[1] == 0.0);
    }
    { /* fewer rows than columns, and a NaN */
        double A[6] = {1, 2, 3, 4, 5, 6}, b[3] = {1, 2, 3}, x[3];
        CHECK(qr_solve(A, 2, 3, b, x, &rank) == 2);
        A[4] = NAN;
        CHECK(qr_solve(A, 3, 2, b, x, &rank) == 1);
    }
}

int main(void)
{
    test_consistent();
    test_inconsistent();
    test_against_jacobi();
    test_triangle();
    test_limits();
    return check_finish("test_qr_lstsq");
}
