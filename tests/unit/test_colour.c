/* Unit tests of the leaf-colour arithmetic (model/colour.h): sRGB <-> CIELAB,
 * CIE76 and CIEDE2000 differences (Sharma, Wu and Dalal 2005 test data),
 * histogram matching (Silva et al. eq. 8), the transfer function and blend
 * (eq. 9) and quantiles.  Prints the measured errors. */
#include "check.h"

#include <stdint.h>
#include <stdlib.h>

#include "model/colour.h"

static uint64_t rng_state = 0x9e3779b97f4a7c15ULL;

/* xorshift64*: uniform in [0, 1) */
static double uniform01(void)
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ULL) >> 11) * 0x1.0p-53;
}

static void shuffle(size_t n, double *c, int stride)
{
    for (size_t i = n; i > 1; --i) {
        size_t j = (size_t)(uniform01() * (double)i);
        for (int k = 0; k < stride; ++k) {
            double t = c[stride * (i - 1) + k];
            c[stride * (i - 1) + k] = c[stride * j + k];
            c[stride * j + k] = t;
        }
    }
}

static void *xmalloc(size_t n)
{
    void *p = malloc(n);
    if (!p) {
        fprintf(stderr, "out of memory\n");
        exit(2);
    }
    return p;
}

/* ---- sRGB <-> CIELAB ---------------------------------------------------- */

