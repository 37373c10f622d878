/* Unit tests of the leaf sap-flow model (model/leaf.h; Silva et al. §3,
 * eqs. 1-7):
 *   - each implicit half-step against a dense solve of the same system,
 *     built here from β, the mask and s_β (Gaussian elimination with
 *     partial pivoting), on a 9 x 7 mask with holes, an empty row and two
 *     runs per line; face conductances against the formula;
 *   - a step is bit-identical to sources + columns + rows;
 *   - conservation without sources, convergence to the mean of each
 *     connected region;
 *   - exact limits: transpiration only, inflow only (dyadic numbers, so
 *     equality is exact), 1-D diffusion against the eigen-decomposition;
 *   - orientation: 180° rotation to round-off; transposition to the
 *     splitting error, whose order in h is measured;
 *   - 1 vs 2 (and 3) threads bit-identical on a 300 x 200 leaf;
 *   - the factorisation caches (another h, new params);
 *   - phc_leaf_advance continuous in t;
 *   - bad input: messages name the field and the pixel. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "model/leaf.h"

#define PI 3.14159265358979323846
#define MW 9
#define MH 7

/* '#' = leaf.  Row 3 is empty: the top half has two regions (left, right),
 * the bottom one; columns have two runs, rows up to two. */
static const char *const MASK_ROWS[MH] = {
    "###.####.",
    "##..#####",
    "####.###.",
    ".........",
    "##.###.##",
    "##.######",
    ".###..###",
};

static void small_mask(unsigned char *m)
{
    for (int y = 0; y < MH; ++y)
        for (int x = 0; x < MW; ++x)
            m[x + MW * y] = MASK_ROWS[y][x] == '#';
}

/* Nonuniform maps (defined everywhere; the leaf ignores values off the mask). */
static void small_maps(double *beta, double *O, double *I, double *y0, size_t W, size_t H)
{
    for (size_t y = 0; y < H; ++y)
        for (size_t x = 0; x < W; ++x) {
            size_t i = x + W * y;
            if (beta)
                beta[i] = 0.3 + 0.45 * (double)((7 * x + 3 * y) % 5) + (x == 4 ? 2.0 : 0.0);
            if (O)
                O[i] = 0.2 + 0.1 * (double)((x + 2 * y) % 4);
            if (I)
                I[i] = (x % 3 == 0) ? 0.7 : 0.05 * (double)(y % 3);
            if (y0)
                y0[i] = 0.5 + 0.4 * sin(0.9 * (double)x + 0.3) * cos(0.7 * (double)y) +
                        0.1 * (double)((x * y) % 3);
        }
}

static phc_leaf_params params(double sb, double so, double si, double dt)
{
    phc_leaf_params p = {sb, so, si, dt};
    return p;
}

static phc_leaf *make(size_t W, size_t H, const unsigned char *m, const double *b, const double *O,
                      const double *I, phc_leaf_params p)
{
    phc_leaf *L = NULL;
    phc_error err;
    int rc = phc_leaf_new(W, H, m, b, O, I, p, &L, &err);
    if (rc) {
        fprintf(stderr, "phc_leaf_new: %s\n", err.message);
        return NULL;
    }
    return L;
}

static double max_abs(const double *a, size_t n)
{
    double m = 0;
    for (size_t i = 0; i < n; ++i)
        if (fabs(a[i]) > m)
            m = fabs(a[i]);
    return m;
}

static double max_diff(const double *a, const double *b, size_t n)
{
    double m = 0;
    for (size_t i = 0; i < n; ++i)
        if (fabs(a[i] - b[i]) > m)
            m = fabs(a[i] - b[i]);
    return m;
}

static int zero_off_mask(const phc_leaf *L)
{
    const double *y = phc_leaf_fluid(L);
    const unsigned char *m = phc_leaf_mask(L);
    size_t n = phc_leaf_width(L) * phc_leaf_height(L);
    for (size_t i = 0; i < n; ++i)
        if (!m[i] && (y[i] != 0 || signbit(y[i])))
            return 0;
    return 1;
}

/* Dense solve A x = b (n x n, row-major, destroyed) by Gaussian elimination
 * with partial pivoting; 0 on success. */
static int dense_solve(double *A, double *b, size_t n)
{
    for (size_t k = 0; k < n; ++k) {
        size_t p = k;
        for (size_t i = k + 1; i < n; ++i)
            if (fabs(A[i * n + k]) > fabs(A[p * n + k]))
                p = i;
        if (A[p * n + k] == 0)
            return 1;
        if (p != k) {
            for (size_t j = 0; j < n; ++j) {
                double t = A[k * n + j];
                A[k * n + j] = A[p * n + j];
                A[p * n + j] = t;
            }
            double t = b[k];
            b[k] = b[p];
            b[p] = t;
        }
        for (size_t i = k + 1; i < n; ++i) {
            double f = A[i * n + k] / A[k * n + k];
            if (f == 0)
                continue;
            for (size_t j = k; j < n; ++j)
                A[i * n + j] -= f * A[k * n + j];
            b[i] -= f * b[k];
        }
    }
    for (size_t k = n; k-- > 0;) {
        double s = b[k];
        for (size_t j = k + 1; j < n; ++j)
            s -= A[k * n + j] * b[j];
        b[k] = s / A[k * n + k];
    }
    return 0;
}

