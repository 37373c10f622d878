/* Unit tests of the tree divide-and-conquer eigensolver (model/tree_eigen.h):
 * exact spectra (the second-difference path, a star with equal leaves),
 * a path against LAPACK's tridiagonal dstedc, random trees against dense
 * dsyevd, residuals |A Q - Q Lambda| and orthogonality |Q^T Q - I| to a few
 * n eps, zero edges, and bad input. */
#include <float.h>
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/tree_eigen.h"
#include "tests/check.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static unsigned long long rng_state = 88172645463325252ULL;
static double uniform(void) /* xorshift64, [0, 1) */
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

static double *dense(size_t n, const size_t *par, const double *diag, const double *off)
{
    double *A = calloc(n * n, sizeof *A);
    for (size_t k = 0; k < n; ++k)
        A[k * n + k] = diag[k];
    for (size_t k = 1; k < n; ++k) {
        A[par[k] * n + k] = off[k];
        A[k * n + par[k]] = off[k];
    }
    return A;
}

/* Solves the tree problem and checks it: eigenvalues ascending and within
 * tol_eig (absolute) of ref (NULL: dense dsyevd), |A Q - Q Lambda|_max and
 * |Q^T Q - I|_max within 20 n eps (times |A|_max for the residual).  Returns
 * the eigenvalues (caller frees). */
static double *solve_and_check(const char *what, size_t n, const size_t *par, const double *diag,
                               const double *off, const double *ref, double tol_eig)
{
    double *lam = malloc(n * sizeof *lam), *Q = malloc(n * n * sizeof *Q);
    phc_error err;
    int rc = phc_tree_eigen(n, par, diag, off, lam, Q, &err);
    CHECK(rc == PHC_OK);
    if (rc) {
        fprintf(stderr, "%s: %s\n", what, err.message);
        free(Q);
        return lam;
    }
    double *A = dense(n, par, diag, off), anorm = 0.0;
    for (size_t k = 0; k < n * n; ++k)
        anorm = fmax(anorm, fabs(A[k]));
    double *w = NULL;
    if (!ref) {
        double *B = malloc(n * n * sizeof *B);
        w = malloc(n * sizeof *w);
        memcpy(B, A, n * n * sizeof *B);
        CHECK(LAPACKE_dsyevd(LAPACK_COL_MAJOR, 'N', 'L', (lapack_int)n, B, (lapack_int)n, w) == 0);
        free(B);
        ref = w;
    }
    double eig = 0.0, res = 0.0, orth = 0.0;
    int sorted = 1;
    for (size_t i = 0; i < n; ++i) {
        eig = fmax(eig, fabs(lam[i] - ref[i]));
        if (i > 0 && lam[i] < lam[i - 1])
            sorted = 0;
    }
    for (size_t i = 0; i < n; ++i) {
        const double *q = Q + i * n;
        for (size_t r = 0; r < n; ++r) {
            double aq = 0.0;
            for (size_t c = 0; c < n; ++c)
                aq += A[c * n + r] * q[c];
            res = fmax(res, fabs(aq - lam[i] * q[r]));
        }
        for (size_t j = 0; j <= i; ++j) {
            double dot = 0.0;
            for (size_t r = 0; r < n; ++r)
                dot += q[r] * Q[j * n + r];
            orth = fmax(orth, fabs(dot - (i == j ? 1.0 : 0.0)));
        }
    }
    printf("%s (n = %zu): max |lambda - reference| = %.2e, |AQ - QL| = %.2e |A|, |Q'Q - I| = %.2e\n",
           what, n, eig, res / anorm, orth);
    CHECK(sorted);
    CHECK(eig <= tol_eig);
    CHECK(res <= 20.0 * (double)n * DBL_EPSILON * anorm);
    CHECK(orth <= 20.0 * (double)n * DBL_EPSILON);
    free(A);
    free(w);
    free(Q);
    return lam;
}

/* Second-difference path: eigenvalues 2 - 2 cos(k pi / (n + 1)) exactly;
 * the tridiagonal also against dstedc. */
static void test_path(size_t n)
{
    size_t *par = malloc(n * sizeof *par);
    double *diag = malloc(n * sizeof *diag), *off = malloc(n * sizeof *off);
    double *ex = malloc(n * sizeof *ex);
    for (size_t k = 0; k < n; ++k) {
        par[k] = k ? k - 1 : 0;
        diag[k] = 2.0;
        off[k] = -1.0;
        ex[k] = 2.0 - 2.0 * cos((double)(k + 1) * M_PI / (double)(n + 1));
    }
    free(solve_and_check("path, second difference", n, par, diag, off, ex, 20.0 * n * DBL_EPSILON));
    /* random tridiagonal against dstedc */
    double *d = malloc(n * sizeof *d), *e = malloc(n * sizeof *e);
    for (size_t k = 0; k < n; ++k) {
        diag[k] = d[k] = 2.0 * uniform() - 1.0;
        off[k] = e[k > 0 ? k - 1 : 0] = 2.0 * uniform() - 1.0;
    }
    for (size_t k = 1; k < n; ++k)
        e[k - 1] = off[k];
    double *Z = malloc(n * n * sizeof *Z);
    CHECK(LAPACKE_dstedc(LAPACK_COL_MAJOR, 'N', (lapack_int)n, d, e, Z, (lapack_int)n) == 0);
    free(solve_and_check("path, random, against dstedc", n, par, diag, off, d,
                         20.0 * n * DBL_EPSILON));
    free(Z);
    free(d);
    free(e);
    free(par);
    free(diag);
    free(off);
    free(ex);
}

