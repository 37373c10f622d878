/* Unit test of the inline angle and sincos of the joint pass
 * (model/trig_inline.h) against glibc's atan2, sin and cos.
 *  1. phc_angle_unit(c, s) for 2,000,000 pseudo-random angles φ in
 *     [0, π/2] (half of them below 0.2 rad), (c, s) = (cos φ, sin φ) from
 *     libm, and for the points within 4 ulps of every table boundary
 *     s = (2j + 1)/32 (and c = (2j + 1)/32 above π/4) and of φ = π/4:
 *     within 2 ulps of libm's atan2(s, c) (the header measured 1.64 ulps
 *     at most of the exact angle; glibc's own error is below 0.52 ulp).  The same vectors
 *     scaled by 1 ± 1e-10 (not unit: the correction by 1/|(c, s)|) within
 *     2 ulps too.  The largest errors are printed.
 *  2. phc_sincos_first_quadrant(θ) for 2,000,000 angles in [0, π/2] (half
 *     below 0.1 rad) and within 4 ulps of every boundary (2j + 1)/32, of
 *     π/4 and of π/2: sine and cosine within 2 ulps of libm's, each.
 *  3. Limits, exactly: the angle of (1, 0) is 0, of (0, 1) π/2 (the double
 *     nearest); sin 0 = 0, cos 0 = 1.
 *  4. Outside the ranges libm's result bit for bit: c or s < 0, NaN, ±∞,
 *     |(c, s)|² − 1 beyond 1e-9 (0.5, 2, 1 + 1e-8), (0, 0); θ < 0,
 *     θ > π/2, NaN, ∞. */
#include "model/trig_inline.h"

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

static double worst_atan = 0, worst_scaled = 0, worst_sin = 0, worst_cos = 0;
static double worst_atan_at, worst_sin_at, worst_cos_at;

static void try_angle(double c, double s)
{
    const double ref = atan2(s, c);
    const double e = ulps(phc_angle_unit(c, s), ref);
    if (e > worst_atan) {
        worst_atan = e;
        worst_atan_at = ref;
    }
    for (int k = -1; k <= 1; k += 2) {
        const double f = 1 + k * 1e-10;
        const double es = ulps(phc_angle_unit(f * c, f * s), atan2(f * s, f * c));
        if (es > worst_scaled)
            worst_scaled = es;
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

    /* 1. the angle of a unit vector */
    for (int n = 0; n < 2000000; ++n) {
        const double phi = n % 2 ? pio2 * uniform() : 0.2 * uniform();
        try_angle(cos(phi), sin(phi));
    }
    for (int j = 0; j <= 11; ++j) {
        double y = (2 * j + 1) / 32.0;
        for (int k = 0; k < 4; ++k)
            y = nextafter(y, 0);
        for (int k = 0; k < 9; ++k, y = nextafter(y, 2)) {
            const double x = sqrt(1 - y * y);
            try_angle(x, y); /* s at the boundary */
            try_angle(y, x); /* c at the boundary, φ > π/4 */
        }
    }
    for (int k = -4; k <= 4; ++k) {
        const double phi = 0.25 * pi + k * 0x1.0p-53;
        try_angle(cos(phi), sin(phi));
    }
    printf("angle: worst %.3f ulps of libm's atan2 (at %.17g rad); scaled by 1 +- 1e-10: %.3f ulps\n",
           worst_atan, worst_atan_at, worst_scaled);
    CHECK(worst_atan <= 2.0);
    CHECK(worst_scaled <= 2.0);

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
    CHECK(phc_angle_unit(1.0, 0.0) == 0.0);
    CHECK(phc_angle_unit(0.0, 1.0) == atan2(1.0, 0.0));
    double s, c;
    phc_sincos_first_quadrant(0.0, &s, &c);
    CHECK(same_bits(s, 0.0) && c == 1.0);

    /* 4. libm outside the ranges */
    const double cs[][2] = {{-0.6, 0.8}, {0.6, -0.8}, {NAN, 1.0}, {1.0, NAN}, {INFINITY, 0.0},
                            {0.5, 0.0},  {2.0, 0.0},  {0.0, 1.0 + 1e-8}, {0.0, 0.0}, {-0.0, 1.0}};
    int libm_same = 1;
    for (size_t a = 0; a < sizeof cs / sizeof cs[0]; ++a) {
        const double f = phc_angle_unit(cs[a][0], cs[a][1]), l = atan2(cs[a][1], cs[a][0]);
        if (!(same_bits(f, l) || (isnan(f) && isnan(l)))) {
            libm_same = 0;
            fprintf(stderr, "angle(%g, %g): %.17g, libm %.17g\n", cs[a][0], cs[a][1], f, l);
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