static void test_lab(void)
{
    /* sRGB -> Lab -> sRGB over a grid of the cube (step 1/20) plus colours
     * straddling the sRGB branch point 0.04045. */
    double max_rt = 0.0;
    for (int i = 0; i <= 20; ++i)
        for (int j = 0; j <= 20; ++j)
            for (int k = 0; k <= 20; ++k) {
                const double rgb[3] = {i / 20.0, j / 20.0, k / 20.0};
                double lab[3], back[3];
                phc_colour_srgb_to_lab(rgb, lab);
                phc_colour_lab_to_srgb(lab, back);
                for (int c = 0; c < 3; ++c)
                    max_rt = fmax(max_rt, fabs(back[c] - rgb[c]));
            }
    const double edge[] = {0.0, 1e-9, 0.0404499, 0.04044995, 0.04045, 0.0404501, 0.5, 1.0};
    const int ne = (int)(sizeof edge / sizeof edge[0]);
    for (int i = 0; i < ne; ++i)
        for (int j = 0; j < ne; ++j)
            for (int k = 0; k < ne; ++k) {
                const double rgb[3] = {edge[i], edge[j], edge[k]};
                double lab[3], back[3];
                phc_colour_srgb_to_lab(rgb, lab);
                phc_colour_lab_to_srgb(lab, back);
                for (int c = 0; c < 3; ++c)
                    max_rt = fmax(max_rt, fabs(back[c] - rgb[c]));
            }
    printf("sRGB -> Lab -> sRGB round trip: max |error| = %.3g\n", max_rt);
    CHECK(max_rt <= 1e-10);

    /* Lab -> sRGB -> Lab over a Lab grid, most of it out of gamut (no
     * clipping: out-of-gamut colours must come back too). */
    double max_rt_lab = 0.0;
    for (int l = 0; l <= 100; l += 5)
        for (int a = -100; a <= 100; a += 10)
            for (int b = -100; b <= 100; b += 10) {
                const double lab[3] = {l, a, b};
                double rgb[3], back[3];
                phc_colour_lab_to_srgb(lab, rgb);
                phc_colour_srgb_to_lab(rgb, back);
                for (int c = 0; c < 3; ++c)
                    max_rt_lab = fmax(max_rt_lab, fabs(back[c] - lab[c]));
            }
    printf("Lab -> sRGB -> Lab round trip (out of gamut included): max |error| = %.3g\n",
           max_rt_lab);
    CHECK(max_rt_lab <= 1e-10);

    /* Known values.  The sRGB matrix is derived from the primaries and the
     * same D65 white as Xn, Zn, so white is a* = b* = 0 to rounding. */
    const double white[3] = {1, 1, 1}, black[3] = {0, 0, 0};
    double lab[3];
    phc_colour_srgb_to_lab(white, lab);
    printf("white -> Lab (%.3g, %.3g, %.3g) - (100, 0, 0)\n", lab[0] - 100, lab[1], lab[2]);
    CHECK_NEAR(lab[0], 100.0, 1e-10, 0);
    CHECK_NEAR(lab[1], 0.0, 1e-10, 0);
    CHECK_NEAR(lab[2], 0.0, 1e-10, 0);
    phc_colour_srgb_to_lab(black, lab);
    CHECK(lab[0] == 0.0 && lab[1] == 0.0 && lab[2] == 0.0);
    const double red[3] = {1, 0, 0}, green[3] = {0, 1, 0}, blue[3] = {0, 0, 1};
    phc_colour_srgb_to_lab(red, lab);
    printf("red -> Lab (%.4f, %.4f, %.4f)\n", lab[0], lab[1], lab[2]);
    CHECK_NEAR(lab[0], 53.24, 0.01, 0);
    CHECK_NEAR(lab[1], 80.09, 0.01, 0);
    CHECK_NEAR(lab[2], 67.20, 0.01, 0);
    phc_colour_srgb_to_lab(green, lab);
    CHECK_NEAR(lab[0], 87.73, 0.01, 0);
    CHECK_NEAR(lab[1], -86.18, 0.01, 0);
    CHECK_NEAR(lab[2], 83.18, 0.01, 0);
    phc_colour_srgb_to_lab(blue, lab);
    CHECK_NEAR(lab[0], 32.30, 0.01, 0);
    CHECK_NEAR(lab[1], 79.19, 0.01, 0);
    CHECK_NEAR(lab[2], -107.86, 0.01, 0);
    /* the transfer function alone: IEC 61966-2-1 values, and encode inverts
     * decode on the whole line, negative (out-of-gamut) values included */
    CHECK_NEAR(phc_colour_srgb_decode(0.5), pow(0.555 / 1.055, 2.4), 1e-15, 0);
    CHECK_NEAR(phc_colour_srgb_decode(0.04), 0.04 / 12.92, 1e-17, 0);
    CHECK_NEAR(phc_colour_srgb_encode(1.0), 1.0, 1e-15, 0);
    CHECK_NEAR(phc_colour_srgb_encode(0.002), 12.92 * 0.002, 1e-17, 0);
    double max_tf = 0.0;
    for (int i = -200; i <= 1200; ++i) {
        const double v = i / 1000.0;
        max_tf = fmax(max_tf, fabs(phc_colour_srgb_encode(phc_colour_srgb_decode(v)) - v));
    }
    for (int i = 0; i < ne; ++i)
        max_tf = fmax(max_tf, fabs(phc_colour_srgb_encode(phc_colour_srgb_decode(edge[i])) - edge[i]));
    printf("sRGB decode -> encode on [-0.2, 1.2]: max |error| = %.3g\n", max_tf);
    CHECK(max_tf <= 1e-14);
    /* mid grey: L* of Y = srgb_decode(0.5) = 0.21404 */
    const double grey[3] = {0.5, 0.5, 0.5};
    phc_colour_srgb_to_lab(grey, lab);
    CHECK_NEAR(lab[0], 116.0 * cbrt(pow(0.555 / 1.055, 2.4)) - 16.0, 1e-12, 0);
    CHECK_NEAR(lab[1], 0.0, 1e-10, 0);
    CHECK_NEAR(lab[2], 0.0, 1e-10, 0);
    /* lab_to_srgb does not clip */
    const double vivid[3] = {50, 120, 0};
    double rgb[3];
    phc_colour_lab_to_srgb(vivid, rgb);
    CHECK(rgb[0] > 1.0 && rgb[1] < 0.0);

    /* phc_colour_convert, in place, both ways, and from == to */
    enum { N = 50 };
    double c[3 * N], orig[3 * N], sep[3 * N];
    for (int i = 0; i < 3 * N; ++i)
        c[i] = orig[i] = uniform01();
    phc_colour_convert(N, c, PHC_COLOUR_RGB, PHC_COLOUR_LAB, sep);
    phc_colour_convert(N, c, PHC_COLOUR_RGB, PHC_COLOUR_LAB, c);
    CHECK(memcmp(c, sep, sizeof c) == 0);
    int same = 1;
    for (int i = 0; i < N; ++i) {
        double l3[3];
        phc_colour_srgb_to_lab(orig + 3 * i, l3);
        same &= memcmp(l3, sep + 3 * i, sizeof l3) == 0;
    }
    CHECK(same);
    phc_colour_convert(N, c, PHC_COLOUR_LAB, PHC_COLOUR_LAB, sep);
    CHECK(memcmp(c, sep, sizeof c) == 0);
    phc_colour_convert(N, c, PHC_COLOUR_LAB, PHC_COLOUR_RGB, c);
    double max_conv = 0.0;
    for (int i = 0; i < 3 * N; ++i)
        max_conv = fmax(max_conv, fabs(c[i] - orig[i]));
    CHECK(max_conv <= 1e-10);
}