/* The conductance of the face between pixels i and j, from the formula
 * (independent of the library). */
static double k_face(const unsigned char *m, const double *beta, double sb, size_t i, size_t j)
{
    if (!m[i] || !m[j])
        return 0;
    return sb * (beta[i] + beta[j]) / 2;
}

/* One implicit half-step along `axis` by a dense solve over the leaf pixels:
 * (1 + h L) y' = y.  Off the leaf y' = 0. */
static int dense_half_step(size_t W, size_t H, const unsigned char *m, const double *beta, double sb,
                           double h, phc_leaf_axis axis, const double *yin, double *yout)
{
    size_t n = W * H, nc = 0;
    long *id = malloc(n * sizeof *id);
    for (size_t i = 0; i < n; ++i)
        id[i] = m[i] ? (long)nc++ : -1;
    double *A = calloc(nc * nc, sizeof *A), *b = malloc(nc * sizeof *b);
    for (size_t y = 0; y < H; ++y)
        for (size_t x = 0; x < W; ++x) {
            size_t i = x + W * y;
            if (!m[i])
                continue;
            long r = id[i];
            A[r * nc + r] += 1;
            b[r] = yin[i];
            size_t nb[2];
            int have[2];
            if (axis == PHC_LEAF_ROWS) {
                have[0] = x > 0, nb[0] = i - 1;
                have[1] = x + 1 < W, nb[1] = i + 1;
            } else {
                have[0] = y > 0, nb[0] = i - W;
                have[1] = y + 1 < H, nb[1] = i + W;
            }
            for (int s = 0; s < 2; ++s) {
                if (!have[s])
                    continue;
                double k = k_face(m, beta, sb, i, nb[s]);
                if (k == 0)
                    continue;
                A[r * nc + r] += h * k;
                A[r * nc + id[nb[s]]] -= h * k;
            }
        }
    int rc = dense_solve(A, b, nc);
    for (size_t i = 0; i < n; ++i)
        yout[i] = m[i] ? b[id[i]] : 0.0;
    free(A);
    free(b);
    free(id);
    return rc;
}

static void test_dense(void)
{
    unsigned char m[MW * MH];
    double beta[MW * MH], O[MW * MH], I[MW * MH], y0[MW * MH], ref[MW * MH];
    small_mask(m);
    small_maps(beta, O, I, y0, MW, MH);
    const double sb = 2.3, h = 0.37;
    phc_leaf *L = make(MW, MH, m, beta, O, I, params(sb, 0.4, 0.3, 0.1));
    CHECK(L != NULL);
    if (!L)
        return;
    CHECK(phc_leaf_width(L) == MW && phc_leaf_height(L) == MH);
    size_t cells = 0;
    for (size_t i = 0; i < MW * MH; ++i)
        cells += m[i];
    CHECK(phc_leaf_cells(L) == cells);
    CHECK(memcmp(phc_leaf_mask(L), m, sizeof m) == 0);

    /* face conductances against the formula, both axes, every pixel */
    int faces_ok = 1;
    for (size_t y = 0; y < MH; ++y)
        for (size_t x = 0; x < MW; ++x) {
            size_t i = x + MW * y;
            double kr = x + 1 < MW ? k_face(m, beta, sb, i, i + 1) : 0;
            double kc = y + 1 < MH ? k_face(m, beta, sb, i, i + MW) : 0;
            faces_ok &= fabs(phc_leaf_face_conductance(L, x, y, PHC_LEAF_ROWS) - kr) <= 1e-15 * kr;
            faces_ok &= fabs(phc_leaf_face_conductance(L, x, y, PHC_LEAF_COLUMNS) - kc) <= 1e-15 * kc;
        }
    CHECK(faces_ok);
    CHECK(phc_leaf_face_conductance(L, MW, 0, PHC_LEAF_ROWS) == 0);

    for (int ax = 0; ax < 2; ++ax) {
        phc_leaf_axis axis = ax ? PHC_LEAF_ROWS : PHC_LEAF_COLUMNS;
        phc_error err;
        CHECK(phc_leaf_set_fluid(L, y0, &err) == 0);
        CHECK(phc_leaf_diffuse(L, h, axis) == 0);
        CHECK(dense_half_step(MW, MH, m, beta, sb, h, axis, y0, ref) == 0);
        double d = max_diff(phc_leaf_fluid(L), ref, MW * MH);
        printf("dense_%s_max_rel_diff: %.2e\n", ax ? "rows" : "columns", d / max_abs(ref, MW * MH));
        CHECK(d <= 1e-12 * max_abs(ref, MW * MH));
        CHECK(zero_off_mask(L));
        /* a second h (slot 1 of the cache), then dt (slot 0) again */
        CHECK(phc_leaf_set_fluid(L, y0, &err) == 0);
        CHECK(phc_leaf_diffuse(L, 2.9, axis) == 0);
        CHECK(dense_half_step(MW, MH, m, beta, sb, 2.9, axis, y0, ref) == 0);
        CHECK(max_diff(phc_leaf_fluid(L), ref, MW * MH) <= 1e-12 * max_abs(ref, MW * MH));
    }

    /* a step is sources + columns + rows, bit for bit */
    phc_leaf *L2 = make(MW, MH, m, beta, O, I, params(sb, 0.4, 0.3, 0.1));
    phc_error err;
    CHECK(L2 != NULL);
    if (L2) {
        CHECK(phc_leaf_set_fluid(L, y0, &err) == 0);
        CHECK(phc_leaf_set_fluid(L2, y0, &err) == 0);
        for (int s = 0; s < 3; ++s) {
            CHECK(phc_leaf_step(L, h) == 0);
            phc_leaf_sources(L2, h);
            CHECK(phc_leaf_diffuse(L2, h, PHC_LEAF_COLUMNS) == 0);
            CHECK(phc_leaf_diffuse(L2, h, PHC_LEAF_ROWS) == 0);
        }
        CHECK(memcmp(phc_leaf_fluid(L), phc_leaf_fluid(L2), sizeof y0) == 0);
        CHECK_NEAR(phc_leaf_time(L), 3 * h, 1e-15, 0);
        CHECK(phc_leaf_time(L2) == 0); /* the pieces do not advance the clock */

        /* sources alone: max(y - h s_O O, 0) + h s_I I, computed here */
        CHECK(phc_leaf_set_fluid(L2, y0, &err) == 0);
        phc_leaf_sources(L2, 1.5);
        int src_ok = 1;
        for (size_t i = 0; i < MW * MH; ++i) {
            double e = m[i] ? fmax(y0[i] - 1.5 * 0.4 * O[i], 0) + 1.5 * 0.3 * I[i] : 0;
            src_ok &= fabs(phc_leaf_fluid(L2)[i] - e) <= 1e-15;
        }
        CHECK(src_ok);
        phc_leaf_free(L2);
    }
    phc_leaf_free(L);
}

