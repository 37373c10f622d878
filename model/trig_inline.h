/* The angle of a unit vector and sincos inline, for the joint pass's
 * partial turn exp(k log δ) (model/particles.c, follow_one): φ and then
 * sin kφ, cos kφ.  Over the ranges used there (φ and kφ in [0, π/2])
 * they agree with glibc's atan2, sin and cos to about an ulp (bounds
 * below; tests/unit/test_trig_inline.c measures them against libm) with
 * no division and short dependency chains: the joint pass runs each
 * shoot's links one after another, each waiting for its parent, so the
 * pass's time is the chain of latencies through a link (its atan2 alone,
 * with its two divisions, was about 15% of a 25k frame on one thread).
 * Outside those ranges (and for NaN, ±∞) they call libm.
 *
 * Both reduce by a table (ours; the identities are the textbook ones,
 * Abramowitz & Stegun 4.3.16–17 and 4.4.40):
 *   angle: (c, s) = (cos φ, sin φ), φ ≤ π/4 (else the angle of (s, c)
 *     from π/2), node θ_j = asin(j/16), j = round(16 s):
 *     sin(φ − θ_j) = s cos θ_j − c j/16 =: r, φ = θ_j + asin r, |r| ≤ 0.043
 *     (j = 1 is taken as j = 0, r = s ≤ 3/32, so that the rounding of r
 *     stays small against φ); asin r by its Taylor series
 *     r + Σ_{n ≥ 1} binom(2n, n) r^{2n+1} / (4ⁿ (2n + 1)) to n = 7 (the
 *     next term ≤ 4e-19 of r), r corrected by 1/|(c, s)| ≈ (3 − |(c, s)|²)/2
 *     (exact to (3/8)η², η = |(c, s)|² − 1 ≤ 1e-9; beyond that libm's atan2);
 *   sincos: θ = c + r, c = j/16, j = round(16θ), |r| ≤ 1/32 (j = 1 as 0:
 *     r ≤ 3/32), above π/4 on π/2 − θ = (PIO2_HI − θ) + PIO2_LO:
 *     sin(c + r) = sin c + (sin c (cos r − 1) + cos c sin r),
 *     cos(c + r) = cos c + (cos c (cos r − 1) − sin c sin r),
 *     sin r to r⁹, cos r − 1 to r¹⁰ (next terms ≤ 2⁻⁵⁹ |r|, 2⁻⁶⁹).
 * The polynomials are evaluated in Estrin's scheme (Knuth, TAOCP vol. 2,
 * 4.6.4), not Horner's: half the dependent steps.  Each table value is a
 * pair hi + lo of doubles (π/2 too), so the error is that of the last few
 * roundings: the final sum's 1/2 ulp plus about 2⁻⁵⁴ of the terms
 * s cos θ_j and c j/16 in r (the angle: 1.64 ulps at most of the exact
 * one in 300,000 angles measured against mpmath at 120 bits, 2 ulps of
 * libm's atan2; sincos: 1 ulp of libm's).
 *
 * The tables (values at 200 bits, rounded to hi, the rest to lo) were made
 * with mpmath 1.3.0: hilo(v) = (float(v), float(v − float(v)));
 *   asin table, j = 0 .. 11, S = mp.mpf(j)/16: hilo(sqrt(1 − S²)),
 *     hilo(asin S), hilo(π/2 − asin S);
 *   sincos table, j = 0 .. 13: hilo(sin(j/16)), hilo(cos(j/16)).
 * Pure C, no I/O; header only, so that the callers inline it. */
#ifndef PHC_TRIG_INLINE_H
#define PHC_TRIG_INLINE_H

#include <math.h>

