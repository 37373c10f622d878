/* One joint of the elastic rods (model/rod.h): the zero-stretch and the
 * bend–twist constraint between a parent segment p and a child segment c,
 * with their first and second derivatives.
 *
 * Deul, Kugelstadt, Weiler, Bender 2018, "Direct position-based solver for
 * stiff rods" (Comput. Graph. Forum 37(6)), §3:
 *   zero stretch (eq. 5):  C_s = x_p + R_p a − x_c − R_c b            (m, 3 rows)
 *   bend–twist  (eq. 7):   C_b = Ω − Ω0,  Ω = (2/ℓ) Im(q̄_p ⊗ q_c)      (1/m, 3 rows)
 * a: the attachment point in p's body frame (m), b: in c's body frame (m),
 * ℓ: the joint's rest length (m, the mean of the two segment lengths), Ω is
 * the discrete Darboux vector in p's frame.  q and -q are one rotation: the
 * relative quaternion q̄_p ⊗ q_c is taken on the hemisphere w >= 0.
 *
 * Derivatives are with respect to z = (Δx, δθ) of each body: Δx the centre
 * displacement (m), δθ a world-frame rotation vector (rad) applied as
 * q ← exp(δθ) ⊗ q (model/quaternion.h).  Matrices are row-major.
 *   ∂C_s/∂z_p = [ I  −[R_p a]× ],   ∂C_s/∂z_c = [ −I  [R_c b]× ]
 *   ∂Ω/∂δθ_c = (2/ℓ) G,  ∂Ω/∂δθ_p = −(2/ℓ) G,  G = ½ (w I − [r]×) R_pᵀ
 * where (w, r) = q̄_p ⊗ q_c.  The Hessian of λ·C (the geometric stiffness of
 * the Newton solver) is exact to second order in (δθ_p, δθ_c); its derivation
 * is in rod_joint.c.  Pure C, no I/O. */
#ifndef PHC_ROD_JOINT_H
#define PHC_ROD_JOINT_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct phc_rod_joint_geometry {
    double a[3];      /* attachment point in the parent's body frame, m */
    double b[3];      /* attachment point in the child's body frame, m */
    double ell;       /* rest length of the joint, m (> 0) */
    double omega0[3]; /* rest Darboux vector, 1/m */
} phc_rod_joint_geometry;

/* C (6: stretch then bend–twist) and, when not NULL, the 6x6 Jacobians
 * jp = ∂C/∂z_p and jc = ∂C/∂z_c. */
void phc_rod_joint_eval(const phc_rod_joint_geometry *j, const double xp[3],
                        const double qp[4], const double xc[3], const double qc[4],
                        double c[6], double jp[36], double jc[36]);

/* The 6x6 blocks of ∇²(λ·C) over (z_p, z_c): hpp, hpc (rows z_p, columns
 * z_c; the (c,p) block is its transpose) and hcc.  Only the rotation parts
 * are non-zero (C is linear in the centres). */
void phc_rod_joint_hessian(const phc_rod_joint_geometry *j, const double qp[4],
                           const double qc[4], const double lambda[6], double hpp[36],
                           double hpc[36], double hcc[36]);

/* The rest Darboux vector Ω(q_p, q_c) = (2/ℓ) Im(q̄_p ⊗ q_c), w >= 0 hemisphere. */
void phc_rod_darboux(const double qp[4], const double qc[4], double ell, double omega[3]);

#ifdef __cplusplus
}
#endif

#endif /* PHC_ROD_JOINT_H */