/* 4-connected regions of the mask; returns their count. */
static int label(const unsigned char *m, size_t W, size_t H, int *lab)
{
    size_t n = W * H;
    size_t *stack = malloc(n * sizeof *stack);
    int nl = 0;
    for (size_t i = 0; i < n; ++i)
        lab[i] = -1;
    for (size_t s = 0; s < n; ++s) {
        if (!m[s] || lab[s] >= 0)
            continue;
        size_t top = 0;
        stack[top++] = s;
        lab[s] = nl;
        while (top) {
            size_t i = stack[--top], x = i % W, y = i / W;
            size_t nb[4];
            int k = 0;
            if (x > 0)
                nb[k++] = i - 1;
            if (x + 1 < W)
                nb[k++] = i + 1;
            if (y > 0)
                nb[k++] = i - W;
            if (y + 1 < H)
                nb[k++] = i + W;
            for (int j = 0; j < k; ++j)
                if (m[nb[j]] && lab[nb[j]] < 0) {
                    lab[nb[j]] = nl;
                    stack[top++] = nb[j];
                }
        }
        ++nl;
    }
    free(stack);
    return nl;
}

static void test_conservation(void)
{
    unsigned char m[MW * MH];
    double beta[MW * MH], y0[MW * MH];
    int lab[MW * MH];
    small_mask(m);
    small_maps(beta, NULL, NULL, y0, MW, MH);
    int nl = label(m, MW, MH, lab);
    CHECK(nl == 3);
    /* O = I = 0: zero scales, and zero maps on a second leaf */
    phc_leaf *L = make(MW, MH, m, beta, NULL, NULL, params(1.7, 0, 0, 0.05));
    CHECK(L != NULL);
    if (!L)
        return;
    phc_error err;
    CHECK(phc_leaf_set_fluid(L, y0, &err) == 0);
    double t0 = phc_leaf_total(L), worst = 0;
    for (int s = 0; s < 200; ++s) {
        CHECK(phc_leaf_step(L, 0.05) == 0);
        double d = fabs(phc_leaf_total(L) - t0) / t0;
        if (d > worst)
            worst = d;
    }
    printf("conservation_max_rel_drift_200_steps: %.2e\n", worst);
    CHECK(worst <= 1e-12);
    CHECK(zero_off_mask(L));
    /* the flat state: the mean of each region */
    double mean[3] = {0, 0, 0}, cnt[3] = {0, 0, 0};
    for (size_t i = 0; i < MW * MH; ++i)
        if (m[i] && lab[i] < 3) {
            mean[lab[i]] += y0[i];
            cnt[lab[i]] += 1;
        }
    for (int r = 0; r < 3; ++r)
        mean[r] /= cnt[r];
    CHECK(fabs(mean[0] - mean[1]) > 0.01 && fabs(mean[1] - mean[2]) > 0.01);
    /* moderate steps: with very large ones the split step tends to
       alternating projections onto line means, which converge slowly on an
       irregular leaf (dt = 5 left 2e-5 after t = 500) */
    phc_leaf_params p = params(1.7, 0, 0, 0.5);
    CHECK(phc_leaf_set_params(L, p, &err) == 0);
    CHECK(phc_leaf_advance(L, 500.0) == 0);
    double dev = 0;
    for (size_t i = 0; i < MW * MH; ++i)
        if (m[i])
            dev = fmax(dev, fabs(phc_leaf_fluid(L)[i] - mean[lab[i]]));
    printf("flat_state_max_dev: %.2e\n", dev);
    CHECK(dev <= 1e-10);
    CHECK(fabs(phc_leaf_total(L) - t0) <= 1e-12 * t0);

    /* zero O and I maps with nonzero scales conserve as well */
    double zero[MW * MH];
    memset(zero, 0, sizeof zero);
    phc_leaf *L2 = make(MW, MH, m, beta, zero, zero, params(0.9, 3.0, 2.0, 0.2));
    CHECK(L2 != NULL);
    if (L2) {
        CHECK(phc_leaf_set_fluid(L2, y0, &err) == 0);
        CHECK(phc_leaf_advance(L2, 40.0) == 0);
        CHECK_NEAR(phc_leaf_total(L2), t0, 0, 1e-12);
        phc_leaf_free(L2);
    }
    phc_leaf_free(L);
}

