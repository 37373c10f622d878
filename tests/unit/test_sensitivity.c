/* Unit tests of fit/engine/sensitivity.c: FME-style L1/L2 summaries and the
 * collinearity index of Brun et al. (2001).
 *
 * Two columns at angle theta: after scaling to unit length they are u and v
 * with u.v = cos(theta), so the Gram matrix is [[1, c], [c, 1]] with
 * eigenvalues 1 +- c.  The smallest is 1 - |cos(theta)|, and
 *     gamma = 1 / sqrt(1 - |cos(theta)|):
 * 1 for orthogonal columns, sqrt(2) at 60 degrees, infinite for parallel
 * ones.  Larger subsets are checked against GSL's symmetric eigensolver. */
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_vector.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fit/engine/sensitivity.h"

static const double PI = 3.14159265358979323846;

static double choose(size_t n, size_t k)
{
    double r = 1;
    for (size_t i = 1; i <= k; ++i)
        r = r * (double)(n - k + i) / (double)i;
    return r;
}

/* gamma of subset idx[0..k-1] of the columns of S (m x n), by GSL. */
static double gsl_gamma(const double *S, size_t m, size_t n, const size_t *idx, size_t k)
{
    gsl_matrix *G = gsl_matrix_alloc(k, k);
    gsl_vector *w = gsl_vector_alloc(k);
    gsl_eigen_symm_workspace *ws = gsl_eigen_symm_alloc(k);
    for (size_t a = 0; a < k; ++a)
        for (size_t b = 0; b < k; ++b) {
            double g = 0, na = 0, nb = 0;
            for (size_t i = 0; i < m; ++i) {
                g += S[i * n + idx[a]] * S[i * n + idx[b]];
                na += S[i * n + idx[a]] * S[i * n + idx[a]];
                nb += S[i * n + idx[b]] * S[i * n + idx[b]];
            }
            gsl_matrix_set(G, a, b, g / sqrt(na * nb));
        }
    gsl_eigen_symm(G, w, ws);
    double lmin = INFINITY;
    for (size_t a = 0; a < k; ++a)
        lmin = fmin(lmin, gsl_vector_get(w, a));
    gsl_eigen_symm_free(ws);
    gsl_vector_free(w);
    gsl_matrix_free(G);
    return 1.0 / sqrt(lmin);
}

/* The set with exactly these members, or NULL. */
static const phc_collinear_set *find_set(const phc_sensitivity *s, const size_t *idx, size_t k)
{
    for (size_t i = 0; i < s->n_sets; ++i) {
        if (s->sets[i].size != k)
            continue;
        int same = 1;
        for (size_t a = 0; a < k && same; ++a)
            same = s->sets[i].index[a] == idx[a];
        if (same)
            return &s->sets[i];
    }
    return NULL;
}

static void test_summaries(void)
{
    /* m = 4, n = 3:
     *   S = [  1  -2   0
     *         -3   4   0.5
     *          2   0  -0.5
     *          0  -2   1  ]
     * L1 = mean |S_.j| = (6/4, 8/4, 2/4) = (1.5, 2, 0.5)
     * L2 = sqrt(mean S^2) = sqrt(14/4, 24/4, 1.5/4) */
    const double S[12] = {1, -2, 0, -3, 4, 0.5, 2, 0, -0.5, 0, -2, 1};
    phc_sensitivity s;
    phc_error err;
    CHECK(phc_sensitivity_compute(S, 4, 3, 1000, &s, &err) == PHC_OK);
    CHECK(s.n == 3);
    CHECK_NEAR(s.l1[0], 1.5, 0, 1e-15);
    CHECK_NEAR(s.l1[1], 2.0, 0, 1e-15);
    CHECK_NEAR(s.l1[2], 0.5, 0, 1e-15);
    CHECK_NEAR(s.l2[0], sqrt(3.5), 0, 1e-15);
    CHECK_NEAR(s.l2[1], sqrt(6.0), 0, 1e-15);
    CHECK_NEAR(s.l2[2], sqrt(0.375), 0, 1e-15);
    /* subsets: {0,1}, {0,2}, {1,2}, {0,1,2} */
    CHECK(s.n_sets == 4);
    CHECK(s.max_size == 3);
    /* {0,1}: cos = (-2 - 12 + 0 + 0) / sqrt(14 * 24) */
    const size_t i01[2] = {0, 1};
    const phc_collinear_set *set = find_set(&s, i01, 2);
    CHECK(set != NULL);
    if (set)
        CHECK_NEAR(set->gamma, 1.0 / sqrt(1.0 - 14.0 / sqrt(14.0 * 24.0)), 0, 1e-13);
    const size_t i012[3] = {0, 1, 2};
    set = find_set(&s, i012, 3);
    CHECK(set != NULL);
    if (set)
        CHECK_NEAR(set->gamma, gsl_gamma(S, 4, 3, i012, 3), 0, 1e-12);
    phc_sensitivity_clear(&s);
    CHECK(s.l1 == NULL && s.sets == NULL && s.n_sets == 0);
    phc_sensitivity_clear(&s);
    phc_sensitivity_clear(NULL);
}

