/* Sensitivities and collinearity indices: see sensitivity.h. */
#include "fit/engine/sensitivity.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>


void phc_sensitivity_clear(phc_sensitivity *s)
{
    if (!s)
        return;
    free(s->l1);
    free(s->l2);
    free(s->sets);
    memset(s, 0, sizeof *s);
}

static double binomial(size_t n, size_t k)
{
    double r = 1;
    for (size_t i = 1; i <= k; ++i)
        r = r * (double)(n - k + i) / (double)i;
    return r;
}

static int by_gamma_desc(const void *a, const void *b)
{
    const double ga = ((const phc_collinear_set *)a)->gamma, gb = ((const phc_collinear_set *)b)->gamma;
    return (ga < gb) - (ga > gb);
}

/* Subsets whose eigenvalues are computed side by side (jacobi_lanes). */
#define LANES 4
#define MAX_K2 (PHC_COLLIN_MAX_SIZE * PHC_COLLIN_MAX_SIZE)

/* Rotation (c, sn) of rows and columns p and q of the symmetric k x k
 * matrix a at row r (r != p, q). */
static inline void rotate_at(double *a, size_t k, size_t r, size_t p, size_t q, double c, double sn)
{
    const double arp = a[r * k + p], arq = a[r * k + q];
    a[r * k + p] = a[p * k + r] = c * arp - sn * arq;
    a[r * k + q] = a[q * k + r] = sn * arp + c * arq;
}

/* Jacobi's test |a_pq| > eps sqrt(|a_pp a_qq|) (jacobi_lanes), decided
 * without the square root when the squares settle it: with P = |a_pp a_qq|
 * and q = a_pq^2 both normal, q > 4 eps^2 P means |a_pq| > 2 eps sqrt(P)
 * and q < eps^2 P / 4 means |a_pq| < eps sqrt(P) / 2, far beyond the
 * roundings of q, P and the square root; only between the two (and for
 * numbers near underflow, overflow or NaN) is the test itself evaluated,
 * so every decision is the test's. */
static inline int rotation_wanted(double app, double aqq, double apq)
{
    const double P = fabs(app) * fabs(aqq), q = apq * apq, e2P = DBL_EPSILON * DBL_EPSILON * P;
    if (e2P >= DBL_MIN && e2P <= DBL_MAX / 8 && q >= DBL_MIN) {
        if (q > 4 * e2P)
            return 1;
        if (q < 0.25 * e2P)
            return 0;
    }
    return fabs(apq) > DBL_EPSILON * sqrt(P);
}

/* Eigenvalues of the symmetric k x k matrices A[l] (row-major, destroyed)
 * of the lanes l < n_lanes with use[l] set, on their diagonals, by the
 * cyclic two-sided Jacobi method (Golub & Van Loan, Matrix Computations,
 * 4th ed., section 8.5: the rotation of 8.5.2, the row-cyclic order of
 * 8.5.3).  A pair (p, q) is skipped once |a_pq| <= eps sqrt(a_pp a_qq),
 * the relative test under which Jacobi's method finds the eigenvalues of a
 * positive definite matrix with a unit diagonal (a Gram matrix of unit
 * columns) to high relative accuracy (Demmel & Veselic 1992, SIAM J.
 * Matrix Anal. Appl. 13:1204-1245).  A rotation costs O(k), against the
 * O(k) dot products and updates of a one-sided rotation of the same
 * matrix.  failed[l] = 1 after 60 sweeps without convergence, else 0.
 *
 * Each matrix goes through exactly the rotations it would alone (its own
 * tests, sweeps and stop); the lanes only interleave them, so that the
 * processor overlaps one matrix's chain of square roots and divisions
 * (a rotation's c and s depend on each other) with the others'. */
