/* Unit tests of fit/engine/uncertainty.c: covariance, standard errors, correlation
 * and undetermined directions from a Jacobian.
 *
 * References are computed here independently: s^2 (X'X)^-1 by GSL's
 * Cholesky inverse and, for 2x2, by the textbook formula; the condition
 * number by GSL's SVD of the column-normalised Jacobian. */
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_vector.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/engine/uncertainty.h"

/* s2 (J'J)^-1 by GSL (Cholesky), n x n row-major into out. */
static void gsl_cov(const double *J, size_t m, size_t n, double s2, double *out)
{
    gsl_matrix *A = gsl_matrix_calloc(n, n);
    for (size_t a = 0; a < n; ++a)
        for (size_t b = 0; b < n; ++b) {
            double s = 0;
            for (size_t i = 0; i < m; ++i)
                s += J[i * n + a] * J[i * n + b];
            gsl_matrix_set(A, a, b, s);
        }
    CHECK(gsl_linalg_cholesky_decomp1(A) == 0);
    CHECK(gsl_linalg_cholesky_invert(A) == 0);
    for (size_t a = 0; a < n; ++a)
        for (size_t b = 0; b < n; ++b)
            out[a * n + b] = s2 * gsl_matrix_get(A, a, b);
    gsl_matrix_free(A);
}

/* Condition number of J with unit-length columns, by GSL's SVD. */
static double gsl_condition(const double *J, size_t m, size_t n)
{
    gsl_matrix *A = gsl_matrix_alloc(m, n), *V = gsl_matrix_alloc(n, n);
    gsl_vector *S = gsl_vector_alloc(n), *work = gsl_vector_alloc(n);
    for (size_t b = 0; b < n; ++b) {
        double ss = 0;
        for (size_t i = 0; i < m; ++i)
            ss += J[i * n + b] * J[i * n + b];
        for (size_t i = 0; i < m; ++i)
            gsl_matrix_set(A, i, b, J[i * n + b] / sqrt(ss));
    }
    gsl_linalg_SV_decomp(A, V, S, work);
    const double c = gsl_vector_get(S, 0) / gsl_vector_get(S, n - 1);
    gsl_matrix_free(A);
    gsl_matrix_free(V);
    gsl_vector_free(S);
    gsl_vector_free(work);
    return c;
}

/* ---- full rank ----------------------------------------------------------------- */

static void test_line_2x2_by_hand(void)
{
    /* y = a + b x: J rows (1, x_i) (the sign of J does not matter to J'J) */
    enum { M = 7 };
    const double x[M] = {0.5, 1.0, 1.5, 2.5, 3.0, 4.5, 6.0};
    double J[M * 2];
    double sx = 0, sxx = 0;
    for (size_t i = 0; i < M; ++i) {
        J[2 * i] = -1.0;
        J[2 * i + 1] = -x[i];
        sx += x[i];
        sxx += x[i] * x[i];
    }
    const double s2 = 0.0123;
    /* (X'X)^-1 = 1/(n Sxx - Sx^2) [[Sxx, -Sx], [-Sx, n]] */
    const double det = M * sxx - sx * sx;
    const double want[4] = {s2 * sxx / det, -s2 * sx / det, -s2 * sx / det, s2 * M / det};
    phc_covariance c;
    phc_error err;
    CHECK(phc_covariance_compute(J, M, 2, s2, 1e-10, NULL, &c, &err) == PHC_OK);
    CHECK(c.n == 2 && c.rank == 2 && c.n_null == 0);
    for (size_t k = 0; k < 4; ++k)
        CHECK_NEAR(c.cov[k], want[k], 0, 1e-12);
    CHECK_NEAR(c.stderr_[0], sqrt(want[0]), 0, 1e-12);
    CHECK_NEAR(c.stderr_[1], sqrt(want[3]), 0, 1e-12);
    /* corr(a, b) = -Sx / sqrt(n Sxx) */
    CHECK_NEAR(c.correlation[1], -sx / sqrt(M * sxx), 0, 1e-12);
    CHECK_NEAR(c.correlation[2], c.correlation[1], 0, 1e-15);
    CHECK_NEAR(c.correlation[0], 1.0, 0, 1e-15);
    CHECK_NEAR(c.correlation[3], 1.0, 0, 1e-15);
    /* condition of [1/sqrt(n), x/|x|]: singular values sqrt(1 +- |r|), r = Sx/sqrt(n Sxx) */
    const double r = sx / sqrt(M * sxx);
    CHECK_NEAR(c.condition, sqrt((1 + r) / (1 - r)), 0, 1e-12);
    CHECK(isfinite(c.condition));
    phc_covariance_clear(&c);
    CHECK(c.cov == NULL && c.n == 0);
    phc_covariance_clear(&c); /* twice is harmless */
    phc_covariance_clear(NULL);
}