static double gamma_of_pair(const double *S, size_t m)
{
    phc_sensitivity s;
    phc_error err;
    double g = NAN;
    if (phc_sensitivity_compute(S, m, 2, 100, &s, &err) == PHC_OK && s.n_sets == 1) {
        g = s.sets[0].gamma;
        CHECK(s.max_gamma[2] == g || (isnan(g) && isnan(s.max_gamma[2])));
    }
    CHECK(s.n_sets == 1);
    phc_sensitivity_clear(&s);
    return g;
}

static void test_pairs(void)
{
    enum { M = 5 };
    double S[2 * M];
    /* identical columns -> inf, for many different columns (the Gram
     * matrix's off-diagonal then rounds to 1 +- 1 ulp or exactly 1) */
    int finite = 0;
    for (int t = 0; t < 200; ++t) {
        for (size_t i = 0; i < M; ++i)
            S[2 * i] = S[2 * i + 1] = sin(0.9 * t + 1.7 * (double)i) * (1.0 + t);
        const double g = gamma_of_pair(S, M);
        if (!isinf(g) && finite++ < 3)
            fprintf(stderr, "identical columns (case %d): gamma %.17g\n", t, g);
    }
    CHECK(finite == 0);
    /* proportional columns (y = a b x: one a multiple of the other) -> inf */
    finite = 0;
    for (int t = 0; t < 200; ++t) {
        const double factor = (t % 2 ? -1.0 : 1.0) * (0.37 + 0.61 * t);
        for (size_t i = 0; i < M; ++i) {
            S[2 * i] = cos(1.1 * t + 0.3 * (double)i * (double)i);
            S[2 * i + 1] = factor * S[2 * i];
        }
        const double g = gamma_of_pair(S, M);
        if (!isinf(g) && finite++ < 3)
            fprintf(stderr, "proportional columns (case %d): gamma %.17g\n", t, g);
    }
    CHECK(finite == 0);
    /* orthogonal columns -> 1 */
    const double orth[2 * M] = {1, 0, 0, 2, 3, 0, 0, -1, 0.5, 0};
    CHECK_NEAR(gamma_of_pair(orth, M), 1.0, 0, 1e-15);
    /* a zero column -> inf */
    const double zero[2 * M] = {1, 0, 2, 0, 3, 0, 4, 0, 5, 0};
    CHECK(isinf(gamma_of_pair(zero, M)));
    /* columns at angle theta, embedded in R^5 and scaled differently:
     * gamma = 1 / sqrt(1 - |cos theta|) */
    static const double degrees[] = {90, 60, 45, 30, 10, 1, 0.1, 120, 170};
    for (size_t k = 0; k < sizeof degrees / sizeof degrees[0]; ++k) {
        const double th = degrees[k] * PI / 180;
        /* u = (1, 0) in the plane of e1, e2 rotated into e1..e5; v at angle th */
        const double u[M] = {0.6, 0, 0.8, 0, 0};
        const double w[M] = {0, 0.48, 0, 0.6, 0.64}; /* unit, orthogonal to u */
        for (size_t i = 0; i < M; ++i) {
            S[2 * i] = 7.0 * u[i];
            S[2 * i + 1] = 0.01 * (cos(th) * u[i] + sin(th) * w[i]);
        }
        const double want = 1.0 / sqrt(1.0 - fabs(cos(th)));
        const double got = gamma_of_pair(S, M);
        /* lambda_min = 1 - |c| loses digits as theta -> 0: error ~ eps / (1 - |c|) */
        const double tol = 1e-14 / (1.0 - fabs(cos(th)));
        if (!(fabs(got - want) <= tol * want))
            fprintf(stderr, "theta %g deg: gamma %.17g, expected %.17g\n", degrees[k], got, want);
        CHECK_NEAR(got, want, 0, tol);
    }
    CHECK_NEAR(1.0 / sqrt(1.0 - cos(PI / 3)), sqrt(2.0), 0, 1e-15); /* the 60-degree case */
}

