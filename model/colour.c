/* Leaf colour from fluid (Silva et al. §3, eqs. 8-9) and colour arithmetic:
 * see colour.h. */
#include "model/colour.h"
#include "model/order_statistics.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ---- sRGB <-> CIE XYZ <-> CIELAB --------------------------------------- */

/* CIE 15 (2004/2018) reference white D65, 2° observer, Y normalised to 1. */
#define PHC_XN 0.95047
#define PHC_YN 1.0
#define PHC_ZN 1.08883

/* Linear sRGB -> XYZ.  Derived (exact rational arithmetic, rounded once to
 * double) from the IEC 61966-2-1 primaries x,y = (0.64, 0.33), (0.30, 0.60),
 * (0.15, 0.06) and the white point above, so that RGB (1,1,1) maps onto
 * (Xn, Yn, Zn) to rounding and white has a* = b* = 0.  (The standard's
 * four-decimal matrix rows sum to 0.9505, 1.0000, 1.0890, which would put
 * white at a* = 0.005, b* = -0.010 with these Xn, Zn.) */
static const double srgb_to_xyz_m[3][3] = {
    {0.4124564390896921, 0.35757607764390897, 0.18043748326639894},
    {0.21267285140562248, 0.71515215528781795, 0.072174993306559576},
    {0.019333895582329317, 0.119192025881303, 0.95030407853636767},
};
/* Its inverse, computed exactly and rounded once. */
static const double xyz_to_srgb_m[3][3] = {
    {3.2404541621141054, -1.5371385127977166, -0.49853140955601621},
    {-0.96926603050518678, 1.8760108454466942, 0.041556017530349841},
    {0.055643430959114691, -0.20402591351675387, 1.0572251882231791},
};

/* IEC 61966-2-1 sRGB decoding (electro-optical transfer): gamma-encoded
 * component -> linear. */
double phc_colour_srgb_decode(double c)
{
    if (c <= 0.04045)
        return c / 12.92;
    return pow((c + 0.055) / 1.055, 2.4);
}

/* IEC 61966-2-1 sRGB encoding: linear -> gamma-encoded.  Not clipped:
 * values outside [0, 1] stay outside.  The standard's constants are
 * consistent only to ~1e-8: decoding jumps at 0.04045 from 0.04045/12.92 =
 * 0.0031308050 (linear branch) to 0.0031308073 (power branch), and the
 * stated encoding threshold 0.0031308 lies below that gap, so colours just
 * under 0.04045 would come back ~3e-8 off.  We switch branch in the middle
 * of the gap instead, so that encoding inverts phc_colour_srgb_decode to
 * rounding on the whole line, even after the 1e-16 perturbations of the XYZ
 * matrices (the two branches differ by < 3e-8 between 0.0031308 and this
 * value). */