static void test_limits(void)
{
    unsigned char m[MW * MH];
    double beta[MW * MH];
    small_mask(m);
    small_maps(beta, NULL, NULL, NULL, MW, MH);
    phc_error err;
    /* transpiration only, no diffusion: y = max(1 - s_O t, 0) exactly
       (h s_O = 1/16, so every value is a dyadic number) */
    phc_leaf *L = make(MW, MH, m, beta, NULL, NULL, params(0, 0.125, 0, 0.5));
    CHECK(L != NULL);
    if (L) {
        int ok = 1;
        for (int s = 1; s <= 20; ++s) {
            CHECK(phc_leaf_step(L, 0.5) == 0);
            double e = fmax(1 - 0.125 * 0.5 * s, 0);
            for (size_t i = 0; i < MW * MH; ++i)
                ok &= phc_leaf_fluid(L)[i] == (m[i] ? e : 0.0);
        }
        CHECK(ok);
        CHECK(phc_leaf_fluid(L)[0] == 0 && !signbit(phc_leaf_fluid(L)[0]));
        phc_leaf_free(L);
    }
    /* the same with diffusion on: a uniform field stays uniform (round-off) */
    L = make(MW, MH, m, beta, NULL, NULL, params(3.0, 0.1, 0, 0.25));
    CHECK(L != NULL);
    if (L) {
        CHECK(phc_leaf_advance(L, 5.0) == 0);
        double dev = 0;
        for (size_t i = 0; i < MW * MH; ++i)
            if (m[i])
                dev = fmax(dev, fabs(phc_leaf_fluid(L)[i] - (1 - 0.1 * 5.0)));
        CHECK(dev <= 1e-14);
        phc_leaf_free(L);
    }
    /* inflow only: y = 1 + s_I t exactly (inflow map 1 on the leaf) */
    double one[MW * MH];
    for (size_t i = 0; i < MW * MH; ++i)
        one[i] = 1;
    L = make(MW, MH, m, beta, NULL, one, params(0, 0, 0.25, 0.5));
    CHECK(L != NULL);
    if (L) {
        int ok = 1;
        for (int s = 1; s <= 20; ++s) {
            CHECK(phc_leaf_step(L, 0.5) == 0);
            for (size_t i = 0; i < MW * MH; ++i)
                ok &= phc_leaf_fluid(L)[i] == (m[i] ? 1 + 0.25 * 0.5 * s : 0.0);
        }
        CHECK(ok);
        phc_leaf_free(L);
    }
    /* 1-D diffusion of one column (W = 1, so the row half-step is the
       identity) against the eigen-decomposition of the Neumann operator:
       mode v_i = cos(pi q (i + 1/2) / n) has eigenvalue
       lambda = 2 k (1 - cos(pi q / n)), so implicit Euler multiplies it by
       1 / (1 + h lambda) per step. */
    {
        enum { n = 12 };
        unsigned char mc[n];
        double y0[n];
        const double k = 0.8, h = 0.3, amp = 0.5;
        const int q = 3, steps = 10;
        for (int i = 0; i < n; ++i) {
            mc[i] = 1;
            y0[i] = 1 + amp * cos(PI * q * (i + 0.5) / n);
        }
        L = make(1, n, mc, NULL, NULL, NULL, params(k, 0, 0, h)); /* β = 1: k_f = s_β */
        CHECK(L != NULL);
        if (L) {
            CHECK(phc_leaf_set_fluid(L, y0, &err) == 0);
            for (int s = 0; s < steps; ++s)
                CHECK(phc_leaf_step(L, h) == 0);
            double lam = 2 * k * (1 - cos(PI * q / n)), g = pow(1 / (1 + h * lam), steps), d = 0;
            for (int i = 0; i < n; ++i)
                d = fmax(d, fabs(phc_leaf_fluid(L)[i] - (1 + amp * g * cos(PI * q * (i + 0.5) / n))));
            printf("diffusion_1d_max_err: %.2e (mode gain %.6f)\n", d, g);
            CHECK(d <= 1e-13);
            phc_leaf_free(L);
        }
        /* the same as one row (H = 1) */
        L = make(n, 1, mc, NULL, NULL, NULL, params(k, 0, 0, h));
        CHECK(L != NULL);
        if (L) {
            CHECK(phc_leaf_set_fluid(L, y0, &err) == 0);
            for (int s = 0; s < steps; ++s)
                CHECK(phc_leaf_step(L, h) == 0);
            double lam = 2 * k * (1 - cos(PI * q / n)), g = pow(1 / (1 + h * lam), steps), d = 0;
            for (int i = 0; i < n; ++i)
                d = fmax(d, fabs(phc_leaf_fluid(L)[i] - (1 + amp * g * cos(PI * q * (i + 0.5) / n))));
            CHECK(d <= 1e-13);
            phc_leaf_free(L);
        }
    }
}

