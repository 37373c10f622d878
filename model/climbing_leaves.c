/* Leaves of a climbing plant: see model/climbing_leaves.h. */
#include "model/climbing_leaves.h"

#include <math.h>
#include <string.h>

#include "model/quaternion.h"

void phc_climbing_leaf_frame(const double d[3], double e1[3], double e2[3])
{
    double q[4];
    static const double ex[3] = {1, 0, 0}, ey[3] = {0, 1, 0};
    phc_quat_from_z(d, q);
    phc_quat_rotate(q, ex, e1);
    phc_quat_rotate(q, ey, e2);
}

void phc_climbing_leaf_petiole(const double d[3], double m, double alpha, double p[3])
{
    double e1[3], e2[3];
    phc_climbing_leaf_frame(d, e1, e2);
    /* the azimuth reduced to [0, 2π) keeps cos/sin exact for large m */
    const double two_pi = 6.28318530717958647692;
    const double phi = fmod(m * alpha, two_pi);
    const double c = cos(phi), s = sin(phi);
    for (int k = 0; k < 3; ++k)
        p[k] = c * e1[k] + s * e2[k];
}

void phc_climbing_leaf_normal(const double n0[3], const double ell[3], double omega,
                              double light, double max_angle, double n[3])
{
    const double w = omega * light;
    double b[3], l = 0;
    for (int k = 0; k < 3; ++k) {
        b[k] = (1 - w) * n0[k] + w * ell[k];
        l += b[k] * b[k];
    }
    l = sqrt(l);
    if (!(l > 1e-12) || w == 0) {
        memcpy(n, n0, 3 * sizeof *n);
        return;
    }
    for (int k = 0; k < 3; ++k)
        b[k] /= l;
    const double c = b[0] * n0[0] + b[1] * n0[1] + b[2] * n0[2];
    const double angle = acos(fmax(-1, fmin(1, c)));
    if (angle <= max_angle) {
        memcpy(n, b, 3 * sizeof *n);
        return;
    }
    /* clamp: turn n0 by max_angle toward b, in the plane of n0 and b */
    double u[3], lu = 0;
    for (int k = 0; k < 3; ++k) {
        u[k] = b[k] - c * n0[k];
        lu += u[k] * u[k];
    }
    lu = sqrt(lu);
    if (!(lu > 0)) { /* b = −n0: no plane; keep n0 */
        memcpy(n, n0, 3 * sizeof *n);
        return;
    }
    const double cm = cos(max_angle), sm = sin(max_angle);
    for (int k = 0; k < 3; ++k)
        n[k] = cm * n0[k] + sm * u[k] / lu;
}