double phc_colour_srgb_encode(double v)
{
    if (v <= 0.003130806118314028)
        return 12.92 * v;
    return 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

/* CIE 15 CIELAB: f(t) = t^(1/3) above (6/29)^3, else the linear segment
 * t / (3 (6/29)^2) + 4/29 (the exact-fraction form of 7.787 t + 16/116). */
static double lab_f(double t)
{
    const double d = 6.0 / 29.0;
    if (t > d * d * d)
        return cbrt(t);
    return t / (3.0 * d * d) + 4.0 / 29.0;
}

static double lab_f_inv(double f)
{
    const double d = 6.0 / 29.0;
    if (f > d)
        return f * f * f;
    return 3.0 * d * d * (f - 4.0 / 29.0);
}

void phc_colour_srgb_to_lab(const double rgb[3], double lab[3])
{
    double lin[3], xyz[3];
    for (int k = 0; k < 3; ++k)
        lin[k] = phc_colour_srgb_decode(rgb[k]);
    for (int r = 0; r < 3; ++r)
        xyz[r] = srgb_to_xyz_m[r][0] * lin[0] + srgb_to_xyz_m[r][1] * lin[1] +
                 srgb_to_xyz_m[r][2] * lin[2];
    const double fx = lab_f(xyz[0] / PHC_XN), fy = lab_f(xyz[1] / PHC_YN),
                 fz = lab_f(xyz[2] / PHC_ZN);
    lab[0] = 116.0 * fy - 16.0;
    lab[1] = 500.0 * (fx - fy);
    lab[2] = 200.0 * (fy - fz);
}

void phc_colour_lab_to_srgb(const double lab[3], double rgb[3])
{
    const double fy = (lab[0] + 16.0) / 116.0;
    const double fx = fy + lab[1] / 500.0;
    const double fz = fy - lab[2] / 200.0;
    const double xyz[3] = {PHC_XN * lab_f_inv(fx), PHC_YN * lab_f_inv(fy),
                           PHC_ZN * lab_f_inv(fz)};
    for (int r = 0; r < 3; ++r) {
        const double lin = xyz_to_srgb_m[r][0] * xyz[0] + xyz_to_srgb_m[r][1] * xyz[1] +
                           xyz_to_srgb_m[r][2] * xyz[2];
        rgb[r] = phc_colour_srgb_encode(lin);
    }
}

void phc_colour_convert(size_t n, const double *in, phc_colour_space from, phc_colour_space to,
                        double *out)
{
    if (from == to) {
        if (in != out)
            memmove(out, in, 3 * n * sizeof *out);
        return;
    }
    for (size_t i = 0; i < n; ++i) {
        const double c[3] = {in[3 * i], in[3 * i + 1], in[3 * i + 2]};
        if (from == PHC_COLOUR_RGB)
            phc_colour_srgb_to_lab(c, out + 3 * i);
        else
            phc_colour_lab_to_srgb(c, out + 3 * i);
    }
}

/* ---- colour differences ------------------------------------------------ */

double phc_colour_de76(const double lab1[3], const double lab2[3])
{
    const double dl = lab1[0] - lab2[0], da = lab1[1] - lab2[1], db = lab1[2] - lab2[2];
    return sqrt(dl * dl + da * da + db * db);
}

/* pi to double precision (M_PI is not ISO C). */
#define PHC_COLOUR_PI 3.14159265358979323846

static double deg2rad(double d) { return d * (PHC_COLOUR_PI / 180.0); }

/* Hue angle in degrees, [0, 360); 0 for the achromatic a = b = 0
 * (Sharma et al. 2005, eq. 4). */
static double hue_deg(double b, double a)
{
    if (a == 0.0 && b == 0.0)
        return 0.0;
    double h = atan2(b, a) * (180.0 / PHC_COLOUR_PI);
    if (h < 0.0)
        h += 360.0;
    return h;
}

/* CIEDE2000 following Sharma, Wu and Dalal (2005), eqs. 1-22, with
 * kL = kC = kH = 1.  Symmetric in its arguments. */
double phc_colour_de2000(const double lab1[3], const double lab2[3])
{
    const double pow25_7 = 6103515625.0; /* 25^7 */
    const double L1 = lab1[0], a1 = lab1[1], b1 = lab1[2];
    const double L2 = lab2[0], a2 = lab2[1], b2 = lab2[2];

    /* eqs. 2-6: a' rescaled by G, C', h' */
    const double Cab = 0.5 * (hypot(a1, b1) + hypot(a2, b2));
    const double Cab7 = pow(Cab, 7.0);
    const double G = 0.5 * (1.0 - sqrt(Cab7 / (Cab7 + pow25_7)));
    const double a1p = (1.0 + G) * a1, a2p = (1.0 + G) * a2;
    const double C1p = hypot(a1p, b1), C2p = hypot(a2p, b2);
    const double h1p = hue_deg(b1, a1p), h2p = hue_deg(b2, a2p);

    /* eqs. 8-11: differences */
    const double dLp = L2 - L1;
    const double dCp = C2p - C1p;
    const double CC = C1p * C2p;
    double dhp = 0.0;
    if (CC != 0.0) {
        dhp = h2p - h1p;
        if (dhp > 180.0)
            dhp -= 360.0;
        else if (dhp < -180.0)
            dhp += 360.0;
    }
    const double dHp = 2.0 * sqrt(CC) * sin(deg2rad(0.5 * dhp));

    /* eqs. 12-22: weighting functions */
    const double Lbp = 0.5 * (L1 + L2);
    const double Cbp = 0.5 * (C1p + C2p);
    double hbp = h1p + h2p;
    if (CC != 0.0) {
        if (fabs(h1p - h2p) <= 180.0)
            hbp *= 0.5;
        else if (hbp < 360.0)
            hbp = 0.5 * (hbp + 360.0);
        else
            hbp = 0.5 * (hbp - 360.0);
    }
    const double T = 1.0 - 0.17 * cos(deg2rad(hbp - 30.0)) + 0.24 * cos(deg2rad(2.0 * hbp)) +
                     0.32 * cos(deg2rad(3.0 * hbp + 6.0)) - 0.20 * cos(deg2rad(4.0 * hbp - 63.0));
    const double q = (hbp - 275.0) / 25.0;
    const double dtheta = 30.0 * exp(-q * q);
    const double Cbp7 = pow(Cbp, 7.0);
    const double RC = 2.0 * sqrt(Cbp7 / (Cbp7 + pow25_7));
    const double l50 = (Lbp - 50.0) * (Lbp - 50.0);
    const double SL = 1.0 + 0.015 * l50 / sqrt(20.0 + l50);
    const double SC = 1.0 + 0.045 * Cbp;
    const double SH = 1.0 + 0.015 * Cbp * T;
    const double RT = -sin(deg2rad(2.0 * dtheta)) * RC;

    const double tl = dLp / SL, tc = dCp / SC, th = dHp / SH;
    const double s = tl * tl + tc * tc + th * th + RT * tc * th;
    return sqrt(s > 0.0 ? s : 0.0);
}

/* ---- order statistics --------------------------------------------------- */

static int cmp_double(const void *pa, const void *pb)
{
    const double a = *(const double *)pa, b = *(const double *)pb;
    return (a > b) - (a < b);
}

typedef struct value_index {
    double v;
    size_t i;
} value_index;

static int cmp_value_index(const void *pa, const void *pb)
{
    const value_index *a = pa, *b = pb;
    if (a->v != b->v)
        return (a->v > b->v) - (a->v < b->v);
    return (a->i > b->i) - (a->i < b->i);
}

/* Quantile function of m sorted values y_0 <= ... <= y_{m-1}, the order
 * statistic y_j placed at probability (j + 1/2)/m, linear in between and
 * constant (y_0, y_{m-1}) outside [1/(2m), 1 - 1/(2m)].  The position
 * pos = u m - 1/2 is passed as the exact fraction (num_plus - num_minus)/den
 * of integers so that integer positions are hit exactly (no rounding of
 * u m): this is what makes matching a set to itself the identity.  The
 * result is clamped to [y_j, y_{j+1}], so it is monotone in pos and never
 * leaves the range of the data. */
static double sorted_quantile(const double *y, size_t m, uint64_t num_plus, uint64_t num_minus,
                              uint64_t den)
{
    if (num_plus <= num_minus)
        return y[0];
    const uint64_t num = num_plus - num_minus;
    const uint64_t j = num / den, rem = num % den;
    if (j >= m - 1)
        return y[m - 1];
    if (rem == 0)
        return y[j];
    const double t = (double)rem / (double)den;
    const double lo = y[j], hi = y[j + 1];
    const double v = lo + t * (hi - lo);
    return v < lo ? lo : (v > hi ? hi : v);
}

/* Flat index (3 i + channel) of the first non-finite component of n
 * interleaved colours, or 3 n when all are finite. */
static size_t first_non_finite(size_t n, const double *c)
{
    for (size_t k = 0; k < 3 * n; ++k)
        if (!isfinite(c[k]))
            return k;
    return 3 * n;
}

/* ---- histogram matching (eq. 8) ---------------------------------------- */

/* For each channel: sort the reference values (Q_ref) and the source values
 * with their indices (F_src).  A run of equal source values at sorted
 * positions a..b (0-based) gets the mid-rank r = (a + b)/2 and probability
 * u = (r + 1/2)/n_src, and maps to Q_ref(u) (sorted_quantile), i.e. to the
 * reference position u n_ref - 1/2 = ((a + b + 1) n_ref - n_src)/(2 n_src).
 * O(n log n) per channel.  Silva et al. §3, eq. 8. */
int phc_colour_match_histograms(size_t n_src, const double *src, size_t n_ref, const double *ref,
                                double *matched, phc_error *err)
{
    if (n_src == 0 || n_ref == 0)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "histogram matching: %s set is empty (%zu source, %zu reference "
                             "colours); both need at least one pixel",
                             n_src == 0 ? "the source" : "the reference", n_src, n_ref);
    if (!src || !ref || !matched)
        return phc_error_set(err, PHC_ERR_INVALID, "histogram matching: NULL colour array");
    /* (a + b + 1) n_ref <= 2 n_src n_ref must fit in 64 bits */
    if (n_src > (UINT64_MAX / 4) / n_ref)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "histogram matching: %zu source x %zu reference colours is too many",
                             n_src, n_ref);
    size_t k = first_non_finite(n_src, src);
    if (k < 3 * n_src)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "histogram matching: source colour %zu channel %zu is not finite (%g)",
                             k / 3, k % 3, src[k]);
    k = first_non_finite(n_ref, ref);
    if (k < 3 * n_ref)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "histogram matching: reference colour %zu channel %zu is not finite "
                             "(%g)",
                             k / 3, k % 3, ref[k]);

    double *yref = malloc(n_ref * sizeof *yref);
    value_index *vs = malloc(n_src * sizeof *vs);
    if (!yref || !vs) {
        free(yref);
        free(vs);
        return phc_error_set(err, PHC_ERR_NOMEM, "histogram matching: out of memory for %zu + %zu "
                             "colours", n_src, n_ref);
    }
    const uint64_t den = 2 * (uint64_t)n_src;
    for (int c = 0; c < 3; ++c) {
        for (size_t j = 0; j < n_ref; ++j)
            yref[j] = ref[3 * j + c];
        qsort(yref, n_ref, sizeof *yref, cmp_double);
        for (size_t i = 0; i < n_src; ++i) {
            vs[i].v = src[3 * i + c];
            vs[i].i = i;
        }
        qsort(vs, n_src, sizeof *vs, cmp_value_index);
        for (size_t a = 0; a < n_src;) {
            size_t b = a;
            while (b + 1 < n_src && vs[b + 1].v == vs[a].v)
                ++b;
            const double m = sorted_quantile(yref, n_ref, ((uint64_t)a + b + 1) * n_ref,
                                             (uint64_t)n_src, den);
            for (size_t p = a; p <= b; ++p)
                matched[3 * vs[p].i + c] = m;
            a = b + 1;
        }
    }
    free(yref);
    free(vs);
    return PHC_OK;
}

