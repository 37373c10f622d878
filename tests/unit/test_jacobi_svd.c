/* model/jacobi_svd: the one-sided Jacobi SVD against exact solutions
 * (matrices built as Q1 diag(s) Q2' from Householder reflections, so their
 * singular values are known exactly up to the rounding of the product),
 * LAPACK's dgesvd on random matrices of the fit analysis' shapes, a
 * rank-deficient Jacobian (two proportional columns), more columns than
 * rows, and the least-squares solve against an exact solution and against
 * LAPACK's dgelsd. */
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/jacobi_svd.h"
#include "tests/check.h"

static unsigned long long rng = 88172645463325252ULL;
static double uniform(void) /* xorshift64, in (-1, 1) */
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return 2.0 * ((double)(rng >> 11) / 9007199254740992.0) - 1.0;
}

/* Q = I - 2 v v' / v'v applied from the left to the k x c row-major M */
static void householder_left(double *M, size_t k, size_t c)
{
    double v[300], vv = 0;
    for (size_t i = 0; i < k; ++i) {
        v[i] = uniform();
        vv += v[i] * v[i];
    }
    for (size_t j = 0; j < c; ++j) {
        double d = 0;
        for (size_t i = 0; i < k; ++i)
            d += v[i] * M[i * c + j];
        for (size_t i = 0; i < k; ++i)
            M[i * c + j] -= 2 * v[i] * d / vv;
    }
}

/* max |A - U diag(s) V'| / max |A| and max |V'V - I| */
static void residuals(const double *A0, const double *US, const double *V, size_t m, size_t n, double *rec,
                      double *orth)
{
    double amax = 0, e = 0, o = 0;
    for (size_t i = 0; i < m; ++i)
        for (size_t j = 0; j < n; ++j) {
            double r = 0;
            for (size_t k = 0; k < n; ++k)
                r += US[i * n + k] * V[j * n + k];
            e = fmax(e, fabs(r - A0[i * n + j]));
            amax = fmax(amax, fabs(A0[i * n + j]));
        }
    for (size_t a = 0; a < n; ++a)
        for (size_t b = 0; b < n; ++b) {
            double d = 0;
            for (size_t k = 0; k < n; ++k)
                d += V[k * n + a] * V[k * n + b];
            o = fmax(o, fabs(d - (a == b)));
        }
    *rec = amax > 0 ? e / amax : e;
    *orth = o;
}