static void test_full_rank_against_gsl(void)
{
    /* y = p0 + p1 x + p2 x^2 + p3 exp(-x): a well-posed 4-parameter model */
    enum { M = 15, N = 4 };
    double J[M * N];
    for (size_t i = 0; i < M; ++i) {
        const double x = 0.3 * (double)i;
        J[i * N + 0] = 1.0;
        J[i * N + 1] = x;
        J[i * N + 2] = x * x;
        J[i * N + 3] = exp(-x);
    }
    const double s2 = 2.5;
    double want[N * N];
    gsl_cov(J, M, N, s2, want);
    static const double scales[N] = {1e3, 1e-3, 1, 7};
    for (int with_scale = 0; with_scale < 2; ++with_scale) {
        phc_covariance c;
        phc_error err;
        CHECK(phc_covariance_compute(J, M, N, s2, 1e-10, with_scale ? scales : NULL, &c, &err) == PHC_OK);
        CHECK(c.rank == N && c.n_null == 0);
        for (size_t a = 0; a < N; ++a) {
            CHECK_NEAR(c.stderr_[a], sqrt(want[a * N + a]), 0, 1e-9);
            for (size_t b = 0; b < N; ++b) {
                CHECK_NEAR(c.cov[a * N + b], want[a * N + b], 1e-9 * sqrt(want[a * N + a] * want[b * N + b]), 1e-9);
                CHECK_NEAR(c.correlation[a * N + b],
                           want[a * N + b] / sqrt(want[a * N + a] * want[b * N + b]), 1e-9, 0);
                CHECK(c.cov[a * N + b] == c.cov[b * N + a] || fabs(c.cov[a * N + b] - c.cov[b * N + a]) <=
                                                                  1e-14 * fabs(c.cov[a * N + b]));
            }
            CHECK_NEAR(c.correlation[a * N + a], 1.0, 0, 1e-15);
        }
        CHECK_NEAR(c.condition, gsl_condition(J, M, N), 0, 1e-9);
        phc_covariance_clear(&c);
    }
    /* the covariance scales with s2 */
    phc_covariance c1, c2;
    phc_error err;
    CHECK(phc_covariance_compute(J, M, N, 1.0, 1e-10, NULL, &c1, &err) == PHC_OK);
    CHECK(phc_covariance_compute(J, M, N, 4.0, 1e-10, NULL, &c2, &err) == PHC_OK);
    for (size_t a = 0; a < N; ++a)
        CHECK_NEAR(c2.stderr_[a], 2.0 * c1.stderr_[a], 0, 1e-14);
    phc_covariance_clear(&c1);
    phc_covariance_clear(&c2);
}

/* ---- rank deficiency --------------------------------------------------------- */

static void test_sum_only(void)
{
    /* y = (a + b) x: both columns are x */
    enum { M = 6 };
    double J[M * 2];
    for (size_t i = 0; i < M; ++i)
        J[2 * i] = J[2 * i + 1] = -(0.5 + (double)i);
    phc_covariance c;
    phc_error err;
    CHECK(phc_covariance_compute(J, M, 2, 0.7, 1e-10, NULL, &c, &err) == PHC_OK);
    CHECK(c.rank == 1);
    CHECK(c.n_null == 1);
    CHECK(isinf(c.condition));
    CHECK(isnan(c.stderr_[0]) && isnan(c.stderr_[1]));
    CHECK(isnan(c.correlation[1]) && isnan(c.correlation[2]));
    CHECK(c.correlation[0] == 1.0 && c.correlation[3] == 1.0);
    const double *v = c.null_vectors;
    CHECK_NEAR(fabs(v[0]), sqrt(0.5), 0, 1e-12);
    CHECK_NEAR(fabs(v[1]), sqrt(0.5), 0, 1e-12);
    CHECK(v[0] * v[1] < 0); /* +-(0.707, -0.707): a up, b down */
    const char *names[2] = {"a", "b"};
    char buf[128];
    phc_covariance_describe_null(&c, 0, names, buf, sizeof buf);
    if (strcmp(buf, "0.707 a - 0.707 b") != 0)
        fprintf(stderr, "null vector described as '%s'\n", buf);
    CHECK(strcmp(buf, "0.707 a - 0.707 b") == 0);
    /* out-of-range index and tiny buffers are safe */
    phc_covariance_describe_null(&c, 1, names, buf, sizeof buf);
    CHECK(buf[0] == '\0');
    char small[6];
    memset(small, 'x', sizeof small);
    phc_covariance_describe_null(&c, 0, names, small, sizeof small);
    CHECK(memchr(small, '\0', sizeof small) != NULL);
    CHECK(strncmp(small, "0.707", 5) == 0);
    phc_covariance_describe_null(&c, 0, names, NULL, 0);
    phc_covariance_clear(&c);
}

