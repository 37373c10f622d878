/* Unit test of the inline atan2 and sincos of the climbing plants' turns
 * (model/trig_inline.h) against glibc's atan2, sin and cos.
 *  1. phc_atan2_upper(y, x) for 2,000,000 pseudo-random angles in [0, π]
 *     (half of them below 0.2 rad, where the joint pass's small turns
 *     lie), radii 10⁻³–10³, and for the points within 4 ulps of every
 *     table boundary t = (2j + 1)/32, of t = 1 and of x = 0: within 2
 *     ulps of libm (the header's bound is about 1.5 ulps of the exact
 *     angle, measured 1.43 against mpmath at 120 bits; glibc's own error
 *     is below 0.52 ulp).  The largest error is printed.
 *  2. phc_sincos_first_quadrant(θ) for 2,000,000 angles in [0, π/2] (half
 *     below 0.1 rad) and within 4 ulps of every boundary (2j + 1)/32, of
 *     π/4 and of π/2: sine and cosine within 2 ulps of libm's, each (the
 *     header's bound about 1.1 ulps, measured against mpmath).
 *  3. Limits, exactly: atan2(y > 0, ±0) = π/2 (the double nearest),
 *     atan2(y, y) = π/4 (nearest), atan2(±0, x) libm's; sin 0 = 0,
 *     cos 0 = 1.
 *  4. Outside the ranges libm's result bit for bit: y ≤ 0 (±0 too),
 *     NaN, ±∞, y + |x| > DBL_MAX; θ < 0, θ > π/2, NaN, ∞. */
#include "model/trig_inline.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "check.h"

/* |a − b| in ulps of b (b ≠ 0: the spacing of doubles at |b|) */
static double ulps(double a, double b)
{
    const double ab = fabs(b);
    const double u = nextafter(ab, INFINITY) - ab;
    return fabs(a - b) / u;
}

static uint64_t state = 0x9e3779b97f4a7c15ull;
static double uniform(void) /* [0, 1) */
{
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(state >> 11) * 0x1.0p-53;
}