/* ---- colour differences ------------------------------------------------ */

/* Sharma, Wu and Dalal, Color Res. Appl. 30:21-30 (2005), Table I: the 34
 * pairs L1 a1 b1, L2 a2 b2, ΔE00 (4 decimals). */
static const double sharma[34][7] = {
    {50.0000, 2.6772, -79.7751, 50.0000, 0.0000, -82.7485, 2.0425},
    {50.0000, 3.1571, -77.2803, 50.0000, 0.0000, -82.7485, 2.8615},
    {50.0000, 2.8361, -74.0200, 50.0000, 0.0000, -82.7485, 3.4412},
    {50.0000, -1.3802, -84.2814, 50.0000, 0.0000, -82.7485, 1.0000},
    {50.0000, -1.1848, -84.8006, 50.0000, 0.0000, -82.7485, 1.0000},
    {50.0000, -0.9009, -85.5211, 50.0000, 0.0000, -82.7485, 1.0000},
    {50.0000, 0.0000, 0.0000, 50.0000, -1.0000, 2.0000, 2.3669},
    {50.0000, -1.0000, 2.0000, 50.0000, 0.0000, 0.0000, 2.3669},
    {50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0009, 7.1792},
    {50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0010, 7.1792},
    {50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0011, 7.2195},
    {50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0012, 7.2195},
    {50.0000, -0.0010, 2.4900, 50.0000, 0.0009, -2.4900, 4.8045},
    {50.0000, -0.0010, 2.4900, 50.0000, 0.0010, -2.4900, 4.8045},
    {50.0000, -0.0010, 2.4900, 50.0000, 0.0011, -2.4900, 4.7461},
    {50.0000, 2.5000, 0.0000, 50.0000, 0.0000, -2.5000, 4.3065},
    {50.0000, 2.5000, 0.0000, 73.0000, 25.0000, -18.0000, 27.1492},
    {50.0000, 2.5000, 0.0000, 61.0000, -5.0000, 29.0000, 22.8977},
    {50.0000, 2.5000, 0.0000, 56.0000, -27.0000, -3.0000, 31.9030},
    {50.0000, 2.5000, 0.0000, 58.0000, 24.0000, 15.0000, 19.4535},
    {50.0000, 2.5000, 0.0000, 50.0000, 3.1736, 0.5854, 1.0000},
    {50.0000, 2.5000, 0.0000, 50.0000, 3.2972, 0.0000, 1.0000},
    {50.0000, 2.5000, 0.0000, 50.0000, 1.8634, 0.5757, 1.0000},
    {50.0000, 2.5000, 0.0000, 50.0000, 3.2592, 0.3350, 1.0000},
    {60.2574, -34.0099, 36.2677, 60.4626, -34.1751, 39.4387, 1.2644},
    {63.0109, -31.0961, -5.8663, 62.8187, -29.7946, -4.0864, 1.2630},
    {61.2901, 3.7196, -5.3901, 61.4292, 2.2480, -4.9620, 1.8731},
    {35.0831, -44.1164, 3.7933, 35.0232, -40.0716, 1.5901, 1.8645},
    {22.7233, 20.0904, -46.6940, 23.0331, 14.9730, -42.5619, 2.0373},
    {36.4612, 47.8580, 18.3852, 36.2715, 50.5065, 21.2231, 1.4146},
    {90.8027, -2.0831, 1.4410, 91.1528, -1.6435, 0.0447, 1.4441},
    {90.9257, -0.5406, -0.9208, 88.6381, -0.8985, -0.7239, 1.5381},
    {6.7747, -0.2908, -2.4247, 5.8714, -0.0985, -2.2286, 0.6377},
    {2.0776, 0.0795, -1.1350, 0.9033, -0.0636, -0.5514, 0.9082},
};