static void jacobi_lanes(double A[][MAX_K2], const int *use, size_t n_lanes, size_t k, int *failed)
{
    int converged[LANES];
    for (size_t l = 0; l < n_lanes; ++l)
        converged[l] = !use[l] || k < 2;
    for (int sweep = 0; sweep < 60; ++sweep) {
        int busy = 0, rotated[LANES] = {0};
        for (size_t l = 0; l < n_lanes; ++l)
            busy |= !converged[l];
        if (!busy)
            break;
        for (size_t p = 0; p + 1 < k; ++p)
            for (size_t q = p + 1; q < k; ++q)
                for (size_t l = 0; l < n_lanes; ++l) {
                    if (converged[l])
                        continue;
                    double *a = A[l];
                    const double app = a[p * k + p], aqq = a[q * k + q], apq = a[p * k + q];
                    if (!rotation_wanted(app, aqq, apq))
                        continue;
                    rotated[l] = 1;
                    const double zeta = (aqq - app) / (2 * apq);
                    const double t = (zeta >= 0 ? 1.0 : -1.0) / (fabs(zeta) + sqrt(1 + zeta * zeta));
                    const double c = 1 / sqrt(1 + t * t), sn = c * t;
                    a[p * k + p] = app - t * apq;
                    a[q * k + q] = aqq + t * apq;
                    a[p * k + q] = a[q * k + p] = 0;
                    for (size_t r = 0; r < p; ++r)
                        rotate_at(a, k, r, p, q, c, sn);
                    for (size_t r = p + 1; r < q; ++r)
                        rotate_at(a, k, r, p, q, c, sn);
                    for (size_t r = q + 1; r < k; ++r)
                        rotate_at(a, k, r, p, q, c, sn);
                }
        for (size_t l = 0; l < n_lanes; ++l)
            if (!converged[l])
                converged[l] = !rotated[l];
    }
    for (size_t l = 0; l < n_lanes; ++l)
        failed[l] = use[l] && !converged[l];
}

/* gamma of n_sets subsets of one size k (at most LANES) from the Gram
 * matrix G = Sn'Sn of all n columns (norm: the columns' norms): the
 * smallest eigenvalue of each subset's k x k block (symmetric positive
 * semi-definite, unit diagonal); infinite for a subset with a zero column. */
static void subset_gammas(const double *G, size_t n, const double *norm, phc_collinear_set *sets, size_t n_sets)
{
    double A[LANES][MAX_K2];
    int use[LANES], failed[LANES];
    const size_t k = sets[0].size;
    for (size_t l = 0; l < n_sets; ++l) {
        const size_t *idx = sets[l].index;
        int zero = 0;
        for (size_t a = 0; a < k; ++a)
            zero |= norm[idx[a]] == 0;
        use[l] = !zero;
        sets[l].gamma = zero ? INFINITY : 0;
        for (size_t a = 0; a < k; ++a)
            for (size_t b = 0; b < k; ++b)
                A[l][a * k + b] = G[idx[a] * n + idx[b]];
        for (size_t a = 0; a < k * k && use[l]; ++a)
            if (!isfinite(A[l][a])) {
                sets[l].gamma = NAN;
                use[l] = 0;
            }
    }
    jacobi_lanes(A, use, n_sets, k, failed);
    for (size_t l = 0; l < n_sets; ++l) {
        if (!use[l])
            continue;
        if (failed[l]) {
            sets[l].gamma = NAN;
            continue;
        }
        double lmin = A[l][0], lmax = A[l][0];
        for (size_t j = 1; j < k; ++j) {
            lmin = fmin(lmin, A[l][j * k + j]);
            lmax = fmax(lmax, A[l][j * k + j]);
        }
        /* Singular to working precision counts as singular: the eigenvalues
         * carry an absolute error of a few k eps lambda_max, so two
         * proportional columns (y = a b x) give lambda_min ~ 1e-16 (or
         * slightly below 0) and gamma ~ 1e8 rather than inf, depending on
         * rounding. */
        sets[l].gamma = lmin > 4.0 * (double)k * DBL_EPSILON * lmax ? 1.0 / sqrt(lmin) : INFINITY;
    }
}