/* Star: centre c, n - 1 leaves of diagonal a on edges b.  Eigenvalues: a
 * (n - 2 times) and a pair from (x - c)(x - a) = (n - 1) b^2.  No cut
 * leaves 1/8 of the nodes on its smaller side: solved as one dense block. */
static void test_star(size_t n)
{
    const double a = -3.0, c = -1.0, b = 0.5;
    size_t *par = calloc(n, sizeof *par);
    double *diag = malloc(n * sizeof *diag), *off = malloc(n * sizeof *off);
    double *ex = malloc(n * sizeof *ex);
    for (size_t k = 0; k < n; ++k) {
        diag[k] = k ? a : c;
        off[k] = b;
    }
    double mid = 0.5 * (a + c), half = sqrt(0.25 * (c - a) * (c - a) + (double)(n - 1) * b * b);
    ex[0] = mid - half;
    for (size_t k = 1; k + 1 < n; ++k)
        ex[k] = a;
    ex[n - 1] = mid + half;
    free(solve_and_check("star, equal leaves", n, par, diag, off, ex, 20.0 * n * DBL_EPSILON * half));
    free(par);
    free(diag);
    free(off);
    free(ex);
}

/* Brooms along a path: `hubs` hubs in a row, each with `leaves` leaves of
 * equal diagonal a on equal edges b.  Per hub, leaves - 1 eigenvalues are
 * exactly a (differences of two leaves, zero elsewhere); the cuts run along
 * the path, so the merges meet these equal eigenvalues in both halves
 * (deflation of equal poles); the rest against dense dsyevd. */
static void test_brooms(size_t hubs, size_t leaves)
{
    const double a = -2.0, b = 0.7, c = -5.0, e = 0.3;
    size_t n = hubs * (leaves + 1);
    size_t *par = calloc(n, sizeof *par);
    double *diag = malloc(n * sizeof *diag), *off = calloc(n, sizeof *off);
    size_t k = 0, prev_hub = 0;
    for (size_t h = 0; h < hubs; ++h) {
        size_t hub = k++;
        par[hub] = h ? prev_hub : 0;
        diag[hub] = c - 0.1 * (double)h;
        off[hub] = h ? e : 0.0;
        for (size_t l = 0; l < leaves; ++l, ++k) {
            par[k] = hub;
            diag[k] = a;
            off[k] = b;
        }
        prev_hub = hub;
    }
    double *lam = solve_and_check("brooms along a path", n, par, diag, off, NULL,
                                  20.0 * n * DBL_EPSILON * 6.0);
    size_t at_a = 0;
    for (size_t i = 0; i < n; ++i)
        at_a += fabs(lam[i] - a) <= 1e-13;
    printf("brooms: %zu eigenvalues at a (exactly %zu expected)\n", at_a, hubs * (leaves - 1));
    CHECK(at_a == hubs * (leaves - 1));
    free(lam);
    free(par);
    free(diag);
    free(off);
}

/* Random trees (random parents: bushy; or parent k - 1 - (k % 3 == 0)...:
 * long branches), some edges zero, entries of mixed scale. */
static void test_random_tree(size_t n, int shape, int zero_edges)
{
    size_t *par = calloc(n, sizeof *par);
    double *diag = malloc(n * sizeof *diag), *off = calloc(n, sizeof *off);
    for (size_t k = 0; k < n; ++k) {
        if (k > 0)
            par[k] = shape == 0 ? (size_t)(uniform() * (double)k)
                                : (k < 4 ? k - 1 : k - 1 - (size_t)(uniform() < 0.3) * 3);
        diag[k] = -(1.0 + 10.0 * uniform());
        if (k > 0)
            off[k] = (zero_edges && k % 7 == 0) ? 0.0 : (uniform() < 0.5 ? -1.0 : 1.0) * uniform();
    }
    char what[80];
    snprintf(what, sizeof what, "random tree, %s%s", shape == 0 ? "random parents" : "long branches",
             zero_edges ? ", zero edges" : "");
    double anorm = 11.0;
    free(solve_and_check(what, n, par, diag, off, NULL, 20.0 * n * DBL_EPSILON * anorm));
    free(par);
    free(diag);
    free(off);
}

static void test_bad_input(void)
{
    size_t par[3] = {0, 2, 0};
    double diag[3] = {1, 2, 3}, off[3] = {0, 1, 1}, lam[3], Q[9];
    phc_error err;
    CHECK(phc_tree_eigen(3, par, diag, off, lam, Q, &err) == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "node 1 has parent 2");
    par[1] = 0;
    diag[2] = NAN;
    CHECK(phc_tree_eigen(3, par, diag, off, lam, Q, &err) == PHC_ERR_INVALID);
    CHECK_STR_CONTAINS(err.message, "node 2 is not finite");
    CHECK(phc_tree_eigen(0, par, diag, off, lam, Q, &err) == PHC_OK);
}

int main(void)
{
    test_path(300);
    test_path(PHC_TREE_EIGEN_LEAF + 1);
    test_star(150);
    test_brooms(12, 15);
    for (size_t n = 1; n <= 3; ++n)
        test_random_tree(n, 0, 0);
    test_random_tree(PHC_TREE_EIGEN_LEAF, 0, 0);
    test_random_tree(400, 0, 0);
    test_random_tree(400, 1, 0);
    test_random_tree(300, 0, 1);
    test_bad_input();
    return check_finish("test_tree_eigen");
}