static int same_bits(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

static double worst_atan = 0, worst_sin = 0, worst_cos = 0;
static double worst_atan_at[2], worst_sin_at, worst_cos_at;

static void try_atan(double y, double x)
{
    const double e = ulps(phc_atan2_upper(y, x), atan2(y, x));
    if (e > worst_atan) {
        worst_atan = e;
        worst_atan_at[0] = y;
        worst_atan_at[1] = x;
    }
}

static void try_sincos(double t)
{
    double s, c;
    phc_sincos_first_quadrant(t, &s, &c);
    const double es = t > 0 ? ulps(s, sin(t)) : fabs(s), ec = ulps(c, cos(t));
    if (es > worst_sin) {
        worst_sin = es;
        worst_sin_at = t;
    }
    if (ec > worst_cos) {
        worst_cos = ec;
        worst_cos_at = t;
    }
}

int main(void)
{
    const double pi = 3.14159265358979323846, pio2 = 0.5 * pi;

    /* 1. atan2 */
    for (int n = 0; n < 2000000; ++n) {
        const double phi = n % 2 ? pi * uniform() : 0.2 * uniform();
        const double r = pow(10.0, 6 * uniform() - 3);
        try_atan(r * sin(phi), r * cos(phi));
    }
    for (int j = 0; j <= 16; ++j) {
        const double t0 = (2 * j + 1) / 32.0;
        double t = t0;
        for (int k = 0; k < 4; ++k)
            t = nextafter(t, 0);
        for (int k = 0; k < 9; ++k, t = nextafter(t, 2)) {
            if (t > 1)
                break;
            for (int sx = -1; sx <= 1; sx += 2) {
                try_atan(t, sx * 1.0);   /* y/x = t */
                try_atan(1.0, sx * t);   /* |x|/y = t */
                try_atan(3.7 * t, sx * 3.7);
            }
        }
    }
    for (int k = -4; k <= 4; ++k) {
        const double x = k * 0x1.0p-1074 * 1e3;
        try_atan(1.0, x);
        try_atan(1.0, 1.0 + k * 0x1.0p-52);
    }
    printf("atan2: worst %.3f ulps of libm's, at y = %.17g, x = %.17g\n", worst_atan, worst_atan_at[0],
           worst_atan_at[1]);
    CHECK(worst_atan <= 2.0);

    /* 2. sincos */
    for (int n = 0; n < 2000000; ++n)
        try_sincos(n % 2 ? pio2 * uniform() : 0.1 * uniform());
    double marks[32];
    int nm = 0;
    for (int j = 0; j <= 24; ++j)
        if ((2 * j + 1) / 32.0 < pio2)
            marks[nm++] = (2 * j + 1) / 32.0;
    marks[nm++] = 0.25 * pi;
    marks[nm++] = 0.5 * pi;
    for (int m = 0; m < nm; ++m) {
        double t = marks[m];
        for (int k = 0; k < 4; ++k)
            t = nextafter(t, 0);
        for (int k = 0; k < 9; ++k, t = nextafter(t, 2))
            try_sincos(t);
    }
    /* π/2 − θ just below the table boundaries above π/4 */
    for (int j = 0; j <= 12; ++j) {
        double t = pio2 - (2 * j + 1) / 32.0;
        for (int k = 0; k < 4; ++k)
            t = nextafter(t, 0);
        for (int k = 0; k < 9; ++k, t = nextafter(t, 2))
            try_sincos(t);
    }
    printf("sincos: worst %.3f ulps of libm's sine (at %.17g), %.3f of its cosine (at %.17g)\n",
           worst_sin, worst_sin_at, worst_cos, worst_cos_at);
    CHECK(worst_sin <= 2.0);
    CHECK(worst_cos <= 2.0);

    /* 3. limits */
    CHECK(same_bits(phc_atan2_upper(0.0, 2.5), 0.0));
    CHECK(same_bits(phc_atan2_upper(-0.0, -2.5), atan2(-0.0, -2.5)));
    CHECK(phc_atan2_upper(1.5, 0.0) == atan2(1.5, 0.0));
    CHECK(phc_atan2_upper(1.5, -0.0) == atan2(1.5, -0.0));
    CHECK(phc_atan2_upper(0.3, 0.3) == atan2(1.0, 1.0));
    CHECK(phc_atan2_upper(0.0, -2.0) == atan2(0.0, -2.0));
    double s, c;
    phc_sincos_first_quadrant(0.0, &s, &c);
    CHECK(same_bits(s, 0.0) && c == 1.0);

    /* 4. libm outside the ranges */
    const double ys[] = {-1.0, -0.0, 0.0, NAN, INFINITY, DBL_MAX};
    const double xs[] = {1.0, -1.0, 0.0, -0.0, NAN, INFINITY, -INFINITY, -DBL_MAX};
    int libm_same = 1;
    for (size_t a = 0; a < sizeof ys / sizeof ys[0]; ++a)
        for (size_t b = 0; b < sizeof xs / sizeof xs[0]; ++b) {
            const double y = ys[a], x = xs[b];
            if (y == DBL_MAX && fabs(x) <= 1)
                continue; /* in range */
            const double f = phc_atan2_upper(y, x), l = atan2(y, x);
            if (!(same_bits(f, l) || (isnan(f) && isnan(l)))) {
                libm_same = 0;
                fprintf(stderr, "atan2(%g, %g): %.17g, libm %.17g\n", y, x, f, l);
            }
        }
    const double ts[] = {-1e-300, -0.5, 1.5707963267948968, 2.0, 100.0, NAN, INFINITY};
    for (size_t a = 0; a < sizeof ts / sizeof ts[0]; ++a) {
        phc_sincos_first_quadrant(ts[a], &s, &c);
        const double ls = sin(ts[a]), lc = cos(ts[a]);
        if (!((same_bits(s, ls) || (isnan(s) && isnan(ls))) && (same_bits(c, lc) || (isnan(c) && isnan(lc))))) {
            libm_same = 0;
            fprintf(stderr, "sincos(%g): %.17g %.17g, libm %.17g %.17g\n", ts[a], s, c, ls, lc);
        }
    }
    CHECK(libm_same);
    return check_finish("test_trig_inline");
}
