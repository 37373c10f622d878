/* The own-weight joint pass on four independent links at once: follow_one
 * of model/particles.c (the equations, with their sources, are there and
 * in particles.h, "Shoots that bend"), lane by lane with the same
 * operations in the same order, so that each lane gives follow_one's bits
 * (x86-64 has no fused multiply-add without -march flags, so nothing is
 * contracted).  The inline trig is model/trig_inline.h's, its table
 * lookups made per lane.  Pure C, no I/O. */
#include "model/particles_joint_lanes.h"

#include <math.h>

#include "model/trig_inline.h"

/* (the helpers below pass vectors by value and are all inlined here: the
   ABI note GCC gives for that without AVX concerns no call; CMakeLists.txt
   silences it with -Wno-psabi, which a pragma cannot) */

typedef phc_v4d v4d;
typedef long v4l __attribute__((vector_size(32))); /* a comparison's lanes: 0 or −1 */

enum { LANES = 4 };

/* Lane by lane: a where m, else b. */
static inline v4d pick(v4l m, v4d a, v4d b) { return (v4d)((m & (v4l)a) | (~m & (v4l)b)); }

static inline v4d splat(double a) { return (v4d){a, a, a, a}; }

/* sqrt lane by lane (correctly rounded, as the scalar one) */
static inline v4d sqrt4(v4d a)
{
    v4d r;
    for (int l = 0; l < LANES; ++l)
        r[l] = sqrt(a[l]);
    return r;
}

/* rotate and rotate_z of model/particles.c: R(q) u = u + 2w (v × u) +
 * 2 v × (v × u), v = Im q, and R(q)(0, 0, h). */
static inline void rotate4(const v4d q[4], const v4d u[3], v4d out[3])
{
    const v4d w = q[0], vx = q[1], vy = q[2], vz = q[3];
    const v4d tx = 2.0 * (vy * u[2] - vz * u[1]);
    const v4d ty = 2.0 * (vz * u[0] - vx * u[2]);
    const v4d tz = 2.0 * (vx * u[1] - vy * u[0]);
    out[0] = u[0] + w * tx + (vy * tz - vz * ty);
    out[1] = u[1] + w * ty + (vz * tx - vx * tz);
    out[2] = u[2] + w * tz + (vx * ty - vy * tx);
}

static inline void rotate_z4(const v4d q[4], v4d h, v4d out[3])
{
    const v4d w = q[0], vx = q[1], vy = q[2], vz = q[3];
    const v4d tx = 2.0 * (vy * h), ty = 2.0 * -(vx * h);
    out[0] = w * tx - vz * ty;
    out[1] = w * ty + vz * tx;
    out[2] = h + (vx * ty - vy * tx);
}

/* quat_mul of model/particles.c: c = a b (Hamilton product). */
static inline void quat_mul4(const v4d a[4], const v4d b[4], v4d c[4])
{
    const v4d w = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
    const v4d x = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
    const v4d y = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
    const v4d z = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
    c[0] = w;
    c[1] = x;
    c[2] = y;
    c[3] = z;
}

/* phc_angle_unit (model/trig_inline.h) lane by lane: φ of (c, s) =
 * (cos φ, sin φ); *ok clears the lanes where it would call atan2. */
static inline v4d angle_unit4(v4d c, v4d s, v4l *ok)
{
    const v4d n2 = c * c + s * s, e1 = n2 - 1;
    *ok &= (c >= 0) & (s >= 0) & (e1 <= 1e-9) & (e1 >= -1e-9);
    const v4l flip = s > c; /* φ > π/4: π/2 − the angle of (s, c) */
    const v4d y = pick(flip, c, s), x = pick(flip, s, c);
    v4d e[6], jd;
    for (int l = 0; l < LANES; ++l) {
        int j = (*ok)[l] ? (int)(16.0 * y[l] + 0.5) : 0;
        j = j == 1 ? 0 : j;
        for (int m = 0; m < 6; ++m)
            e[m][l] = phc_trig_asin_table[j][m];
        jd[l] = 0.0625 * j;
    }
    const v4d r = ((y * e[0] - x * jd) + y * e[1]) * (1.5 - 0.5 * n2);
    const v4d z = r * r, z2 = z * z, z4 = z2 * z2;
    const v4d p = ((1.0 / 6 + z * (3.0 / 40)) + z2 * (5.0 / 112 + z * (35.0 / 1152))) +
                  z4 * ((63.0 / 2816 + z * (231.0 / 13312)) + z2 * (143.0 / 10240));
    const v4d rho = r + r * z * p; /* asin r */
    return pick(flip, e[4] + (e[5] - rho), e[2] + (e[3] + rho));
}

/* phc_sincos_first_quadrant (model/trig_inline.h) lane by lane: sin θ,
 * cos θ; *ok clears the lanes where it would call libm. */