static void test_differences(void)
{
    double max_err = 0.0, max_asym = 0.0;
    for (int p = 0; p < 34; ++p) {
        const double *c1 = sharma[p], *c2 = sharma[p] + 3;
        const double d12 = phc_colour_de2000(c1, c2), d21 = phc_colour_de2000(c2, c1);
        const double e = fabs(d12 - sharma[p][6]);
        if (e > 0.5e-4 + 1e-12)
            printf("  Sharma pair %d: ΔE00 %.6f, table %.4f\n", p + 1, d12, sharma[p][6]);
        max_err = fmax(max_err, e);
        max_asym = fmax(max_asym, fabs(d12 - d21));
        CHECK_NEAR(d12, sharma[p][6], 1e-4, 0);
        CHECK_NEAR(d21, d12, 1e-13, 0);
    }
    printf("CIEDE2000 vs Sharma et al. Table I (34 pairs, 4-decimal values): max |error| = "
           "%.3g, max asymmetry = %.3g\n",
           max_err, max_asym);
    /* half a unit in the last printed decimal: the table rounds to 4 */
    CHECK(max_err <= 0.5e-4 + 1e-12);
    const double a[3] = {41.3, -12.5, 33.0};
    CHECK(phc_colour_de2000(a, a) == 0.0);
    CHECK(phc_colour_de76(a, a) == 0.0);

    const double p1[3] = {50, 0, 0}, p2[3] = {53, 4, 0}, p3[3] = {40, 10, -20};
    CHECK_NEAR(phc_colour_de76(p1, p2), 5.0, 1e-14, 0);
    CHECK_NEAR(phc_colour_de76(p1, p3), sqrt(100.0 + 100.0 + 400.0), 1e-13, 0);
    CHECK(phc_colour_de76(p1, p3) == phc_colour_de76(p3, p1));
    CHECK(phc_colour_de76(p2, p3) == phc_colour_de76(p3, p2));
    /* random symmetry of ΔE00 */
    double asym = 0.0;
    for (int i = 0; i < 1000; ++i) {
        const double x[3] = {100 * uniform01(), 200 * uniform01() - 100, 200 * uniform01() - 100};
        const double y[3] = {100 * uniform01(), 200 * uniform01() - 100, 200 * uniform01() - 100};
        asym = fmax(asym, fabs(phc_colour_de2000(x, y) - phc_colour_de2000(y, x)));
    }
    CHECK(asym <= 1e-12);
}

/* ---- histogram matching -------------------------------------------------- */

static double median_of(size_t n, const double *c, int ch)
{
    double *s = xmalloc(n * sizeof *s), q;
    phc_error err;
    if (phc_colour_quantiles(n, c, ch, 1, s, &q, &err)) {
        fprintf(stderr, "quantiles: %s\n", err.message);
        exit(2);
    }
    free(s);
    return q;
}