int main(void)
{
    enum { MMAX = 260, NMAX = 10 };
    static double A[MMAX * NMAX], A0[MMAX * NMAX], B[MMAX * NMAX], V[NMAX * NMAX], s[NMAX], sl[NMAX],
        superb[NMAX], work[2 * NMAX], x[NMAX], b[MMAX], bl[MMAX];
    double worst_exact = 0, worst_lapack = 0, worst_rec = 0, worst_orth = 0;
    int cases = 0;
    /* exact: A = Q1 [diag(s); 0] Q2', singular values spread over 1e-6..1e3 */
    const size_t shapes[][2] = {{1, 1}, {2, 2}, {3, 2}, {14, 2}, {14, 3}, {25, 4}, {54, 5}, {250, 7}, {35, 9}, {9, 9}};
    for (size_t t = 0; t < sizeof shapes / sizeof *shapes; ++t)
        for (int rep = 0; rep < 5; ++rep) {
            const size_t m = shapes[t][0], n = shapes[t][1];
            double exact[NMAX];
            memset(A, 0, sizeof A);
            for (size_t j = 0; j < n; ++j) {
                exact[j] = pow(10.0, 3.0 - 9.0 * (double)j / (double)(n > 1 ? n - 1 : 1)) * (1 + 0.1 * uniform());
                A[j * n + j] = exact[j];
            }
            for (int h = 0; h < 2; ++h)
                householder_left(A, m, n);
            /* right side: M Q2' = (Q2 M')' */
            for (int h = 0; h < 2; ++h) {
                double T[NMAX * MMAX];
                for (size_t i = 0; i < m; ++i)
                    for (size_t j = 0; j < n; ++j)
                        T[j * m + i] = A[i * n + j];
                householder_left(T, n, m);
                for (size_t i = 0; i < m; ++i)
                    for (size_t j = 0; j < n; ++j)
                        A[i * n + j] = T[j * m + i];
            }
            memcpy(A0, A, m * n * sizeof *A);
            CHECK(phc_jacobi_svd(A, m, n, s, V) == 0);
            /* exact values sorted descending */
            for (size_t j = 0; j < n; ++j)
                for (size_t k = j + 1; k < n; ++k)
                    if (exact[k] > exact[j]) {
                        const double tmp = exact[j];
                        exact[j] = exact[k];
                        exact[k] = tmp;
                    }
            for (size_t j = 0; j < n; ++j)
                worst_exact = fmax(worst_exact, fabs(s[j] - exact[j]) / exact[0]);
            double rec, orth;
            residuals(A0, A, V, m, n, &rec, &orth);
            worst_rec = fmax(worst_rec, rec);
            worst_orth = fmax(worst_orth, orth);
            ++cases;
        }
    printf("exact singular values, %d matrices (s from 1e3 down to 1e-6): max |s - s_exact| / s_max = %.3g\n", cases,
           worst_exact);
    CHECK(worst_exact < 1e-14);

    /* random matrices of the analysis' shapes, against LAPACK */
    for (int rep = 0; rep < 200; ++rep) {
        const size_t n = 1 + (size_t)(rep % 9), m = n + (size_t)((rep * 37) % 240);
        for (size_t k = 0; k < m * n; ++k)
            A[k] = uniform() * pow(10.0, 2.0 * uniform()); /* badly scaled entries */
        memcpy(A0, A, m * n * sizeof *A);
        memcpy(B, A, m * n * sizeof *A);
        CHECK(phc_jacobi_svd(A, m, n, s, V) == 0);
        CHECK(LAPACKE_dgesvd(LAPACK_ROW_MAJOR, 'N', 'N', (lapack_int)m, (lapack_int)n, B, (lapack_int)n, sl, NULL, 1,
                             NULL, 1, superb) == 0);
        for (size_t j = 0; j < n; ++j)
            worst_lapack = fmax(worst_lapack, fabs(s[j] - sl[j]) / sl[0]);
        double rec, orth;
        residuals(A0, A, V, m, n, &rec, &orth);
        worst_rec = fmax(worst_rec, rec);
        worst_orth = fmax(worst_orth, orth);
        ++cases;
    }
    printf("200 random matrices: max |s - s_dgesvd| / s_max = %.3g; all %d: |A - U S V'| / max|A| <= %.3g, "
           "|V'V - I| <= %.3g\n", worst_lapack, cases, worst_rec, worst_orth);
    CHECK(worst_lapack < 1e-13);
    CHECK(worst_rec < 1e-13);
    CHECK(worst_orth < 1e-13);

    /* nearly collinear columns on many rows (Kirby2's rational function:
       151 rows, columns 1, x, x^2, ... for x in 9..78; their dot products
       carry ~sqrt(m) eps of rounding, so a tolerance of eps alone never
       converged): converges, and agrees with dgesvd */
    {
        const size_t m = 151, n = 5;
        double worst_v = 0;
        for (size_t i = 0; i < m; ++i) {
            const double xv = 9 + 69.0 * (double)i / (double)(m - 1);
            for (size_t j = 0; j < n; ++j)
                A[i * n + j] = B[i * n + j] = pow(xv, (double)j) / pow(78.0, (double)j);
        }
        CHECK(phc_jacobi_svd(A, m, n, s, V) == 0);
        CHECK(LAPACKE_dgesvd(LAPACK_ROW_MAJOR, 'N', 'N', (lapack_int)m, (lapack_int)n, B, (lapack_int)n, sl, NULL, 1,
                             NULL, 1, superb) == 0);
        for (size_t j = 0; j < n; ++j)
            worst_v = fmax(worst_v, fabs(s[j] - sl[j]) / sl[0]);
        printf("151 x 5 monomials: s_min / s_max = %.3g, max |s - s_dgesvd| / s_max = %.3g\n", s[n - 1] / s[0],
               worst_v);
        CHECK(worst_v < 1e-14);
    }
    /* rank-deficient: column 2 = 3 x column 0, so s[2] = 0 up to rounding, and
       the null vector is (3, 0, -1)/sqrt(10) up to sign */
    {
        const size_t m = 14, n = 3;
        for (size_t i = 0; i < m; ++i) {
            A[i * n] = uniform();
            A[i * n + 1] = uniform();
            A[i * n + 2] = 3 * A[i * n];
        }
        CHECK(phc_jacobi_svd(A, m, n, s, V) == 0);
        printf("proportional columns: s = %.3g %.3g %.3g, null vector (%.6f, %.6f, %.6f)\n", s[0], s[1], s[2], V[2],
               V[5], V[8]);
        CHECK(s[2] <= 1e-15 * s[0]);
        CHECK_NEAR(fabs(V[2]), 3 / sqrt(10.0), 1e-14, 0);
        CHECK_NEAR(fabs(V[5]), 0, 1e-14, 0);
        CHECK_NEAR(fabs(V[8]), 1 / sqrt(10.0), 1e-14, 0);
    }
    /* more columns than rows: n - m zero singular values (to working
       precision: below eps s_max) */
    {
        const size_t m = 2, n = 4;
        for (size_t k = 0; k < m * n; ++k)
            A0[k] = A[k] = uniform();
        CHECK(phc_jacobi_svd(A, m, n, s, V) == 0);
        CHECK(s[2] <= 1e-15 * s[0] && s[3] <= 1e-15 * s[0] && s[1] > 1e-3 * s[0]);
        double rec, orth;
        residuals(A0, A, V, m, n, &rec, &orth);
        CHECK(rec < 1e-14 && orth < 1e-14);
    }
    /* NaN: reported, not looped on */
    A[0] = NAN;
    CHECK(phc_jacobi_svd(A, 2, 2, s, V) == 1);
    /* the zero matrix: all singular values 0, V = I */
    memset(A, 0, sizeof A);
    CHECK(phc_jacobi_svd(A, 5, 3, s, V) == 0);
    CHECK(s[0] == 0 && V[0] == 1 && V[4] == 1 && V[8] == 1);

    /* least squares: a consistent system with a known solution, and a noisy
       one against dgelsd (rcond 1e-13, as the fit's polishing step) */
    double worst_ls = 0, worst_dgelsd = 0;
    for (int rep = 0; rep < 50; ++rep) {
        const size_t n = 1 + (size_t)(rep % 8), m = n + 3 + (size_t)(rep * 11 % 60);
        double xt[NMAX];
        for (size_t j = 0; j < n; ++j)
            xt[j] = uniform() * 10;
        for (size_t i = 0; i < m; ++i) {
            b[i] = 0;
            for (size_t j = 0; j < n; ++j) {
                A[i * n + j] = uniform();
                b[i] += A[i * n + j] * xt[j];
            }
        }
        size_t rank = 0;
        CHECK(phc_jacobi_lstsq(A, m, n, b, 1e-13, V, work, x, &rank) == 0);
        CHECK(rank == n);
        for (size_t j = 0; j < n; ++j)
            worst_ls = fmax(worst_ls, fabs(x[j] - xt[j]) / 10);
        for (size_t i = 0; i < m; ++i) {
            for (size_t j = 0; j < n; ++j)
                A[i * n + j] = B[i * n + j] = uniform();
            bl[i] = b[i] = uniform();
        }
        lapack_int lrank = 0;
        CHECK(LAPACKE_dgelsd(LAPACK_ROW_MAJOR, (lapack_int)m, (lapack_int)n, 1, B, (lapack_int)n, bl, 1, sl, 1e-13,
                             &lrank) == 0);
        CHECK(phc_jacobi_lstsq(A, m, n, b, 1e-13, V, work, x, &rank) == 0);
        CHECK(rank == (size_t)lrank);
        for (size_t j = 0; j < n; ++j)
            worst_dgelsd = fmax(worst_dgelsd, fabs(x[j] - bl[j]) / (1 + fabs(bl[j])));
    }
    /* rank-deficient least squares: the minimum-norm solution.  Columns 0 and
       1 equal: x0 = x1 = c / 2 where c fits b with column 0 alone */
    {
        const size_t m = 6, n = 2;
        double num = 0, den = 0;
        for (size_t i = 0; i < m; ++i) {
            A[i * n] = A[i * n + 1] = uniform();
            b[i] = uniform();
            num += A[i * n] * b[i];
            den += A[i * n] * A[i * n];
        }
        size_t rank = 0;
        CHECK(phc_jacobi_lstsq(A, m, n, b, 1e-13, V, work, x, &rank) == 0);
        CHECK(rank == 1);
        CHECK_NEAR(x[0], num / den / 2, 1e-14, 1e-13);
        CHECK_NEAR(x[1], num / den / 2, 1e-14, 1e-13);
    }
    printf("least squares: exact solutions to %.3g (relative to |x| ~ 10), dgelsd's to %.3g\n", worst_ls,
           worst_dgelsd);
    CHECK(worst_ls < 1e-13);
    CHECK(worst_dgelsd < 1e-12);
    return check_finish("test_jacobi_svd");
}
