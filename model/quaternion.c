/* Unit quaternions: see quaternion.h. */
#include "model/quaternion.h"

#include <math.h>

void phc_quat_mul(const double a[4], const double b[4], double out[4])
{
    const double w = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
    const double x = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
    const double y = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
    const double z = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
    out[0] = w;
    out[1] = x;
    out[2] = y;
    out[3] = z;
}

void phc_quat_conj(const double q[4], double out[4])
{
    out[0] = q[0];
    out[1] = -q[1];
    out[2] = -q[2];
    out[3] = -q[3];
}

void phc_quat_normalize(double q[4])
{
    const double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (n > 0.0 && isfinite(n))
        for (int k = 0; k < 4; ++k)
            q[k] /= n;
}

void phc_quat_to_matrix(const double q[4], double r[9])
{
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    r[0] = 1.0 - 2.0 * (y * y + z * z);
    r[1] = 2.0 * (x * y - w * z);
    r[2] = 2.0 * (x * z + w * y);
    r[3] = 2.0 * (x * y + w * z);
    r[4] = 1.0 - 2.0 * (x * x + z * z);
    r[5] = 2.0 * (y * z - w * x);
    r[6] = 2.0 * (x * z - w * y);
    r[7] = 2.0 * (y * z + w * x);
    r[8] = 1.0 - 2.0 * (x * x + y * y);
}

/* R u = u + 2w (v × u) + 2 v × (v × u), v = Im q. */
void phc_quat_rotate(const double q[4], const double u[3], double out[3])
{
    const double w = q[0], vx = q[1], vy = q[2], vz = q[3];
    const double tx = 2.0 * (vy * u[2] - vz * u[1]);
    const double ty = 2.0 * (vz * u[0] - vx * u[2]);
    const double tz = 2.0 * (vx * u[1] - vy * u[0]);
    const double ox = u[0] + w * tx + (vy * tz - vz * ty);
    const double oy = u[1] + w * ty + (vz * tx - vx * tz);
    const double oz = u[2] + w * tz + (vx * ty - vy * tx);
    out[0] = ox;
    out[1] = oy;
    out[2] = oz;
}

void phc_quat_rotate_inverse(const double q[4], const double u[3], double out[3])
{
    double c[4];
    phc_quat_conj(q, c);
    phc_quat_rotate(c, u, out);
}

void phc_quat_exp(const double v[3], double out[4])
{
    const double a = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    double s;
    /* sin(a/2)/a by its series below 1e-4 (error < 1e-17) */
    if (a < 1e-4)
        s = 0.5 - a * a / 48.0;
    else
        s = sin(0.5 * a) / a;
    out[0] = cos(0.5 * a);
    out[1] = s * v[0];
    out[2] = s * v[1];
    out[3] = s * v[2];
}

void phc_quat_log(const double q[4], double v[3])
{
    double w = q[0], x = q[1], y = q[2], z = q[3];
    if (w < 0.0) {
        w = -w;
        x = -x;
        y = -y;
        z = -z;
    }
    const double s = sqrt(x * x + y * y + z * z);
    /* angle = 2 atan2(s, w); factor angle / s, by its series for small s */
    const double f = (s < 1e-8) ? 2.0 / w : 2.0 * atan2(s, w) / s;
    v[0] = f * x;
    v[1] = f * y;
    v[2] = f * z;
}

void phc_quat_from_two_vectors(const double a[3], const double b[3], double out[4])
{
    const double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                   a[0] * b[1] - a[1] * b[0]};
    if (d < -1.0 + 1e-12) {
        /* antiparallel: half turn about a unit vector perpendicular to a */
        double p[3] = {1.0, 0.0, 0.0};
        if (fabs(a[0]) > 0.9) {
            p[0] = 0.0;
            p[1] = 1.0;
        }
        c[0] = a[1] * p[2] - a[2] * p[1];
        c[1] = a[2] * p[0] - a[0] * p[2];
        c[2] = a[0] * p[1] - a[1] * p[0];
        const double n = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        out[0] = 0.0;
        out[1] = c[0] / n;
        out[2] = c[1] / n;
        out[3] = c[2] / n;
        return;
    }
    /* q = (1 + d, a × b) normalised: half the angle between a and b */
    out[0] = 1.0 + d;
    out[1] = c[0];
    out[2] = c[1];
    out[3] = c[2];
    phc_quat_normalize(out);
}

/* Shepperd's method: the largest of w², x², y², z² is taken from the
 * diagonal, the others from off-diagonal sums (no cancellation). */
void phc_quat_from_matrix(const double R[9], double q[4])
{
    const double t = R[0] + R[4] + R[8];
    if (t >= R[0] && t >= R[4] && t >= R[8]) {
        const double r = sqrt(1 + t), h = 0.5 / r;
        q[0] = 0.5 * r;
        q[1] = (R[7] - R[5]) * h;
        q[2] = (R[2] - R[6]) * h;
        q[3] = (R[3] - R[1]) * h;
    } else if (R[0] >= R[4] && R[0] >= R[8]) {
        const double r = sqrt(1 + R[0] - R[4] - R[8]), h = 0.5 / r;
        q[0] = (R[7] - R[5]) * h;
        q[1] = 0.5 * r;
        q[2] = (R[1] + R[3]) * h;
        q[3] = (R[2] + R[6]) * h;
    } else if (R[4] >= R[8]) {
        const double r = sqrt(1 - R[0] + R[4] - R[8]), h = 0.5 / r;
        q[0] = (R[2] - R[6]) * h;
        q[1] = (R[1] + R[3]) * h;
        q[2] = 0.5 * r;
        q[3] = (R[5] + R[7]) * h;
    } else {
        const double r = sqrt(1 - R[0] - R[4] + R[8]), h = 0.5 / r;
        q[0] = (R[3] - R[1]) * h;
        q[1] = (R[2] + R[6]) * h;
        q[2] = (R[5] + R[7]) * h;
        q[3] = 0.5 * r;
    }
    if (q[0] < 0)
        for (int k = 0; k < 4; ++k)
            q[k] = -q[k];
}

void phc_quat_from_z(const double d[3], double q[4]) { phc_quat_from_z_inline(d, q); }