static void test_matching(void)
{
    phc_error err;
    enum { N = 400, M = 77 };
    double *src = xmalloc(3 * N * sizeof *src), *ref = xmalloc(3 * N * sizeof *ref);
    double *out = xmalloc(3 * N * sizeof *out);

    /* identity on itself, with ties (values quantised to 1/32) */
    for (int i = 0; i < 3 * N; ++i)
        src[i] = floor(uniform01() * 32.0) / 32.0;
    src[5] = 0.3; /* a non-dyadic value */
    CHECK(phc_colour_match_histograms(N, src, N, src, out, &err) == 0);
    CHECK(memcmp(out, src, 3 * N * sizeof *out) == 0);
    for (int i = 0; i < 3 * N; ++i)
        src[i] = uniform01() * 100.0 - 30.0;
    CHECK(phc_colour_match_histograms(N, src, N, src, out, &err) == 0);
    CHECK(memcmp(out, src, 3 * N * sizeof *out) == 0);

    /* an increasing affine map per channel (reference shuffled) is recovered
     * exactly when n_src == n_ref, ties included */
    const double scale[3] = {2.0, 0.37, 1.0 / 3.0}, shift[3] = {0.25, -11.0, 4.1};
    for (int pass = 0; pass < 2; ++pass) {
        if (pass == 1)
            for (int i = 0; i < 3 * N; ++i)
                src[i] = floor(uniform01() * 10.0);
        for (int i = 0; i < N; ++i)
            for (int c = 0; c < 3; ++c)
                ref[3 * i + c] = scale[c] * src[3 * i + c] + shift[c];
        shuffle(N, ref, 3);
        CHECK(phc_colour_match_histograms(N, src, N, ref, out, &err) == 0);
        int exact = 1;
        for (int i = 0; i < N; ++i)
            for (int c = 0; c < 3; ++c)
                exact &= out[3 * i + c] == scale[c] * src[3 * i + c] + shift[c];
        CHECK(exact);
    }

    /* n_src != n_ref: output within the reference range, monotone, equal
     * in -> equal out */
    for (int i = 0; i < 3 * N; ++i)
        src[i] = floor(uniform01() * 50.0) / 7.0;
    for (int i = 0; i < 3 * M; ++i)
        ref[i] = 5.0 + 3.0 * uniform01() * uniform01();
    CHECK(phc_colour_match_histograms(N, src, M, ref, out, &err) == 0);
    int in_range = 1, monotone = 1, ties = 1;
    for (int c = 0; c < 3; ++c) {
        double lo = INFINITY, hi = -INFINITY;
        for (int j = 0; j < M; ++j) {
            lo = fmin(lo, ref[3 * j + c]);
            hi = fmax(hi, ref[3 * j + c]);
        }
        for (int i = 0; i < N; ++i) {
            const double v = out[3 * i + c];
            in_range &= v >= lo && v <= hi;
            for (int j = 0; j < N; ++j) {
                if (src[3 * i + c] < src[3 * j + c])
                    monotone &= v <= out[3 * j + c];
                if (src[3 * i + c] == src[3 * j + c])
                    ties &= v == out[3 * j + c];
            }
        }
    }
    CHECK(in_range);
    CHECK(monotone);
    CHECK(ties);

    /* a hand example: src 0,1,2,3 onto ref 10,20 (positions -1/4 .. 5/4) */
    const double s4[12] = {3, 0, 0, 0, 1, 1, 2, 2, 2, 1, 3, 3};
    const double r2[6] = {20, 10, 10, 10, 20, 20};
    double o4[12];
    CHECK(phc_colour_match_histograms(4, s4, 2, r2, o4, &err) == 0);
    const double want0[4] = {20, 10, 17.5, 12.5}; /* channel 0: 3,0,2,1 */
    for (int i = 0; i < 4; ++i)
        CHECK_NEAR(o4[3 * i], want0[i], 1e-14, 0);

    /* a constant source maps to the reference median (odd and even n_ref) */
    for (int mref = 7; mref <= 8; ++mref) {
        for (int i = 0; i < 3 * mref; ++i)
            ref[i] = uniform01();
        for (int i = 0; i < 3 * 10; ++i)
            src[i] = 0.42;
        CHECK(phc_colour_match_histograms(10, src, (size_t)mref, ref, out, &err) == 0);
        for (int c = 0; c < 3; ++c) {
            double sorted[8];
            for (int j = 0; j < mref; ++j)
                sorted[j] = ref[3 * j + c];
            for (int a = 0; a < mref; ++a) /* insertion sort */
                for (int b = a; b > 0 && sorted[b] < sorted[b - 1]; --b) {
                    double t = sorted[b];
                    sorted[b] = sorted[b - 1];
                    sorted[b - 1] = t;
                }
            const double med = mref % 2 ? sorted[mref / 2]
                                        : 0.5 * (sorted[mref / 2 - 1] + sorted[mref / 2]);
            CHECK_NEAR(out[c], med, 1e-15, 0);
            CHECK(out[3 * 9 + c] == out[c]);
            CHECK(out[c] == median_of((size_t)mref, ref, c));
        }
    }

    /* bad input */
    CHECK(phc_colour_match_histograms(0, src, N, ref, out, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "source");
    CHECK(phc_colour_match_histograms(N, src, 0, ref, out, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "reference");
    for (int i = 0; i < 3 * N; ++i)
        src[i] = ref[i] = uniform01();
    src[3 * 17 + 2] = NAN;
    CHECK(phc_colour_match_histograms(N, src, N, ref, out, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "source colour 17 channel 2 is not finite");
    src[3 * 17 + 2] = 0.5;
    ref[4] = -INFINITY;
    CHECK(phc_colour_match_histograms(N, src, N, ref, out, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "reference colour 1 channel 1 is not finite");
    CHECK(phc_colour_match_histograms(N, src, N, ref, out, NULL) == PHC_ERR_INPUT);

    free(src);
    free(ref);
    free(out);
}

/* ---- transfer function and blend ---------------------------------------- */

static void test_transfer(void)
{
    const phc_colour_transfer tf = {0.2, 0.6};
    double gy, glo, ghi;
    CHECK(phc_colour_transfer_weight(tf, 0.2, &gy, &glo, &ghi) == 0.0);
    CHECK(gy == 0.0 && glo == 0.0 && ghi == 0.0);
    CHECK(phc_colour_transfer_weight(tf, 0.6, &gy, &glo, &ghi) == 1.0);
    CHECK(gy == 0.0 && glo == 0.0 && ghi == 0.0);
    CHECK(phc_colour_transfer_weight(tf, -3.0, NULL, NULL, NULL) == 0.0);
    CHECK(phc_colour_transfer_weight(tf, 7.0, NULL, NULL, NULL) == 1.0);
    CHECK_NEAR(phc_colour_transfer_weight(tf, 0.4, NULL, NULL, NULL), 0.5, 1e-15, 0);
    /* s = 1/4: g = 1/16 (3 - 1/2) = 5/32 */
    CHECK_NEAR(phc_colour_transfer_weight(tf, 0.3, NULL, NULL, NULL), 5.0 / 32.0, 1e-15, 0);

    /* derivatives against central differences */
    const double h = 1e-6;
    double max_fd = 0.0;
    for (int i = 1; i < 20; ++i) {
        const double y = 0.2 + 0.4 * i / 20.0;
        phc_colour_transfer_weight(tf, y, &gy, &glo, &ghi);
        const phc_colour_transfer lo_p = {tf.y_lo + h, tf.y_hi}, lo_m = {tf.y_lo - h, tf.y_hi};
        const phc_colour_transfer hi_p = {tf.y_lo, tf.y_hi + h}, hi_m = {tf.y_lo, tf.y_hi - h};
        const double fy = (phc_colour_transfer_weight(tf, y + h, NULL, NULL, NULL) -
                           phc_colour_transfer_weight(tf, y - h, NULL, NULL, NULL)) / (2 * h);
        const double flo = (phc_colour_transfer_weight(lo_p, y, NULL, NULL, NULL) -
                            phc_colour_transfer_weight(lo_m, y, NULL, NULL, NULL)) / (2 * h);
        const double fhi = (phc_colour_transfer_weight(hi_p, y, NULL, NULL, NULL) -
                            phc_colour_transfer_weight(hi_m, y, NULL, NULL, NULL)) / (2 * h);
        max_fd = fmax(max_fd, fmax(fabs(gy - fy), fmax(fabs(glo - flo), fabs(ghi - fhi))));
        CHECK_NEAR(gy + glo + ghi, 0.0, 1e-13, 0);
    }
    printf("transfer derivatives vs central differences: max |error| = %.3g\n", max_fd);
    CHECK(max_fd <= 1e-7);

    /* C^1 at the ends: value and derivative continuous */
    const double eps = 1e-9;
    double g = phc_colour_transfer_weight(tf, 0.2 + eps, &gy, &glo, &ghi);
    CHECK(g >= 0.0 && g <= 1e-16);
    CHECK(fabs(gy) <= 1e-7 && fabs(glo) <= 1e-7 && fabs(ghi) <= 1e-15);
    g = phc_colour_transfer_weight(tf, 0.6 - eps, &gy, &glo, &ghi);
    CHECK(fabs(g - 1.0) <= 1e-15);
    CHECK(fabs(gy) <= 1e-7 && fabs(glo) <= 1e-15 && fabs(ghi) <= 1e-7);

    /* transfer_check */
    phc_error err;
    phc_error_clear(&err);
    CHECK(phc_colour_transfer_check(tf, &err) == 0);
    const phc_colour_transfer equal = {0.5, 0.5}, reversed = {0.6, 0.2};
    const phc_colour_transfer nan_lo = {NAN, 0.5}, inf_hi = {0.1, INFINITY};
    CHECK(phc_colour_transfer_check(equal, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "y_hi");
    CHECK_STR_CONTAINS(err.message, "y_lo");
    CHECK(phc_colour_transfer_check(reversed, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "y_hi (0.2) must be greater than y_lo (0.6)");
    CHECK(phc_colour_transfer_check(nan_lo, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "y_lo");
    CHECK(phc_colour_transfer_check(inf_hi, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "y_hi");
    CHECK(phc_colour_transfer_check(reversed, NULL) == PHC_ERR_INPUT);
}

static void test_blend(void)
{
    enum { N = 30 };
    double o[3 * N], m[3 * N], y[N], out[3 * N];
    const phc_colour_transfer tf = {0.2, 0.6};
    for (int i = 0; i < 3 * N; ++i) {
        o[i] = uniform01();
        m[i] = uniform01() * 90.0;
    }
    for (int i = 0; i < N; ++i)
        y[i] = 0.6 + i; /* g = 1 */
    phc_colour_blend(N, o, m, y, tf, out);
    CHECK(memcmp(out, o, sizeof out) == 0);
    for (int i = 0; i < N; ++i)
        y[i] = 0.2 - i; /* g = 0 */
    phc_colour_blend(N, o, m, y, tf, out);
    CHECK(memcmp(out, m, sizeof out) == 0);
    for (int i = 0; i < N; ++i)
        y[i] = 0.4; /* g = 1/2 */
    phc_colour_blend(N, o, m, y, tf, out);
    double e = 0.0;
    for (int i = 0; i < 3 * N; ++i)
        e = fmax(e, fabs(out[i] - 0.5 * (o[i] + m[i])));
    CHECK(e <= 1e-13);
}

/* ---- quantiles ----------------------------------------------------------- */

static int cmp_dbl(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The multi-selection inside phc_colour_quantiles gives exactly the values
 * of a full sort: random data with many ties, sizes 1..400, nq 1..40,
 * against quantiles computed here from a qsort'ed copy with the same
 * interpolation rule (positions (k + 1/2) n / nq - 1/2). */
static void test_quantiles_against_sort(void)
{
    unsigned long long state = 12345;
    double worst = 0;
    for (size_t n = 1; n <= 400; n += (n < 20 ? 1 : 37)) {
        double *c = malloc(3 * n * sizeof *c), *sorted = malloc(n * sizeof *sorted), *scr = malloc(n * sizeof *scr);
        for (size_t i = 0; i < 3 * n; ++i) {
            state = state * 6364136223846793005ULL + 1442695040888963407ULL;
            c[i] = (double)((state >> 33) % 17); /* ties everywhere */
        }
        for (size_t nq = 1; nq <= 40; nq += 3) {
            double q[40];
            phc_error err;
            CHECK(phc_colour_quantiles(n, c, 1, nq, scr, q, &err) == PHC_OK);
            for (size_t i = 0; i < n; ++i)
                sorted[i] = c[3 * i + 1];
            qsort(sorted, n, sizeof *sorted, cmp_dbl);
            for (size_t k = 0; k < nq; ++k) {
                double pos = ((double)k + 0.5) * (double)n / (double)nq - 0.5;
                double want;
                if (pos <= 0)
                    want = sorted[0];
                else if (pos >= (double)(n - 1))
                    want = sorted[n - 1];
                else {
                    const size_t j = (size_t)pos;
                    want = sorted[j] + (pos - (double)j) * (sorted[j + 1] - sorted[j]);
                }
                worst = fmax(worst, fabs(q[k] - want));
            }
        }
        free(c);
        free(sorted);
        free(scr);
    }
    printf("quantiles_vs_sort_max_diff: %.3g\n", worst);
    CHECK(worst <= 1e-12);
}

static void test_quantiles(void)
{
    enum { N = 100 };
    double c[3 * N], scratch[N], q[200];
    phc_error err;
    for (int i = 0; i < N; ++i) {
        c[3 * i] = uniform01();
        c[3 * i + 1] = i;
        c[3 * i + 2] = -i;
    }
    shuffle(N, c, 3);
    CHECK(phc_colour_quantiles(N, c, 1, 100, scratch, q, &err) == 0);
    int exact = 1;
    for (int k = 0; k < 100; ++k)
        exact &= q[k] == k;
    CHECK(exact);
    CHECK(phc_colour_quantiles(N, c, 1, 10, scratch, q, &err) == 0);
    exact = 1;
    for (int k = 0; k < 10; ++k)
        exact &= q[k] == 10 * k + 4.5;
    CHECK(exact);
    CHECK(phc_colour_quantiles(N, c, 1, 4, scratch, q, &err) == 0);
    CHECK(q[0] == 12 && q[1] == 37 && q[2] == 62 && q[3] == 87);
    CHECK(phc_colour_quantiles(N, c, 1, 1, scratch, q, &err) == 0);
    CHECK(q[0] == 49.5);
    CHECK(phc_colour_quantiles(N, c, 2, 1, scratch, q, &err) == 0);
    CHECK(q[0] == -49.5);
    /* nq = 200: positions k/2 - 1/4, clamped at both ends */
    CHECK(phc_colour_quantiles(N, c, 1, 200, scratch, q, &err) == 0);
    CHECK(q[0] == 0 && q[1] == 0.25 && q[2] == 0.75 && q[198] == 98.75 && q[199] == 99);

    CHECK(phc_colour_quantiles(0, c, 1, 10, scratch, q, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "n = 0");
    CHECK(phc_colour_quantiles(N, c, 3, 10, scratch, q, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "channel 3");
    CHECK(phc_colour_quantiles(N, c, -1, 10, scratch, q, &err) == PHC_ERR_INPUT);
    CHECK(phc_colour_quantiles(N, c, 1, 0, scratch, q, &err) == PHC_ERR_INPUT);
    c[3 * 40] = NAN;
    CHECK(phc_colour_quantiles(N, c, 0, 10, scratch, q, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "colour 40 channel 0 is not finite");
    CHECK(phc_colour_quantiles(N, c, 1, 10, scratch, q, &err) == 0); /* other channel fine */
}

int main(void)
{
    test_quantiles_against_sort();
    test_lab();
    test_differences();
    test_matching();
    test_transfer();
    test_blend();
    test_quantiles();
    return check_finish("test_colour");
}