static inline void sincos4(v4d theta, v4d *s, v4d *c, v4l *ok)
{
    *ok &= (theta >= 0) & (theta <= PHC_TRIG_PIO2_HI);
    const v4l flip = theta > 0x1.921fb54442d18p-1; /* π/4: work on π/2 − θ */
    const v4d a = pick(flip, PHC_TRIG_PIO2_HI - theta, theta); /* exact */
    v4d e[4], jd;
    for (int l = 0; l < LANES; ++l) {
        int j = (*ok)[l] ? (int)(16.0 * a[l] + 0.5) : 0;
        j = j == 1 ? 0 : j; /* a < 3/32 by the series alone */
        for (int m = 0; m < 4; ++m)
            e[m][l] = phc_trig_sincos_table[j][m];
        jd[l] = 0.0625 * j;
    }
    v4d r = a - jd; /* exact, |r| ≤ 3/32 */
    r = pick(flip, r + PHC_TRIG_PIO2_LO, r);
    const v4d r2 = r * r, r4 = r2 * r2, r8 = r4 * r4;
    const v4d sr =
        r + r * r2 * ((-1.0 / 6 + r2 * (1.0 / 120)) + r4 * (-1.0 / 5040 + r2 * (1.0 / 362880)));
    const v4d cm = r2 * ((-0.5 + r2 * (1.0 / 24)) + r4 * (-1.0 / 720 + r2 * (1.0 / 40320)) +
                         r8 * (-1.0 / 3628800)); /* cos r − 1 */
    const v4d sa = e[0] + (e[1] + (e[0] * cm + e[2] * sr));
    const v4d ca = e[2] + (e[3] + (e[2] * cm - e[0] * sr));
    *s = pick(flip, ca, sa);
    *c = pick(flip, sa, ca);
}

int phc_joint_lanes(const phc_joint_lanes_in *in, double dt2, phc_joint_lanes_out *out)
{
    v4l ok = {-1, -1, -1, -1};
    /* the joint J = x_u + R(q_u) j_i in u's current frame */
    v4d J[3];
    rotate4(in->qu, in->ju, J);
    for (int d = 0; d < 3; ++d)
        J[d] += in->xu[d];
    /* the rest turn q* = q_u q̄_u⁻¹ q̄_i */
    v4d qs[4];
    quat_mul4(in->qu, in->rel, qs);
    /* k = 1: held at the rest angle, q = q* / |q*| */
    const v4l held = in->k >= 1;
    const v4d rh = 1.0 / sqrt4(qs[0] * qs[0] + qs[1] * qs[1] + qs[2] * qs[2] + qs[3] * qs[3]);
    /* the free turn q_f: the shortest turn from the axis e = R(q_i) ẑ to
     * d = (L/2) e + a Δt², as (|d| + e·d, e × d)/sqrt(2|d|(|d| + e·d)),
     * then applied to q_i */
    v4d axis[3], dir[3], dq[4], qf[4];
    rotate_z4(in->qt, splat(1.0), axis);
    for (int d = 0; d < 3; ++d)
        dir[d] = in->half * axis[d] + dt2 * in->acc[d];
    const v4d dn2 = dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2];
    ok &= dn2 > 0; /* (no load direction: q_f = q_i, in follow_one) */
    const v4d dn = sqrt4(dn2);
    const v4d cd = axis[0] * dir[0] + axis[1] * dir[1] + axis[2] * dir[2];
    ok &= ~(cd < (-1.0 + 1e-12) * dn); /* (a half turn: phc_quat_from_two_vectors) */
    const v4d wd = dn + cd, inv = 1.0 / sqrt4(2.0 * dn * wd);
    dq[0] = wd * inv;
    dq[1] = (axis[1] * dir[2] - axis[2] * dir[1]) * inv;
    dq[2] = (axis[2] * dir[0] - axis[0] * dir[2]) * inv;
    dq[3] = (axis[0] * dir[1] - axis[1] * dir[0]) * inv;
    quat_mul4(dq, in->qt, qf);
    /* the joint's spring, exp(k log(q* q_f⁻¹)) q_f as the slerp from q_f
     * to q* (follow_one): cos φ = q*·q_f (q* as −q* when negative),
     * q = (cos kφ − cos φ f) q_f + f q*, f = sin kφ / sin φ,
     * sin φ = |q* − cos φ q_f| */
    v4d c = qs[0] * qf[0] + qs[1] * qf[1] + qs[2] * qf[2] + qs[3] * qf[3];
    const v4d sg = pick(c < 0, splat(-1.0), splat(1.0));
    c *= sg;
    v4d qn[4], w2 = splat(0.0);
    for (int d = 0; d < 4; ++d) {
        qn[d] = sg * qs[d];
        const v4d w = qn[d] - c * qf[d];
        w2 += w * w;
    }
    const v4d sn = sqrt4(w2);
    ok &= sn > 1e-8; /* (below: the limit k/cos φ, in follow_one) */
    const v4d isn = 1.0 / sn;
    const v4d phi = angle_unit4(c, sn, &ok);
    v4d sk, ck;
    sincos4(in->k * phi, &sk, &ck, &ok);
    const v4d fac = sk * isn, a = ck - c * fac;
    v4d q[4];
    for (int d = 0; d < 4; ++d)
        q[d] = a * qf[d] + fac * qn[d];
    /* normalised by 1/|q| = (3 − |q|²)/2 (|q|² = 1 to 1e-8, else follow_one's 1/sqrt) */
    const v4d n2 = (q[0] * q[0] + q[1] * q[1]) + (q[2] * q[2] + q[3] * q[3]), e2 = n2 - 1;
    ok &= (e2 <= 1e-8) & (e2 >= -1e-8);
    const v4d rn = 1.5 - 0.5 * n2;
    for (int d = 0; d < 4; ++d)
        q[d] = pick(held, qs[d] * rh, q[d] * rn);
    ok |= held; /* (the held lanes take none of the free turn's paths) */
    /* the centre x_i = J + R(q_i)(0, 0, L_i/2) */
    v4d hr[3];
    rotate_z4(q, in->half, hr);
    for (int d = 0; d < 4; ++d)
        out->q[d] = q[d];
    for (int d = 0; d < 3; ++d)
        out->x[d] = J[d] + hr[d];
    int placed = 0;
    for (int l = 0; l < LANES; ++l)
        placed |= ok[l] ? 1 << l : 0;
    return placed;
}