int phc_sensitivity_compute(const double *S, size_t m, size_t n, size_t max_sets,
                            phc_sensitivity *out, phc_error *err)
{
    memset(out, 0, sizeof *out);
    if (!S || m == 0 || n == 0)
        return phc_error_set(err, PHC_ERR_INVALID, "sensitivity: empty matrix");
    out->n = n;
    out->l1 = calloc(n, sizeof *out->l1);
    out->l2 = calloc(n, sizeof *out->l2);
    double *norm = calloc(n, sizeof *norm);
    double *G = calloc(n * n, sizeof *G);
    int rc = PHC_OK;
    if (!out->l1 || !out->l2 || !norm || !G) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "sensitivity: out of memory");
        goto fail;
    }
    for (size_t j = 0; j < n; ++j) {
        double s1 = 0, s2 = 0;
        for (size_t i = 0; i < m; ++i) {
            s1 += fabs(S[i * n + j]);
            s2 += S[i * n + j] * S[i * n + j];
        }
        out->l1[j] = s1 / (double)m;
        out->l2[j] = sqrt(s2 / (double)m);
        norm[j] = sqrt(s2);
    }
    for (size_t a = 0; a < n; ++a)
        for (size_t b = a; b < n; ++b) {
            double g = 0;
            for (size_t i = 0; i < m; ++i)
                g += S[i * n + a] * S[i * n + b];
            const double d = norm[a] * norm[b];
            G[a * n + b] = G[b * n + a] = d > 0 ? g / d : (a == b ? 0.0 : 0.0);
        }
    /* How many subset sizes fit in the budget. */
    size_t kmax = n < PHC_COLLIN_MAX_SIZE ? n : PHC_COLLIN_MAX_SIZE;
    double total = 0;
    size_t usable = 1;
    for (size_t k = 2; k <= kmax; ++k) {
        total += binomial(n, k);
        if (total > (double)max_sets)
            break;
        usable = k;
    }
    out->max_size = usable;
    if (usable < 2)
        goto fail; /* nothing to evaluate: n = 1 or no budget */
    size_t count = 0;
    for (size_t k = 2; k <= usable; ++k)
        count += (size_t)binomial(n, k);
    out->sets = calloc(count, sizeof *out->sets);
    if (!out->sets) {
        rc = phc_error_set(err, PHC_ERR_NOMEM, "sensitivity: out of memory");
        goto fail;
    }
    for (size_t k = 2; k <= usable; ++k) {
        size_t idx[PHC_COLLIN_MAX_SIZE];
        for (size_t a = 0; a < k; ++a)
            idx[a] = a;
        const size_t first = out->n_sets;
        for (;;) {
            phc_collinear_set *set = &out->sets[out->n_sets++];
            set->size = k;
            memcpy(set->index, idx, k * sizeof *idx);
            /* next combination in lexicographic order */
            size_t a = k;
            while (a > 0 && idx[a - 1] == n - k + a - 1)
                --a;
            if (a == 0)
                break;
            ++idx[a - 1];
            for (size_t b = a; b < k; ++b)
                idx[b] = idx[b - 1] + 1;
        }
        for (size_t i = first; i < out->n_sets; i += LANES)
            subset_gammas(G, n, norm, out->sets + i, out->n_sets - i < LANES ? out->n_sets - i : LANES);
        for (size_t i = first; i < out->n_sets; ++i)
            if (!(out->sets[i].gamma <= out->max_gamma[k]))
                out->max_gamma[k] = out->sets[i].gamma;
    }
    qsort(out->sets, out->n_sets, sizeof *out->sets, by_gamma_desc);
fail:
    free(norm);
    free(G);
    if (rc)
        phc_sensitivity_clear(out);
    return rc;
}
