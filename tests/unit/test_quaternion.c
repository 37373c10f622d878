/* model/quaternion: the rest orientation phc_quat_from_z (shared by the
 * oriented particles and the climbing plants) takes z onto its direction,
 * including the near-antiparallel case, and is a unit quaternion; the
 * shortest arc leaves the axis z x d fixed. */
#include <math.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include <stdio.h>

#include "model/quaternion.h"
#include "tests/check.h"

int main(void)
{
    const double z[3] = {0, 0, 1};
    double worst = 0, worst_norm = 0, worst_axis = 0;
    int n = 0;
    for (int a = 0; a <= 24; ++a)
        for (int b = 0; b < 24; ++b) {
            /* polar angle up to pi (exactly -z at a = 24), plus one just short of it */
            const double th = a == 24 ? (b % 2 ? M_PI - 1e-9 : M_PI) : M_PI * a / 24.0, ph = 2 * M_PI * b / 24.0;
            const double d[3] = {sin(th) * cos(ph), sin(th) * sin(ph), cos(th)};
            double q[4], r[3];
            phc_quat_from_z(d, q);
            phc_quat_rotate(q, z, r);
            for (int k = 0; k < 3; ++k)
                worst = fmax(worst, fabs(r[k] - d[k]));
            worst_norm = fmax(worst_norm, fabs(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] - 1));
            /* the rotation axis z x d (when defined) is left where it is */
            const double ax[3] = {-d[1], d[0], 0};
            const double l = hypot(ax[0], ax[1]);
            if (l > 1e-6) {
                double ra[3];
                phc_quat_rotate(q, ax, ra);
                for (int k = 0; k < 3; ++k)
                    worst_axis = fmax(worst_axis, fabs(ra[k] - ax[k]) / l);
            }
            ++n;
        }
    printf("phc_quat_from_z over %d directions: |R z - d| <= %.3g, | |q| - 1 | <= %.3g, axis moved <= %.3g\n", n,
           worst, worst_norm, worst_axis);
    CHECK(worst < 1e-8); /* the direction 1e-9 short of -z: q0 = 1 + cos(th) loses digits */
    CHECK(worst_norm < 1e-14);
    CHECK(worst_axis < 1e-12);
    double q[4], r[3];
    phc_quat_from_z(z, q); /* z itself: the identity */
    CHECK(q[0] == 1 && q[1] == 0 && q[2] == 0 && q[3] == 0);
    const double mz[3] = {0, 0, -1};
    phc_quat_from_z(mz, q);
    phc_quat_rotate(q, z, r);
    CHECK_NEAR(r[2], -1, 1e-15, 0);
    return check_finish("test_quaternion");
}
