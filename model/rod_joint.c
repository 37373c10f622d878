/* One joint of the elastic rods: see rod_joint.h.
 *
 * Derivation of the bend–twist Hessian.  With exp(a) ≈ (1 − |a|²/8, a/2) to
 * second order, the perturbed relative rotation is
 *     ω' = q̄_p ē(a) e(b) q_c = (s, R_pᵀ v) ⊗ ω,
 *     s = 1 − |a|²/8 − |b|²/8 + a·b/4,   v = (b − a)/2 − (a × b)/4,
 * (a = δθ_p, b = δθ_c, ω = (w, r) = q̄_p q_c), and
 *     λ·Im((s, u) ⊗ (w, r)) = s (λ·r) + u·(w λ + r × λ).
 * With ρ = λ·r and μ = R_p (w λ + r × λ) the second-order part of
 * (ℓ/2) λ·Ω is −ρ|a|²/8 − ρ|b|²/8 + ρ a·b/4 + ¼ aᵀ[μ]× b, so
 *     H_pp = H_cc = −(ρ/4)(2/ℓ) I,   H_pc = (2/ℓ)(ρ/4 I + ¼[μ]×).
 * For the stretch rows, R(δθ)u = u + δθ×u + ½ δθ×(δθ×u) + O(3) gives
 * ∇²_θ (λ·R u) = ½(λuᵀ + uλᵀ) − (λ·u) I. */
#include "model/rod_joint.h"

#include "model/quaternion.h"

/* m[r*6+c] helpers for 6x6 row-major blocks */
static void skew_into(double *m, int stride, const double v[3], double s)
{
    /* adds s [v]× at m */
    m[0 * stride + 1] += -s * v[2];
    m[0 * stride + 2] += s * v[1];
    m[1 * stride + 0] += s * v[2];
    m[1 * stride + 2] += -s * v[0];
    m[2 * stride + 0] += -s * v[1];
    m[2 * stride + 1] += s * v[0];
}

static void relative(const double qp[4], const double qc[4], double w[4])
{
    double cp[4];
    phc_quat_conj(qp, cp);
    phc_quat_mul(cp, qc, w);
    if (w[0] < 0.0)
        for (int k = 0; k < 4; ++k)
            w[k] = -w[k];
}

void phc_rod_darboux(const double qp[4], const double qc[4], double ell, double omega[3])
{
    double w[4];
    relative(qp, qc, w);
    for (int k = 0; k < 3; ++k)
        omega[k] = 2.0 / ell * w[k + 1];
}

void phc_rod_joint_eval(const phc_rod_joint_geometry *j, const double xp[3],
                        const double qp[4], const double xc[3], const double qc[4],
                        double c[6], double jp[36], double jc[36])
{
    double up[3], uc[3], w[4];
    phc_quat_rotate(qp, j->a, up);
    phc_quat_rotate(qc, j->b, uc);
    relative(qp, qc, w);
    for (int k = 0; k < 3; ++k) {
        c[k] = xp[k] + up[k] - xc[k] - uc[k];
        c[3 + k] = 2.0 / j->ell * w[k + 1] - j->omega0[k];
    }
    if (!jp || !jc)
        return;
    for (int k = 0; k < 36; ++k)
        jp[k] = jc[k] = 0.0;
    for (int k = 0; k < 3; ++k) {
        jp[k * 6 + k] = 1.0;
        jc[k * 6 + k] = -1.0;
    }
    skew_into(jp + 3, 6, up, -1.0);
    skew_into(jc + 3, 6, uc, 1.0);
    /* G = ½ (w I − [r]×) R_pᵀ;  rows 3..5, columns 3..5 */
    double rp[9], m[9] = {0};
    phc_quat_to_matrix(qp, rp);
    m[0] = m[4] = m[8] = w[0];
    skew_into(m, 3, w + 1, -1.0);
    const double f = 2.0 / j->ell * 0.5;
    for (int r = 0; r < 3; ++r)
        for (int col = 0; col < 3; ++col) {
            /* (m R_pᵀ)[r][col] = Σ_k m[r][k] R_p[col][k] */
            double g = 0.0;
            for (int k = 0; k < 3; ++k)
                g += m[r * 3 + k] * rp[col * 3 + k];
            jc[(3 + r) * 6 + 3 + col] = f * g;
            jp[(3 + r) * 6 + 3 + col] = -f * g;
        }
}

void phc_rod_joint_hessian(const phc_rod_joint_geometry *j, const double qp[4],
                           const double qc[4], const double lambda[6], double hpp[36],
                           double hpc[36], double hcc[36])
{
    double up[3], uc[3], w[4];
    for (int k = 0; k < 36; ++k)
        hpp[k] = hpc[k] = hcc[k] = 0.0;
    phc_quat_rotate(qp, j->a, up);
    phc_quat_rotate(qc, j->b, uc);
    relative(qp, qc, w);
    const double *ls = lambda, *lb = lambda + 3;
    const double lup = ls[0] * up[0] + ls[1] * up[1] + ls[2] * up[2];
    const double luc = ls[0] * uc[0] + ls[1] * uc[1] + ls[2] * uc[2];
    for (int r = 0; r < 3; ++r)
        for (int col = 0; col < 3; ++col) {
            const double id = (r == col) ? 1.0 : 0.0;
            hpp[(3 + r) * 6 + 3 + col] =
                0.5 * (ls[r] * up[col] + up[r] * ls[col]) - lup * id;
            hcc[(3 + r) * 6 + 3 + col] =
                -(0.5 * (ls[r] * uc[col] + uc[r] * ls[col]) - luc * id);
        }
    /* bend–twist part */
    const double *rv = w + 1;
    const double rho = lb[0] * rv[0] + lb[1] * rv[1] + lb[2] * rv[2];
    double nu[3] = {w[0] * lb[0] + rv[1] * lb[2] - rv[2] * lb[1],
                    w[0] * lb[1] + rv[2] * lb[0] - rv[0] * lb[2],
                    w[0] * lb[2] + rv[0] * lb[1] - rv[1] * lb[0]};
    double mu[3];
    phc_quat_rotate(qp, nu, mu);
    const double f = 2.0 / j->ell;
    for (int k = 0; k < 3; ++k) {
        hpp[(3 + k) * 6 + 3 + k] += -f * rho / 4.0;
        hcc[(3 + k) * 6 + 3 + k] += -f * rho / 4.0;
        hpc[(3 + k) * 6 + 3 + k] += f * rho / 4.0;
    }
    skew_into(hpc + 3 * 6 + 3, 6, mu, f / 4.0);
}