/* A larger irregular leaf: an ellipse with two holes, veins in β. */
static void irregular(size_t W, size_t H, unsigned char *m, double *beta, double *O, double *I,
                      double *y0)
{
    for (size_t y = 0; y < H; ++y)
        for (size_t x = 0; x < W; ++x) {
            size_t i = x + W * y;
            double u = (x + 0.5) / W * 2 - 1, v = (y + 0.5) / H * 2 - 1;
            int in = u * u / 0.9 + v * v / 0.8 < 1;
            double h1 = (u - 0.3) * (u - 0.3) + (v + 0.2) * (v + 0.2);
            double h2 = (u + 0.4) * (u + 0.4) + (v - 0.3) * (v - 0.3);
            if (h1 < 0.02 || h2 < 0.01)
                in = 0;
            m[i] = (unsigned char)in;
            int vein = fabs(u - 0.1 * v) < 0.06 || fabs(v - 0.5 * u) < 0.05;
            beta[i] = vein ? 1.0 : 0.05 + 0.02 * (double)((x * 3 + y * 5) % 7);
            O[i] = 1.0 + 0.3 * sin(0.2 * (double)x);
            I[i] = vein ? 0.8 : 0.0;
            y0[i] = 0.6 + 0.3 * cos(0.15 * (double)x + 0.05 * (double)y * (double)y / H);
        }
}

static void test_orientation(void)
{
    const size_t W = 37, H = 29, n = W * H;
    unsigned char *m = malloc(n), *mr = malloc(n), *mt = malloc(n);
    double *b = malloc(n * 8), *O = malloc(n * 8), *I = malloc(n * 8), *y0 = malloc(n * 8);
    double *br = malloc(n * 8), *Or = malloc(n * 8), *Ir = malloc(n * 8), *yr = malloc(n * 8);
    double *bt = malloc(n * 8), *Ot = malloc(n * 8), *It = malloc(n * 8), *yt = malloc(n * 8);
    irregular(W, H, m, b, O, I, y0);
    for (size_t y = 0; y < H; ++y)
        for (size_t x = 0; x < W; ++x) {
            size_t i = x + W * y, r = (W - 1 - x) + W * (H - 1 - y), t = y + H * x;
            mr[r] = m[i], br[r] = b[i], Or[r] = O[i], Ir[r] = I[i], yr[r] = y0[i];
            mt[t] = m[i], bt[t] = b[i], Ot[t] = O[i], It[t] = I[i], yt[t] = y0[i];
        }
    phc_leaf_params p = params(20.0, 0.3, 0.2, 0.05);
    phc_error err;
    /* 180° rotation: the same lines, reversed: round-off only */
    phc_leaf *A = make(W, H, m, b, O, I, p), *R = make(W, H, mr, br, Or, Ir, p);
    CHECK(A && R);
    if (A && R) {
        CHECK(phc_leaf_set_fluid(A, y0, &err) == 0);
        CHECK(phc_leaf_set_fluid(R, yr, &err) == 0);
        CHECK(phc_leaf_advance(A, 1.0) == 0);
        CHECK(phc_leaf_advance(R, 1.0) == 0);
        double d = 0;
        for (size_t y = 0; y < H; ++y)
            for (size_t x = 0; x < W; ++x)
                d = fmax(d, fabs(phc_leaf_fluid(A)[x + W * y] -
                                 phc_leaf_fluid(R)[(W - 1 - x) + W * (H - 1 - y)]));
        d /= max_abs(phc_leaf_fluid(A), n);
        printf("rotation_180_max_rel_diff: %.2e\n", d);
        CHECK(d <= 1e-13);
    }
    phc_leaf_free(A);
    phc_leaf_free(R);

    /* transposition: columns-then-rows becomes rows-then-columns; the
       difference at fixed t is the splitting error, O(h) globally */
    const double T = 0.4;
    double diff[3];
    for (int k = 0; k < 3; ++k) {
        double h = 0.02 / (double)(1 << k);
        phc_leaf_params pk = params(20.0, 0.3, 0.2, h);
        A = make(W, H, m, b, O, I, pk);
        phc_leaf *Tl = make(H, W, mt, bt, Ot, It, pk);
        CHECK(A && Tl);
        diff[k] = NAN;
        if (A && Tl) {
            CHECK(phc_leaf_set_fluid(A, y0, &err) == 0);
            CHECK(phc_leaf_set_fluid(Tl, yt, &err) == 0);
            for (int s = 0; s < (20 << k); ++s) {
                CHECK(phc_leaf_step(A, h) == 0);
                CHECK(phc_leaf_step(Tl, h) == 0);
            }
            double d = 0;
            for (size_t y = 0; y < H; ++y)
                for (size_t x = 0; x < W; ++x)
                    d = fmax(d, fabs(phc_leaf_fluid(A)[x + W * y] - phc_leaf_fluid(Tl)[y + H * x]));
            diff[k] = d;
        }
        phc_leaf_free(A);
        phc_leaf_free(Tl);
    }
    double r1 = diff[0] / diff[1], r2 = diff[1] / diff[2];
    printf("transpose_diff_at_t%.1f: %.3e %.3e %.3e (h = 0.02, 0.01, 0.005; ratios %.3f %.3f)\n", T,
           diff[0], diff[1], diff[2], r1, r2);
    CHECK(diff[0] > 1e-6);     /* the split is really there */
    CHECK(diff[0] < 0.05);     /* and small */
    /* first order globally (O(h^2) per step): the difference halves with h;
       measured 1.83 and 1.90, tending to 2 */
    CHECK(r1 > 1.75 && r1 < 2.25);
    CHECK(r2 > 1.75 && r2 < 2.25);
    free(m), free(mr), free(mt), free(b), free(O), free(I), free(y0);
    free(br), free(Or), free(Ir), free(yr), free(bt), free(Ot), free(It), free(yt);
}