/* ---- transfer function and blending (eq. 9) ---------------------------- */

/* Smoothstep g = s^2 (3 - 2 s), s = (y - y_lo)/w, w = y_hi - y_lo (Silva et
 * al. §3, eq. 9).  dg/ds = 6 s (1 - s); ds/dy = 1/w, ds/dy_lo = (s - 1)/w,
 * ds/dy_hi = -s/w (the three derivatives sum to 0: g depends only on the
 * differences).  All derivatives vanish outside (y_lo, y_hi) and at its
 * ends, so g is C^1. */
double phc_colour_transfer_weight(phc_colour_transfer tf, double y, double *dg_dy,
                                  double *dg_dlo, double *dg_dhi)
{
    double g, gy = 0.0, glo = 0.0, ghi = 0.0;
    if (y <= tf.y_lo) {
        g = 0.0;
    } else if (y >= tf.y_hi) {
        g = 1.0;
    } else {
        const double w = tf.y_hi - tf.y_lo;
        const double s = (y - tf.y_lo) / w;
        const double ds = 6.0 * s * (1.0 - s) / w; /* dg/ds / w */
        g = s * s * (3.0 - 2.0 * s);
        gy = ds;
        glo = ds * (s - 1.0);
        ghi = -ds * s;
    }
    if (dg_dy)
        *dg_dy = gy;
    if (dg_dlo)
        *dg_dlo = glo;
    if (dg_dhi)
        *dg_dhi = ghi;
    return g;
}

