/* atan2 and sincos inline, for the climbing plants' turns: the joint
 * pass's partial turn exp(k log δ) (model/particles.c, follow_one) and the
 * tropisms' Rodrigues turn (model/climbing_tropism.c).  Over the ranges
 * they are used on (an angle in (0, π) from y > 0; a turn in [0, π/2])
 * they agree with glibc's atan2, sin and cos to about an ulp (the
 * bounds below; tests/unit/test_trig_inline.c checks them against libm)
 * in some 60 instructions where glibc's atan2 and sincos take some 260;
 * outside those ranges (and for NaN, ±∞, y = 0) they call libm.
 *
 * Both reduce by a table at the nodes j/16 (ours; the tables' identities
 * are the textbook ones, Abramowitz & Stegun 4.4.34 and 4.3.16–17):
 *   atan t = atan(c) + atan(u),  u = (t − c)/(1 + t c),  c = j/16 ∈ [0, 1],
 *   sin(c + r) = sin c + (sin c (cos r − 1) + cos c sin r),
 *   cos(c + r) = cos c + (cos c (cos r − 1) − sin c sin r),
 * |t − c| ≤ 1/32, so |u|, |r| ≤ 1/32, where Taylor series of a few terms
 * are exact to far below an ulp: atan u to u¹¹ (next term ≤ |u|·2⁻⁶⁰/13),
 * sin r to r⁷ (next ≤ |r|·2⁻⁴⁰/9!, about 2⁻⁵⁸ |r|), cos r − 1 to r⁸ (next
 * ≤ 2⁻⁵⁰/10!).  t − c and r = a − c are exact (Sterbenz: c/2 ≤ t ≤ 2c for
 * j ≥ 1), and each table value is a pair hi + lo of doubles (π/2 too), so
 * the error is that of the last few roundings: the sum's 1/2 ulp plus the
 * correction term's roundings, at most about 2⁻⁵³ of the correction (which
 * is at most as large as the result); about one ulp in all, two at worst
 * near the smallest nodes (measured: test_trig_inline).  Above π/4 the
 * sincos works on π/2 − θ = (PIO2_HI − θ) + PIO2_LO (the first difference
 * exact by Sterbenz), so cos θ keeps its relative accuracy up to π/2.
 *
 * The tables (the values at 200 bits, rounded twice to hi and lo) were
 * made with mpmath 1.3.0 by
 *   hilo = lambda v: (float(v), float(v - mp.mpf(float(v))))
 *   atan table: hilo(mp.atan(j/16)), hilo(π/2 − atan), hilo(π − atan),
 *               hilo(π/2 + atan) for j = 0 .. 16 (mp.mpf(j)/16)
 *   sincos table: hilo(mp.sin(j/16)), hilo(mp.cos(j/16)), j = 0 .. 13
 * Pure C, no I/O; header only, so that the callers inline it. */
#ifndef PHC_TRIG_INLINE_H
#define PHC_TRIG_INLINE_H

#include <float.h>
#include <math.h>