static void test_threads(void)
{
    const size_t W = 300, H = 200, n = W * H;
    unsigned char *m = malloc(n);
    double *b = malloc(n * 8), *O = malloc(n * 8), *I = malloc(n * 8), *y0 = malloc(n * 8);
    double *out[3];
    irregular(W, H, m, b, O, I, y0);
    static const int nt[3] = {1, 2, 3};
    phc_error err;
    for (int k = 0; k < 3; ++k) {
        omp_set_num_threads(nt[k]);
        out[k] = malloc(n * 8);
        phc_leaf *L = make(W, H, m, b, O, I, params(30.0, 0.2, 0.1, 0.05));
        CHECK(L != NULL);
        if (!L) {
            memset(out[k], 0, n * 8);
            continue;
        }
        CHECK(phc_leaf_cells(L) >= 16384); /* large enough to run in parallel */
        CHECK(phc_leaf_set_fluid(L, y0, &err) == 0);
        for (int s = 0; s < 20; ++s)
            CHECK(phc_leaf_step(L, 0.05) == 0);
        CHECK(phc_leaf_step(L, 0.0123) == 0); /* the second cache */
        CHECK(phc_leaf_diffuse(L, 0.7, PHC_LEAF_ROWS) == 0);
        CHECK(phc_leaf_diffuse(L, 0.7, PHC_LEAF_COLUMNS) == 0);
        phc_leaf_sources(L, 0.3);
        memcpy(out[k], phc_leaf_fluid(L), n * 8);
        CHECK(zero_off_mask(L));
        phc_leaf_free(L);
    }
    CHECK(memcmp(out[0], out[1], n * 8) == 0);
    CHECK(memcmp(out[0], out[2], n * 8) == 0);
    omp_set_num_threads(omp_get_num_procs());
    for (int k = 0; k < 3; ++k)
        free(out[k]);
    free(m), free(b), free(O), free(I), free(y0);
}