int phc_colour_transfer_check(phc_colour_transfer tf, phc_error *err)
{
    if (!isfinite(tf.y_lo))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "colour transfer: y_lo must be a finite number, found %g", tf.y_lo);
    if (!isfinite(tf.y_hi))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "colour transfer: y_hi must be a finite number, found %g", tf.y_hi);
    if (!(tf.y_hi > tf.y_lo))
        return phc_error_set(err, PHC_ERR_INPUT,
                             "colour transfer: y_hi (%g) must be greater than y_lo (%g)", tf.y_hi,
                             tf.y_lo);
    return PHC_OK;
}

/* Eq. 9, written g o + (1 - g) m so that g = 1 gives o and g = 0 gives m
 * exactly. */
void phc_colour_blend(size_t n, const double *original, const double *matched,
                      const double *fluid, phc_colour_transfer tf, double *out)
{
    for (size_t i = 0; i < n; ++i) {
        const double g = phc_colour_transfer_weight(tf, fluid[i], NULL, NULL, NULL);
        for (int c = 0; c < 3; ++c)
            out[3 * i + c] = g * original[3 * i + c] + (1.0 - g) * matched[3 * i + c];
    }
}

/* ---- quantiles ----------------------------------------------------------- */

/* q_k = Q((k + 1/2)/nq): position ((2k + 1) n - nq)/(2 nq) among the sorted
 * values, interpolated as in histogram matching (sorted_quantile). */