/* The text of a +-(0.707, -0.707) direction does not depend on the last bits
 * of the SVD (whose two magnitudes often differ by an ulp): always a first. */
static void test_sum_only_text_is_stable(void)
{
    int differ = 0;
    for (int t = 0; t < 300; ++t) {
        const size_t m = 3 + (size_t)(t % 17);
        double J[2 * 20];
        for (size_t i = 0; i < m; ++i)
            J[2 * i] = J[2 * i + 1] = sin(1.3 * t + 0.7 * (double)i) + 0.01 * t;
        phc_covariance c;
        phc_error err;
        if (phc_covariance_compute(J, m, 2, 1.0, 1e-10, NULL, &c, &err) != PHC_OK) {
            CHECK(!"covariance failed");
            continue;
        }
        const char *names[2] = {"a", "b"};
        char buf[64];
        phc_covariance_describe_null(&c, 0, names, buf, sizeof buf);
        if (c.n_null != 1 || strcmp(buf, "0.707 a - 0.707 b") != 0) {
            if (differ++ < 3)
                fprintf(stderr, "case %d: '%s' (v = %.17g, %.17g)\n", t, buf, c.null_vectors[0], c.null_vectors[1]);
        }
        phc_covariance_clear(&c);
    }
    CHECK(differ == 0);
}

/* y = (a + b) x + c: the sum is undetermined, c is not; c's variance equals
 * that of the reparametrised model y = s x + c. */
static void test_sum_with_determined_parameter(void)
{
    enum { M = 8 };
    double J[M * 3], Jr[M * 2];
    for (size_t i = 0; i < M; ++i) {
        const double x = 0.25 + 0.5 * (double)i;
        J[3 * i] = J[3 * i + 1] = x;
        J[3 * i + 2] = 1.0;
        Jr[2 * i] = x;
        Jr[2 * i + 1] = 1.0;
    }
    const double s2 = 0.3;
    double want[4];
    gsl_cov(Jr, M, 2, s2, want);
    phc_covariance c;
    phc_error err;
    CHECK(phc_covariance_compute(J, M, 3, s2, 1e-10, NULL, &c, &err) == PHC_OK);
    CHECK(c.rank == 2 && c.n_null == 1);
    CHECK(isnan(c.stderr_[0]) && isnan(c.stderr_[1]));
    CHECK_NEAR(c.stderr_[2], sqrt(want[3]), 0, 1e-10);
    CHECK(isnan(c.correlation[0 * 3 + 2]) && isnan(c.correlation[2 * 3 + 1]));
    CHECK(c.correlation[2 * 3 + 2] == 1.0);
    CHECK(fabs(c.null_vectors[2]) < 1e-12); /* c takes no part in the null direction */
    const char *names[3] = {"a", "b", "c"};
    char buf[128];
    phc_covariance_describe_null(&c, 0, names, buf, sizeof buf);
    CHECK(strcmp(buf, "0.707 a - 0.707 b") == 0);
    phc_covariance_clear(&c);
}

/* A column whose effect |J_j| scale_j is negligible is undetermined; with a
 * scale that makes its effect visible it is determined. */
