/* Unit quaternions for rigid-body orientations (the elastic rods, model/rod.h).
 *
 * A quaternion is double[4] = (w, x, y, z), w the real part.  A unit
 * quaternion q rotates a body-frame vector u to the world frame as
 * R(q)u = Im(q ⊗ (0,u) ⊗ q̄).  Orientation increments are rotation vectors
 * δθ in the WORLD frame (radians), applied on the left: q ← exp(δθ) ⊗ q,
 * with the exact exponential exp(δθ) = (cos(|δθ|/2), sin(|δθ|/2) δθ/|δθ|).
 * Pure C, no I/O. */
#ifndef PHC_QUATERNION_H
#define PHC_QUATERNION_H

#include <math.h>

#ifdef __cplusplus
extern "C" {
#endif

/* out = a ⊗ b (Hamilton product); out may alias a or b. */
void phc_quat_mul(const double a[4], const double b[4], double out[4]);

/* out = q̄ (conjugate: (w, -x, -y, -z)); out may alias q. */
void phc_quat_conj(const double q[4], double out[4]);

/* q / |q|; leaves q unchanged when |q| is 0 or not finite. */
void phc_quat_normalize(double q[4]);

/* out = R(q) u (q unit); out may alias u. */
void phc_quat_rotate(const double q[4], const double u[3], double out[3]);

/* out = R(q)ᵀ u = R(q̄) u (q unit); out may alias u. */
void phc_quat_rotate_inverse(const double q[4], const double u[3], double out[3]);

/* Rotation matrix R(q), row-major 3x3 (q unit). */
void phc_quat_to_matrix(const double q[4], double r[9]);
/* The unit quaternion (w >= 0) of a rotation matrix r (row-major), by
 * Shepperd's method. */
void phc_quat_from_matrix(const double r[9], double q[4]);

/* exp(v) for a rotation vector v in radians: exact, also for |v| -> 0. */
void phc_quat_exp(const double v[3], double out[4]);

/* The rotation vector of a unit quaternion (the inverse of phc_quat_exp on
 * the hemisphere w >= 0; q and -q give the same vector), in radians. */
void phc_quat_log(const double q[4], double v[3]);

/* The minimal rotation (about a × b) taking unit vector a to unit vector b
 * (parallel transport of a frame along a bend).  For antiparallel a, b the
 * axis is any unit vector perpendicular to a. */
void phc_quat_from_two_vectors(const double a[3], const double b[3], double out[4]);
/* The shortest-arc rotation taking the local z axis to the unit direction
 * d (the rest orientation of a particle or segment along d); z to -z turns
 * about x. */
void phc_quat_from_z(const double d[3], double q[4]);
/* phc_quat_from_z for inner loops in other files (the climbing hand-over):
 * the same operations, so the same numbers to the bit, without a call. */
static inline void phc_quat_from_z_inline(const double d[3], double q[4])
{
    if (d[2] < -1 + 1e-12) {
        q[0] = 0;
        q[1] = 1;
        q[2] = q[3] = 0;
        return;
    }
    q[0] = 1 + d[2];
    q[1] = -d[1];
    q[2] = d[0];
    q[3] = 0;
    /* phc_quat_normalize */
    const double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (n > 0.0 && isfinite(n))
        for (int k = 0; k < 4; ++k)
            q[k] /= n;
}

#ifdef __cplusplus
}
#endif

#endif /* PHC_QUATERNION_H */