/* {cos θ_j hi, lo, θ_j hi, lo, π/2 − θ_j hi, lo}, θ_j = asin(j/16) */
static const double phc_trig_asin_table[12][6] = {
    {0x1.0000000000000p+0, 0.0, 0.0, 0.0, 0x1.921fb54442d18p+0, 0x1.1a62633145c07p-54},
    {0x1.feffbfdfebf1fp-1, 0x1.5dee51994f18bp-55, 0x1.002abde953619p-4, 0x1.182e2dc6ddeedp-58, 0x1.821d0965ad9b7p+0, -0x1.37207fab281e8p-54},
    {0x1.fbfbf7ebc755fp-1, -0x1.b2a94084da0b6p-55, 0x1.00abe0c129e1ep-3, 0x1.7ceb0ee49d42ap-60, 0x1.720a392c1d955p+0, -0x1.eb91490a4cb4ap-54},
    {0x1.f6eb62d27730dp-1, -0x1.401d95ca1ce34p-55, 0x1.82494ed0e78fcp-3, -0x1.443c2697a7d2fp-57, 0x1.61d68b6a25df9p+0, -0x1.7a2c2ff78a8a7p-55},
    {0x1.efbdeb14f4edap-1, -0x1.3a145fe1be078p-55, 0x1.02be9ce0b87cdp-2, 0x1.e5d09da2e0f04p-58, 0x1.51700e0c14b25p+0, -0x1.fd535474274b1p-61},
    {0x1.e65b9edeba38ep-1, -0x1.bb73251e8c364p-57, 0x1.457393b90e2aap-2, 0x1.b1f64d329fe98p-56, 0x1.40c2d055ff46ep+0, -0x1.521b301b6239fp-54},
    {0x1.daa2fefaae1d8p-1, -0x1.3fe0e03f44594p-58, 0x1.899f4edc962d3p-2, 0x1.3e919701b7c6dp-60, 0x1.2fb7e18d1d464p+0, -0x1.ea97e32ac11ebp-54},
    {0x1.cc665b0328622p-1, -0x1.1baa4d369f814p-55, 0x1.cfaf27460fe9fp-2, -0x1.8bf75f355f723p-57, 0x1.1e33eb72bed71p+0, -0x1.b41eb0e80e515p-54},
    {0x1.bb67ae8584caap-1, 0x1.cec95d0b5c1e3p-55, 0x1.0c152382d7366p-1, -0x1.ee6913347c2a6p-55, 0x1.0c152382d7366p+0, -0x1.ee6913347c2a6p-54},
    {0x1.a751f9447b724p-1, 0x1.2b909477e9ed1p-56, 0x1.31df40fbd31cdp-1, 0x1.10ebcfd1cc29dp-60, 0x1.f260298cb2864p-1, -0x1.d3c2981c02e07p-55},
    {0x1.8fae0c15ad38ap-1, -0x1.db7adb6817f6dp-57, 0x1.59aad71ced00fp-1, -0x1.b5b31565e9408p-58, 0x1.ca94936b98a22p-1, -0x1.9484d6f0b7571p-55},
    {0x1.73ce704fb7b23p-1, 0x1.1470b816b17a6p-55, 0x1.841deb5114bb4p-1, -0x1.49d1c4e2eba5ep-55, 0x1.a0217f3770e7dp-1, -0x1.02d2e97511b28p-56},
};
static const double phc_trig_sincos_table[14][4] = { /* sin(j/16), cos(j/16) */
    {0.0, 0.0, 0x1.0000000000000p+0, 0.0},
    {0x1.ffaaaeeed4edbp-5, -0x1.2d16d32684b69p-59, 0x1.ff0015549f4d3p-1, 0x1.328387b99426fp-55},
    {0x1.feaaeee86ee36p-4, -0x1.afcb2bcc6f03bp-59, 0x1.fc015527d5bd3p-1, 0x1.b68f35094efb8p-55},
    {0x1.7dc102fbaf2b5p-3, 0x1.5ab50e23c97c3p-59, 0x1.f706bdf9ece1cp-1, -0x1.698c80c36dcb4p-55},
    {0x1.faaeed4f31577p-3, -0x1.15d88508e32b8p-57, 0x1.f01549f7deea1p-1, 0x1.d3c1e99e5cafdp-55},
    {0x1.3ad129769d3d8p-2, 0x1.03d550487839ap-63, 0x1.e733ea0193d40p-1, -0x1.6428b3546ce13p-55},
    {0x1.7710255764214p-2, -0x1.6ead7314bb6cep-57, 0x1.dc6b7eb995912p-1, 0x1.4b364776dcd35p-58},
    {0x1.b1d8305321617p-2, -0x1.ae242cb99f519p-56, 0x1.cfc6cfa52ad9fp-1, 0x1.8b5b5508f2a0dp-55},
    {0x1.eaee8744b05f0p-2, -0x1.789b43c9b027dp-58, 0x1.c1528065b7d50p-1, -0x1.892111312e828p-55},
    {0x1.110d0c4b69c3bp-1, 0x1.d918998809981p-55, 0x1.b11d04162a4c6p-1, 0x1.1dd561efbc0c2p-56},
    {0x1.2b91dea88421ep-1, -0x1.fa371db216ab0p-55, 0x1.9f368ed912f85p-1, -0x1.1d200c5791606p-55},
    {0x1.44eb381cf386bp-1, -0x1.3ed6c1e6a5505p-55, 0x1.8bb105a5dc900p-1, 0x1.863e03e9474c1p-55},
    {0x1.5cffc16bf8f0dp-1, 0x1.96cb370eb578ap-55, 0x1.769fec655211fp-1, -0x1.827d5cf8c68c5p-57},
    {0x1.73b7680dea578p-1, -0x1.2248306dc12a2p-56, 0x1.6018526f563dfp-1, 0x1.46ca5e0e432d0p-55},
};
#define PHC_TRIG_PIO2_HI 0x1.921fb54442d18p+0
#define PHC_TRIG_PIO2_LO 0x1.1a62633145c07p-54