static void test_negligible_column(void)
{
    enum { M = 9 };
    double J[M * 2];
    double sxx = 0;
    for (size_t i = 0; i < M; ++i) {
        const double x = 1.0 + (double)i;
        J[2 * i] = x;
        J[2 * i + 1] = 1e-14 * cos((double)i); /* e.g. exp(-b x) with b driven huge */
        sxx += x * x;
    }
    const char *names[2] = {"a", "rate"};
    char buf[64];
    phc_covariance c;
    phc_error err;
    /* no scale: effect ratio 1e-14 / |x| < rcond */
    CHECK(phc_covariance_compute(J, M, 2, 1.0, 1e-10, NULL, &c, &err) == PHC_OK);
    CHECK(c.rank == 1 && c.n_null == 1);
    CHECK(isnan(c.stderr_[1]));
    CHECK_NEAR(c.stderr_[0], sqrt(1.0 / sxx), 0, 1e-12); /* a alone: 1 / |x| */
    CHECK(isnan(c.correlation[1]) && isnan(c.correlation[2]));
    CHECK_NEAR(fabs(c.null_vectors[1]), 1.0, 0, 1e-12);
    CHECK(fabs(c.null_vectors[0]) < 1e-12);
    phc_covariance_describe_null(&c, 0, names, buf, sizeof buf);
    CHECK(strcmp(buf, "1 rate") == 0);
    phc_covariance_clear(&c);
    /* a typical magnitude of 1e6 for the second parameter: effect 1e-8 relative, visible */
    const double big[2] = {1.0, 1e6};
    CHECK(phc_covariance_compute(J, M, 2, 1.0, 1e-10, big, &c, &err) == PHC_OK);
    CHECK(c.rank == 2 && c.n_null == 0);
    CHECK(isfinite(c.stderr_[0]) && isfinite(c.stderr_[1]));
    phc_covariance_clear(&c);
    /* the first parameter's scale does not rescue the second */
    const double other[2] = {1e6, 1.0};
    CHECK(phc_covariance_compute(J, M, 2, 1.0, 1e-10, other, &c, &err) == PHC_OK);
    CHECK(c.rank == 1 && isnan(c.stderr_[1]) && isfinite(c.stderr_[0]));
    phc_covariance_clear(&c);
    /* an exactly zero column */
    for (size_t i = 0; i < M; ++i)
        J[2 * i + 1] = 0.0;
    CHECK(phc_covariance_compute(J, M, 2, 1.0, 1e-10, NULL, &c, &err) == PHC_OK);
    CHECK(c.rank == 1 && isnan(c.stderr_[1]));
    CHECK_NEAR(c.stderr_[0], sqrt(1.0 / sxx), 0, 1e-12);
    phc_covariance_clear(&c);
}

/* Nearly collinear columns: the rank decision follows rcond on the
 * column-scaled J (smallest singular value sqrt(1 - cos theta) ~ theta/sqrt(2)). */
static void test_near_collinear(void)
{
    enum { M = 2 };
    for (int k = 0; k < 2; ++k) {
        const double theta = k == 0 ? 1e-6 : 1e-13;
        const double J[M * 2] = {1.0, cos(theta), 0.0, sin(theta)};
        phc_covariance c;
        phc_error err;
        CHECK(phc_covariance_compute(J, M, 2, 1.0, 1e-10, NULL, &c, &err) == PHC_OK);
        if (k == 0) {
            CHECK(c.rank == 2);
            /* exact inverse of [[1, cos],[0, sin]]' [[1, cos],[0, sin]]: var(p1) = 1/sin^2 */
            CHECK_NEAR(c.stderr_[1], 1.0 / sin(theta), 0, 1e-6);
        } else {
            CHECK(c.rank == 1);
            CHECK(isnan(c.stderr_[0]) && isnan(c.stderr_[1]));
        }
        phc_covariance_clear(&c);
    }
}

/* Fewer rows than parameters: at most rank m, no crash (LAPACK sees padded rows). */
static void test_fewer_rows(void)
{
    const double J[2] = {1.0, 2.0};
    phc_covariance c;
    phc_error err;
    CHECK(phc_covariance_compute(J, 1, 2, 1.0, 1e-10, NULL, &c, &err) == PHC_OK);
    CHECK(c.rank == 1 && c.n_null == 1);
    CHECK(isnan(c.stderr_[0]) && isnan(c.stderr_[1]));
    const char *names[2] = {"p", "q"};
    char buf[64];
    phc_covariance_describe_null(&c, 0, names, buf, sizeof buf);
    CHECK(strcmp(buf, "0.707 p - 0.707 q") == 0); /* in scaled coordinates */
    phc_covariance_clear(&c);
}

static void test_invalid(void)
{
    const double J[2] = {1, 2};
    phc_covariance c;
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_covariance_compute(NULL, 1, 2, 1, 1e-10, NULL, &c, &err) == PHC_ERR_INVALID);
    CHECK(strlen(err.message) > 0);
    CHECK(phc_covariance_compute(J, 0, 2, 1, 1e-10, NULL, &c, &err) == PHC_ERR_INVALID);
    CHECK(phc_covariance_compute(J, 1, 0, 1, 1e-10, NULL, &c, &err) == PHC_ERR_INVALID);
    CHECK(c.cov == NULL);
}

int main(void)
{
    test_line_2x2_by_hand();
    test_full_rank_against_gsl();
    test_sum_only();
    test_sum_only_text_is_stable();
    test_sum_with_determined_parameter();
    test_negligible_column();
    test_near_collinear();
    test_fewer_rows();
    test_invalid();
    return check_finish("test_uncertainty");
}