/* A deterministic "random" m x n matrix. */
static void fill(double *S, size_t m, size_t n, double seed)
{
    for (size_t i = 0; i < m; ++i)
        for (size_t j = 0; j < n; ++j)
            S[i * n + j] = sin(seed + 1.234 * (double)i + 2.345 * (double)j * (double)j) + 0.3 * cos(0.7 * (double)(i * j));
}

static void test_enumeration(void)
{
    enum { M = 30 };
    static double S[M * 12];
    static const size_t ns[] = {1, 2, 3, 4, 6, 7, 10, 12};
    for (size_t q = 0; q < sizeof ns / sizeof ns[0]; ++q) {
        const size_t n = ns[q];
        fill(S, M, n, 0.3 * (double)q);
        phc_sensitivity s;
        phc_error err;
        CHECK(phc_sensitivity_compute(S, M, n, 1000000, &s, &err) == PHC_OK);
        const size_t kmax = n < 6 ? n : 6;
        double expected = 0;
        for (size_t k = 2; k <= kmax; ++k)
            expected += choose(n, k);
        CHECK(s.n_sets == (size_t)expected);
        CHECK(s.max_size == (n >= 2 ? kmax : 1));
        /* every subset once, members increasing and in range; sizes counted */
        unsigned char *seen = calloc((size_t)1 << n, 1);
        size_t per_size[PHC_COLLIN_MAX_SIZE + 1] = {0};
        double max_by_size[PHC_COLLIN_MAX_SIZE + 1];
        for (size_t k = 0; k <= PHC_COLLIN_MAX_SIZE; ++k)
            max_by_size[k] = 0;
        int dup = 0, bad = 0, mismatch = 0;
        for (size_t i = 0; i < s.n_sets; ++i) {
            const phc_collinear_set *set = &s.sets[i];
            unsigned mask = 0;
            if (set->size < 2 || set->size > kmax)
                bad = 1;
            for (size_t a = 0; a < set->size && !bad; ++a) {
                if (set->index[a] >= n || (a && set->index[a] <= set->index[a - 1]))
                    bad = 1;
                mask |= 1u << set->index[a];
            }
            if (bad)
                break;
            dup |= seen[mask]++;
            per_size[set->size]++;
            max_by_size[set->size] = fmax(max_by_size[set->size], set->gamma);
            /* each gamma against GSL (every set for small n, a sample for large) */
            if (n <= 7 || i % 17 == 0) {
                const double want = gsl_gamma(S, M, n, set->index, set->size);
                if (!(fabs(set->gamma - want) <= 1e-10 * want) && mismatch++ < 3)
                    fprintf(stderr, "n=%zu set %zu: gamma %.17g, GSL %.17g\n", n, i, set->gamma, want);
            }
            if (i + 1 < s.n_sets)
                CHECK(s.sets[i].gamma >= s.sets[i + 1].gamma); /* sorted descending */
        }
        CHECK(!bad && !dup && mismatch == 0);
        for (size_t k = 2; k <= kmax; ++k) {
            CHECK(per_size[k] == (size_t)choose(n, k));
            CHECK(s.max_gamma[k] == max_by_size[k]);
            CHECK(s.max_gamma[k] >= 1.0);
        }
        free(seen);
        phc_sensitivity_clear(&s);
    }
}