static void test_caches_and_advance(void)
{
    const size_t W = 23, H = 19, n = W * H;
    unsigned char m[23 * 19];
    double b[23 * 19], O[23 * 19], I[23 * 19], y0[23 * 19];
    irregular(W, H, m, b, O, I, y0);
    phc_error err;
    /* the two cache slots compute the same: dt and h2 swapped */
    const double dt = 0.1, h2 = 0.037;
    phc_leaf *A = make(W, H, m, b, O, I, params(5, 0.2, 0.1, dt));
    phc_leaf *B = make(W, H, m, b, O, I, params(5, 0.2, 0.1, h2));
    CHECK(A && B);
    if (A && B) {
        CHECK(phc_leaf_set_fluid(A, y0, &err) == 0);
        CHECK(phc_leaf_set_fluid(B, y0, &err) == 0);
        double hs[5] = {dt, h2, dt, h2, dt};
        for (int s = 0; s < 5; ++s) {
            CHECK(phc_leaf_step(A, hs[s]) == 0);
            CHECK(phc_leaf_step(B, hs[s]) == 0);
        }
        CHECK(memcmp(phc_leaf_fluid(A), phc_leaf_fluid(B), n * 8) == 0);
        /* new params: the factors are redone (compared with a fresh leaf) */
        phc_leaf *C = make(W, H, m, b, O, I, params(11, 0.3, 0.05, dt));
        CHECK(C != NULL);
        if (C) {
            CHECK(phc_leaf_set_fluid(C, phc_leaf_fluid(A), &err) == 0);
            CHECK(phc_leaf_set_params(A, params(11, 0.3, 0.05, dt), &err) == 0);
            CHECK(phc_leaf_step(A, dt) == 0);
            CHECK(phc_leaf_step(C, dt) == 0);
            CHECK(memcmp(phc_leaf_fluid(A), phc_leaf_fluid(C), n * 8) == 0);
            phc_leaf_params g = phc_leaf_get_params(A);
            CHECK(g.beta_scale == 11 && g.stomata_scale == 0.3 && g.inflow_scale == 0.05 && g.dt == dt);
            /* s_O, s_I and dt changed, s_beta not: the factors are kept
               (they depend on h and s_beta only), the steps still equal a
               fresh leaf's to the bit, for h = the old dt, the new dt and
               another h; then s_beta changes again: refactorised */
            const phc_leaf_params ps[3] = {params(11, 0.7, 0.2, dt), params(11, 0.05, 0.4, h2),
                                           params(2.5, 0.05, 0.4, h2)};
            for (int k = 0; k < 3; ++k) {
                phc_leaf *D = make(W, H, m, b, O, I, ps[k]);
                CHECK(D != NULL);
                if (!D)
                    continue;
                CHECK(phc_leaf_set_fluid(D, phc_leaf_fluid(A), &err) == 0);
                CHECK(phc_leaf_set_params(A, ps[k], &err) == 0);
                const double hk[3] = {dt, h2, 0.029};
                for (int s = 0; s < 3; ++s) {
                    CHECK(phc_leaf_step(A, hk[s]) == 0);
                    CHECK(phc_leaf_step(D, hk[s]) == 0);
                }
                CHECK(memcmp(phc_leaf_fluid(A), phc_leaf_fluid(D), n * 8) == 0);
                phc_leaf_free(D);
            }
            phc_leaf_free(C);
        }
    }
    phc_leaf_free(A);
    phc_leaf_free(B);

    /* many different h (more than the cache's slots, each twice, then in
       reverse): every step equals a fresh leaf's step with that h as its dt */
    A = make(W, H, m, b, O, I, params(5, 0.2, 0.1, dt));
    CHECK(A != NULL);
    if (A) {
        double *ref = malloc(n * 8);
        CHECK(phc_leaf_set_fluid(A, y0, &err) == 0);
        memcpy(ref, y0, n * 8);
        for (size_t i = 0; i < n; ++i)
            ref[i] = m[i] ? ref[i] : 0.0;
        int same = 1;
        for (int s = 0; s < 60; ++s) {
            const int k = s < 40 ? s % 20 : 59 - s;
            const double h = k == 7 ? dt : 0.003 * (k + 1);
            phc_leaf *R = make(W, H, m, b, O, I, params(5, 0.2, 0.1, h));
            if (!R) {
                same = 0;
                break;
            }
            CHECK(phc_leaf_set_fluid(R, ref, &err) == 0);
            CHECK(phc_leaf_step(R, h) == 0);
            CHECK(phc_leaf_step(A, h) == 0);
            memcpy(ref, phc_leaf_fluid(R), n * 8);
            same &= memcmp(ref, phc_leaf_fluid(A), n * 8) == 0;
            phc_leaf_free(R);
        }
        CHECK(same);
        free(ref);
        phc_leaf_free(A);
    }

    /* advance(t) is continuous at t = k dt */
    const double tiny = 1e-9;
    double *res[3];
    double ts[3] = {7 * dt, 7 * dt + tiny, 7 * dt - tiny};
    for (int k = 0; k < 3; ++k) {
        res[k] = malloc(n * 8);
        A = make(W, H, m, b, O, I, params(5, 0.2, 0.1, dt));
        CHECK(A != NULL);
        if (!A) {
            memset(res[k], 0, n * 8);
            continue;
        }
        CHECK(phc_leaf_set_fluid(A, y0, &err) == 0);
        CHECK(phc_leaf_advance(A, ts[k]) == 0);
        CHECK_NEAR(phc_leaf_time(A), ts[k], 1e-15, 0);
        memcpy(res[k], phc_leaf_fluid(A), n * 8);
        phc_leaf_free(A);
    }
    double d1 = max_diff(res[0], res[1], n), d2 = max_diff(res[0], res[2], n);
    printf("advance_continuity: %.2e (+1e-9), %.2e (-1e-9)\n", d1, d2);
    CHECK(d1 <= 1e-9);
    CHECK(d2 <= 1e-9);
    /* advance in pieces: 3 dt + 0.5 dt then 0.5 dt + 3 dt, close to 7 dt
       (the half steps split differently: the splitting error, small) */
    A = make(W, H, m, b, O, I, params(5, 0.2, 0.1, dt));
    if (A) {
        CHECK(phc_leaf_set_fluid(A, y0, &err) == 0);
        CHECK(phc_leaf_advance(A, 3.5 * dt) == 0);
        CHECK(phc_leaf_advance(A, 3.5 * dt) == 0);
        CHECK_NEAR(phc_leaf_time(A), 7 * dt, 1e-14, 0);
        CHECK(max_diff(res[0], phc_leaf_fluid(A), n) < 0.02);
        CHECK(phc_leaf_advance(A, 0) == 0);
        CHECK(phc_leaf_advance(A, -1) == PHC_ERR_INVALID);
        CHECK(phc_leaf_advance(A, NAN) == PHC_ERR_INVALID);
        CHECK(phc_leaf_step(A, 0) == PHC_ERR_INVALID);
        CHECK(phc_leaf_step(A, -0.1) == PHC_ERR_INVALID);
        CHECK(phc_leaf_diffuse(A, INFINITY, PHC_LEAF_ROWS) == PHC_ERR_INVALID);
        /* reset */
        phc_leaf_reset(A, 0.25);
        CHECK(phc_leaf_time(A) == 0);
        int ok = 1;
        for (size_t i = 0; i < n; ++i)
            ok &= phc_leaf_fluid(A)[i] == (m[i] ? 0.25 : 0.0);
        CHECK(ok);
        phc_leaf_free(A);
    }
    for (int k = 0; k < 3; ++k)
        free(res[k]);
    phc_leaf_free(NULL);
}