int phc_colour_quantiles(size_t n, const double *colours, int channel, size_t nq, double *scratch,
                         double *q, phc_error *err)
{
    if (n == 0)
        return phc_error_set(err, PHC_ERR_INPUT, "colour quantiles: no colours (n = 0)");
    if (nq == 0)
        return phc_error_set(err, PHC_ERR_INPUT, "colour quantiles: no quantiles asked (nq = 0)");
    if (channel < 0 || channel > 2)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "colour quantiles: channel %d is not 0, 1 or 2", channel);
    if (!colours || !scratch || !q)
        return phc_error_set(err, PHC_ERR_INVALID, "colour quantiles: NULL array");
    if (n > (UINT64_MAX / 4) / nq)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "colour quantiles: %zu colours x %zu quantiles is too many", n, nq);
    for (size_t i = 0; i < n; ++i) {
        const double v = colours[3 * i + (size_t)channel];
        if (!isfinite(v))
            return phc_error_set(err, PHC_ERR_INPUT,
                                 "colour quantiles: colour %zu channel %d is not finite (%g)", i,
                                 channel, v);
        scratch[i] = v;
    }
    const uint64_t den = 2 * (uint64_t)nq;
    /* Only the order statistics the quantiles read are needed: put those
     * in place in O(n) (model/order_statistics.h), against a full sort's
     * O(n log n) with a comparison callback: the calibration computes
     * these for every photo at every trial point.  The values read are
     * the same as after a sort, so the result is too. */
    size_t *pos = malloc(2 * nq * sizeof *pos), np = 0;
    if (!pos) {
        qsort(scratch, n, sizeof *scratch, cmp_double);
    } else {
        for (size_t k = 0; k < nq; ++k) {
            const uint64_t plus = (2 * (uint64_t)k + 1) * n, minus = (uint64_t)nq;
            if (plus <= minus) {
                pos[np++] = 0;
                continue;
            }
            const uint64_t j = (plus - minus) / den, rem = (plus - minus) % den;
            if (j >= n - 1) {
                pos[np++] = n - 1;
                continue;
            }
            pos[np++] = (size_t)j;
            if (rem)
                pos[np++] = (size_t)j + 1;
        }
        /* ascending and distinct (they are generated in order) */
        size_t u = 0;
        for (size_t i = 0; i < np; ++i)
            if (u == 0 || pos[i] > pos[u - 1])
                pos[u++] = pos[i];
        phc_order_statistics_select(scratch, n, pos, u);
        free(pos);
    }
    for (size_t k = 0; k < nq; ++k)
        q[k] = sorted_quantile(scratch, n, (2 * (uint64_t)k + 1) * n, (uint64_t)nq, den);
    return PHC_OK;
}