static const double phc_trig_atan_table[4][17][2] = {
    { /* atan(j/16) */
     {0.0, 0.0},
     {0x1.ff55bb72cfdeap-5, -0x1.c934d86d23f1dp-60},
     {0x1.fd5ba9aac2f6ep-4, -0x1.cd37686760c17p-59},
     {0x1.7b97b4bce5b02p-3, 0x1.347b0b4f881cap-58},
     {0x1.f5b75f92c80ddp-3, 0x1.8ab6e3cf7afbdp-57},
     {0x1.362773707ebccp-2, -0x1.963a544b672d8p-57},
     {0x1.6f61941e4def1p-2, -0x1.c63aae6f6e918p-56},
     {0x1.a64eec3cc23fdp-2, -0x1.24dec1b50b7ffp-56},
     {0x1.dac670561bb4fp-2, 0x1.a2b7f222f65e2p-56},
     {0x1.0657e94db30d0p-1, -0x1.d5b495f6349e6p-56},
     {0x1.1e00babdefeb4p-1, -0x1.928df287a668fp-58},
     {0x1.345f01cce37bbp-1, 0x1.1021137c71102p-55},
     {0x1.4978fa3269ee1p-1, 0x1.2419a87f2a458p-56},
     {0x1.5d58987169b18p-1, 0x1.0028e4bc5e7cap-57},
     {0x1.700a7c5784634p-1, -0x1.8c34d25aadef6p-56},
     {0x1.819d0b7158a4dp-1, -0x1.bf76229d3b917p-56},
     {0x1.921fb54442d18p-1, 0x1.1a62633145c07p-55},
    },
    { /* pi/2 - atan(j/16) */
     {0x1.921fb54442d18p+0, 0x1.1a62633145c07p-54},
     {0x1.82250768ac529p+0, -0x1.e78c96d05afcbp-58},
     {0x1.7249faa996a21p+0, 0x1.a8cc1e7480c68p-54},
     {0x1.62acbeaca61b8p+0, 0x1.c6ac9f134fa91p-60},
     {0x1.5368c951e9cfdp+0, -0x1.96f47948a99f1p-54},
     {0x1.4495d86823225p+0, 0x1.4d29adbab2a62p-54},
     {0x1.3647503caf55cp+0, 0x1.17e21d9a42c9ap-55},
     {0x1.288bfa3512419p+0, 0x1.8e684e7a2281bp-56},
     {0x1.1b6e192ebbe44p+0, 0x1.b1b466a88828ep-54},
     {0x1.0ef3c09d694b0p+0, 0x1.8fcf88aed2e80p-54},
     {0x1.031f57e54adbep+0, 0x1.338b4259c0270p-54},
     {0x1.efe068bba2275p-1, 0x1.24a3b2e61a70bp-55},
     {0x1.dac670561bb4fp-1, 0x1.a2b7f222f65e2p-55},
     {0x1.c6e6d2171bf18p-1, 0x1.f4ba8d3373e1bp-55},
     {0x1.b434ee31013fdp-1, -0x1.0520d0701d877p-55},
     {0x1.a2a25f172cfe4p-1, -0x1.d700509dad6cep-56},
     {0x1.921fb54442d18p-1, 0x1.1a62633145c07p-55},
    },
    { /* pi - atan(j/16) */
     {0x1.921fb54442d18p+1, 0x1.1a62633145c07p-53},
     {0x1.8a225e5677921p+1, -0x1.820b331ddff7bp-53},
     {0x1.8234d7f6ecb9dp+1, -0x1.3cd17e5a39792p-54},
     {0x1.7a6639f874768p+1, 0x1.217d15ad92ff1p-54},
     {0x1.72c43f4b1650ap+1, 0x1.c1b6f4f44e10bp-53},
     {0x1.6b5ac6d632f9fp+1, -0x1.9873ef1407997p-54},
     {0x1.643382c07913ap+1, 0x1.a65371fe67254p-54},
     {0x1.5d55d7bcaa899p+1, -0x1.4101c49818cf9p-53},
     {0x1.56c6e7397f5aep+1, 0x1.660b64ece6f4bp-53},
     {0x1.5089baf0d60e4p+1, 0x1.5518f5f00c544p-53},
     {0x1.4a9f8694c6d6bp+1, 0x1.26f6d2c582f3bp-53},
     {0x1.4507f4d109f29p+1, 0x1.d65a1e52297c6p-53},
     {0x1.3fc176b7a8560p+1, -0x1.441a3bd3f1083p-58},
     {0x1.3ac98f27e8652p+1, 0x1.0a5fd4e57fd8ap-53},
     {0x1.361d162e61b8bp+1, 0x1.4be8fd7c9b7e6p-53},
     {0x1.31b87267eca85p+1, 0x1.49449e13b4ca7p-55},
     {0x1.2d97c7f3321d2p+1, 0x1.a79394c9e8a0ap-54},
    },
    { /* pi/2 + atan(j/16) */
     {0x1.921fb54442d18p+0, 0x1.1a62633145c07p-54},
     {0x1.a21a631fd9508p+0, -0x1.acc270306ecf6p-54},
     {0x1.b1f56fdeef00fp+0, 0x1.17f14fdc1574cp-55},
     {0x1.c192abdbdf879p+0, -0x1.d255ec19c1bddp-54},
     {0x1.d0d6a1369bd34p+0, -0x1.a23602a65700cp-57},
     {0x1.dfa992206280bp+0, 0x1.cf36314fb1b58p-55},
     {0x1.edf81a4bd64d4p+0, 0x1.a8d3b7956a1c1p-54},
     {0x1.fbb3705373617p+0, 0x1.d12ab2c402e07p-54},
     {0x1.0468a8ace4df6p+1, 0x1.0620bf7406affp-55},
     {0x1.0aa5d4f58e2c0p+1, 0x1.49ea7b677131bp-55},
     {0x1.109009519d639p+1, 0x1.01398408cb59ep-54},
     {0x1.16279b155a47bp+1, -0x1.76344c4206ddfp-56},
     {0x1.1b6e192ebbe44p+1, 0x1.b1b466a88828ep-53},
     {0x1.206600be7bd52p+1, 0x1.3a677fc8d1900p-54},
     {0x1.251279b802819p+1, 0x1.6eaa5d3534893p-55},
     {0x1.29771d7e7791fp+1, 0x1.55426d44fb6e1p-53},
     {0x1.2d97c7f3321d2p+1, 0x1.a79394c9e8a0ap-54},
    },
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


/* atan2(y, x) ∈ (0, π) for y > 0 (rad); libm's atan2 for y ≤ 0 (glibc
 * returns at once for y = 0), NaN, ±∞ or y + |x| > DBL_MAX. */
static inline double phc_atan2_upper(double y, double x)
{
    const double ax = fabs(x);
    if (!(y > 0 && y + ax <= DBL_MAX)) /* also NaN, ±∞ and y = ±0 */
        return atan2(y, x);
    const int swap = y > ax; /* then atan2 = π/2 ∓ atan(|x|/y) */
    const double t = swap ? ax / y : y / ax; /* in [0, 1] */
    int j = (int)(16.0 * t + 0.5);
    j = j == 1 ? 0 : j; /* t < 3/32 by the series alone (u = t exactly) */
    const double c = 0.0625 * j;
    const double u = (t - c) / (1.0 + t * c), u2 = u * u;
    const double p =
        u + u * u2 * (-1.0 / 3 +
                      u2 * (1.0 / 5 +
                            u2 * (-1.0 / 7 +
                                  u2 * (1.0 / 9 +
                                        u2 * (-1.0 / 11 + u2 * (1.0 / 13 + u2 * (-1.0 / 15 + u2 * (1.0 / 17))))))));
    /* quadrant: 0 atan t, 1 π/2 − atan t, 2 π − atan t, 3 π/2 + atan t */
    const int k = (x < 0) * 2 + swap;
    const double *e = phc_trig_atan_table[k][j];
    return e[0] + (e[1] + ((k == 1 || k == 2) ? -p : p));
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
    const double r2 = r * r;
    const double sr = r + r * r2 * (-1.0 / 6 + r2 * (1.0 / 120 + r2 * (-1.0 / 5040 + r2 * (1.0 / 362880))));
    const double cm =
        r2 * (-0.5 + r2 * (1.0 / 24 + r2 * (-1.0 / 720 + r2 * (1.0 / 40320 + r2 * (-1.0 / 3628800)))));
    const double *e = phc_trig_sincos_table[j];
    const double sa = e[0] + (e[1] + (e[0] * cm + e[2] * sr));
    const double ca = e[2] + (e[3] + (e[2] * cm - e[0] * sr));
    *s = flip ? ca : sa;
    *c = flip ? sa : ca;
}

#endif