static void test_bad_input(void)
{
    unsigned char m[MW * MH], none[MW * MH];
    double beta[MW * MH], O[MW * MH], I[MW * MH];
    small_mask(m);
    memset(none, 0, sizeof none);
    small_maps(beta, O, I, NULL, MW, MH);
    phc_leaf_params p = phc_leaf_params_default();
    CHECK(p.beta_scale == 50 && p.stomata_scale == 0.1 && p.inflow_scale == 0.05 && p.dt == 0.1);
    phc_leaf *L = (phc_leaf *)&p; /* must be reset to NULL on failure */
    phc_error err;

    phc_error_clear(&err);
    CHECK(phc_leaf_new(MW, MH, none, NULL, NULL, NULL, p, &L, &err) == PHC_ERR_INPUT);
    CHECK(L == NULL);
    CHECK_STR_CONTAINS(err.message, "mask");

    double bad[MW * MH];
    memcpy(bad, beta, sizeof bad);
    bad[3 + MW * 2] = -0.5; /* (3, 2) is on the leaf */
    CHECK(phc_leaf_new(MW, MH, m, bad, NULL, NULL, p, &L, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "beta");
    CHECK_STR_CONTAINS(err.message, "(3, 2)");
    /* off the leaf a bad value is ignored: (3, 0) is not leaf */
    memcpy(bad, beta, sizeof bad);
    bad[3] = -1;
    CHECK(phc_leaf_new(MW, MH, m, bad, NULL, NULL, p, &L, &err) == PHC_OK);
    phc_leaf_free(L);

    memcpy(bad, O, sizeof bad);
    bad[1 + MW * 4] = NAN;
    CHECK(phc_leaf_new(MW, MH, m, beta, bad, I, p, &L, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "stomata");
    CHECK_STR_CONTAINS(err.message, "(1, 4)");
    memcpy(bad, I, sizeof bad);
    bad[8 + MW * 6] = INFINITY;
    CHECK(phc_leaf_new(MW, MH, m, beta, O, bad, p, &L, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "inflow");
    CHECK_STR_CONTAINS(err.message, "(8, 6)");

    phc_leaf_params q = p;
    q.dt = 0;
    CHECK(phc_leaf_new(MW, MH, m, beta, O, I, q, &L, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "dt");
    q.dt = -0.1;
    CHECK(phc_leaf_new(MW, MH, m, beta, O, I, q, &L, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "dt");
    q = p;
    q.beta_scale = -1;
    CHECK(phc_leaf_new(MW, MH, m, beta, O, I, q, &L, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "beta_scale");
    q = p;
    q.stomata_scale = -2;
    CHECK(phc_leaf_new(MW, MH, m, beta, O, I, q, &L, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "stomata_scale");
    q = p;
    q.inflow_scale = NAN;
    CHECK(phc_leaf_new(MW, MH, m, beta, O, I, q, &L, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "inflow_scale");

    CHECK(phc_leaf_new(MW, MH, NULL, beta, O, I, p, &L, &err) == PHC_ERR_INVALID);
    CHECK(phc_leaf_new(0, MH, m, beta, O, I, p, &L, &err) == PHC_ERR_INVALID);
    CHECK(phc_leaf_new(MW, MH, m, beta, O, I, p, NULL, &err) == PHC_ERR_INVALID);
    CHECK(phc_leaf_new(MW, MH, none, NULL, NULL, NULL, p, &L, NULL) == PHC_ERR_INPUT);

    /* on an existing leaf: params and fluid */
    CHECK(phc_leaf_new(MW, MH, m, beta, O, I, p, &L, &err) == PHC_OK);
    if (L) {
        q = p;
        q.stomata_scale = -0.5;
        CHECK(phc_leaf_set_params(L, q, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "stomata_scale");
        q = p;
        q.dt = -1;
        CHECK(phc_leaf_set_params(L, q, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "dt");
        CHECK(phc_leaf_get_params(L).dt == p.dt); /* unchanged */
        double y[MW * MH];
        for (size_t i = 0; i < MW * MH; ++i)
            y[i] = 0.5;
        y[2 + MW * 5] = -1; /* (2, 5) is a hole: ignored */
        CHECK(phc_leaf_set_fluid(L, y, &err) == PHC_OK);
        CHECK(phc_leaf_fluid(L)[2 + MW * 5] == 0);
        y[6 + MW * 5] = -1;
        CHECK(phc_leaf_set_fluid(L, y, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "fluid");
        CHECK_STR_CONTAINS(err.message, "(6, 5)");
        CHECK(phc_leaf_fluid(L)[6 + MW * 5] == 0.5); /* unchanged */
        phc_leaf_free(L);
    }
}

int main(void)
{
    test_dense();
    test_conservation();
    test_limits();
    test_orientation();
    test_threads();
    test_caches_and_advance();
    test_bad_input();
    return check_finish("test_leaf");
}