static void test_budget(void)
{
    enum { M = 20, N = 10 };
    static double S[M * N];
    fill(S, M, N, 1.0);
    /* C(10, k) for k = 2..6: 45, 120, 210, 252, 210 (cumulative 45, 165, 375, 627, 837) */
    static const struct {
        size_t budget, max_size, n_sets;
    } cases[] = {
        {1000000, 6, 837}, {837, 6, 837}, {836, 5, 627}, {627, 5, 627}, {400, 4, 375}, {374, 3, 165},
        {165, 3, 165},     {164, 2, 45},  {45, 2, 45},   {44, 1, 0},    {0, 1, 0},
    };
    for (size_t q = 0; q < sizeof cases / sizeof cases[0]; ++q) {
        phc_sensitivity s;
        phc_error err;
        CHECK(phc_sensitivity_compute(S, M, N, cases[q].budget, &s, &err) == PHC_OK);
        if (s.max_size != cases[q].max_size || s.n_sets != cases[q].n_sets)
            fprintf(stderr, "budget %zu: max_size %zu, n_sets %zu\n", cases[q].budget, s.max_size, s.n_sets);
        CHECK(s.max_size == cases[q].max_size);
        CHECK(s.n_sets == cases[q].n_sets);
        for (size_t i = 0; i < s.n_sets; ++i)
            CHECK(s.sets[i].size <= s.max_size);
        for (size_t i = 0; i + 1 < s.n_sets; ++i)
            CHECK(s.sets[i].gamma >= s.sets[i + 1].gamma);
        for (size_t k = s.max_size + 1; k <= PHC_COLLIN_MAX_SIZE; ++k)
            CHECK(s.max_gamma[k] == 0); /* sizes not evaluated */
        /* the summaries do not depend on the budget */
        CHECK(s.l1 != NULL && s.l2 != NULL);
        phc_sensitivity_clear(&s);
    }
}

/* A collinear pair inside a larger set: every subset containing both is
 * infinite and sorts first; the infinite ones are exactly those. */
static void test_sorting_with_infinite(void)
{
    enum { M = 12, N = 5 };
    double S[M * N];
    fill(S, M, N, 2.0);
    for (size_t i = 0; i < M; ++i)
        S[i * N + 3] = -2.5 * S[i * N + 1]; /* columns 1 and 3 parallel */
    phc_sensitivity s;
    phc_error err;
    CHECK(phc_sensitivity_compute(S, M, N, 1000, &s, &err) == PHC_OK);
    /* subsets containing both 1 and 3: sizes 2..5 from the other 3 columns: 2^3 = 8 */
    size_t n_inf = 0;
    for (size_t i = 0; i < s.n_sets; ++i) {
        int has1 = 0, has3 = 0;
        for (size_t a = 0; a < s.sets[i].size; ++a) {
            has1 |= s.sets[i].index[a] == 1;
            has3 |= s.sets[i].index[a] == 3;
        }
        if (isinf(s.sets[i].gamma)) {
            CHECK(i == n_inf); /* infinite ones first */
            ++n_inf;
            CHECK(has1 && has3);
        } else {
            if (has1 && has3)
                fprintf(stderr, "set %zu of size %zu with both parallel columns: gamma %.17g\n", i, s.sets[i].size,
                        s.sets[i].gamma);
            CHECK(!(has1 && has3));
            CHECK(isfinite(s.sets[i].gamma) && s.sets[i].gamma >= 1.0);
        }
    }
    CHECK(n_inf == 8);
    for (size_t k = 2; k <= 5; ++k)
        CHECK(isinf(s.max_gamma[k]));
    phc_sensitivity_clear(&s);
}

static void test_invalid(void)
{
    const double S[2] = {1, 2};
    phc_sensitivity s;
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_sensitivity_compute(NULL, 1, 2, 10, &s, &err) == PHC_ERR_INVALID);
    CHECK(strlen(err.message) > 0);
    CHECK(phc_sensitivity_compute(S, 0, 2, 10, &s, &err) == PHC_ERR_INVALID);
    CHECK(phc_sensitivity_compute(S, 1, 0, 10, &s, &err) == PHC_ERR_INVALID);
    /* one parameter: summaries, no subsets */
    CHECK(phc_sensitivity_compute(S, 2, 1, 10, &s, &err) == PHC_OK);
    CHECK(s.n_sets == 0 && s.sets == NULL);
    CHECK_NEAR(s.l1[0], 1.5, 0, 1e-15);
    CHECK_NEAR(s.l2[0], sqrt(2.5), 0, 1e-15);
    phc_sensitivity_clear(&s);
}

int main(void)
{
    test_summaries();
    test_pairs();
    test_enumeration();
    test_budget();
    test_sorting_with_infinite();
    test_invalid();
    return check_finish("test_sensitivity");
}