/* The angle φ ∈ [0, π/2] (rad) of (c, s) = (cos φ, sin φ), c, s ≥ 0, a
 * unit vector to rounding (|c² + s² − 1| ≤ 1e-9); libm's atan2(s, c)
 * otherwise (also for NaN, ±∞). */
static inline double phc_angle_unit(double c, double s)
{
    const double n2 = c * c + s * s;
    if (!(c >= 0 && s >= 0 && fabs(n2 - 1) <= 1e-9))
        return atan2(s, c);
    const int flip = s > c; /* φ > π/4: π/2 − the angle of (s, c) */
    const double y = flip ? c : s, x = flip ? s : c; /* y ≤ 0.7072 */
    int j = (int)(16.0 * y + 0.5);
    j = j == 1 ? 0 : j;
    const double *e = phc_trig_asin_table[j];
    const double r = ((y * e[0] - x * (0.0625 * j)) + y * e[1]) * (1.5 - 0.5 * n2);
    const double z = r * r, z2 = z * z, z4 = z2 * z2;
    const double p = ((1.0 / 6 + z * (3.0 / 40)) + z2 * (5.0 / 112 + z * (35.0 / 1152))) +
                     z4 * ((63.0 / 2816 + z * (231.0 / 13312)) + z2 * (143.0 / 10240));
    const double rho = r + r * z * p; /* asin r */
    return flip ? e[4] + (e[5] - rho) : e[2] + (e[3] + rho);
}

/* *s = sin θ, *c = cos θ for θ ∈ [0, π/2] (rad); libm's elsewhere. */
static inline void phc_sincos_first_quadrant(double theta, double *s, double *c)
{
    if (!(theta >= 0 && theta <= PHC_TRIG_PIO2_HI)) {
        *s = sin(theta);
        *c = cos(theta);
        return;
    }
    const int flip = theta > 0x1.921fb54442d18p-1; /* π/4: work on π/2 − θ */
    const double a = flip ? PHC_TRIG_PIO2_HI - theta : theta; /* exact */
    int j = (int)(16.0 * a + 0.5);
    j = j == 1 ? 0 : j; /* a < 3/32 by the series alone */
    double r = a - 0.0625 * j; /* exact, |r| ≤ 3/32 */
    if (flip)
        r += PHC_TRIG_PIO2_LO;
    const double r2 = r * r, r4 = r2 * r2, r8 = r4 * r4;
    const double sr =
        r + r * r2 * ((-1.0 / 6 + r2 * (1.0 / 120)) + r4 * (-1.0 / 5040 + r2 * (1.0 / 362880)));
    const double cm = r2 * ((-0.5 + r2 * (1.0 / 24)) + r4 * (-1.0 / 720 + r2 * (1.0 / 40320)) +
                            r8 * (-1.0 / 3628800)); /* cos r − 1 */
    const double *e = phc_trig_sincos_table[j];
    const double sa = e[0] + (e[1] + (e[0] * cm + e[2] * sr));
    const double ca = e[2] + (e[3] + (e[2] * cm - e[0] * sr));
    *s = flip ? ca : sa;
    *c = flip ? sa : ca;
}

#endif
